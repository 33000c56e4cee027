//! decoder-core behind the conformance protocol (conformance/README.md,
//! "The decoder protocol"), with nothing but decoder-core and std: a
//! stream on standard input; the state hash (SPEC §8) after the seed and
//! after every round, then `ok` or `error <class>` (SPEC §10.1).
//!
//! The conformance runner's own `decode` is the same decoder behind the
//! encoder's dependencies; this one cross-builds alone, which is what CI
//! needs to run the vectors through the 32-bit Arm code paths (under
//! qemu-user, `.ci/test`):
//!
//! ```text
//! cargo build --release -p splitstream-decoder-core --features alloc --example protocol_decode
//! target/debug/splitstream-conformance run --decoder "target/release/examples/protocol_decode"
//! ```

use std::io::{Read, Write};

use splitstream_decoder_core::Error;
use splitstream_decoder_core::owned::OwnedWorkspace;

fn main() {
    let mut stream = Vec::new();
    let out = std::io::stdout();
    let mut out = out.lock();
    if let Err(e) = std::io::stdin().read_to_end(&mut stream) {
        eprintln!("protocol_decode: reading standard input: {e}");
        std::process::exit(2);
    }
    let result = decode(&stream, &mut |hash| {
        // A closed pipe is the runner's business; the verdict line below
        // fails the same way.
        let _ = writeln!(out, "{hash:016x}");
    });
    let verdict = match result {
        Ok(()) => "ok".to_string(),
        Err(e) => format!("error {}", e.class()),
    };
    let _ = writeln!(out, "{verdict}");
}

/// Decodes `stream` level by level and round by round, reporting the state
/// hash after the seed mesh (SPEC §6.3) and after every round (SPEC §7.3).
fn decode(stream: &[u8], report: &mut dyn FnMut(u64)) -> Result<(), Error> {
    let mut workspace = OwnedWorkspace::for_stream(stream)?;
    let mut decoder = workspace.decoder(stream)?;
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream)?;
        let mut level = decoder.begin_level(k, bytes)?;
        if k == 0 {
            report(level.state().state_hash());
        }
        while level.next_round()?.is_some() {
            report(level.state().state_hash());
        }
    }
    Ok(())
}
