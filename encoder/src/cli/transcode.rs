//! `splitstream transcode`: a stream written again from its own
//! refinement, without the input mesh.

use std::path::PathBuf;
use std::time::Instant;

use splitstream_decoder_core::Header;
use splitstream_encoder::emit::transcode;

use super::CliResult;
use super::coding::CodingArgs;
use super::output::check_stream_output;

/// `splitstream transcode`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub coding: CodingArgs,
}

pub fn run(a: Args) -> CliResult {
    a.coding.check()?;
    check_stream_output(&a.output, None)?;
    let stream = std::fs::read(&a.input).map_err(|e| format!("{}: {e}", a.input.display()))?;
    // The lane count by the mesh's size (a stream that does not parse fails
    // in `transcode` with its own error).
    let vertices = Header::parse(&stream).map_or(usize::MAX, |h| h.vertex_capacity as usize);
    let options = a.coding.options(vertices);
    let started = Instant::now();
    let done = transcode(&stream, &options).map_err(|e| format!("{}: {e}", a.input.display()))?;
    let seconds = started.elapsed().as_secs_f64();
    std::fs::write(&a.output, &done.stream).map_err(|e| format!("{}: {e}", a.output.display()))?;
    // Both headers parse: the input decoded, the output was just written.
    let header = |bytes: &[u8]| Header::parse(bytes).map_err(|e| e.to_string());
    let (before, after) = (header(&stream)?, header(&done.stream)?);
    println!(
        "{}: {} -> {} bytes ({:+.1} %), format 3.{}, {} levels, {} rounds, state hash {:016x} (the input's)",
        a.output.display(),
        stream.len(),
        done.stream.len(),
        100.0 * (done.stream.len() as f64 / stream.len() as f64 - 1.0),
        after.version_minor,
        done.levels,
        done.rounds,
        done.final_hash,
    );
    println!(
        "decoder memory: {} -> {} bytes (stored and deflate chunks up to {} -> {} bytes)",
        before.workspace_bytes, after.workspace_bytes, before.max_chunk_len, after.max_chunk_len
    );
    println!("time: {seconds:.2} s");
    Ok(())
}
