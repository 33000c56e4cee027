//! One refinement round (SPEC §7.2, §7.3): find candidates, read one flag per
//! candidate, apply the flagged splits in ascending vertex order.
//!
//! The procedure is shared by the stream decoder and by the encoder, which
//! replays it to write streams that are correct by construction: both plug
//! in a [`RecordSource`].

use crate::Error;
use crate::limits::{MAX_SPLIT_VALENCE, NONE};
use crate::ring::Ring;
use crate::split::{SplitOutcome, SplitRecord};
use crate::state::{MeshState, next, prev};

/// Flagged vertices whose fans are warmed together (see `warm_fans`).
const WARM_BATCH: usize = 32;
/// Wedges walked per fan when warming: typical valences, not the maximum.
const WARM_STEPS: usize = 12;

/// Where a round gets its flags and split records from.
pub trait RecordSource {
    /// The flag of candidate `v` (SPEC §7.3), asked in ascending order.
    fn flag(&mut self, state: &MeshState<'_>, v: u32) -> Result<bool, Error>;
    /// The record of the split of `r`, whose canonical ring is `ring` (SPEC §7.4).
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error>;
    /// Called after each applied split (the encoder tracks vertex identities).
    fn applied(&mut self, _r: u32, _c: u32, _outcome: &SplitOutcome) {}
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
        // the bitmap is kept up to date by every split (SPEC §7.3).
        let mut stats = RoundStats {
            candidates: self.bitmaps().0[..words]
                .iter()
                .map(|w| w.count_ones())
                .sum(),
            ..RoundStats::default()
        };
        // Step 2: one flag per candidate, in ascending order; a candidate
        // next to one flagged before it has no flag (it reads as 0).
        let mut result = Ok(());
        let mut batch = [0u32; WARM_BATCH];
        'flags: for w in 0..words {
            let mut bits = self.bitmaps().0[w] & !self.bitmaps().2[w];
            // Warm the fans of this word's candidates together: the fan walk
            // of each flagged one (block_neighbours) then hits the cache
            // instead of waiting for one miss after another.
            let mut pending = bits;
            while pending != 0 {
                let mut len = 0;
                while pending != 0 && len < WARM_BATCH {
                    batch[len] = (w * 64) as u32 + pending.trailing_zeros();
                    pending &= pending - 1;
                    len += 1;
                }
                self.warm_fans(&batch[..len]);
            }
            while bits != 0 {
                let v = (w * 64) as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                if self.bitmaps().2[w] & (1u64 << (v % 64)) != 0 {
                    continue;
                }
                match source.flag(self, v) {
                    Ok(false) => {}
                    Ok(true) => {
                        self.bitmaps().1[w] |= 1u64 << (v % 64);
                        stats.splits += 1;
                        if let Err(e) = self.block_neighbours(v) {
                            result = Err(e);
                            break 'flags;
                        }
                    }
                    Err(e) => {
                        result = Err(e);
                        break 'flags;
                    }
                }
            }
        }
        self.bitmaps().2[..words].fill(0);
        if result.is_ok() && stats.splits != declared {
            result = Err(Error::FlagCountMismatch { round: 0 });
        }
        if let Err(e) = result {
            self.bitmaps().1[..words].fill(0);
            return Err(e);
        }
        // Step 3: the splits, in ascending order of the split vertex.
        let result = self.split_flagged(n, words, source, ring, &mut stats);
        self.bitmaps().1[..words].fill(0);
        result.map(|()| stats)
    }

    /// Marks the neighbours of a flagged vertex: their flags are inferred
    /// (SPEC §7.2), which makes every round's splits independent. Walks the
    /// fan both ways and marks both outer corners of every wedge (order and
    /// duplicates do not matter here, so no canonical ring is needed).
    fn block_neighbours(&mut self, v: u32) -> Result<(), Error> {
        let half = self.candidates.len() / 3;
        let start = self.vertex_corner[v as usize];
        let mark = |state: &mut Self, c: u32| {
            for x in [
                state.corners[next(c) as usize],
                state.corners[prev(c) as usize],
            ] {
                state.candidates[2 * half + (x / 64) as usize] |= 1u64 << (x % 64);
            }
        };
        let mut c = start;
        for _ in 0..MAX_SPLIT_VALENCE {
            mark(self, c);
            let o = self.opposite[next(c) as usize];
            if o == NONE {
                // An open fan: the wedges clockwise of the start remain.
                let mut c = start;
                for _ in 0..MAX_SPLIT_VALENCE {
                    let o = self.opposite[prev(c) as usize];
                    if o == NONE {
                        return Ok(());
                    }
                    c = prev(o);
                    mark(self, c);
                }
                return Err(Error::ValenceOverflow);
            }
            c = next(o);
            if c == start {
                return Ok(());
            }
        }
        Err(Error::ValenceOverflow)
    }

    fn split_flagged<S: RecordSource>(
        &mut self,
        n: u32,
        words: usize,
        source: &mut S,
        ring: &mut Ring,
        stats: &mut RoundStats,
    ) -> Result<(), Error> {
        let mut c = n;
        let mut batch = [0u32; WARM_BATCH];
        for w in 0..words {
            let mut bits = self.bitmaps().1[w];
            while bits != 0 {
                // Up to a batch of this word's flagged vertices: warm their
                // fans' cache lines together, then split them in order.
                let mut len = 0;
                while bits != 0 && len < WARM_BATCH {
                    batch[len] = (w * 64) as u32 + bits.trailing_zeros();
                    bits &= bits - 1;
                    len += 1;
                }
                self.warm_fans(&batch[..len]);
                for &r in &batch[..len] {
                    self.ring(r, ring)?;
                    let record = source.record(self, r, ring)?;
                    let outcome = self.apply_split(r, ring, &record, c)?;
                    source.applied(r, c, &outcome);
                    stats.triangles_added += outcome.triangles_added;
                    c += 1;
                }
            }
        }
        Ok(())
    }

    /// Walks the fans of `rs` in lockstep, reading what their splits will
    /// read, so that the cache misses of independent fans overlap instead of
    /// queueing one dependent load after another. Changes nothing: a pure
    /// performance measure.
    fn warm_fans(&self, rs: &[u32]) {
        let mut corner = [NONE; WARM_BATCH];
        for (c, &r) in corner.iter_mut().zip(rs) {
            *c = self.vertex_corner[r as usize];
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
                sum = sum.wrapping_add(self.positions[v as usize][0]);
                let o = self.opposite[next(c) as usize];
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
