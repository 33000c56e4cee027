//! The decoder's fans walked ahead (decoder-core `round.rs`: batches of
//! 128 candidates across bitmap words, up to 48 fans per lockstep walk)
//! are only a speed setting: a terrain large enough for many batches per
//! round decodes to the same state after every round with fans walked
//! ahead in every round and in none, under both schedules and both record
//! orders.

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::{RecordOrder, Schedule};
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::input::fractal_terrain;

/// The state hash after the seed and after every round.
fn round_hashes(stream: &[u8], fans_ahead_from: u32) -> Vec<u64> {
    let mut workspace = OwnedWorkspace::for_stream(stream).expect("workspace");
    let mut decoder = workspace.decoder(stream).expect("header");
    decoder.set_fans_ahead_from(fans_ahead_from);
    let mut hashes = Vec::new();
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream).expect("level bytes");
        let mut level = decoder.begin_level(k, bytes).expect("level");
        hashes.push(level.state().state_hash());
        while level.next_round().expect("round").is_some() {
            hashes.push(level.state().state_hash());
        }
    }
    hashes
}

#[test]
fn fans_walked_ahead_change_no_round() {
    // 150 x 150: 22,500 vertices, rounds of up to about 2,900 splits
    // among 11,000 candidates (176 bitmap words).
    let mesh = fractal_terrain(150, 33);
    for (schedule, records) in [
        (Schedule::EveryVertex, None),
        (Schedule::EveryVertex, Some(RecordOrder::WingsFirst)),
        (Schedule::SplitValences, None),
    ] {
        let options = EncodeOptions {
            schedule,
            records,
            ..EncodeOptions::default()
        };
        let stream = encode(&mesh, &options, |_| {}).expect("encodes").stream;
        let never = round_hashes(&stream, u32::MAX);
        let always = round_hashes(&stream, 0);
        assert!(never.len() > 40, "{schedule:?}: {} rounds", never.len());
        assert_eq!(never, always, "{schedule:?}, {records:?}");
    }
}
