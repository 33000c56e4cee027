//! The GPU decoder's capture (phase 1: decoder-core reads the stream for
//! the device) read with the records on a second thread against one
//! thread: on every conformance vector, and on a generated stream large
//! enough for the default threshold, the same rounds, flags, records and
//! hashes, and on the invalid vectors the same fault after the same rounds.
#![cfg(feature = "gpu")]

mod vectors;

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

#[test]
fn every_vector_captures_the_same_on_two_threads() {
    let dir = newest_vectors();
    let mut streams = 0;
    let files = ["valid", "invalid"]
        .iter()
        .flat_map(|sub| std::fs::read_dir(dir.join(sub)).unwrap())
        .map(|entry| entry.unwrap().path());
    for path in files {
        if path.extension().is_none_or(|e| e != "sps") {
            continue;
        }
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let one = capture_stream(&bytes, true);
        // Every level through the second thread, then the default split.
        for from in [0, TWO_THREADS_FROM_SPLITS] {
            assert_same(&name, &one, &capture_stream_two_threads(&bytes, true, from));
        }
        streams += 1;
    }
    assert!(streams > 100, "{streams} vectors in {}", dir.display());
}
