//! Structured mutation of valid streams before framing: the fuzzer edits
//! record substreams (flags, wing offsets and distances, config bits,
//! deficits, edge and placement varints), split counts, level counts and
//! stream parameters of fixed deep seed streams, which are then framed with
//! valid checksums, so every input reaches the split logic. Input: byte 0
//! picks the seed, the rest is a list of mutations (see `streams::mutate_levels`).
//! Must never panic; with no mutation the decode must match the replay.
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use splitstream_decoder_core_fuzz::streams::{self, Choices, Generated};

static SEEDS: OnceLock<Vec<Generated>> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let seeds = SEEDS.get_or_init(streams::seed_generated);
    let Some((&pick, ops)) = data.split_first() else {
        return;
    };
    let seed = &seeds[pick as usize % seeds.len()];
    let (params, levels) = streams::mutate_levels(seed, &mut Choices::new(ops));
    let stream = streams::frame(&params, &levels, seed.seeded);
    let decoded = streams::decode_full(&stream);
    if let Err(msg) = streams::check_fans_ahead(&stream, &decoded) {
        panic!("{msg}");
    }
    if let Err(msg) = streams::check_piped(&stream, &decoded) {
        panic!("{msg}");
    }
    if ops.is_empty() {
        streams::check_against(seed, &decoded).unwrap();
    }
    if let Some(e) = decoded.error {
        // Typed errors only; the class is total.
        let _ = e.class();
        let _ = e.to_string();
    }
});
