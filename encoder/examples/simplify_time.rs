//! Times the parallel simplification alone on the demo terrain (or a mesh
//! file) and prints a digest of its collapses, to compare two builds.
//!
//! `cargo run --release -p splitstream-encoder --example simplify_time -- [SIDE|FILE] [constrained] [runs]`

use std::hash::{Hash, Hasher};
use std::time::Instant;

use splitstream_encoder::input::fractal_terrain;
use splitstream_encoder::quantize::{Lattice, Quantization, Units, quantize_with};
use splitstream_encoder::simplify::{Checked, SimplifyOptions, simplify};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let what = args.first().map_or("1000", String::as_str);
    let constrained = args.iter().any(|a| a == "constrained");
    let runs: usize = args.get(2).and_then(|r| r.parse().ok()).unwrap_or(1);
    let mesh = match what.parse::<usize>() {
        Ok(side) => fractal_terrain(side, 2012),
        Err(_) => splitstream_encoder::input::read_mesh(
            std::path::Path::new(what),
            &splitstream_encoder::input::ReadOptions::default(),
        )
        .expect("read"),
    };
    let q = quantize_with(
        &mesh,
        14,
        Units::Linear,
        Quantization::PerAxis,
        Lattice::Ignore,
    );
    let q = Checked::new(&q).unwrap_or_else(|e| {
        eprintln!("simplify_time: {e}");
        std::process::exit(1)
    });
    let options = SimplifyOptions {
        target_vertices: 16,
        constrained,
        ..SimplifyOptions::default()
    };
    for _ in 0..runs {
        let t = Instant::now();
        let s = simplify(&q, &options, |_| {});
        let secs = t.elapsed().as_secs_f64();
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for step in &s.steps {
            step.len().hash(&mut h);
            for c in step {
                (
                    c.p,
                    c.c,
                    c.wing_a,
                    c.wing_b,
                    c.position_r,
                    c.error.to_bits(),
                )
                    .hash(&mut h);
            }
        }
        println!(
            "simplify {:.3} s, {} steps, {} collapses, digest {:016x}",
            secs,
            s.steps.len(),
            s.steps.iter().map(Vec::len).sum::<usize>(),
            h.finish()
        );
    }
}
