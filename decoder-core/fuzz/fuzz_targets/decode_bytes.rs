//! Arbitrary bytes through the no-alloc decode path: `workspace_len`,
//! `Decoder::new` over a bounded workspace (at most 16 MiB: a stream that
//! asks for more gets less and is decoded as far as it fits), every level
//! that fits, the state hash. Must never panic. Differential checks:
//! * the result does not depend on what the workspace held before;
//! * a smaller workspace decodes a prefix of the levels to the same states
//!   (SPEC §9), through `decode_available`.
//!
//! Inputs whose length is odd are first passed through `fix_checksums`
//! (every locatable CRC rewritten), so that byte mutations also reach the
//! level parsers and the split logic; even-length inputs are decoded as is.
#![no_main]

use std::cell::RefCell;

use libfuzzer_sys::fuzz_target;
use splitstream_decoder_core::{Decoder, Error, Inflater, crc32};
use splitstream_decoder_core_fuzz::{WORKSPACE_CAP, decode_into, needed};

thread_local! {
    static BYTES: RefCell<Vec<u8>> = RefCell::new(vec![0u8; WORKSPACE_CAP + 8]);
    static INFLATER: RefCell<Box<Inflater>> = RefCell::new(Box::new(Inflater::new()));
}

fuzz_target!(|input: &[u8]| {
    let mut fixed;
    let data = if input.len() % 2 == 1 {
        fixed = input.to_vec();
        splitstream_decoder_core_fuzz::fix_checksums(&mut fixed);
        &fixed[..]
    } else {
        input
    };
    // Misalign the workspace start by 0..8 bytes, chosen by the input length.
    let skew = data.len() % 8;
    let size = match needed(data) {
        Some(n) => n.min(WORKSPACE_CAP),
        // The head does not parse: Decoder::new must say why, whatever the size.
        None => 4096,
    };
    BYTES.with_borrow_mut(|buf| {
        INFLATER.with_borrow_mut(|inflater| {
            let ws = &mut buf[skew..skew + size];
            ws.fill(0);
            let first = decode_into(data, ws, inflater);
            if let Err(Error::WorkspaceTooSmall { available, .. }) = first.result {
                assert_eq!(available, size);
            }
            if size <= 1 << 20 {
                // Same decode over a workspace full of stale bytes.
                let ws = &mut buf[skew..skew + size];
                ws.fill(0xA5);
                let again = decode_into(data, ws, inflater);
                assert_eq!(first, again, "decode depends on prior workspace contents");
            }
            if first.levels_that_fit > 1 {
                // A pseudo-random smaller workspace: the levels that still
                // fit must decode to the same states.
                let smaller = (crc32(data) as usize) % size;
                let ws = &mut buf[..smaller];
                let Ok(mut decoder) = Decoder::new(data, ws, inflater) else {
                    return;
                };
                let fit = decoder.levels_that_fit();
                assert!(fit <= first.levels_that_fit);
                let result = decoder.decode_available(data);
                if let Ok(done) = result {
                    assert_eq!(done, fit);
                    if first.level_hashes.len() >= done as usize {
                        assert_eq!(
                            decoder.state_hash(),
                            first.level_hashes[done as usize - 1],
                            "a smaller workspace decoded level {done} differently"
                        );
                    }
                }
            }
        })
    });
});
