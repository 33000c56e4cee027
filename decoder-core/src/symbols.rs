//! How a split record's connectivity fields are coded (SPEC §7.4): the
//! wings as ranks among the ring entries that may be wings, the deficits of
//! P and C as split valences.
//!
//! A ring entry that was a candidate (deficit 0) at the start of the round
//! can never be a wing: its deficit is still 0 when R splits, and a wing's
//! deficit drops by one (`valence-overflow`). So the wings are named among
//! the other entries (and the ghost), which makes both fields smaller. The
//! set is taken at the start of the round, not from the live deficits, so
//! that the splits of a round stay independent of their order (SPEC §7.2):
//! [`MeshState::run_round`] keeps a copy of the round's candidate bitmap.
//! Under the schedule `every-vertex` (format 3.6) no vertex has a split
//! valence, so every ring entry may be a wing ([`WingCandidates::all`]).

use crate::Error;
use crate::header::Schedule;
use crate::limits::{LEAF, MAX_SPLIT_VALENCE};
use crate::ring::Ring;
use crate::state::MeshState;

/// The ring positions that may be wings (SPEC §7.4), as a bit mask over
/// the ring (a ring has at most 255 entries).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WingCandidates {
    mask: [u64; 4],
    count: usize,
}

impl WingCandidates {
    /// The entries of a ring of at most 64 entries whose bits `mask` sets
    /// (unit tests).
    #[cfg(test)]
    pub(crate) fn from_first_mask(mask: u64) -> WingCandidates {
        WingCandidates {
            mask: [mask, 0, 0, 0],
            count: mask.count_ones() as usize,
        }
    }

    /// Every entry of a ring of `k` entries (at most 255): the eligible
    /// set under the schedule `every-vertex` (SPEC §7.4).
    pub fn all(k: usize) -> WingCandidates {
        let mut out = WingCandidates::default();
        let k = k.min(4 * 64);
        for (w, word) in out.mask.iter_mut().enumerate() {
            let bits = k.saturating_sub(64 * w).min(64);
            *word = crate::round::all_ones(bits);
        }
        out.count = k;
        out
    }

    /// `m`: the number of ring entries that may be wings.
    #[inline]
    pub fn count(&self) -> usize {
        self.count
    }

    /// Bits `64 w .. 64 w + 64` of the set: bit `i` says whether ring
    /// position `64 w + i` may be a wing (0 past the fourth word).
    #[inline]
    pub fn word(&self, w: usize) -> u64 {
        self.mask.get(w).copied().unwrap_or(0)
    }

    /// Whether ring position `i` may be a wing.
    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        self.mask
            .get(i / 64)
            .is_some_and(|w| w >> (i % 64) & 1 != 0)
    }

    /// The ring position of the `n`-th eligible entry (from 0), if any.
    #[inline]
    fn select(&self, mut n: usize) -> Option<usize> {
        for (k, &word) in self.mask.iter().enumerate() {
            let ones = word.count_ones() as usize;
            if n < ones {
                let mut w = word;
                for _ in 0..n {
                    w &= w - 1;
                }
                return Some(64 * k + w.trailing_zeros() as usize);
            }
            n -= ones;
        }
        None
    }

    /// Eligible entries at ring positions below `i`.
    fn rank(&self, i: usize) -> usize {
        let mut n = 0;
        for (k, &word) in self.mask.iter().enumerate() {
            if i >= 64 * (k + 1) {
                n += word.count_ones() as usize;
            } else {
                if i > 64 * k {
                    n += (word & ((1u64 << (i - 64 * k)) - 1)).count_ones() as usize;
                }
                break;
            }
        }
        n
    }

    /// The wings' ring offset and distance `(o, d)` named by the coded
    /// ranks `o'` and `d'` (SPEC §7.4): `a` is the `o'`-th eligible entry,
    /// `b` the `(o' + d')`-th. Fails with `ring-offset-out-of-range` when
    /// `d' = 0` or `o' + d' >= m`.
    #[inline]
    pub fn wings(&self, o_rank: u8, d_rank: u8) -> Result<(usize, usize), Error> {
        let (o_rank, d_rank) = (o_rank as usize, d_rank as usize);
        if d_rank == 0 || o_rank + d_rank >= self.count {
            return Err(Error::RingOffsetOutOfRange);
        }
        match (self.select(o_rank), self.select(o_rank + d_rank)) {
            (Some(a), Some(b)) => Ok((a, b - a)),
            _ => Err(Error::RingOffsetOutOfRange),
        }
    }

    /// The coded ranks `(o', d')` of the wings at ring positions `o` and
    /// `o + d` (encoder): `None` when one of them may not be a wing.
    pub fn ranks(&self, o: usize, d: usize) -> Option<(u8, u8)> {
        if d == 0 || !self.contains(o) || !self.contains(o + d) {
            return None;
        }
        let before_a = self.rank(o);
        let before_b = self.rank(o + d);
        Some((before_a as u8, (before_b - before_a) as u8))
    }
}

impl MeshState<'_> {
    /// The entries of `ring` that may be wings of a split in the current
    /// round (SPEC §7.4): the ghost, and every vertex that was not a
    /// candidate when the round started. Meaningful while a round runs
    /// (inside [`crate::RecordSource::record`]); between rounds every entry
    /// is eligible.
    #[inline]
    pub fn wing_candidates(&self, ring: &Ring) -> WingCandidates {
        if self.schedule == Schedule::EveryVertex {
            // 3.6: no split valence to overflow, every entry may be a wing.
            return WingCandidates::all(ring.len());
        }
        // The round-start copy of the candidate bitmap (SPEC §9, region 6).
        let third = self.candidates.len() / 3;
        let start = &self.candidates[third..2 * third];
        // 1 when `v` may be a wing. The ghost (NONE) is beyond every
        // bitmap: never a candidate. (The bitmap, a bit per vertex, is
        // denser in the cache than the deficits.)
        let eligible = |v: u32| -> u64 {
            start
                .get((v / 64) as usize)
                .map_or(1, |w| !(w >> (v % 64)) & 1)
        };
        let mut out = WingCandidates::default();
        let vertices = ring.vertices();
        if vertices.len() <= 64 {
            let mut bits = 0u64;
            for (i, &v) in vertices.iter().enumerate() {
                bits |= eligible(v) << i;
            }
            out.mask[0] = bits;
            out.count = bits.count_ones() as usize;
            return out;
        }
        for (word, entries) in out.mask.iter_mut().zip(vertices.chunks(64)) {
            let mut bits = 0u64;
            for (i, &v) in entries.iter().enumerate() {
                bits |= eligible(v) << i;
            }
            *word = bits;
            out.count += bits.count_ones() as usize;
        }
        out
    }
}

/// The deficit of a vertex whose valence right after the split is
/// `valence`, from its coded split-valence symbol (SPEC §7.4): 0 is a leaf,
/// any other symbol is the split valence minus 2, which must lie in
/// `valence ..= 255`; otherwise `valence-overflow`.
#[inline]
pub fn deficit_of(symbol: u8, valence: usize) -> Result<u8, Error> {
    if symbol == 0 {
        return Ok(LEAF);
    }
    let split_valence = symbol as usize + 2;
    if split_valence < valence || split_valence > MAX_SPLIT_VALENCE {
        return Err(Error::SplitValenceOutOfRange);
    }
    Ok((split_valence - valence) as u8)
}

/// The symbol that codes `deficit` for a vertex of valence `valence`
/// (encoder): 0 for a leaf, else `deficit + valence − 2`.
#[inline]
pub fn split_valence_symbol(deficit: u8, valence: usize) -> u8 {
    if deficit == LEAF {
        0
    } else {
        (deficit as usize + valence - 2).min(255) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidates(eligible: &[usize]) -> WingCandidates {
        let mut out = WingCandidates::default();
        for &i in eligible {
            out.mask[i / 64] |= 1 << (i % 64);
            out.count += 1;
        }
        out
    }

    #[test]
    fn ranks_and_wings_are_inverse() {
        let c = candidates(&[0, 2, 3, 7, 63, 64, 100, 200, 254]);
        for o in 0..255 {
            for d in 1..255 - o {
                if let Some((ro, rd)) = c.ranks(o, d) {
                    assert_eq!(c.wings(ro, rd), Ok((o, d)));
                }
            }
        }
        assert_eq!(c.ranks(1, 1), None);
        assert_eq!(c.wings(0, 0), Err(Error::RingOffsetOutOfRange));
        assert_eq!(c.wings(8, 1), Err(Error::RingOffsetOutOfRange));
        assert_eq!(c.wings(0, 8), Ok((0, 254)));
        assert_eq!(c.wings(255, 255), Err(Error::RingOffsetOutOfRange));
    }

    #[test]
    fn split_valence_symbols() {
        assert_eq!(deficit_of(0, 3), Ok(LEAF));
        assert_eq!(deficit_of(1, 3), Ok(0));
        assert_eq!(deficit_of(4, 3), Ok(3));
        assert_eq!(deficit_of(253, 3), Ok(252));
        assert_eq!(deficit_of(254, 3), Err(Error::SplitValenceOutOfRange));
        assert_eq!(deficit_of(255, 3), Err(Error::SplitValenceOutOfRange));
        assert_eq!(deficit_of(3, 6), Err(Error::SplitValenceOutOfRange));
        assert_eq!(deficit_of(4, 6), Ok(0));
        for valence in 3..=255 {
            for deficit in (0..=255 - valence as u8).chain([LEAF]) {
                let s = split_valence_symbol(deficit, valence);
                assert_eq!(deficit_of(s, valence), Ok(deficit));
            }
        }
    }
}
