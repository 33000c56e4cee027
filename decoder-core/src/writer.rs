//! Writing streams (SPEC §3–§5), the inverse of the parsers: used by the
//! encoder and by tests that build streams by hand. Needs the `alloc` feature.

use alloc::vec;
use alloc::vec::Vec;

use crate::bytes::crc32;
use crate::header::{Header, PositionMode};
use crate::layout::Layout;
use crate::level_table::{LevelInfo, head_len, write_level_table};
use crate::limits::{CHUNK_ENTRY_LEN, HEADER_LEN, VERSION_MINOR, codec, substream};

/// A growing substream: bytes, bits (least significant first) or varints.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SubstreamWriter {
    bytes: Vec<u8>,
    bit_count: u8,
}

impl SubstreamWriter {
    pub fn byte(&mut self, b: u8) {
        debug_assert_eq!(
            self.bit_count, 0,
            "bytes and bits do not mix in one substream"
        );
        self.bytes.push(b);
    }

    pub fn bit(&mut self, bit: bool) {
        if self.bit_count == 0 {
            self.bytes.push(0);
        }
        if bit {
            *self.bytes.last_mut().expect("pushed above") |= 1 << self.bit_count;
        }
        self.bit_count = (self.bit_count + 1) % 8;
    }

    /// Minimal LEB128 (SPEC §5.4).
    pub fn varint(&mut self, mut v: u32) {
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
    pub fn signed(&mut self, v: i32) {
        self.varint(((v << 1) ^ (v >> 31)) as u32);
    }

    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes
    }

    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }
}

/// How chunks are coded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChunkCodec {
    Stored,
    /// Raw deflate at this miniz_oxide level (1..=10).
    Deflate(u8),
}

/// One level's content before framing.
///
/// A base level given to [`write_stream`] holds just the seed mesh: its
/// `substreams` are ids 9..=11 and it has no rounds. [`write_stream_seeded`]
/// takes the seed separately, so that level 0 can also carry rounds.
#[derive(Clone, Debug, Default)]
pub struct LevelPayload {
    /// Declared split count of each round.
    pub round_splits: Vec<u32>,
    /// Substreams in id order: ids 1..=8 for rounds (index 0 is id 1), or
    /// ids 9..=11 for a base level given to [`write_stream`].
    pub substreams: Vec<SubstreamWriter>,
    pub vertex_count: u32,
    pub triangle_count: u32,
    pub geometric_error: f32,
}

/// Stream-wide parameters.
#[derive(Clone, Copy, Debug)]
pub struct StreamParams {
    pub position_mode: PositionMode,
    pub bits: u8,
    pub origin: [f64; 3],
    pub scale: [f64; 3],
    pub codec: ChunkCodec,
    /// Largest raw chunk the writer cuts (SPEC §5.2).
    pub chunk_limit: u32,
}

/// The seed mesh of level 0 (SPEC §6.3): counts and substreams 9..=11.
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
                substreams[0].signed((p[k] as i64 - previous[k]) as i32);
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
            vertex_count: self.vertices,
            triangle_count: self.triangles,
            substreams: self.substreams,
            geometric_error,
        }
    }
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
    let mut framed: Vec<Vec<u8>> = Vec::with_capacity(levels.len());
    let mut max_chunk = 0u32;
    for (k, level) in levels.iter().enumerate() {
        let (bytes, largest) = frame_level(level, (k == 0).then_some(seed), params);
        max_chunk = max_chunk.max(largest);
        framed.push(bytes);
    }
    let level_count = levels.len() as u16;
    let mut offset = head_len(level_count) as u64;
    let mut entries = Vec::with_capacity(levels.len());
    for (level, bytes) in levels.iter().zip(&framed) {
        entries.push(LevelInfo {
            offset,
            length: bytes.len() as u32,
            vertex_count: level.vertex_count,
            triangle_count: level.triangle_count,
            round_count: level.round_splits.len() as u32,
            geometric_error: level.geometric_error,
        });
        offset += bytes.len() as u64;
    }
    let max_chunk = max_chunk.max(1);
    let (base, top) = (&levels[0], &levels[levels.len() - 1]);
    let layout = Layout::new(
        top.vertex_count,
        top.triangle_count,
        base.vertex_count,
        base.triangle_count,
        max_chunk,
    );
    let header = Header {
        version_minor: VERSION_MINOR,
        position_mode: params.position_mode,
        bits: params.bits,
        level_count,
        vertex_capacity: top.vertex_count,
        triangle_capacity: top.triangle_count,
        max_chunk_len: max_chunk,
        origin: params.origin,
        scale: params.scale,
        workspace_bytes: layout.total,
    };
    let mut out = vec![0u8; head_len(level_count)];
    let mut head = [0u8; HEADER_LEN];
    header.write(&mut head);
    out[..HEADER_LEN].copy_from_slice(&head);
    write_level_table(&entries, &mut out[HEADER_LEN..]);
    for bytes in framed {
        out.extend_from_slice(&bytes);
    }
    out
}

/// Frames one level (SPEC §5.1); returns its bytes and its largest raw chunk.
/// `seed` is given for level 0 only.
pub fn frame_level(
    level: &LevelPayload,
    seed: Option<&SeedPayload>,
    params: &StreamParams,
) -> (Vec<u8>, u32) {
    let limit = params.chunk_limit.max(1) as usize;
    let mut directory = Vec::new();
    let mut payload = Vec::new();
    let mut largest = 0u32;
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
        for raw in sub.as_bytes().chunks(limit) {
            let (codec_id, stored) = match params.codec {
                ChunkCodec::Stored => (codec::STORED, raw.to_vec()),
                ChunkCodec::Deflate(l) => {
                    let packed = miniz_oxide::deflate::compress_to_vec(raw, l);
                    if packed.len() < raw.len() {
                        (codec::DEFLATE, packed)
                    } else {
                        (codec::STORED, raw.to_vec())
                    }
                }
            };
            let mut entry = [0u8; CHUNK_ENTRY_LEN];
            entry[0] = id;
            entry[1] = codec_id;
            entry[4..8].copy_from_slice(&(raw.len() as u32).to_le_bytes());
            entry[8..12].copy_from_slice(&(stored.len() as u32).to_le_bytes());
            entry[12..16].copy_from_slice(&crc32(&stored).to_le_bytes());
            directory.push(entry);
            largest = largest.max(raw.len() as u32);
            payload.extend_from_slice(&stored);
        }
    }
    let mut out = Vec::new();
    out.extend_from_slice(&(level.round_splits.len() as u32).to_le_bytes());
    out.extend_from_slice(&(directory.len() as u32).to_le_bytes());
    if let Some(seed) = seed {
        out.extend_from_slice(&seed.vertices.to_le_bytes());
        out.extend_from_slice(&seed.triangles.to_le_bytes());
    }
    for s in &level.round_splits {
        out.extend_from_slice(&s.to_le_bytes());
    }
    for e in &directory {
        out.extend_from_slice(e);
    }
    let crc = crc32(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out.extend_from_slice(&payload);
    (out, largest)
}
