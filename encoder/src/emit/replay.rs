//! Replays the refinement with decoder-core's round procedure, writing each
//! flag and split record as the decoder will read it (SPEC §7).

use splitstream_decoder_core::corner_refs;
use splitstream_decoder_core::limits::{LEAF, NONE, substream};
use splitstream_decoder_core::symbols::split_valence_symbol;
use splitstream_decoder_core::writer::{
    Chunk, FramedLevel, LevelPayload, SeedPayload, StreamParams, SubstreamWriter, coded_len_under,
    frame_level_with,
};
use splitstream_decoder_core::{
    CornerRefs, DeficitContexts, Error, MeshState, PlanePolicy, PositionMode, RecordOrder,
    RecordSource, Ring, Schedule, SplitOutcome, SplitRecord, StateMemory, Ties, WingPolicy,
};

use std::sync::mpsc;

use rayon::prelude::*;

use super::deficits::DeficitCoding;
use super::flags::FlagCoding;
use super::geometry::{
    EarlyOrder, GeometryBatch, GeometrySender, LevelGeometry, SplitGeometry, code_geometry,
    geometry_channels,
};
use super::levels::LevelPlan;
use super::policies::{choose_policy, code_policies, early_choice_at, ranking_params};
use super::positions_first::PositionsFirstCoding;
use super::wings::WingCoding;
use crate::corner_table::Fan;
use crate::mesh::sorted_canonical;
use crate::prefetch::prefetch;
use crate::quantize::QuantizedMesh;
use crate::simplify::{Collapse, NO_SPLIT, Simplification};

/// The replay found the simplification and the decoder disagreeing: an
/// encoder bug, never a property of the input.
#[derive(Debug)]
pub struct ReplayError(pub String);

impl std::fmt::Display for ReplayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "internal encoder error during replay: {}", self.0)
    }
}

impl std::error::Error for ReplayError {}

/// Output of the replay: framed-ready levels and the vertex permutation.
pub struct Replayed {
    /// The seed mesh level 0 starts from.
    pub seed: SeedPayload,
    /// Level 0's rounds, then the refinement levels.
    pub levels: Vec<LevelPayload>,
    /// Each level framed (`writer::frame_level`).
    pub framed: Vec<FramedLevel>,
    /// Input vertex id of each decoded vertex.
    pub permutation: Vec<u32>,
    /// State hash after the last round, when [`ReplayOptions::final_hash`]
    /// asks for it.
    pub final_hash: Option<u64>,
}

/// What a replay codes each level with, and what it reports.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReplayOptions {
    /// The plane policy of every level; by default each level's cheapest.
    pub plane: Option<PlanePolicy>,
    /// The wing policy of every level; by default each level's cheapest.
    pub wings: Option<WingPolicy>,
    /// The contexts of every level (SPEC §5.1, level header byte 10): under
    /// `split-valences` the deficit contexts, by default each level's
    /// cheapest; under `every-vertex` the flag contexts, `Plain` (by
    /// valence, 3.6) or by default `SplitHistory` (3.10).
    pub deficits: Option<DeficitContexts>,
    /// The record order of every level (format 3.7); by default each
    /// level's cheaper where `positions-first` is allowed
    /// ([`positions_first_allowed`]).
    pub records: Option<RecordOrder>,
    /// The tie rule of every positions-first level (format 3.8); by
    /// default each level's cheapest.
    pub ties: Option<Ties>,
    /// Whether to hash the final state (SPEC §8; a serial pass over the
    /// whole state, about 45 ms on the 1M terrain, which `encode` does not
    /// need and `transcode` compares).
    pub final_hash: bool,
}

/// Owned memory for a [`MeshState`].
struct Memory {
    positions: Vec<[u32; 3]>,
    corners: Vec<u32>,
    /// Corner references as 4-byte words (aligned for the base build's
    /// scratch), viewed as bytes by [`CornerRefs`].
    opposite: Vec<u32>,
    vertex_corner: Vec<u32>,
    width: usize,
    deficit: Vec<u8>,
    candidates: Vec<u64>,
}

impl Memory {
    fn new(v: usize, t: usize, base_v: usize, base_t: usize) -> Memory {
        let width = corner_refs::width_for(3 * t as u64);
        let words = |bytes: u64| (bytes as usize).div_ceil(4);
        let base_scratch = 4 * MeshState::base_scratch_len(base_v as u32, base_t as u32) as u64;
        Memory {
            positions: vec![[0; 3]; v],
            corners: vec![0; 3 * t],
            opposite: vec![0; words(corner_refs::bytes_for(3 * t as u64, width).max(base_scratch))],
            vertex_corner: vec![0; words(corner_refs::bytes_for(v as u64, width))],
            width,
            deficit: vec![0; v],
            candidates: vec![0; 3 * v.div_ceil(64)],
        }
    }

    fn state(&mut self, bits: u8, schedule: Schedule) -> MeshState<'_> {
        MeshState::new(
            StateMemory {
                positions: &mut self.positions,
                corners: &mut self.corners,
                swing: CornerRefs::new(bytemuck::cast_slice_mut(&mut self.opposite), self.width),
                vertex_corner: CornerRefs::new(
                    bytemuck::cast_slice_mut(&mut self.vertex_corner),
                    self.width,
                ),
                deficit: &mut self.deficit,
                candidates: &mut self.candidates,
            },
            bits,
            schedule,
        )
    }
}

/// Feeds one round from the collapses of one simplification step.
struct StepSource<'a> {
    collapses: &'a [Collapse],
    /// The decoder ids of each collapse's wings (`wing_a`, `wing_b`),
    /// looked up before the round: the wings do not split in it, so their
    /// ids hold for the whole round, and the look-ups, independent of one
    /// another there, overlap their cache misses instead of each waiting
    /// inside its record.
    wings: &'a [[u32; 2]],
    /// The level's flags, in the contexts of each choice still open.
    flags: &'a mut FlagCoding,
    /// For each decoder id, the index of its vertex's collapse in this step
    /// (or NONE): the decoder asks by its own ids, one look-up instead of
    /// two through `dec2enc` for every candidate.
    current: &'a mut [u32],
    enc2dec: &'a mut [u32],
    dec2enc: &'a mut Vec<u32>,
    /// The level's split-valence symbols in every choice of contexts.
    deficit_coding: &'a mut DeficitCoding,
    /// What the records take from the state for their wing ranks,
    /// placement codes and residual vectors, gathered for another thread
    /// (`geometry`) and sent to it a batch at a time.
    geometry: &'a mut GeometryBatch,
    geometry_out: &'a GeometrySender,
    pending: Option<usize>,
    /// Whether the pending split gives the collapse's C index R (SPEC §7.4).
    swapped: bool,
    problem: Option<String>,
}

fn slot(id: u8) -> usize {
    (id - substream::FLAGS) as usize
}

impl StepSource<'_> {
    fn fail(&mut self, what: String) -> Error {
        self.problem.get_or_insert(what);
        Error::RingOffsetOutOfRange
    }
}

impl RecordSource for StepSource<'_> {
    fn flag(&mut self, state: &MeshState<'_>, v: u32) -> Result<bool, Error> {
        let flagged = self.current[v as usize] != NONE;
        let byte = state.deficits().get(v as usize).copied().unwrap_or(0);
        self.flags.write(byte, state.split_in_level(v), flagged);
        Ok(flagged)
    }

    fn likely_flags(&mut self, _state: &MeshState<'_>, upcoming: &[u32]) -> u128 {
        // Exactly the flags flag() will give: the candidates that collapse
        // in this step. (`current` is indexed by decoder id, as in flag();
        // indexing it by encoder id warmed the fans of unrelated vertices.)
        // The records of the batch's collapses are asked for while their
        // fans are walked: a collapse lies wherever the simplifier put it,
        // so reading it in `record` was a cache miss on the replay's path.
        upcoming.iter().enumerate().fold(0, |bits, (i, &v)| {
            let index = self.current[v as usize];
            if index != NONE {
                prefetch(self.collapses, index as usize);
                prefetch(self.wings, index as usize);
            }
            bits | ((index != NONE) as u128) << i
        })
    }

    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        let index = self.current[r as usize] as usize;
        let col = self.collapses[index];
        let id = col.p;
        self.pending = Some(index);
        let [a, b] = self.wings[index];
        let find = |x: u32| ring.vertices().iter().position(|&y| y == x);
        let (Some(ia), Some(ib)) = (find(a), find(b)) else {
            return Err(self.fail(format!("wings of the collapse of {id} not in the ring")));
        };
        // The collapse's P keeps R's index when its arc (counter-clockwise
        // from wing A to wing B) is arc 1; otherwise the roles swap and its
        // C keeps the index (SPEC §7.4: arc 1 always goes to P).
        let swapped = ia > ib;
        let (o, d) = if swapped {
            (ib, ia - ib)
        } else {
            (ia, ib - ia)
        };
        self.swapped = swapped;
        let (sv_p, sv_c, p, c) = if swapped {
            (
                col.split_valence_c,
                col.split_valence_p,
                col.position_c,
                col.position_p,
            )
        } else {
            (
                col.split_valence_p,
                col.split_valence_c,
                col.position_p,
                col.position_c,
            )
        };
        let k = ring.len();
        let len_p = d;
        let deficit = |split_valence: u8, valence: usize| -> Option<u8> {
            if split_valence == NO_SPLIT {
                Some(LEAF)
            } else {
                (split_valence as usize)
                    .checked_sub(valence)
                    .map(|x| x as u8)
            }
        };
        let (valence_p, valence_c) = (len_p + 2, k - len_p + 2);
        let (dp, dc) = match state.schedule() {
            Schedule::SplitValences => {
                let (Some(dp), Some(dc)) = (deficit(sv_p, valence_p), deficit(sv_c, valence_c))
                else {
                    return Err(self.fail(format!("valence of {id} grew past its split valence")));
                };
                self.deficit_coding.write(
                    split_valence_symbol(dp, valence_p),
                    split_valence_symbol(dc, valence_c),
                    dp,
                    valence_p,
                    valence_c,
                );
                (dp, dc)
            }
            // No split valences (SPEC §7.4, 3.6): the bytes are the valences.
            Schedule::EveryVertex => (valence_p.min(255) as u8, valence_c.min(255) as u8),
        };
        let parent = state.positions()[r as usize];
        if parent != col.position_r {
            return Err(self.fail(format!("position of {id} differs from its collapse")));
        }
        // The rest of the record comes from the ring as it is now, at the
        // start of the round: copied out for the geometry thread.
        let positions = state.positions();
        let batch = &mut *self.geometry;
        batch.ring_positions.extend(
            ring.vertices()
                .iter()
                .map(|&v| positions.get(v as usize).copied().unwrap_or_default()),
        );
        batch.splits.push(SplitGeometry {
            id,
            o: o as u8,
            d: d as u8,
            k: k as u8,
            boundary: ring.is_boundary(),
            eligible: state.wing_candidates(ring),
            parent,
            p,
            c,
        });
        if batch.is_full() {
            self.geometry_out.send(batch);
        }
        Ok(SplitRecord {
            wing_offset: o as u8,
            wing_distance: d as u8,
            deficit_p: dp,
            deficit_c: dc,
            position_p: p,
            position_c: c,
        })
    }

    fn applied(&mut self, r: u32, c: u32, _outcome: &SplitOutcome) {
        if let Some(index) = self.pending.take() {
            let col = self.collapses[index];
            // Which input vertex keeps index r and which gets the new index.
            let (kept, new) = if self.swapped {
                (col.c, col.p)
            } else {
                (col.p, col.c)
            };
            self.enc2dec[kept as usize] = r;
            self.dec2enc[r as usize] = kept;
            self.enc2dec[new as usize] = c;
            self.dec2enc.push(new);
        }
    }
}

/// A level's payload and its framed bytes with its largest chunks
/// (`writer::frame_level`).
type LevelAndFrame = (LevelPayload, FramedLevel);

/// The replay's levels, and the final state's hash when asked for
/// ([`ReplayOptions::final_hash`]).
type LevelsAndHash = Result<(Vec<LevelAndFrame>, Option<u64>), ReplayError>;

/// Replays `s` level by level as planned, returning the level payloads,
/// each with the plane policy, the wing policy and the deficit contexts of
/// `options`, or by default the ones whose residuals, wing ranks and split
/// valences cost least under `params`.
pub fn replay(
    mesh: &QuantizedMesh,
    s: &Simplification,
    plan: &LevelPlan,
    params: &StreamParams,
    options: ReplayOptions,
) -> Result<Replayed, ReplayError> {
    let ReplayOptions {
        plane,
        wings: wing_policy,
        deficits: deficit_contexts,
        records,
        ties: forced_ties,
        final_hash,
    } = options;
    // Positions first is tried where the level could declare it: in
    // constrained mode, with the plane policy `height` and the wing policy
    // `ranks` of its escapes allowed.
    let try_positions_first = records != Some(RecordOrder::WingsFirst)
        && positions_first_allowed(params.position_mode, plane, wing_policy);
    let mode = params.position_mode;
    // Byte 10 of every level header (SPEC §5.1): `split-history` names the
    // flags' contexts of `every-vertex` (3.10), not deficit contexts.
    if params.schedule == Schedule::SplitValences
        && deficit_contexts == Some(DeficitContexts::SplitHistory)
    {
        return Err(ReplayError(
            "the contexts split-history apply to the schedule every-vertex only".into(),
        ));
    }
    let n = mesh.positions.len();
    let t_total = mesh.triangles.len();
    // Base mesh: survivors in ascending id.
    let mut dec2enc: Vec<u32> = (0..n as u32).filter(|&v| s.alive[v as usize]).collect();
    let mut enc2dec = vec![NONE; n];
    for (d, &e) in dec2enc.iter().enumerate() {
        enc2dec[e as usize] = d as u32;
    }
    let base_triangles: Vec<[u32; 3]> = s
        .table
        .vertex
        .chunks_exact(3)
        .filter(|t| t[0] != NONE)
        .map(|t| {
            [
                enc2dec[t[0] as usize],
                enc2dec[t[1] as usize],
                enc2dec[t[2] as usize],
            ]
        })
        .collect();
    let mut fan = Fan::default();
    let base_deficits: Vec<u8> = dec2enc
        .iter()
        .map(|&e| {
            let sv = s.split_valence[e as usize];
            if sv == NO_SPLIT {
                return LEAF;
            }
            s.table.fan(e, &mut fan);
            let valence = fan.corners.len() + if fan.boundary { 2 } else { 0 };
            (sv as usize).saturating_sub(valence) as u8
        })
        .collect();
    let (v0, t0) = (dec2enc.len(), base_triangles.len());
    let mut memory = Memory::new(n, t_total, v0, t0);
    let mut state = memory.state(mesh.bits, params.schedule);
    let base_positions: Vec<[u32; 3]> = dec2enc.iter().map(|&e| s.positions[e as usize]).collect();
    {
        let (positions, corners, deficits) = state.base_arrays();
        positions[..v0].copy_from_slice(&base_positions);
        for (i, t) in base_triangles.iter().enumerate() {
            corners[3 * i..3 * i + 3].copy_from_slice(t);
        }
        deficits[..v0].copy_from_slice(&base_deficits);
    }
    state
        .finish_base(v0 as u32, t0 as u32)
        .map_err(|e| ReplayError(format!("base mesh rejected by the decoder: {e}")))?;
    // Under `every-vertex` the seed codes no deficits (SPEC §6.3, 3.6).
    let seed_deficits: &[u8] = match params.schedule {
        Schedule::SplitValences => &base_deficits,
        Schedule::EveryVertex => &[],
    };
    let seed = SeedPayload::new(&base_positions, &base_triangles, seed_deficits);
    let mut current = vec![NONE; n];
    let mut flagged = Vec::new();
    let mut wings = Vec::new();
    let mut ring = Ring::default();
    // A level's residuals are coded under the six plane policies on one
    // thread while the level replays; choosing the policy and framing the
    // level run on another while the next level replays (same bytes: the
    // replay itself is sequential).
    let seed_ref = &seed;
    let done = std::thread::scope(|scope| -> LevelsAndHash {
        let mut choosing = Vec::with_capacity(plan.rounds.len());
        let mut input_sorted = None;
        for (l, steps) in plan.rounds.iter().enumerate() {
            // SPEC §6.1 (3.10): the split-history bits start each level at
            // 0. (The replay's own rounds are its triangle count's check.)
            state.start_level(u32::MAX);
            if l + 1 == plan.rounds.len() {
                // The input's side of the exactness check needs nothing
                // from the replay: it is sorted beside the last level,
                // whose replay leaves the other core mostly idle once the
                // level's policies are chosen.
                input_sorted = Some(scope.spawn(|| sorted_canonical(&mesh.triangles, None)));
            }
            let mut subs = vec![SubstreamWriter::default(); 7];
            // Under `every-vertex` no split valences are coded, and the
            // level header says `plain` (SPEC §5.1, 3.6).
            let mut deficit_coding = DeficitCoding::new(match params.schedule {
                Schedule::SplitValences => deficit_contexts,
                Schedule::EveryVertex => Some(DeficitContexts::Plain),
            });
            // The level's split geometry goes round by round to a thread
            // that codes the wings and computes the residual vectors, and
            // they on to a thread that codes them under every plane policy.
            let (batches, coded_batches) = mpsc::channel();
            let splits = steps.iter().map(|&k| s.steps[k].len()).sum();
            let mut flag_coding = FlagCoding::new(params, deficit_contexts);
            // A large level whose records may be read positions first
            // chooses its record order on its first eighth, with the
            // residuals' cost so far from their coder.
            // (Forced, it has no order to weigh, and the coder no cost to
            // send.)
            let weighed = try_positions_first && records != Some(RecordOrder::PositionsFirst);
            let (early_cost, edge_cost) = weighed.then(mpsc::channel).unzip();
            let positions_first = try_positions_first.then(|| {
                let order = EarlyOrder {
                    edge_cost,
                    forced_ties,
                };
                (PositionsFirstCoding::default(), order)
            });
            let coder = scope
                .spawn(move || code_policies(coded_batches, params, plane, splits, early_cost));
            let (geometry_batches, geometry_in) = geometry_channels();
            let heights = plane.is_none_or(|p| p == PlanePolicy::Height);
            let wing_coding = WingCoding::new(wing_policy);
            let geometry_coder = scope.spawn(move || {
                code_geometry(
                    geometry_in,
                    batches,
                    wing_coding,
                    positions_first,
                    params,
                    splits,
                    heights,
                )
            });
            let mut geometry = GeometryBatch::new();
            let mut round_splits = Vec::with_capacity(steps.len());
            // A large level chooses its deficit contexts after the round
            // that completes its first eighth, as it chooses its plane and
            // wing policies (`policies::EARLY_CHOICE_SPLITS`); the symbols
            // after it are written in the chosen contexts only.
            let (mut early, mut seen) = (early_choice_at(splits), 0);
            for &k in steps {
                let collapses = &s.steps[k];
                flagged.clear();
                wings.clear();
                let dec = |enc: u32| {
                    if enc == NONE {
                        NONE
                    } else {
                        enc2dec[enc as usize]
                    }
                };
                for (i, col) in collapses.iter().enumerate() {
                    let r = enc2dec[col.p as usize];
                    current[r as usize] = i as u32;
                    flagged.push(r);
                    wings.push([dec(col.wing_a), dec(col.wing_b)]);
                }
                let mut source = StepSource {
                    collapses,
                    wings: &wings,
                    flags: &mut flag_coding,
                    current: &mut current,
                    enc2dec: &mut enc2dec,
                    dec2enc: &mut dec2enc,
                    deficit_coding: &mut deficit_coding,
                    geometry: &mut geometry,
                    geometry_out: &geometry_batches,
                    pending: None,
                    swapped: false,
                    problem: None,
                };
                let result = state.run_round(collapses.len() as u32, &mut source, &mut ring);
                if let Err(e) = result {
                    let why = source.problem.take().unwrap_or_else(|| e.to_string());
                    return Err(ReplayError(format!("step {k}: {why}")));
                }
                for &r in &flagged {
                    current[r as usize] = NONE;
                }
                round_splits.push(collapses.len() as u32);
                seen += collapses.len();
                if early.is_some_and(|at| seen >= at) {
                    early = None;
                    deficit_coding.choose_early(params);
                }
            }
            let (vertex_count, triangle_count) = (state.vertex_count(), state.triangle_count());
            let geometric_error = plan.errors[l];
            geometry_batches.send(&mut geometry);
            drop(geometry_batches);
            choosing.push(scope.spawn(move || {
                let level_error = |why: String| ReplayError(format!("level {l}: {why}"));
                let LevelGeometry {
                    wings: wing_coding,
                    placement,
                    positions_first,
                } = geometry_coder
                    .join()
                    .expect("coding the split geometry does not panic")
                    .map_err(level_error)?;
                if mode == PositionMode::Constrained {
                    subs[slot(substream::PLACEMENT)] = placement;
                }
                let residuals = coder
                    .join()
                    .expect("coding residuals does not panic")
                    .map_err(level_error)?;
                let plane = choose_policy(&mut subs, residuals, params, plane)
                    .map_err(|why| level_error(why.to_string()))?;
                let wings = wing_coding.choose(&mut subs, params);
                let deficits = deficit_coding.choose(&mut subs, params);
                let flag_contexts = flag_coding.choose(&mut subs);
                // Byte 10: the deficit contexts, or under `every-vertex`
                // (which codes no split valences) the flags' (SPEC §5.1).
                let deficits = match params.schedule {
                    Schedule::SplitValences => deficits,
                    Schedule::EveryVertex => flag_contexts,
                };
                let (plane, wings, records, ties) =
                    choose_record_order(&mut subs, positions_first, params, records, forced_ties)
                        .unwrap_or((plane, wings, RecordOrder::WingsFirst, Ties::Ring));
                let level = LevelPayload {
                    round_splits,
                    plane,
                    wings,
                    deficits,
                    records,
                    ties,
                    substreams: subs,
                    vertex_count,
                    triangle_count,
                    geometric_error,
                };
                // The level's chunks are coded in parallel (same bytes).
                let parallel = |n: usize, job: &(dyn Fn(usize) -> Chunk + Sync)| {
                    (0..n).into_par_iter().map(job).collect()
                };
                let framed =
                    frame_level_with(&level, (l == 0).then_some(seed_ref), params, &parallel);
                Ok((level, framed))
            }));
        }
        // The replay is over: check it (and hash it, if asked) while the last levels
        // are still being chosen and framed.
        let input_sorted =
            input_sorted.map(|h| h.join().expect("sorting triangles does not panic"));
        let (checked, hash) = rayon::join(
            || check_exact(mesh, &state, &dec2enc, input_sorted),
            || final_hash.then(|| state.state_hash()),
        );
        let checked = checked.map(|()| hash);
        let levels = choosing
            .into_iter()
            .map(|h| h.join().expect("choosing a plane policy does not panic"))
            .collect::<Result<Vec<_>, _>>()?;
        Ok((levels, checked?))
    })?;
    let (done, final_hash) = done;
    let (levels, framed) = done.into_iter().unzip();
    Ok(Replayed {
        seed,
        levels,
        framed,
        permutation: dec2enc,
        final_hash,
    })
}

/// Whether a level may read its records positions first (SPEC §5.1, 3.7):
/// constrained mode, and neither a plane policy other than `height` nor a
/// wing policy other than `ranks` (its escapes') forced.
pub fn positions_first_allowed(
    mode: PositionMode,
    plane: Option<PlanePolicy>,
    wings: Option<WingPolicy>,
) -> bool {
    mode == PositionMode::Constrained
        && plane.is_none_or(|p| p == PlanePolicy::Height)
        && wings.is_none_or(|w| w == WingPolicy::Ranks)
}

/// The positions-first records of a level when they are forced, or when
/// their four substreams code smaller than the wings-first ones already in
/// `subs`: they replace those, and the level's plane and wing policies,
/// record order and tie rule are returned. `None` keeps the wings-first
/// records.
fn choose_record_order(
    subs: &mut [SubstreamWriter],
    positions_first: Option<PositionsFirstCoding>,
    params: &StreamParams,
    forced: Option<RecordOrder>,
    forced_ties: Option<Ties>,
) -> Option<(PlanePolicy, WingPolicy, RecordOrder, Ties)> {
    let mut pf = positions_first?;
    // A large level that chose positions first on its first eighth
    // (`geometry::code_geometry`) wrote no wings-first records after it,
    // and where it chose its tie rule too, no other rule's wings.
    let ties = if let Some(ties) = pf.kept_ties() {
        ties
    } else if forced == Some(RecordOrder::PositionsFirst) || pf.chosen {
        forced_ties.unwrap_or_else(|| pf.cost(params).1)
    } else {
        // The eight substreams are costed in parallel: after the last
        // level's replay this is on the emission's critical path. The
        // wings-first ones were costed as their policies were chosen:
        // their plans give their lengths again.
        let ranking = ranking_params(params);
        let ids = [
            substream::WING_OFFSET,
            substream::WING_DISTANCE,
            substream::EDGE,
            substream::PLACEMENT,
        ];
        let held = &mut *subs;
        let (wings_first, positions_first) = rayon::join(
            || {
                held.par_iter_mut()
                    .enumerate()
                    .map(|(i, sub)| (substream::FLAGS + i as u8, sub))
                    .filter(|(id, _)| ids.contains(id))
                    .map(|(id, sub)| {
                        coded_len_under(
                            sub,
                            id,
                            DeficitContexts::Plain,
                            RecordOrder::WingsFirst,
                            &ranking,
                        )
                    })
                    .sum::<usize>()
            },
            || match forced_ties {
                Some(ties) => (pf.cost_under(params, ties), ties),
                None => pf.cost(params),
            },
        );
        let (positions_first, ties) = positions_first;
        if positions_first >= wings_first {
            return None;
        }
        ties
    };
    pf.install(ties, subs);
    Some((
        PlanePolicy::Height,
        WingPolicy::Ranks,
        RecordOrder::PositionsFirst,
        ties,
    ))
}

/// decode(encode(M)) == M: the refined state, mapped back to input ids, has
/// exactly the input's oriented triangles and quantized positions.
/// `input_sorted` is [`sorted_canonical`] of the input's triangles when
/// the caller already has it.
fn check_exact(
    mesh: &QuantizedMesh,
    state: &MeshState<'_>,
    dec2enc: &[u32],
    input_sorted: Option<Vec<[u32; 3]>>,
) -> Result<(), ReplayError> {
    if state.vertex_count() as usize != mesh.positions.len() {
        return Err(ReplayError(format!(
            "replay ended with {} vertices, the input has {}",
            state.vertex_count(),
            mesh.positions.len()
        )));
    }
    for (d, &e) in dec2enc.iter().enumerate() {
        if state.positions()[d] != mesh.positions[e as usize] {
            return Err(ReplayError(format!(
                "vertex {e} decodes to another position"
            )));
        }
    }
    let (decoded, input) = rayon::join(
        || sorted_canonical(state.triangles(), Some(dec2enc)),
        || input_sorted.unwrap_or_else(|| sorted_canonical(&mesh.triangles, None)),
    );
    if decoded != input {
        return Err(ReplayError(
            "decoded triangles differ from the input".into(),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The warm-up hint must name exactly the candidates `flag` then flags,
    /// with decoder and encoder ids apart (a hint read through the wrong
    /// map still decodes the same, but warms the fans of other vertices).
    #[test]
    fn likely_flags_are_the_flags() {
        let n = 8usize;
        // Decoder id d is encoder id 7 - d.
        let mut dec2enc: Vec<u32> = (0..n as u32).rev().collect();
        let mut enc2dec: Vec<u32> = (0..n as u32).rev().collect();
        // Decoder ids 1, 2 and 6 collapse in this step.
        let mut current = vec![NONE; n];
        for (i, d) in [1usize, 2, 6].into_iter().enumerate() {
            current[d] = i as u32;
        }
        let split_valences = StreamParams {
            schedule: Schedule::SplitValences,
            ..StreamParams::default()
        };
        let mut flags = FlagCoding::new(&split_valences, None);
        let mut deficit_coding = DeficitCoding::new(None);
        let mut geometry = GeometryBatch::default();
        let (geometry_out, _geometry_in) = geometry_channels();
        let mut source = StepSource {
            collapses: &[],
            wings: &[],
            current: &mut current,
            enc2dec: &mut enc2dec,
            dec2enc: &mut dec2enc,
            flags: &mut flags,
            deficit_coding: &mut deficit_coding,
            geometry: &mut geometry,
            geometry_out: &geometry_out,
            pending: None,
            swapped: false,
            problem: None,
        };
        let mut memory = Memory::new(n, 8, 4, 4);
        let state = memory.state(8, Schedule::SplitValences);
        let upcoming: Vec<u32> = (0..n as u32).collect();
        let likely = source.likely_flags(&state, &upcoming);
        for (i, &v) in upcoming.iter().enumerate() {
            let flagged = source.flag(&state, v).unwrap();
            assert_eq!(likely >> i & 1 == 1, flagged, "decoder id {v}");
        }
        assert_eq!(likely, 0b0100_0110);
    }
}
