//! `splitstream verify`.

use std::path::Path;
use std::time::Instant;

use splitstream_decoder_core::Error;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_sdk_native::threaded::{self, TwoThreadMemory};

use super::{CliResult, read_file};

pub fn run(input: &Path) -> CliResult {
    let stream = read_file(input)?;
    let started = Instant::now();
    let verified = verify(&stream).map_err(|e| format!("{}: {e}", input.display()))?;
    println!(
        "{}: ok: {} levels, {} rounds, {} vertices, {} triangles, checksums valid, decoded in {:.1} ms",
        input.display(),
        verified.levels,
        verified.rounds,
        verified.vertices,
        verified.triangles,
        started.elapsed().as_secs_f64() * 1e3
    );
    println!("state hash {:016x}", verified.hash);
    // SPEC §4.2: bytes after the last level are not part of the stream.
    // Said, so that two files glued together do not pass for one.
    if let Some(extra) = (stream.len() as u64)
        .checked_sub(verified.end)
        .filter(|&n| n > 0)
    {
        println!(
            "note: {extra} bytes after the last level's end (byte {}) are not part of the stream and were not read",
            verified.end
        );
    }
    Ok(())
}

/// What a full decode of a stream ended in.
struct Verified {
    levels: u16,
    rounds: usize,
    vertices: u32,
    triangles: u32,
    /// The state hash after the last round (SPEC §8).
    hash: u64,
    /// Where the last level ends (SPEC §4.2).
    end: u64,
}

/// Decodes every level of `stream`, a large level's records on a second
/// thread (the same state, sdk-native `threaded`), every checksum and rule
/// checked; the state hash is taken once, at the end (hashing after every
/// round took longer than the decode of the 1M demo terrain).
fn verify(stream: &[u8]) -> Result<Verified, Error> {
    let mut workspace = OwnedWorkspace::for_stream(stream)?;
    let mut decoder = workspace.decoder(stream)?;
    let mut memory = TwoThreadMemory::new(decoder.state().vertex_capacity());
    let mut rounds = 0;
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream)?;
        threaded::decode_level_observed(&mut decoder, k, bytes, &mut memory, |round, _| {
            rounds += round.is_some() as usize;
        })?;
    }
    let end = decoder
        .level_range(decoder.levels_done().saturating_sub(1))
        .end;
    Ok(Verified {
        end,
        levels: decoder.levels_done(),
        rounds,
        vertices: decoder.state().vertex_count(),
        triangles: decoder.state().triangle_count(),
        hash: decoder.state_hash(),
    })
}
