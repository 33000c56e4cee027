//! The stream decoder: levels in order, rounds within a level (SPEC §7.6).

use crate::Error;
use crate::header::Header;
use crate::inflate::Inflater;
use crate::layout::Layout;
use crate::level_header::LevelHeader;
use crate::level_table::{LevelInfo, LevelTable};
use crate::limits::substream::{self, SLOTS};
use crate::pipe::{PendingSplits, RecordPipe, RecordsHalf};

/// The flags' slot among a level's refinement substreams (ids 1..=7).
const FLAGS_SLOT: usize = 0;
use crate::record::{RecordScratch, StreamSource, read_base};
use crate::ring::Ring;
use crate::round::{RecordSource, RoundStats};
use crate::split::{SplitOutcome, SplitRecord};
use crate::state::MeshState;
use crate::substream::Substreams;

/// Sees every flag and split record as the decoder reads them (SPEC §7.3,
/// §7.4), with the state they are read against: for tools that study a
/// stream (the `split_fields` example) or mirror its rounds (sdk-native's
/// GPU capture), through [`LevelDecoder::next_round_observed`]. Nothing it
/// does changes decoding.
pub trait SplitObserver {
    /// The flag of `v`, read from the stream (not inferred: a vertex whose
    /// flag the format infers is not shown, §7.2). `state` is as the flag
    /// saw it.
    #[inline(always)]
    fn flag(&mut self, state: &MeshState<'_>, v: u32, flag: bool) {
        let _ = (state, v, flag);
    }

    /// The record of the split of `r`, whose canonical ring is `ring`, read
    /// and not applied yet: `state` is as the record saw it.
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring, record: &SplitRecord);
}

/// Observes nothing: [`LevelDecoder::next_round`].
impl SplitObserver for () {
    #[inline(always)]
    fn record(&mut self, _: &MeshState<'_>, _: u32, _: &Ring, _: &SplitRecord) {}
}

/// The stream's records, each shown to an observer before it is applied.
struct Observed<'o, S, O> {
    source: S,
    observer: &'o mut O,
}

impl<S: RecordSource, O: SplitObserver> RecordSource for Observed<'_, S, O> {
    #[inline(always)]
    fn flag(&mut self, state: &MeshState<'_>, v: u32) -> Result<bool, Error> {
        let flag = self.source.flag(state, v)?;
        self.observer.flag(state, v, flag);
        Ok(flag)
    }

    #[inline(always)]
    fn record(&mut self, state: &MeshState<'_>, r: u32, ring: &Ring) -> Result<SplitRecord, Error> {
        let record = self.source.record(state, r, ring)?;
        self.observer.record(state, r, ring, &record);
        Ok(record)
    }

    #[inline(always)]
    fn applied(&mut self, r: u32, c: u32, outcome: &SplitOutcome) {
        self.source.applied(r, c, outcome);
    }

    #[inline(always)]
    fn likely_flags(&mut self, state: &MeshState<'_>, upcoming: &[u32]) -> u128 {
        self.source.likely_flags(state, upcoming)
    }
}

/// What one finished round did, with the counts after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RoundInfo {
    pub level: u16,
    pub round: u32,
    pub stats: RoundStats,
    pub vertex_count: u32,
    pub triangle_count: u32,
}

/// Decodes a stream level by level into a caller-owned workspace.
///
/// Levels are fed as byte slices (each fetched by its own range request if
/// need be), in order. When the workspace is smaller than the whole stream
/// needs, the decoder holds as many levels as fit and [`Decoder::next_level`]
/// returns `None` after the last of them (SPEC §9).
pub struct Decoder<'h, 'ws> {
    header: Header,
    table: LevelTable<'h>,
    state: MeshState<'ws>,
    buffers: [&'ws mut [u8]; SLOTS],
    inflater: &'ws mut Inflater,
    ring: Ring,
    next_level: u16,
    levels_that_fit: u16,
    poisoned: bool,
    /// A level was begun and not completed yet.
    level_open: bool,
}

impl<'h, 'ws> Decoder<'h, 'ws> {
    /// Parses the header and level table at the start of `head` (the whole
    /// stream or just its first bytes, see [`Header::head_len`]) and lays the
    /// decoder out in `workspace` (SPEC §3.3, §4.2, §9, the first steps of
    /// §10.3).
    pub fn new(
        head: &'h [u8],
        workspace: &'ws mut [u8],
        inflater: &'ws mut Inflater,
    ) -> Result<Self, Error> {
        let header = Header::parse(head)?;
        let table = LevelTable::parse(head, &header)?;
        declared_layout(&header, &table)?;
        // The largest prefix of levels whose layout fits the workspace.
        let mut fit = header.level_count;
        let layout = loop {
            let layout = layout_for(&header, &table, fit - 1);
            if layout.fits(workspace) {
                break layout;
            }
            fit -= 1;
            if fit == 0 {
                return Err(Error::WorkspaceTooSmall {
                    needed: usize::try_from(layout_for(&header, &table, 0).total)
                        .unwrap_or(usize::MAX),
                    available: workspace.len(),
                });
            }
        };
        let (memory, buffers) = layout.carve(workspace)?;
        Ok(Decoder {
            state: MeshState::new(memory, header.bits, header.schedule),
            header,
            table,
            buffers,
            inflater,
            ring: Ring::default(),
            next_level: 0,
            levels_that_fit: fit,
            poisoned: false,
            level_open: false,
        })
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn level_table(&self) -> &LevelTable<'h> {
        &self.table
    }

    /// Levels (base included) this workspace can hold.
    pub fn levels_that_fit(&self) -> u16 {
        self.levels_that_fit
    }

    /// The level to feed next, or `None` when every level that fits is done.
    pub fn next_level(&self) -> Option<u16> {
        (self.next_level < self.levels_that_fit && !self.poisoned).then_some(self.next_level)
    }

    /// Levels decoded so far (base included).
    pub fn levels_done(&self) -> u16 {
        self.next_level
    }

    /// The current mesh state.
    pub fn state(&self) -> &MeshState<'ws> {
        &self.state
    }

    /// A speed setting: see [`MeshState::set_fans_ahead_from`].
    pub fn set_fans_ahead_from(&mut self, vertices: u32) {
        self.state.set_fans_ahead_from(vertices);
    }

    pub fn positions(&self) -> &[[u32; 3]] {
        self.state.positions()
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        self.state.triangles()
    }

    /// The canonical state hash of SPEC §8.
    pub fn state_hash(&self) -> u64 {
        self.state.state_hash()
    }

    /// Level `k`'s bytes within the whole `stream` (SPEC §4.1).
    pub fn level_bytes<'s>(&self, k: u16, stream: &'s [u8]) -> Result<&'s [u8], Error> {
        let range = self.level_range(k);
        let start = usize::try_from(range.start).map_err(|_| Error::Truncated)?;
        let end = usize::try_from(range.end).map_err(|_| Error::Truncated)?;
        stream.get(start..end).ok_or(Error::Truncated)
    }

    /// The byte range of level `k` in the stream (SPEC §4.1), for a range
    /// request.
    pub fn level_range(&self, k: u16) -> core::ops::Range<u64> {
        let e = self.table.get(k);
        e.offset..e.offset + e.length as u64
    }

    /// Starts level `level` from its bytes (SPEC §5.1); decode its rounds
    /// with [`LevelDecoder::next_round`]. The base level's seed (0, §6.3) is
    /// decoded at once.
    pub fn begin_level<'d, 'l>(
        &'d mut self,
        level: u16,
        bytes: &'l [u8],
    ) -> Result<LevelDecoder<'d, 'l, 'ws>, Error> {
        if self.poisoned {
            return Err(Error::Poisoned);
        }
        if self.level_open {
            // The previous level was dropped half way: its state is mixed.
            self.poisoned = true;
            return Err(Error::Poisoned);
        }
        if level != self.next_level || level >= self.levels_that_fit {
            return Err(Error::LevelOutOfOrder {
                expected: self.next_level,
                got: level,
            });
        }
        let info = self.table.get(level);
        let header = match self
            .table
            .level_header(level, bytes, self.header.level_rules())
        {
            Ok(h) => h,
            Err(e) => {
                self.poisoned = true;
                return Err(e);
            }
        };
        self.state.start_level(info.triangle_count);
        if level == 0 {
            // The seed mesh first (ids 8..=10), then the level's rounds.
            let buffers = self.buffers.each_mut().map(|b| &mut **b);
            let mut subs = Substreams::open(
                bytes,
                header,
                substream::BASE_POSITIONS,
                buffers,
                self.inflater,
                self.header.lane_count,
            );
            let seed = (header.seed_vertices, header.seed_triangles);
            if let Err(e) = read_base(&mut self.state, &mut subs, seed.0, seed.1) {
                self.poisoned = true;
                return Err(e);
            }
        }
        Ok(open_level(self, level, info, header, bytes))
    }

    /// Decodes a whole level: its header, rounds and end (SPEC §5.1, §7.3,
    /// §7.6; see [`Decoder::begin_level`]).
    pub fn decode_level(&mut self, level: u16, bytes: &[u8]) -> Result<(), Error> {
        let mut ld = self.begin_level(level, bytes)?;
        while ld.next_round()?.is_some() {}
        Ok(())
    }

    /// Decodes every level that fits from the whole `stream` (SPEC §9
    /// "Decoding as far as fits", §10.3); returns the number of levels
    /// decoded (base included).
    pub fn decode_available(&mut self, stream: &[u8]) -> Result<u16, Error> {
        while let Some(k) = self.next_level() {
            let result = self
                .level_bytes(k, stream)
                .and_then(|bytes| self.decode_level(k, bytes));
            if let Err(e) = result {
                self.poisoned = true;
                return Err(e);
            }
        }
        Ok(self.next_level)
    }

    /// Real coordinates of a quantized position.
    pub fn dequantize(&self, q: [u32; 3]) -> [f64; 3] {
        self.header.dequantize(q)
    }
}

fn open_level<'d, 'l, 'ws>(
    decoder: &'d mut Decoder<'_, 'ws>,
    level: u16,
    info: LevelInfo,
    header: LevelHeader<'l>,
    bytes: &'l [u8],
) -> LevelDecoder<'d, 'l, 'ws> {
    let buffers = decoder.buffers.each_mut().map(|b| &mut **b);
    let lanes = decoder.header.lane_count;
    let subs = Substreams::open(
        bytes,
        header,
        substream::FLAGS,
        buffers,
        decoder.inflater,
        lanes,
    );
    LevelDecoder {
        level,
        info,
        header,
        round: 0,
        splits: header.split_counts(),
        mode: decoder.header.position_mode,
        state: &mut decoder.state,
        subs,
        ring: &mut decoder.ring,
        next_level: &mut decoder.next_level,
        poisoned: &mut decoder.poisoned,
        level_open: {
            decoder.level_open = true;
            &mut decoder.level_open
        },
        done: false,
    }
}

/// Decodes one level round by round; a viewer may draw between rounds.
pub struct LevelDecoder<'d, 'l, 'ws> {
    level: u16,
    info: LevelInfo,
    header: LevelHeader<'l>,
    round: u32,
    /// The split counts of the rounds not yet decoded (SPEC §5.1).
    splits: crate::SplitCounts<'l>,
    mode: crate::header::PositionMode,
    state: &'d mut MeshState<'ws>,
    subs: Substreams<'l, 'd>,
    ring: &'d mut Ring,
    next_level: &'d mut u16,
    poisoned: &'d mut bool,
    level_open: &'d mut bool,
    done: bool,
}

impl<'d, 'l, 'ws> LevelDecoder<'d, 'l, 'ws> {
    /// Decodes the next round (SPEC §7.3); `None` once the level is complete
    /// and verified (§7.6).
    pub fn next_round(&mut self) -> Result<Option<RoundInfo>, Error> {
        self.next_round_observed(&mut ())
    }

    /// [`LevelDecoder::next_round`], showing `observer` every split record
    /// of the round before it is applied.
    pub fn next_round_observed<O: SplitObserver>(
        &mut self,
        observer: &mut O,
    ) -> Result<Option<RoundInfo>, Error> {
        if *self.poisoned {
            return Err(Error::Poisoned);
        }
        if self.done {
            return Ok(None);
        }
        if self.round == self.header.round_count {
            return match self.complete() {
                Ok(()) => Ok(None),
                Err(e) => {
                    *self.poisoned = true;
                    Err(e)
                }
            };
        }
        let declared = self.splits.next().unwrap_or(0);
        let mut source = Observed {
            source: StreamSource::new(&mut self.subs, self.mode),
            observer,
        };
        let result = self.state.run_round(declared, &mut source, self.ring);
        self.round_done(result)
    }

    /// The round's outcome: its counts, or the error, which poisons the
    /// decoder.
    fn round_done(
        &mut self,
        result: Result<RoundStats, Error>,
    ) -> Result<Option<RoundInfo>, Error> {
        match result {
            Ok(stats) => {
                let info = RoundInfo {
                    level: self.level,
                    round: self.round,
                    stats,
                    vertex_count: self.state.vertex_count(),
                    triangle_count: self.state.triangle_count(),
                };
                self.round += 1;
                Ok(Some(info))
            }
            Err(e) => {
                *self.poisoned = true;
                Err(match e {
                    Error::FlagCountMismatch { .. } => {
                        Error::FlagCountMismatch { round: self.round }
                    }
                    other => other,
                })
            }
        }
    }

    /// Moves the level's record substreams into a [`RecordsHalf`] that
    /// reads them with `inflater` and keeps its own copy of the positions in
    /// `positions` (at least the decoder's vertex capacity; the current
    /// positions are copied in): the records can then be read on another
    /// thread while [`LevelDecoder::next_round_piped`] runs the rounds here
    /// (see [`crate::pipe`]). Give them back with
    /// [`LevelDecoder::join_records`] before the level ends.
    pub fn split_records(
        &mut self,
        inflater: &'d mut Inflater,
        positions: &'d mut [[u32; 3]],
    ) -> Result<RecordsHalf<'l, 'd>, Error> {
        let n = self.state.vertex_count() as usize;
        if positions.len() < self.state.vertex_capacity() as usize {
            return Err(Error::CapacityExceeded);
        }
        positions[..n].copy_from_slice(self.state.positions());
        let source = StreamSource::new(&mut self.subs, self.mode);
        let coding = source.coding();
        Ok(RecordsHalf {
            subs: self.subs.split_off(FLAGS_SLOT, inflater),
            coding,
            scratch: RecordScratch::default(),
            ring: Ring::default(),
            positions,
            bits: self.state.bits(),
            failed: None,
        })
    }

    /// Takes back the record substreams of [`LevelDecoder::split_records`];
    /// [`LevelDecoder::next_round`] then ends the level (SPEC §7.6).
    pub fn join_records(&mut self, records: RecordsHalf<'l, 'd>) {
        self.subs.join(FLAGS_SLOT, records.subs);
    }

    /// Decodes the next round (SPEC §7.3) with its records read through
    /// `pipe` by the [`RecordsHalf`] of [`LevelDecoder::split_records`],
    /// holding up to `pending` splits whose records are on their way.
    /// `None` once the rounds are all done: join the records and call
    /// [`LevelDecoder::next_round`] to end the level. Every round ends in
    /// the state [`LevelDecoder::next_round`] gives, and fails with the
    /// same error.
    pub fn next_round_piped<P: RecordPipe>(
        &mut self,
        pipe: &mut P,
        pending: &mut PendingSplits<'_>,
    ) -> Result<Option<RoundInfo>, Error> {
        if *self.poisoned {
            return Err(Error::Poisoned);
        }
        if self.done || self.round == self.header.round_count {
            return Ok(None);
        }
        let declared = self.splits.next().unwrap_or(0);
        let mut source = StreamSource::new(&mut self.subs, self.mode);
        let result = self
            .state
            .run_round_piped(declared, &mut source, pipe, self.ring, pending);
        self.round_done(result)
    }

    /// The mesh state as of the last round.
    pub fn state(&self) -> &MeshState<'ws> {
        self.state
    }

    fn complete(&mut self) -> Result<(), Error> {
        self.subs.finish()?;
        if self.state.vertex_count() != self.info.vertex_count
            || self.state.triangle_count() != self.info.triangle_count
        {
            return Err(Error::LevelCountMismatch);
        }
        self.done = true;
        *self.level_open = false;
        *self.next_level += 1;
        Ok(())
    }
}

/// The layout of the whole stream, checked against the header's declared
/// `workspace_bytes` (SPEC §9).
pub fn declared_layout(header: &Header, table: &LevelTable<'_>) -> Result<Layout, Error> {
    let full = layout_for(header, table, header.level_count - 1);
    if full.total != header.workspace_bytes {
        return Err(Error::InvalidHeader(
            "declared workspace size differs from SPEC §9",
        ));
    }
    Ok(full)
}

/// Layout for decoding levels `0 ..= last` of a stream (SPEC §9).
pub fn layout_for(header: &Header, table: &LevelTable<'_>, last: u16) -> Layout {
    let base = table.get(0);
    let top = table.get(last);
    Layout::new(
        top.vertex_count,
        top.triangle_count,
        base.vertex_count,
        base.triangle_count,
        header.max_chunk_len,
    )
}
