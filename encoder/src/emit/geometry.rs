//! The geometry of a level's split records, coded on a thread of its own
//! while the replay goes on: the wing ranks under every wing policy, the
//! placement codes and the residual vectors (SPEC §7.4).
//!
//! All of it depends only on the split's ring as it is at the start of its
//! round, which the replay copies out ([`SplitGeometry`]: the ring entries'
//! positions, which of them may be wings, R's position, P's and C's): the
//! replay's thread, the emission's critical path, then keeps only the
//! decoder's own work and what the record's connectivity needs. The values
//! written are those the replay wrote itself before (same streams): each
//! computation runs on the copied entries, renumbered 0.. in ring order.

use std::sync::mpsc::{self, Receiver, Sender, SyncSender};

use splitstream_decoder_core::limits::{MAX_SPLIT_VALENCE, NONE, substream};
use splitstream_decoder_core::writer::{StreamParams, SubstreamWriter, coded_len};
use splitstream_decoder_core::{
    Plane, PlanePolicy, PositionMode, Ring, SplitFan, Target, Ties, WingCandidates, add_residual,
    arc_means, constrained_positions, context, predict, residual,
};

use super::policies::{SplitResiduals, early_choice_at, ranking_params};
use super::positions_first::{
    PositionsFirstCoding, SplitSeen, WingsFirstRecord, cheapest, escape_wing_context,
};
use super::wings::WingCoding;

/// What a split's record takes from the state at the start of its round.
#[derive(Clone, Copy, Debug)]
pub struct SplitGeometry {
    /// The collapse's vertex, for error messages.
    pub id: u32,
    /// The wings' ring positions (SPEC §7.4 `o`, `d`).
    pub o: u8,
    pub d: u8,
    /// Ring length `k`; its entries' positions are the batch's next `k`.
    pub k: u8,
    /// Whether entry 0 is the ghost (a boundary vertex, SPEC §7.1).
    pub boundary: bool,
    /// The ring entries that may be wings.
    pub eligible: WingCandidates,
    /// Positions of R, P and C.
    pub parent: [u32; 3],
    pub p: [u32; 3],
    pub c: [u32; 3],
}

/// Consecutive splits of a level, in split order, and their rings'
/// positions back to back (the ghost's slot holds anything).
#[derive(Default)]
pub struct GeometryBatch {
    pub splits: Vec<SplitGeometry>,
    pub ring_positions: Vec<[u32; 3]>,
}

/// Splits sent to the geometry thread at once: small enough that the
/// thread starts on a round while it is still replayed, and that little is
/// held in flight (whole rounds took the 1M terrain's peak RSS from
/// 707-727 MB to 735-765 MB).
const GEOMETRY_BATCH: usize = 4096;

impl GeometryBatch {
    pub fn new() -> GeometryBatch {
        GeometryBatch {
            splits: Vec::with_capacity(GEOMETRY_BATCH),
            // Valence 6 mostly, 7 or 8 for boundaries and irregular meshes.
            ring_positions: Vec::with_capacity(8 * GEOMETRY_BATCH),
        }
    }

    /// Whether the batch is due to be sent.
    pub fn is_full(&self) -> bool {
        self.splits.len() >= GEOMETRY_BATCH
    }
}

/// The replay's end of the geometry thread's channels: full batches go,
/// and come back emptied to be filled again (fresh ones, allocated and
/// their pages faulted in every few thousand splits, cost the replay's
/// thread more than the copies themselves).
pub struct GeometrySender {
    full: SyncSender<GeometryBatch>,
    spent: Receiver<GeometryBatch>,
}

/// The geometry thread's end ([`code_geometry`]).
pub struct GeometryReceiver {
    full: Receiver<GeometryBatch>,
    spent: Sender<GeometryBatch>,
}

/// The two ends of a level's geometry channels.
pub fn geometry_channels() -> (GeometrySender, GeometryReceiver) {
    let (full_out, full_in) = mpsc::sync_channel(2);
    let (spent_out, spent_in) = mpsc::channel();
    (
        GeometrySender {
            full: full_out,
            spent: spent_in,
        },
        GeometryReceiver {
            full: full_in,
            spent: spent_out,
        },
    )
}

impl GeometrySender {
    /// Sends the splits gathered in `batch` (if any), leaving an empty
    /// batch in its place. A closed channel means the geometry thread
    /// failed: its error is reported when it is joined.
    pub fn send(&self, batch: &mut GeometryBatch) {
        if batch.splits.is_empty() {
            return;
        }
        let next = self
            .spent
            .try_recv()
            .unwrap_or_else(|_| GeometryBatch::new());
        let _ = self.full.send(std::mem::replace(batch, next));
    }
}

/// A level's coded geometry: the wing ranks under every wing policy, and in
/// constrained mode the placement substream, and the records read
/// positions first when they are a choice (format 3.7).
pub struct LevelGeometry {
    pub wings: WingCoding,
    pub placement: SubstreamWriter,
    pub positions_first: Option<PositionsFirstCoding>,
}

/// What a level whose records may be read positions first needs to choose
/// its record order on its first eighth, as it chooses its policies
/// (`policies::EARLY_CHOICE_SPLITS`).
pub struct EarlyOrder {
    /// What the residual coder's kept plane policy costs so far
    /// (`policies::code_policies`); `None` under `--records
    /// positions-first`, where there is nothing to weigh.
    pub edge_cost: Option<Receiver<usize>>,
    /// `--ties`: the only tie rule.
    pub forced_ties: Option<Ties>,
}

/// Codes the batches arriving on `batches` for one level of `splits` splits
/// and passes each batch's residual vectors on to `residuals` (the plane
/// policies' coder); `heights`: whether the residuals under `height` are
/// worth computing. A large level keeps one wing policy once its first
/// eighth is coded (`policies::EARLY_CHOICE_SPLITS`), and where its records
/// may be read positions first (`positions_first`, with what the early
/// choice needs) its record order where one is clearly smaller
/// ([`EARLY_ORDER_MARGIN`]):
/// the other order's records are not written after that. An error names
/// the first split whose record does not give back its positions or whose
/// wings may not be wings: an encoder bug.
pub fn code_geometry(
    batches: GeometryReceiver,
    residuals: Sender<Vec<SplitResiduals>>,
    mut wings: WingCoding,
    positions_first: Option<(PositionsFirstCoding, EarlyOrder)>,
    params: &StreamParams,
    splits: usize,
    heights: bool,
) -> Result<LevelGeometry, String> {
    let mode = params.position_mode;
    let (mut positions_first, order) = positions_first.unzip();
    // A large level's wing policy is chosen on its first eighth (unless
    // forced: then there is nothing to choose).
    let mut early = early_choice_at(splits);
    // Whether the records read wings first are still written (until the
    // level chooses positions first).
    let mut wings_first = true;
    let mut seen = 0;
    let mut placement = SubstreamWriter::default();
    let mut ring = Ring::default();
    // Local ids 0.. of the ring entries (the ghost is NONE).
    let mut ids = [0u32; MAX_SPLIT_VALENCE];
    for (i, id) in ids.iter_mut().enumerate() {
        *id = i as u32;
    }
    for mut batch in batches.full {
        let mut out = Vec::with_capacity(batch.splits.len());
        let mut start = 0;
        for g in &batch.splits {
            let k = g.k as usize;
            let positions = &batch.ring_positions[start..start + k];
            start += k;
            ids[0] = if g.boundary { NONE } else { 0 };
            if !ring.set_vertices(&ids[..k]) {
                return Err(format!("the ring of {} is too long", g.id));
            }
            let (o, d) = (g.o as usize, g.d as usize);
            if wings_first && !wings.write(positions, &ring, &g.eligible, o, d) {
                return Err(format!(
                    "a wing of the collapse of {} was a candidate at the start of its round",
                    g.id
                ));
            }
            let (residuals, placed) =
                split_residuals(g, positions, &ring, mode, heights, &mut placement)?;
            if let (Some(pf), Some((code, placement_context))) = (&mut positions_first, placed) {
                let ranks = g
                    .eligible
                    .ranks(o, d)
                    .ok_or_else(|| format!("the wings of {} are not eligible", g.id))?;
                let seen = SplitSeen {
                    positions,
                    ring: &ring,
                    eligible: &g.eligible,
                    parent: g.parent,
                    p: g.p,
                    c: g.c,
                    o,
                    d,
                    code,
                };
                let escape = WingsFirstRecord {
                    ranks,
                    wing_context: escape_wing_context(&g.eligible),
                    placement_context,
                    vector: residuals.vectors(PlanePolicy::Height).0,
                };
                pf.write(&seen, &escape);
            }
            out.push(residuals);
        }
        // A closed channel means the coder failed: its error is reported
        // when it is joined.
        if wings_first {
            let _ = residuals.send(out);
        }
        seen += batch.splits.len();
        if early.is_some_and(|at| seen >= at) {
            early = None;
            let wing_cost = wings.choose_early(params);
            if let (Some(pf), Some(order)) = (&mut positions_first, &order) {
                match choose_order_early(pf, order, wing_cost, &mut placement, params) {
                    Some(EarlyChoice::PositionsFirst(ties)) => {
                        pf.chosen = true;
                        if let Some(ties) = ties {
                            pf.keep_ties(ties);
                        }
                        wings_first = false;
                    }
                    Some(EarlyChoice::WingsFirst) => positions_first = None,
                    None => {}
                }
            }
        }
        batch.splits.clear();
        batch.ring_positions.clear();
        let _ = batches.spent.send(batch);
    }
    Ok(LevelGeometry {
        wings,
        placement,
        positions_first,
    })
}

/// A large level chooses its record order, and its tie rule, on its first
/// eighth only where one codes it smaller than the other by more than this
/// share (1/32, about 3 %); closer ones are weighed on the whole level.
/// Measured on the demo terrains and the Jacksboro DEM (BENCHMARKS.md,
/// "The record order chosen early"): the first eighth ranked the orders as
/// the whole level did wherever they were 3.7 % apart or more, and the one
/// level it ranked otherwise (the 4M terrain's level 1) was 0.3 % apart;
/// it ranked the tie rules as the whole level wherever they were 3.6 %
/// apart or more.
const EARLY_ORDER_MARGIN: usize = 32;

/// A record order chosen on a level's first eighth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum EarlyChoice {
    WingsFirst,
    /// With the tie rule, where one was clearly the cheapest (or forced).
    PositionsFirst(Option<Ties>),
}

/// The early choice of a level's record order, on its first eighth, by
/// the same measure as at the level's end (`replay::choose_record_order`)
/// on what is written so far: the four substreams under positions first
/// (under their cheapest tie rule) against the wings (`wing_cost`), the
/// `placement` codes and the residuals (`order.edge_cost`) under wings
/// first. `None`: too close to call ([`EARLY_ORDER_MARGIN`]). Residuals
/// whose coder failed (its error ends the level) count as costing more
/// than any alternative.
fn choose_order_early(
    pf: &mut PositionsFirstCoding,
    order: &EarlyOrder,
    wing_cost: Option<usize>,
    placement: &mut SubstreamWriter,
    params: &StreamParams,
) -> Option<EarlyChoice> {
    let Some(edge_cost) = &order.edge_cost else {
        // Positions first forced: only the tie rule may be chosen.
        let ties = order.forced_ties.or_else(|| {
            let (_, by_rule) = pf.costs_by_rule(params, None);
            clear_tie_rule(&by_rule)
        });
        return Some(EarlyChoice::PositionsFirst(ties));
    };
    let (rest, by_rule) = pf.costs_by_rule(params, order.forced_ties);
    let ties = order.forced_ties.or_else(|| clear_tie_rule(&by_rule));
    let ranking = ranking_params(params);
    let edge = edge_cost.recv().unwrap_or(usize::MAX);
    let wings_first = [
        wing_cost.unwrap_or(usize::MAX),
        coded_len(placement, substream::PLACEMENT, &ranking),
        edge,
    ]
    .into_iter()
    .fold(0usize, usize::saturating_add);
    let positions_first = rest + cheapest(&by_rule).0;
    if clearly_below(positions_first, wings_first) {
        Some(EarlyChoice::PositionsFirst(ties))
    } else if clearly_below(wings_first, positions_first) {
        Some(EarlyChoice::WingsFirst)
    } else {
        None
    }
}

/// Whether `a` is below `b` by more than [`EARLY_ORDER_MARGIN`].
fn clearly_below(a: usize, b: usize) -> bool {
    a < b - b / EARLY_ORDER_MARGIN
}

/// The tie rule whose wings cost clearly less than every other's, if one
/// does.
fn clear_tie_rule(by_rule: &[(usize, Ties)]) -> Option<Ties> {
    let (best, ties) = cheapest(by_rule);
    by_rule
        .iter()
        .all(|&(cost, other)| other == ties || clearly_below(best, cost))
        .then_some(ties)
}

/// The residual vectors of split `g` (and in constrained mode its placement
/// code, written to `placement`, and returned with its context), from its
/// ring's `positions`.
fn split_residuals(
    g: &SplitGeometry,
    positions: &[[u32; 3]],
    ring: &Ring,
    mode: PositionMode,
    heights: bool,
    placement: &mut SubstreamWriter,
) -> Result<(SplitResiduals, Option<(u8, u8)>), String> {
    let (parent, p, c) = (g.parent, g.p, g.c);
    let mut placed = None;
    let means = arc_means(positions, parent, ring, g.o as usize, g.d as usize);
    let wide = |x: [u32; 3]| x.map(|v| v as i64);
    let sub = |a: [i64; 3], b: [i64; 3]| -> [i64; 3] { std::array::from_fn(|i| a[i] - b[i]) };
    let add = |a: [i64; 3], b: [i64; 3]| -> [i64; 3] { std::array::from_fn(|i| a[i] + b[i]) };
    let (origin, p_wide, c_wide) = (wide(parent), wide(p), wide(c));
    let fan = SplitFan {
        positions,
        parent,
        ring,
    };
    // The z of the residual of vector `x` under `height` (format 3.1).
    let height = |target: Target, prediction: [i64; 3], x: [i64; 3]| -> i64 {
        if heights {
            fan.residual(PlanePolicy::Height, target, prediction, x)[2]
        } else {
            0
        }
    };
    let consistent;
    let (first, second, height_residuals) = match mode {
        PositionMode::Optimal => {
            let p_hat = predict(&means, mode, Target::P);
            let c_hat = predict(&means, mode, Target::C);
            let rs = residual(sub(p_wide, origin), p_hat);
            let rt = residual(sub(c_wide, origin), c_hat);
            // What the decoder will compute from the residuals (each plane
            // policy's coding is checked to give them back).
            consistent = add(origin, add_residual(p_hat, rs)) == p_wide
                && add(origin, add_residual(c_hat, rt)) == c_wide;
            let h = [
                height(Target::P, p_hat, sub(p_wide, origin)),
                height(Target::C, c_hat, sub(c_wide, origin)),
            ];
            (rs, rt, h)
        }
        PositionMode::Constrained => {
            let e = sub(c_wide, p_wide);
            let mid: [u32; 3] = std::array::from_fn(|i| (p_wide[i] + (e[i] >> 1)) as u32);
            let (code, x) = if parent == p {
                (0, sub(c_wide, origin))
            } else if parent == c {
                (1, sub(p_wide, origin))
            } else if parent == mid {
                (2, e)
            } else {
                return Err(format!(
                    "constrained position of {} off P, C and midpoint",
                    g.id
                ));
            };
            let placement_context = context::placement(&means);
            placement.byte_in(placement_context, code);
            placed = Some((code, placement_context));
            let target = Target::of_code(code).expect("codes 0..=2");
            let prediction = predict(&means, mode, target);
            let r = residual(x, prediction);
            consistent = constrained_positions(parent, code, add_residual(prediction, r))
                == (p_wide, c_wide);
            (r, [0; 3], [height(target, prediction, x), 0])
        }
    };
    if !consistent {
        return Err(format!(
            "the residuals of {} do not decode to its positions",
            g.id
        ));
    }
    Ok((
        SplitResiduals {
            normal: Plane::new(PlanePolicy::Dominant, &means).normal,
            first,
            second,
            height: height_residuals,
            id: g.id,
        },
        placed,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An order or a tie rule is chosen early only when it is clearly
    /// smaller: within 1/32 of each other, the whole level decides.
    #[test]
    fn early_choices_need_a_clear_margin() {
        // 1000 − 1000/32 = 969: 968 is clearly below, 969 is not.
        assert!(clearly_below(968, 1000));
        assert!(!clearly_below(969, 1000));
        assert!(!clearly_below(1000, 1000));
        assert!(!clearly_below(0, 0));
        // A failed residual coder costs `usize::MAX`.
        assert!(clearly_below(5, usize::MAX));
        use Ties::{Falling, Ring, Rising};
        assert_eq!(
            clear_tie_rule(&[(1000, Ring), (900, Rising), (1100, Falling)]),
            Some(Rising)
        );
        assert_eq!(
            clear_tie_rule(&[(1000, Ring), (980, Rising), (1100, Falling)]),
            None
        );
        assert_eq!(clear_tie_rule(&[(700, Falling)]), Some(Falling));
        assert_eq!(
            clear_tie_rule(&[(0, Ring), (0, Rising), (0, Falling)]),
            None
        );
    }
}
