//! The vectors of the compact level framing (SPEC §5.1.1, format 3.11):
//! streams whose header sets flag bit 2, valid ones under each codec and
//! invalid ones for the rules the compact layout adds (varints, the
//! combined id and codec byte, a directory cut short).

use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_decoder_core::{Framing, PositionMode, Schedule, crc32, fixed_head_len};
use splitstream_encoder::emit::EncodeOptions;

use super::meshes;
use super::mutate::{append_level, failing_with, fix_table_crc, level_count, level_range};
use super::{Specs, encoded, every_vertex, opts};

const TAG: &str = "framing-compact";

/// `options` with the compact level headers of format 3.11 (and the fixed
/// level table, which `with_level` rewrites; 3.12's compact table has
/// vectors of its own, `table.rs`).
fn compact(options: EncodeOptions) -> EncodeOptions {
    EncodeOptions {
        framing: Framing::CompactLevels,
        ..options
    }
}

pub(super) fn compact_vectors(s: &mut Specs) {
    let stored = encoded(
        &meshes::icosphere(2),
        compact(EncodeOptions {
            codec: ChunkCodec::Stored,
            chunk_limit: 64,
            ..opts()
        }),
    );
    s.valid(
        "compact-icosphere-stored-small-chunks",
        "Icosphere (162 vertices), optimal positions, stored chunks of at most 64 bytes (many directory entries a substream), level headers in the compact framing (SPEC §5.1.1, format 3.11).",
        &["encoded", TAG],
        stored.clone(),
    );
    s.valid(
        "compact-icosphere-deflate",
        "Icosphere (642 vertices), optimal positions, deflate, compact framing.",
        &["encoded", TAG],
        encoded(
            &meshes::icosphere(3),
            compact(EncodeOptions {
                codec: ChunkCodec::Deflate(9),
                ..opts()
            }),
        ),
    );
    s.valid(
        "compact-icosphere-rans-every-vertex-8-lanes",
        "Icosphere (642 vertices), constrained positions, rANS in 8 lanes, the schedule every-vertex, compact framing.",
        &["encoded", TAG, "rans"],
        encoded(
            &meshes::icosphere(3),
            compact(every_vertex(EncodeOptions {
                position_mode: PositionMode::Constrained,
                codec: ChunkCodec::Rans { lanes: 8 },
                ..opts()
            })),
        ),
    );
    s.valid(
        "compact-grid-defaults",
        "A 40 x 40 height grid with the encoder's defaults (constrained, rANS, every-vertex, records positions first where smaller, compact level headers and, since 3.12, the compact level table).",
        &["encoded", TAG],
        encoded(&meshes::grid(40, 40, 7, None), EncodeOptions::default()),
    );
    debug_assert_eq!(
        EncodeOptions::default().schedule,
        Schedule::EveryVertex,
        "the grid vector's description"
    );

    // Level 1 of the stored stream, field by field.
    let fields = Fields::of(&stored, 1);
    let level = &stored[level_range(&stored, 1)];
    s.invalid(
        "compact-checksum-level-header",
        "checksum-mismatch",
        "Compact framing: a bit of level 1's first split count flipped (its varint stays minimal); the level header CRC left as it was.",
        &["checksum", TAG],
        failing_with("ChecksumMismatch(LevelHeader)", {
            let mut b = stored.clone();
            b[level_range(&stored, 1).start + fields.counts_at] ^= 0x01;
            b
        }),
    );
    s.invalid(
        "compact-varint-not-minimal",
        "malformed",
        "Compact framing: level 1's first split count written in one byte more than it needs (a last byte 0x00, SPEC §5.4's minimality), level header CRC, level length and table recomputed.",
        &["reserved", TAG],
        failing_with(
            "InvalidLevelHeader(\"varint not minimal\")",
            with_level(&stored, 1, &{
                let at = fields.counts_at;
                let mut l = level.to_vec();
                let v = l[at];
                assert!(v < 0x80, "a one-byte split count");
                l.splice(at..at + 1, [v | 0x80, 0x00]);
                with_crc(l, fields.crc_at + 1)
            }),
        ),
    );
    s.invalid(
        "compact-varint-over-32-bits",
        "malformed",
        "Compact framing: level 1's first split count written in 5 bytes whose last is 0x10 (a 33rd bit), level header CRC, level length and table recomputed.",
        &["reserved", TAG],
        failing_with(
            "InvalidLevelHeader(\"varint over 32 bits\")",
            with_level(&stored, 1, &{
                let at = fields.counts_at;
                let mut l = level.to_vec();
                let v = l[at];
                l.splice(at..at + 1, [v | 0x80, 0x80, 0x80, 0x80, 0x10]);
                with_crc(l, fields.crc_at + 4)
            }),
        ),
    );
    s.invalid(
        "compact-codec-3",
        "malformed",
        "Compact framing: the codec half (bits 4-7) of level 1's first directory entry's id_codec byte set to 3, reserved (level header CRC recomputed).",
        &["reserved", TAG],
        failing_with(
            "InvalidLevelHeader(\"unknown codec\")",
            with_level(&stored, 1, &{
                let mut l = level.to_vec();
                let at = fields.directory_at;
                l[at] = (l[at] & 0x0F) | 0x30;
                with_crc(l, fields.crc_at)
            }),
        ),
    );
    s.invalid(
        "compact-substream-0",
        "malformed",
        "Compact framing: the id half (bits 0-3) of level 1's first directory entry's id_codec byte set to 0, not a substream (level header CRC recomputed).",
        &["reserved", TAG],
        failing_with(
            "InvalidLevelHeader(\"substream id not allowed in this level\")",
            with_level(&stored, 1, &{
                let mut l = level.to_vec();
                let at = fields.directory_at;
                l[at] &= 0xF0;
                with_crc(l, fields.crc_at)
            }),
        ),
    );
    let last = level_count(&stored) - 1;
    let last_fields = Fields::of(&stored, last);
    s.invalid(
        "compact-directory-cut",
        "truncated",
        "Compact framing: the last level ends (by its level-table length, table CRC recomputed, and the stream with it) in the middle of its chunk directory, so reading the directory runs past the level.",
        &["truncated", TAG],
        failing_with("Truncated", {
            let range = level_range(&stored, last);
            let cut = last_fields.directory_at + 3;
            with_level(&stored, last, &stored[range.start..range.start + cut])
        }),
    );
}

/// Where the parts of a compact level header lie, relative to the level.
struct Fields {
    counts_at: usize,
    directory_at: usize,
    crc_at: usize,
}

impl Fields {
    /// Reads level `k` of a valid compact stream (SPEC §5.1.1).
    fn of(stream: &[u8], k: u16) -> Fields {
        let level = &stream[level_range(stream, k)];
        let mut at = 0;
        let mut varint = || {
            let mut v = 0u32;
            let mut shift = 0;
            loop {
                let b = level[at];
                at += 1;
                v |= u32::from(b & 0x7F) << shift;
                shift += 7;
                if b & 0x80 == 0 {
                    return v;
                }
            }
        };
        let rounds = varint();
        let chunks = varint();
        at += 4;
        if k == 0 {
            at = skip_varints(level, at, 2);
        }
        let counts_at = at;
        at = skip_varints(level, at, rounds as usize);
        let directory_at = at;
        for _ in 0..chunks {
            at = skip_varints(level, at + 1, 2) + 4;
        }
        Fields {
            counts_at,
            directory_at,
            crc_at: at,
        }
    }
}

/// The offset past `n` varints from `at`.
fn skip_varints(level: &[u8], mut at: usize, n: usize) -> usize {
    for _ in 0..n {
        while level[at] & 0x80 != 0 {
            at += 1;
        }
        at += 1;
    }
    at
}

/// `level` with its header CRC (at `crc_at`) recomputed.
fn with_crc(mut level: Vec<u8>, crc_at: usize) -> Vec<u8> {
    let crc = crc32(&level[..crc_at]);
    level[crc_at..crc_at + 4].copy_from_slice(&crc.to_le_bytes());
    level
}

/// `stream` with level `k`'s bytes replaced by `level`: the table's
/// offsets and lengths and its CRC follow.
fn with_level(stream: &[u8], k: u16, level: &[u8]) -> Vec<u8> {
    let levels = level_count(stream);
    let mut out = stream[..fixed_head_len(levels)].to_vec();
    for l in 0..levels {
        if l == k {
            append_level(&mut out, l, level);
        } else {
            append_level(&mut out, l, &stream[level_range(stream, l)]);
        }
    }
    fix_table_crc(&mut out);
    out
}
