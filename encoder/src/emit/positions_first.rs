//! A level's records read positions first (SPEC §7.4 "Positions first",
//! format 3.7): the geometry thread writes every split's record both ways,
//! and the level keeps the record order whose four substreams (wing-offset,
//! wing-distance, edge, placement) code smallest, and the tie rule whose
//! wings do (a large level, where one order or rule is clearly smaller,
//! on its first eighth).
//!
//! A split is written positions first when its fan has free lattice
//! points, its new vertex is one of them and its wings are one of the
//! pairs that keep the new triangles counter-clockwise in xy; otherwise it
//! is an escape, written as under `wings-first` with the wing policy
//! `ranks` and the plane policy `height`, which a positions-first level
//! declares.

use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::positions_first::{
    KIND_CONTEXT, KIND_ESCAPE, NewEdge, OFFSET_CONTEXT, PositionsFirst, Z_CONTEXT, choice_context,
    rank_context,
};
use splitstream_decoder_core::writer::{StreamParams, SubstreamWriter, coded_len_under};
use splitstream_decoder_core::{
    DeficitContexts, RecordOrder, Ring, Target, Ties, WingCandidates, context, height_prediction,
};

use splitstream_decoder_core::predict::wrap;

use rayon::prelude::*;

use super::policies::ranking_params;

/// One level's records under the record order `positions-first`.
#[derive(Clone, Default)]
pub struct PositionsFirstCoding {
    pf: PositionsFirst,
    /// Substreams 6 and 7 (edge, placement) of the level under this order.
    rest: [SubstreamWriter; 2],
    /// Substreams 2 and 3 (wing-offset, wing-distance) under each tie rule
    /// of [`Ties::ALL`]: the level keeps the rule whose wings code
    /// smallest (SPEC §5.1, §7.4; 3.8).
    wings: [[SubstreamWriter; 2]; 3],
    /// The one tie rule still written, once a large level chose it on its
    /// first eighth ([`Self::keep_ties`]).
    kept: Option<Ties>,
    /// Whether a large level chose this order on its first eighth
    /// (`geometry::code_geometry`): its records read wings first are not
    /// written after that, and the orders are not weighed again.
    pub chosen: bool,
    /// Splits read positions first, and escapes.
    pub named: usize,
    pub escaped: usize,
}

/// A split as the geometry thread sees it: its ring (local ids, positions
/// of the entries), R, P and C, the wings and the placement code.
pub struct SplitSeen<'a> {
    pub positions: &'a [[u32; 3]],
    pub ring: &'a Ring,
    pub eligible: &'a WingCandidates,
    pub parent: [u32; 3],
    pub p: [u32; 3],
    pub c: [u32; 3],
    pub o: usize,
    pub d: usize,
    pub code: u8,
}

/// The escape's part of a split: what `wings-first` writes under the wing
/// policy `ranks` and the plane policy `height`.
pub struct WingsFirstRecord {
    /// Wing ranks `o'`, `d'` and their context.
    pub ranks: (u8, u8),
    pub wing_context: u8,
    /// Placement code's context.
    pub placement_context: u8,
    /// The residual vector under `height` (x, y linear, z of the surface).
    pub vector: [i64; 3],
}

impl PositionsFirstCoding {
    /// Writes the record of split `s`, positions first where it can be,
    /// else `escape`.
    pub fn write(&mut self, s: &SplitSeen<'_>, escape: &WingsFirstRecord) {
        let named = self.name(s);
        let kept = self.kept;
        let rules = Ties::ALL
            .into_iter()
            .zip(&mut self.wings)
            .filter(move |&(ties, _)| kept.is_none_or(|k| k == ties));
        let [edge, placement] = &mut self.rest;
        match named {
            Ok(named) => {
                placement.byte_in(KIND_CONTEXT, named.kind);
                edge.varint_in(rank_context(named.free), named.rank as u32);
                if let Some(t) = named.offset {
                    placement.byte_in(OFFSET_CONTEXT, t);
                }
                edge.signed_in(Z_CONTEXT, named.r_z as i32);
                for (ties, [offset, distance]) in rules {
                    let t = ties as usize;
                    offset.byte_in(choice_context(named.xs), named.u[t] as u8);
                    distance.byte_in(choice_context(named.ys), named.v[t] as u8);
                }
                self.named += 1;
            }
            Err(has_free_points) => {
                if has_free_points {
                    placement.byte_in(KIND_CONTEXT, KIND_ESCAPE);
                }
                for (_, [offset, distance]) in rules {
                    offset.byte_in(escape.wing_context, escape.ranks.0);
                    distance.byte_in(escape.wing_context, escape.ranks.1);
                }
                placement.byte_in(escape.placement_context, s.code);
                for (axis, &r) in escape.vector.iter().enumerate() {
                    edge.signed_in(axis as u8, r as i32);
                }
                self.escaped += 1;
            }
        }
    }

    /// The record of split `s` read positions first, or for an escape
    /// whether the fan has free points (then a kind is read: SPEC §7.4
    /// `read_record_pf`, backwards).
    fn name(&mut self, s: &SplitSeen<'_>) -> Result<Named, bool> {
        let free = self
            .pf
            .free_points(s.positions, s.parent, s.ring)
            .ok_or(false)?;
        self.name_among(s, free).ok_or(true)
    }

    /// [`Self::name`] once the fan's `free` points are known.
    fn name_among(&mut self, s: &SplitSeen<'_>, free: usize) -> Option<Named> {
        let wide = |v: [u32; 3]| v.map(|x| x as i64);
        let (r, p, c) = (wide(s.parent), wide(s.p), wide(s.c));
        let rel = |v: [i64; 3]| [v[0] - r[0], v[1] - r[1]];
        let (o, b) = (s.o, s.o + s.d);
        // The new vertex N, the edge's ends, the offset and the pair.
        let (n, edge, offset, pair, vector_z) = match s.code {
            0 => {
                let n = rel(c);
                let e = NewEdge {
                    a: n,
                    b: [0, 0],
                    midpoint: false,
                };
                (n, e, None, (b, o), c[2] - r[2])
            }
            1 => {
                let n = rel(p);
                let e = NewEdge {
                    a: n,
                    b: [0, 0],
                    midpoint: false,
                };
                (n, e, None, (o, b), p[2] - r[2])
            }
            _ => {
                let n = rel(c);
                let t = [p[0] - (2 * r[0] - c[0]), p[1] - (2 * r[1] - c[1])];
                if !(0..=1).contains(&t[0]) || !(0..=1).contains(&t[1]) {
                    return None;
                }
                let e = NewEdge {
                    a: rel(p),
                    b: n,
                    midpoint: true,
                };
                (n, e, Some((t[0] + 2 * t[1]) as u8), (o, b), c[2] - p[2])
            }
        };
        let rank = self.pf.rank_of(n)?;
        // The lists do not depend on the tie rule, only their order.
        let xs = self.pf.order_xs(s.eligible, &edge);
        // Under every rule at once (`u`, `v`: by `Ties::ALL` index); only
        // the rules still written are read.
        let u = self.pf.ranks_of_choice(xs, pair.0)?;
        let ys = self.pf.order_ys(&edge, pair.0);
        let v = self.pf.ranks_of_choice(ys, pair.1)?;
        // z: the fan's surface at the new x and y, or 0 where no wedge
        // holds it.
        let target = Target::of_code(s.code)?;
        let xy = match offset {
            Some(t) => [2 * n[0] - (t & 1) as i64, 2 * n[1] - (t >> 1) as i64],
            None => n,
        };
        let h = height_prediction(s.positions, s.parent, s.ring, target, [xy[0], xy[1], 0])
            .unwrap_or(0);
        Some(Named {
            kind: u8::from(s.code == 2),
            free,
            rank,
            offset,
            xs,
            u,
            ys,
            v,
            r_z: wrap(vector_z - h),
        })
    }

    /// The four substreams' cost under `params`' ranking parameters, in a
    /// positions-first level, with the wings under the tie rule that codes
    /// them smallest (the lowest rule of equal cost: `ring` keeps the
    /// stream readable by 3.7 decoders); and that rule.
    pub fn cost(&mut self, params: &StreamParams) -> (usize, Ties) {
        let (rest, wings) = self.costs_by_rule(params, None);
        let (wing_cost, best) = cheapest(&wings);
        (rest + wing_cost, best)
    }

    /// [`Self::cost`] with the wings under `ties`.
    pub fn cost_under(&mut self, params: &StreamParams, ties: Ties) -> usize {
        let (rest, wings) = self.costs_by_rule(params, Some(ties));
        rest + cheapest(&wings).0
    }

    /// The edge and placement substreams' cost under `params`' ranking
    /// parameters, and the two wing substreams' under each tie rule still
    /// written, or only under `only` (their rANS plans kept for framing,
    /// `coded_len_under`).
    pub fn costs_by_rule(
        &mut self,
        params: &StreamParams,
        only: Option<Ties>,
    ) -> (usize, Vec<(usize, Ties)>) {
        let ranking = ranking_params(params);
        let cost = |id: u8, sub: &mut SubstreamWriter| {
            coded_len_under(
                sub,
                id,
                DeficitContexts::Plain,
                RecordOrder::PositionsFirst,
                &ranking,
            )
        };
        let [edge, placement] = &mut self.rest;
        let only = only.or(self.kept);
        let mut wings: Vec<(Ties, &mut [SubstreamWriter; 2])> = Ties::ALL
            .into_iter()
            .zip(&mut self.wings)
            .filter(|&(ties, _)| only.is_none_or(|forced| forced == ties))
            .collect();
        rayon::join(
            || cost(substream::EDGE, edge) + cost(substream::PLACEMENT, placement),
            || {
                wings
                    .par_iter_mut()
                    .map(|(ties, [o, d])| {
                        let ties = *ties;
                        let wings =
                            cost(substream::WING_OFFSET, o) + cost(substream::WING_DISTANCE, d);
                        (wings, ties)
                    })
                    .collect()
            },
        )
    }

    /// Writes the wings under `ties` alone from now on (a large level's
    /// early choice: `geometry::code_geometry`).
    pub fn keep_ties(&mut self, ties: Ties) {
        for (rule, wings) in Ties::ALL.into_iter().zip(&mut self.wings) {
            if rule != ties {
                *wings = Default::default();
            }
        }
        self.kept = Some(ties);
    }

    /// The tie rule [`Self::keep_ties`] kept, if it was called.
    pub fn kept_ties(&self) -> Option<Ties> {
        self.kept
    }

    /// Puts the four substreams into `subs` (ids 1..=7 at 0..=6), the wings
    /// those under `ties`.
    pub fn install(self, ties: Ties, subs: &mut [SubstreamWriter]) {
        let [edge, placement] = self.rest;
        let [ring, rising, falling] = self.wings;
        let [offset, distance] = match ties {
            Ties::Ring => ring,
            Ties::Rising => rising,
            Ties::Falling => falling,
        };
        for (id, sub) in [
            (substream::WING_OFFSET, offset),
            (substream::WING_DISTANCE, distance),
            (substream::EDGE, edge),
            (substream::PLACEMENT, placement),
        ] {
            subs[(id - substream::FLAGS) as usize] = sub;
        }
    }
}

/// The cheapest of the wing costs by tie rule, the lowest rule of equal
/// cost (`Ties::ALL` order); `(0, Ring)` for none.
pub fn cheapest(wings: &[(usize, Ties)]) -> (usize, Ties) {
    wings
        .iter()
        .copied()
        .min_by_key(|&(c, ties)| (c, ties as u8))
        .unwrap_or((0, Ties::Ring))
}

/// A record read positions first: its values and the counts their
/// contexts come from.
struct Named {
    kind: u8,
    free: usize,
    rank: usize,
    offset: Option<u8>,
    xs: usize,
    /// The ranks of the wings under each rule of [`Ties::ALL`].
    u: [usize; 3],
    ys: usize,
    v: [usize; 3],
    r_z: i64,
}

/// The wing-offset and wing-distance context of an escaped record
/// (SPEC §5.5.5: by the eligible entries).
pub fn escape_wing_context(eligible: &WingCandidates) -> u8 {
    context::wing(eligible.count())
}
