//! Times `input::read_mesh` (parsing alone, no check) on mesh or grid files:
//! `cargo run --release -p splitstream-encoder --example read_time -- FILE... [--runs N]`.
//! Prints each file's median and fastest read of N (default 5), and a
//! digest of what was read, so that two readers can be compared on the
//! same files (encoder/BENCHMARKS.md, "Reading PLY, OBJ, OFF and glTF files faster").
use splitstream_encoder::input::{ReadOptions, read_mesh};

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut runs = 5usize;
    if let Some(i) = args.iter().position(|a| a == "--runs") {
        runs = args
            .get(i + 1)
            .and_then(|r| r.parse().ok())
            .unwrap_or_else(|| fail("--runs takes a number"));
        args.drain(i..i + 2);
    }
    if args.is_empty() {
        fail("usage: read_time FILE... [--runs N]");
    }
    for file in &args {
        let path = std::path::Path::new(file);
        let mut times = Vec::new();
        let mut digest = 0u64;
        let mut counts = (0, 0);
        for _ in 0..runs.max(1) {
            let t = std::time::Instant::now();
            let mesh =
                read_mesh(path, &ReadOptions::default()).unwrap_or_else(|e| fail(&e.to_string()));
            times.push(t.elapsed().as_secs_f64() * 1e3);
            counts = (mesh.positions.len(), mesh.triangles.len());
            digest = fnv(&mesh);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{file}: read median {:.1} ms of {} runs (min {:.1}); {} vertices, {} triangles, digest {digest:016x}",
            times[times.len() / 2],
            times.len(),
            times[0],
            counts.0,
            counts.1,
        );
    }
}

/// FNV-1a over the positions' bits and the triangles' indices.
fn fnv(mesh: &splitstream_encoder::Mesh) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h = (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
        }
    };
    for p in &mesh.positions {
        for c in p {
            eat(&c.to_bits().to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for i in t {
            eat(&i.to_le_bytes());
        }
    }
    h
}

/// One line on stderr and a non-zero exit, as the command line does.
fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1)
}
