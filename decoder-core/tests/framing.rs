//! The three framings (SPEC §4.1, §4.3, §5.1, §5.1.1, formats 3.11 and
//! 3.12): the same payloads decode to the same states whichever frames
//! them, the compact headers' and tables' fields read back as the fixed
//! ones', and no cut or changed byte of a compact level header or table
//! panics or decodes.

use splitstream_decoder_core::handmade::{params, tetra_stream_under};
use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::writer::{ChunkCodec, StreamParams};
use splitstream_decoder_core::{ChunkEntry, Error, Framing, Header, LevelInfo, LevelTable, crc32};

const FRAMINGS: [Framing; 3] = [Framing::Fixed, Framing::CompactLevels, Framing::Compact];

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

/// The level table's entries, offsets measured from the end of the table.
fn table_entries(stream: &[u8]) -> Vec<LevelInfo> {
    let header = Header::parse(stream).unwrap();
    let table = LevelTable::parse(stream, &header).unwrap();
    let head = header.head_len() as u64;
    let entries: Vec<LevelInfo> = table.iter().collect();
    assert_eq!(
        entries,
        (0..header.level_count)
            .map(|k| table.get(k))
            .collect::<Vec<_>>()
    );
    entries
        .into_iter()
        .map(|e| LevelInfo {
            offset: e.offset - head,
            ..e
        })
        .collect()
}

#[test]
fn every_framing_decodes_to_the_same_states_and_reads_the_same_fields() {
    for codec in codecs() {
        let streams = FRAMINGS.map(|f| framed(codec, f));
        let [fixed, compact_levels, compact] = &streams;
        assert!(compact_levels.len() < fixed.len(), "{codec:?}");
        assert!(compact.len() < compact_levels.len(), "{codec:?}");
        for (framing, stream) in FRAMINGS.iter().zip(&streams) {
            let header = Header::parse(stream).unwrap();
            assert_eq!(header.framing, *framing);
            // SPEC §1: the lowest minor version whose features are used.
            let minor = match framing {
                Framing::Fixed => header.version_minor,
                Framing::CompactLevels => 11,
                Framing::Compact => 12,
            };
            assert_eq!(header.version_minor, minor, "{framing:?}");
            let (a, b) = (
                decode_all(fixed, true).unwrap(),
                decode_all(stream, true).unwrap(),
            );
            assert_eq!(a.round_hashes, b.round_hashes, "{codec:?} {framing:?}");
            assert_eq!((a.positions, a.triangles), (b.positions, b.triangles));
            assert_eq!(level_fields(fixed), level_fields(stream), "{codec:?}");
            // The same counts, rounds and errors; a level's length follows
            // its header's framing.
            let counts = |s: &[u8]| {
                table_entries(s)
                    .into_iter()
                    .map(|e| {
                        (
                            e.vertex_count,
                            e.triangle_count,
                            e.round_count,
                            e.geometric_error,
                        )
                    })
                    .collect::<Vec<_>>()
            };
            assert_eq!(counts(fixed), counts(stream), "{codec:?}");
            if *framing == Framing::Compact {
                assert_eq!(table_entries(compact_levels), table_entries(stream));
            }
            // Everything after the table is the same bytes.
            let head = |s: &[u8]| Header::parse(s).unwrap().head_len();
            if *framing != Framing::Fixed {
                assert_eq!(
                    &compact_levels[head(compact_levels)..],
                    &stream[head(stream)..]
                );
            }
        }
    }
}

/// `stream` with its compact table replaced by `entries` (their CRC
/// recomputed), `table_len` set to match and the header CRC recomputed.
fn with_compact_table(stream: &[u8], entries: &[u8]) -> Vec<u8> {
    let header = Header::parse(stream).unwrap();
    let mut out = stream[..96].to_vec();
    let table_len = entries.len() as u32 + 4;
    out[28..32].copy_from_slice(&table_len.to_le_bytes());
    let crc = crc32(&out[..92]);
    out[92..96].copy_from_slice(&crc.to_le_bytes());
    out.extend_from_slice(entries);
    out.extend_from_slice(&crc32(entries).to_le_bytes());
    out.extend_from_slice(&stream[header.head_len()..]);
    out
}

fn compact_entries(stream: &[u8]) -> Vec<u8> {
    let header = Header::parse(stream).unwrap();
    stream[96..header.head_len() - 4].to_vec()
}

fn table_error(stream: &[u8]) -> Option<Error> {
    Header::parse(stream)
        .and_then(|h| LevelTable::parse(stream, &h).map(|_| ()))
        .err()
}

#[test]
fn a_compact_table_breaks_as_the_spec_says() {
    let stream = framed(ChunkCodec::Stored, Framing::Compact);
    let entries = compact_entries(&stream);
    assert_eq!(table_error(&with_compact_table(&stream, &entries)), None);
    // A byte left after the last entry.
    let mut longer = entries.clone();
    longer.push(0);
    assert!(matches!(
        table_error(&with_compact_table(&stream, &longer)),
        Some(Error::InvalidLevelTable(_))
    ));
    // The last entry's error cut short: it runs past the table. (Entry 0's
    // length written as 128, in two bytes, keeps the table above the
    // header's lower bound of 8 bytes an entry; the table does not check
    // lengths against the levels, SPEC §4.3.)
    assert!(entries[0] < 0x80);
    let mut shorter = vec![0x80, 0x01];
    shorter.extend_from_slice(&entries[1..entries.len() - 1]);
    assert_eq!(
        table_error(&with_compact_table(&stream, &shorter)),
        Some(Error::InvalidLevelTable(
            "an entry runs past the table's length"
        ))
    );
    // Entry 0's length (one byte here) written in two: not minimal.
    assert!(entries[0] < 0x80);
    let mut long_varint = vec![entries[0] | 0x80, 0x00];
    long_varint.extend_from_slice(&entries[1..]);
    assert_eq!(
        table_error(&with_compact_table(&stream, &long_varint)),
        Some(Error::InvalidLevelTable("varint not minimal"))
    );
    // Entry 0's vertex step at 2^32 - 1: the sum passes the capacity
    // before it could wrap (SPEC §4.3).
    let first_len = 1;
    let mut huge = entries[..first_len].to_vec();
    huge.extend_from_slice(&[0xFF, 0xFF, 0xFF, 0xFF, 0x0F]);
    let vertex_step_len = 1 + entries[first_len..]
        .iter()
        .take_while(|&&b| b & 0x80 != 0)
        .count();
    huge.extend_from_slice(&entries[first_len + vertex_step_len..]);
    assert_eq!(
        table_error(&with_compact_table(&stream, &huge)),
        Some(Error::CapacityExceeded)
    );
    // The table's CRC.
    let mut bad_crc = stream.clone();
    bad_crc[96] ^= 1;
    assert!(matches!(
        table_error(&bad_crc),
        Some(Error::ChecksumMismatch(_))
    ));
}

#[test]
fn a_compact_table_header_is_bounded() {
    let stream = framed(ChunkCodec::Stored, Framing::Compact);
    let patched = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut s = stream.clone();
        f(&mut s);
        let crc = crc32(&s[..92]);
        s[92..96].copy_from_slice(&crc.to_le_bytes());
        Header::parse(&s).err()
    };
    let levels = u16::from_le_bytes([stream[14], stream[15]]) as u32;
    for table_len in [8 * levels + 3, 24 * levels + 5, 0, u32::MAX] {
        assert!(
            matches!(
                patched(&|s| s[28..32].copy_from_slice(&table_len.to_le_bytes())),
                Some(Error::InvalidHeader(_))
            ),
            "table_len {table_len}"
        );
    }
    // 256 levels are too many for a compact table, whatever its length.
    assert!(matches!(
        patched(&|s| {
            s[14..16].copy_from_slice(&256u16.to_le_bytes());
            s[28..32].copy_from_slice(&(8 * 256 + 4u32).to_le_bytes());
        }),
        Some(Error::InvalidHeader(_))
    ));
    // A compact table needs the compact level headers (bit 2).
    assert!(matches!(
        patched(&|s| s[10] &= !4),
        Some(Error::InvalidHeader(_))
    ));
    // Offset 28 is reserved under the fixed table.
    assert!(matches!(
        patched(&|s| s[10] &= !8),
        Some(Error::InvalidHeader(_))
    ));
}

#[test]
fn a_compact_table_with_every_byte_changed_or_cut_never_panics() {
    let stream = framed(ChunkCodec::RansAlways { lanes: 2 }, Framing::Compact);
    let head = Header::parse(&stream).unwrap().head_len();
    for at in 96..head {
        for value in [0x00, 0x01, 0x0F, 0x10, 0x7F, 0x80, 0xFF] {
            let mut bytes = stream.clone();
            bytes[at] = value;
            let crc = crc32(&bytes[96..head - 4]);
            bytes[head - 4..head].copy_from_slice(&crc.to_le_bytes());
            // The decode may succeed (the byte's own value) or fail; it
            // must not panic.
            let _ = decode_all(&bytes, true);
        }
    }
    for cut in 0..head {
        assert!(table_error(&stream[..cut]).is_some(), "cut at {cut}");
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
