//! One stream decoded on two threads (`threaded`, `Session::
//! decode_level_two_threads`) against one thread: on every conformance
//! vector the same hash after every round (the manifest's), the same final
//! mesh, and on the invalid ones the same error class.

mod vectors;

use serde_json::Value;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_sdk_native::Session;
use splitstream_sdk_native::threaded::{self, TwoThreadMemory};
use vectors::newest_vectors;

/// Every vector: name, bytes, whether valid, and the round hashes.
fn vectors() -> Vec<(String, Vec<u8>, bool, Vec<String>)> {
    let dir = newest_vectors();
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).unwrap()).unwrap();
    manifest["vectors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            let hashes = v["round_hashes"]
                .as_array()
                .map(|a| a.iter().map(|h| h.as_str().unwrap().to_string()).collect())
                .unwrap_or_default();
            let bytes = std::fs::read(dir.join(v["file"].as_str().unwrap())).unwrap();
            (
                v["name"].as_str().unwrap().to_string(),
                bytes,
                v["valid"].as_bool().unwrap(),
                hashes,
            )
        })
        .collect()
}

fn level<'a>(s: &Session, stream: &'a [u8], k: u16) -> &'a [u8] {
    let r = s.level_range(k).unwrap();
    let end = (r.end as usize).min(stream.len());
    &stream[(r.start as usize).min(end)..end]
}

/// Decodes every level of `stream` with a session, on one thread or two;
/// the error's class if it fails.
fn decode(stream: &[u8], two: bool) -> Result<Session, String> {
    let mut s = Session::open(stream).map_err(|e| e.class().to_string())?;
    // The vectors are small: every level through the second thread.
    s.set_two_threads_from(0);
    while let Some(k) = s.next_level() {
        let bytes = level(&s, stream, k);
        let result = if two {
            s.decode_level_two_threads(k, bytes)
        } else {
            s.decode_level(k, bytes)
        };
        result.map_err(|e| e.class().to_string())?;
    }
    Ok(s)
}

#[test]
fn two_threads_give_the_manifest_hashes_after_every_round() {
    let mut checked = 0;
    for (name, stream, valid, expected) in vectors() {
        if !valid {
            continue;
        }
        let mut ws = OwnedWorkspace::for_stream(&stream).unwrap();
        let mut decoder = ws.decoder(&stream).unwrap();
        let mut memory = TwoThreadMemory::new(decoder.state().vertex_capacity());
        memory.set_two_threads_from(0);
        let mut hashes = Vec::new();
        while let Some(k) = decoder.next_level() {
            let r = decoder.level_range(k);
            let bytes = &stream[r.start as usize..r.end as usize];
            threaded::decode_level_observed(&mut decoder, k, bytes, &mut memory, |_, state| {
                hashes.push(format!("{:016x}", state.state_hash()))
            })
            .unwrap();
        }
        assert_eq!(hashes, expected, "{name}");
        checked += 1;
    }
    assert!(checked > 20, "only {checked} valid vectors");
}

#[test]
fn sessions_on_two_threads_end_alike_and_fail_alike() {
    for (name, stream, valid, _) in vectors() {
        match (decode(&stream, false), decode(&stream, true)) {
            (Ok(one), Ok(two)) => {
                assert!(valid, "{name} decoded");
                assert_eq!(one.state_hash(), two.state_hash(), "{name}");
                assert_eq!(one.positions(), two.positions(), "{name}");
                assert_eq!(one.triangles(), two.triangles(), "{name}");
                assert_eq!(one.deficits(), two.deficits(), "{name}");
            }
            (Err(a), Err(b)) => {
                assert!(!valid, "{name} failed: {a}");
                assert_eq!(a, b, "{name}");
            }
            (one, two) => panic!(
                "{name}: one thread {:?}, two threads {:?}",
                one.err(),
                two.err()
            ),
        }
    }
}

#[test]
fn two_threads_while_a_level_is_open_is_misuse() {
    let (_, stream, _, _) = vectors()
        .into_iter()
        .find(|(_, b, valid, _)| *valid && Session::open(b).unwrap().level_count() >= 2)
        .expect("a vector with two levels");
    let mut s = Session::open(&stream).unwrap();
    s.set_two_threads_from(0);
    s.begin_level(0, level(&s, &stream, 0)).unwrap();
    let l1 = level(&s, &stream, 1);
    let e = s.decode_level_two_threads(1, l1).unwrap_err();
    assert_eq!(e.class(), "api-misuse");
    // Out of order, with no level open: the decoder's own error.
    while s.next_round().unwrap().is_some() {}
    let l2 = level(&s, &stream, 1);
    assert!(s.decode_level_two_threads(0, l2).is_err());
    s.decode_level_two_threads(1, l2).unwrap();
}

/// What the README and the C header say the second thread costs besides
/// the positions: a second inflater and `PENDING` waiting rings.
#[test]
fn two_thread_memory_beyond_the_positions_is_about_1_6_mb() {
    let fixed = TwoThreadMemory::new(0).bytes();
    assert_eq!(TwoThreadMemory::new(1000).bytes(), fixed + 12 * 1000);
    assert!((1_500_000..1_700_000).contains(&fixed), "{fixed} bytes");
}
