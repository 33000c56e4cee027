//! Writing streams (SPEC §3–§5), the inverse of the parsers: used by the
//! encoder and by tests that build streams by hand. Needs the `alloc` feature.

use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;
use core::ops::Range;

use crate::bytes::crc32;
use crate::context::{self, DeficitContexts};
use crate::deflate_trial::DeflateTrial;
use crate::header::{Framing, Header, PositionMode, Schedule};
use crate::layout::{Layout, RANS_SLOT_BYTES};
use crate::level_header::ChunkEntry;
use crate::level_table::{LevelInfo, fixed_head_len, write_level_table};
use crate::limits::{
    CHUNK_ENTRY_LEN, HEADER_LEN, MAX_COMPACT_LEVELS, VERSION_MINOR_ADAPTIVE,
    VERSION_MINOR_BASELINE, VERSION_MINOR_COMPACT, VERSION_MINOR_COMPACT_TABLE,
    VERSION_MINOR_DEFICITS, VERSION_MINOR_HEIGHT, VERSION_MINOR_RANS_CHUNKS, VERSION_MINOR_RECORDS,
    VERSION_MINOR_SCHEDULE, VERSION_MINOR_SPLIT_HISTORY, VERSION_MINOR_TIES, VERSION_MINOR_WINGS,
    codec, substream,
};
use crate::positions_first::{RecordOrder, Ties};
use crate::predict::PlanePolicy;
use crate::rans_segments::rans_segments;
use crate::rans_writer::{
    ChunkTables, Symbol, encode_chunk_with, estimated_chunk_len, push_varint,
};
use crate::wing_order::WingPolicy;

/// A growing substream: bytes, bits (least significant first) or varints
/// for the byte codecs (SPEC §5.4), and the same values with their contexts
/// for rANS (SPEC §5.5). The plain methods use context 0; the `_in` methods
/// take the context the decoder will compute (see [`crate::context`]).
#[derive(Clone, Debug, Default)]
pub struct SubstreamWriter {
    bytes: Vec<u8>,
    bit_count: u8,
    symbols: Vec<Symbol>,
    /// What costing its rANS chunks last found ([`coded_len_under`]).
    plan: Option<Box<RansPlan>>,
    /// The chunks the rANS codec's deflate trial coded in costing
    /// ([`coded_len_under`]), for framing or costing it again.
    trial: Option<Box<DeflateTrial>>,
}

/// Two substreams are equal when they hold the same values: a plan is
/// what costing found from them.
impl PartialEq for SubstreamWriter {
    fn eq(&self, other: &Self) -> bool {
        (&self.bytes, self.bit_count, &self.symbols)
            == (&other.bytes, other.bit_count, &other.symbols)
    }
}

impl Eq for SubstreamWriter {}

/// A substream's rANS chunks (SPEC §5.2, §5.5) as [`coded_len_under`]
/// costed them: where it cuts them (`rans_segments`) and the tables it
/// chose for each (`rans_writer::ChunkTables`). An encoder
/// costs the alternative it writes (a plane policy's residuals, a choice of
/// contexts) before it frames it, or costs it twice; both then find the
/// same cuts and tables here instead of again, and write the same bytes.
/// It holds for the substream's first `values` values (values are only
/// appended), `contexts` tables, `lanes` lanes and chunks of at most
/// `limit` values.
#[derive(Clone, Debug)]
struct RansPlan {
    contexts: usize,
    lanes: usize,
    limit: usize,
    values: usize,
    /// Whether adaptive tables were allowed in costing.
    adaptive_tables: bool,
    /// The chunks' estimated payload bytes.
    payloads: usize,
    chunks: Vec<(Range<usize>, ChunkTables)>,
}

impl SubstreamWriter {
    /// An empty substream with room for `values` values of `bytes` bytes
    /// in all (an encoder that knows a level's split count saves the
    /// copies of growing its substreams).
    pub fn with_capacity(values: usize, bytes: usize) -> SubstreamWriter {
        SubstreamWriter {
            bytes: Vec::with_capacity(bytes),
            bit_count: 0,
            symbols: Vec::with_capacity(values),
            plan: None,
            trial: None,
        }
    }

    pub fn byte(&mut self, b: u8) {
        self.byte_in(0, b);
    }

    pub fn bit(&mut self, bit: bool) {
        self.bit_in(0, bit);
    }

    pub fn varint(&mut self, v: u32) {
        self.varint_in(0, v);
    }

    pub fn signed(&mut self, v: i32) {
        self.signed_in(0, v);
    }

    pub fn byte_in(&mut self, context: u8, b: u8) {
        debug_assert_eq!(
            self.bit_count, 0,
            "bytes and bits do not mix in one substream"
        );
        self.bytes.push(b);
        self.symbols.push((context, b as u32));
    }

    pub fn bit_in(&mut self, context: u8, bit: bool) {
        self.symbols.push((context, bit as u32));
        if self.bit_count == 0 {
            self.bytes.push(0);
        }
        if bit {
            *self.bytes.last_mut().expect("pushed above") |= 1 << self.bit_count;
        }
        self.bit_count = (self.bit_count + 1) % 8;
    }

    /// Minimal LEB128 (SPEC §5.4).
    pub fn varint_in(&mut self, context: u8, mut v: u32) {
        self.symbols.push((context, v));
        loop {
            let low = (v & 0x7F) as u8;
            v >>= 7;
            if v == 0 {
                self.bytes.push(low);
                return;
            }
            self.bytes.push(low | 0x80);
        }
    }

    /// Zigzag then LEB128 (SPEC §5.4).
    pub fn signed_in(&mut self, context: u8, v: i32) {
        self.varint_in(context, ((v << 1) ^ (v >> 31)) as u32);
    }

    /// The values with their contexts, as rANS codes them.
    pub fn symbols(&self) -> &[Symbol] {
        &self.symbols
    }

    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes
    }

    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty() && self.symbols.is_empty()
    }

    /// Takes the deflate trial `other` kept (the chunks coded to weigh
    /// deflate against rANS, [`coded_len_under`]) where `other` holds the
    /// same bytes: a level's flags are written under two choices of
    /// contexts, in the same bits.
    pub fn share_deflate_trial(&mut self, other: &SubstreamWriter) {
        let same = self.symbols.len() == other.symbols.len() && self.bytes == other.bytes;
        if let Some(trial) = other.trial.as_deref().filter(|_| same) {
            self.trial = Some(Box::new(trial.clone()));
        }
    }

    /// Its deflate trial in chunks of at most `limit` raw bytes: the one
    /// costing kept where it holds for its values as they are now, or a
    /// fresh one.
    fn trial_for(&self, limit: usize) -> DeflateTrial {
        let values = self.symbols.len();
        match self.trial.as_deref() {
            Some(trial) if trial.holds(values, limit) => trial.clone(),
            _ => DeflateTrial::new(values, limit),
        }
    }

    /// The level-10 deflate chunks (of at most `limit` raw bytes) that the
    /// rANS codec writes instead of its rANS chunks of `rans` payload bytes,
    /// if it does ([`DeflateTrial::deflate_instead`]); the chunks coded to
    /// find out are kept with it.
    fn deflate_instead(&mut self, limit: usize, rans: usize) -> Option<&[Chunk]> {
        let values = self.symbols.len();
        if !self
            .trial
            .as_deref()
            .is_some_and(|t| t.holds(values, limit))
        {
            self.trial = Some(Box::new(DeflateTrial::new(values, limit)));
        }
        let trial = self.trial.as_deref_mut().expect("kept above");
        trial.deflate_instead(&self.bytes, rans)
    }

    /// The plan of its rANS chunks in `contexts` tables, `lanes` lanes and
    /// chunks of at most `limit` values, if costing left one for its
    /// values as they are now.
    fn plan_for(&self, contexts: usize, lanes: usize, limit: usize) -> Option<&RansPlan> {
        let plan = self.plan.as_deref()?;
        let key = (contexts, lanes, limit, self.symbols.len());
        (key == (plan.contexts, plan.lanes, plan.limit, plan.values)).then_some(plan)
    }

    /// Its rANS chunks' estimated payload bytes and count, with
    /// `adaptive_tables` allowed or not, kept as its plan: the plan left by
    /// an earlier costing where it holds, or else its cuts where only
    /// `adaptive_tables` differs.
    fn costed_rans(
        &mut self,
        contexts: usize,
        lanes: usize,
        limit: usize,
        adaptive_tables: bool,
    ) -> (usize, usize) {
        let kept = self.plan_for(contexts, lanes, limit);
        if let Some(plan) = kept.filter(|p| p.adaptive_tables == adaptive_tables) {
            return (plan.payloads, plan.chunks.len());
        }
        let symbols = &self.symbols;
        let segments = match kept {
            Some(plan) => plan.chunks.iter().map(|(r, _)| r.clone()).collect(),
            None => rans_segments(symbols, contexts, lanes, limit),
        };
        let mut payloads = 0;
        let chunks: Vec<(Range<usize>, ChunkTables)> = segments
            .into_iter()
            .map(|range| {
                let values = &symbols[range.clone()];
                let (len, tables) = estimated_chunk_len(values, contexts, lanes, adaptive_tables);
                payloads += len;
                (range, tables)
            })
            .collect();
        let count = chunks.len();
        self.plan = Some(Box::new(RansPlan {
            contexts,
            lanes,
            limit,
            values: symbols.len(),
            adaptive_tables,
            payloads,
            chunks,
        }));
        (payloads, count)
    }
}

/// How chunks are coded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChunkCodec {
    Stored,
    /// Raw deflate at this miniz_oxide level (1..=10).
    Deflate(u8),
    /// rANS with this many lanes (1..=32); a substream whose deflate form
    /// is smaller is written with deflate (level 10) instead.
    Rans {
        lanes: u8,
    },
    /// rANS for every substream, even where deflate or stored is smaller
    /// (test streams and conformance vectors).
    RansAlways {
        lanes: u8,
    },
}

impl ChunkCodec {
    /// The header's lane count (SPEC §3.2): 1 unless rANS.
    pub fn lane_count(&self) -> u8 {
        match self {
            ChunkCodec::Rans { lanes } | ChunkCodec::RansAlways { lanes } => *lanes,
            _ => 1,
        }
    }
}

/// One level's content before framing.
///
/// A base level given to [`write_stream`] holds just the seed mesh: its
/// `substreams` are ids 8..=10 and it has no rounds. [`write_stream_seeded`]
/// takes the seed separately, so that level 0 can also carry rounds.
#[derive(Clone, Debug, Default)]
pub struct LevelPayload {
    /// Declared split count of each round.
    pub round_splits: Vec<u32>,
    /// The level's plane policy (SPEC §5.1, §7.4).
    pub plane: PlanePolicy,
    /// The level's wing policy (SPEC §5.1, §7.4; 3.2).
    pub wings: WingPolicy,
    /// The contexts of the level's split-valence symbols (SPEC §5.1,
    /// §5.5.5; 3.3): they also set how many tables deficit-p and deficit-c
    /// have.
    pub deficits: DeficitContexts,
    /// How the level's records are read (SPEC §5.1, §7.4; 3.7): it also
    /// sets how many tables edge and placement have.
    pub records: RecordOrder,
    /// Under `positions-first`, how the wing choices' ties are broken
    /// (SPEC §5.1, §7.4; 3.8).
    pub ties: Ties,
    /// Substreams in id order: ids 1..=7 for rounds (index 0 is id 1), or
    /// ids 8..=10 for a base level given to [`write_stream`].
    pub substreams: Vec<SubstreamWriter>,
    pub vertex_count: u32,
    pub triangle_count: u32,
    pub geometric_error: f32,
}

/// The reference encoder's longest rANS chunk, in values. Chunks are cut
/// shorter where their own tables pay for themselves (`rans_segments`);
/// on a 1M-vertex terrain the longest substream of the last level holds 3
/// million values.
pub const DEFAULT_RANS_CHUNK_LIMIT: u32 = 1 << 18;

/// Stream-wide parameters.
#[derive(Clone, Copy, Debug)]
pub struct StreamParams {
    pub position_mode: PositionMode,
    pub bits: u8,
    pub origin: [f64; 3],
    pub scale: [f64; 3],
    pub codec: ChunkCodec,
    /// Largest stored or deflate chunk the writer cuts, in raw bytes: the
    /// header's `max_chunk_len`, which sets the decoder's buffers (SPEC §5.2,
    /// §9).
    pub chunk_limit: u32,
    /// Largest rANS chunk the writer cuts, in values. A rANS chunk needs no
    /// buffer of its length (only its tables and lanes), so from format 3.4
    /// it may exceed `max_chunk_len` (SPEC §5.2); smaller chunks have
    /// tables fitted to fewer values and cost more table bytes.
    pub rans_chunk_limit: u32,
    /// Which vertices split in which round (SPEC §3.2 header flag bit 1,
    /// format 3.6).
    pub schedule: Schedule,
    /// Whether rANS chunks may code a context with an adaptive table where
    /// that is smaller (SPEC §5.5.2, format 3.9). Without, the stream stays
    /// readable by 3.8 decoders.
    pub adaptive_tables: bool,
    /// How the level headers and the level table are laid out (SPEC §3.2
    /// header flag bits 2 and 3, §4.3, §5.1.1, formats 3.11 and 3.12).
    /// `CompactLevels` keeps the stream readable by 3.11 decoders, `Fixed`
    /// by 3.10 ones. A stream of more than 255 levels gets `CompactLevels`
    /// for `Compact` (SPEC §3.3).
    pub framing: Framing,
}

impl Default for StreamParams {
    /// The reference encoder's defaults on a unit grid: optimal positions,
    /// 14 bits, rANS in 4 lanes, byte-codec chunks of 16 KiB and rANS
    /// chunks of up to [`DEFAULT_RANS_CHUNK_LIMIT`] values.
    fn default() -> Self {
        StreamParams {
            position_mode: PositionMode::Optimal,
            bits: 14,
            origin: [0.0; 3],
            scale: [1.0; 3],
            codec: ChunkCodec::Rans { lanes: 4 },
            chunk_limit: 16 * 1024,
            rans_chunk_limit: DEFAULT_RANS_CHUNK_LIMIT,
            schedule: Schedule::default(),
            adaptive_tables: true,
            framing: Framing::Compact,
        }
    }
}

/// The seed mesh of level 0 (SPEC §6.3): counts and substreams 8..=10.
#[derive(Clone, Debug, Default)]
pub struct SeedPayload {
    pub vertices: u32,
    pub triangles: u32,
    pub substreams: Vec<SubstreamWriter>,
}

impl SeedPayload {
    /// The seed substreams of SPEC §6.3: positions as zigzag deltas from the
    /// previous vertex, triangles as varints, one deficit byte per vertex.
    pub fn new(positions: &[[u32; 3]], triangles: &[[u32; 3]], deficits: &[u8]) -> SeedPayload {
        let mut substreams = vec![SubstreamWriter::default(); 3];
        let mut previous = [0i64; 3];
        for p in positions {
            for k in 0..3 {
                substreams[0].signed_in(context::axis(k), (p[k] as i64 - previous[k]) as i32);
                previous[k] = p[k] as i64;
            }
        }
        for t in triangles {
            for &v in t {
                substreams[1].varint(v);
            }
        }
        for &d in deficits {
            substreams[2].byte(d);
        }
        SeedPayload {
            vertices: positions.len() as u32,
            triangles: triangles.len() as u32,
            substreams,
        }
    }

    /// This seed as a level 0 without rounds, for [`write_stream`].
    pub fn into_level(self, geometric_error: f32) -> LevelPayload {
        LevelPayload {
            round_splits: Vec::new(),
            plane: PlanePolicy::Off,
            wings: WingPolicy::Ranks,
            deficits: DeficitContexts::Plain,
            records: RecordOrder::WingsFirst,
            ties: Ties::Ring,
            vertex_count: self.vertices,
            triangle_count: self.triangles,
            substreams: self.substreams,
            geometric_error,
        }
    }
}

/// One level as [`frame_level`] writes it, with the largest chunks it cut.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FramedLevel {
    pub bytes: Vec<u8>,
    /// Raw bytes of its largest stored or deflate chunk (0 if none).
    pub largest_byte_chunk: u32,
    /// Values of its largest rANS chunk (0 if none).
    pub largest_rans_chunk: u32,
    /// Whether a rANS chunk codes a context with an adaptive table (3.9).
    pub adaptive: bool,
}

/// Frames a base level (seed mesh only) and refinement levels.
pub fn write_stream(params: &StreamParams, levels: &[LevelPayload]) -> Vec<u8> {
    let base = &levels[0];
    let seed = SeedPayload {
        vertices: base.vertex_count,
        triangles: base.triangle_count,
        substreams: base.substreams.clone(),
    };
    let mut rounds = levels.to_vec();
    rounds[0].substreams = Vec::new();
    rounds[0].round_splits = Vec::new();
    write_stream_seeded(params, &seed, &rounds)
}

/// Frames a stream whose level 0 is `seed` followed by the rounds of
/// `levels[0]`; `levels[1..]` are the refinement levels.
pub fn write_stream_seeded(
    params: &StreamParams,
    seed: &SeedPayload,
    levels: &[LevelPayload],
) -> Vec<u8> {
    let framed: Vec<FramedLevel> = levels
        .iter()
        .enumerate()
        .map(|(k, level)| frame_level(level, (k == 0).then_some(seed), params))
        .collect();
    assemble_stream(params, levels, framed)
}

/// The stream of `levels`, already framed by [`frame_level`] (level 0 with
/// its seed): header, level table, levels. Lets a caller frame the levels
/// in parallel.
pub fn assemble_stream(
    params: &StreamParams,
    levels: &[LevelPayload],
    framed: Vec<FramedLevel>,
) -> Vec<u8> {
    // `max_chunk_len` bounds the byte-codec chunks only (SPEC §5.2, 3.4):
    // they are what a decoder buffers. Where the rANS chunks fit under it
    // anyway (the buffers are at least RANS_SLOT_BYTES, §9), it covers them
    // too, so that the stream stays readable by 3.3 decoders for the same
    // memory.
    let largest_byte = framed.iter().map(|f| f.largest_byte_chunk).max();
    let largest_byte = largest_byte.unwrap_or(0);
    let largest_rans = framed.iter().map(|f| f.largest_rans_chunk).max();
    let largest_rans = largest_rans.unwrap_or(0);
    let adaptive = framed.iter().any(|f| f.adaptive);
    let free = largest_byte.max(RANS_SLOT_BYTES as u32);
    let rans_above = largest_rans > free;
    let max_chunk = if rans_above {
        largest_byte
    } else {
        largest_byte.max(largest_rans)
    }
    .max(1);
    let framed: Vec<Vec<u8>> = framed.into_iter().map(|f| f.bytes).collect();
    let level_count = levels.len() as u16;
    let framing = if params.framing.compact_table() && level_count > MAX_COMPACT_LEVELS {
        Framing::CompactLevels
    } else {
        params.framing
    };
    let mut entries: Vec<LevelInfo> = levels
        .iter()
        .zip(&framed)
        .map(|(level, bytes)| LevelInfo {
            offset: 0,
            length: bytes.len() as u32,
            vertex_count: level.vertex_count,
            triangle_count: level.triangle_count,
            round_count: level.round_splits.len() as u32,
            geometric_error: level.geometric_error,
        })
        .collect();
    // A compact table leaves the offsets out, so it is written before
    // them; where it ends, level 0 starts.
    let compact_table = framing
        .compact_table()
        .then(|| compact_level_table(&entries));
    let mut offset = match &compact_table {
        Some(table) => (HEADER_LEN + table.len()) as u64,
        None => fixed_head_len(level_count) as u64,
    };
    for e in &mut entries {
        e.offset = offset;
        offset += e.length as u64;
    }
    let table = compact_table.unwrap_or_else(|| {
        let mut table = vec![0u8; fixed_head_len(level_count) - HEADER_LEN];
        write_level_table(&entries, &mut table);
        table
    });
    let (base, top) = (&levels[0], &levels[levels.len() - 1]);
    let layout = Layout::new(
        top.vertex_count,
        top.triangle_count,
        base.vertex_count,
        base.triangle_count,
        max_chunk,
    );
    // SPEC §1: 3.12 where the level table is compact, 3.11 where the level headers are compact, 3.10 where a level's flags use the contexts
    // `split-history`, 3.9 where a rANS chunk has an adaptive table, 3.8 where a positions-first level breaks ties by a
    // diagonal, 3.7 where a level reads its records positions first, 3.6 where the schedule `every-vertex` is used, 3.4 only where a 3.4 feature (a rANS chunk longer than
    // `max_chunk_len`) is used, 3.3 where a 3.3 feature (the deficit
    // contexts `valence`) is, 3.2 where a 3.2 feature (a wing policy other
    // than `ranks`) is, 3.1 where a 3.1 feature (the plane policy `height`)
    // is; every other stream stays readable by 3.0 decoders.
    let version_minor = if framing.compact_table() {
        VERSION_MINOR_COMPACT_TABLE
    } else if framing.compact_level_headers() {
        VERSION_MINOR_COMPACT
    } else if levels
        .iter()
        .any(|l| l.deficits == DeficitContexts::SplitHistory)
    {
        VERSION_MINOR_SPLIT_HISTORY
    } else if adaptive {
        VERSION_MINOR_ADAPTIVE
    } else if levels
        .iter()
        .any(|l| l.records == RecordOrder::PositionsFirst && l.ties != Ties::Ring)
    {
        VERSION_MINOR_TIES
    } else if levels
        .iter()
        .any(|l| l.records == RecordOrder::PositionsFirst)
    {
        VERSION_MINOR_RECORDS
    } else if params.schedule == Schedule::EveryVertex {
        VERSION_MINOR_SCHEDULE
    } else if rans_above {
        VERSION_MINOR_RANS_CHUNKS
    } else if levels.iter().any(|l| l.deficits != DeficitContexts::Plain) {
        VERSION_MINOR_DEFICITS
    } else if levels.iter().any(|l| l.wings != WingPolicy::Ranks) {
        VERSION_MINOR_WINGS
    } else if levels.iter().any(|l| l.plane == PlanePolicy::Height) {
        VERSION_MINOR_HEIGHT
    } else {
        VERSION_MINOR_BASELINE
    };
    let header = Header {
        version_minor,
        position_mode: params.position_mode,
        schedule: params.schedule,
        framing,
        table_len: table.len() as u32,
        bits: params.bits,
        lane_count: params.codec.lane_count(),
        level_count,
        vertex_capacity: top.vertex_count,
        triangle_capacity: top.triangle_count,
        max_chunk_len: max_chunk,
        origin: params.origin,
        scale: params.scale,
        workspace_bytes: layout.total,
    };
    let mut out = vec![0u8; HEADER_LEN];
    let mut head = [0u8; HEADER_LEN];
    header.write(&mut head);
    out.copy_from_slice(&head);
    out.extend_from_slice(&table);
    for bytes in framed {
        out.extend_from_slice(&bytes);
    }
    out
}

/// A compact level table (SPEC §4.3, 3.12): each entry's length, vertex
/// and triangle steps and round count as varints and its geometric error,
/// then the CRC of the entries. The entries' offsets are not written.
pub fn compact_level_table(entries: &[LevelInfo]) -> Vec<u8> {
    let mut out = Vec::with_capacity(12 * entries.len() + 4);
    let (mut vertices, mut triangles) = (0u32, 0u32);
    for e in entries {
        push_varint(&mut out, e.length);
        push_varint(&mut out, e.vertex_count.wrapping_sub(vertices));
        push_varint(&mut out, e.triangle_count.wrapping_sub(triangles));
        push_varint(&mut out, e.round_count);
        out.extend_from_slice(&e.geometric_error.to_le_bytes());
        (vertices, triangles) = (e.vertex_count, e.triangle_count);
    }
    let crc = crc32(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// Frames one level (SPEC §5.1). `seed` is given for level 0 only.
pub fn frame_level(
    level: &LevelPayload,
    seed: Option<&SeedPayload>,
    params: &StreamParams,
) -> FramedLevel {
    frame_level_with(level, seed, params, &one_by_one)
}

/// Runs `job(i)` for every chunk `i` in `0..n` and returns the chunks in
/// that order: how [`frame_level_with`] codes a substream's chunks, which
/// are independent of each other.
pub type ChunkMap<'a> = &'a (dyn Fn(usize, &(dyn Fn(usize) -> Chunk + Sync)) -> Vec<Chunk> + Sync);

/// The [`ChunkMap`] of [`frame_level`]: one chunk after the other.
pub fn one_by_one(n: usize, job: &(dyn Fn(usize) -> Chunk + Sync)) -> Vec<Chunk> {
    (0..n).map(job).collect()
}

/// [`frame_level`], coding each substream's chunks with `map` (an encoder
/// with threads passes one that codes them in parallel: the bytes are the
/// same).
pub fn frame_level_with(
    level: &LevelPayload,
    seed: Option<&SeedPayload>,
    params: &StreamParams,
    map: ChunkMap<'_>,
) -> FramedLevel {
    let mut directory: Vec<ChunkEntry> = Vec::new();
    let mut payload = Vec::new();
    let (mut largest_byte_chunk, mut largest_rans_chunk) = (0u32, 0u32);
    let mut adaptive = false;
    let rounds = level
        .substreams
        .iter()
        .enumerate()
        .map(|(i, s)| (substream::FLAGS + i as u8, s));
    let base = seed
        .into_iter()
        .flat_map(|s| s.substreams.iter().enumerate())
        .map(|(i, s)| (substream::BASE_POSITIONS + i as u8, s));
    for (id, sub) in rounds.chain(base) {
        let contexts = context::count(id, level.deficits, level.records, params.schedule);
        let chunks = substream_chunks(sub, contexts, params, map);
        for chunk in chunks {
            directory.push(ChunkEntry {
                substream: id,
                codec: chunk.codec,
                raw_len: chunk.raw_len,
                stored_len: chunk.stored.len() as u32,
                crc: crc32(&chunk.stored),
            });
            let largest = if chunk.codec == codec::RANS {
                &mut largest_rans_chunk
            } else {
                &mut largest_byte_chunk
            };
            *largest = (*largest).max(chunk.raw_len);
            adaptive |= chunk.adaptive;
            payload.extend_from_slice(&chunk.stored);
        }
    }
    let mut out = Vec::new();
    let compact = params.framing.compact_level_headers();
    // A count or length: a u32 under the fixed framing (SPEC §5.1), a
    // varint under the compact one (§5.1.1).
    let count = |out: &mut Vec<u8>, v: u32| {
        if compact {
            push_varint(out, v);
        } else {
            out.extend_from_slice(&v.to_le_bytes());
        }
    };
    count(&mut out, level.round_splits.len() as u32);
    count(&mut out, directory.len() as u32);
    out.extend_from_slice(&[
        level.plane.to_byte(),
        level.wings.to_byte(),
        level.deficits.to_byte(),
        level.records.to_byte(level.ties),
    ]);
    if let Some(seed) = seed {
        count(&mut out, seed.vertices);
        count(&mut out, seed.triangles);
    }
    for &s in &level.round_splits {
        count(&mut out, s);
    }
    for e in &directory {
        if compact {
            out.push(e.substream | e.codec << 4);
        } else {
            out.extend_from_slice(&[e.substream, e.codec, 0, 0]);
        }
        count(&mut out, e.raw_len);
        count(&mut out, e.stored_len);
        out.extend_from_slice(&e.crc.to_le_bytes());
    }
    let crc = crc32(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out.extend_from_slice(&payload);
    FramedLevel {
        bytes: out,
        largest_byte_chunk,
        largest_rans_chunk,
        adaptive,
    }
}

/// The chunks of a substream as `frame_level` codes them, in a level whose
/// rANS chunks have `contexts` tables for it (`context::count`): byte-codec
/// chunks of at most `params.chunk_limit` bytes, rANS chunks of at most
/// `params.rans_chunk_limit` values. [`coded_len_under`] costs the same
/// chunks, estimating the rANS lanes instead of coding them
/// (`tests::the_coded_length_is_near_the_framed_one`).
fn substream_chunks(
    sub: &SubstreamWriter,
    contexts: usize,
    params: &StreamParams,
    map: ChunkMap<'_>,
) -> Vec<Chunk> {
    let limit = params.chunk_limit.max(1) as usize;
    let rans_limit = params.rans_chunk_limit.max(1) as usize;
    let rans_in = |lanes: u8| {
        rans_chunks(
            sub,
            rans_limit,
            contexts,
            lanes as usize,
            params.adaptive_tables,
            map,
        )
    };
    match params.codec {
        ChunkCodec::Stored => byte_chunks(sub.as_bytes(), limit, None, map),
        ChunkCodec::Deflate(l) => byte_chunks(sub.as_bytes(), limit, Some(l), map),
        ChunkCodec::Rans { lanes } => {
            let rans = rans_in(lanes);
            let rans_size = rans.iter().map(Chunk::stored_len).sum();
            match sub
                .trial_for(limit)
                .deflate_instead(sub.as_bytes(), rans_size)
            {
                Some(deflate) => deflate.to_vec(),
                None => rans,
            }
        }
        ChunkCodec::RansAlways { lanes } => rans_in(lanes),
    }
}

/// Bytes substream `id` takes in a level framed with `params`, whose deficit
/// contexts are `plain`: its chunk payloads and directory entries. Lets an
/// encoder compare alternatives (the plane policies of SPEC §7.4) by their
/// cost: exact under the byte codecs, and under rANS each lane of a chunk
/// estimated from its values' bits, within a byte of its length
/// (`rans_writer::estimated_chunk_len`). Under rANS it keeps the chunks' cuts and
/// tables in `sub` for framing it or costing it again (`RansPlan`): the
/// same bytes, found once.
pub fn coded_len(sub: &mut SubstreamWriter, id: u8, params: &StreamParams) -> usize {
    coded_len_in(sub, id, DeficitContexts::Plain, params)
}

/// [`coded_len`] in a level whose deficit contexts are `deficits` (they set
/// the table count of deficit-p and deficit-c, SPEC §5.5.5).
pub fn coded_len_in(
    sub: &mut SubstreamWriter,
    id: u8,
    deficits: DeficitContexts,
    params: &StreamParams,
) -> usize {
    coded_len_under(sub, id, deficits, RecordOrder::WingsFirst, params)
}

/// [`coded_len_in`] in a level whose record order is `records` (it sets
/// the table count of edge and placement, SPEC §5.5.5, 3.7).
pub fn coded_len_under(
    sub: &mut SubstreamWriter,
    id: u8,
    deficits: DeficitContexts,
    records: RecordOrder,
    params: &StreamParams,
) -> usize {
    let contexts = context::count(id, deficits, records, params.schedule);
    // The rANS chunks' payloads and count, their lanes estimated, not
    // coded: the same cuts and tables as `substream_chunks`, which
    // `frame_level` writes, and each lane within a byte of its own.
    let limit = params.rans_chunk_limit.max(1) as usize;
    let mut rans_len =
        |lanes: u8| sub.costed_rans(contexts, lanes as usize, limit, params.adaptive_tables);
    let framed = |(payloads, chunks): (usize, usize)| payloads + chunks * CHUNK_ENTRY_LEN;
    let rans = match params.codec {
        ChunkCodec::Rans { lanes } | ChunkCodec::RansAlways { lanes } => Some(rans_len(lanes)),
        ChunkCodec::Stored | ChunkCodec::Deflate(_) => None,
    };
    let byte_codec = |sub: &SubstreamWriter, level: Option<u8>| {
        let chunks = byte_chunks(
            sub.as_bytes(),
            params.chunk_limit.max(1) as usize,
            level,
            &one_by_one,
        );
        (
            chunks.iter().map(|c| c.stored.len()).sum::<usize>(),
            chunks.len(),
        )
    };
    framed(match params.codec {
        ChunkCodec::Stored => byte_codec(sub, None),
        ChunkCodec::Deflate(l) => byte_codec(sub, Some(l)),
        ChunkCodec::RansAlways { .. } => rans.expect("costed above"),
        ChunkCodec::Rans { .. } => {
            let rans = rans.expect("costed above");
            let limit = params.chunk_limit.max(1) as usize;
            match sub.deflate_instead(limit, rans.0) {
                Some(deflate) => (deflate.iter().map(Chunk::stored_len).sum(), deflate.len()),
                None => rans,
            }
        }
    })
}

/// [`coded_len_in`] of a substream that is still being written, costed
/// chunk by chunk as its chunks fill up: an encoder weighing alternatives
/// costs them while it writes them, off its critical path, and only the
/// last chunk is left when the substream is complete. Under the byte codecs
/// each chunk is coded on its own, so the sum is the same number. The rANS
/// codecs are left to [`GrowingCodedLen::finish`]: where their chunks end
/// depends on the whole substream (`rans_segments`), and `Rans`'s deflate
/// trial weighs the whole substream too.
#[derive(Clone, Debug, Default)]
pub struct GrowingCodedLen {
    /// Chunks costed so far (the first ones).
    chunks: usize,
    /// Their payloads and directory entries.
    bytes: usize,
}

impl GrowingCodedLen {
    /// Costs the chunks of `sub` that later values can no longer change.
    pub fn advance(
        &mut self,
        sub: &SubstreamWriter,
        _id: u8,
        _deficits: DeficitContexts,
        params: &StreamParams,
    ) {
        let (units, limit) = match params.codec {
            // Where rANS chunks end depends on the whole substream
            // (`rans_segments`).
            ChunkCodec::Rans { .. } | ChunkCodec::RansAlways { .. } => return,
            // A bit substream's last byte takes more bits.
            ChunkCodec::Stored | ChunkCodec::Deflate(_) => (
                sub.bytes.len() - usize::from(sub.bit_count != 0),
                params.chunk_limit.max(1) as usize,
            ),
        };
        while (self.chunks + 1) * limit <= units {
            self.bytes += single_chunk(sub, self.chunks, params).stored.len() + CHUNK_ENTRY_LEN;
            self.chunks += 1;
        }
    }

    /// [`coded_len_in`] of the complete substream `sub`, the one advanced.
    pub fn finish(
        &self,
        sub: &mut SubstreamWriter,
        id: u8,
        deficits: DeficitContexts,
        params: &StreamParams,
    ) -> usize {
        let count = match params.codec {
            ChunkCodec::Rans { .. } | ChunkCodec::RansAlways { .. } => {
                return coded_len_in(sub, id, deficits, params);
            }
            ChunkCodec::Stored | ChunkCodec::Deflate(_) => {
                sub.bytes.len().div_ceil(params.chunk_limit.max(1) as usize)
            }
        };
        self.bytes
            + (self.chunks..count)
                .map(|i| single_chunk(sub, i, params).stored.len() + CHUNK_ENTRY_LEN)
                .sum::<usize>()
    }
}

/// Chunk `i` of `sub` under a byte codec (stored or deflate: each chunk is
/// coded on its own, `limit` bytes long but the last).
fn single_chunk(sub: &SubstreamWriter, i: usize, params: &StreamParams) -> Chunk {
    let limit = params.chunk_limit.max(1) as usize;
    let level = match params.codec {
        ChunkCodec::Deflate(l) => Some(l),
        _ => None,
    };
    byte_chunk(&sub.bytes, limit, level, i)
}

/// One coded chunk before framing.
#[derive(Clone, Debug)]
pub struct Chunk {
    codec: u8,
    raw_len: u32,
    stored: Vec<u8>,
    /// A rANS chunk with an adaptive table (3.9).
    adaptive: bool,
}

impl Chunk {
    /// Its payload bytes.
    pub(crate) fn stored_len(&self) -> usize {
        self.stored.len()
    }
}

/// Byte-codec chunks of at most `limit` raw bytes; deflated at `level` where
/// that is smaller than storing.
fn byte_chunks(bytes: &[u8], limit: usize, level: Option<u8>, map: ChunkMap<'_>) -> Vec<Chunk> {
    map(bytes.len().div_ceil(limit), &|i| {
        byte_chunk(bytes, limit, level, i)
    })
}

/// Chunk `i` of [`byte_chunks`].
pub(crate) fn byte_chunk(bytes: &[u8], limit: usize, level: Option<u8>, i: usize) -> Chunk {
    let raw = &bytes[i * limit..bytes.len().min((i + 1) * limit)];
    let packed = level.map(|l| miniz_oxide::deflate::compress_to_vec(raw, l));
    match packed {
        Some(p) if p.len() < raw.len() => Chunk {
            codec: codec::DEFLATE,
            raw_len: raw.len() as u32,
            stored: p,
            adaptive: false,
        },
        _ => Chunk {
            codec: codec::STORED,
            raw_len: raw.len() as u32,
            stored: raw.to_vec(),
            adaptive: false,
        },
    }
}

/// rANS chunks of at most `limit` values each, `contexts` tables each
/// (SPEC §5.5), cut where [`rans_segments`] estimates the substream
/// smallest: the cuts and tables of `sub`'s plan where costing left one.
fn rans_chunks(
    sub: &SubstreamWriter,
    limit: usize,
    contexts: usize,
    lanes: usize,
    adaptive_tables: bool,
    map: ChunkMap<'_>,
) -> Vec<Chunk> {
    let symbols = sub.symbols();
    let plan = sub.plan_for(contexts, lanes, limit);
    let segments = match plan {
        Some(plan) => plan.chunks.iter().map(|(r, _)| r.clone()).collect(),
        None => rans_segments(symbols, contexts, lanes, limit),
    };
    map(segments.len(), &|i| {
        let values = &symbols[segments[i].clone()];
        let chosen = plan.map(|p| &p.chunks[i].1);
        let (stored, adaptive) =
            encode_chunk_with(values, contexts, lanes, adaptive_tables, chosen);
        Chunk {
            codec: codec::RANS,
            raw_len: values.len() as u32,
            stored,
            adaptive,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::substream;
    use proptest::prelude::*;

    proptest! {
        /// `coded_len_under` estimates the rANS lanes instead of writing
        /// them: its length is that of the chunks `frame_level` writes
        /// under the byte codecs, and within a byte a lane of each rANS
        /// chunk under the rANS codecs (whichever codec `Rans` then
        /// takes), with and without adaptive tables.
        #[test]
        fn the_coded_length_is_near_the_framed_one(
            values in proptest::collection::vec((any::<u8>(), -3000i32..3000), 0..600),
            skew in 1i32..3000,
            codec_choice in 0u8..6,
            adaptive_tables in any::<bool>(),
            chunk_limit in 1u32..300,
            rans_chunk_limit in 1u32..300,
        ) {
            let codec = match codec_choice {
                0 => ChunkCodec::Stored,
                1 => ChunkCodec::Deflate(1),
                2 => ChunkCodec::Deflate(10),
                3 => ChunkCodec::RansAlways { lanes: 1 },
                4 => ChunkCodec::RansAlways { lanes: 4 },
                _ => ChunkCodec::Rans { lanes: 2 },
            };
            let params = StreamParams {
                codec,
                chunk_limit,
                rans_chunk_limit,
                adaptive_tables,
                ..StreamParams::default()
            };
            let mut sub = SubstreamWriter::default();
            for &(ctx, v) in &values {
                sub.signed_in(ctx % 3, v % skew);
            }
            let contexts = context::count(
                substream::EDGE,
                DeficitContexts::Plain,
                RecordOrder::WingsFirst,
                params.schedule,
            );
            let framed: usize = substream_chunks(&sub, contexts, &params, &one_by_one)
                .iter()
                .map(|c| c.stored.len() + CHUNK_ENTRY_LEN)
                .sum();
            let lanes = match codec {
                ChunkCodec::RansAlways { lanes } | ChunkCodec::Rans { lanes } => lanes as usize,
                ChunkCodec::Stored | ChunkCodec::Deflate(_) => 0,
            };
            let rans_chunks =
                rans_segments(sub.symbols(), contexts, lanes, rans_chunk_limit as usize).len();
            let coded = coded_len(&mut sub, substream::EDGE, &params);
            prop_assert!(
                coded.abs_diff(framed) <= rans_chunks * lanes,
                "coded {} bytes, framed {}, {} rANS chunks of {} lanes",
                coded,
                framed,
                rans_chunks,
                lanes
            );
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// A substream costed before it is framed (its plan kept: the
        /// chunks' cuts and tables) frames as one never costed: with
        /// adaptive tables allowed in costing or not, in framing or not,
        /// chunks cut by `rans_segments`' blocks or by a small limit, and
        /// values written after the costing (the plan no longer holds).
        #[test]
        fn a_costed_substream_frames_as_a_fresh_one(
            values in proptest::collection::vec((any::<u8>(), -3000i32..3000), 0..12_000),
            skew in 1i32..3000,
            lanes in 1u8..=4,
            rans_always in any::<bool>(),
            adaptive_cost in any::<bool>(),
            adaptive_frame in any::<bool>(),
            small_chunks in any::<bool>(),
            runs in any::<bool>(),
            appended in 0usize..2,
        ) {
            let codec = if rans_always {
                ChunkCodec::RansAlways { lanes }
            } else {
                ChunkCodec::Rans { lanes }
            };
            let rans_chunk_limit = if small_chunks { 300 } else { DEFAULT_RANS_CHUNK_LIMIT };
            let params = |adaptive_tables| StreamParams {
                codec,
                rans_chunk_limit,
                adaptive_tables,
                ..StreamParams::default()
            };
            // Values whose spread drifts, for chunks of their own; or runs
            // of zeros and small values, which adaptive tables code smaller.
            let mut fresh = SubstreamWriter::default();
            for (i, &(ctx, v)) in values.iter().enumerate() {
                let v = if runs {
                    (i / 37 % 2) as i32 * (v % 3)
                } else {
                    (v % skew) >> (i / 2500 % 3)
                };
                fresh.signed_in(ctx % 3, v);
            }
            let mut costed = fresh.clone();
            coded_len(&mut costed, substream::EDGE, &params(adaptive_cost));
            for sub in [&mut fresh, &mut costed] {
                for i in 0..appended {
                    sub.signed_in(1, i as i32);
                }
            }
            let contexts = context::count(
                substream::EDGE,
                DeficitContexts::Plain,
                RecordOrder::WingsFirst,
                Schedule::default(),
            );
            let frame = |sub: &SubstreamWriter| -> Vec<(u8, u32, Vec<u8>, bool)> {
                substream_chunks(sub, contexts, &params(adaptive_frame), &one_by_one)
                    .into_iter()
                    .map(|c| (c.codec, c.raw_len, c.stored, c.adaptive))
                    .collect()
            };
            prop_assert_eq!(frame(&costed), frame(&fresh));
        }
    }
}
