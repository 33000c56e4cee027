//! One invalid vector for each check of SPEC §3.3, §4.2, §5.1, §5.5 and
//! §6.3 that the other invalid vectors leave unreached: a decoder that
//! skips any one of them fails a vector. Each vector is checked here to
//! fail in decoder-core with exactly the check it is named after (its
//! error's detail, not only its class), and
//! `conformance/tests/every_check_reached.rs` requires every detailed error
//! decoder-core can return to be reached by some vector. The checks whose
//! errors carry no detail (`Truncated`, `LevelCountMismatch`, …) were found
//! unreached with coverage runs over the vector set (conformance/README.md,
//! "Reach"); `reach.rs` adds one vector for each.

use splitstream_decoder_core::handmade;
use splitstream_decoder_core::limits::codec;
use splitstream_decoder_core::writer::{ChunkCodec, write_stream};
use splitstream_encoder::emit::EncodeOptions;

use super::meshes;
use super::mutate::*;
use super::{Specs, deflate_opts, encoded, opts};

/// One vector: its name, the check it meets (the detail of decoder-core's
/// error), what was broken, and its bytes.
struct Case {
    name: &'static str,
    detail: &'static str,
    what: String,
    stream: Vec<u8>,
}

fn case(name: &'static str, detail: &'static str, what: &str, stream: Vec<u8>) -> Case {
    Case {
        name,
        detail,
        what: what.to_string(),
        stream,
    }
}

/// Adds `cases` as invalid vectors of `class`, each checked to fail with
/// `variant(detail)`, described by `describe(what)`.
fn add(
    s: &mut Specs,
    cases: Vec<Case>,
    (variant, class): (&str, &'static str),
    features: &[&str],
    describe: impl Fn(&str) -> String,
) {
    for c in cases {
        let stream = failing_with(&format!("{variant}({:?})", c.detail), c.stream);
        s.invalid(c.name, class, &describe(&c.what), features, stream);
    }
}

pub(super) fn malformed_vectors(s: &mut Specs) {
    header_vectors(s);
    level_table_vectors(s);
    level_header_vectors(s);
    rans_chunk_vectors(s);
    base_mesh_vectors(s);
}

/// SPEC §3.3: each header field rule, the header CRC recomputed.
fn header_vectors(s: &mut Specs) {
    let subject = handmade::tetra_stream(ChunkCodec::Stored);
    let cases = vec![
        case(
            "header-bits-0",
            "bits per axis outside 1..=31",
            "bits per axis (byte 12) 0",
            with_header(&subject, |h| h[12] = 0),
        ),
        case(
            "header-bits-32",
            "bits per axis outside 1..=31",
            "bits per axis (byte 12) 32",
            with_header(&subject, |h| h[12] = 32),
        ),
        case(
            "header-reserved-28",
            "reserved field not zero",
            "the reserved u32 at byte 28 set to 1",
            with_header(&subject, |h| put_u32(h, 28, 1)),
        ),
        case(
            "header-no-levels",
            "no levels",
            "level_count (bytes 14-15) 0",
            with_header(&subject, |h| h[14..16].copy_from_slice(&0u16.to_le_bytes())),
        ),
        case(
            "header-vertex-capacity-0",
            "vertex capacity",
            "vertex_capacity (bytes 16-19) 0",
            with_header(&subject, |h| put_u32(h, 16, 0)),
        ),
        case(
            "header-triangle-capacity-0",
            "triangle capacity",
            "triangle_capacity (bytes 20-23) 0",
            with_header(&subject, |h| put_u32(h, 20, 0)),
        ),
        case(
            "header-max-chunk-len-0",
            "max chunk length is 0",
            "max_chunk_len (bytes 24-27) 0",
            with_header(&subject, |h| put_u32(h, 24, 0)),
        ),
        case(
            "header-origin-nan",
            "origin not finite",
            "origin y (bytes 40-47) NaN",
            with_header(&subject, |h| put_f64(h, 40, f64::NAN)),
        ),
        case(
            "header-scale-0",
            "scale not finite and positive",
            "scale z (bytes 72-79) 0.0",
            with_header(&subject, |h| put_f64(h, 72, 0.0)),
        ),
        case(
            "header-scale-negative",
            "scale not finite and positive",
            "scale x (bytes 56-63) -1.0",
            with_header(&subject, |h| put_f64(h, 56, -1.0)),
        ),
    ];
    add(
        s,
        cases,
        ("InvalidHeader", "malformed"),
        &["header", "malformed-detail"],
        |what| {
            format!(
                "SPEC Appendix A's stream with its header's {what}, every earlier field valid (header CRC recomputed; SPEC §3.3)."
            )
        },
    );
}

/// SPEC §4.2: each entry rule, the table CRC recomputed.
fn level_table_vectors(s: &mut Specs) {
    let subject = encoded(&meshes::icosphere(2), deflate_opts());
    let cases = vec![
        case(
            "table-not-contiguous",
            "levels are not contiguous",
            "level 1's offset one byte past the end of level 0",
            with_table_entry(&subject, 1, |e| {
                let offset = u64::from_le_bytes(e[..8].try_into().expect("8 bytes")) + 1;
                e[..8].copy_from_slice(&offset.to_le_bytes());
            }),
        ),
        case(
            "table-geometric-error-nan",
            "geometric error not finite and >= 0",
            "level 1's geometric error NaN",
            with_table_entry(&subject, 1, |e| {
                e[24..28].copy_from_slice(&f32::NAN.to_le_bytes())
            }),
        ),
        case(
            "table-geometric-error-negative",
            "geometric error not finite and >= 0",
            "level 1's geometric error −1.0 (−0.0 is allowed)",
            with_table_entry(&subject, 1, |e| {
                e[24..28].copy_from_slice(&(-1.0f32).to_le_bytes())
            }),
        ),
        case(
            "table-base-rounds-over-vertices",
            "base level counts",
            "level 0's round count one more than its vertex count",
            with_table_entry(&subject, 0, |e| {
                let vertices = u32::from_le_bytes(e[12..16].try_into().expect("4 bytes"));
                put_u32(e, 20, vertices + 1);
            }),
        ),
        case(
            "table-triangles-do-not-grow",
            "level counts do not grow consistently",
            "level 1's triangle count equal to level 0's (every split adds triangles)",
            {
                let base = u32::from_le_bytes(
                    subject[table_entry(0) + 16..table_entry(0) + 20]
                        .try_into()
                        .expect("4 bytes"),
                );
                with_table_entry(&subject, 1, |e| put_u32(e, 16, base))
            },
        ),
        case(
            "table-last-below-capacity",
            "last level differs from the declared capacity",
            "header vertex_capacity one more than the last level's vertex count (header CRC recomputed; the table itself unchanged)",
            with_header(&subject, |h| {
                let v = u32::from_le_bytes(h[16..20].try_into().expect("4 bytes"));
                put_u32(h, 16, v + 1);
            }),
        ),
    ];
    add(
        s,
        cases,
        ("InvalidLevelTable", "malformed"),
        &["level-table", "malformed-detail"],
        |what| {
            format!(
                "An icosphere stream (2 subdivisions) with {what}; every earlier rule holds (table CRC recomputed; SPEC §4.2)."
            )
        },
    );
}

/// SPEC §5.1: each level header rule, the covering CRCs recomputed.
fn level_header_vectors(s: &mut Specs) {
    let subject = encoded(&meshes::icosphere(2), deflate_opts());
    let stored = encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            codec: ChunkCodec::Stored,
            ..opts()
        },
    );
    let entry = |b: &[u8], k: u16, c: usize| chunk_entry_at(b, k, c);
    let cases = vec![
        case(
            "level-seed-without-vertices",
            "empty seed mesh",
            "level 0's seed_vertices (level header bytes 12-15) 0",
            {
                let at = level_range(&subject, 0).start + 12;
                let mut b = subject.clone();
                put_u32(&mut b, at, 0);
                fix_level_header_crc(&mut b, 0);
                b
            },
        ),
        case(
            "level-chunk-id-0",
            "substream id not allowed in this level",
            "substream id 0 (no such substream) in level 1's first chunk entry",
            with_level_header_byte(&subject, 1, entry(&subject, 1, 0), 0),
        ),
        case(
            "level-chunk-seed-id-in-refinement",
            "substream id not allowed in this level",
            "substream id 8 (base-positions, level 0 only) in level 1's last chunk entry",
            {
                let last = chunk_count(&subject, 1) - 1;
                with_level_header_byte(&subject, 1, entry(&subject, 1, last), 8)
            },
        ),
        case(
            "level-chunks-out-of-order",
            "chunks not ordered by substream",
            "level 1's first chunk entry given substream id 7, above the next entry's",
            {
                let next = subject[entry(&subject, 1, 1)];
                assert!(next < 7, "level 1's second chunk is of a substream below 7");
                with_level_header_byte(&subject, 1, entry(&subject, 1, 0), 7)
            },
        ),
        case(
            "level-stored-lengths-differ",
            "stored chunk lengths differ",
            "a stored chunk of level 1 whose raw_len is one less than its stored_len",
            {
                let at = entry(&stored, 1, 0);
                assert_eq!(stored[at + 1], codec::STORED);
                let raw = u32::from_le_bytes(stored[at + 4..at + 8].try_into().expect("4 bytes"));
                assert!(raw > 1);
                let mut b = stored.clone();
                put_u32(&mut b, at + 4, raw - 1);
                fix_level_header_crc(&mut b, 1);
                b
            },
        ),
        case(
            "level-bytes-after-last-chunk",
            "bytes after the last chunk",
            "one zero byte after the last level's last chunk payload, counted in the level's table length (table CRC recomputed)",
            {
                let last = level_count_of(&subject) - 1;
                let mut b = subject.clone();
                b.push(0);
                let at = table_entry(last) + 8;
                let len = u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"));
                put_u32(&mut b, at, len + 1);
                fix_table_crc(&mut b);
                b
            },
        ),
        case(
            "level-round-without-splits",
            "a round without splits",
            "level 1's first round declaring 0 splits",
            {
                let mut b = subject.clone();
                put_u32(&mut b, split_count_at(&subject, 1, 0), 0);
                fix_level_header_crc(&mut b, 1);
                b
            },
        ),
    ];
    add(
        s,
        cases,
        ("InvalidLevelHeader", "malformed"),
        &["level-header", "malformed-detail"],
        |what| {
            format!(
                "An icosphere stream (2 subdivisions) with {what}; every earlier rule holds (level header CRC recomputed; SPEC §5.1)."
            )
        },
    );
}

/// SPEC §5.5.2, §5.5.3, §5.5.4: the rANS chunk rules the other rANS
/// vectors leave unreached, in SPEC Appendix A's stream coded with rANS.
fn rans_chunk_vectors(s: &mut Specs) {
    let one_lane = handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 1 });
    // Level 1's first chunk is its flags: one context, one value.
    assert_eq!(chunk_codec(&one_lane, 1, 0), codec::RANS);
    let state = (1u32 << 23).to_le_bytes();
    // Two lanes and one value: lane 1 holds no value and must be empty.
    let two_lanes = handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 2 });
    let cases = vec![
        case(
            "rans-tables-past-chunk",
            "tables run past the chunk",
            "the flags chunk cut to its first byte, a table of 2 tokens whose counts are missing",
            with_chunk_payload(&one_lane, 1, 0, vec![2]),
        ),
        case(
            "rans-table-varint-not-minimal",
            "bad varint in tables",
            "the flags table's first count written 0x81 0x00 (not minimal)",
            with_chunk_payload(
                &one_lane,
                1,
                0,
                [&[1u8, 0x81, 0x00, 4][..], &state].concat(),
            ),
        ),
        case(
            "rans-table-varint-over-32-bits",
            "bad varint in tables",
            "the flags table's first count a 5-byte varint above 2^32 − 1 (last byte 0x1F)",
            with_chunk_payload(
                &one_lane,
                1,
                0,
                [&[1u8, 0xFF, 0xFF, 0xFF, 0xFF, 0x1F, 4][..], &state].concat(),
            ),
        ),
        case(
            "rans-tables-past-chunk-at-count",
            "tables run past the chunk",
            "the wing-offset chunk (8 contexts) cut to its first table, unused: the second table's token count is missing",
            {
                let c = (0..chunk_count(&one_lane, 1))
                    .find(|&c| one_lane[chunk_entry_at(&one_lane, 1, c)] == 2)
                    .expect("level 1 has a wing-offset chunk");
                with_chunk_payload(&one_lane, 1, c, vec![0])
            },
        ),
        case(
            "rans-last-count-zero",
            "last token count is zero",
            "the flags table with 2 tokens, counts 1 and 0",
            with_chunk_payload(&one_lane, 1, 0, [&[2u8, 1, 0, 4][..], &state].concat()),
        ),
        case(
            "rans-lane-past-chunk",
            "lanes run past the chunk",
            "the flags lane's length 5 where 4 bytes follow",
            with_chunk_payload(&one_lane, 1, 0, [&[1u8, 1, 5][..], &state].concat()),
        ),
        case(
            "rans-bytes-after-lanes",
            "bytes after the last lane",
            "one byte after the flags lane, outside every lane",
            with_chunk_payload(&one_lane, 1, 0, [&[1u8, 1, 4][..], &state, &[0]].concat()),
        ),
        case(
            "rans-lane-runs-out",
            "lane ran out of bytes",
            "the flags table with 2 tokens of frequency 2048 each and a lane of only its 4-byte state 2^23: decoding the flag leaves the state at 2^22, and renormalising finds no byte",
            with_chunk_payload(&one_lane, 1, 0, [&[2u8, 1, 1, 4][..], &state].concat()),
        ),
        case(
            "rans-value-without-table",
            "value in a context without a table",
            "the flags table unused (0 tokens), but the chunk codes a flag in it",
            with_chunk_payload(&one_lane, 1, 0, [&[0u8, 4][..], &state].concat()),
        ),
        case(
            "rans-bytes-in-empty-lane",
            "bytes in a lane without values",
            "2 lanes (header lane_count 2) and one flag: lane 1 given one byte",
            with_chunk_payload(
                &two_lanes,
                1,
                0,
                [&[1u8, 1, 4, 1][..], &state, &[0]].concat(),
            ),
        ),
    ];
    add(
        s,
        cases,
        ("InvalidRansChunk", "malformed"),
        &["rans", "handmade", "malformed-detail"],
        |what| {
            format!(
                "SPEC Appendix A's stream coded with rANS, level 1's flags chunk replaced: {what} (chunk and level header CRCs, level lengths and offsets recomputed; SPEC §5.5)."
            )
        },
    );
}

/// SPEC §6.3: the base mesh checks the other vectors leave unreached.
fn base_mesh_vectors(s: &mut Specs) {
    let hand = |levels: &[splitstream_decoder_core::writer::LevelPayload]| {
        write_stream(&handmade::stored(), levels)
    };
    let positions = [[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]];
    let seed = |vertices: &[[u32; 3]], triangles: &[[u32; 3]]| {
        hand(&[handmade::base(
            vertices,
            triangles,
            &[255; 5][..vertices.len()],
        )])
    };
    let cases = vec![
        case(
            "base-index-out-of-range",
            "vertex index out of range",
            "A tetrahedron's seed whose last triangle names vertex 4 of 4",
            seed(&positions, &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 4]]),
        ),
        case(
            "base-degenerate-triangle",
            "degenerate triangle",
            "A tetrahedron's seed whose last triangle names vertex 1 twice",
            seed(&positions, &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 1]]),
        ),
        case(
            "base-unreferenced-vertex",
            "unreferenced vertex",
            "A tetrahedron's seed with a fifth vertex no triangle names",
            seed(
                &[&positions[..], &[[5, 5, 5]]].concat(),
                &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            ),
        ),
    ];
    add(
        s,
        cases,
        ("NonManifold", "non-manifold"),
        &["handmade", "base-only", "manifold", "malformed-detail"],
        |what| format!("{what} (SPEC §6.3)."),
    );
}
