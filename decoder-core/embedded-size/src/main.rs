//! A minimal bare-metal decoder: decodes an embedded tetrahedron stream
//! (deflate chunks, one refinement level) into a static workspace and
//! returns its state hash. Built for `thumbv7em-none-eabihf` with
//! `opt-level = "z"`, LTO and `panic = "abort"`, its `.text` is the code
//! size of a complete splitstream decoder (inflate included).
//!
//! `unsafe` is confined to this demo (handing out the static buffers);
//! `splitstream-decoder-core` itself forbids it.
#![no_std]
#![no_main]

use core::mem::MaybeUninit;
use core::panic::PanicInfo;

use splitstream_decoder_core::{Decoder, Inflater};

static STREAM: &[u8] = include_bytes!("../tetrahedron.sps");

/// Workspace for the demo stream (13,304 bytes, mostly the seven substream
/// slots that can hold rANS tables, SPEC §9; 8-aligned).
const WORDS: usize = 1664;
static mut WORKSPACE: [u64; WORDS] = [0; WORDS];
/// miniz_oxide's inflater state (about 10.5 KB); its constructor is not
/// const, so it lives in `.bss` and is initialised on each call.
static mut INFLATER: MaybeUninit<Inflater> = MaybeUninit::uninit();

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    loop {
        core::hint::spin_loop();
    }
}

/// Decodes the whole demo stream; returns its state hash, or 0 on error.
#[unsafe(no_mangle)]
pub extern "C" fn splitstream_decode_demo() -> u64 {
    // SAFETY: single-threaded demo; this function is the only user of the
    // statics and is not re-entered.
    let (words, inflater) = unsafe { (&mut *(&raw mut WORKSPACE), &mut *(&raw mut INFLATER)) };
    let inflater = inflater.write(Inflater::new());
    let workspace: &mut [u8] = bytemuck_free_bytes(words);
    // Keep the stream opaque to the optimiser.
    let stream = core::hint::black_box(STREAM);
    let Ok(mut decoder) = Decoder::new(stream, workspace, inflater) else {
        return 0;
    };
    match decoder.decode_available(stream) {
        Ok(_) => decoder.state_hash(),
        Err(_) => 0,
    }
}

/// Views the word buffer as bytes.
fn bytemuck_free_bytes(words: &mut [u64; WORDS]) -> &mut [u8] {
    // SAFETY: u8 has no alignment or validity requirements; the length is
    // the byte size of the array.
    unsafe { core::slice::from_raw_parts_mut(words.as_mut_ptr().cast::<u8>(), WORDS * 8) }
}

/// Entry point: decode, then park.
#[unsafe(no_mangle)]
pub extern "C" fn _start() -> ! {
    let hash = splitstream_decode_demo();
    core::hint::black_box(hash);
    loop {
        core::hint::spin_loop();
    }
}
