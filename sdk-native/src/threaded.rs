//! One stream decoded on two cores: decoder-core's rounds on the calling
//! thread, the split records (SPEC §7.4) read on a second thread
//! (`splitstream_decoder_core::pipe`).
//!
//! The calling thread reads the flags, walks the flagged vertices' rings and
//! applies the splits; the second reads the records from their own
//! substreams. Rings go one way and records the other, in batches of
//! [`BATCH`], so that the threads meet once per batch rather than once per
//! split. Every round ends in the state a one-thread decode gives (the same
//! state hash, SPEC §8), and a bad stream fails with the same error.
//!
//! It costs memory beside the decoder's workspace: a copy of the positions
//! (12 bytes a vertex), a second inflater and [`PENDING`] waiting rings
//! (about 2 KiB each). See the README's "On two cores" for what it gains.

use std::collections::VecDeque;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};

use splitstream_decoder_core::pipe::{
    InPlacePipe, PendingSplit, PendingSplits, RecordPipe, RecordsHalf,
};
use splitstream_decoder_core::{
    Decoder, Error, Inflater, LevelDecoder, MeshState, Ring, RoundInfo, SplitObserver, SplitRecord,
    WingCandidates,
};

/// Splits sent to the records thread at once: at first, whenever the
/// records thread has nothing left to do (at the start of each round), so
/// that it starts soon; then twice as many each time, up to [`BATCH`], so
/// that the threads meet seldom.
pub const FIRST_BATCH: usize = 8;
/// The most splits sent at once.
pub const BATCH: usize = 256;
/// Splits whose records may be on their way at once: how far the rings may
/// run ahead of the records (three batches, so that the calling thread
/// walks the next batch while the records of the one before come back).
pub const PENDING: usize = 3 * BATCH;

/// By default a level adding fewer splits than this decodes on the calling
/// thread alone: starting the second thread and meeting it at every round
/// costs more than it saves (see the README's "On two cores").
pub const TWO_THREADS_FROM_SPLITS: u32 = 4096;

/// The memory a two-thread decode needs beside the decoder's workspace,
/// kept from level to level, and from how many splits a level uses it.
pub struct TwoThreadMemory {
    inflater: Box<Inflater>,
    positions: Vec<[u32; 3]>,
    pending: Vec<PendingSplit>,
    from_splits: u32,
}

impl TwoThreadMemory {
    /// Memory for a decoder holding up to `vertex_capacity` vertices.
    pub fn new(vertex_capacity: u32) -> Self {
        TwoThreadMemory {
            inflater: Box::default(),
            positions: vec![[0; 3]; vertex_capacity as usize],
            pending: vec![PendingSplit::default(); PENDING],
            from_splits: TWO_THREADS_FROM_SPLITS,
        }
    }

    /// Levels adding at least `splits` splits use the second thread; the
    /// others decode on the calling thread alone (default
    /// [`TWO_THREADS_FROM_SPLITS`]; 0: every level, as the tests do).
    pub fn set_two_threads_from(&mut self, splits: u32) {
        self.from_splits = splits;
    }

    /// Bytes it holds (besides the allocator's own).
    pub fn bytes(&self) -> usize {
        size_of::<Inflater>()
            + self.positions.len() * size_of::<[u32; 3]>()
            + self.pending.len() * size_of::<PendingSplit>()
    }
}

/// Decodes level `level` from its `bytes` like [`Decoder::decode_level`],
/// with the records read on a second thread.
pub fn decode_level(
    decoder: &mut Decoder<'_, '_>,
    level: u16,
    bytes: &[u8],
    memory: &mut TwoThreadMemory,
) -> Result<(), Error> {
    decode_level_observed(decoder, level, bytes, memory, |_, _| {})
}

/// [`decode_level`], showing `after` the state after level 0's seed mesh
/// (with `None`) and after every round (with the round's counts), as the
/// conformance runner checks it (SPEC §8).
pub fn decode_level_observed<F>(
    decoder: &mut Decoder<'_, '_>,
    level: u16,
    bytes: &[u8],
    memory: &mut TwoThreadMemory,
    after: F,
) -> Result<(), Error>
where
    F: FnMut(Option<&RoundInfo>, &MeshState<'_>),
{
    decode_level_tapped(decoder, level, bytes, memory, &mut AfterRounds(after))
}

/// What a two-thread decode shows of a level besides its result: the
/// state after level 0's seed and after every round, and every split.
pub trait RoundTap {
    /// Whether [`RoundTap::split`] wants the splits: if not, the pipe does
    /// not keep their vertices for it.
    const SPLITS: bool = true;
    /// The level has begun (its header read, and level 0's seed mesh):
    /// `state` is where its first round starts.
    fn begin_level(&mut self, _state: &MeshState<'_>) {}
    /// The state after level 0's seed mesh (`info` `None`) and after every
    /// round (with the round's counts).
    fn after(&mut self, info: Option<&RoundInfo>, state: &MeshState<'_>);
    /// The split of vertex `r` with its `record`, in split order, once the
    /// record is read (on either thread) and before the split is applied;
    /// a round that fails may have shown some of its splits.
    fn split(&mut self, _r: u32, _record: &SplitRecord) {}
}

/// A [`RoundTap`] that shows `after` the rounds only.
struct AfterRounds<F>(F);

impl<F: FnMut(Option<&RoundInfo>, &MeshState<'_>)> RoundTap for AfterRounds<F> {
    const SPLITS: bool = false;

    fn after(&mut self, info: Option<&RoundInfo>, state: &MeshState<'_>) {
        (self.0)(info, state);
    }
}

/// A level's rounds read on one thread show their splits to the tap.
struct SplitsTo<'t, T>(&'t mut T);

impl<T: RoundTap> SplitObserver for SplitsTo<'_, T> {
    fn record(&mut self, _: &MeshState<'_>, r: u32, _: &Ring, record: &SplitRecord) {
        self.0.split(r, record);
    }
}

/// [`decode_level`], showing `tap` the states after the seed and the
/// rounds and every split with its record.
pub fn decode_level_tapped<T: RoundTap>(
    decoder: &mut Decoder<'_, '_>,
    level: u16,
    bytes: &[u8],
    memory: &mut TwoThreadMemory,
    tap: &mut T,
) -> Result<(), Error> {
    let capacity = decoder.state().vertex_capacity() as usize;
    if memory.positions.len() < capacity {
        memory.positions.resize(capacity, [0; 3]);
    }
    let level_vertices = decoder.level_table().get(level).vertex_count;
    let mut level_decoder = decoder.begin_level(level, bytes)?;
    tap.begin_level(level_decoder.state());
    if level == 0 {
        tap.after(None, level_decoder.state());
    }
    let splits = level_vertices.saturating_sub(level_decoder.state().vertex_count());
    // A platform without threads (wasm32-unknown-unknown) or with one core
    // decodes on the calling thread.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if splits < memory.from_splits || cores < 2 {
        while let Some(info) = level_decoder.next_round_observed(&mut SplitsTo(tap))? {
            tap.after(Some(&info), level_decoder.state());
        }
        return Ok(());
    }
    let mut records = level_decoder.split_records(&mut memory.inflater, &mut memory.positions)?;
    let Some(mut pending) = PendingSplits::new(&mut memory.pending) else {
        return Err(Error::CapacityExceeded);
    };
    let (rounds, records) = std::thread::scope(|scope| {
        let (requests, requests_in) = channel();
        let (answers_out, answers) = channel();
        let (records_out, records_in) = channel();
        let spawned = std::thread::Builder::new()
            .name("splitstream-records".into())
            .spawn_scoped(scope, move || {
                let records = records_in.recv().ok()?;
                Some(serve(records, requests_in, answers_out))
            });
        let Ok(worker) = spawned else {
            // No second thread to be had: the same rounds, the records
            // read on this thread.
            let mut pipe = Tapped::new(InPlacePipe::new(&mut records, false), &mut *tap);
            let rounds = run_rounds(&mut level_decoder, &mut pipe, &mut pending);
            drop(pipe);
            return (rounds, Some(records));
        };
        // The worker waits for its records half: it cannot fail to get it.
        let _ = records_out.send(records);
        let channels = ChannelPipe {
            building: Batch::default(),
            spare: Vec::new(),
            batch: FIRST_BATCH,
            outstanding: 0,
            requests,
            answers,
            ready: VecDeque::new(),
        };
        let mut pipe = Tapped::new(channels, &mut *tap);
        let rounds = run_rounds(&mut level_decoder, &mut pipe, &mut pending);
        // Closing the requests ends the worker, which gives the record
        // substreams back.
        drop(pipe);
        match worker.join() {
            Ok(records) => (rounds, records),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    });
    // The records half always comes back (the worker is given it before
    // any request); without it the level could not end.
    let Some(records) = records else {
        return Err(Error::Poisoned);
    };
    level_decoder.join_records(records);
    rounds?;
    // The rounds are done: this ends the level (SPEC §7.6).
    while level_decoder.next_round()?.is_some() {}
    Ok(())
}

/// Runs the level's rounds with their records read through `pipe`,
/// showing its tap the state after each.
fn run_rounds<P: RecordPipe, T: RoundTap>(
    level_decoder: &mut LevelDecoder<'_, '_, '_>,
    pipe: &mut Tapped<'_, P, T>,
    pending: &mut PendingSplits<'_>,
) -> Result<(), Error> {
    while let Some(info) = level_decoder.next_round_piped(pipe, pending)? {
        pipe.tap.after(Some(&info), level_decoder.state());
    }
    Ok(())
}

/// A pipe that shows each split and its record to a [`RoundTap`] as the
/// record is taken: records come back in the order their splits were
/// sent, so the vertices sent wait here until then.
struct Tapped<'t, P, T> {
    pipe: P,
    tap: &'t mut T,
    sent: VecDeque<u32>,
}

impl<'t, P, T> Tapped<'t, P, T> {
    fn new(pipe: P, tap: &'t mut T) -> Self {
        Tapped {
            pipe,
            tap,
            sent: VecDeque::new(),
        }
    }
}

impl<P: RecordPipe, T: RoundTap> RecordPipe for Tapped<'_, P, T> {
    fn send(&mut self, r: u32, c: u32, vertices: &[u32], eligible: &WingCandidates) {
        if T::SPLITS {
            self.sent.push_back(r);
        }
        self.pipe.send(r, c, vertices, eligible);
    }

    fn take(&mut self, wait: bool) -> Option<Result<SplitRecord, Error>> {
        let record = self.pipe.take(wait)?;
        if T::SPLITS {
            let r = self.sent.pop_front();
            if let (Some(r), Ok(record)) = (r, &record) {
                self.tap.split(r, record);
            }
        }
        Some(record)
    }
}

/// One split's request: R, C's index, the eligible wing entries and where
/// its ring lies in the batch's `vertices`.
struct Request {
    r: u32,
    c: u32,
    eligible: WingCandidates,
    ring_start: u32,
    ring_len: u32,
}

/// Requests going to the records thread, and their records coming back in
/// the same batch, whose buffers then serve again.
#[derive(Default)]
struct Batch {
    requests: Vec<Request>,
    vertices: Vec<u32>,
    records: Vec<Result<SplitRecord, Error>>,
}

/// The calling thread's end of the pipe.
struct ChannelPipe {
    building: Batch,
    /// Batches back from the records thread, emptied, to build again.
    spare: Vec<Batch>,
    /// Requests the batch being built is sent with.
    batch: usize,
    /// Requests sent whose records have not come back.
    outstanding: usize,
    requests: Sender<Batch>,
    answers: Receiver<Batch>,
    /// Records come back and not taken yet, oldest first.
    ready: VecDeque<Result<SplitRecord, Error>>,
}

impl ChannelPipe {
    fn flush(&mut self) {
        if !self.building.requests.is_empty() {
            self.outstanding += self.building.requests.len();
            self.batch = (2 * self.batch).min(BATCH);
            let next = self.spare.pop().unwrap_or_default();
            // A closed channel shows as a closed answer channel in `take`.
            let _ = self
                .requests
                .send(std::mem::replace(&mut self.building, next));
        }
    }
}

impl RecordPipe for ChannelPipe {
    fn send(&mut self, r: u32, c: u32, vertices: &[u32], eligible: &WingCandidates) {
        let b = &mut self.building;
        b.requests.push(Request {
            r,
            c,
            eligible: *eligible,
            ring_start: b.vertices.len() as u32,
            ring_len: vertices.len() as u32,
        });
        b.vertices.extend_from_slice(vertices);
        if b.requests.len() >= self.batch {
            self.flush();
        }
    }

    fn take(&mut self, wait: bool) -> Option<Result<SplitRecord, Error>> {
        if let Some(record) = self.ready.pop_front() {
            return Some(record);
        }
        let mut batch = if wait {
            // The oldest request may still be in the batch being built.
            self.flush();
            receive(&self.answers)?
        } else {
            match self.answers.try_recv() {
                Ok(batch) => batch,
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return None,
            }
        };
        self.outstanding -= batch.records.len();
        if self.outstanding == 0 && self.building.requests.is_empty() {
            // The records thread has caught up: the next batch is small.
            self.batch = FIRST_BATCH;
        }
        self.ready.extend(batch.records.drain(..));
        batch.requests.clear();
        batch.vertices.clear();
        self.spare.push(batch);
        self.ready.pop_front()
    }
}

/// The records thread: reads each batch's records in order and sends them
/// back in the same batch, until the requests close; returns the records
/// half.
fn serve<'l, 'b>(
    mut records: RecordsHalf<'l, 'b>,
    requests: Receiver<Batch>,
    answers: Sender<Batch>,
) -> RecordsHalf<'l, 'b> {
    while let Some(mut batch) = receive(&requests) {
        batch.records.clear();
        for q in &batch.requests {
            let start = q.ring_start as usize;
            let ring = &batch.vertices[start..start + q.ring_len as usize];
            batch
                .records
                .push(records.read(q.r, q.c, ring, &q.eligible));
        }
        if answers.send(batch).is_err() {
            break;
        }
    }
    records
}

/// How many times a thread polls an empty channel before it sleeps on it.
/// Sleeping and being woken costs tens of microseconds, about what a batch
/// of records takes to read, so a thread that waits for the other polls
/// first, for some hundreds of microseconds.
const POLLS: u32 = 1 << 14;
/// Polls between yields: if the other thread shares this core (the
/// scheduler has not moved a new thread yet, or the machine is busy), it
/// runs instead of waiting for this one's time slice to end.
const POLLS_PER_YIELD: u32 = 256;

/// The next message of `from`, polling before sleeping; `None` once the
/// sender is gone.
fn receive<T>(from: &Receiver<T>) -> Option<T> {
    for i in 1..=POLLS {
        match from.try_recv() {
            Ok(message) => return Some(message),
            Err(TryRecvError::Empty) if i % POLLS_PER_YIELD == 0 => std::thread::yield_now(),
            Err(TryRecvError::Empty) => std::hint::spin_loop(),
            Err(TryRecvError::Disconnected) => return None,
        }
    }
    from.recv().ok()
}
