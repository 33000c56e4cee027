//! The CPU side of GPU decoding, phase 1: decoder-core reads the stream
//! (headers, chunks, entropy decoding, records with resolved positions) and
//! applies every round itself; a [`Capture`] keeps each round's flags and
//! records so that the GPU can replay the same rounds ([`super::replay`]).
//!
//! The level framing follows decoder-core's `Decoder` (SPEC §10.3 order),
//! rebuilt from its public pieces because `Decoder` does not let a caller
//! wrap the record source of its rounds.

use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::record::{StreamSource, read_base};
use splitstream_decoder_core::substream::Substreams;
use splitstream_decoder_core::{Error, Header, Inflater, LevelTable, MeshState, Ring, layout_for};

use super::capture::{Capture, CapturedRound};

/// The seed mesh as decoder-core holds it after reading it (SPEC §6.3).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BaseState {
    pub positions: Vec<[u32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub deficits: Vec<u8>,
    pub bits: u8,
}

impl BaseState {
    /// A copy of `state`'s normative arrays.
    pub fn of(state: &MeshState<'_>) -> BaseState {
        BaseState {
            positions: state.positions().to_vec(),
            triangles: state.triangles().to_vec(),
            deficits: state.deficits().to_vec(),
            bits: state.bits(),
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
    let header = Header::parse(stream)?;
    let table = LevelTable::parse(stream, &header)?;
    let layout = splitstream_decoder_core::declared_layout(&header, &table)?;
    out.vertex_capacity = layout.vertex_capacity;
    out.triangle_capacity = layout.triangle_capacity;
    let full = layout_for(&header, &table, header.level_count - 1);
    let len = usize::try_from(full.bytes_unaligned()).map_err(|_| Error::CapacityExceeded)?;
    // The same bound as decoder-core's OwnedWorkspace: no absurd allocation
    // from a hostile header.
    let limit = table
        .stream_len()
        .saturating_mul(splitstream_decoder_core::owned::MAX_WORKSPACE_PER_STREAM_BYTE)
        .saturating_add(1 << 20);
    if len as u64 > limit {
        return Err(Error::CapacityExceeded.into());
    }
    let mut workspace = vec![0u8; len];
    let (memory, mut buffers) = full.carve(&mut workspace)?;
    let mut state = MeshState::new(memory, header.bits);
    let mut inflater = Box::new(Inflater::new());
    let mut ring = Box::new(Ring::default());
    for k in 0..header.level_count {
        let info = table.get(k);
        let bytes = usize::try_from(info.offset)
            .ok()
            .and_then(|s| stream.get(s..s.checked_add(info.length as usize)?))
            .ok_or(Error::Truncated)?;
        // SPEC §5.1: the level header against the table entry.
        let is_base = k == 0;
        let level_header = table.level_header(k, bytes, header.max_chunk_len)?;
        state.set_triangle_limit(info.triangle_count);
        if is_base {
            let slots = buffers.each_mut().map(|b| &mut **b);
            let mut seed = Substreams::open(
                bytes,
                level_header,
                substream::BASE_POSITIONS,
                slots,
                &mut inflater,
                header.lane_count,
            );
            let (v, t) = (level_header.seed_vertices, level_header.seed_triangles);
            read_base(&mut state, &mut seed, v, t)?;
            out.base = Some(BaseState::of(&state));
            if hash_rounds {
                out.cpu_hashes.push(state.state_hash());
            }
        }
        out.levels.push(CapturedLevel {
            triangle_limit: info.triangle_count,
            rounds: Vec::new(),
        });
        let slots = buffers.each_mut().map(|b| &mut **b);
        let mut subs = Substreams::open(
            bytes,
            level_header,
            substream::FLAGS,
            slots,
            &mut inflater,
            header.lane_count,
        );
        for r in 0..level_header.round_count {
            let source = StreamSource::new(&mut subs, header.position_mode);
            let mut capture = Capture::new(source);
            state
                .run_round(level_header.split_count(r), &mut capture, &mut ring)
                .map_err(|e| match e {
                    Error::FlagCountMismatch { .. } => Error::FlagCountMismatch { round: r },
                    other => other,
                })?;
            if capture.out_of_order {
                return Err(CaptureError::FlagOrder);
            }
            let round = capture.take_round();
            if let Some(level) = out.levels.last_mut() {
                level.rounds.push(round);
            }
            if hash_rounds {
                out.cpu_hashes.push(state.state_hash());
            }
        }
        // SPEC §7.6: end of level.
        subs.finish()?;
        if state.vertex_count() != info.vertex_count
            || state.triangle_count() != info.triangle_count
        {
            return Err(Error::LevelCountMismatch.into());
        }
    }
    Ok(())
}
