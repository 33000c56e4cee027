//! Where the writer cuts a substream's values into rANS chunks (SPEC §5.2:
//! a rANS chunk codes any number of values, and chunk boundaries carry no
//! meaning, so this is the encoder's choice alone).
//!
//! Every chunk sends its own frequency tables. Long chunks send few tables,
//! short ones follow the values' statistics as they drift through a level
//! (its first rounds and its last split vertices of different valences, at
//! different scales). The substream is cut into blocks, and neighbouring
//! blocks are joined pairwise, level by level as in a binary tree, wherever
//! the joined chunk is estimated smaller than the two halves as they are
//! best cut ([`chunk_cost_bits`]): the cheapest cut among those whose
//! chunks are aligned runs of 2^h blocks.

use alloc::vec;
use alloc::vec::Vec;
use core::ops::Range;

use crate::limits::rans::TOKENS;
use crate::rans::token_of;
use crate::rans_writer::{Symbol, chunk_cost_bits};

/// Values per block: the finest cut. Blocks this long hold enough values
/// for their tables to pay (a table costs a few dozen bytes), and a large
/// level's longest substream (3 million values on a 1M-vertex terrain) has
/// under a thousand of them, so the joins cost milliseconds.
pub const SEGMENT_BLOCK: usize = 4096;

/// One run of blocks as best cut: its chunks and their estimated bits, and
/// the token counts of the whole run (to join it with its neighbour).
struct Run {
    values: Range<usize>,
    histograms: Vec<[u32; TOKENS]>,
    chunks: Vec<Range<usize>>,
    bits: f64,
}

/// The ranges of `symbols` that the writer codes as its rANS chunks, in
/// order, each of 1 ..= `limit` values; none for no values. A `limit` of at
/// most [`SEGMENT_BLOCK`] cuts every chunk `limit` long (the last one
/// shorter), as tests and conformance vectors ask of small limits.
pub fn rans_segments(
    symbols: &[Symbol],
    contexts: usize,
    lanes: usize,
    limit: usize,
) -> Vec<Range<usize>> {
    let limit = limit.max(1);
    let n = symbols.len();
    if limit <= SEGMENT_BLOCK || n <= SEGMENT_BLOCK {
        return (0..n.div_ceil(limit))
            .map(|i| i * limit..n.min((i + 1) * limit))
            .collect();
    }
    let contexts = contexts.max(1);
    let mut runs: Vec<Run> = (0..n.div_ceil(SEGMENT_BLOCK))
        .map(|i| {
            let values = i * SEGMENT_BLOCK..n.min((i + 1) * SEGMENT_BLOCK);
            let mut histograms = vec![[0u32; TOKENS]; contexts];
            for &(context, value) in &symbols[values.clone()] {
                if let Some(h) = histograms.get_mut(context as usize) {
                    h[token_of(value).0 as usize] += 1;
                }
            }
            let bits = chunk_cost_bits(&histograms, values.len(), lanes);
            Run {
                chunks: vec![values.clone()],
                values,
                histograms,
                bits,
            }
        })
        .collect();
    while runs.len() > 1 {
        let mut joined = Vec::with_capacity(runs.len().div_ceil(2));
        let mut pairs = runs.into_iter();
        while let Some(first) = pairs.next() {
            match pairs.next() {
                Some(second) => joined.push(join(first, second, lanes, limit)),
                None => joined.push(first),
            }
        }
        runs = joined;
    }
    runs.pop().map(|r| r.chunks).unwrap_or_default()
}

/// Two neighbouring runs as one: a single chunk where that fits in `limit`
/// values and is estimated no larger than their cuts side by side.
fn join(mut first: Run, second: Run, lanes: usize, limit: usize) -> Run {
    let values = first.values.start..second.values.end;
    let split_bits = first.bits + second.bits;
    for (a, b) in first.histograms.iter_mut().zip(&second.histograms) {
        for (x, y) in a.iter_mut().zip(b) {
            *x += y;
        }
    }
    if values.len() <= limit {
        let whole_bits = chunk_cost_bits(&first.histograms, values.len(), lanes);
        if whole_bits <= split_bits {
            return Run {
                chunks: vec![values.clone()],
                values,
                histograms: first.histograms,
                bits: whole_bits,
            };
        }
    }
    first.chunks.extend(second.chunks);
    Run {
        values,
        histograms: first.histograms,
        chunks: first.chunks,
        bits: split_bits,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values drawn from a small generator, `n` of them, in `contexts`
    /// contexts, whose spread changes every `drift` values.
    fn drifting(n: usize, contexts: u8, drift: usize) -> Vec<Symbol> {
        let mut x = 0x9E37_79B9u32;
        (0..n)
            .map(|i| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                let spread = if (i / drift).is_multiple_of(2) {
                    3
                } else {
                    2000
                };
                ((i % contexts as usize) as u8, x % spread)
            })
            .collect()
    }

    fn assert_partition(chunks: &[Range<usize>], n: usize, limit: usize) {
        let mut at = 0;
        for c in chunks {
            assert_eq!(c.start, at, "{chunks:?}");
            assert!(!c.is_empty() && c.len() <= limit, "{chunks:?}");
            at = c.end;
        }
        assert_eq!(at, n);
    }

    #[test]
    fn small_limits_cut_every_chunk_that_long() {
        let symbols = drifting(100, 2, 10);
        for limit in [1, 5, 7, 64, 4096] {
            let chunks = rans_segments(&symbols, 2, 4, limit);
            let want: Vec<Range<usize>> = (0..100usize.div_ceil(limit))
                .map(|i| i * limit..100.min((i + 1) * limit))
                .collect();
            assert_eq!(chunks, want, "limit {limit}");
        }
        assert!(rans_segments(&[], 1, 4, 16_384).is_empty());
    }

    #[test]
    fn chunks_partition_the_values_within_the_limit() {
        for (n, limit) in [
            (4097, 1 << 20),
            (50_000, 10_000),
            (100_000, 16_384),
            (9000, 8192),
        ] {
            let symbols = drifting(n, 3, 20_000);
            let chunks = rans_segments(&symbols, 3, 4, limit);
            assert_partition(&chunks, n, limit);
        }
    }

    #[test]
    fn steady_values_make_one_chunk_and_drifting_ones_are_cut_where_they_change() {
        let steady = drifting(64 * 1024, 2, usize::MAX);
        let one = rans_segments(&steady, 2, 4, 1 << 20);
        assert_eq!((one.len(), one[0].clone()), (1, 0..64 * 1024));
        // Spreads of 3 and of 2,000 alternate every 32,768 values: each
        // run is its own chunk.
        let drift = drifting(128 * 1024, 2, 32 * 1024);
        let chunks = rans_segments(&drift, 2, 4, 1 << 20);
        assert_eq!(
            chunks,
            [0..32768, 32768..65536, 65536..98304, 98304..131072]
        );
    }
}
