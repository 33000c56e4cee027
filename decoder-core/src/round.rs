//! One refinement round (SPEC §7.2, §7.3): find candidates, read one flag per
//! candidate, apply the flagged splits in ascending vertex order. The
//! round's candidate set is kept for its whole duration: it says which ring
//! entries may be wings (SPEC §7.4).
//!
//! The procedure is shared by the stream decoder and by the encoder, which
//! replays it to write streams that are correct by construction: both plug
//! in a [`RecordSource`].

use crate::Error;
use crate::header::Schedule;
use crate::limits::NONE;
use crate::pipe::{PendingSplits, RecordPipe};
use crate::ring::{FAN_LEN, FANS, FansAhead, Ring};
use crate::split::{SplitOutcome, SplitRecord};
use crate::state::{MeshState, next};

/// Candidates taken together, whose likely flagged ones have their fans
/// walked ahead at once (see `walk_fans`): about a fifth of them are
/// flagged under `every-vertex`, so a batch fills about half of [`FANS`]
/// (25.2 fans a walk on the 1M demo terrain). With 32 candidates, within
/// one bitmap word, a walk held 4.7 fans, and that terrain decoded about
/// 1.1x slower.
const WARM_BATCH: usize = 128;
/// By default fans are walked ahead only from this vertex count on
/// ([`MeshState::set_fans_ahead_from`]): a smaller state (about 58 bytes a
/// vertex, SPEC §9) mostly stays in the caches, where the extra bookkeeping
/// costs about as much as the overlapped misses save.
pub const FANS_AHEAD_FROM_VERTICES: u32 = 1 << 16;

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
    /// flagged: bit i for `upcoming[i]` (at most 128). Only a hint for
    /// prefetching (a wrong hint costs speed, never correctness); the
    /// default says all of them.
    fn likely_flags(&mut self, _state: &MeshState<'_>, upcoming: &[u32]) -> u128 {
        all_ones_wide(upcoming.len())
    }
}

/// The low `n` bits set (n at most 64).
#[inline]
pub fn all_ones(n: usize) -> u64 {
    if n >= 64 { u64::MAX } else { (1u64 << n) - 1 }
}

/// The low `n` bits set (n at most 128), from two 64-bit halves: a
/// variable 128-bit shift is a library call on 32-bit targets.
#[inline]
pub fn all_ones_wide(n: usize) -> u128 {
    (all_ones(n.saturating_sub(64)) as u128) << 64 | all_ones(n) as u128
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
        self.round_with(declared, source, ring, &mut Fused)
    }

    /// [`MeshState::run_round`] with each split's record read elsewhere:
    /// `pipe` gets every flagged vertex's ring and gives its record back
    /// (in split order), and the split is applied when it comes back, at the
    /// latest when `pending` is full or the round ends. `source` only gives
    /// the flags. The state after the round is the same as
    /// [`MeshState::run_round`]'s, and so is the error (see
    /// [`crate::pipe`]).
    pub fn run_round_piped<S: RecordSource, P: RecordPipe>(
        &mut self,
        declared: u32,
        source: &mut S,
        pipe: &mut P,
        ring: &mut Ring,
        pending: &mut PendingSplits<'_>,
    ) -> Result<RoundStats, Error> {
        pending.clear();
        let mut piped = Piped { pipe, pending };
        self.round_with(declared, source, ring, &mut piped)
    }

    /// Steps 1 to 3 of SPEC §7.3, each flagged split handed to `splits`.
    fn round_with<S: RecordSource, F: FlaggedSplits<S>>(
        &mut self,
        declared: u32,
        source: &mut S,
        ring: &mut Ring,
        splits: &mut F,
    ) -> Result<RoundStats, Error> {
        let n = self.vertex_count;
        if n as u64 + declared as u64 > self.vertex_capacity() as u64 {
            return Err(Error::CapacityExceeded);
        }
        let words = (n as usize).div_ceil(64);
        // Step 1: the candidates are the vertices below n with deficit 0,
        // or every one of them under the schedule `every-vertex` (3.6); the
        // bitmap is kept up to date by every split (SPEC §7.3). A copy
        // of it as it is now says which ring entries may be wings during
        // the round (SPEC §7.4, symbols.rs): splits change the live bitmap.
        let every_vertex = self.schedule == Schedule::EveryVertex;
        let (candidates, round_start, _) = self.bitmaps();
        let words = words.min(candidates.len()).min(round_start.len());
        // Under `every-vertex` every entry may be a wing, and the round-start
        // bitmap holds the split-history bits instead (SPEC §6.1, §9, 3.10).
        if !every_vertex {
            round_start[..words].copy_from_slice(&candidates[..words]);
        }
        let mut stats = RoundStats {
            candidates: candidates[..words].iter().map(|w| w.count_ones()).sum(),
            ..RoundStats::default()
        };
        let result = self.flag_and_split(n, words, source, ring, splits, &mut stats);
        let (_, round_start, blocked) = self.bitmaps();
        if !every_vertex {
            round_start[..words].fill(0);
        }
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
    fn flag_and_split<S: RecordSource, F: FlaggedSplits<S>>(
        &mut self,
        n: u32,
        words: usize,
        source: &mut S,
        ring: &mut Ring,
        splits: &mut F,
        stats: &mut RoundStats,
    ) -> Result<Option<Error>, Error> {
        let mut split_error = None;
        let mut batch = [0u32; WARM_BATCH];
        let warm_up = n >= self.fans_ahead_from;
        // Candidates at round start: vertices below n with deficit 0 (or
        // all below n, `every-vertex`). Splits of this round only change the
        // bits of blocked vertices and of new vertices (n and above), so
        // reading a word before the splits of the candidates before it is
        // reading it as it was at the start; a vertex blocked since is
        // skipped when its turn comes.
        let unblocked = |state: &Self, w: usize| {
            let below_n = if (w + 1) * 64 <= n as usize {
                u64::MAX
            } else {
                (1u64 << (n as usize - w * 64)) - 1
            };
            let third = state.candidates.len() / 3;
            state.candidates[w] & !state.candidates[2 * third + w] & below_n
        };
        let (mut w, mut bits) = (0, if words > 0 { unblocked(self, 0) } else { 0 });
        loop {
            // A batch runs across bitmap words: the more flagged fans one
            // lockstep walk holds, the more of their misses overlap.
            let mut len = 0;
            while len < WARM_BATCH {
                if bits == 0 {
                    w += 1;
                    if w >= words {
                        break;
                    }
                    bits = unblocked(self, w);
                    continue;
                }
                batch[len] = (w * 64) as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                len += 1;
            }
            if len == 0 {
                break;
            }
            // Warm the fans of the batch's candidates that the next
            // flags say will be flagged, together, so that their fan
            // walks hit the cache instead of waiting for one miss after
            // another. (Where the flags are not known yet, every
            // candidate's fan is warmed.)
            if warm_up {
                self.walk_batch(&batch[..len], source, &mut ring.ahead, F::READS_POSITIONS);
            }
            for &v in &batch[..len] {
                if self.is_blocked(v) {
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
                let c = n + stats.splits - 1;
                splits.flagged(self, source, v, c, ring, stats, &mut split_error);
            }
            // The fans walked ahead are the batch's: none outlives it.
            ring.ahead.owner = [NONE; FANS];
        }
        splits.finish(self, stats, &mut split_error);
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

    /// Whether `v` is blocked in this round (its flag is inferred 0).
    #[inline]
    fn is_blocked(&self, v: u32) -> bool {
        let third = self.bitmap_words;
        let w = 2 * third + (v / 64) as usize;
        self.candidates
            .get(w)
            .is_some_and(|&word| word & (1u64 << (v % 64)) != 0)
    }

    /// Walks ahead the fans of the candidates of `batch` that are not
    /// blocked and that `source` says are likely flagged (see
    /// [`FansAhead`]).
    fn walk_batch<S: RecordSource>(
        &mut self,
        batch: &[u32],
        source: &mut S,
        ahead: &mut FansAhead,
        positions: bool,
    ) {
        let mut upcoming = [0u32; WARM_BATCH];
        let mut upcoming_len = 0;
        for &v in batch {
            if !self.is_blocked(v) {
                upcoming[upcoming_len] = v;
                upcoming_len += 1;
            }
        }
        let likely = source.likely_flags(self, &upcoming[..upcoming_len]);
        // By 64-bit halves (see `all_ones_wide`).
        let halves = [likely as u64, (likely >> 64) as u64];
        let mut walk = [0u32; WARM_BATCH];
        let mut walk_len = 0;
        for (i, &v) in upcoming[..upcoming_len].iter().enumerate() {
            if halves[i / 64] >> (i % 64) & 1 != 0 {
                walk[walk_len] = v;
                walk_len += 1;
            }
        }
        self.walk_fans(&walk[..walk_len], ahead, positions);
    }

    /// Walks the fans of `rs` (ascending) in lockstep into `ahead`, then
    /// touches the positions and deficits of the ring vertices met, so that
    /// the cache misses of independent fans overlap instead of queueing one
    /// dependent load after another. Each lockstep step is short (one swing
    /// and one corner per fan), so that many fans' loads fit in the
    /// processor's window at once; the positions, which depend on no
    /// further load, come last, all together.
    fn walk_fans(&self, rs: &[u32], ahead: &mut FansAhead, positions: bool) {
        let count = rs.len().min(FANS);
        let mut corner = [NONE; FANS];
        for i in 0..FANS {
            ahead.owner[i] = rs.get(i).copied().unwrap_or(NONE);
            ahead.len[i] = 0;
        }
        ahead.cursor = 0;
        for (c, &r) in corner.iter_mut().zip(&rs[..count]) {
            *c = self.vertex_corner.get(r);
        }
        let start = corner;
        // Fans still being walked, as a bit mask.
        let mut active: u64 = all_ones(count);
        for step in 0..FAN_LEN {
            let mut left = active;
            while left != 0 {
                let i = left.trailing_zeros() as usize;
                left &= left - 1;
                let c = corner[i];
                let Some(&v) = self.corners.get(next(c) as usize) else {
                    active &= !(1u64 << i);
                    continue;
                };
                ahead.vertices[i][step] = v;
                ahead.corners[i][step] = c;
                let s = self.swing.get(c);
                if s == start[i] {
                    // Closed: the whole ring is held.
                    ahead.len[i] = step as u8 + 1;
                    active &= !(1u64 << i);
                } else if s == NONE {
                    // A boundary vertex: its ring is walked when it splits.
                    active &= !(1u64 << i);
                }
                corner[i] = s;
            }
            if active == 0 {
                break;
            }
        }
        let mut sum = 0u32;
        if !positions {
            // The records are read elsewhere (`pipe.rs`): only the wings'
            // deficits are read here, when the splits are applied.
            for i in 0..count {
                for &v in &ahead.vertices[i][..ahead.len[i] as usize] {
                    if let Some(&d) = self.deficit.get(v as usize) {
                        sum = sum.wrapping_add(d as u32);
                    }
                }
            }
            core::hint::black_box(sum);
            return;
        }
        for (i, &r) in rs[..count].iter().enumerate() {
            // The owner's own position too: its record reads it first
            // (the parent of the split's positions, SPEC §7.4), and nothing
            // else loads it before.
            if let Some(p) = self.positions.get(r as usize) {
                sum = sum.wrapping_add(p[0]);
            }
            for &v in &ahead.vertices[i][..ahead.len[i] as usize] {
                if let (Some(p), Some(&d)) =
                    (self.positions.get(v as usize), self.deficit.get(v as usize))
                {
                    sum = sum.wrapping_add(p[0]).wrapping_add(d as u32);
                }
            }
        }
        core::hint::black_box(sum);
    }
}

/// What a round does with each flagged vertex once its ring is walked and
/// blocked (SPEC §7.3, step 3): `flagged` is called in split order, the
/// `c`-th vertex index for its C, until a split fails; `finish` once the
/// round's flags are all read.
trait FlaggedSplits<S> {
    /// Whether the round's records are read on this thread, from this
    /// state's positions (the fans walked ahead then touch them too).
    const READS_POSITIONS: bool = true;
    #[allow(clippy::too_many_arguments)]
    fn flagged(
        &mut self,
        state: &mut MeshState<'_>,
        source: &mut S,
        r: u32,
        c: u32,
        ring: &Ring,
        stats: &mut RoundStats,
        split_error: &mut Option<Error>,
    );
    fn finish(
        &mut self,
        _state: &mut MeshState<'_>,
        _stats: &mut RoundStats,
        _split_error: &mut Option<Error>,
    ) {
    }
}

/// The decoder on one thread: each record is read and its split applied
/// at once.
struct Fused;

impl<S: RecordSource> FlaggedSplits<S> for Fused {
    #[inline(always)]
    fn flagged(
        &mut self,
        state: &mut MeshState<'_>,
        source: &mut S,
        r: u32,
        c: u32,
        ring: &Ring,
        stats: &mut RoundStats,
        split_error: &mut Option<Error>,
    ) {
        let split = source.record(state, r, ring).and_then(|record| {
            let outcome = state.apply_split(r, ring, &record, c)?;
            source.applied(r, c, &outcome);
            Ok(outcome)
        });
        match split {
            Ok(outcome) => stats.triangles_added += outcome.triangles_added,
            Err(e) => *split_error = Some(e),
        }
    }
}

/// The records read elsewhere (`pipe.rs`): each ring goes into the pipe and
/// waits in `pending` until its record comes back.
struct Piped<'a, 'p, P> {
    pipe: &'a mut P,
    pending: &'a mut PendingSplits<'p>,
}

impl<P: RecordPipe> Piped<'_, '_, P> {
    /// Applies the oldest pending split with its record, waiting for the
    /// record if `wait`; `false` when nothing was applied.
    fn apply_oldest(
        &mut self,
        state: &mut MeshState<'_>,
        wait: bool,
        stats: &mut RoundStats,
        split_error: &mut Option<Error>,
    ) -> bool {
        if self.pending.is_empty() {
            return false;
        }
        let Some(record) = self.pipe.take(wait) else {
            if wait {
                // The other half went away: nothing more will come back.
                *split_error = split_error.or(Some(Error::Poisoned));
                self.pending.clear();
            }
            return false;
        };
        let Some((r, c, ring)) = self.pending.pop() else {
            return false;
        };
        if split_error.is_some() {
            // After a failed split nothing is applied: the records still
            // in the pipe are drained.
            return true;
        }
        match record.and_then(|record| state.apply_split(r, ring, &record, c)) {
            Ok(outcome) => stats.triangles_added += outcome.triangles_added,
            Err(e) => *split_error = Some(e),
        }
        true
    }
}

impl<S: RecordSource, P: RecordPipe> FlaggedSplits<S> for Piped<'_, '_, P> {
    const READS_POSITIONS: bool = false;

    #[inline]
    fn flagged(
        &mut self,
        state: &mut MeshState<'_>,
        _source: &mut S,
        r: u32,
        c: u32,
        ring: &Ring,
        stats: &mut RoundStats,
        split_error: &mut Option<Error>,
    ) {
        // Room for this ring: the oldest waits for its record if need be.
        while self.pending.is_full() && split_error.is_none() {
            if !self.apply_oldest(state, true, stats, split_error) {
                break;
            }
        }
        if split_error.is_some() {
            return;
        }
        let eligible = state.wing_candidates(ring);
        self.pipe.send(r, c, ring.vertices(), &eligible);
        self.pending.push(r, c, ring);
        // Whatever has come back already is applied now.
        while self.apply_oldest(state, false, stats, split_error) {}
    }

    fn finish(
        &mut self,
        state: &mut MeshState<'_>,
        stats: &mut RoundStats,
        split_error: &mut Option<Error>,
    ) {
        while self.apply_oldest(state, true, stats, split_error) {}
    }
}
