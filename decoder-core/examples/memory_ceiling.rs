//! What the memory of this machine allows a vertex-split decoder: the
//! latency of a dependent load and the cost of independent loads over an
//! array the size of a 1M-vertex decoder's workspace, and the splits per
//! second they bound when each split touches a given number of cache lines
//! no cache holds (decoder-core/README.md, "Where the time goes").
//!
//! ```text
//! cargo run --release -p splitstream-decoder-core --example memory_ceiling -- [MEGABYTES]
//! ```

use std::time::Instant;

fn main() {
    let megabytes: usize = std::env::args()
        .nth(1)
        .and_then(|m| m.parse().ok())
        .unwrap_or(64);
    let n = megabytes * (1 << 20) / 8;
    // A random cyclic permutation (Sattolo), so the chase visits every slot.
    let mut next: Vec<u64> = (0..n as u64).collect();
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut random = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    for i in (1..n).rev() {
        let j = (random() % i as u64) as usize;
        next.swap(i, j);
    }
    let steps = 4_000_000usize;
    let mut best_dependent = f64::MAX;
    let mut best_independent = f64::MAX;
    for _ in 0..3 {
        let started = Instant::now();
        let mut p = 0u64;
        for _ in 0..steps {
            p = next[p as usize];
        }
        std::hint::black_box(p);
        best_dependent = best_dependent.min(started.elapsed().as_secs_f64() / steps as f64);
        let started = Instant::now();
        let mut sum = 0u64;
        let mut i = 1u64;
        for _ in 0..steps {
            i = i
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            sum = sum.wrapping_add(next[(i >> 20) as usize % n]);
        }
        std::hint::black_box(sum);
        best_independent = best_independent.min(started.elapsed().as_secs_f64() / steps as f64);
    }
    println!(
        "{megabytes} MiB: dependent load {:.1} ns, independent load {:.1} ns (best of 3)",
        best_dependent * 1e9,
        best_independent * 1e9
    );
    for lines in [4, 8, 16, 24] {
        println!(
            "  {lines:2} missed lines per split: at most {:5.1} M splits/s if every miss overlaps, {:4.2} M/s if none does",
            1e-6 / (lines as f64 * best_independent),
            1e-6 / (lines as f64 * best_dependent)
        );
    }
}
