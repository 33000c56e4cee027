//! The wing policy of a level (SPEC §5.1, §7.4, format 3.2): the replay
//! writes each split's wings under every policy that may be chosen, and the
//! level keeps the policy whose two wing substreams code smallest.

use splitstream_decoder_core::limits::{MAX_SPLIT_VALENCE, substream};
use splitstream_decoder_core::wing_order::{NearKeys, near_keys, near_keys_both, near_ranks};
use splitstream_decoder_core::writer::{StreamParams, SubstreamWriter, coded_len};

use super::policies::ranking_params;
use splitstream_decoder_core::{Ring, WingCandidates, WingPolicy, context};

/// One level's wing ranks under every wing policy that may be chosen.
#[derive(Clone)]
pub struct WingCoding {
    /// Per policy of [`WingPolicy::ALL`]: the wing-offset and wing-distance
    /// values, or `None` when the policy is not a choice.
    coded: [Option<[SubstreamWriter; 2]>; 3],
    /// The current ring's keys under `near` and `near-xy`.
    keys: [NearKeys; 2],
}

impl WingCoding {
    /// Every policy, or only `forced`.
    pub fn new(forced: Option<WingPolicy>) -> WingCoding {
        let used = |p: WingPolicy| forced.is_none_or(|f| f == p);
        WingCoding {
            coded: WingPolicy::ALL.map(|p| used(p).then(Default::default)),
            keys: [[0; MAX_SPLIT_VALENCE]; 2],
        }
    }

    /// Records the wings at ring positions `o` and `o + d` of the split of
    /// `ring`, whose entries `eligible` may be wings (the round-start rule,
    /// `MeshState::wing_candidates`) and whose vertices have `positions`,
    /// under each policy; `false` when they are not both eligible.
    pub fn write(
        &mut self,
        positions: &[[u32; 3]],
        ring: &Ring,
        eligible: &WingCandidates,
        o: usize,
        d: usize,
    ) -> bool {
        let ctx = context::wing(eligible.count());
        let k = ring.len();
        // The near keys of both near policies in one pass over the ring.
        let [near, near_xy] = &mut self.keys;
        let m = match (&self.coded[1], &self.coded[2]) {
            (Some(_), Some(_)) => near_keys_both(positions, ring, eligible, near, near_xy),
            (Some(_), None) => near_keys(positions, ring, eligible, WingPolicy::Near, near),
            (None, Some(_)) => near_keys(positions, ring, eligible, WingPolicy::NearXy, near_xy),
            (None, None) => 0,
        };
        for (index, coded) in self.coded.iter_mut().enumerate() {
            let Some([offset, distance]) = coded else {
                continue;
            };
            let ranks = match index {
                0 => eligible.ranks(o, d),
                near => near_ranks(&self.keys[near - 1][..m], k, o, d),
            };
            let Some((first, second)) = ranks else {
                return false;
            };
            offset.byte_in(ctx, first);
            distance.byte_in(ctx, second);
        }
        true
    }

    /// Keeps only the policy whose wing substreams code smallest so far,
    /// ties to the earlier policy (a large level's early choice, see
    /// `policies::EARLY_CHOICE_SPLITS`): later splits are written under it
    /// alone. Returns what its two substreams cost so far.
    pub fn choose_early(&mut self, params: &StreamParams) -> Option<usize> {
        let ranking = ranking_params(params);
        let (cost, best) = (0..self.coded.len())
            .filter_map(|i| Some((cost(self.coded[i].as_mut()?, &ranking), i)))
            .min()?;
        for (i, coded) in self.coded.iter_mut().enumerate() {
            if i != best {
                *coded = None;
            }
        }
        Some(cost)
    }

    /// Puts the cheapest policy's wing substreams into `subs` (ids 1..=7 at
    /// 0..=6) and returns it; ties go to the earlier policy, so `ranks`
    /// (readable by 3.0 and 3.1 decoders) wins when nothing is gained.
    pub fn choose(self, subs: &mut [SubstreamWriter], params: &StreamParams) -> WingPolicy {
        let ranking = ranking_params(params);
        let single = self.coded.iter().filter(|c| c.is_some()).count() == 1;
        let (_, policy, [offset, distance]) = WingPolicy::ALL
            .into_iter()
            .zip(self.coded)
            .filter_map(|(p, c)| c.map(|c| (p, c)))
            .map(|(p, mut coded)| {
                let cost = if single {
                    0
                } else {
                    cost(&mut coded, &ranking)
                };
                ((cost, p.to_byte()), p, coded)
            })
            .min_by_key(|&(key, ..)| key)
            .expect("at least one wing policy is a choice");
        subs[(substream::WING_OFFSET - substream::FLAGS) as usize] = offset;
        subs[(substream::WING_DISTANCE - substream::FLAGS) as usize] = distance;
        policy
    }
}

/// Bytes a policy's wing-offset and wing-distance substreams take under the
/// ranking parameters (their rANS plans kept for framing, `coded_len`).
fn cost([offset, distance]: &mut [SubstreamWriter; 2], ranking: &StreamParams) -> usize {
    coded_len(offset, substream::WING_OFFSET, ranking)
        + coded_len(distance, substream::WING_DISTANCE, ranking)
}
