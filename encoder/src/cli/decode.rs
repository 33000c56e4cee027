//! `splitstream decode`.

use std::path::Path;

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_sdk_native::threaded::{self, TwoThreadMemory};

use super::output::write_mesh;
use super::{CliResult, read_file};

/// What to decode: up to `level` (the last level by default), and with
/// `available` only the levels whose bytes are all in the file; with
/// `threads` 2 each level's records are read on a second thread.
pub struct DecodeOptions {
    pub level: Option<u16>,
    pub available: bool,
    pub threads: u32,
}

pub fn run(input: &Path, output: &Path, options: DecodeOptions) -> CliResult {
    super::output::mesh_extension(output)?;
    if !(1..=2).contains(&options.threads) {
        return Err(format!(
            "--threads {}: a stream decodes on 1 or 2 threads",
            options.threads
        ));
    }
    let stream = read_file(input)?;
    let fail = |e: splitstream_decoder_core::Error| format!("{}: {e}", input.display());
    let mut ws = OwnedWorkspace::for_stream(&stream).map_err(fail)?;
    let mut decoder = ws.decoder(&stream).map_err(fail)?;
    let last = decoder.header().level_count - 1;
    let mut stop = options.level.unwrap_or(last);
    if stop > last {
        return Err(format!("--level {stop}: the stream has levels 0..={last}"));
    }
    // A prefix of the stream, as a client holds it after fetching its first
    // levels (SPEC §4.1): the levels before the first one cut off.
    let in_file = super::info::levels_in(&stream, decoder.level_table());
    let mut missing = String::new();
    if options.available && in_file <= stop {
        if in_file == 0 {
            return Err(format!(
                "{}: no whole level in the file: level 0 ends at byte {}, the file has {} bytes",
                input.display(),
                decoder.level_range(0).end,
                stream.len()
            ));
        }
        missing = format!(
            " (levels {in_file}..={last} are not in the file: it has {} of {} bytes)",
            stream.len(),
            decoder.level_range(last).end
        );
        stop = in_file - 1;
    }
    let mut two_threads =
        (options.threads == 2).then(|| TwoThreadMemory::new(decoder.state().vertex_capacity()));
    while let Some(k) = decoder.next_level().filter(|&k| k <= stop) {
        let bytes = decoder.level_bytes(k, &stream).map_err(|e| {
            if options.available {
                fail(e)
            } else {
                format!(
                    "{}: {e}: level {k} ends at byte {}, the file has {} bytes \
                     (--available decodes the levels before it)",
                    input.display(),
                    decoder.level_range(k).end,
                    stream.len()
                )
            }
        })?;
        match &mut two_threads {
            Some(memory) => threaded::decode_level(&mut decoder, k, bytes, memory),
            None => decoder.decode_level(k, bytes),
        }
        .map_err(fail)?;
    }
    let positions: Vec<[f64; 3]> = decoder
        .positions()
        .iter()
        .map(|&q| decoder.dequantize(q))
        .collect();
    write_mesh(output, &positions, decoder.triangles())?;
    println!(
        "{}: level {stop}{missing}, {} vertices, {} triangles, state hash {:016x}",
        output.display(),
        positions.len(),
        decoder.triangles().len(),
        decoder.state_hash()
    );
    Ok(())
}
