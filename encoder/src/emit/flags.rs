//! The flag contexts of a level (SPEC §5.1, §5.5.5): under the schedule
//! `every-vertex` a level codes its flags by the vertex's valence
//! (`valence`, format 3.6, written as byte 0) or by its valence and its
//! split-history bit (`split-history`, 3.10, byte 2). The replay writes
//! every flag in the contexts of each choice still open, and the level
//! keeps the one whose flags code smaller.
//!
//! Only levels of fewer than [`EARLY_CHOICE_SPLITS`] splits weigh both:
//! three more tables can outweigh what the split-history bit saves on a
//! small level (the npm bunny's stream was 3 bytes larger with it), while on
//! every large level measured it saved 2 to 3 % of the flags
//! (encoder/BENCHMARKS.md), and pricing a large level's flags twice would
//! sit on the emission's critical path for its last level. A small level
//! is priced as it is written (adaptive tables included), not under the
//! ranking's static tables: the three tables are the difference there.

use splitstream_decoder_core::context;
use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::writer::{StreamParams, SubstreamWriter, coded_len_in};
use splitstream_decoder_core::{DeficitContexts, Schedule};

use super::policies::EARLY_CHOICE_SPLITS;

/// The choices, in the order of their bytes (ties go to the first, which
/// 3.9 decoders read).
const CHOICES: [DeficitContexts; 2] = [DeficitContexts::Plain, DeficitContexts::SplitHistory];

/// One level's flags in the contexts of every choice still open.
#[derive(Clone)]
pub struct FlagCoding {
    schedule: Schedule,
    /// Per choice of [`CHOICES`]: the flags, or `None` when ruled out.
    coded: [Option<SubstreamWriter>; 2],
}

impl FlagCoding {
    /// The flags of a level of `splits` splits in a stream of schedule
    /// `schedule`: under `split-valences` one context (SPEC §5.5.5); under
    /// `every-vertex` the contexts `forced` (`valence` for `Plain` or
    /// `Valence`), or by default `split-history`, weighed against
    /// `valence` on a small level.
    pub fn new(schedule: Schedule, forced: Option<DeficitContexts>, splits: usize) -> FlagCoding {
        let open = |c: DeficitContexts| match (schedule, forced) {
            (Schedule::SplitValences, _) => c == DeficitContexts::Plain,
            (Schedule::EveryVertex, Some(DeficitContexts::SplitHistory)) => {
                c == DeficitContexts::SplitHistory
            }
            (Schedule::EveryVertex, Some(_)) => c == DeficitContexts::Plain,
            (Schedule::EveryVertex, None) => {
                c == DeficitContexts::SplitHistory || splits < EARLY_CHOICE_SPLITS
            }
        };
        FlagCoding {
            schedule,
            coded: CHOICES.map(|c| open(c).then(SubstreamWriter::default)),
        }
    }

    /// Records the flag of a vertex whose state byte is `byte` and whose
    /// split-history bit is `split`, at the start of the round (SPEC §7.3).
    #[inline]
    pub fn write(&mut self, byte: u8, split: bool, flagged: bool) {
        for (contexts, coded) in CHOICES.into_iter().zip(&mut self.coded) {
            if let Some(sub) = coded {
                sub.bit_in(context::flag(self.schedule, contexts, byte, split), flagged);
            }
        }
    }

    /// Puts the cheaper choice's flags into `subs` (ids 1..=7 at 0..=6)
    /// and returns its contexts byte's meaning: `Plain` is `valence` under
    /// `every-vertex`.
    pub fn choose(self, subs: &mut [SubstreamWriter], params: &StreamParams) -> DeficitContexts {
        let single = self.coded.iter().filter(|c| c.is_some()).count() == 1;
        let cost = |sub: &SubstreamWriter, c: DeficitContexts| {
            if single {
                0
            } else {
                coded_len_in(sub, substream::FLAGS, c, params)
            }
        };
        let (contexts, flags) = CHOICES
            .into_iter()
            .zip(self.coded)
            .filter_map(|(c, sub)| sub.map(|s| (c, s)))
            .min_by_key(|(c, sub)| (cost(sub, *c), c.to_byte()))
            .expect("at least one choice of flag contexts");
        // Substream ids start at FLAGS: its slot is the first.
        subs[0] = flags;
        contexts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Flags that follow the split-history bit make `split-history` the
    /// cheaper choice once there are enough of them; a handful keep
    /// `valence`, whose five tables cost less than eight.
    #[test]
    fn the_choice_follows_the_cost() {
        let params = StreamParams {
            schedule: Schedule::EveryVertex,
            ..StreamParams::default()
        };
        let pick = |n: usize| {
            let mut coding = FlagCoding::new(Schedule::EveryVertex, None, n / 4);
            // Pseudo-random flags (a periodic pattern would deflate to
            // nothing, and the rANS codec keeps deflate where smaller).
            let mut x = 0x9e37_79b9u64;
            for _ in 0..n {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let (split, draw) = ((x >> 40).is_multiple_of(3), (x >> 20) % 32);
                // Split vertices rarely split again, the others half the time.
                let flagged = if split { draw == 0 } else { draw < 16 };
                coding.write(6, split, flagged);
            }
            let mut subs = vec![SubstreamWriter::default(); 7];
            coding.choose(&mut subs, &params)
        };
        assert_eq!(pick(6), DeficitContexts::Plain);
        assert_eq!(pick(6000), DeficitContexts::SplitHistory);
    }

    /// A large level takes `split-history` without weighing; forcing and
    /// the schedule `split-valences` leave one choice.
    #[test]
    fn large_levels_and_forced_choices_write_one_substream() {
        let open =
            |coding: &FlagCoding| coding.coded.iter().map(Option::is_some).collect::<Vec<_>>();
        let every = Schedule::EveryVertex;
        assert_eq!(
            open(&FlagCoding::new(every, None, EARLY_CHOICE_SPLITS)),
            [false, true]
        );
        assert_eq!(open(&FlagCoding::new(every, None, 10)), [true, true]);
        let valence = Some(DeficitContexts::Valence);
        assert_eq!(open(&FlagCoding::new(every, valence, 10)), [true, false]);
        let history = Some(DeficitContexts::SplitHistory);
        assert_eq!(open(&FlagCoding::new(every, history, 10)), [false, true]);
        let split_valences = Schedule::SplitValences;
        assert_eq!(
            open(&FlagCoding::new(split_valences, None, 10)),
            [true, false]
        );
    }
}
