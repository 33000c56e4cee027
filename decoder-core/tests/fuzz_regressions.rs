//! Inputs saved from fuzzing (decoder-core/fuzz): each must decode to a
//! typed error or a valid mesh, never panic.
//!
//! `tests/fuzz_regressions/*.bin` are raw streams (the `decode_bytes` input
//! format; for inputs of odd length that target first rewrites the
//! checksums, as [`fix_checksums`] below does). Crashes found by the fuzzers
//! get a named test here as well.

#[path = "../fuzz/src/streams.rs"]
mod streams;

use std::path::Path;

use splitstream_decoder_core::owned::decode_all;
use splitstream_decoder_core::{Decoder, Error, Inflater, workspace_len};

/// The same checksum rewrite as `splitstream_decoder_core_fuzz::fix_checksums`.
#[path = "../fuzz/src/fix_checksums.rs"]
mod fix;
use fix::fix_checksums;

/// Decodes `stream` like the `decode_bytes` target (workspace capped at
/// 16 MiB) and like `decode_all`; returns the first error, if any.
fn decode_like_the_fuzzer(stream: &[u8]) -> Result<u16, Error> {
    let size = workspace_len(stream)
        .map(|n| n.min(16 << 20))
        .unwrap_or(4096);
    let mut ws = vec![0u8; size];
    let mut inflater = Box::new(Inflater::new());
    let no_alloc =
        Decoder::new(stream, &mut ws, &mut inflater).and_then(|mut d| d.decode_available(stream));
    let owned = if size < 16 << 20 {
        Some(decode_all(stream, true))
    } else {
        None
    };
    if let (Some(owned), Ok(_)) = (&owned, &no_alloc) {
        assert!(
            owned.is_ok(),
            "owned path failed where the no-alloc path did not"
        );
    }
    no_alloc
}

fn each_saved_input(mut f: impl FnMut(&str, &[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    let mut paths: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    paths.sort();
    for p in paths {
        if p.extension().is_some_and(|e| e == "bin") {
            let bytes = std::fs::read(&p).unwrap();
            f(&p.file_name().unwrap().to_string_lossy(), &bytes);
        }
    }
}

#[test]
fn every_saved_input_gives_a_typed_result() {
    each_saved_input(|name, bytes| {
        let mut fixed = bytes.to_vec();
        if fixed.len() % 2 == 1 {
            fix_checksums(&mut fixed);
        }
        for input in [bytes, &fixed[..]] {
            match decode_like_the_fuzzer(input) {
                Ok(levels) => assert!(levels >= 1, "{name}"),
                Err(e) => assert!(!e.class().is_empty(), "{name}: {e:?}"),
            }
        }
    });
}

/// The fuzzers' seed streams (valid) decode to the replay's states.
#[test]
fn seed_streams_still_decode() {
    for g in streams::seed_generated() {
        assert_eq!(decode_like_the_fuzzer(&g.stream).map(|_| ()), Ok(()));
    }
}

/// `fix_checksums` leaves valid streams unchanged (it follows the format).
#[test]
fn fix_checksums_is_the_identity_on_valid_streams() {
    let mut compact = 0;
    for g in streams::seed_generated() {
        let mut s = g.stream.clone();
        fix_checksums(&mut s);
        assert!(s == g.stream, "{} (seeded: {})", g.base, g.seeded);
        // Header flag bit 2: the compact framing (3.11).
        compact += usize::from(g.stream[10] & 4 != 0);
    }
    assert!(compact > 0, "no seed stream in the compact framing");
}

/// `fix_checksums` finds every CRC of a compact-framing stream (SPEC
/// §5.1.1), under either level table (§4.1, §4.3, 3.12): with each of
/// them broken, it gives the stream back.
#[test]
fn fix_checksums_restores_a_compact_streams_crcs() {
    // Flag bit 2 alone (3.11), and bits 2 and 3 (3.12).
    for flags in [4, 12] {
        let g = streams::seed_generated()
            .into_iter()
            .find(|g| g.stream[10] & 12 == flags && g.stream.len() > 300)
            .expect("a compact seed stream");
        restores_every_crc(&g.stream, g.base);
    }
}

fn restores_every_crc(stream: &[u8], base: &str) {
    let header = splitstream_decoder_core::Header::parse(stream).unwrap();
    let table = splitstream_decoder_core::LevelTable::parse(stream, &header).unwrap();
    let mut broken = stream.to_vec();
    // The header's and the table's CRCs.
    broken[92..96].fill(0);
    let head = header.head_len();
    broken[head - 4..head].fill(0);
    for k in 0..header.level_count {
        let info = table.get(k);
        let start = info.offset as usize;
        let level = &stream[start..start + info.length as usize];
        let lh = table.level_header(k, level, header.level_rules()).unwrap();
        // The level header's CRC, and each chunk's (the last 4 bytes of
        // its entry), zeroed.
        let crc_at = start + lh.payload_start - 4;
        broken[crc_at..crc_at + 4].fill(0);
        let directory_len = lh.chunks().count();
        let mut at = 0;
        let mut ends = Vec::new();
        for _ in 0..directory_len {
            let (_, next) = lh.entry_at(at).unwrap();
            ends.push(next);
            at = next;
        }
        let directory_at = crc_at - at;
        for end in ends {
            broken[directory_at + end - 4..directory_at + end].fill(0);
        }
    }
    assert!(broken != stream);
    fix_checksums(&mut broken);
    assert!(broken == stream, "{base}");
}
