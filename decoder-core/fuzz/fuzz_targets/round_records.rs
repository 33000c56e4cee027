//! Drives `MeshState::run_round` with a `RecordSource` that takes flags and
//! split records from the fuzz bytes (valid by construction, with rare
//! injected faults), writes the chosen records into a stream, decodes it and
//! compares the decoder with the replay after every round: same state
//! hashes, same final mesh, or the very same error; and the decoder with
//! fans walked ahead in every round with the default one.
#![no_main]

use libfuzzer_sys::fuzz_target;
use splitstream_decoder_core_fuzz::streams::{self, Choices};

fuzz_target!(|data: &[u8]| {
    let g = streams::generate(&mut Choices::new(data), true);
    let decoded = streams::decode_full(&g.stream);
    if let Err(msg) = streams::check_against(&g, &decoded) {
        panic!("decoder and replay disagree: {msg}");
    }
    if let Err(msg) = streams::check_fans_ahead(&g.stream, &decoded) {
        panic!("{msg}");
    }
    if let Err(msg) = streams::check_piped(&g.stream, &decoded) {
        panic!("{msg}");
    }
});
