//! The invalid vectors: streams with one thing broken, each expected to
//! fail with its error class (SPEC §10).

use splitstream_decoder_core::handmade;
use splitstream_decoder_core::limits::LEAF;
use splitstream_decoder_core::writer::{ChunkCodec, write_stream};
use splitstream_decoder_core::{DeficitContexts, Header, PositionMode, WingPolicy, fixed_head_len};
use splitstream_encoder::emit::EncodeOptions;

use super::meshes;
use super::mutate::*;
use super::rans::rans_vectors;
use super::{Specs, deflate_opts, encoded, every_vertex, opts};
use crate::builtin;
use crate::protocol::Verdict;
use handmade::{Rec, base, level, tetra_split, tetra_split_level};

fn flip(mut s: Vec<u8>, at: usize, mask: u8) -> Vec<u8> {
    s[at] ^= mask;
    s
}

pub(super) fn invalid_vectors(s: &mut Specs) {
    let sphere = meshes::icosphere(3);
    let subject = encoded(&sphere, deflate_opts());
    let stored_subject = encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            codec: ChunkCodec::Stored,
            ..opts()
        },
    );
    let constrained = encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            position_mode: PositionMode::Constrained,
            codec: ChunkCodec::Stored,
            ..opts()
        },
    );
    let levels = Header::parse(&subject).expect("valid").level_count;
    let last = levels - 1;
    let head = fixed_head_len(levels);

    // Truncation at several depths.
    let cut = |n: usize| subject[..n].to_vec();
    let level0 = level_range(&subject, 0);
    let level2 = level_range(&subject, 2);
    for (name, at, what) in [
        ("truncated-signature", 5, "inside the 8-byte signature"),
        (
            "truncated-after-version",
            9,
            "after the signature and the major version, before the minor version (SPEC §3.3: `len < 10`)",
        ),
        ("truncated-header", 60, "inside the 96-byte header"),
        ("truncated-level-table", head - 10, "inside the level table"),
        (
            "truncated-base-level",
            level0.start + level0.len() / 2,
            "in the middle of level 0",
        ),
        (
            "truncated-mid-level",
            level2.start + level2.len() / 2,
            "in the middle of level 2 (levels 0 and 1 decode first)",
        ),
        (
            "truncated-last-byte",
            subject.len() - 1,
            "one byte before the end",
        ),
    ] {
        s.invalid(
            name,
            "truncated",
            &format!("The icosphere stream cut {what}."),
            &["truncated"],
            cut(at),
        );
    }

    // Checksums.
    s.invalid(
        "checksum-header",
        "checksum-mismatch",
        "A bit of the header's origin flipped; the header CRC left as it was.",
        &["checksum"],
        flip(subject.clone(), 40, 0x01),
    );
    s.invalid(
        "checksum-level-table",
        "checksum-mismatch",
        "A bit of level 1's geometric error flipped in the level table; its CRC left as it was.",
        &["checksum"],
        flip(subject.clone(), table_entry(1) + 24, 0x01),
    );
    s.invalid(
        "checksum-level-header",
        "checksum-mismatch",
        "A bit of a split count of level 1 flipped; the level header CRC left as it was.",
        &["checksum"],
        flip(subject.clone(), split_count_at(&subject, 1, 0), 0x01),
    );
    let c = chunk_count(&subject, 2) - 1;
    let payload = chunk_payload(&subject, 2, c);
    s.invalid(
        "checksum-chunk",
        "checksum-mismatch",
        "A bit of the last chunk of level 2 flipped; its CRC left as it was (met when the chunk is loaded).",
        &["checksum"],
        flip(subject.clone(), payload.start + payload.len() / 2, 0x01),
    );

    // Signature and version.
    s.invalid(
        "bad-magic",
        "bad-magic",
        "The second signature byte changed from 'S' to 'X'.",
        &["header"],
        {
            let mut b = subject.clone();
            b[1] = b'X';
            b
        },
    );
    s.invalid(
        "unsupported-version",
        "unsupported-version",
        "Major version 2, the previous format (header CRC recomputed).",
        &["header", "versioning"],
        {
            let mut b = subject.clone();
            b[8] = 2;
            fix_header_crc(&mut b);
            b
        },
    );
    s.valid(
        "minor-version-1",
        "Minor version 1 of major 3 with every reserved field zero: decodes exactly as 3.0 (header CRC recomputed).",
        &["header", "versioning"],
        {
            let mut b = handmade::tetra_stream(ChunkCodec::Stored);
            b[9] = 1;
            fix_header_crc(&mut b);
            b
        },
    );

    s.valid(
        "trailing-bytes-ignored",
        "The icosphere stream followed by 16 bytes past the end of its last level, which decoders ignore (SPEC §10.3).",
        &["framing"],
        {
            let mut b = subject.clone();
            b.extend_from_slice(b"not splitstream!");
            b
        },
    );
    s.invalid(
        "seed-level-trailing-data",
        "count-mismatch",
        "A tetrahedron seed with no rounds, but one byte in level 0's flag substream: the seed's hash is reported, then the end of level 0 fails (SPEC §7.6).",
        &["handmade", "record-count", "seed"],
        {
            let mut p = unframe(&write_stream(
                &handmade::stored(),
                &[handmade::tetrahedron_leaves()],
            ));
            p.levels[0].substreams[0].push(0);
            reframe(&p)
        },
    );
    s.invalid(
        "round-count-mismatch",
        "count-mismatch",
        "Level-table entry 1 declares one round more than level 1's header (table CRC recomputed).",
        &["framing", "level-count"],
        {
            let mut b = subject.clone();
            let at = table_entry(1) + 20;
            let rounds = u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"));
            b[at..at + 4].copy_from_slice(&(rounds + 1).to_le_bytes());
            fix_table_crc(&mut b);
            b
        },
    );

    // Header capacities and the declared workspace.
    let patch_header = |f: &dyn Fn(&mut Header)| {
        let mut h = Header::parse(&subject).expect("valid");
        f(&mut h);
        let mut b = subject.clone();
        let mut out = [0u8; 96];
        h.write(&mut out);
        b[..96].copy_from_slice(&out);
        b
    };
    s.invalid(
        "capacity-vertices-lie",
        "capacity-exceeded",
        "Header vertex_capacity one less than the last level's vertex count (header CRC recomputed).",
        &["capacity"],
        patch_header(&|h| h.vertex_capacity -= 1),
    );
    s.invalid(
        "capacity-triangles-lie",
        "capacity-exceeded",
        "Header triangle_capacity one less than the last level's triangle count (header CRC recomputed).",
        &["capacity"],
        patch_header(&|h| h.triangle_capacity -= 1),
    );
    s.invalid(
        "workspace-bytes-wrong",
        "malformed",
        "Header workspace_bytes 8 more than SPEC §9 gives (header CRC recomputed).",
        &["capacity", "workspace"],
        patch_header(&|h| h.workspace_bytes += 8),
    );

    // Reserved fields and codecs (covering CRCs recomputed).
    s.invalid(
        "reserved-header-flag",
        "malformed",
        "Header flag bit 4 (reserved; bit 2 is the framing since 3.11, bit 3 the level table since 3.12) set.",
        &["reserved"],
        {
            let mut b = subject.clone();
            b[10] |= 16;
            fix_header_crc(&mut b);
            b
        },
    );
    for (name, lanes) in [("lane-count-0", 0u8), ("lane-count-33", 33)] {
        s.invalid(
            name,
            "malformed",
            &format!("Header lane_count (byte 13) {lanes}, outside 1..=32."),
            &["header", "rans"],
            {
                let mut b = subject.clone();
                b[13] = lanes;
                fix_header_crc(&mut b);
                b
            },
        );
    }
    s.invalid(
        "reserved-level-table",
        "malformed",
        "The reserved field of level-table entry 0 not zero (table CRC recomputed).",
        &["reserved"],
        {
            let mut b = subject.clone();
            b[table_entry(0) + 28] = 1;
            fix_table_crc(&mut b);
            b
        },
    );
    s.invalid(
        "reserved-chunk-entry",
        "malformed",
        "The reserved field of level 1's first chunk-directory entry not zero (level header CRC recomputed).",
        &["reserved"],
        with_level_header_byte(&subject, 1, chunk_entry_at(&subject, 1, 0) + 2, 1),
    );
    s.invalid(
        "plane-policy-reserved",
        "malformed",
        "Level 1's plane policy byte (level header byte 8) set to 6, the first value 3.1 reserves (level header CRC recomputed).",
        &["reserved", "plane-policy"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1), 6),
    );
    s.invalid(
        "plane-policy-255",
        "malformed",
        "Level 0's plane policy byte set to 255 (level header CRC recomputed).",
        &["reserved", "plane-policy"],
        with_level_header_byte(&subject, 0, plane_policy_at(&subject, 0), 255),
    );
    s.invalid(
        "wing-policy-reserved",
        "malformed",
        "Level 1's wing policy byte (level header byte 9) set to 3, the first value 3.2 reserves (level header CRC recomputed).",
        &["reserved", "wing-policy"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1) + 1, 3),
    );
    s.invalid(
        "deficit-contexts-reserved",
        "malformed",
        "Level 1's contexts byte (level header byte 10) set to 2 in a stream of the schedule split-valences: reserved from 3.3, and since 3.10 `split-history`, which only the schedule every-vertex allows (level header CRC recomputed).",
        &["reserved", "deficit-contexts"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1) + 2, 2),
    );
    // A level whose rANS chunks were written under the deficit contexts
    // `valence` (5 and 6 tables for deficit-p and deficit-c) read as
    // `plain` (1 and 5): deficit-p's first chunk then ends its tables early
    // and reads a table byte as its lane directory (SPEC §5.5.2, §5.5.3).
    s.invalid(
        "deficit-contexts-switched",
        "malformed",
        "Level 1, written with deficit contexts `valence` (byte 10 = 1), relabelled `plain` (level header CRC recomputed): its deficit-p and deficit-c chunks hold more tables than `plain` reads.",
        &["deficit-contexts", "rans"],
        {
            let valence = encoded(
                &sphere,
                EncodeOptions {
                    deficits: Some(DeficitContexts::Valence),
                    codec: ChunkCodec::RansAlways { lanes: 4 },
                    ..opts()
                },
            );
            let at = plane_policy_at(&valence, 1) + 2;
            assert_eq!(valence[at], 1);
            with_level_header_byte(&valence, 1, at, 0)
        },
    );
    s.invalid(
        "reserved-level-header",
        "malformed",
        "Level 1's level header byte 11 (after the deficit contexts; reserved until 3.6, the record order since 3.7) is 1, positions-first, in an optimal-mode stream, where it is not allowed (level header CRC recomputed).",
        &["reserved", "plane-policy", "positions-first"],
        with_level_header_byte(&subject, 1, plane_policy_at(&subject, 1) + 3, 1),
    );
    // A stored chunk longer than the header's max_chunk_len: the buffer a
    // decoder sized from the header could not hold it (SPEC §5.2). Both
    // lengths are below RANS_SLOT_BYTES, so the declared workspace stays
    // right (SPEC §9) and the level header is what fails.
    s.invalid(
        "byte-chunk-above-max-chunk-len",
        "malformed",
        "A stream of 64-byte stored chunks whose header says max_chunk_len 63 and minor version 4 (header CRC recomputed; the declared workspace is unchanged, both lengths being below RANS_SLOT_BYTES): level 0's first 64-byte chunk is above the maximum, which in 3.4 still bounds stored and deflate chunks, whatever the minor version.",
        &["codec", "byte-chunk-above-max"],
        {
            let mut stream = encoded(
                &sphere,
                EncodeOptions {
                    codec: ChunkCodec::Stored,
                    chunk_limit: 64,
                    rans_chunk_limit: 64,
                    ..opts()
                },
            );
            assert_eq!(Header::parse(&stream).expect("valid").max_chunk_len, 64);
            stream[24..28].copy_from_slice(&63u32.to_le_bytes());
            stream[9] = 4;
            fix_header_crc(&mut stream);
            stream
        },
    );
    s.invalid(
        "unknown-codec",
        "malformed",
        "Codec id 3 (reserved) on a stored chunk of level 1 (level header CRC recomputed).",
        &["codec"],
        {
            let mut b = stored_subject.clone();
            assert_eq!(chunk_codec(&b, 1, 0), 0);
            b[chunk_entry_at(&stored_subject, 1, 0) + 1] = 3;
            fix_level_header_crc(&mut b, 1);
            b
        },
    );
    s.invalid(
        "corrupt-deflate-chunk",
        "malformed",
        "A deflate chunk of level 1 whose first byte announces the reserved block type 3; chunk and level header CRCs recomputed.",
        &["codec"],
        {
            let mut b = subject.clone();
            let c = (0..chunk_count(&b, 1))
                .find(|&c| chunk_codec(&b, 1, c) == 1)
                .expect("a deflate chunk in level 1");
            let at = chunk_payload(&b, 1, c).start;
            b[at] = 0xFF;
            fix_chunk_crc(&mut b, 1, c);
            b
        },
    );

    // Record-level faults, re-framed with the writer (all checksums valid).
    let parts = unframe(&subject);
    s.invalid(
        "ring-offset-wing-distance",
        "ring-offset-out-of-range",
        "Level 1's first split record with wing distance 255 (o + d beyond the ring).",
        &["records", "ring-offset"],
        {
            let mut p = parts.clone();
            p.levels[1].substreams[2][0] = 255;
            reframe(&p)
        },
    );
    // The near order's ranks (3.2) out of range: the first wing's rank u
    // beyond the m eligible entries, the second's v beyond those after it.
    let near = unframe(&encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            codec: ChunkCodec::Stored,
            wings: Some(WingPolicy::Near),
            ..opts()
        },
    ));
    for (slot, name, what) in [
        (
            1,
            "near-wing-first-rank",
            "first wing's near rank u = 255 (u >= m)",
        ),
        (
            2,
            "near-wing-second-rank",
            "second wing's near rank v = 255 (beyond the entries after the first)",
        ),
    ] {
        s.invalid(
            name,
            "ring-offset-out-of-range",
            &format!(
                "Level 1 (wing policy `near`, 3.2): its first split record's {what} (SPEC §7.4)."
            ),
            &["records", "ring-offset", "wing-policy"],
            {
                let mut p = near.clone();
                assert_eq!(p.levels[1].wings, WingPolicy::Near);
                p.levels[1].substreams[slot][0] = 255;
                reframe(&p)
            },
        );
    }
    s.invalid(
        "flag-count-declared-less",
        "count-mismatch",
        "A round of the last level declares one split fewer than it flags (level counts in the table adjusted to the declaration).",
        &["records", "flag-count"],
        {
            let mut p = parts.clone();
            let l = &mut p.levels[last as usize];
            let r = l.round_splits.iter().position(|&n| n >= 2).expect("a round with 2 splits");
            l.round_splits[r] -= 1;
            l.vertex_count -= 1;
            l.triangle_count -= 2;
            reframe(&p)
        },
    );
    s.invalid(
        "level-triangles-low",
        "count-mismatch",
        "The last level's table entry (and so the header capacity) one triangle short of what its splits make.",
        &["records", "level-count"],
        {
            let mut p = parts.clone();
            p.levels[last as usize].triangle_count -= 1;
            reframe(&p)
        },
    );
    s.invalid(
        "seed-triangles-over-entry",
        "count-mismatch",
        "Level 0 alone, its table entry (and so the header capacity and workspace) one triangle short of the seed mesh its header declares (3.5, SPEC §5.1: failed in the level header, before the seed is read; a 3.4 decoder met it as capacity-exceeded or count-mismatch, by its memory).",
        &["framing", "level-count", "capacity"],
        {
            let mut p = parts.clone();
            p.levels.truncate(1);
            let (_, seed_triangles, _) = p.levels[0].seed.as_ref().expect("level 0 has a seed");
            p.levels[0].triangle_count = seed_triangles - 1;
            reframe(&p)
        },
    );
    s.invalid(
        "record-trailing-data",
        "count-mismatch",
        "One byte appended to the edge substream of the last level: data after the level's last record.",
        &["records", "record-count"],
        {
            let mut p = parts.clone();
            p.levels[last as usize].substreams[5].push(0);
            reframe(&p)
        },
    );
    s.invalid(
        "record-trailing-data-in-chunk",
        "count-mismatch",
        "One byte appended to the wing-distance substream of the last level, inside its last chunk (no chunk added): a loaded chunk with a byte no record reads (SPEC §7.6).",
        &["records", "record-count"],
        {
            let mut p = parts.clone();
            p.levels[last as usize].substreams[2].push(0);
            let b = reframe(&p);
            assert_eq!(
                chunk_count(&b, last),
                chunk_count(&subject, last),
                "the byte stays in the substream's last chunk"
            );
            b
        },
    );
    s.invalid(
        "record-substream-short",
        "count-mismatch",
        "The wing-distance substream of the last level one byte short: it runs out in the last record.",
        &["records", "record-count"],
        {
            let mut p = parts.clone();
            p.levels[last as usize].substreams[2].pop();
            reframe(&p)
        },
    );
    s.invalid(
        "flags-padding-not-zero",
        "count-mismatch",
        "The top padding bit after the last flag of a refinement level set (SPEC §5.4): every round of that level decodes, and the level's end-of-level check finds the unread bit.",
        &["records", "record-count"],
        {
            // The first level whose last flag byte has padding bits: its
            // flag count is not a multiple of 8. Setting the top bit of a
            // byte without padding would change a real flag instead (a
            // count-mismatch within a round), so each level is tried and
            // kept only when decoder-core decodes all its rounds first.
            let rounds_through = |k: usize| -> usize {
                1 + parts.levels[..=k]
                    .iter()
                    .map(|l| l.round_splits.len())
                    .sum::<usize>()
            };
            (1..parts.levels.len())
                .find_map(|k| {
                    let mut p = parts.clone();
                    *p.levels[k].substreams[0].last_mut()? |= 0x80;
                    let bytes = reframe(&p);
                    let outcome = builtin::decoder_core(&bytes);
                    (outcome.verdict == Verdict::Error("count-mismatch".into())
                        && outcome.hashes.len() == rounds_through(k))
                    .then_some(bytes)
                })
                .expect("a level whose flags end with padding bits")
        },
    );
    s.invalid(
        "deflate-unused-payload-byte",
        "malformed",
        "A deflate chunk (one stored block) followed by a zero byte inside its payload, lengths and CRCs matching: no payload byte may remain unused (SPEC §5.2).",
        &["chunks", "deflate-stored-block"],
        // Level 1's first chunk: level 0 decodes first.
        wrap_chunks_in_deflate_with(&stored_subject, Some((1, 0))),
    );
    s.invalid(
        "placement-code-3",
        "malformed",
        "Constrained mode: the first placement code of level 1 is 3.",
        &["records", "position-constrained"],
        {
            let mut p = unframe(&constrained);
            p.levels[1].substreams[6][0] = 3;
            reframe(&p)
        },
    );

    // Hand-made faults (SPEC §6.3, §7).
    let hand = |levels: &[splitstream_decoder_core::writer::LevelPayload]| {
        write_stream(&handmade::deflated(), levels)
    };
    let tetra = handmade::tetrahedron;
    s.invalid(
        "ring-offset-handmade",
        "ring-offset-out-of-range",
        "Tetrahedron split with wing ranks o' = 2, d' = 1 among m = 3 eligible ring entries (o' + d' = m).",
        &["handmade", "ring-offset"],
        {
            let mut rec = tetra_split();
            rec.o = 2;
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.invalid(
        "ring-offset-distance-0",
        "ring-offset-out-of-range",
        "Tetrahedron split with wing rank distance d' = 0.",
        &["handmade", "ring-offset"],
        {
            let mut rec = tetra_split();
            rec.d = 0;
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.invalid(
        "wing-rank-skips-round-start-candidate",
        "ring-offset-out-of-range",
        "Tetrahedron with adjacent candidates 0 and 1: vertex 1 was a candidate at the start of the round, so it may not be a wing and vertex 0's ring (1, 3, 2) has m = 2 eligible entries; ranks o' = 0, d' = 2 name none (SPEC §7.4).",
        &["handmade", "ring-offset", "wing-eligibility"],
        {
            let rec = Rec {
                m: 2,
                d: 2,
                ..tetra_split()
            };
            hand(&[
                handmade::tetrahedron_two_candidates(),
                tetra_split_level(rec),
            ])
        },
    );
    s.valid(
        "wing-ranks-skip-round-start-candidate",
        "Tetrahedron with adjacent candidates 0 and 1; vertex 0 splits and ranks 0 and 1 among its m = 2 eligible ring entries (3 and 2; vertex 1 was a candidate at round start) name wings 3 and 2. Vertex 1 stays a candidate: its flag is inferred (SPEC §7.2, §7.4).",
        &["handmade", "one-split", "wing-eligibility", "inferred-flags"],
        {
            let build = |rec: Rec| {
                write_stream(
                    &handmade::stored(),
                    &[
                        handmade::tetrahedron_two_candidates(),
                        tetra_split_level(rec),
                    ],
                )
            };
            let rec = Rec {
                m: 2,
                ..tetra_split()
            };
            let rec = handmade::solve(rec, 0, 4, [0, 0, 0], [4, 0, 2], &build)
                .expect("the record decodes");
            build(rec)
        },
    );
    s.invalid(
        "flag-count-handmade",
        "count-mismatch",
        "Tetrahedron: one split declared, the only candidate's flag 0.",
        &["handmade", "flag-count"],
        hand(&[tetra(), level(&[false], vec![1], &[tetra_split()], 5, 6)]),
    );
    s.invalid(
        "flag-of-inferred-candidate",
        "count-mismatch",
        "Tetrahedron with adjacent candidates 0 and 1; the stream codes a flag 1 for vertex 1 too, but vertex 1's flag is inferred 0 once vertex 0 is flagged (SPEC §7.2), so the round flags 1 split where 2 are declared.",
        &["handmade", "independence", "inferred-flags"],
        hand(&[
            handmade::tetrahedron_two_candidates(),
            level(&[true, true], vec![2], &[tetra_split(), tetra_split()], 6, 8),
        ]),
    );
    s.invalid(
        "valence-overflow-wing",
        "valence-overflow",
        "Octahedron whose non-adjacent vertices 0 and 1 are candidates and whose vertex 2 (deficit 1) is next to both: both split in one round with 2 as a wing. At round start 2 may be a wing (deficit 1); after the first split its deficit is 0 and the second split fails (SPEC §7.5).",
        &["handmade", "valence", "wing-eligibility"],
        {
            let rec = Rec {
                m: 4,
                valence_c: 5,
                e: [0; 3],
                t: [0; 3],
                ..tetra_split()
            };
            hand(&[
                handmade::octahedron(&[0, 0, 1, 255, 255, 255]),
                level(&[true, true], vec![2], &[rec, rec], 8, 12),
            ])
        },
    );
    rans_vectors(s);
    s.invalid(
        "valence-overflow-base",
        "valence-overflow",
        "Base tetrahedron vertex of valence 3 with deficit 253 (split valence 256 > 255).",
        &["handmade", "valence", "base-only"],
        hand(&[handmade::tetrahedron_with(&[253, LEAF, LEAF, LEAF])]),
    );
    s.invalid(
        "valence-overflow-split",
        "valence-overflow",
        "Split record whose split-valence symbol for P is 254: split valence 256 > 255 (SPEC §7.4).",
        &["handmade", "valence", "split-valence"],
        {
            let rec = Rec {
                sp: 254,
                ..tetra_split()
            };
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.invalid(
        "split-valence-below-valence",
        "valence-overflow",
        "Split record whose split-valence symbol for C is 1 (split valence 3) while C's valence right after the split is 4 (SPEC §7.4).",
        &["handmade", "valence", "split-valence"],
        {
            let rec = Rec {
                sc: 1,
                ..tetra_split()
            };
            hand(&[tetra(), tetra_split_level(rec)])
        },
    );
    s.valid(
        "split-valence-255",
        "Split record whose split-valence symbol for P is 253: split valence 255, P keeps deficit 252 at valence 3 (the largest legal symbol, SPEC §7.4).",
        &["handmade", "one-split", "split-valence"],
        {
            let build = |rec: Rec| {
                write_stream(
                    &handmade::stored(),
                    &[tetra(), tetra_split_level(rec)],
                )
            };
            let rec = Rec {
                sp: 253,
                ..tetra_split()
            };
            let rec = handmade::solve(rec, 0, 4, [0, 0, 0], [2, 2, 2], &build)
                .expect("the record decodes");
            build(rec)
        },
    );
    s.invalid(
        "non-manifold-bowtie",
        "non-manifold",
        "Base mesh of two tetrahedra sharing one vertex (two fans at a vertex).",
        &["handmade", "base-only", "manifold"],
        hand(&[handmade::bowtie()]),
    );
    s.invalid(
        "non-manifold-flipped-face",
        "non-manifold",
        "Base tetrahedron with one face reversed: a directed edge used twice.",
        &["handmade", "base-only", "manifold"],
        hand(&[base(
            &handmade::TETRA_POSITIONS,
            &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 3, 2]],
            &[255; 4],
        )]),
    );
    s.invalid(
        "position-out-of-range-base",
        "position-out-of-range",
        "Base vertex x = 256 with 8 bits per axis.",
        &["handmade", "base-only", "positions"],
        hand(&[base(
            &[[0, 0, 0], [256, 0, 0], [0, 10, 0]],
            &[[0, 1, 2]],
            &[255; 3],
        )]),
    );
    s.invalid(
        "position-out-of-range-split",
        "position-out-of-range",
        "A split placing C at x = 300 with 8 bits per axis.",
        &["handmade", "positions"],
        {
            let build = |rec: Rec| hand(&[tetra(), tetra_split_level(rec)]);
            let rec = handmade::solve(tetra_split(), 0, 4, [0, 0, 0], [300, 2, 2], &build)
                .expect("the record decodes");
            build(rec)
        },
    );
    let triangle = || handmade::triangle(&[LEAF; 3]);
    for (name, bytes, what) in [
        (
            "varint-not-minimal",
            &[0x80u8, 0x00, 0x01, 0x02][..],
            "index 0 written as 0x80 0x00 (not minimal)",
        ),
        (
            "varint-too-long",
            &[0x80, 0x80, 0x80, 0x80, 0x80, 0x00, 0x01, 0x02][..],
            "a 6-byte varint",
        ),
        (
            "varint-over-32-bits",
            &[0xFF, 0xFF, 0xFF, 0xFF, 0x1F, 0x01, 0x02][..],
            "a 5-byte varint above 2^32 - 1",
        ),
    ] {
        s.invalid(
            name,
            "malformed",
            &format!("Base triangle substream with {what}."),
            &["handmade", "varint"],
            hand(&[handmade::with_raw_substream(triangle(), 1, bytes)
                .expect("a base level has a triangle substream (1)")]),
        );
    }
    every_vertex_invalid(s);
    super::positions_first::positions_first_invalid(s);
}

/// Faults of the schedule `every-vertex` (SPEC §3.2, §5.1, §6.3, §7.6,
/// format 3.6), and a stream read under the other schedule.
fn every_vertex_invalid(s: &mut Specs) {
    let tag = "schedule-every-vertex";
    let every = encoded(
        &meshes::icosphere(2),
        every_vertex(EncodeOptions {
            codec: ChunkCodec::Stored,
            ..opts()
        }),
    );
    let split_valences = encoded(
        &meshes::icosphere(2),
        EncodeOptions {
            codec: ChunkCodec::Stored,
            ..opts()
        },
    );
    s.invalid(
        "every-vertex-deficit-contexts-valence",
        "malformed",
        "A stream of the schedule every-vertex whose level 1 says deficit contexts `valence` (level header byte 10 = 1, CRC recomputed): under every-vertex, which codes no split valences, it MUST be 0 or (3.10) 2 (SPEC §5.1).",
        &["deficit-contexts", tag],
        with_level_header_byte(&every, 1, plane_policy_at(&every, 1) + 2, 1),
    );
    s.invalid(
        "every-vertex-contexts-reserved",
        "malformed",
        "A stream of the schedule every-vertex whose level 1's contexts byte (level header byte 10) is 3, the first value 3.10 reserves (level header CRC recomputed).",
        &["reserved", "flag-contexts", tag],
        with_level_header_byte(&every, 1, plane_policy_at(&every, 1) + 2, 3),
    );
    // A level whose flags were written in the 8 contexts of `split-history`
    // read as `valence` (5): the flags' first chunk then ends its tables
    // early and reads a table byte as its lane directory (SPEC §5.5.2).
    s.invalid(
        "every-vertex-flag-contexts-switched",
        "malformed",
        "A stream of the schedule every-vertex whose level 1, written with the flag contexts `split-history` (byte 10 = 2, 8 tables), is relabelled `valence` (byte 0, 5 tables; level header CRC recomputed).",
        &["flag-contexts", "rans", tag],
        {
            let history = encoded(
                &meshes::icosphere(2),
                every_vertex(EncodeOptions {
                    deficits: Some(DeficitContexts::SplitHistory),
                    codec: ChunkCodec::RansAlways { lanes: 4 },
                    adaptive_tables: false,
                    ..opts()
                }),
            );
            let at = plane_policy_at(&history, 1) + 2;
            assert_eq!(history[at], 2);
            with_level_header_byte(&history, 1, at, 0)
        },
    );
    s.invalid(
        "every-vertex-deficit-p-value",
        "count-mismatch",
        "A stream of the schedule every-vertex with one value in level 1's deficit-p substream (re-framed, every checksum valid): under every-vertex nothing reads it, so it is left over at the level's end (SPEC §7.4, §7.6).",
        &["records", tag],
        {
            let mut p = unframe(&every);
            p.levels[1].substreams[3].push(6);
            reframe(&p)
        },
    );
    s.invalid(
        "every-vertex-relabelled-split-valences",
        "count-mismatch",
        "A stream written with split valences whose header says every-vertex (flag bit 1 set, CRC recomputed): the seed's base-deficits substream holds values that every-vertex does not read (SPEC §6.3).",
        &["reserved", tag],
        {
            let mut b = split_valences.clone();
            b[10] |= 2;
            fix_header_crc(&mut b);
            b
        },
    );
    s.invalid(
        "every-vertex-relabelled-as-split-valences",
        "count-mismatch",
        "A stream of the schedule every-vertex whose header says split valences (flag bit 1 cleared, CRC recomputed): the seed's base-deficits substream, which split valences read, is empty (SPEC §6.3).",
        &["reserved", tag],
        {
            let mut b = every.clone();
            b[10] &= !2;
            fix_header_crc(&mut b);
            b
        },
    );
}
