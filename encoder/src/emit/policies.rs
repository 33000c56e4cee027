//! A level's position residuals under every plane policy (SPEC §7.4), and
//! the choice of the cheapest.
//!
//! The replay records each split's residual vectors once, with the split's
//! plane normal and its height residuals (format 3.1); coding them under
//! the six policies runs on another thread, batch by batch while the replay
//! goes on, so that it stays off the replay's critical path. The values
//! written are the same as if each split had been coded six ways on the
//! spot.

use std::sync::mpsc::{Receiver, Sender};

use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::writer::{
    ChunkCodec, GrowingCodedLen, StreamParams, SubstreamWriter,
};
use splitstream_decoder_core::{DeficitContexts, Plane, PlanePolicy, PositionMode};

use rayon::prelude::*;

/// One split's residual vectors before a plane policy is applied, as the
/// replay computes them (`predict::residual`: 32-bit values).
#[derive(Clone, Copy, Debug)]
pub struct SplitResiduals {
    /// The split's shifted plane normal (`Plane::new(Dominant, …).normal`).
    pub normal: [i64; 3],
    /// The edge substream's vector.
    pub first: [i64; 3],
    /// Optimal mode's second vector (the placement substream); unused in
    /// constrained mode.
    pub second: [i64; 3],
    /// The z of `first` and `second` under the plane policy `height`
    /// (format 3.1): the vector's z less the surface prediction, or the
    /// linear residual's z where no wedge holds the point.
    pub height: [i64; 2],
    /// The collapse's vertex, for error messages.
    pub id: u32,
}

impl SplitResiduals {
    /// The residual vectors the policy codes: the linear residuals, with
    /// the height residuals' z under `height`.
    pub fn vectors(&self, policy: PlanePolicy) -> ([i64; 3], [i64; 3]) {
        match policy {
            PlanePolicy::Height => (
                [self.first[0], self.first[1], self.height[0]],
                [self.second[0], self.second[1], self.height[1]],
            ),
            _ => (self.first, self.second),
        }
    }
}

/// A level's residual substreams under one plane policy.
#[derive(Clone, Default)]
pub struct PolicyResiduals {
    pub edge: SubstreamWriter,
    /// Optimal mode's second vector (the placement substream).
    pub placement: SubstreamWriter,
    /// Every coded value fits in 32 bits.
    pub usable: bool,
    /// The costs of `edge` and `placement` under the ranking parameters
    /// ([`ranking_params`]), chunk by chunk as they fill up: the last
    /// level's choice, which follows its replay, then only costs the last
    /// chunks.
    costs: [GrowingCodedLen; 2],
}

impl PolicyResiduals {
    /// Costs the chunks that are complete; `optimal`: the placement
    /// substream holds residuals too.
    fn advance_costs(&mut self, optimal: bool, ranking: &StreamParams) {
        let [edge, placement] = &mut self.costs;
        edge.advance(&self.edge, substream::EDGE, DeficitContexts::Plain, ranking);
        if optimal {
            placement.advance(
                &self.placement,
                substream::PLACEMENT,
                DeficitContexts::Plain,
                ranking,
            );
        }
    }

    /// The substreams' cost under `ranking`, the parameters they were
    /// advanced under: `coded_len` of `edge`, plus that of `placement` in
    /// optimal mode.
    fn cost(&mut self, optimal: bool, ranking: &StreamParams) -> usize {
        let [edge, placement] = &self.costs;
        let edge = edge.finish(
            &mut self.edge,
            substream::EDGE,
            DeficitContexts::Plain,
            ranking,
        );
        let placement = if optimal {
            placement.finish(
                &mut self.placement,
                substream::PLACEMENT,
                DeficitContexts::Plain,
                ranking,
            )
        } else {
            0
        };
        edge + placement
    }
}

/// Levels of at least this many splits choose their plane policy, their
/// wing policy (`geometry.rs`) and their deficit contexts (`replay.rs`, after
/// the round that completes the eighth), on their first eighth
/// ([`early_choice_at`]) and code the rest under the chosen one only:
/// on the 1M terrain, forcing every policy instead of weighing them over
/// every split took the emission from 1.02 to 0.89 s, and on large levels
/// the first eighth (8,192 splits or more) ranks them as the whole level
/// does (on every level of the 1M and 4M demo terrains and of the
/// Jacksboro DEM, the choices and the streams stayed the same;
/// BENCHMARKS.md). Smaller levels,
/// where margins can be narrow and the work is small, weigh every split.
pub const EARLY_CHOICE_SPLITS: usize = 65_536;

/// After how many of its `splits` splits a level makes its early choice
/// (see [`EARLY_CHOICE_SPLITS`]), if it makes one.
pub fn early_choice_at(splits: usize) -> Option<usize> {
    (splits >= EARLY_CHOICE_SPLITS).then_some(splits / 8)
}

/// Codes the batches arriving on `batches` (a level's `splits` splits in
/// split order) under every policy, or only `forced`, and costs them for
/// [`choose_policy`] under `params`' ranking parameters as they grow;
/// returns the substreams in `PlanePolicy::ALL` order (unused policies stay
/// empty and unusable). A large level keeps only the cheapest policy once
/// its first eighth is coded ([`EARLY_CHOICE_SPLITS`]), and then sends
/// what its edge substream (and in optimal mode its placement substream)
/// costs so far on `early_cost`, for the level's early choice of its
/// record order (`geometry::code_geometry`): `usize::MAX` where no policy
/// is usable.
pub fn code_policies(
    batches: Receiver<Vec<SplitResiduals>>,
    params: &StreamParams,
    forced: Option<PlanePolicy>,
    splits: usize,
    early_cost: Option<Sender<usize>>,
) -> Result<Vec<PolicyResiduals>, String> {
    let optimal = params.position_mode == PositionMode::Optimal;
    let ranking = ranking_params(params);
    // Room for every value from the start: growing six policies' vectors
    // by doubling copied and faulted in about a quarter of the encoder's
    // fresh pages on the 1M terrain. A residual's varint is mostly 1 or 2
    // bytes.
    let writer = |used: bool, vectors: usize| {
        let values = if used { 3 * vectors * splits } else { 0 };
        SubstreamWriter::with_capacity(values, 2 * values)
    };
    let mut out: Vec<PolicyResiduals> = PlanePolicy::ALL
        .iter()
        .map(|&p| {
            let used = forced.is_none_or(|f| f == p);
            PolicyResiduals {
                usable: used,
                edge: writer(used, 1),
                placement: writer(used && optimal, 1),
                costs: Default::default(),
            }
        })
        .collect();
    // The policies still coded: all, or one once forced or chosen early.
    let mut only = forced;
    let mut early = early_choice_at(splits);
    let mut seen = 0;
    for batch in batches {
        for (policy, residuals) in PlanePolicy::ALL.iter().zip(out.iter_mut()) {
            if only.is_some_and(|f| f != *policy) {
                continue;
            }
            for split in &batch {
                let plane = Plane::with_normal(*policy, split.normal);
                let (first, second) = split.vectors(*policy);
                residuals.usable &= write_vector(&mut residuals.edge, &plane, first, split)?;
                if optimal {
                    residuals.usable &=
                        write_vector(&mut residuals.placement, &plane, second, split)?;
                }
            }
            // A forced or chosen policy is not weighed.
            if only.is_none() && residuals.usable {
                residuals.advance_costs(optimal, &ranking);
            }
        }
        seen += batch.len();
        if early.is_some_and(|at| seen >= at) {
            early = None;
            // The cheapest so far, ties to the earlier policy (as
            // `choose_policy`). Coded values fit in 32 bits by
            // construction (both additions wrap, SPEC §7.4), so the
            // policy kept stays usable.
            let mut kept_cost = None;
            if only.is_none() {
                let best = out
                    .iter_mut()
                    .enumerate()
                    .filter(|(_, r)| r.usable)
                    .map(|(i, r)| (r.cost(optimal, &ranking), i))
                    .min();
                if let Some((cost, best)) = best {
                    only = Some(PlanePolicy::ALL[best]);
                    kept_cost = Some(cost);
                    for (i, residuals) in out.iter_mut().enumerate() {
                        if i != best {
                            *residuals = PolicyResiduals::default();
                        }
                    }
                }
            } else if early_cost.is_some() {
                kept_cost = PlanePolicy::ALL
                    .iter()
                    .zip(&mut out)
                    .find(|(p, r)| only == Some(**p) && r.usable)
                    .map(|(_, r)| r.cost(optimal, &ranking));
            }
            if let Some(tell) = &early_cost {
                // Nobody listening (no record order to choose) is fine.
                let _ = tell.send(kept_cost.unwrap_or(usize::MAX));
            }
        }
    }
    Ok(out)
}

/// Writes residual vector `r` under `plane`, in the plane's order and
/// contexts; `Ok(false)` when a coded value does not fit in 32 bits.
fn write_vector(
    w: &mut SubstreamWriter,
    plane: &Plane,
    r: [i64; 3],
    split: &SplitResiduals,
) -> Result<bool, String> {
    let coded = plane.encode(r);
    if coded.iter().any(|&x| i32::try_from(x).is_err()) {
        return Ok(false);
    }
    // What the decoder will compute from the coded values is `r` by
    // construction: the predicted axis's offset depends only on the two
    // other axes, which encoding leaves as they are, and both additions wrap
    // modulo 2^32 (SPEC §7.4), so decoding adds back exactly what encoding
    // took off. Debug builds check it; the decode costs a division per
    // vector and policy.
    debug_assert!(
        r.iter().any(|&x| i32::try_from(x).is_err()) || plane.decode(coded) == r,
        "the residuals of {} do not decode to its positions",
        split.id
    );
    for axis in plane.order() {
        w.signed_in(plane.context(axis), coded[axis] as i32);
    }
    Ok(true)
}

/// The parameters a level's alternatives (plane and wing policies, deficit
/// contexts) are ranked under: under the rANS codec their rANS cost alone.
/// Framing may still deflate the chosen substreams where that is smaller,
/// but deflating every alternative (at level 10) took a third of the
/// replay on the 1M terrain and never changed the ranking on the real
/// meshes. Static tables only: with adaptive tables (format 3.9) priced
/// for every alternative, one run of the 1M terrain's emission took
/// 1.74 s against 1.2–1.3 s (once, on a noisy VM); framing still uses them
/// where they are smaller.
pub fn ranking_params(params: &StreamParams) -> StreamParams {
    match params.codec {
        ChunkCodec::Rans { lanes } => StreamParams {
            codec: ChunkCodec::RansAlways { lanes },
            adaptive_tables: false,
            ..*params
        },
        _ => *params,
    }
}

/// Puts the cheapest usable policy's residual substreams (or those of
/// `forced`) into `subs` (a level's substreams from id 1: ids 6 and 7; in
/// constrained mode id 7 holds the placement codes, which do not depend on
/// the policy, and is left alone) and returns that policy. Ties go to the
/// earlier policy of `PlanePolicy::ALL` (`off` first).
pub fn choose_policy(
    subs: &mut [SubstreamWriter],
    mut residuals: Vec<PolicyResiduals>,
    params: &StreamParams,
    forced: Option<PlanePolicy>,
) -> Result<PlanePolicy, String> {
    let optimal = params.position_mode == PositionMode::Optimal;
    let ranking = ranking_params(params);
    let params = &ranking;
    // A single usable policy (forced, or chosen early) is not weighed.
    let single = residuals.iter().filter(|r| r.usable).count() == 1;
    let cost = |(r, policy): (&mut PolicyResiduals, PlanePolicy)| {
        if forced.is_some_and(|f| f != policy) {
            return None;
        }
        r.usable.then(|| {
            if forced.is_some() || single {
                return 0;
            }
            r.cost(optimal, params)
        })
    };
    // Nothing to weigh is not sent to the thread pool: at the last level
    // the pool is busy with the exactness check, and this level's framing
    // waited about 40 ms behind it for the answer (1M terrain).
    let costs: Vec<Option<usize>> = if forced.is_some() || single {
        residuals
            .iter_mut()
            .zip(PlanePolicy::ALL)
            .map(cost)
            .collect()
    } else {
        residuals
            .par_iter_mut()
            .zip(PlanePolicy::ALL)
            .map(cost)
            .collect()
    };
    let best = (0..costs.len())
        .filter(|&i| costs[i].is_some())
        .min_by_key(|&i| (costs[i], i))
        .ok_or("a position residual does not fit in 32 bits under any plane policy")?;
    let chosen = residuals.into_iter().nth(best).expect("index of a policy");
    subs[(substream::EDGE - substream::FLAGS) as usize] = chosen.edge;
    if optimal {
        subs[(substream::PLACEMENT - substream::FLAGS) as usize] = chosen.placement;
    }
    Ok(PlanePolicy::ALL[best])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;

    fn batches(splits: &[SplitResiduals]) -> Receiver<Vec<SplitResiduals>> {
        let (tx, rx) = mpsc::channel();
        // Two batches: the coder must run on across them.
        let (a, b) = splits.split_at(splits.len() / 2);
        tx.send(a.to_vec()).unwrap();
        tx.send(b.to_vec()).unwrap();
        rx
    }

    fn splits() -> Vec<SplitResiduals> {
        (0..40)
            .map(|i| SplitResiduals {
                normal: [i % 5 - 2, 7, -(i % 3)],
                first: [i, -2 * i, 3],
                second: [1 - i, i % 4, -i],
                height: [i % 7 - 3, 2 - i],
                id: i as u32,
            })
            .collect()
    }

    #[test]
    fn every_policy_codes_what_coding_each_split_on_the_spot_gives() {
        let splits = splits();
        let params = StreamParams::default();
        assert_eq!(params.position_mode, PositionMode::Optimal);
        let coded = code_policies(batches(&splits), &params, None, splits.len(), None).unwrap();
        for (policy, residuals) in PlanePolicy::ALL.iter().zip(&coded) {
            assert!(residuals.usable);
            let (mut edge, mut placement) =
                (SubstreamWriter::default(), SubstreamWriter::default());
            for s in &splits {
                let plane = Plane::with_normal(*policy, s.normal);
                let (first, second) = s.vectors(*policy);
                for (w, r) in [(&mut edge, first), (&mut placement, second)] {
                    let c = plane.encode(r);
                    for axis in plane.order() {
                        w.signed_in(plane.context(axis), c[axis] as i32);
                    }
                }
            }
            assert_eq!(residuals.edge.as_bytes(), edge.as_bytes(), "{policy:?}");
            assert_eq!(residuals.edge.symbols(), edge.symbols(), "{policy:?}");
            assert_eq!(residuals.placement.as_bytes(), placement.as_bytes());
        }
    }

    /// The costs kept while the batches arrive are what costing the whole
    /// substreams gives (so the choice, and the stream, are the same).
    #[test]
    fn the_costs_kept_on_the_way_are_the_whole_costs() {
        use splitstream_decoder_core::writer::coded_len;
        for codec in [
            ChunkCodec::Rans { lanes: 4 },
            ChunkCodec::Deflate(10),
            ChunkCodec::Stored,
        ] {
            let params = StreamParams {
                codec,
                chunk_limit: 9,
                rans_chunk_limit: 7,
                ..StreamParams::default()
            };
            let ranking = ranking_params(&params);
            let splits = splits();
            let coded = code_policies(batches(&splits), &params, None, splits.len(), None).unwrap();
            for mut residuals in coded {
                let whole = coded_len(&mut residuals.edge.clone(), substream::EDGE, &ranking)
                    + coded_len(
                        &mut residuals.placement.clone(),
                        substream::PLACEMENT,
                        &ranking,
                    );
                assert_eq!(residuals.cost(true, &ranking), whole, "{codec:?}");
            }
        }
    }

    /// A level of `EARLY_CHOICE_SPLITS` splits or more keeps one policy
    /// after its first eighth, codes it as forcing it would, and on
    /// residuals whose statistics do not drift picks the policy the whole
    /// level would.
    #[test]
    fn a_large_level_keeps_its_early_choice() {
        use splitstream_decoder_core::writer::coded_len;
        let n = EARLY_CHOICE_SPLITS + 1000;
        // Residuals small along z after the plane's prediction for normals
        // facing z: `z` should win (and under `off` z costs its full size).
        let mut x = 0x9e37_79b9u64;
        let mut next = |m: i64| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 33) as i64 % (2 * m + 1)) - m
        };
        let splits: Vec<SplitResiduals> = (0..n)
            .map(|i| {
                let (a, b) = (next(60), next(60));
                SplitResiduals {
                    normal: [next(3), next(3), 4000],
                    first: [a, b, next(2) + 300],
                    second: [next(9), next(9), next(400)],
                    height: [next(50), next(50)],
                    id: i as u32,
                }
            })
            .collect();
        let params = StreamParams {
            position_mode: PositionMode::Constrained,
            ..StreamParams::default()
        };
        let ranking = ranking_params(&params);
        let send = |splits: &[SplitResiduals]| {
            let (tx, rx) = mpsc::channel();
            for batch in splits.chunks(4096) {
                tx.send(batch.to_vec()).unwrap();
            }
            rx
        };
        let early = code_policies(send(&splits), &params, None, n, None).unwrap();
        assert_eq!(early.iter().filter(|r| r.usable).count(), 1);
        let kept = early.iter().position(|r| r.usable).unwrap();
        // Every policy forced, over the whole level.
        let whole: Vec<(usize, Vec<u8>)> = PlanePolicy::ALL
            .iter()
            .map(|&p| {
                let coded = code_policies(send(&splits), &params, Some(p), n, None).unwrap();
                let mut r = coded.into_iter().find(|r| r.usable).unwrap();
                (
                    coded_len(&mut r.edge, substream::EDGE, &ranking),
                    r.edge.as_bytes().to_vec(),
                )
            })
            .collect();
        let best = (0..whole.len()).min_by_key(|&i| (whole[i].0, i)).unwrap();
        assert_eq!(
            kept,
            best,
            "costs {:?}",
            whole.iter().map(|w| w.0).collect::<Vec<_>>()
        );
        assert_eq!(early[kept].edge.as_bytes(), &whole[kept].1[..]);
        // choose_policy takes it without weighing it again.
        let mut subs = vec![SubstreamWriter::default(); 7];
        let chosen = choose_policy(&mut subs, early, &params, None).unwrap();
        assert_eq!(chosen, PlanePolicy::ALL[best]);
    }

    #[test]
    fn a_forced_policy_is_the_only_one_coded() {
        let forced = PlanePolicy::ALL[2];
        let params = StreamParams {
            position_mode: PositionMode::Constrained,
            ..StreamParams::default()
        };
        let coded = code_policies(batches(&splits()), &params, Some(forced), 40, None).unwrap();
        for (policy, residuals) in PlanePolicy::ALL.iter().zip(&coded) {
            assert_eq!(residuals.usable, *policy == forced);
            assert_eq!(residuals.edge.as_bytes().is_empty(), *policy != forced);
            // Constrained mode: the placement substream holds codes, not residuals.
            assert!(residuals.placement.as_bytes().is_empty());
        }
    }
}
