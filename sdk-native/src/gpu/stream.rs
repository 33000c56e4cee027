//! The CPU side of GPU decoding, phase 1: decoder-core reads the stream
//! (headers, chunks, entropy decoding, records with resolved positions) and
//! applies every round itself; a [`Capture`] keeps each round's flags and
//! records so that the GPU can replay the same rounds ([`super::replay()`]).
//!
//! [`capture_stream`] reads on one thread with decoder-core's `Decoder`,
//! a [`Capture`] observing each round's flags and records.
//! [`capture_stream_two_threads`] reads with `Decoder` too, the records
//! on a second thread ([`crate::threaded`]), and sees each round's splits
//! through a [`RoundTap`]: the same capture, about as much faster as the
//! two-thread decode (sdk-native/README.md, "On two cores"), which is what
//! a GPU decode of a large stream waits for.

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::{
    Error, MeshState, RoundInfo, Schedule, SplitRecord, declared_layout,
};

use super::capture::{Capture, CapturedRound, gpu_record};
use crate::threaded::{RoundTap, TwoThreadMemory, decode_level_tapped};

/// The seed mesh as decoder-core holds it after reading it (SPEC §6.3).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BaseState {
    pub positions: Vec<[u32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Deficits, or under the schedule `every-vertex` valences (SPEC §6.2).
    pub deficits: Vec<u8>,
    pub bits: u8,
    /// The stream's schedule (SPEC §3.2, format 3.6): what `deficits` hold
    /// and which vertices the GPU takes as candidates.
    pub schedule: Schedule,
}

impl BaseState {
    /// A copy of `state`'s normative arrays.
    pub fn of(state: &MeshState<'_>) -> BaseState {
        BaseState {
            positions: state.positions().to_vec(),
            triangles: state.triangles().to_vec(),
            deficits: state.deficits().to_vec(),
            bits: state.bits(),
            schedule: state.schedule(),
        }
    }
}

/// One level's rounds.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CapturedLevel {
    /// The level's triangle count, the limit its splits may reach (SPEC §7.5).
    pub triangle_limit: u32,
    pub rounds: Vec<CapturedRound>,
}

/// Everything the CPU read from a stream, up to its first fault.
#[derive(Clone, Debug, Default)]
pub struct CapturedStream {
    pub vertex_capacity: u32,
    pub triangle_capacity: u32,
    /// `None` when the stream failed before its seed mesh was complete.
    pub base: Option<BaseState>,
    /// Levels begun, in order; the last may be partial when `error` is set.
    pub levels: Vec<CapturedLevel>,
    /// decoder-core's state hash after the seed and after every round (when
    /// asked for).
    pub cpu_hashes: Vec<u64>,
    /// The first fault, with its place: after the seed, the rounds captured
    /// (the GPU replays them and reports their hashes) come first.
    pub error: Option<CaptureError>,
}

/// Why a capture ended early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaptureError {
    /// The stream's first fault, found by decoder-core.
    Stream(Error),
    /// decoder-core asked for a flag of a vertex that is not a candidate: its
    /// round procedure changed in a way [`Capture`] does not follow.
    FlagOrder,
}

impl From<Error> for CaptureError {
    fn from(e: Error) -> Self {
        CaptureError::Stream(e)
    }
}

impl CapturedStream {
    /// Splits over all captured rounds.
    pub fn splits(&self) -> u64 {
        self.levels
            .iter()
            .flat_map(|l| &l.rounds)
            .map(|r| r.records.len() as u64)
            .sum()
    }

    /// Rounds captured.
    pub fn rounds(&self) -> usize {
        self.levels.iter().map(|l| l.rounds.len()).sum()
    }
}

/// Decodes `stream` with decoder-core, capturing every round; with
/// `hash_rounds`, also records decoder-core's state hashes. Never fails:
/// the first fault ends the capture and is kept in
/// [`CapturedStream::error`].
pub fn capture_stream(stream: &[u8], hash_rounds: bool) -> CapturedStream {
    let mut out = CapturedStream::default();
    if let Err(e) = capture_into(stream, hash_rounds, &mut out) {
        out.error = Some(e);
    }
    out
}

fn capture_into(
    stream: &[u8],
    hash_rounds: bool,
    out: &mut CapturedStream,
) -> Result<(), CaptureError> {
    let mut workspace = OwnedWorkspace::for_stream(stream)?;
    let mut decoder = workspace.decoder(stream)?;
    let layout = declared_layout(decoder.header(), decoder.level_table())?;
    out.vertex_capacity = layout.vertex_capacity;
    out.triangle_capacity = layout.triangle_capacity;
    while let Some(k) = decoder.next_level() {
        let triangle_limit = decoder.level_table().get(k).triangle_count;
        let bytes = decoder.level_bytes(k, stream)?;
        let mut level = decoder.begin_level(k, bytes)?;
        if k == 0 {
            // The seed mesh, read by `begin_level` (SPEC §6.3), and its hash
            // before the rounds (§8).
            out.base = Some(BaseState::of(level.state()));
            if hash_rounds {
                out.cpu_hashes.push(level.state().state_hash());
            }
        }
        out.levels.push(CapturedLevel {
            triangle_limit,
            rounds: Vec::new(),
        });
        let mut capture = Capture::default();
        while level.next_round_observed(&mut capture)?.is_some() {
            if capture.out_of_order {
                return Err(CaptureError::FlagOrder);
            }
            let round = capture.take_round();
            if let Some(captured) = out.levels.last_mut() {
                captured.rounds.push(round);
            }
            if hash_rounds {
                out.cpu_hashes.push(level.state().state_hash());
            }
        }
    }
    Ok(())
}

/// [`capture_stream`] with the records read on a second thread for every
/// level adding at least `two_threads_from` splits
/// ([`crate::threaded::TWO_THREADS_FROM_SPLITS`] by default; 0: every
/// level). The same capture: the same rounds, flags, records and hashes,
/// and on a bad stream the same rounds before the same fault.
pub fn capture_stream_two_threads(
    stream: &[u8],
    hash_rounds: bool,
    two_threads_from: u32,
) -> CapturedStream {
    let mut out = CapturedStream::default();
    if let Err(e) = capture_two_threads_into(stream, hash_rounds, two_threads_from, &mut out) {
        out.error = Some(e);
    }
    out
}

fn capture_two_threads_into(
    stream: &[u8],
    hash_rounds: bool,
    two_threads_from: u32,
    out: &mut CapturedStream,
) -> Result<(), CaptureError> {
    let mut workspace = OwnedWorkspace::for_stream(stream)?;
    let mut decoder = workspace.decoder(stream)?;
    let layout = declared_layout(decoder.header(), decoder.level_table())?;
    out.vertex_capacity = layout.vertex_capacity;
    out.triangle_capacity = layout.triangle_capacity;
    let mut memory = TwoThreadMemory::new(layout.vertex_capacity);
    memory.set_two_threads_from(two_threads_from);
    let mut tap = CaptureTap {
        out,
        hash_rounds,
        triangle_limit: 0,
        candidates: Vec::new(),
        word: 0,
        before: 0,
        round: CapturedRound::default(),
        last: None,
        out_of_order: false,
    };
    while let Some(k) = decoder.next_level() {
        tap.triangle_limit = decoder.level_table().get(k).triangle_count;
        let bytes = decoder.level_bytes(k, stream)?;
        decode_level_tapped(&mut decoder, k, bytes, &mut memory, &mut tap)?;
        if tap.out_of_order {
            return Err(CaptureError::FlagOrder);
        }
    }
    Ok(())
}

/// Captures the rounds of a two-thread decode from what it shows: the
/// round-start candidates come from the state after the seed or the round
/// before, and each split marks its vertex's flag (a split vertex is a
/// flagged candidate; every other candidate's flag reads 0, as in
/// [`Capture`]) and adds its record.
struct CaptureTap<'o> {
    out: &'o mut CapturedStream,
    hash_rounds: bool,
    /// The triangle count of the level being decoded.
    triangle_limit: u32,
    /// The round's candidates as a bitmap (decoder-core's, copied at the
    /// round's start: the splits change it), bits from the vertex count on
    /// cleared.
    candidates: Vec<u64>,
    /// Candidates in the words of `candidates` before word `word`.
    word: usize,
    before: u32,
    round: CapturedRound,
    /// The last split vertex, to check that they come in ascending order.
    last: Option<u32>,
    /// A split vertex was not a candidate of its round, or came out of
    /// order.
    out_of_order: bool,
}

impl CaptureTap<'_> {
    /// A round starts from `state`: its candidates are the vertices of
    /// deficit 0 (under `every-vertex`: every vertex; decoder-core's bitmap
    /// follows the schedule), which the round's flags follow in ascending
    /// order.
    fn begin_round(&mut self, state: &MeshState<'_>) {
        let n = state.vertex_count() as usize;
        self.candidates.clear();
        self.candidates.extend_from_slice(state.candidate_words());
        if let Some(last) = self.candidates.last_mut()
            && !n.is_multiple_of(64)
        {
            *last &= (1u64 << (n % 64)) - 1;
        }
        let count: u32 = self.candidates.iter().map(|w| w.count_ones()).sum();
        self.round = CapturedRound {
            candidates: count,
            flags: vec![0; count.div_ceil(32) as usize],
            records: Vec::new(),
        };
        (self.word, self.before, self.last) = (0, 0, None);
    }

    /// The index of `r` among the round's candidates, if it is one; `r`
    /// grows from call to call within a round.
    fn rank(&mut self, r: u32) -> Option<u32> {
        if self.last.is_some_and(|last| r <= last) {
            return None;
        }
        self.last = Some(r);
        let w = (r / 64) as usize;
        let word = *self.candidates.get(w)?;
        while self.word < w {
            self.before += self.candidates[self.word].count_ones();
            self.word += 1;
        }
        let bit = 1u64 << (r % 64);
        (word & bit != 0).then(|| self.before + (word & (bit - 1)).count_ones())
    }
}

impl RoundTap for CaptureTap<'_> {
    fn begin_level(&mut self, state: &MeshState<'_>) {
        self.out.levels.push(CapturedLevel {
            triangle_limit: self.triangle_limit,
            rounds: Vec::new(),
        });
        self.begin_round(state);
    }

    fn after(&mut self, info: Option<&RoundInfo>, state: &MeshState<'_>) {
        if info.is_none() {
            self.out.base = Some(BaseState::of(state));
        } else if let Some(level) = self.out.levels.last_mut() {
            level.rounds.push(core::mem::take(&mut self.round));
        }
        if self.hash_rounds {
            self.out.cpu_hashes.push(state.state_hash());
        }
        self.begin_round(state);
    }

    fn split(&mut self, r: u32, record: &SplitRecord) {
        match self.rank(r) {
            Some(i) => self.round.flags[i as usize / 32] |= 1 << (i % 32),
            None => self.out_of_order = true,
        }
        self.round.records.push(gpu_record(record));
    }
}
