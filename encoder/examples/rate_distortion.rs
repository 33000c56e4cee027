//! Error against bytes, level by level, for both position modes: each
//! level's decoded mesh against the input (symmetric sampled Hausdorff and
//! RMS distance, % of the bounding-box diagonal), beside the stream's bytes
//! up to that level.
//!
//! `cargo run --release -p splitstream-encoder --example rate_distortion -- FILE... [--uniform] [--samples N]`

use splitstream_decoder_core::PositionMode;
use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_encoder::Mesh;
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::input::{ReadOptions, read_mesh};
use splitstream_encoder::metrics::surface_distance;
use splitstream_encoder::quantize::Quantization;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let uniform = args.iter().any(|a| a == "--uniform");
    let samples = args
        .iter()
        .position(|a| a == "--samples")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(200_000usize);
    let files: Vec<&String> = args
        .iter()
        .enumerate()
        .filter(|&(i, a)| !a.starts_with("--") && (i == 0 || args[i - 1] != "--samples"))
        .map(|(_, a)| a)
        .collect();
    println!(
        "| input | mode | level | vertices | bytes to here | bits per input vertex | Hausdorff % | RMS % |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    for file in files {
        let mesh = read_mesh(std::path::Path::new(file), &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let name = std::path::Path::new(file)
            .file_stem()
            .map_or(file.clone(), |s| s.to_string_lossy().into_owned());
        for mode in [PositionMode::Optimal, PositionMode::Constrained] {
            let options = EncodeOptions {
                position_mode: mode,
                quantization: if uniform {
                    Quantization::Uniform
                } else {
                    Quantization::PerAxis
                },
                ..EncodeOptions::default()
            };
            let encoded = encode(&mesh, &options, |_| {}).expect("encode");
            for (level, bytes, decoded) in levels(&encoded.stream) {
                let d = surface_distance(&mesh, &decoded, samples, 2012);
                println!(
                    "| {name} | {} | {level} | {} | {bytes} | {:.2} | {:.4} | {:.5} |",
                    match mode {
                        PositionMode::Optimal => "optimal",
                        PositionMode::Constrained => "constrained",
                    },
                    decoded.positions.len(),
                    8.0 * bytes as f64 / mesh.positions.len() as f64,
                    100.0 * d.hausdorff / d.diagonal,
                    100.0 * d.rms / d.diagonal,
                );
            }
        }
    }
}

/// Each level's mesh, dequantized, with the stream's bytes up to its end.
fn levels(stream: &[u8]) -> Vec<(u16, usize, Mesh)> {
    let mut ws = OwnedWorkspace::for_stream(stream).expect("workspace");
    let mut decoder = ws.decoder(stream).expect("decoder");
    let mut out = Vec::new();
    while let Some(k) = decoder.next_level() {
        let bytes = decoder.level_bytes(k, stream).expect("level bytes");
        let end = bytes.as_ptr() as usize + bytes.len() - stream.as_ptr() as usize;
        decoder.decode_level(k, bytes).expect("decode");
        let positions = decoder
            .positions()
            .iter()
            .map(|&q| decoder.dequantize(q))
            .collect();
        let triangles = decoder.triangles().to_vec();
        out.push((
            k,
            end,
            Mesh {
                positions,
                triangles,
            },
        ));
    }
    out
}
