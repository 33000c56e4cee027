//! One stream decoded on one thread and on two (`threaded`): the
//! wall-clock medians of `runs` interleaved pairs, their ratio, and a check
//! that both end in the same state (SPEC §8 hash). Each decode reuses its
//! workspace (and the two-thread memory), as a client decoding a stream
//! again would; only the levels' decoding is timed.
//!
//! ```text
//! cargo run --release -p splitstream-sdk-native --example decode_two_threads -- STREAM.sps [--runs 7] [--only 1|2] [--from SPLITS]
//! ```
//!
//! `--only` decodes one way only (for a profiler); then no ratio is printed.
//! `--from` sets the level size from which the second thread is used
//! (`TwoThreadMemory::set_two_threads_from`; 0: every level).

use std::time::Instant;

use splitstream_decoder_core::owned::OwnedWorkspace;
use splitstream_sdk_native::threaded::{self, TwoThreadMemory};

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: decode_two_threads STREAM.sps [--runs N] [--only 1|2] [--from SPLITS]");
        std::process::exit(2);
    };
    let mut runs = 7usize;
    let mut ways = vec![1, 2];
    let mut from: Option<u32> = None;
    while let Some(a) = args.next() {
        match (a.as_str(), args.next().and_then(|v| v.parse().ok())) {
            ("--runs", Some(n)) => runs = n,
            ("--only", Some(t @ (1 | 2))) => ways = vec![t],
            ("--from", Some(n)) => from = Some(n as u32),
            _ => {
                eprintln!(
                    "usage: decode_two_threads STREAM.sps [--runs N] [--only 1|2] [--from SPLITS]"
                );
                std::process::exit(2);
            }
        }
    }
    let stream = std::fs::read(&path).unwrap_or_else(|e| {
        eprintln!("error: {path}: {e}");
        std::process::exit(1);
    });
    let mut ws = OwnedWorkspace::for_stream(&stream).unwrap_or_else(|e| {
        eprintln!("error: {path}: {e}");
        std::process::exit(1);
    });
    let mut memory: Option<TwoThreadMemory> = None;
    let (mut one, mut two) = (Vec::new(), Vec::new());
    let mut hashes = (0u64, 0u64);
    let mut splits = 0u64;
    for _ in 0..runs.max(1) {
        for &threads in &ways {
            let mut decoder = ws.decoder(&stream).unwrap_or_else(|e| {
                eprintln!("error: {path}: {e}");
                std::process::exit(1);
            });
            let memory = memory.get_or_insert_with(|| {
                let mut m = TwoThreadMemory::new(decoder.state().vertex_capacity());
                if let Some(splits) = from {
                    m.set_two_threads_from(splits);
                }
                m
            });
            let started = Instant::now();
            while let Some(k) = decoder.next_level() {
                let bytes = decoder
                    .level_bytes(k, &stream)
                    .expect("level in the stream");
                let result = if threads == 1 {
                    decoder.decode_level(k, bytes)
                } else {
                    threaded::decode_level(&mut decoder, k, bytes, memory)
                };
                if let Err(e) = result {
                    eprintln!("error: {path}: level {k}: {e}");
                    std::process::exit(1);
                }
            }
            let seconds = started.elapsed().as_secs_f64();
            let base = decoder.level_table().get(0).vertex_count as u64;
            splits = decoder.positions().len() as u64 - base;
            if threads == 1 {
                one.push(seconds);
                hashes.0 = decoder.state_hash();
            } else {
                two.push(seconds);
                hashes.1 = decoder.state_hash();
            }
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    if ways.len() == 1 {
        let (way, times) = if ways[0] == 1 {
            ("1 thread", &mut one)
        } else {
            ("2 threads", &mut two)
        };
        let m = median(times);
        println!(
            "{path}: {splits} splits; {way} {:.1} ms ({:.2} M splits/s, median of {runs})",
            m * 1e3,
            splits as f64 / m * 1e-6
        );
        return;
    }
    if hashes.0 != hashes.1 {
        eprintln!(
            "error: {path}: two threads ended in state {:016x}, one thread in {:016x}",
            hashes.1, hashes.0
        );
        std::process::exit(1);
    }
    let (m1, m2) = (median(&mut one), median(&mut two));
    println!(
        "{path}: {splits} splits; 1 thread {:.1} ms ({:.2} M splits/s), 2 threads {:.1} ms ({:.2} M splits/s), ratio {:.2} (medians of {runs}); hash {:016x} both",
        m1 * 1e3,
        splits as f64 / m1 * 1e-6,
        m2 * 1e3,
        splits as f64 / m2 * 1e-6,
        m1 / m2,
        hashes.0
    );
}
