//! The public API never panics when misused: levels out of order, twice,
//! with the wrong bytes, after an error, past the levels that fit; rounds
//! after the end of a level; level ranges of levels that do not exist.

#[path = "../fuzz/src/streams.rs"]
mod streams;

use splitstream_decoder_core::{Decoder, Error, Inflater, workspace_len};
use streams::Choices;

fn deep_stream() -> Vec<u8> {
    // Grid base, all-zero choices: 5 levels, 120 splits.
    streams::generate(&mut Choices::new(&[2, 0]), false).stream
}

#[test]
fn levels_out_of_order_twice_and_after_errors() {
    let stream = deep_stream();
    let mut ws = vec![0u8; workspace_len(&stream).unwrap()];
    let mut inflater = Box::new(Inflater::new());
    let mut d = Decoder::new(&stream, &mut ws, &mut inflater).unwrap();
    let levels = d.header().level_count;
    assert!(levels >= 3);
    // Not the next level.
    let l1 = d.level_bytes(1, &stream).unwrap();
    assert_eq!(
        d.decode_level(1, l1).unwrap_err(),
        Error::LevelOutOfOrder {
            expected: 0,
            got: 1
        }
    );
    // Ranges of levels that do not exist are empty or zero, never a panic.
    for k in [levels, levels + 1, u16::MAX] {
        let _ = d.level_range(k);
        assert!(
            d.level_bytes(k, &stream).is_err() || d.level_bytes(k, &stream).unwrap().is_empty()
        );
    }
    let l0 = d.level_bytes(0, &stream).unwrap();
    d.decode_level(0, l0).unwrap();
    // Twice.
    assert!(matches!(
        d.decode_level(0, l0),
        Err(Error::LevelOutOfOrder {
            expected: 1,
            got: 0
        })
    ));
    // A level's rounds one by one, then more calls after the end.
    let l1 = d.level_bytes(1, &stream).unwrap();
    {
        let mut level = d.begin_level(1, l1).unwrap();
        while level.next_round().unwrap().is_some() {}
        for _ in 0..3 {
            assert_eq!(level.next_round(), Ok(None));
        }
    }
    assert_eq!(d.next_level(), Some(2));
    // The wrong bytes for level 2 (level 1's): an error, then poisoned.
    assert!(d.decode_level(2, l1).is_err());
    assert_eq!(d.next_level(), None);
    let l2 = d.level_bytes(2, &stream).unwrap();
    assert_eq!(d.decode_level(2, l2), Err(Error::Poisoned));
    assert_eq!(d.decode_available(&stream), Ok(2));
    // The state stays readable.
    let _ = (d.state_hash(), d.positions().len(), d.triangles().len());
}

#[test]
fn a_level_dropped_half_way_fails_when_restarted() {
    let stream = deep_stream();
    let mut ws = vec![0u8; workspace_len(&stream).unwrap()];
    let mut inflater = Box::new(Inflater::new());
    let mut d = Decoder::new(&stream, &mut ws, &mut inflater).unwrap();
    d.decode_level(0, d.level_bytes(0, &stream).unwrap())
        .unwrap();
    let l1 = d.level_bytes(1, &stream).unwrap();
    {
        let mut level = d.begin_level(1, l1).unwrap();
        level.next_round().unwrap();
        // Dropped before the level is complete.
    }
    // The level did not complete: it is still the next one, and starting it
    // again from its first round over the half-split state must fail
    // cleanly (a typed error), not panic.
    assert_eq!(d.next_level(), Some(1));
    let again = d.decode_level(1, l1);
    assert!(again.is_err(), "{again:?}");
    eprintln!("re-decoding a half-done level: {again:?}");
}

#[test]
fn streams_cut_at_every_level_boundary() {
    let stream = deep_stream();
    let mut ws = vec![0u8; workspace_len(&stream).unwrap()];
    let mut inflater = Box::new(Inflater::new());
    let levels = Decoder::new(&stream, &mut ws, &mut inflater)
        .unwrap()
        .header()
        .level_count;
    for k in 0..levels {
        let end = {
            let d = Decoder::new(&stream, &mut ws, &mut inflater).unwrap();
            d.level_range(k).end as usize
        };
        // Only levels 0..=k present: decode_available decodes them, then
        // reports the missing level as truncated.
        let mut d = Decoder::new(&stream[..end], &mut ws, &mut inflater).unwrap();
        let r = d.decode_available(&stream[..end]);
        if k + 1 == levels {
            assert_eq!(r, Ok(levels));
        } else {
            assert_eq!(r, Err(Error::Truncated));
            assert_eq!(d.levels_done(), k + 1);
        }
    }
}
