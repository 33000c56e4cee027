//! Many streams decoded on several cores: a client showing a set of tiles
//! or objects opens one `Session` per stream and decodes them on worker
//! threads (a `Session` is `Send`). Decodes one stream `copies` times on one
//! thread, then the same copies spread over `threads` threads, and prints
//! the splits per second of both and their ratio (medians of `runs`
//! interleaved pairs). Each decode opens its session (its workspace
//! allocation included) and decodes every level.
//!
//! ```text
//! cargo run --release -p splitstream-sdk-native --example decode_threads -- \
//!     STREAM.sps [--copies 8] [--threads N] [--runs 5]
//! ```
//!
//! `--threads` defaults to the machine's available parallelism.

use std::time::Instant;

use splitstream_sdk_native::Session;

/// Opens and decodes `stream` whole; returns the splits decoded.
fn try_decode(stream: &[u8]) -> Result<u64, splitstream_decoder_core::Error> {
    let mut s = Session::open(stream)?;
    while let Some(k) = s.next_level() {
        let r = s.level_range(k).unwrap_or(0..0);
        let bytes = stream
            .get(r.start as usize..r.end as usize)
            .ok_or(splitstream_decoder_core::Error::Truncated)?;
        s.decode_level(k, bytes)?;
    }
    let base = s.level_info(0).map_or(0, |l| l.vertex_count) as u64;
    Ok(s.positions().len() as u64 - base)
}

/// [`try_decode`] of a stream `main` has already decoded once without error
/// (decoding is deterministic: the same bytes decode the same way).
fn decode(stream: &[u8]) -> u64 {
    try_decode(stream).expect("decoded once already")
}

/// Seconds to decode `copies` copies on `threads` threads, and the splits.
fn timed(stream: &[u8], copies: usize, threads: usize) -> (f64, u64) {
    let started = Instant::now();
    let splits = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|t| {
                // Copies t, t + threads, …: shares differ by at most one.
                let share = (t..copies).step_by(threads).count();
                scope.spawn(move || (0..share).map(|_| decode(stream)).sum::<u64>())
            })
            .collect();
        workers
            .into_iter()
            .map(|w| w.join().expect("decoding does not panic"))
            .sum::<u64>()
    });
    (started.elapsed().as_secs_f64(), splits)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut path = None;
    let (mut copies, mut runs) = (8usize, 5usize);
    let mut threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    while let Some(a) = args.next() {
        let mut number = |name: &str| -> usize {
            match args.next().and_then(|v| v.parse().ok()) {
                Some(n) if n > 0 => n,
                _ => {
                    eprintln!("decode_threads: {name} needs a number above 0");
                    std::process::exit(2);
                }
            }
        };
        match a.as_str() {
            "--copies" => copies = number("--copies"),
            "--threads" => threads = number("--threads"),
            "--runs" => runs = number("--runs"),
            _ => path = Some(a),
        }
    }
    let Some(path) = path else {
        eprintln!("usage: decode_threads STREAM.sps [--copies 8] [--threads N] [--runs 5]");
        std::process::exit(2);
    };
    let stream = match std::fs::read(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("decode_threads: {path}: {e}");
            std::process::exit(1);
        }
    };
    // A bad stream is reported here, once, before any timed decode.
    if let Err(e) = try_decode(&stream) {
        eprintln!("decode_threads: {path}: {e}");
        std::process::exit(1);
    }
    let (mut one, mut many) = (Vec::new(), Vec::new());
    let mut splits = 0;
    for _ in 0..runs {
        let (t1, s1) = timed(&stream, copies, 1);
        let (tn, sn) = timed(&stream, copies, threads);
        assert_eq!(s1, sn);
        splits = s1;
        one.push(t1);
        many.push(tn);
    }
    let ratios: Vec<f64> = one.iter().zip(&many).map(|(a, b)| a / b).collect();
    let (t1, tn) = (median(one), median(many));
    println!(
        "{path}: {copies} copies, {splits} splits in all; 1 thread {:.1} ms ({:.2} M splits/s), \
         {threads} threads {:.1} ms ({:.2} M splits/s): {:.2}x (median of {runs} pairs; pairs {:.2}-{:.2}x)",
        t1 * 1e3,
        splits as f64 / t1 / 1e6,
        tn * 1e3,
        splits as f64 / tn / 1e6,
        median(ratios.clone()),
        ratios.iter().copied().fold(f64::MAX, f64::min),
        ratios.iter().copied().fold(f64::MIN, f64::max),
    );
}
