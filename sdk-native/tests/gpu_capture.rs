//! The GPU decoder's capture (phase 1: decoder-core reads the stream for
//! the device) read with the records on a second thread against one
//! thread: on every conformance vector, and on a generated stream large
//! enough for the default threshold, the same rounds, flags, records and
//! hashes, and on the invalid vectors the same fault after the same rounds;
//! the same on valid vectors with bytes changed or cut off, on generated
//! streams with faults in their records, and on the `decode_mutated` fuzz
//! target's edits of deep streams (reframed with valid checksums, so that
//! the faults are met inside the rounds).
#![cfg(feature = "gpu")]

#[path = "../../decoder-core/fuzz/src/streams.rs"]
mod streams;
mod vectors;

use proptest::prelude::*;
use splitstream_sdk_native::gpu::{CapturedStream, capture_stream, capture_stream_two_threads};
use splitstream_sdk_native::threaded::TWO_THREADS_FROM_SPLITS;
use vectors::newest_vectors;

fn assert_same(name: &str, one: &CapturedStream, two: &CapturedStream) {
    assert_eq!(one.error, two.error, "{name}: the fault");
    assert_eq!(one.vertex_capacity, two.vertex_capacity, "{name}");
    assert_eq!(one.triangle_capacity, two.triangle_capacity, "{name}");
    assert_eq!(one.base, two.base, "{name}: the seed mesh");
    assert_eq!(one.cpu_hashes, two.cpu_hashes, "{name}: the hashes");
    assert_eq!(one.levels.len(), two.levels.len(), "{name}: levels begun");
    for (k, (a, b)) in one.levels.iter().zip(&two.levels).enumerate() {
        assert_eq!(a.triangle_limit, b.triangle_limit, "{name}: level {k}");
        assert_eq!(a.rounds.len(), b.rounds.len(), "{name}: level {k}'s rounds");
        for (r, (x, y)) in a.rounds.iter().zip(&b.rounds).enumerate() {
            assert_eq!(x, y, "{name}: level {k}, round {r}");
        }
    }
}

/// The stream files of the vector set's `sub` folder ("valid" or
/// "invalid"), by name.
fn vector_files(sub: &str) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(newest_vectors().join(sub))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "sps"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_vector_captures_the_same_on_two_threads() {
    let mut streams = 0;
    for path in vector_files("valid")
        .into_iter()
        .chain(vector_files("invalid"))
    {
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let one = capture_stream(&bytes, true);
        // Every level through the second thread, then the default split.
        for from in [0, TWO_THREADS_FROM_SPLITS] {
            assert_same(&name, &one, &capture_stream_two_threads(&bytes, true, from));
        }
        streams += 1;
    }
    assert!(streams > 100, "{streams} vectors");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A valid vector with some bytes changed (past its header, mostly in
    /// the levels, where the records are) or cut short: the two-thread
    /// capture keeps the one-thread capture's rounds and fault.
    #[test]
    fn changed_vectors_capture_the_same_on_two_threads(
        pick in any::<prop::sample::Index>(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), 1u8..=255), 1..4),
        cut in prop::option::weighted(0.2, any::<prop::sample::Index>()),
    ) {
        let files = vector_files("valid");
        let path = &files[pick.index(files.len())];
        let mut bytes = std::fs::read(path).unwrap();
        let len = bytes.len();
        for (at, flip) in &edits {
            let i = 96 + at.index(len.saturating_sub(96).max(1));
            if let Some(b) = bytes.get_mut(i) {
                *b ^= flip;
            }
        }
        if let Some(cut) = cut {
            bytes.truncate(cut.index(len));
        }
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        assert_same(&name, &capture_stream(&bytes, true), &capture_stream_two_threads(&bytes, true, 0));
    }
}

fn seeds() -> &'static [streams::Generated] {
    static SEEDS: std::sync::OnceLock<Vec<streams::Generated>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(streams::seed_generated)
}

/// Both captures of `stream`, every level through the second thread.
fn assert_both_capture_alike(stream: &[u8]) {
    let one = capture_stream(stream, true);
    assert_same("stream", &one, &capture_stream_two_threads(stream, true, 0));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Generated streams, some with a fault injected in a record (a raw
    /// wing rank or split-valence symbol, a bad placement code, a flagged
    /// neighbour): the same rounds before the same fault.
    #[test]
    fn generated_streams_capture_the_same_on_two_threads(
        choices in prop::collection::vec(any::<u8>(), 0..2048),
    ) {
        let g = streams::generate(&mut streams::Choices::new(&choices), true);
        assert_both_capture_alike(&g.stream);
    }

    /// The `decode_mutated` fuzz target's edits of the deep seed streams.
    #[test]
    fn mutated_streams_capture_the_same_on_two_threads(
        pick in any::<u8>(),
        ops in prop::collection::vec(any::<u8>(), 1..96),
    ) {
        let seeds = seeds();
        let seed = &seeds[pick as usize % seeds.len()];
        let (params, levels) = streams::mutate_levels(seed, &mut streams::Choices::new(&ops));
        assert_both_capture_alike(&streams::frame(&params, &levels, seed.seeded));
    }
}
