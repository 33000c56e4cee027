//! A round's records read on another thread (SPEC §7.2, §7.3; informative).
//!
//! A round has two kinds of work. The *structure*: the flags, the rings of
//! the flagged vertices (the fan walks, which wait on memory), the blocked
//! set, and applying the splits. The *records*: the wing ranks, the split
//! valences and the positions (SPEC §7.4), which are decoded from their own
//! substreams and read nothing of the state but the positions of R and its
//! ring and which ring entries were candidates at the start of the round.
//!
//! By §7.2 a split changes neither the ring nor those positions of another
//! split of its round, so the record of a flagged vertex can be read as
//! soon as its ring is known, while the splits before it are still being
//! applied. [`crate::MeshState::run_round_piped`] does the structure and
//! hands each ring to a [`RecordPipe`]; a [`RecordsHalf`], which holds the
//! level's record substreams and its own copy of the positions, reads the
//! records, on another thread if the pipe carries them there. The splits
//! are applied in the same order, with the same records, as by
//! [`crate::MeshState::run_round`], so every round ends in the same state
//! (SPEC §8) and a bad stream fails with the same error (SPEC §10.3): the
//! flags' errors are the structure's own, a record's error comes back
//! through the pipe in its split's place, and after a failed split no
//! later one is applied.
//!
//! Nothing here spawns a thread (decoder-core is `no_std`): the SDKs do,
//! with their own channels (`splitstream-sdk-native`, `threaded.rs`).

use crate::Error;
use crate::limits::MAX_SPLIT_VALENCE;
use crate::record::{RecordCoding, RecordFan, RecordScratch, read_record};
use crate::ring::Ring;
use crate::split::SplitRecord;
use crate::substream::Substreams;
use crate::symbols::WingCandidates;

/// Carries split requests from the structure half of a round to a
/// [`RecordsHalf`] and the records back, both in split order.
pub trait RecordPipe {
    /// Asks for the record of the split of `r`, whose C gets index `c`,
    /// whose canonical ring is `vertices` (SPEC §7.1) and whose ring
    /// entries that may be wings are `eligible` (SPEC §7.4).
    fn send(&mut self, r: u32, c: u32, vertices: &[u32], eligible: &WingCandidates);
    /// The record of the oldest split asked for and not taken yet (or the
    /// error reading it). When it has not come back: `None` at once if not
    /// `wait`, else waits for it; `None` after waiting means the other
    /// half is gone (the round then fails with [`Error::Poisoned`]).
    fn take(&mut self, wait: bool) -> Option<Result<SplitRecord, Error>>;
}

/// Reads split records for [`crate::MeshState::run_round_piped`]: the
/// level's record substreams (split off its [`crate::LevelDecoder`]) and a
/// copy of the positions, kept up to date by the records it reads.
pub struct RecordsHalf<'l, 'b> {
    pub(crate) subs: Substreams<'l, 'b>,
    pub(crate) coding: RecordCoding,
    pub(crate) scratch: RecordScratch,
    pub(crate) ring: Ring,
    pub(crate) positions: &'b mut [[u32; 3]],
    pub(crate) bits: u8,
    pub(crate) failed: Option<Error>,
}

impl RecordsHalf<'_, '_> {
    /// Reads the record that [`RecordPipe::send`] asked for (SPEC §7.4) and
    /// moves R and C to its positions in this half's copy. After an error,
    /// every later request gets the same error and nothing more is read.
    pub fn read(
        &mut self,
        r: u32,
        c: u32,
        vertices: &[u32],
        eligible: &WingCandidates,
    ) -> Result<SplitRecord, Error> {
        if let Some(e) = self.failed {
            return Err(e);
        }
        let result = self.read_one(r, c, vertices, eligible);
        if let Err(e) = result {
            self.failed = Some(e);
        }
        result
    }

    fn read_one(
        &mut self,
        r: u32,
        c: u32,
        vertices: &[u32],
        eligible: &WingCandidates,
    ) -> Result<SplitRecord, Error> {
        if !self.ring.set_vertices(vertices) {
            return Err(Error::ValenceOverflow);
        }
        let fan = RecordFan {
            positions: self.positions,
            bits: self.bits,
            r,
            ring: &self.ring,
            eligible,
        };
        let record = read_record(&mut self.subs, &self.coding, &mut self.scratch, &fan)?;
        // C's index is checked against the capacity when the split is
        // applied; this copy only needs the slot.
        if (c as usize) >= self.positions.len() || (r as usize) >= self.positions.len() {
            return Err(Error::CapacityExceeded);
        }
        self.positions[r as usize] = record.position_p;
        self.positions[c as usize] = record.position_c;
        Ok(record)
    }
}

/// One split waiting for its record: R, C's index, and R's ring with its
/// corners (the split needs them, SPEC §7.5).
#[derive(Clone)]
pub struct PendingSplit {
    r: u32,
    c: u32,
    len: u8,
    vertices: [u32; MAX_SPLIT_VALENCE],
    corners: [u32; MAX_SPLIT_VALENCE],
}

impl Default for PendingSplit {
    fn default() -> Self {
        PendingSplit {
            r: 0,
            c: 0,
            len: 0,
            vertices: [0; MAX_SPLIT_VALENCE],
            corners: [0; MAX_SPLIT_VALENCE],
        }
    }
}

/// The splits of a round whose records are in the pipe, oldest first, in
/// caller-owned slots (about 2 KiB each): how far the structure may run
/// ahead of the records. At least one slot.
pub struct PendingSplits<'p> {
    slots: &'p mut [PendingSplit],
    head: usize,
    len: usize,
    ring: Ring,
}

impl<'p> PendingSplits<'p> {
    /// Pending splits held in `slots`; `None` when there is none.
    pub fn new(slots: &'p mut [PendingSplit]) -> Option<Self> {
        if slots.is_empty() {
            return None;
        }
        Some(PendingSplits {
            slots,
            head: 0,
            len: 0,
            ring: Ring::default(),
        })
    }

    pub(crate) fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub(crate) fn is_full(&self) -> bool {
        self.len == self.slots.len()
    }

    /// Keeps the ring of a split just sent (the caller made room).
    pub(crate) fn push(&mut self, r: u32, c: u32, ring: &Ring) {
        let at = (self.head + self.len) % self.slots.len();
        let slot = &mut self.slots[at];
        let k = ring.len().min(MAX_SPLIT_VALENCE);
        slot.r = r;
        slot.c = c;
        slot.len = k as u8;
        slot.vertices[..k].copy_from_slice(&ring.vertices()[..k]);
        slot.corners[..k].copy_from_slice(&ring.corners()[..k]);
        self.len += 1;
    }

    /// The oldest split: R, C's index and the ring it was sent with.
    pub(crate) fn pop(&mut self) -> Option<(u32, u32, &Ring)> {
        if self.len == 0 {
            return None;
        }
        let slot = &self.slots[self.head];
        let k = slot.len as usize;
        self.ring
            .set_walked(&slot.vertices[..k], &slot.corners[..k]);
        let (r, c) = (slot.r, slot.c);
        self.head = (self.head + 1) % self.slots.len();
        self.len -= 1;
        Some((r, c, &self.ring))
    }
}

/// A [`RecordPipe`] that reads each record on the calling thread, with a
/// [`RecordsHalf`] it borrows: the two-thread code path run on one thread,
/// for tests and fuzzing. With `lag`, a record is only given back when
/// [`RecordPipe::take`] waits for it, so that splits pile up in
/// [`PendingSplits`] as behind a slow thread.
#[cfg(feature = "alloc")]
pub struct InPlacePipe<'h, 'l, 'b> {
    half: &'h mut RecordsHalf<'l, 'b>,
    ready: alloc::collections::VecDeque<Result<SplitRecord, Error>>,
    lag: bool,
}

#[cfg(feature = "alloc")]
impl<'h, 'l, 'b> InPlacePipe<'h, 'l, 'b> {
    pub fn new(half: &'h mut RecordsHalf<'l, 'b>, lag: bool) -> Self {
        InPlacePipe {
            half,
            ready: alloc::collections::VecDeque::new(),
            lag,
        }
    }
}

#[cfg(feature = "alloc")]
impl RecordPipe for InPlacePipe<'_, '_, '_> {
    fn send(&mut self, r: u32, c: u32, vertices: &[u32], eligible: &WingCandidates) {
        let record = self.half.read(r, c, vertices, eligible);
        self.ready.push_back(record);
    }

    fn take(&mut self, wait: bool) -> Option<Result<SplitRecord, Error>> {
        if self.lag && !wait {
            return None;
        }
        self.ready.pop_front()
    }
}
