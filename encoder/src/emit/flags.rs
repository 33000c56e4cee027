//! The flag contexts of a level (SPEC §5.1, §5.5.5): under the schedule
//! `every-vertex` a level codes its flags by the vertex's valence
//! (`valence`, format 3.6, written as byte 0) or by its valence and its
//! split-history bit (`split-history`, 3.10, byte 2). The replay writes
//! every flag in the contexts of each choice still open, and the level
//! keeps the one whose flags code smaller.
//!
//! A level writes its first [`PRICED_FLAGS`] flags both ways. A level with
//! no more keeps the choice whose flags code smaller; a larger one takes
//! `split-history` from there on, unpriced. Three more tables can outweigh
//! what the split-history bit saves on a small level (the npm bunny keeps
//! `valence` on four of its five levels), while every level of the scanned
//! meshes, the DEM and the 1M terrain takes `split-history` when priced
//! (2 to 3 % of the flags, encoder/BENCHMARKS.md). Pricing whole levels
//! made the 1M terrain's emission about 6 % slower (its level 0 has 68
//! rounds of flags for up to 63,058 vertices, coded twice more). Choosing
//! on a large level's first flags instead made its stream 0.4 % larger:
//! they are its first round's, where no vertex has split yet and the bit
//! tells nothing. A regular grid's finest level can do better without the
//! bit (the 160 × 160 grid vector's level 4 would be 95 bytes smaller under
//! `valence`); that is the price of not pricing. The flags are priced as
//! they are written (adaptive tables included), not under the ranking's
//! static tables: the tables are the difference on a small level.

use splitstream_decoder_core::context;
use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::writer::{StreamParams, SubstreamWriter, coded_len_in};
use splitstream_decoder_core::{DeficitContexts, Schedule};

/// How many of a level's flags are written in both contexts before a
/// larger level settles on `split-history` (see the module
/// documentation).
pub const PRICED_FLAGS: usize = 65_536;

/// The choices, in the order of their bytes (ties go to the first, which
/// 3.9 decoders read).
const CHOICES: [DeficitContexts; 2] = [DeficitContexts::Plain, DeficitContexts::SplitHistory];

/// One level's flags in the contexts of every choice still open.
#[derive(Clone)]
pub struct FlagCoding {
    schedule: Schedule,
    /// What the flags are priced under.
    params: StreamParams,
    /// Per choice of [`CHOICES`]: the flags, or `None` when ruled out.
    coded: [Option<SubstreamWriter>; 2],
    /// Flags written so far.
    written: usize,
}

impl FlagCoding {
    /// The flags of a level in a stream of schedule `schedule`: under
    /// `split-valences` one context (SPEC §5.5.5); under `every-vertex` the
    /// contexts `forced` (`valence` for `Plain` or `Valence`), or by
    /// default `split-history`, weighed against `valence` on a level of at
    /// most [`PRICED_FLAGS`] flags. `params` are the stream's: the flags
    /// are priced as they will be written.
    pub fn new(params: &StreamParams, forced: Option<DeficitContexts>) -> FlagCoding {
        let schedule = params.schedule;
        let open = |c: DeficitContexts| match (schedule, forced) {
            (Schedule::SplitValences, _) => c == DeficitContexts::Plain,
            (Schedule::EveryVertex, Some(DeficitContexts::SplitHistory)) => {
                c == DeficitContexts::SplitHistory
            }
            (Schedule::EveryVertex, Some(_)) => c == DeficitContexts::Plain,
            (Schedule::EveryVertex, None) => true,
        };
        FlagCoding {
            schedule,
            params: *params,
            coded: CHOICES.map(|c| open(c).then(SubstreamWriter::default)),
            written: 0,
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
        self.written += 1;
        if self.written == PRICED_FLAGS && self.coded.iter().all(Option::is_some) {
            // A large level: `split-history`, unpriced.
            self.coded[0] = None;
        }
    }

    /// The choice still open whose flags so far code smaller (`valence`
    /// on a tie, which 3.9 decoders read); their rANS plans are kept for
    /// framing (`coded_len_in`).
    fn cheaper(&mut self) -> DeficitContexts {
        let single = self.coded.iter().filter(|c| c.is_some()).count() == 1;
        let params = &self.params;
        let mut costs = [None; CHOICES.len()];
        for i in 0..CHOICES.len() {
            let (before, rest) = self.coded.split_at_mut(i);
            let Some(sub) = rest[0].as_mut() else {
                continue;
            };
            // Both choices hold the same bits: the deflate trial the first
            // coded to weigh deflate against its rANS chunks serves the
            // second too.
            for earlier in before.iter().flatten() {
                sub.share_deflate_trial(earlier);
            }
            let c = CHOICES[i];
            costs[i] = Some(if single {
                0
            } else {
                coded_len_in(sub, substream::FLAGS, c, params)
            });
        }
        CHOICES
            .into_iter()
            .zip(costs)
            .filter_map(|(c, cost)| Some(((cost?, c.to_byte()), c)))
            .min_by_key(|&(key, _)| key)
            .expect("at least one choice of flag contexts")
            .1
    }

    /// Puts the cheaper choice's flags into `subs` (ids 1..=7 at 0..=6)
    /// and returns its contexts byte's meaning: `Plain` is `valence` under
    /// `every-vertex`.
    pub fn choose(mut self, subs: &mut [SubstreamWriter]) -> DeficitContexts {
        let contexts = self.cheaper();
        let at = CHOICES
            .iter()
            .position(|&c| c == contexts)
            .expect("a choice");
        // Substream ids start at FLAGS: its slot is the first.
        subs[0] = self.coded[at].take().expect("the cheaper choice is open");
        contexts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn every_vertex() -> StreamParams {
        StreamParams {
            schedule: Schedule::EveryVertex,
            ..StreamParams::default()
        }
    }

    /// `n` pseudo-random flags (a periodic pattern would deflate to
    /// nothing, and the rANS codec keeps deflate where smaller): a third
    /// of the vertices have split, and `split_again` is the chance (of 32)
    /// that such a vertex splits again; the others split half the time.
    fn write_flags(coding: &mut FlagCoding, n: usize, split_again: u64) {
        let mut x = 0x9e37_79b9u64;
        for _ in 0..n {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let (split, draw) = ((x >> 40).is_multiple_of(3), (x >> 20) % 32);
            let flagged = if split { draw < split_again } else { draw < 16 };
            coding.write(6, split, flagged);
        }
    }

    /// Flags that follow the split-history bit make `split-history` the
    /// cheaper choice once there are enough of them; a handful keep
    /// `valence`, whose five tables cost less than eight.
    #[test]
    fn the_choice_follows_the_cost() {
        let pick = |n: usize| {
            let mut coding = FlagCoding::new(&every_vertex(), None);
            write_flags(&mut coding, n, 1);
            let mut subs = vec![SubstreamWriter::default(); 7];
            coding.choose(&mut subs)
        };
        assert_eq!(pick(6), DeficitContexts::Plain);
        assert_eq!(pick(6000), DeficitContexts::SplitHistory);
    }

    /// A level settles on `split-history` after its first
    /// [`PRICED_FLAGS`] flags, unpriced, even where the bit tells nothing
    /// (split vertices flagged as often as the others); forcing and the
    /// schedule `split-valences` leave one choice.
    #[test]
    fn large_levels_settle_and_forced_choices_write_one_substream() {
        let open =
            |coding: &FlagCoding| coding.coded.iter().map(Option::is_some).collect::<Vec<_>>();
        let mut large = FlagCoding::new(&every_vertex(), None);
        write_flags(&mut large, PRICED_FLAGS - 1, 1);
        assert_eq!(open(&large), [true, true]);
        write_flags(&mut large, 1, 1);
        assert_eq!(open(&large), [false, true]);
        let mut blind = FlagCoding::new(&every_vertex(), None);
        write_flags(&mut blind, PRICED_FLAGS, 16);
        assert_eq!(open(&blind), [false, true]);
        let valence = Some(DeficitContexts::Valence);
        assert_eq!(
            open(&FlagCoding::new(&every_vertex(), valence)),
            [true, false]
        );
        let history = Some(DeficitContexts::SplitHistory);
        assert_eq!(
            open(&FlagCoding::new(&every_vertex(), history)),
            [false, true]
        );
        let split_valences = StreamParams::default();
        assert_eq!(open(&FlagCoding::new(&split_valences, None)), [true, false]);
    }
}
