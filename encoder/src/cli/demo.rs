//! `splitstream demo`: the main job on a built-in terrain, end to end.

use std::time::Instant;

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_decoder_core::writer::ChunkCodec;
use splitstream_encoder::emit::{EncodeOptions, encode, lanes_for};
use splitstream_encoder::input::fractal_terrain;

use super::CliResult;
use super::output::check_stream_output;

pub fn run(
    side: usize,
    output: Option<&std::path::Path>,
    schedule: splitstream_decoder_core::Schedule,
    records: Option<splitstream_decoder_core::RecordOrder>,
) -> CliResult {
    if !(2..=4096).contains(&side) {
        return Err(format!("--side {side} is outside 2..=4096"));
    }
    if let Some(path) = output {
        check_stream_output(path, None)?;
    }
    let started = Instant::now();
    let mesh = fractal_terrain(side, 2012);
    println!(
        "terrain: {side}x{side} fractal DEM, {} vertices, {} triangles (generated in {:.2} s)",
        mesh.positions.len(),
        mesh.triangles.len(),
        started.elapsed().as_secs_f64()
    );
    // As `splitstream encode` does by default: constrained positions, x and
    // y kept exactly on the raster's lattice, the schedule `every-vertex`
    // (13.67 bits per vertex at side 1000, 14.84 under `split-valences`;
    // optimal mode, which this command used until 2026-12-02, took 32.3).
    // The lanes `splitstream encode` would write for this terrain.
    let options = EncodeOptions {
        schedule,
        records,
        codec: ChunkCodec::Rans {
            lanes: lanes_for(mesh.positions.len()),
        },
        ..EncodeOptions::default()
    };
    let started = Instant::now();
    let encoded = encode(&mesh, &options, |_| {}).map_err(|e| e.to_string())?;
    let seconds = started.elapsed().as_secs_f64();
    let stream = &encoded.stream;
    if let Some(path) = output {
        std::fs::write(path, stream).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    println!(
        "encoded: {} bytes ({:.2} bits/vertex), {} levels, {} rounds, in {:.2} s ({:.2} M triangles/s; check {:.2} s, simplify {:.2} s, emit {:.2} s)",
        stream.len(),
        8.0 * stream.len() as f64 / mesh.positions.len() as f64,
        encoded.level_vertex_counts.len(),
        encoded.rounds,
        seconds,
        mesh.triangles.len() as f64 / seconds / 1e6,
        encoded.check_seconds,
        encoded.simplify_seconds,
        encoded.emit_seconds,
    );
    println!(
        "{}",
        super::encode::positions_line(options.position_mode, encoded.on_lattice)
    );
    let fail = |e: splitstream_decoder_core::Error| format!("demo stream: {e}");
    let mut ws = OwnedWorkspace::for_stream(stream).map_err(fail)?;
    let mut decoder = ws.decoder(stream).map_err(fail)?;
    println!("level   vertices  triangles   bytes  total bytes  geometric error (m)  decode ms");
    let mut total = decoder.header().head_len() as u64;
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream).map_err(fail)?;
        let t = Instant::now();
        decoder.decode_level(k, bytes).map_err(fail)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        total += bytes.len() as u64;
        let e = decoder.level_table().get(k);
        println!(
            "{:>5} {:>10} {:>10} {:>7} {:>12} {:>20.3} {:>10.2}",
            k,
            e.vertex_count,
            e.triangle_count,
            bytes.len(),
            total,
            e.geometric_error,
            ms
        );
    }
    println!(
        "final state hash {:016x}: decoded exactly (checked against the input during encoding)",
        decoder.state_hash()
    );
    Ok(())
}
