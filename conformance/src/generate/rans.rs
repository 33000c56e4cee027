//! The rANS codec's invalid vectors (SPEC §5.5): broken tables and lanes.

use splitstream_decoder_core::handmade;
use splitstream_decoder_core::limits::codec;
use splitstream_decoder_core::writer::{ChunkCodec, write_stream};
use splitstream_encoder::emit::EncodeOptions;

use super::meshes;
use super::mutate::*;
use super::{Specs, encoded, opts};
use handmade::{tetra_split, tetra_split_level};

/// Faults inside rANS chunks (SPEC §5.5), patched into SPEC Appendix A's
/// stream coded with rANS in one lane (chunk CRCs recomputed).
pub(super) fn rans_vectors(s: &mut Specs) {
    let subject = handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 1 });
    // Level 1's first chunk is its flags: one context, one lane.
    let flags = chunk_payload(&subject, 1, 0);
    assert_eq!(chunk_codec(&subject, 1, 0), codec::RANS);
    let layout = rans_layout(&subject, flags.clone(), 1, 1);
    let patched = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = subject.clone();
        f(&mut b);
        fix_chunk_crc(&mut b, 1, 0);
        b
    };
    s.invalid(
        "rans-lane-state-low",
        "malformed",
        "The flags lane's initial state is 1, below 2^23 (SPEC §5.5.3).",
        &["rans", "handmade"],
        patched(&|b| b[layout.lanes[0]..layout.lanes[0] + 4].copy_from_slice(&1u32.to_le_bytes())),
    );
    s.invalid(
        "rans-lane-not-exhausted",
        "malformed",
        "The flags lane's initial state is 2^23 + 1: its only value decodes, but the lane does not end in state 2^23 (SPEC §5.5.4).",
        &["rans", "handmade"],
        patched(&|b| {
            b[layout.lanes[0]..layout.lanes[0] + 4].copy_from_slice(&((1u32 << 23) + 1).to_le_bytes())
        }),
    );
    s.invalid(
        "rans-too-many-tokens",
        "malformed",
        "The flags table announces 45 tokens; the code has 44 (SPEC §5.5.2).",
        &["rans", "handmade"],
        patched(&|b| b[layout.token_counts[0]] = 45),
    );
    s.invalid(
        "rans-lane-shorter-than-its-state",
        "malformed",
        "The flags lane is 3 bytes long: its 4-byte initial state does not fit (SPEC §5.5.3; chunk payload replaced, its length and every CRC fixed).",
        &["rans", "handmade"],
        {
            let lane = layout.lanes[0];
            // One lane: its length is the one-byte varint just before it.
            let mut payload = subject[flags.start..lane - 1].to_vec();
            payload.push(3);
            payload.extend_from_slice(&subject[lane..lane + 3]);
            with_chunk_payload(&subject, 1, 0, payload)
        },
    );
    s.invalid(
        "rans-adaptive-too-many-states",
        "malformed",
        "In a stream of 4 lanes, the flags table is adaptive with 16 tokens (table byte 0x8F): 15 probabilities per lane, 60 in all, above the 48 a table holds (SPEC §5.5.2, 3.9; chunk payload replaced, its length and every CRC fixed).",
        &["rans", "rans-adaptive", "handmade"],
        {
            let subject = handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 4 });
            let flags = chunk_payload(&subject, 1, 0);
            let layout = rans_layout(&subject, flags.clone(), 1, 4);
            // The static table (its byte and counts) becomes one byte.
            let mut payload = vec![0x8F];
            let after_table = layout.token_counts[0] + 1 + 2;
            assert_eq!(subject[layout.token_counts[0]], 2, "a two-token table, counts of one byte");
            payload.extend_from_slice(&subject[after_table..flags.end]);
            with_chunk_payload(&subject, 1, 0, payload)
        },
    );
    s.invalid(
        "rans-adaptive-too-many-states-unused",
        "malformed",
        "In a stream of 4 lanes, the wing-offset chunk's table of context 7, which no value reads, is adaptive with 16 tokens (table byte 0x8F, in place of its 0): 60 probabilities, above the 48 a table holds (SPEC §5.5.2, 3.9). Nothing else is wrong, so only the bound fails it (chunk CRC fixed).",
        &["rans", "rans-adaptive", "handmade"],
        {
            let mut b = handmade::tetra_stream(ChunkCodec::RansAlways { lanes: 4 });
            // Level 1's second chunk: wing-offset (substream id 2), 8
            // contexts by the eligible entries; the tetrahedron's ring has
            // 3, so context 7 (9 or more) is never read.
            assert_eq!(b[chunk_entry_at(&b, 1, 1)], 2, "the wing-offset chunk");
            assert_eq!(chunk_codec(&b, 1, 1), codec::RANS);
            let layout = rans_layout(&b, chunk_payload(&b, 1, 1), 8, 4);
            let table = layout.token_counts[7];
            assert_eq!(b[table], 0, "context 7's table is unused");
            b[table] = 0x8F;
            fix_chunk_crc(&mut b, 1, 1);
            b
        },
    );
    s.invalid(
        "rans-adaptive-table-too-short",
        "malformed",
        "The flags table of the one-lane stream is the adaptive table byte 0x81 of handmade-tetra-split-rans-adaptive followed by nothing: the lane directory is missing (SPEC §5.5.2, §5.5.3; chunk payload replaced, its length and every CRC fixed).",
        &["rans", "rans-adaptive", "handmade"],
        with_chunk_payload(&subject, 1, 0, vec![0x81]),
    );
    // The tetrahedron's split in rANS with one substream holding a single
    // value out of its field's range (slots from substream id 1).
    let out_of_range = |slot: usize, value: u32| {
        let mut lvl = tetra_split_level(tetra_split());
        let mut w = splitstream_decoder_core::writer::SubstreamWriter::default();
        w.varint(value);
        lvl.substreams[slot] = w;
        write_stream(
            &handmade::params(ChunkCodec::RansAlways { lanes: 1 }),
            &[handmade::tetrahedron(), lvl],
        )
    };
    s.invalid(
        "rans-bit-value-2",
        "malformed",
        "The flags substream, rANS-coded, holds the value 2 for a one-bit field (SPEC §5.5).",
        &["rans", "handmade"],
        out_of_range(0, 2),
    );
    s.invalid(
        "rans-byte-value-256",
        "malformed",
        "The deficit-p substream, rANS-coded, holds the value 256 for a byte field (SPEC §5.5): the wings read, the split-valence symbol does not.",
        &["rans", "handmade"],
        // Slot 3: substream id 4, deficit-p.
        out_of_range(3, 256),
    );
    s.invalid(
        "rans-mixed-codecs",
        "malformed",
        "A substream whose chunks mix rANS and stored (the codec byte of its second chunk set to 0; level header CRC recomputed).",
        &["rans", "codec"],
        {
            let mut b = encoded(
                &meshes::icosphere(2),
                EncodeOptions {
                    codec: ChunkCodec::RansAlways { lanes: 2 },
                    chunk_limit: 5,
                    rans_chunk_limit: 5,
                    ..opts()
                },
            );
            let c = 1;
            assert_eq!(chunk_codec(&b, 1, c), codec::RANS);
            let id = |c: usize| b[chunk_entry_at(&b, 1, c)];
            assert_eq!(id(0), id(1), "two chunks of one substream");
            let at = chunk_entry_at(&b, 1, c) + 1;
            b[at] = codec::STORED;
            fix_level_header_crc(&mut b, 1);
            b
        },
    );
}
