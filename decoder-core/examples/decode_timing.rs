//! Decodes a stream file several times, single-threaded, and prints the
//! median time and splits per second (a quick check beside the criterion
//! bench `cargo bench -p splitstream-encoder --bench decode`). On Linux it
//! also prints the CPU time the thread ran (from /proc/thread-self/schedstat),
//! which is steadier than wall time when other processes share the cores.
//!
//! ```text
//! cargo run --release -p splitstream-decoder-core --features alloc --example decode_timing -- FILE.sps [RUNS]
//! ```

use std::time::Instant;

use splitstream_decoder_core::owned::OwnedWorkspace;

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: decode_timing FILE.sps [RUNS]");
        std::process::exit(2);
    };
    let runs: usize = args.next().and_then(|r| r.parse().ok()).unwrap_or(5);
    let stream = match std::fs::read(&path) {
        Ok(bytes) => bytes,
        Err(e) => {
            eprintln!("error: {path}: {e}");
            std::process::exit(1);
        }
    };
    let mut ws = match OwnedWorkspace::for_stream(&stream) {
        Ok(ws) => ws,
        Err(e) => {
            eprintln!("error: {path}: {e}");
            std::process::exit(1);
        }
    };
    let mut times = Vec::with_capacity(runs);
    let mut cpu_times = Vec::with_capacity(runs);
    let mut splits = 0u64;
    let mut hash = 0u64;
    for _ in 0..runs.max(1) {
        let started = Instant::now();
        let cpu_started = cpu_ns();
        let mut decoder = ws.decoder(&stream).expect("valid stream");
        decoder.decode_available(&stream).expect("decodes");
        times.push(started.elapsed().as_secs_f64());
        if let (Some(a), Some(b)) = (cpu_started, cpu_ns()) {
            cpu_times.push((b - a) as f64 * 1e-9);
        }
        splits = decoder.positions().len() as u64 - seed_vertices(&stream);
        hash = decoder.state_hash();
    }
    times.sort_by(f64::total_cmp);
    cpu_times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let cpu = cpu_times
        .get(cpu_times.len() / 2)
        .map(|t| format!(", cpu median {:.1} ms", t * 1e3))
        .unwrap_or_default();
    println!(
        "{path}: wall median {:.1} ms of {} runs (min {:.1}){cpu}, {:.2} M splits/s (wall), hash {hash:016x}",
        median * 1e3,
        times.len(),
        times[0] * 1e3,
        splits as f64 / median / 1e6
    );
}

/// Nanoseconds this thread has run on a CPU (Linux), if known.
fn cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// Vertices of the seed mesh: the ones no split created.
fn seed_vertices(stream: &[u8]) -> u64 {
    use splitstream_decoder_core::{Header, LevelHeader, LevelTable};
    let head = Header::parse(stream).expect("header");
    let table = LevelTable::parse(stream, &head).expect("level table");
    let level0 = table.get(0);
    let bytes = &stream[level0.offset as usize..(level0.offset + level0.length as u64) as usize];
    let level = LevelHeader::parse(bytes, true, head.level_rules()).expect("level 0");
    level.seed_vertices as u64
}
