//! The rANS chunk encoder (SPEC §5.5), the inverse of `rans.rs`: builds the
//! per-context tables from the chunk's own values, then codes each lane
//! backwards so that the decoder reads it forwards.

use alloc::vec;
use alloc::vec::Vec;

use crate::limits::CHUNK_ENTRY_LEN;
use crate::limits::rans::{PROB_BITS, RAW_BITS_STEP, STATE_LOW, TOKENS};
use crate::rans::{normalise, token_of};

/// The most raw-bit steps of one value: 31 extra bits in steps of
/// `RAW_BITS_STEP`.
const RAW_STEPS_MAX: usize = 31usize.div_ceil(RAW_BITS_STEP as usize);

/// A value and the context it is coded in.
pub type Symbol = (u8, u32);

fn push_varint(out: &mut Vec<u8>, mut v: u32) {
    loop {
        let low = (v & 0x7F) as u8;
        v >>= 7;
        if v == 0 {
            out.push(low);
            return;
        }
        out.push(low | 0x80);
    }
}

fn varint_len(v: u32) -> usize {
    (32 - v.leading_zeros()).div_ceil(7).max(1) as usize
}

/// Counts sent for one context, scaled down so the table stays small.
/// Tries a few scales and keeps the cheapest (table bytes + estimated code).
fn choose_counts(histogram: &[u32]) -> Vec<u32> {
    scaled_counts(histogram).1
}

/// [`choose_counts`] and the bits it was chosen for: the table's count
/// bytes and the values' tokens under it (raw bits left out: they do not
/// depend on the table).
fn scaled_counts(histogram: &[u32]) -> (f64, Vec<u32>) {
    let n = histogram.iter().rposition(|&c| c > 0).map_or(0, |i| i + 1);
    let histogram = &histogram[..n];
    let max = histogram.iter().copied().max().unwrap_or(0);
    let mut best: Option<(f64, Vec<u32>)> = None;
    for limit in [7u32, 31, 127, 1023, u32::MAX] {
        let counts: Vec<u32> = if max <= limit {
            histogram.to_vec()
        } else {
            histogram
                .iter()
                .map(|&c| {
                    if c == 0 {
                        0
                    } else {
                        ((c as u64 * limit as u64).div_ceil(max as u64)) as u32
                    }
                })
                .collect()
        };
        let mut freqs = counts.clone();
        if normalise(&mut freqs).is_err() {
            continue;
        }
        let table_bits = 8.0 * counts.iter().map(|&c| varint_len(c)).sum::<usize>() as f64;
        let code_bits: f64 = histogram
            .iter()
            .zip(&freqs)
            .filter(|(c, _)| **c > 0)
            .map(|(&c, &f)| c as f64 * (PROB_BITS as f64 - libm_log2(f as f64)))
            .sum();
        let cost = table_bits + code_bits;
        if best.as_ref().is_none_or(|(b, _)| cost < *b) {
            best = Some((cost, counts));
        }
        if max <= limit {
            break;
        }
    }
    best.unwrap_or_default()
}

/// Estimated bits of one rANS chunk coding `values` values whose tokens
/// fall into `histograms` (one per context), beside their raw bits: its
/// directory entry, every context's table, the tokens under those tables
/// (as [`encode_chunk`] chooses them) and the lanes' lengths and final
/// states. What [`crate::writer`] weighs when it decides where to cut a
/// substream into chunks.
pub fn chunk_cost_bits(histograms: &[[u32; TOKENS]], values: usize, lanes: usize) -> f64 {
    // Directory entry, then per lane a length varint (about 2 bytes) and
    // its 4-byte state.
    let fixed_bytes = CHUNK_ENTRY_LEN + 6 * lanes.min(values.max(1));
    let tables: f64 = histograms.iter().map(|h| 8.0 + scaled_counts(h).0).sum();
    8.0 * fixed_bytes as f64 + tables
}

/// log2 without std: exact enough for choosing a table scale.
fn libm_log2(x: f64) -> f64 {
    // x is a frequency in 1..=4096: integer part from the exponent, then a
    // short series for the mantissa.
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7FF) as i64 - 1023;
    let m = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
    // ln(m) for m in [1, 2) via atanh series, then / ln 2.
    let y = (m - 1.0) / (m + 1.0);
    let y2 = y * y;
    let ln =
        2.0 * y * (1.0 + y2 / 3.0 + y2 * y2 / 5.0 + y2 * y2 * y2 / 7.0 + y2 * y2 * y2 * y2 / 9.0);
    exponent as f64 + ln / core::f64::consts::LN_2
}

/// Encodes `symbols` as one rANS chunk payload with `contexts` tables and
/// `lanes` lanes (SPEC §5.5.2, §5.5.3).
pub fn encode_chunk(symbols: &[Symbol], contexts: usize, lanes: usize) -> Vec<u8> {
    let mut histograms = vec![[0u32; TOKENS]; contexts];
    for &(ctx, value) in symbols {
        histograms[ctx as usize][token_of(value).0 as usize] += 1;
    }
    let mut out = Vec::new();
    // Cumulative starts and frequencies per context and token.
    let mut start = vec![[0u32; TOKENS]; contexts];
    let mut freq = vec![[0u32; TOKENS]; contexts];
    for c in 0..contexts {
        let counts = choose_counts(&histograms[c]);
        out.push(counts.len() as u8);
        for &count in &counts {
            push_varint(&mut out, count);
        }
        let mut f = counts.clone();
        if f.is_empty() {
            continue;
        }
        normalise(&mut f).expect("nonzero counts normalise");
        let mut cum = 0;
        for (t, &ft) in f.iter().enumerate() {
            start[c][t] = cum;
            freq[c][t] = ft;
            cum += ft;
        }
    }
    let mut lane_bytes: Vec<Vec<u8>> = Vec::with_capacity(lanes);
    for lane in 0..lanes {
        let mut x = STATE_LOW;
        let mut bytes = Vec::new(); // reversed
        let mine = symbols.iter().skip(lane).step_by(lanes);
        let mine: Vec<&Symbol> = mine.collect();
        if mine.is_empty() {
            lane_bytes.push(Vec::new());
            continue;
        }
        for &&(ctx, value) in mine.iter().rev() {
            let (token, extra, low) = token_of(value);
            // Raw bits: the decoder reads the low step first, so the
            // encoder pushes the high steps first. At most 31 extra bits:
            // two steps (a fixed array; a Vec here allocated once per value
            // with raw bits).
            let mut steps = [(0u32, 0u32); RAW_STEPS_MAX];
            let mut count = 0;
            let mut done = 0;
            while done < extra {
                let step = (extra - done).min(RAW_BITS_STEP);
                steps[count] = (step, (low >> done) & ((1 << step) - 1));
                count += 1;
                done += step;
            }
            for &(step, bits) in steps[..count].iter().rev() {
                let x_max = (STATE_LOW >> step) << 8;
                while x >= x_max {
                    bytes.push(x as u8);
                    x >>= 8;
                }
                x = (x << step) | bits;
            }
            let (s, f) = (
                start[ctx as usize][token as usize],
                freq[ctx as usize][token as usize],
            );
            debug_assert!(f > 0);
            let x_max = ((STATE_LOW >> PROB_BITS) << 8) * f;
            while x >= x_max {
                bytes.push(x as u8);
                x >>= 8;
            }
            x = ((x / f) << PROB_BITS) + (x % f) + s;
        }
        bytes.extend_from_slice(&x.to_be_bytes());
        bytes.reverse();
        // The state was pushed big-endian then reversed: little-endian now.
        lane_bytes.push(bytes);
    }
    for b in &lane_bytes {
        push_varint(&mut out, b.len() as u32);
    }
    for b in lane_bytes {
        out.extend_from_slice(&b);
    }
    out
}
