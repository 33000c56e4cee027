//! `splitstream verify`.

use std::path::Path;
use std::time::Instant;

use splitstream_decoder_core::owned::decode_all;

use super::{CliResult, read_file};

pub fn run(input: &Path) -> CliResult {
    let stream = read_file(input)?;
    let started = Instant::now();
    let mesh = decode_all(&stream, true).map_err(|e| format!("{}: {e}", input.display()))?;
    println!(
        "{}: ok: {} levels, {} rounds, {} vertices, {} triangles, checksums valid, decoded in {:.1} ms",
        input.display(),
        mesh.levels,
        mesh.round_hashes.len() - 1,
        mesh.positions.len(),
        mesh.triangles.len(),
        started.elapsed().as_secs_f64() * 1e3
    );
    println!(
        "state hash {:016x}",
        mesh.round_hashes.last().copied().unwrap_or_default()
    );
    Ok(())
}
