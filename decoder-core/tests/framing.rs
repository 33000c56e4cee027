//! The two level framings (SPEC §5.1, §5.1.1, format 3.11): the same
//! payloads decode to the same states whichever frames them, the compact
//! header's fields read back as the fixed one's, and no cut of a compact
//! level header panics or decodes.

use splitstream_decoder_core::handmade::{params, tetra_stream_under};
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{ChunkCodec, StreamParams};
use splitstream_decoder_core::{ChunkEntry, Framing, Header, LevelTable};

fn codecs() -> [ChunkCodec; 4] {
    [
        ChunkCodec::Stored,
        ChunkCodec::Deflate(6),
        ChunkCodec::RansAlways { lanes: 1 },
        ChunkCodec::RansAlways { lanes: 5 },
    ]
}

fn framed(codec: ChunkCodec, framing: Framing) -> Vec<u8> {
    tetra_stream_under(&StreamParams {
        framing,
        ..params(codec)
    })
}

/// A level's round count, split counts and directory, as parsed.
type LevelFields = (u32, Vec<u32>, Vec<ChunkEntry>);

fn level_fields(stream: &[u8]) -> Vec<LevelFields> {
    let header = Header::parse(stream).unwrap();
    let table = LevelTable::parse(stream, &header).unwrap();
    (0..header.level_count)
        .map(|k| {
            let info = table.get(k);
            let bytes = &stream[info.offset as usize..(info.offset + info.length as u64) as usize];
            let lh = table.level_header(k, bytes, header.level_rules()).unwrap();
            let chunks = lh.chunks().map(|e| e.unwrap()).collect();
            (lh.round_count, lh.split_counts().collect(), chunks)
        })
        .collect()
}

#[test]
fn both_framings_decode_to_the_same_states_and_read_the_same_fields() {
    for codec in codecs() {
        let fixed = framed(codec, Framing::Fixed);
        let compact = framed(codec, Framing::Compact);
        assert!(compact.len() < fixed.len(), "{codec:?}");
        assert_eq!(Header::parse(&compact).unwrap().framing, Framing::Compact);
        assert_eq!(Header::parse(&fixed).unwrap().framing, Framing::Fixed);
        let (a, b) = (
            decode_all(&fixed, true).unwrap(),
            decode_all(&compact, true).unwrap(),
        );
        assert_eq!(a.round_hashes, b.round_hashes, "{codec:?}");
        assert_eq!((a.positions, a.triangles), (b.positions, b.triangles));
        assert_eq!(level_fields(&fixed), level_fields(&compact), "{codec:?}");
    }
}

#[test]
fn a_compact_level_cut_anywhere_fails_cleanly() {
    for codec in codecs() {
        let stream = framed(codec, Framing::Compact);
        let header = Header::parse(&stream).unwrap();
        let table = LevelTable::parse(&stream, &header).unwrap();
        for k in 0..header.level_count {
            let info = table.get(k);
            let start = info.offset as usize;
            let level = &stream[start..start + info.length as usize];
            let rules = header.level_rules();
            for cut in 0..level.len() {
                let short = &level[..cut];
                assert!(
                    splitstream_decoder_core::LevelHeader::parse(short, k == 0, rules).is_err(),
                    "{codec:?}: level {k} cut at {cut} of {}",
                    level.len()
                );
            }
        }
    }
}

#[test]
fn a_compact_header_with_every_byte_changed_never_panics() {
    let stream = framed(ChunkCodec::Stored, Framing::Compact);
    let header = Header::parse(&stream).unwrap();
    let table = LevelTable::parse(&stream, &header).unwrap();
    let info = table.get(1);
    let start = info.offset as usize;
    let level = &stream[start..start + info.length as usize];
    for at in 0..level.len().min(96) {
        for value in [0x00, 0x01, 0x0F, 0x10, 0x7F, 0x80, 0xFF] {
            let mut bytes = level.to_vec();
            bytes[at] = value;
            // Parsing may succeed (a payload byte, or the value it had);
            // it must not panic.
            let _ =
                splitstream_decoder_core::LevelHeader::parse(&bytes, false, header.level_rules());
        }
    }
}
