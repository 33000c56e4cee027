//! Taking valid streams apart and putting them back together with exactly
//! one fault: record-level faults are re-framed with decoder-core's writer
//! (every checksum valid), framing faults are patched in place with the
//! checksums that cover them recomputed unless the checksum is the fault.

use std::ops::Range;

use splitstream_decoder_core::limits::{CHUNK_ENTRY_LEN, HEADER_LEN, LEVEL_ENTRY_LEN, codec};
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{
    ChunkCodec, LevelPayload, SeedPayload, StreamParams, SubstreamWriter, write_stream_seeded,
};
use splitstream_decoder_core::{
    DeficitContexts, Header, Inflater, LevelHeader, LevelTable, PlanePolicy, WingPolicy, crc32,
    fixed_head_len,
};

/// One level's content, substreams as raw bytes.
#[derive(Clone, Debug)]
pub struct Level {
    /// Level 0 only: the seed mesh's vertex and triangle counts and its
    /// substreams (ids 8..=10).
    pub seed: Option<(u32, u32, Vec<Vec<u8>>)>,
    pub round_splits: Vec<u32>,
    /// The level's plane policy (SPEC §5.1).
    pub plane: PlanePolicy,
    /// The level's wing policy (SPEC §5.1, 3.2).
    pub wings: WingPolicy,
    /// The level's deficit contexts (SPEC §5.1, 3.3).
    pub deficits: DeficitContexts,
    /// The level's record order (SPEC §5.1, 3.7).
    pub records: splitstream_decoder_core::RecordOrder,
    /// Its wing choices' tie rule under `positions-first` (SPEC §5.1, 3.8).
    pub ties: splitstream_decoder_core::Ties,
    /// The rounds' substreams, ids 1..=7.
    pub substreams: Vec<Vec<u8>>,
    pub vertex_count: u32,
    pub triangle_count: u32,
    pub geometric_error: f32,
}

/// A stream taken apart.
#[derive(Clone, Debug)]
pub struct Unframed {
    pub params: StreamParams,
    pub levels: Vec<Level>,
}

/// Takes a valid stream apart into its levels' substreams.
pub fn unframe(stream: &[u8]) -> Unframed {
    let header = Header::parse(stream).expect("a valid stream");
    let table = LevelTable::parse(stream, &header).expect("a valid stream");
    let mut inflater = Box::new(Inflater::new());
    let mut any_deflate = false;
    let mut levels = Vec::new();
    for k in 0..header.level_count {
        let info = table.get(k);
        let bytes = &stream[level_range(stream, k)];
        let lh = LevelHeader::parse(bytes, k == 0, header.level_rules()).expect("a valid level");
        // Slots 0..7: ids 1..=7 (rounds); 7..10: ids 8..=10 (seed).
        let mut substreams = vec![Vec::new(); 10];
        let mut at = lh.payload_start;
        for e in lh.chunks() {
            let e = e.expect("a valid chunk");
            let stored = &bytes[at..at + e.stored_len as usize];
            let mut raw = vec![0u8; e.raw_len as usize];
            assert_ne!(
                e.codec,
                codec::RANS,
                "unframe takes byte-codec streams only"
            );
            if e.codec == codec::STORED {
                raw.copy_from_slice(stored);
            } else {
                any_deflate = true;
                inflater
                    .inflate_exact(stored, &mut raw)
                    .expect("a valid chunk");
            }
            substreams[(e.substream - 1) as usize].extend_from_slice(&raw);
            at += e.stored_len as usize;
        }
        let seed_substreams = substreams.split_off(7);
        let seed = (k == 0).then_some((lh.seed_vertices, lh.seed_triangles, seed_substreams));
        levels.push(Level {
            seed,
            round_splits: lh.split_counts().collect(),
            plane: lh.plane_policy,
            wings: lh.wing_policy,
            deficits: lh.deficit_contexts,
            records: lh.record_order,
            ties: lh.ties,
            substreams,
            vertex_count: info.vertex_count,
            triangle_count: info.triangle_count,
            geometric_error: info.geometric_error,
        });
    }
    Unframed {
        params: StreamParams {
            position_mode: header.position_mode,
            bits: header.bits,
            origin: header.origin,
            scale: header.scale,
            codec: if any_deflate {
                ChunkCodec::Deflate(9)
            } else {
                ChunkCodec::Stored
            },
            chunk_limit: header.max_chunk_len,
            rans_chunk_limit: header.max_chunk_len,
            schedule: header.schedule,
            adaptive_tables: false,
            framing: header.framing,
        },
        levels,
    }
}

fn writers(substreams: &[Vec<u8>]) -> Vec<SubstreamWriter> {
    substreams
        .iter()
        .map(|bytes| {
            let mut w = SubstreamWriter::default();
            for &b in bytes {
                w.byte(b);
            }
            w
        })
        .collect()
}

/// Frames the levels again (all checksums, counts and sizes recomputed).
pub fn reframe(u: &Unframed) -> Vec<u8> {
    let payloads: Vec<LevelPayload> = u
        .levels
        .iter()
        .map(|l| LevelPayload {
            round_splits: l.round_splits.clone(),
            plane: l.plane,
            wings: l.wings,
            deficits: l.deficits,
            records: l.records,
            ties: l.ties,
            substreams: writers(&l.substreams),
            vertex_count: l.vertex_count,
            triangle_count: l.triangle_count,
            geometric_error: l.geometric_error,
        })
        .collect();
    let (vertices, triangles, seed) = u.levels[0].seed.as_ref().expect("level 0 has a seed");
    let seed = SeedPayload {
        vertices: *vertices,
        triangles: *triangles,
        substreams: writers(seed),
    };
    write_stream_seeded(&u.params, &seed, &payloads)
}

fn u32_at(s: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(s[at..at + 4].try_into().expect("4 bytes"))
}

pub fn level_count(s: &[u8]) -> u16 {
    u16::from_le_bytes([s[14], s[15]])
}

/// Recomputes the header CRC (SPEC §3.3).
pub fn fix_header_crc(s: &mut [u8]) {
    let crc = crc32(&s[..HEADER_LEN - 4]);
    s[HEADER_LEN - 4..HEADER_LEN].copy_from_slice(&crc.to_le_bytes());
}

/// Offset of level-table entry `k`.
pub fn table_entry(k: u16) -> usize {
    HEADER_LEN + LEVEL_ENTRY_LEN * k as usize
}

/// Recomputes the level-table CRC (SPEC §4.2).
pub fn fix_table_crc(s: &mut [u8]) {
    let end = fixed_head_len(level_count(s)) - 4;
    let crc = crc32(&s[HEADER_LEN..end]);
    s[end..end + 4].copy_from_slice(&crc.to_le_bytes());
}

/// Byte range of level `k`, from the level table.
pub fn level_range(s: &[u8], k: u16) -> Range<usize> {
    let at = table_entry(k);
    let offset = u64::from_le_bytes(s[at..at + 8].try_into().expect("8 bytes")) as usize;
    offset..offset + u32_at(s, at + 8) as usize
}

/// Offset of the split counts of level `k`: after the round and chunk
/// counts, the plane policy byte and 3 reserved bytes, and in level 0 the
/// seed mesh's vertex and triangle counts (SPEC §5.1).
fn split_counts_at(s: &[u8], k: u16) -> usize {
    level_range(s, k).start + if k == 0 { 20 } else { 12 }
}

/// Offset of the plane policy byte of level `k` (SPEC §5.1); the 3
/// reserved bytes follow it.
pub fn plane_policy_at(s: &[u8], k: u16) -> usize {
    level_range(s, k).start + 8
}

/// Where the level header of level `k` keeps its CRC.
fn level_crc_at(s: &[u8], k: u16) -> usize {
    let start = level_range(s, k).start;
    let rounds = u32_at(s, start) as usize;
    let chunks = u32_at(s, start + 4) as usize;
    split_counts_at(s, k) + 4 * rounds + CHUNK_ENTRY_LEN * chunks
}

/// Recomputes the level header CRC of level `k` (SPEC §5.1).
pub fn fix_level_header_crc(s: &mut [u8], k: u16) {
    let start = level_range(s, k).start;
    let at = level_crc_at(s, k);
    let crc = crc32(&s[start..at]);
    s[at..at + 4].copy_from_slice(&crc.to_le_bytes());
}

/// `s` with byte `at` of level `k`'s header set to `value` and that header's
/// CRC recomputed, so the fault is met past the CRC check.
pub fn with_level_header_byte(s: &[u8], k: u16, at: usize, value: u8) -> Vec<u8> {
    let mut b = s.to_vec();
    b[at] = value;
    fix_level_header_crc(&mut b, k);
    b
}

/// Offset of the split count of round `r` of level `k`.
pub fn split_count_at(s: &[u8], k: u16, r: usize) -> usize {
    split_counts_at(s, k) + 4 * r
}

/// Offset of chunk-directory entry `c` of level `k`.
pub fn chunk_entry_at(s: &[u8], k: u16, c: usize) -> usize {
    let rounds = u32_at(s, level_range(s, k).start) as usize;
    split_counts_at(s, k) + 4 * rounds + CHUNK_ENTRY_LEN * c
}

/// Number of chunks of level `k`.
pub fn chunk_count(s: &[u8], k: u16) -> usize {
    u32_at(s, level_range(s, k).start + 4) as usize
}

/// Byte range of chunk `c`'s stored payload in level `k`.
pub fn chunk_payload(s: &[u8], k: u16, c: usize) -> Range<usize> {
    let mut at = level_crc_at(s, k) + 4;
    for i in 0..c {
        at += u32_at(s, chunk_entry_at(s, k, i) + 8) as usize;
    }
    at..at + u32_at(s, chunk_entry_at(s, k, c) + 8) as usize
}

/// Codec byte of chunk `c` of level `k`.
pub fn chunk_codec(s: &[u8], k: u16, c: usize) -> u8 {
    s[chunk_entry_at(s, k, c) + 1]
}

/// Sets chunk `c`'s CRC to match its payload, then the level header CRC.
pub fn fix_chunk_crc(s: &mut [u8], k: u16, c: usize) {
    let crc = crc32(&s[chunk_payload(s, k, c)]);
    let at = chunk_entry_at(s, k, c) + 12;
    s[at..at + 4].copy_from_slice(&crc.to_le_bytes());
    fix_level_header_crc(s, k);
}

/// Re-codes every stored chunk of a valid stream as a raw-deflate stream of
/// one uncompressed block (BFINAL = 1, BTYPE = 00: 5 bytes of block header,
/// then the bytes): valid deflate chunks that are larger than their raw
/// data, which no sensible encoder writes but every decoder must accept.
/// Level lengths and offsets, and the CRCs covering them, are recomputed.
pub fn wrap_chunks_in_deflate(stream: &[u8]) -> Vec<u8> {
    wrap_chunks_in_deflate_with(stream, None)
}

/// [`wrap_chunks_in_deflate`], with one zero byte appended after the
/// deflate stream of chunk `c` of level `k` when `extra_byte` is
/// `Some((k, c))`: a payload byte the deflate stream never uses (SPEC §5.2:
/// `malformed`), with every CRC and length made to match it.
pub fn wrap_chunks_in_deflate_with(stream: &[u8], extra_byte: Option<(u16, usize)>) -> Vec<u8> {
    let levels = level_count(stream);
    let head = fixed_head_len(levels);
    let mut out = stream[..head].to_vec();
    for k in 0..levels {
        let start = level_range(stream, k).start;
        let chunks = chunk_count(stream, k);
        let mut level = stream[start..level_crc_at(stream, k) + 4].to_vec();
        let mut payload = Vec::new();
        for c in 0..chunks {
            let raw = &stream[chunk_payload(stream, k, c)];
            let entry = chunk_entry_at(stream, k, c) - start;
            let packed = if level[entry + 1] == codec::STORED {
                assert!(raw.len() <= 0xFFFF);
                let len = raw.len() as u16;
                let mut p = vec![0x01];
                p.extend_from_slice(&len.to_le_bytes());
                p.extend_from_slice(&(!len).to_le_bytes());
                p.extend_from_slice(raw);
                if extra_byte == Some((k, c)) {
                    p.push(0);
                }
                level[entry + 1] = codec::DEFLATE;
                set_stored_payload(&mut level[entry..entry + CHUNK_ENTRY_LEN], &p);
                p
            } else {
                raw.to_vec()
            };
            payload.extend_from_slice(&packed);
        }
        let crc_at = level.len() - 4;
        let crc = crc32(&level[..crc_at]);
        level[crc_at..].copy_from_slice(&crc.to_le_bytes());
        level.extend_from_slice(&payload);
        append_level(&mut out, k, &level);
    }
    fix_table_crc(&mut out);
    out
}

/// Offsets inside a rANS chunk payload starting at `at` (SPEC §5.5.2,
/// §5.5.3): of each context's token count, and of each lane's first byte.
pub struct RansLayout {
    pub token_counts: Vec<usize>,
    pub lanes: Vec<usize>,
}

/// Parses the table and lane directory of the rANS chunk at `payload`.
pub fn rans_layout(s: &[u8], payload: Range<usize>, contexts: usize, lanes: usize) -> RansLayout {
    fn varint(s: &[u8], at: &mut usize) -> u32 {
        let mut v = 0u32;
        for i in 0..5 {
            let b = s[*at];
            *at += 1;
            v |= ((b & 0x7F) as u32) << (7 * i);
            if b & 0x80 == 0 {
                break;
            }
        }
        v
    }
    let mut at = payload.start;
    let mut token_counts = Vec::new();
    for _ in 0..contexts {
        token_counts.push(at);
        let n = s[at] as usize;
        at += 1;
        // An adaptive table (3.9) is its table byte alone.
        if n & 0x80 == 0 {
            for _ in 0..n {
                varint(s, &mut at);
            }
        }
    }
    let lengths: Vec<u32> = (0..lanes).map(|_| varint(s, &mut at)).collect();
    let mut starts = Vec::new();
    for len in lengths {
        starts.push(at);
        at += len as usize;
    }
    assert_eq!(at, payload.end, "rANS chunk layout");
    RansLayout {
        token_counts,
        lanes: starts,
    }
}

/// `stream` with the payload of chunk `c` of level `k` replaced by
/// `payload`: its directory entry's `stored_len` and CRC, the level header
/// CRC, the level lengths and offsets in the table and the table CRC are
/// made to match (`raw_len` is kept). For faults inside a chunk, met after
/// every framing check passes.
pub fn with_chunk_payload(stream: &[u8], k: u16, c: usize, payload: Vec<u8>) -> Vec<u8> {
    let levels = level_count(stream);
    let mut out = stream[..fixed_head_len(levels)].to_vec();
    for l in 0..levels {
        let range = level_range(stream, l);
        let mut level = stream[range.clone()].to_vec();
        if l == k {
            let old = chunk_payload(stream, k, c);
            let (from, to) = (old.start - range.start, old.end - range.start);
            level.splice(from..to, payload.iter().copied());
            let entry = chunk_entry_at(stream, k, c) - range.start;
            set_stored_payload(&mut level[entry..entry + CHUNK_ENTRY_LEN], &payload);
        }
        append_level(&mut out, l, &level);
    }
    fix_table_crc(&mut out);
    fix_level_header_crc(&mut out, k);
    out
}

/// Sets a chunk directory `entry`'s `stored_len` and CRC to `payload`'s.
fn set_stored_payload(entry: &mut [u8], payload: &[u8]) {
    entry[8..12].copy_from_slice(&(payload.len() as u32).to_le_bytes());
    entry[12..16].copy_from_slice(&crc32(payload).to_le_bytes());
}

/// Appends `level` to `out` as level `k`, setting its table entry's offset
/// and length (the table CRC is the caller's).
pub fn append_level(out: &mut Vec<u8>, k: u16, level: &[u8]) {
    let entry = table_entry(k);
    let offset = out.len() as u64;
    out[entry..entry + 8].copy_from_slice(&offset.to_le_bytes());
    out[entry + 8..entry + 12].copy_from_slice(&(level.len() as u32).to_le_bytes());
    out.extend_from_slice(level);
}

/// `stream`, after checking that decoder-core rejects it with `detail`
/// (the error's `Debug` form).
pub fn failing_with(detail: &str, stream: Vec<u8>) -> Vec<u8> {
    match decode_all(&stream, false) {
        Err(e) => assert_eq!(format!("{e:?}"), detail, "the vector meets another check"),
        Ok(_) => panic!("the vector for {detail} decodes"),
    }
    stream
}

/// `stream` with `f` applied to its header, whose CRC is then recomputed.
pub fn with_header(stream: &[u8], f: impl Fn(&mut [u8])) -> Vec<u8> {
    let mut b = stream.to_vec();
    f(&mut b[..HEADER_LEN]);
    fix_header_crc(&mut b);
    b
}

/// `stream` with `f` applied to level-table entry `k`, whose CRC is then
/// recomputed.
pub fn with_table_entry(stream: &[u8], k: u16, f: impl Fn(&mut [u8])) -> Vec<u8> {
    let mut b = stream.to_vec();
    let at = table_entry(k);
    f(&mut b[at..at + LEVEL_ENTRY_LEN]);
    fix_table_crc(&mut b);
    b
}

pub fn put_u32(b: &mut [u8], at: usize, v: u32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

pub fn put_f64(b: &mut [u8], at: usize, v: f64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

/// The level count of a valid stream.
pub fn level_count_of(stream: &[u8]) -> u16 {
    splitstream_decoder_core::Header::parse(stream)
        .expect("a valid stream")
        .level_count
}
