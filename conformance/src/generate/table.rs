//! The vectors of the compact level table (SPEC §3.3, §4.3, format 3.12):
//! streams whose header sets flag bits 2 and 3, valid ones and invalid
//! ones for each rule the compact table adds (the header's bounds on
//! `table_len` and the level count, its varints, its end, its running
//! sums) and for a length that moves the levels after it.

use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{
    Framing, Header, LevelInfo, LevelTable, PositionMode, compact_level_table, crc32,
};
use splitstream_encoder::emit::EncodeOptions;

use super::meshes;
use super::mutate::{failing_with, fix_header_crc, put_u32};
use super::{Specs, encoded, every_vertex, opts};

const TAG: &str = "table-compact";

/// `options` with the compact level table (and compact level headers).
fn compact_table(options: EncodeOptions) -> EncodeOptions {
    EncodeOptions {
        framing: Framing::Compact,
        ..options
    }
}

/// The table's entries as the decoder reads them.
fn entries(stream: &[u8]) -> Vec<LevelInfo> {
    let header = Header::parse(stream).expect("a valid header");
    let table = LevelTable::parse(stream, &header).expect("a valid table");
    table.iter().collect()
}

/// `stream` with its compact table's entry bytes replaced by `body` (the
/// table CRC recomputed), `table_len` set to match and the header CRC
/// recomputed; the levels follow unchanged.
fn with_table_body(stream: &[u8], body: &[u8]) -> Vec<u8> {
    let head = Header::parse(stream).expect("a valid header").head_len();
    let mut out = stream[..96].to_vec();
    put_u32(&mut out, 28, body.len() as u32 + 4);
    fix_header_crc(&mut out);
    out.extend_from_slice(body);
    out.extend_from_slice(&crc32(body).to_le_bytes());
    out.extend_from_slice(&stream[head..]);
    out
}

/// The entry bytes (CRC left off) of a compact table holding `entries`.
fn body_of(entries: &[LevelInfo]) -> Vec<u8> {
    let table = compact_level_table(entries);
    table[..table.len() - 4].to_vec()
}

pub(super) fn table_vectors(s: &mut Specs) {
    let stored = encoded(
        &meshes::icosphere(3),
        compact_table(EncodeOptions {
            codec: ChunkCodec::Stored,
            chunk_limit: 64,
            ..opts()
        }),
    );
    s.valid(
        "table-compact-icosphere-stored",
        "Icosphere (642 vertices), optimal positions, stored chunks of at most 64 bytes, the compact level table (SPEC §4.3, format 3.12) with compact level headers; level lengths of two-byte varints.",
        &["encoded", TAG],
        stored.clone(),
    );
    s.valid(
        "table-compact-rans-every-vertex-7-levels",
        "Icosphere (2,562 vertices), constrained positions, rANS in 3 lanes, the schedule every-vertex, 7 levels, the compact level table.",
        &["encoded", TAG, "rans"],
        encoded(
            &meshes::icosphere(4),
            compact_table(every_vertex(EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::Rans { lanes: 3 },
                levels: 7,
                ..opts()
            })),
        ),
    );

    let header_vector =
        |s: &mut Specs, name: &str, why: &str, detail: &str, f: &dyn Fn(&mut [u8])| {
            let mut b = stored.clone();
            f(&mut b);
            fix_header_crc(&mut b);
            s.invalid(
                name,
                "malformed",
                why,
                &["header", TAG],
                failing_with(detail, b),
            );
        };
    let levels = u16::from_le_bytes([stored[14], stored[15]]) as u32;
    header_vector(
        s,
        "table-compact-without-compact-levels",
        "Header flag bit 3 (compact level table) set with bit 2 (compact level headers) clear (SPEC §3.3).",
        "InvalidHeader(\"a compact level table without compact level headers\")",
        &|b| b[10] &= !4,
    );
    header_vector(
        s,
        "table-compact-256-levels",
        "Compact level table declaring 256 levels, with a table_len (8 x 256 + 4) within its bounds (SPEC §3.3: at most 255).",
        "InvalidHeader(\"more than 255 levels in a compact level table\")",
        &|b| {
            b[14..16].copy_from_slice(&256u16.to_le_bytes());
            put_u32(b, 28, 8 * 256 + 4);
        },
    );
    header_vector(
        s,
        "table-compact-len-below-bound",
        "Compact level table with table_len 8 x level_count + 3, below its bound (SPEC §3.3).",
        "InvalidHeader(\"compact level table length out of range for its level count\")",
        &|b| put_u32(b, 28, 8 * levels + 3),
    );
    header_vector(
        s,
        "table-compact-len-above-bound",
        "Compact level table with table_len 24 x level_count + 5, above its bound (SPEC §3.3).",
        "InvalidHeader(\"compact level table length out of range for its level count\")",
        &|b| put_u32(b, 28, 24 * levels + 5),
    );
    header_vector(
        s,
        "table-len-under-fixed-table",
        "Header flag bit 3 cleared (a fixed level table) with table_len (offset 28, reserved under a fixed table) left non-zero (SPEC §3.3).",
        "InvalidHeader(\"reserved field not zero\")",
        &|b| b[10] &= !8,
    );

    let head = Header::parse(&stored).expect("valid").head_len();
    let body = stored[96..head - 4].to_vec();
    s.invalid(
        "table-compact-checksum",
        "checksum-mismatch",
        "Compact level table: a bit of entry 0's length flipped, the table CRC left as it was.",
        &["checksum", TAG],
        failing_with("ChecksumMismatch(LevelTable)", {
            let mut b = stored.clone();
            b[96] ^= 1;
            b
        }),
    );
    s.invalid(
        "table-compact-cut",
        "truncated",
        "The stream cut two bytes before the end of its compact level table (head_len = 96 + table_len, SPEC §4.3).",
        &["truncated", TAG],
        failing_with("Truncated", stored[..head - 2].to_vec()),
    );
    assert!(
        body[0] & 0x80 != 0 && body[1] & 0x80 == 0,
        "a two-byte length"
    );
    // Entry 0's two-byte length written longer: with a last byte 0x00
    // (not minimal), or in five bytes whose last is 0x10 (a 33rd bit).
    for (name, detail, how, tail) in [
        (
            "table-compact-varint-not-minimal",
            "varint not minimal",
            "in three bytes, the last 0x00 (SPEC §5.4's minimality)",
            &[0x00][..],
        ),
        (
            "table-compact-varint-over-32-bits",
            "varint over 32 bits",
            "in five bytes whose last is 0x10 (a 33rd bit)",
            &[0x80, 0x80, 0x10][..],
        ),
    ] {
        let mut b = vec![body[0], body[1] | 0x80];
        b.extend_from_slice(tail);
        b.extend_from_slice(&body[2..]);
        s.invalid(
            name,
            "malformed",
            &format!(
                "Compact level table: entry 0's length written {how}; table_len and both CRCs recomputed."
            ),
            &["reserved", TAG],
            failing_with(
                &format!("InvalidLevelTable({detail:?})"),
                with_table_body(&stored, &b),
            ),
        );
    }
    s.invalid(
        "table-compact-entry-past-end",
        "malformed",
        "Compact level table: table_len one byte short, so the last entry's geometric error runs past the table's end (its CRC recomputed over the shorter table): malformed, not truncated (SPEC §4.3).",
        &["reserved", TAG],
        failing_with(
            "InvalidLevelTable(\"an entry runs past the table's length\")",
            with_table_body(&stored, &body[..body.len() - 1]),
        ),
    );
    s.invalid(
        "table-compact-bytes-left",
        "malformed",
        "Compact level table: a byte 0x00 after the last entry, inside table_len (CRCs recomputed) (SPEC §4.3).",
        &["reserved", TAG],
        failing_with(
            "InvalidLevelTable(\"bytes left after the last entry of a compact table\")",
            with_table_body(&stored, &[&body[..], &[0]].concat()),
        ),
    );
    let e = entries(&stored);
    s.invalid(
        "table-compact-step-past-capacity",
        "capacity-exceeded",
        "Compact level table: entry 0's vertex step 2^32 - 1, so the running vertex count passes vertex_capacity (and 2^32; SPEC §4.3: exact sums, not wrapped).",
        &["capacity", TAG],
        failing_with("CapacityExceeded", {
            let mut e = e.clone();
            e[0].vertex_count = u32::MAX;
            let mut b = body_of(&e);
            // Only entry 0's step changes: the later steps stay the
            // stream's (compact_level_table took them from the new count).
            let rest = body_of(&entries(&stored));
            let first = |t: &[u8]| entry_len(t);
            b.truncate(first(&b));
            b.extend_from_slice(&rest[first(&rest)..]);
            with_table_body(&stored, &b)
        }),
    );
    s.invalid(
        "table-compact-triangle-step-0",
        "malformed",
        "Compact level table: entry 1's triangle step 0 (entry 2's grown to keep the later counts), so level 1 adds vertices but no triangle (SPEC §4.2's growth rule on the steps).",
        &["reserved", TAG],
        failing_with("InvalidLevelTable(\"level counts do not grow consistently\")", {
            let mut e = e.clone();
            e[1].triangle_count = e[0].triangle_count;
            with_table_body(&stored, &body_of(&e))
        }),
    );
    for (name, delta, class, detail, why) in [
        (
            "table-compact-length-short",
            -1i64,
            "truncated",
            "Truncated",
            "Compact level table: entry 0's length one byte short (CRCs recomputed). Offsets follow the lengths, so the table is valid; level 0 then ends before its last chunk: truncated, though every byte is there (SPEC §4.3, §5.1).",
        ),
        (
            "table-compact-length-long",
            1,
            "malformed",
            "InvalidLevelHeader(\"bytes after the last chunk\")",
            "Compact level table: entry 0's length one byte long (CRCs recomputed): level 0 ends one byte after its last chunk (SPEC §4.3, §5.1).",
        ),
    ] {
        let mut e = e.clone();
        e[0].length = (e[0].length as i64 + delta) as u32;
        s.invalid(
            name,
            class,
            why,
            &[
                if class == "truncated" {
                    "truncated"
                } else {
                    "reserved"
                },
                TAG,
            ],
            failing_with(detail, with_table_body(&stored, &body_of(&e))),
        );
    }
}

/// Bytes of the first compact entry of `body`: four varints and an f32.
fn entry_len(body: &[u8]) -> usize {
    let mut at = 0;
    for _ in 0..4 {
        while body[at] & 0x80 != 0 {
            at += 1;
        }
        at += 1;
    }
    at + 4
}
