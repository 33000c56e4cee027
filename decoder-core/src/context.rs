//! The contexts of the rANS codec (SPEC §5.5.5): which frequency table each
//! value is coded with, from what the decoder already knows. Encoders call
//! the same functions, so both sides agree by construction.

use crate::header::Schedule;
use crate::limits::{LEAF, substream};
use crate::positions_first::RecordOrder;
use crate::predict::{ArcMeans, PlanePolicy, placement_context};

/// A level's contexts (SPEC §5.1, level header byte 10, `contexts`):
/// under the schedule `split-valences` which contexts deficit-p and
/// deficit-c use (format 3.3); under `every-vertex`, which code no
/// split-valence symbols, which contexts the flags use (`Plain`, byte 0:
/// by valence; `SplitHistory`, byte 2, format 3.10).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DeficitContexts {
    /// Formats 3.0 to 3.2: deficit-p in one context, deficit-c by whether P
    /// is a leaf and by C's valence up to 6.
    #[default]
    Plain,
    /// 3.3: each of P and C by its own valence right after the split, 4 (or
    /// less) to 8 (or more); deficit-c also by whether P is a leaf. A split
    /// valence is at least the valence, and it mostly settles near the
    /// larger of the valence and 7, so the valence shapes its distribution.
    Valence,
    /// 3.10, `every-vertex` only (named `split-history`): the flags in 8
    /// contexts, by the vertex's valence (5 or less … 8 or more) and its
    /// split-history bit (whether it has split in this level, SPEC §6.1).
    /// A vertex that has split in a level splits again in it with other
    /// odds than one of the same valence that has not.
    SplitHistory,
}

impl DeficitContexts {
    /// Every choice, in byte order.
    pub const ALL: [DeficitContexts; 3] = [
        DeficitContexts::Plain,
        DeficitContexts::Valence,
        DeficitContexts::SplitHistory,
    ];

    pub fn from_byte(b: u8) -> Option<DeficitContexts> {
        DeficitContexts::ALL.get(b as usize).copied()
    }

    pub fn to_byte(self) -> u8 {
        self as u8
    }

    /// The name `splitstream info` and the SPEC use.
    pub fn name(self) -> &'static str {
        match self {
            DeficitContexts::Plain => "plain",
            DeficitContexts::Valence => "valence",
            DeficitContexts::SplitHistory => "split-history",
        }
    }

    /// Whether a level of a stream with schedule `schedule` may declare
    /// these contexts (SPEC §5.1): `valence` under `split-valences` only,
    /// `split-history` under `every-vertex` only.
    pub fn allowed_under(self, schedule: Schedule) -> bool {
        match self {
            DeficitContexts::Plain => true,
            DeficitContexts::Valence => schedule == Schedule::SplitValences,
            DeficitContexts::SplitHistory => schedule == Schedule::EveryVertex,
        }
    }
}

/// Number of contexts (frequency tables per rANS chunk) of substream `id`
/// in a level whose deficit contexts are `deficits` and record order
/// `records`, in a stream of schedule `schedule` (SPEC §5.3, §5.5.5).
pub fn count(id: u8, deficits: DeficitContexts, records: RecordOrder, schedule: Schedule) -> usize {
    if records == RecordOrder::PositionsFirst {
        // 3.7: the lattice rank's contexts after the axes', the kind and
        // the midpoint offset after the placement codes'.
        match id {
            substream::EDGE => return 8,
            substream::PLACEMENT => return 7,
            _ => {}
        }
    }
    match (id, deficits, schedule) {
        (substream::FLAGS, DeficitContexts::SplitHistory, Schedule::EveryVertex) => {
            SPLIT_HISTORY_FLAG_CONTEXTS
        }
        (substream::FLAGS, _, Schedule::EveryVertex) => FLAG_CONTEXTS,
        (substream::DEFICIT_P, DeficitContexts::Valence, _) => 5,
        (substream::DEFICIT_C, DeficitContexts::Valence, _) => 6,
        _ => substream::CONTEXTS.get(id as usize).copied().unwrap_or(0) as usize,
    }
}

/// Contexts of the flags under the schedule `every-vertex` (SPEC §5.5.5).
pub const FLAG_CONTEXTS: usize = 5;

/// Contexts of the flags under `every-vertex` with the contexts
/// `split-history` (SPEC §5.5.5, 3.10).
pub const SPLIT_HISTORY_FLAG_CONTEXTS: usize = 8;

/// The flag of a vertex whose state byte is `byte` and whose split-history
/// bit is `split` (SPEC §5.5.5, §7.3), in a level with contexts `contexts`:
/// under `every-vertex` the byte is the vertex's valence (capped at 255),
/// and the context its valence 4 (or less) … 8 (or more) as 0..=4, or
/// under `split-history` its valence 5 (or less) … 8 (or more) as 0..=3,
/// plus 4 when it has split in this level; under `split-valences`, 0.
#[inline]
pub fn flag(schedule: Schedule, contexts: DeficitContexts, byte: u8, split: bool) -> u8 {
    match (schedule, contexts) {
        (Schedule::SplitValences, _) => SINGLE,
        (Schedule::EveryVertex, DeficitContexts::SplitHistory) => {
            byte.clamp(5, 8) - 5 + 4 * u8::from(split)
        }
        (Schedule::EveryVertex, _) => byte.clamp(4, 8) - 4,
    }
}

/// P's split valence: under `valence`, P's valence 4 (or less) … 8 (or
/// more) right after the split as 0..=4; under `plain`, 0.
#[inline]
pub fn deficit_p(deficits: DeficitContexts, valence_p: usize) -> u8 {
    match deficits {
        DeficitContexts::Valence => (valence_p.clamp(4, 8) - 4) as u8,
        _ => SINGLE,
    }
}

/// Wing offset and wing distance, by the number `m` of ring entries that
/// may be wings (SPEC §7.4): 2 or fewer, 3, …, 8, then 9 and more.
#[inline]
pub fn wing(eligible: usize) -> u8 {
    (eligible.clamp(2, 9) - 2) as u8
}

/// C's split valence, by P's deficit and C's valence right after the split.
/// Under `plain`: 4 when P is a leaf, otherwise C's valence 3 (or less), 4,
/// 5, or 6 and more as 0..=3. Under `valence`: 0 when P is a leaf,
/// otherwise C's valence 4 (or less) … 8 (or more) as 1..=5.
#[inline]
pub fn deficit_c(deficits: DeficitContexts, deficit_p: u8, valence_c: usize) -> u8 {
    match (deficits, deficit_p == LEAF) {
        (DeficitContexts::Valence, true) => 0,
        (DeficitContexts::Valence, false) => (valence_c.clamp(4, 8) - 3) as u8,
        // `split-history` is `every-vertex`'s, which codes no split
        // valences: `plain`'s contexts, never used.
        (_, true) => 4,
        (_, false) => (valence_c.clamp(3, 6) - 3) as u8,
    }
}

/// Constrained mode's placement code, by where R lies between the two arcs
/// (SPEC §7.4): 0..=4.
#[inline]
pub fn placement(means: &ArcMeans) -> u8 {
    placement_context(means)
}

/// Position residuals: under the `dominant` plane policy 1 for the
/// predicted axis and 0 for the two others; otherwise the axis (0 x, 1 y,
/// 2 z).
#[inline]
pub fn residual(policy: PlanePolicy, axis: usize, predicted: Option<usize>) -> u8 {
    match policy {
        PlanePolicy::Dominant => (predicted == Some(axis)) as u8,
        _ => axis as u8,
    }
}

/// Seed positions: the axis (0 x, 1 y, 2 z).
#[inline]
pub fn axis(k: usize) -> u8 {
    k as u8
}

/// Every other value: its substream's single table.
pub const SINGLE: u8 = 0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::rans::MAX_CONTEXTS;

    /// Every context a deficit can get is one of its substream's tables
    /// (SPEC §5.5.5), for every valence a ring allows and both leafnesses.
    #[test]
    fn deficit_contexts_stay_below_the_table_count() {
        let split_valences = DeficitContexts::ALL
            .into_iter()
            .filter(|set| set.allowed_under(Schedule::SplitValences));
        for set in split_valences {
            let (p_tables, c_tables) = (
                count(
                    substream::DEFICIT_P,
                    set,
                    RecordOrder::WingsFirst,
                    Schedule::SplitValences,
                ),
                count(
                    substream::DEFICIT_C,
                    set,
                    RecordOrder::WingsFirst,
                    Schedule::SplitValences,
                ),
            );
            assert!(p_tables <= MAX_CONTEXTS && c_tables <= MAX_CONTEXTS);
            let mut p_seen = [false; MAX_CONTEXTS];
            let mut c_seen = [false; MAX_CONTEXTS];
            for valence in 2..=257 {
                let p = deficit_p(set, valence) as usize;
                assert!(p < p_tables, "{set:?} P valence {valence}");
                p_seen[p] = true;
                for deficit_p in [0, 1, 7, LEAF] {
                    let c = deficit_c(set, deficit_p, valence) as usize;
                    assert!(c < c_tables, "{set:?} C valence {valence}");
                    c_seen[c] = true;
                }
            }
            // And every table is used by some split.
            assert!(p_seen[..p_tables].iter().all(|&s| s), "{set:?}");
            assert!(c_seen[..c_tables].iter().all(|&s| s), "{set:?}");
        }
    }

    #[test]
    fn deficit_context_bytes_round_trip_and_reserve_the_rest() {
        for set in DeficitContexts::ALL {
            assert_eq!(DeficitContexts::from_byte(set.to_byte()), Some(set));
        }
        assert_eq!(
            DeficitContexts::from_byte(2),
            Some(DeficitContexts::SplitHistory)
        );
        assert_eq!(DeficitContexts::from_byte(3), None);
        assert_eq!(DeficitContexts::from_byte(255), None);
    }

    /// Every context a flag can get is one of the flags' tables, and
    /// every table is used (SPEC §5.5.5), under every schedule and every
    /// contexts byte it allows.
    #[test]
    fn flag_contexts_stay_below_the_table_count_and_use_every_table() {
        for schedule in [Schedule::SplitValences, Schedule::EveryVertex] {
            for set in DeficitContexts::ALL {
                if !set.allowed_under(schedule) {
                    continue;
                }
                let tables = count(substream::FLAGS, set, RecordOrder::WingsFirst, schedule);
                assert!(tables <= MAX_CONTEXTS);
                let mut seen = [false; MAX_CONTEXTS];
                for byte in 0..=255u8 {
                    for split in [false, true] {
                        let c = flag(schedule, set, byte, split) as usize;
                        assert!(c < tables, "{schedule:?} {set:?} {byte} {split}");
                        seen[c] = true;
                    }
                }
                assert!(seen[..tables].iter().all(|&s| s), "{schedule:?} {set:?}");
            }
        }
    }
}
