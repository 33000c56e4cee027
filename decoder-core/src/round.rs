//! One refinement round (SPEC §7.2, §7.3): find candidates, read one flag per
//! candidate, apply the flagged splits in ascending vertex order.
//!
//! The procedure is shared by the stream decoder and by the encoder, which
//! replays it to write streams that are correct by construction: both plug
//! in a [`RecordSource`].

use crate::Error;
use crate::ring::Ring;
use crate::split::{SplitOutcome, SplitRecord};
use crate::state::MeshState;

/// Where a round gets its flags and split records from.
pub trait RecordSource {
    /// The flag of candidate `v` (SPEC §7.3), asked in ascending order.
    fn flag(&mut self, v: u32) -> Result<bool, Error>;
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
        let (candidates, flagged) = self.bitmaps();
        let mut stats = RoundStats {
            candidates: candidates[..words].iter().map(|w| w.count_ones()).sum(),
            ..RoundStats::default()
        };
        // Step 2: one flag per candidate, in ascending order.
        for w in 0..words {
            let mut bits = candidates[w];
            while bits != 0 {
                let v = (w * 64) as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                if source.flag(v)? {
                    flagged[w] |= 1u64 << (v % 64);
                    stats.splits += 1;
                }
            }
        }
        if stats.splits != declared {
            flagged[..words].fill(0);
            return Err(Error::FlagCountMismatch { round: 0 });
        }
        // Step 3: the splits, in ascending order of the split vertex.
        let result = self.split_flagged(n, words, source, ring, &mut stats);
        self.bitmaps().1[..words].fill(0);
        result.map(|()| stats)
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
        for w in 0..words {
            let mut bits = self.bitmaps().1[w];
            while bits != 0 {
                let r = (w * 64) as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                self.ring(r, ring)?;
                self.check_independent(ring, n)?;
                let record = source.record(self, r, ring)?;
                let outcome = self.apply_split(r, ring, &record, c)?;
                source.applied(r, c, &outcome);
                stats.triangles_added += outcome.triangles_added;
                c += 1;
            }
        }
        Ok(())
    }

    /// The independence rule (SPEC §7.2): no neighbour of a split vertex may
    /// be split in the same round. Flagged vertices are still marked; a
    /// vertex created earlier in this round has an index of at least `n`.
    fn check_independent(&self, ring: &Ring, n: u32) -> Result<(), Error> {
        let flagged = &self.candidates[self.candidates.len() / 2..];
        for &x in ring.vertices() {
            if x == crate::limits::NONE {
                continue;
            }
            if x >= n || flagged[(x / 64) as usize] & (1u64 << (x % 64)) != 0 {
                return Err(Error::DependentSplits);
            }
        }
        Ok(())
    }
}
