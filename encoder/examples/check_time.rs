//! Times `input::check_mesh` on the fractal terrain (or a mesh file):
//! `cargo run --release -p splitstream-encoder --example check_time -- [SIDE|FILE] [RUNS]`.
use splitstream_encoder::input::{ReadOptions, check_mesh, fractal_terrain, read_mesh};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let what = args.first().map_or("1000", String::as_str);
    let runs: usize = args.get(1).and_then(|r| r.parse().ok()).unwrap_or(5);
    let mesh = match what.parse::<usize>() {
        Ok(side) => fractal_terrain(side, 2012),
        Err(_) => match read_mesh(std::path::Path::new(what), &ReadOptions::default()) {
            Ok(mesh) => mesh,
            Err(e) => fail(&e.to_string()),
        },
    };
    let mut times = Vec::new();
    let mut stats = None;
    for _ in 0..runs.max(1) {
        let t = std::time::Instant::now();
        match check_mesh(&mesh) {
            Ok(s) => stats = Some(s),
            Err(e) => fail(&format!("{what}: {e}")),
        }
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    if let Some(stats) = stats {
        println!(
            "{what}: check_mesh median {:.1} ms of {} runs (min {:.1}); {stats}",
            times[times.len() / 2],
            times.len(),
            times[0],
        );
    }
}

/// One line on stderr and a non-zero exit, as the command line does.
fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1)
}
