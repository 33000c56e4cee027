//! `splitstream decode`.

use std::path::Path;

use splitstream_decoder_core::owned::OwnedWorkspace;

use super::output::write_mesh;
use super::{CliResult, read_file};

pub fn run(input: &Path, output: &Path, level: Option<u16>) -> CliResult {
    super::output::mesh_extension(output)?;
    let stream = read_file(input)?;
    let fail = |e: splitstream_decoder_core::Error| format!("{}: {e}", input.display());
    let mut ws = OwnedWorkspace::for_stream(&stream).map_err(fail)?;
    let mut decoder = ws.decoder(&stream).map_err(fail)?;
    let last = decoder.header().level_count - 1;
    let stop = level.unwrap_or(last);
    if stop > last {
        return Err(format!("--level {stop}: the stream has levels 0..={last}"));
    }
    while let Some(k) = decoder.next_level().filter(|&k| k <= stop) {
        let bytes = decoder.level_bytes(k, &stream).map_err(fail)?;
        decoder.decode_level(k, bytes).map_err(fail)?;
    }
    let positions: Vec<[f64; 3]> = decoder
        .positions()
        .iter()
        .map(|&q| decoder.dequantize(q))
        .collect();
    write_mesh(output, &positions, decoder.triangles())?;
    println!(
        "{}: level {stop}, {} vertices, {} triangles, state hash {:016x}",
        output.display(),
        positions.len(),
        decoder.triangles().len(),
        decoder.state_hash()
    );
    Ok(())
}
