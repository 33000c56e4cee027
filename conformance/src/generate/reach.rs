//! Invalid and valid vectors for rules the rest of the set left unmet,
//! found by coverage runs of decoder-core and of the Python decoder over
//! the set and by reading SPEC §10.1's table (conformance/README.md,
//! "Reach"): checks whose errors carry no detail (`Truncated`,
//! `LevelCountMismatch`, …), so that one vector per check is the only way
//! to know a decoder makes it.

use splitstream_decoder_core::handmade;
use splitstream_decoder_core::limits::codec;
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{ChunkCodec, write_stream};
use splitstream_encoder::emit::EncodeOptions;

use super::meshes;
use super::mutate::*;
use super::{Specs, deflate_opts, encoded, opts};

/// Checks whose errors carry no detail that no other vector met (found
/// with a coverage run): a level too short for its header, its chunk
/// directory or its payloads; split counts disagreeing with the level
/// table; a level ending with fewer triangles than its entry; a rANS flag
/// of 2 under the schedule `every-vertex`.
pub(super) fn reach_vectors(s: &mut Specs) {
    let subject = encoded(&meshes::icosphere(2), deflate_opts());
    let last = level_count_of(&subject) - 1;
    let range = level_range(&subject, last);
    let payload_start = chunk_payload(&subject, last, 0).start - range.start;
    let with_last_length =
        |len: usize| with_table_entry(&subject, last, |e| put_u32(e, 8, len as u32));
    for (name, len, what) in [
        (
            "level-shorter-than-header",
            8,
            "8 bytes: its round and chunk counts, but not the rest of its 12-byte fixed part (SPEC §5.1: `len < H`)",
        ),
        (
            "level-directory-past-level",
            payload_start - 1,
            "one byte short of its level header: the header CRC lies partly outside (SPEC §5.1: `len < payload_start`)",
        ),
        (
            "level-payloads-past-level",
            range.len() - 1,
            "one byte short of its chunk payloads (SPEC §5.1: `total > len`)",
        ),
    ] {
        s.invalid(
            name,
            "truncated",
            &format!(
                "An icosphere stream (2 subdivisions) whose last level is declared {what}; the table CRC recomputed, the bytes after the declared end ignored as trailing bytes."
            ),
            &["truncated", "level-header"],
            failing_with("Truncated", with_last_length(len)),
        );
    }
    s.invalid(
        "level-split-counts-over-entry",
        "count-mismatch",
        "An icosphere stream (2 subdivisions) whose level 1 declares one split more in its first round than its table entry's vertex count allows (level header CRC recomputed; SPEC §5.1).",
        &["level-header", "level-count"],
        failing_with("LevelCountMismatch", {
            let at = split_count_at(&subject, 1, 0);
            let n = u32::from_le_bytes(subject[at..at + 4].try_into().expect("4 bytes"));
            let mut b = subject.clone();
            put_u32(&mut b, at, n + 1);
            fix_level_header_crc(&mut b, 1);
            b
        }),
    );
    // A mesh with a boundary: its splits with the ghost as a wing add one
    // triangle, so its entries may claim one more and still grow
    // consistently (SPEC §4.2).
    let open = encoded(
        &meshes::grid(24, 20, 1, Some([8, 15, 6, 12])),
        deflate_opts(),
    );
    s.invalid(
        "level-ends-short-of-triangles",
        "count-mismatch",
        "A height field with a hole whose level 1 table entry claims one triangle more than its splits make (table CRC recomputed): every split fits under the entry, and the level ends one triangle short (SPEC §7.6).",
        &["level-count", "boundary"],
        failing_with(
            "LevelCountMismatch",
            with_table_entry(&open, 1, |e| {
                let t = u32::from_le_bytes(e[16..20].try_into().expect("4 bytes"));
                put_u32(e, 16, t + 1);
            }),
        ),
    );
    // Two fans at one base vertex, each way SPEC §6.3's rule can break
    // other than the bowtie of two closed fans.
    let two_fans = |positions: &[[u32; 3]], triangles: &[[u32; 3]]| {
        failing_with(
            "NonManifold(\"a vertex has more than one fan\")",
            write_stream(
                &handmade::stored(),
                &[handmade::base(
                    positions,
                    triangles,
                    &vec![255; positions.len()],
                )],
            ),
        )
    };
    s.invalid(
        "non-manifold-disk-and-fan",
        "non-manifold",
        "Base mesh of a tetrahedron and one more triangle sharing only its vertex 0: vertex 0's link is a cycle and a separate path, two fans (SPEC §6.3).",
        &["handmade", "base-only", "manifold"],
        two_fans(
            &[
                [0, 0, 0],
                [10, 0, 0],
                [0, 10, 0],
                [0, 0, 10],
                [20, 20, 0],
                [20, 0, 20],
            ],
            &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 4, 5]],
        ),
    );
    // A deflate chunk that inflates to one byte fewer, or one more, than
    // its directory entry's raw_len (SPEC §5.2: exactly raw_len).
    let max_chunk = u32::from_le_bytes(subject[24..28].try_into().expect("4 bytes"));
    let c = (0..chunk_count(&subject, 1))
        .find(|&c| {
            let at = chunk_entry_at(&subject, 1, c);
            let raw = u32::from_le_bytes(subject[at + 4..at + 8].try_into().expect("4 bytes"));
            chunk_codec(&subject, 1, c) == codec::DEFLATE && raw > 1 && raw < max_chunk
        })
        .expect("a deflate chunk in level 1 below the maximum length");
    for (name, delta, what) in [
        ("deflate-shorter-than-raw-len", 1i64, "one byte fewer than"),
        ("deflate-longer-than-raw-len", -1, "one byte more than"),
    ] {
        s.invalid(
            name,
            "malformed",
            &format!(
                "An icosphere stream (2 subdivisions) whose level 1 deflate chunk {c} inflates to {what} its directory entry's raw_len (raw_len changed, level header CRC recomputed; SPEC §5.2: exactly raw_len)."
            ),
            &["codec"],
            failing_with("CorruptChunk", {
                let at = chunk_entry_at(&subject, 1, c) + 4;
                let raw = u32::from_le_bytes(subject[at..at + 4].try_into().expect("4 bytes"));
                let mut b = subject.clone();
                put_u32(&mut b, at, (raw as i64 + delta) as u32);
                fix_level_header_crc(&mut b, 1);
                b
            }),
        );
    }
    s.invalid(
        "non-manifold-pillow",
        "non-manifold",
        "Base mesh of two triangles back to back, (0, 1, 2) and (0, 2, 1): no directed edge twice, but every vertex has a closed fan of 2 triangles (SPEC §6.3: a closed fan needs at least 3).",
        &["handmade", "base-only", "manifold"],
        two_fans(&handmade::TRIANGLE_POSITIONS, &[[0, 1, 2], [0, 2, 1]]),
    );
    // A vertex whose ring grew past 255 entries, flagged: decoders walk
    // rings into buffers of 255 entries (SPEC §6.2, §7.1).
    for (name, mesh, what) in [
        (
            "ring-over-255-closed",
            meshes::cone(300, 1),
            "a closed cone of 300 sides (an apex of valence 300)",
        ),
        (
            "ring-over-255-boundary",
            fan(300),
            "a fan of 300 triangles around a boundary vertex (valence 301)",
        ),
    ] {
        let stream = encoded(
            &meshes::checked(mesh, name),
            super::every_vertex(deflate_opts()),
        );
        s.invalid(
            name,
            "valence-overflow",
            &format!(
                "{what}, the schedule every-vertex, deflate: in a round of the last levels one flag set and the next set flag cleared (re-framed, every checksum valid), the first such swap that flags the high-valence vertex once its ring is longer than 255 (SPEC §7.1: the ring of a split vertex has at most 255 entries)."
            ),
            &["records", "high-valence", "schedule-every-vertex"],
            flag_swap_failing_with("ValenceOverflow", &stream),
        );
    }
    // Under split valences the flags are decoded ahead of their use
    // (decoder-core's `decode_bits_ahead`): a bad value after a good one is
    // met ahead and must fail when its flag is read, not be skipped.
    s.invalid(
        "rans-flag-2-after-a-good-flag",
        "malformed",
        "Tetrahedron with adjacent candidates 0 and 1, rANS in one lane: vertex 0's flag 0, then vertex 1's flag 2 (SPEC §5.5: a flag above 1).",
        &["rans", "handmade"],
        failing_with("ValueOutOfRange(1)", {
            let mut lvl = handmade::level(&[false, false], vec![1], &[handmade::tetra_split()], 5, 6);
            let mut flags = splitstream_decoder_core::writer::SubstreamWriter::default();
            flags.bit(false);
            flags.varint(2);
            lvl.substreams[0] = flags;
            write_stream(
                &handmade::params(ChunkCodec::RansAlways { lanes: 1 }),
                &[handmade::tetrahedron_two_candidates(), lvl],
            )
        }),
    );
    // Every flag's table a single token, 2: each flag decodes to 2 in no
    // bytes (SPEC §5.5.4), whatever the vertex's valence context.
    let every = encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            codec: ChunkCodec::RansAlways { lanes: 1 },
            ..super::every_vertex(opts())
        },
    );
    assert_eq!(
        every[chunk_entry_at(&every, 1, 0)],
        1,
        "level 1's first chunk holds flags"
    );
    let tables: Vec<u8> = [3u8, 0, 0, 1].repeat(5);
    let state = (1u32 << 23).to_le_bytes();
    s.invalid(
        "every-vertex-rans-flag-2",
        "malformed",
        "An icosphere stream (2 subdivisions) of the schedule every-vertex, rANS in one lane, whose level 1 flags chunk codes 2 in each of its 5 contexts (tables of one token, 2): a flag above 1 (SPEC §5.5; chunk and level header CRCs, level lengths and offsets recomputed).",
        &["rans", "schedule-every-vertex"],
        failing_with(
            "ValueOutOfRange(1)",
            with_chunk_payload(&every, 1, 0, [&tables[..], &[4], &state].concat()),
        ),
    );
}

/// A fan of `n` triangles around vertex 0, which lies on the boundary with
/// valence `n + 1`.
fn fan(n: usize) -> splitstream_encoder::Mesh {
    let mut positions = vec![[0.0, 0.0, 0.0]];
    for i in 0..=n {
        let a = std::f64::consts::PI * i as f64 / n as f64;
        // Exact enough and platform-independent: a polygon on the unit
        // square's upper half, not a circle (no libm).
        let t = a / std::f64::consts::PI;
        positions.push([1.0 - 2.0 * t, 1.0 - (2.0 * t - 1.0) * (2.0 * t - 1.0), 0.0]);
    }
    let triangles = (0..n as u32).map(|i| [0, i + 1, i + 2]).collect();
    splitstream_encoder::Mesh {
        positions,
        triangles,
    }
}

/// `stream` (byte-coded) with one flag bit set and the next set bit of the
/// same substream cleared, so the round's flag count holds: the first such
/// swap, from the last level back, that decoder-core rejects with `detail`.
fn flag_swap_failing_with(detail: &str, stream: &[u8]) -> Vec<u8> {
    let parts = unframe(stream);
    for k in (1..parts.levels.len()).rev() {
        let flags = &parts.levels[k].substreams[0];
        let bit = |i: usize| flags[i / 8] >> (i % 8) & 1 == 1;
        let bits = 8 * flags.len();
        for j in (0..bits).filter(|&j| !bit(j)) {
            let Some(i) = (j + 1..bits).find(|&i| bit(i)) else {
                break;
            };
            let mut p = parts.clone();
            let f = &mut p.levels[k].substreams[0];
            f[j / 8] |= 1 << (j % 8);
            f[i / 8] &= !(1 << (i % 8));
            let b = reframe(&p);
            if matches!(decode_all(&b, false), Err(e) if format!("{e:?}") == detail) {
                return b;
            }
        }
    }
    panic!("no flag swap fails with {detail}")
}
