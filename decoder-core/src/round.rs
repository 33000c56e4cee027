//! One refinement round (SPEC §7.2, §7.3): find candidates, read one flag per
//! candidate, apply the flagged splits in ascending vertex order. The
//! round's candidate set is kept for its whole duration: it says which ring
//! entries may be wings (SPEC §7.4).
//!
//! The procedure is shared by the stream decoder and by the encoder, which
//! replays it to write streams that are correct by construction: both plug
//! in a [`RecordSource`].

use crate::Error;
use crate::limits::NONE;
use crate::ring::Ring;
use crate::split::{SplitOutcome, SplitRecord};
use crate::state::{MeshState, next};

/// Flagged vertices whose fans are warmed together (see `warm_fans`).
const WARM_BATCH: usize = 32;
/// Wedges walked per fan when warming: typical valences, not the maximum.
const WARM_STEPS: usize = 12;
/// Fans are warmed only from this vertex count on: a smaller state (about
/// 58 bytes a vertex, SPEC §9) stays in the caches, and walking its fans
/// twice costs more than it saves (measured on this project's meshes:
/// 17 % slower at 26k vertices, 4 % faster at 139k, 24 % at 1M).
const WARM_FROM_VERTICES: u32 = 1 << 16;

/// Where a round gets its flags and split records from.
pub trait RecordSource {
    /// The flag of candidate `v` (SPEC §7.3), asked in ascending order.
    fn flag(&mut self, state: &MeshState<'_>, v: u32) -> Result<bool, Error>;
    /// The record of the split of `r`, whose canonical ring is `ring` (SPEC §7.4).
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error>;
    /// Called after each applied split (the encoder tracks vertex identities).
    fn applied(&mut self, _r: u32, _c: u32, _outcome: &SplitOutcome) {}
    /// Which of `upcoming`, the next candidates whose flags will be read
    /// (in order, as if none of them blocked another), are likely to be
    /// flagged: bit i for `upcoming[i]` (at most 64). Only a hint for
    /// prefetching (a wrong hint costs speed, never correctness); the
    /// default says all of them.
    fn likely_flags(&mut self, _state: &MeshState<'_>, upcoming: &[u32]) -> u64 {
        all_ones(upcoming.len())
    }
}

/// The low `n` bits set (n at most 64).
#[inline]
pub fn all_ones(n: usize) -> u64 {
    if n >= 64 { u64::MAX } else { (1u64 << n) - 1 }
}

/// What one round did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RoundStats {
    pub candidates: u32,
    pub splits: u32,
    pub triangles_added: u32,
}

impl MeshState<'_> {
    /// Runs one round whose declared split count is `declared` (SPEC §7.3).
    ///
    /// SPEC §7.3 reads every flag before the first split. This does the same
    /// work in one pass, batch by batch of candidates: a batch's flags, then
    /// the batch's splits, then the next batch. That is the same result,
    /// because a round's splits are independent (§7.2): a split touches only
    /// its own ring, and every vertex of that ring is blocked (its flag is
    /// inferred), so the flags, rings and candidacy of the later candidates
    /// are what they were at the start of the round. It also reports the
    /// same error: a failing split stops the splits but not the flags, and
    /// the flag pass's own errors and the flag count come first. The gain is
    /// speed: each flagged fan is walked while it is still in the cache.
    pub fn run_round<S: RecordSource>(
        &mut self,
        declared: u32,
        source: &mut S,
        ring: &mut Ring,
    ) -> Result<RoundStats, Error> {
        let n = self.vertex_count;
        if n as u64 + declared as u64 > self.vertex_capacity() as u64 {
            return Err(Error::CapacityExceeded);
        }
        let words = (n as usize).div_ceil(64);
        // Step 1: the candidates are the vertices below n with deficit 0;
        // the bitmap is kept up to date by every split (SPEC §7.3). A copy
        // of it as it is now says which ring entries may be wings during
        // the round (SPEC §7.4, symbols.rs): splits change the live bitmap.
        let (candidates, round_start, _) = self.bitmaps();
        let words = words.min(candidates.len()).min(round_start.len());
        round_start[..words].copy_from_slice(&candidates[..words]);
        let mut stats = RoundStats {
            candidates: candidates[..words].iter().map(|w| w.count_ones()).sum(),
            ..RoundStats::default()
        };
        let result = self.flag_and_split(n, words, source, ring, &mut stats);
        let (_, round_start, blocked) = self.bitmaps();
        round_start[..words].fill(0);
        blocked[..words].fill(0);
        match result {
            Err(e) => Err(e),
            Ok(_) if stats.splits != declared => Err(Error::FlagCountMismatch { round: 0 }),
            Ok(Some(split_error)) => Err(split_error),
            Ok(None) => Ok(stats),
        }
    }

    /// Steps 2 and 3 of SPEC §7.3, fused (see [`MeshState::run_round`]).
    /// Returns a flag-pass error as `Err`, the first split error as
    /// `Ok(Some(_))`.
    fn flag_and_split<S: RecordSource>(
        &mut self,
        n: u32,
        words: usize,
        source: &mut S,
        ring: &mut Ring,
        stats: &mut RoundStats,
    ) -> Result<Option<Error>, Error> {
        let mut split_error = None;
        let mut batch = [0u32; WARM_BATCH];
        let warm_up = n >= WARM_FROM_VERTICES;
        for w in 0..words {
            // Candidates at round start: vertices below n with deficit 0.
            // Splits of this round only change the bits of blocked vertices
            // and of new vertices (n and above), so reading the word now is
            // reading it as it was at the start.
            let below_n = if (w + 1) * 64 <= n as usize {
                u64::MAX
            } else {
                (1u64 << (n as usize - w * 64)) - 1
            };
            let mut bits = self.bitmaps().0[w] & !self.bitmaps().2[w] & below_n;
            while bits != 0 {
                let mut len = 0;
                while bits != 0 && len < WARM_BATCH {
                    batch[len] = (w * 64) as u32 + bits.trailing_zeros();
                    bits &= bits - 1;
                    len += 1;
                }
                // Warm the fans of the batch's candidates that the next
                // flags say will be flagged, together, so that their fan
                // walks hit the cache instead of waiting for one miss after
                // another. (Where the flags are not known yet, every
                // candidate's fan is warmed.)
                if warm_up {
                    self.warm_batch(&batch[..len], w, source);
                }
                for &v in &batch[..len] {
                    if self.bitmaps().2[w] & (1u64 << (v % 64)) != 0 {
                        continue;
                    }
                    if !source.flag(self, v)? {
                        continue;
                    }
                    stats.splits += 1;
                    // The ring is the one at round start (no neighbour of v
                    // has split: they would have blocked v). Its vertices'
                    // flags are inferred from now on (SPEC §7.2).
                    self.ring(v, ring)?;
                    self.block(ring);
                    if split_error.is_some() {
                        continue;
                    }
                    let c = self.vertex_count;
                    let split = source.record(self, v, ring).and_then(|record| {
                        let outcome = self.apply_split(v, ring, &record, c)?;
                        source.applied(v, c, &outcome);
                        Ok(outcome)
                    });
                    match split {
                        Ok(outcome) => stats.triangles_added += outcome.triangles_added,
                        Err(e) => split_error = Some(e),
                    }
                }
            }
        }
        Ok(split_error)
    }

    /// Marks the ring of a flagged vertex: those vertices' flags are
    /// inferred (SPEC §7.2), which makes every round's splits independent.
    #[inline]
    fn block(&mut self, ring: &Ring) {
        let third = self.candidates.len() / 3;
        let blocked = &mut self.candidates[2 * third..];
        for &x in ring.vertices() {
            if x != NONE
                && let Some(word) = blocked.get_mut((x / 64) as usize)
            {
                *word |= 1u64 << (x % 64);
            }
        }
    }

    /// Warms the fans of the candidates of `batch` (all in bitmap word `w`)
    /// that are not blocked and that `source` says are likely flagged.
    fn warm_batch<S: RecordSource>(&mut self, batch: &[u32], w: usize, source: &mut S) {
        let mut upcoming = [0u32; WARM_BATCH];
        let mut upcoming_len = 0;
        for &v in batch {
            if self.bitmaps().2[w] & (1u64 << (v % 64)) == 0 {
                upcoming[upcoming_len] = v;
                upcoming_len += 1;
            }
        }
        let likely = source.likely_flags(self, &upcoming[..upcoming_len]);
        let mut warm = [0u32; WARM_BATCH];
        let mut warm_len = 0;
        for (i, &v) in upcoming[..upcoming_len].iter().enumerate() {
            if likely >> i & 1 != 0 {
                warm[warm_len] = v;
                warm_len += 1;
            }
        }
        self.warm_fans(&warm[..warm_len]);
    }

    /// Walks the fans of `rs` in lockstep, reading the corners, opposites,
    /// positions and deficits their splits will read, so that the cache misses of
    /// independent fans overlap instead of queueing one dependent load after
    /// another. Changes nothing: a pure performance measure.
    fn warm_fans(&self, rs: &[u32]) {
        let mut corner = [NONE; WARM_BATCH];
        for (c, &r) in corner.iter_mut().zip(rs) {
            *c = self.vertex_corner.get(r);
        }
        let start = corner;
        let mut sum = 0u32;
        for _ in 0..WARM_STEPS {
            let mut active = false;
            for i in 0..rs.len() {
                let c = corner[i];
                if c == NONE {
                    continue;
                }
                let v = self.corners[next(c) as usize];
                if let (Some(p), Some(&d)) =
                    (self.positions.get(v as usize), self.deficit.get(v as usize))
                {
                    sum = sum.wrapping_add(p[0]).wrapping_add(d as u32);
                }
                let o = self.opposite.get(next(c));
                corner[i] = if o == NONE || next(o) == start[i] {
                    NONE
                } else {
                    next(o)
                };
                active |= corner[i] != NONE;
            }
            if !active {
                break;
            }
        }
        core::hint::black_box(sum);
    }
}
