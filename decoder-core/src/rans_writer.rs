//! The rANS chunk encoder (SPEC §5.5), the inverse of `rans.rs`: builds the
//! per-context tables from the chunk's own values, then codes each lane
//! backwards so that the decoder reads it forwards.

use alloc::vec;
use alloc::vec::Vec;

use crate::limits::CHUNK_ENTRY_LEN;
use crate::limits::rans::{
    ADAPTIVE_BITS, ADAPTIVE_FLAG, ADAPTIVE_RATE_MIN, ADAPTIVE_START, ADAPTIVE_STATES,
    ADAPTIVE_TOKENS, MAX_LANES, PROB_BITS, PROB_SCALE, RAW_BITS_STEP, STATE_LOW, TOKENS,
};
use crate::rans::{adaptive_shift, normalise, token_of};

/// A value and the context it is coded in.
pub type Symbol = (u8, u32);

pub(crate) fn push_varint(out: &mut Vec<u8>, mut v: u32) {
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

/// A context's static table as [`scaled_counts`] chooses it.
#[derive(Clone, Copy, Debug)]
struct StaticTable {
    /// Its count bytes and the context's tokens under it, in bits.
    cost: f64,
    /// Its tokens: the counts and frequencies of `..tokens` are its own.
    tokens: usize,
    counts: [u32; TOKENS],
    /// The counts normalised (`normalise`), where `tokens > 0`.
    freqs: [u32; TOKENS],
}

/// Bits of a token whose frequency is `f` out of `PROB_SCALE`, for `f` in
/// `0..=PROB_SCALE` (entry 0 unused): `PROB_BITS − log2 f` as
/// [`libm_log2`] computes it (the same function, evaluated once).
static TOKEN_BITS: [f64; PROB_SCALE as usize + 1] = token_bits();

const fn token_bits() -> [f64; PROB_SCALE as usize + 1] {
    let mut table = [0f64; PROB_SCALE as usize + 1];
    let mut f = 1;
    while f <= PROB_SCALE as usize {
        table[f] = PROB_BITS as f64 - libm_log2(f as f64);
        f += 1;
    }
    table
}

/// The static table of a context whose tokens counted `histogram`: the
/// count scale whose table bytes and tokens under it cost fewest bits (raw
/// bits left out: they do not depend on the table).
fn scaled_counts(histogram: &[u32]) -> StaticTable {
    let n = histogram.iter().rposition(|&c| c > 0).map_or(0, |i| i + 1);
    let mut best = StaticTable {
        cost: 0.0,
        tokens: 0,
        counts: [0; TOKENS],
        freqs: [0; TOKENS],
    };
    if n == 0 {
        // (No scale normalises an empty table.)
        return best;
    }
    let histogram = &histogram[..n];
    let max = histogram.iter().copied().max().unwrap_or(0);
    let mut found = false;
    for limit in [7u32, 31, 127, 1023, u32::MAX] {
        let mut counts = [0u32; TOKENS];
        if max <= limit {
            counts[..n].copy_from_slice(histogram);
        } else {
            for (c, &h) in counts.iter_mut().zip(histogram) {
                if h != 0 {
                    *c = ((h as u64 * limit as u64).div_ceil(max as u64)) as u32;
                }
            }
        }
        let mut freqs = counts;
        if normalise(&mut freqs[..n]).is_err() {
            continue;
        }
        let table_bits = 8.0 * counts[..n].iter().map(|&c| varint_len(c)).sum::<usize>() as f64;
        let code_bits: f64 = histogram
            .iter()
            .zip(&freqs)
            .filter(|(c, _)| **c > 0)
            .map(|(&c, &f)| c as f64 * TOKEN_BITS[f as usize])
            .sum();
        let cost = table_bits + code_bits;
        if !found || cost < best.cost {
            found = true;
            best = StaticTable {
                cost,
                tokens: n,
                counts,
                freqs,
            };
        }
        if max <= limit {
            break;
        }
    }
    best
}

/// Estimated bits of one rANS chunk coding `values` values whose tokens
/// fall into `histograms` (one per context), beside their raw bits: its
/// directory entry, every context's static table, the tokens under those
/// tables (at the scale [`encode_chunk_with`] chooses) and the lanes'
/// lengths and final states. What [`crate::writer`] weighs when it decides
/// where to cut a substream into chunks. Adaptive tables (3.9) are left
/// out: pricing them needs the values in order, not their counts, and
/// they only make a chunk smaller.
pub fn chunk_cost_bits(histograms: &[[u32; TOKENS]], values: usize, lanes: usize) -> f64 {
    // Directory entry, then per lane a length varint (about 2 bytes) and
    // its 4-byte state.
    let fixed_bytes = CHUNK_ENTRY_LEN + 6 * lanes.min(values.max(1));
    let tables: f64 = histograms.iter().map(|h| 8.0 + scaled_counts(h).cost).sum();
    8.0 * fixed_bytes as f64 + tables
}

/// log2 without std: exact enough for choosing a table scale.
const fn libm_log2(x: f64) -> f64 {
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

/// How a chunk codes one context's tokens (SPEC §5.5.2).
#[allow(
    clippy::large_enum_variant,
    reason = "at most 8 per chunk, built once per chunk"
)]
#[derive(Clone, Debug)]
enum Model {
    /// A static table: each token's cumulative start and frequency.
    Static {
        start: [u32; TOKENS],
        freq: [u32; TOKENS],
    },
    /// An adaptive table (3.9) of `tokens` tokens and rate `rate`.
    Adaptive { tokens: usize, rate: u8 },
}

/// Bits an adaptive table must save per value of its context over the
/// best static table: an adaptive decision costs a decoder about ten more
/// instructions than a static table's lookup. Measured on armadillo, 0.005
/// keeps 375 of the 394 bytes that every adaptive table smaller than its
/// static one saves, on 71 % of the values instead of 94 % (decoding 7.6 %
/// more instructions than static tables instead of 9.7 %, measured with the
/// decisions inlined); on the 1M
/// terrain, 2,061 of 2,492 bytes on 18 % of the values instead of 42 %
/// (encoder/BENCHMARKS.md, "Adaptive tables").
const ADAPTIVE_MIN_GAIN: f64 = 0.005;

/// The rate an encoder tries first for an adaptive table: after its first
/// values a probability follows about the last 2^rate answers. Measured on
/// the scanned meshes, 7 suits most contexts, 5 or 6 some, 8 a few
/// (encoder/BENCHMARKS.md).
const FIRST_RATE: u8 = 7;

/// The rates tried, from [`FIRST_RATE`] one step at a time towards the
/// cheaper side while the cost falls (about three trials a context instead
/// of one per rate: each is a pass over the context's values).
fn best_rate(mut cost: impl FnMut(u8) -> f64) -> (f64, u8) {
    let rates = ADAPTIVE_RATE_MIN..=ADAPTIVE_RATE_MIN + 7;
    let mut best = (cost(FIRST_RATE), FIRST_RATE);
    let slower = (cost(FIRST_RATE + 1), FIRST_RATE + 1);
    let step: i8 = if slower.0 < best.0 {
        best = slower;
        1
    } else {
        -1
    };
    loop {
        let next = best.1.wrapping_add_signed(step);
        if !rates.contains(&next) {
            return best;
        }
        let tried = (cost(next), next);
        if tried.0 >= best.0 {
            return best;
        }
        best = tried;
    }
}

/// Bits of a binary decision whose chosen side has frequency `f` out of
/// `PROB_SCALE`, for `f` in `0..=PROB_SCALE` (entry 0 unused).
const fn decision_bits() -> [f32; PROB_SCALE as usize + 1] {
    let mut table = [0f32; PROB_SCALE as usize + 1];
    let mut f = 1;
    while f <= PROB_SCALE as usize {
        table[f] = (PROB_BITS as f64 - libm_log2(f as f64)) as f32;
        f += 1;
    }
    table
}

/// One adaptive decision (SPEC §5.5.4, 3.9): the frequencies of "above"
/// and "not above" under probability `q`.
#[inline]
fn decision_frequencies(q: u16) -> (u32, u32) {
    let above = ((q as u32) >> (ADAPTIVE_BITS - PROB_BITS)).max(1);
    (above, PROB_SCALE - above)
}

/// Moves an adaptive probability used `count` times before towards the
/// answer `above` (SPEC §5.5.4, 3.9), and counts the use.
#[inline]
fn adapt(q: &mut u16, count: &mut u8, above: bool, rate: u8) {
    let shift = adaptive_shift(*count, rate);
    *count = count.saturating_add(1);
    if above {
        *q += (((1u32 << ADAPTIVE_BITS) - *q as u32) >> shift) as u16;
    } else {
        *q -= *q >> shift;
    }
}

/// The table byte of an adaptive table of `tokens` tokens (at most
/// `ADAPTIVE_TOKENS`) and rate `rate` (SPEC §5.5.2, 3.9).
fn adaptive_byte(tokens: usize, rate: u8) -> u8 {
    ADAPTIVE_FLAG | (rate - ADAPTIVE_RATE_MIN) << 4 | (tokens - 1) as u8
}

/// For a probability `q` of an adaptive decision, indexed by `q >>
/// (ADAPTIVE_BITS − PROB_BITS)`: the bits of the answer "above" and of
/// "not above" ([`decision_bits`] of [`decision_frequencies`]).
static ANSWER_BITS: [[f32; 2]; PROB_SCALE as usize] = answer_bits();

const fn answer_bits() -> [[f32; 2]; PROB_SCALE as usize] {
    let bits = decision_bits();
    let mut table = [[0f32; 2]; PROB_SCALE as usize];
    let mut i = 0;
    while i < PROB_SCALE as usize {
        let above = if i == 0 { 1 } else { i };
        table[i] = [bits[above], bits[PROB_SCALE as usize - above]];
        i += 1;
    }
    table
}

/// For each rate less `ADAPTIVE_RATE_MIN`, the shift of a probability used
/// `count` times before, by `count`: [`adaptive_shift`]'s `min(rate, 1 +
/// bit length of count)` (`tests::the_shift_table_is_adaptive_shift`).
static SHIFTS: [[u8; 256]; 8] = shifts();

const fn shifts() -> [[u8; 256]; 8] {
    let mut table = [[0u8; 256]; 8];
    let mut r = 0;
    while r < 8 {
        let mut count = 0;
        while count < 256 {
            table[r][count] = adaptive_shift(count as u8, ADAPTIVE_RATE_MIN + r as u8) as u8;
            count += 1;
        }
        r += 1;
    }
    table
}

/// Bits the tokens `lanes_tokens` (each lane's tokens of one context, in
/// order) cost under an adaptive table of `tokens` tokens and `rate`;
/// `per_lane(lane, bits)` takes each lane's share. Token `t` answers "above"
/// to the decisions before `t` and "not above" to decision `t`, if there is
/// one (the decisions of [`lane_steps`], by tables).
fn adaptive_bits(
    lanes_tokens: &[Vec<u8>],
    tokens: usize,
    rate: u8,
    mut per_lane: impl FnMut(usize, f64),
) -> f64 {
    const INDEX_SHIFT: u32 = ADAPTIVE_BITS - PROB_BITS;
    let shifts = &SHIFTS[(rate - ADAPTIVE_RATE_MIN) as usize];
    let decisions = tokens - 1;
    let mut bits = 0f64;
    let mut probs = [ADAPTIVE_START; ADAPTIVE_TOKENS];
    let mut counts = [0u8; ADAPTIVE_TOKENS];
    for (lane, lane_tokens) in lanes_tokens.iter().enumerate() {
        probs.fill(ADAPTIVE_START);
        counts.fill(0);
        let mut lane_bits = 0f32;
        for &t in lane_tokens {
            let t = t as usize;
            let aboves = t.min(decisions);
            for (q, count) in probs[..aboves].iter_mut().zip(&mut counts[..aboves]) {
                lane_bits += ANSWER_BITS[(*q >> INDEX_SHIFT) as usize][0];
                let shift = shifts[*count as usize];
                *count = count.saturating_add(1);
                *q += (((1u32 << ADAPTIVE_BITS) - *q as u32) >> shift) as u16;
            }
            if t < decisions {
                let (q, count) = (&mut probs[t], &mut counts[t]);
                lane_bits += ANSWER_BITS[(*q >> INDEX_SHIFT) as usize][1];
                let shift = shifts[*count as usize];
                *count = count.saturating_add(1);
                *q -= *q >> shift;
            }
        }
        per_lane(lane, lane_bits as f64);
        bits += lane_bits as f64;
    }
    bits
}

/// A chunk's tables as [`estimated_chunk_len`] chose them, kept so that
/// coding the same values ([`encode_chunk_with`]) need not choose them
/// again: an encoder costs the alternative it writes before it frames it.
#[derive(Clone, Debug)]
pub(crate) struct ChunkTables {
    /// Whether `models` were chosen with adaptive tables allowed.
    adaptive_tables: bool,
    /// The table bytes that announce `models` (SPEC §5.5.2).
    bytes: Vec<u8>,
    models: Vec<Model>,
    /// Every context's best static table: what adaptive tables are weighed
    /// against where coding allows them and costing did not.
    priced: Vec<StaticTable>,
}

/// The model of each context for `symbols` coded in `lanes` lanes, and the
/// table bytes that announce them: an adaptive table where it is estimated
/// smaller than the best static one (at most `ADAPTIVE_TOKENS` tokens,
/// every lane's probabilities within `ADAPTIVE_STATES`), a static table
/// otherwise. With `lane_bits`, also the bits each lane is estimated to
/// take under them ([`estimated_chunk_len`]): its tokens under the chosen
/// models and its values' raw bits. `priced`: the contexts' static tables
/// when they are known already (the same values costed before).
fn choose_models(
    symbols: &[Symbol],
    contexts: usize,
    lanes: usize,
    adaptive_tables: bool,
    priced: Option<&[StaticTable]>,
    mut lane_bits: Option<&mut Vec<f64>>,
) -> ChunkTables {
    let mut out = Vec::new();
    let mut histograms = vec![[0u32; TOKENS]; contexts];
    // Per lane and context (`lane * contexts + context`), when estimating.
    let mut lane_histograms = Vec::new();
    if let Some(bits) = lane_bits.as_deref_mut() {
        let used = lanes.min(symbols.len());
        bits.clear();
        bits.resize(used, 0.0);
        lane_histograms = vec![[0u32; TOKENS]; used * contexts];
        let mut lane = 0;
        for &(ctx, value) in symbols {
            let (token, extra, _) = token_of(value);
            lane_histograms[lane * contexts + ctx as usize][token as usize] += 1;
            bits[lane] += extra as f64;
            lane = if lane + 1 == lanes { 0 } else { lane + 1 };
        }
        for (i, h) in lane_histograms.iter().enumerate() {
            for (all, &n) in histograms[i % contexts].iter_mut().zip(h) {
                *all += n;
            }
        }
    } else if priced.is_none() {
        for &(ctx, value) in symbols {
            histograms[ctx as usize][token_of(value).0 as usize] += 1;
        }
    }
    let priced: Vec<StaticTable> = match priced {
        Some(priced) if lane_bits.is_none() => priced.to_vec(),
        _ => histograms.iter().map(|h| scaled_counts(h)).collect(),
    };
    let may_adapt = |tokens: usize| {
        adaptive_tables
            && tokens > 1
            && tokens <= ADAPTIVE_TOKENS
            && (tokens - 1) * lanes <= ADAPTIVE_STATES
    };
    // Each such context's tokens, lane by lane, gathered in one pass.
    let mut lanes_tokens: Vec<Vec<Vec<u8>>> = priced
        .iter()
        .map(|table| {
            if may_adapt(table.tokens) {
                vec![Vec::new(); lanes]
            } else {
                Vec::new()
            }
        })
        .collect();
    // (Skipped where no context may adapt: ranking costs static tables
    // only. The lane is counted, not divided for.)
    if lanes_tokens.iter().any(|l| !l.is_empty()) {
        let mut lane = 0;
        for &(ctx, value) in symbols {
            if let Some(tokens) = lanes_tokens[ctx as usize].get_mut(lane) {
                tokens.push(token_of(value).0 as u8);
            }
            lane = if lane + 1 == lanes { 0 } else { lane + 1 };
        }
    }
    let mut models = Vec::with_capacity(contexts);
    for (ctx, (table, lanes_tokens)) in priced.iter().zip(&lanes_tokens).enumerate() {
        let tokens = table.tokens;
        if may_adapt(tokens) {
            // Each rate's bits per lane, kept as the rates are tried.
            let mut tried = [[0f64; MAX_LANES as usize]; 8];
            let (bits, rate) = best_rate(|rate| {
                let row = &mut tried[(rate - ADAPTIVE_RATE_MIN) as usize];
                adaptive_bits(lanes_tokens, tokens, rate, |lane, bits| {
                    // (At most `MAX_LANES` lanes: the header's limit.)
                    if let Some(slot) = row.get_mut(lane) {
                        *slot = bits;
                    }
                })
            });
            let values: usize = lanes_tokens.iter().map(Vec::len).sum();
            if bits + ADAPTIVE_MIN_GAIN * values as f64 <= table.cost {
                out.push(adaptive_byte(tokens, rate));
                models.push(Model::Adaptive { tokens, rate });
                if let Some(lane_bits) = lane_bits.as_deref_mut() {
                    // (Lanes past the values have no bits to add.)
                    let row = &tried[(rate - ADAPTIVE_RATE_MIN) as usize];
                    for (sum, bits) in lane_bits.iter_mut().zip(row) {
                        *sum += bits;
                    }
                }
                continue;
            }
        }
        out.push(tokens as u8);
        for &count in &table.counts[..tokens] {
            push_varint(&mut out, count);
        }
        let (mut start, mut freq) = ([0u32; TOKENS], [0u32; TOKENS]);
        if tokens > 0 {
            let mut cum = 0;
            for (t, &ft) in table.freqs[..tokens].iter().enumerate() {
                start[t] = cum;
                freq[t] = ft;
                cum += ft;
            }
        }
        if let Some(lane_bits) = lane_bits.as_deref_mut() {
            // Each token's bits under the table, then each lane's tokens.
            let token_bits = freq.map(|f| TOKEN_BITS[f as usize]);
            for (lane, bits) in lane_bits.iter_mut().enumerate() {
                let counts = &lane_histograms[lane * contexts + ctx];
                *bits += counts
                    .iter()
                    .zip(&token_bits)
                    .map(|(&n, &b)| n as f64 * b)
                    .sum::<f64>();
            }
        }
        models.push(Model::Static { start, freq });
    }
    ChunkTables {
        adaptive_tables,
        bytes: out,
        models,
        priced,
    }
}

/// One step of a lane as the decoder takes it: a symbol of `freq` slots
/// from `start`, or `count` raw bits.
#[derive(Clone, Copy)]
enum Step {
    Symbol { start: u32, freq: u32 },
    Raw { count: u32, bits: u32 },
}

/// The steps of one lane's values, in the decoder's order: each value's
/// token (one symbol, or an adaptive table's decisions), then its raw bits
/// low steps first.
fn lane_steps(symbols: &[Symbol], models: &[Model], lane: usize, lanes: usize) -> Vec<Step> {
    let values = symbols.iter().skip(lane).step_by(lanes);
    let mut steps = Vec::with_capacity(values.len() * 2);
    let mut probs: Vec<Vec<(u16, u8)>> = models
        .iter()
        .map(|m| match m {
            Model::Adaptive { tokens, .. } => vec![(ADAPTIVE_START, 0); tokens - 1],
            Model::Static { .. } => Vec::new(),
        })
        .collect();
    debug_assert!(lane < lanes);
    for &(ctx, value) in values {
        let (token, extra, low) = token_of(value);
        match &models[ctx as usize] {
            Model::Static { start, freq } => {
                let (start, freq) = (start[token as usize], freq[token as usize]);
                debug_assert!(freq > 0);
                steps.push(Step::Symbol { start, freq });
            }
            Model::Adaptive { rate, .. } => {
                for (i, (q, count)) in probs[ctx as usize].iter_mut().enumerate() {
                    let (above, below) = decision_frequencies(*q);
                    let is_above = token as usize > i;
                    steps.push(if is_above {
                        Step::Symbol {
                            start: below,
                            freq: above,
                        }
                    } else {
                        Step::Symbol {
                            start: 0,
                            freq: below,
                        }
                    });
                    adapt(q, count, is_above, *rate);
                    if !is_above {
                        break;
                    }
                }
            }
        }
        let mut done = 0;
        while done < extra {
            let count = (extra - done).min(RAW_BITS_STEP);
            steps.push(Step::Raw {
                count,
                bits: (low >> done) & ((1 << count) - 1),
            });
            done += count;
        }
    }
    steps
}

/// Bits of the numerators [`DIVISORS`] divides exactly: a coder state
/// about to take a symbol step stays below `((STATE_LOW >> PROB_BITS) << 8)
/// × freq` ≤ 2^31 (SPEC §5.5.4, taken backwards).
const DIVIDEND_BITS: u32 = 31;

/// For each frequency `f` in `1..=PROB_SCALE`, a multiplier `m` and shift
/// `s` with `x / f == (x × m) >> s` for every `x < 2^DIVIDEND_BITS`
/// (entry 0 unused). Coding a symbol divides the state by its frequency;
/// a division takes a CPU several times the cycles of a multiplication, and
/// every step of a lane depends on the one before.
///
/// With `l = ceil(log2 f)`, `s = DIVIDEND_BITS + l` and `m = ceil(2^s / f)`:
/// `2^s ≤ m·f < 2^s + f ≤ 2^s + 2^l`, which makes the quotient exact for
/// dividends below `2^DIVIDEND_BITS` (T. Granlund and P. L. Montgomery,
/// "Division by invariant integers using multiplication", 1994, theorem
/// 4.2); `m ≤ 2^32`, so `x × m` fits 64 bits.
static DIVISORS: [(u64, u32); PROB_SCALE as usize + 1] = divisors();

const fn divisors() -> [(u64, u32); PROB_SCALE as usize + 1] {
    let mut table = [(0u64, 0u32); PROB_SCALE as usize + 1];
    let mut f = 1u64;
    while f <= PROB_SCALE as u64 {
        let l = 64 - (f - 1).leading_zeros();
        let s = DIVIDEND_BITS + l;
        table[f as usize] = ((1u64 << s).div_ceil(f), s);
        f += 1;
    }
    table
}

/// `x / freq` and `x % freq` for a coder state `x < 2^DIVIDEND_BITS` and a
/// frequency in `1..=PROB_SCALE`, by [`DIVISORS`].
#[inline(always)]
fn div_rem(x: u32, freq: u32) -> (u32, u32) {
    debug_assert!(x < 1 << DIVIDEND_BITS && (1..=PROB_SCALE).contains(&freq));
    let (m, s) = DIVISORS[freq as usize];
    let q = ((x as u64 * m) >> s) as u32;
    (q, x - q * freq)
}

/// A lane's coder state `x` after one step taken backwards (rANS codes the
/// decoder's last step first); `put` takes each byte it shifts out.
#[inline(always)]
fn code_step(x: &mut u32, step: Step, mut put: impl FnMut(u8)) {
    match step {
        Step::Raw { count, bits } => {
            let x_max = (STATE_LOW >> count) << 8;
            while *x >= x_max {
                put(*x as u8);
                *x >>= 8;
            }
            *x = (*x << count) | bits;
        }
        Step::Symbol { start, freq } => {
            let x_max = ((STATE_LOW >> PROB_BITS) << 8) * freq;
            while *x >= x_max {
                put(*x as u8);
                *x >>= 8;
            }
            let (q, r) = div_rem(*x, freq);
            *x = (q << PROB_BITS) + r + start;
        }
    }
}

/// Codes one lane of a chunk under `models` (`adaptive`: one of them is)
/// backwards, the decoder's last step first: its values are every
/// `lanes`-th symbol from `lane`. `put` takes the bytes in the order they
/// are shifted out (the reverse of the lane's), and the final state, which
/// the lane starts with, is returned. Static tables let the steps be taken
/// backwards straight from the values; an adaptive table's decisions
/// depend on the values before, so they are listed forwards first.
fn code_lane(
    symbols: &[Symbol],
    models: &[Model],
    adaptive: bool,
    (lane, lanes): (usize, usize),
    mut put: impl FnMut(u8),
) -> u32 {
    let mut x = STATE_LOW;
    if adaptive {
        for step in lane_steps(symbols, models, lane, lanes).into_iter().rev() {
            code_step(&mut x, step, &mut put);
        }
        return x;
    }
    let last = lane + (symbols.len() - 1 - lane) / lanes * lanes;
    for i in (lane..=last).rev().step_by(lanes) {
        let (ctx, value) = symbols[i];
        let (token, extra, low) = token_of(value);
        // The raw steps, high first, then the token.
        let mut done = extra.div_ceil(RAW_BITS_STEP) * RAW_BITS_STEP;
        while done > 0 {
            done -= RAW_BITS_STEP;
            let count = (extra - done).min(RAW_BITS_STEP);
            let bits = (low >> done) & ((1 << count) - 1);
            code_step(&mut x, Step::Raw { count, bits }, &mut put);
        }
        let Model::Static { start, freq } = &models[ctx as usize] else {
            unreachable!("only static tables here");
        };
        let (start, freq) = (start[token as usize], freq[token as usize]);
        code_step(&mut x, Step::Symbol { start, freq }, &mut put);
    }
    x
}

/// About the length of the payload [`encode_chunk_with`] writes for the
/// same arguments, without coding the lanes: its tables exactly, and each
/// lane's bytes from the bits its values take under them. A lane shifts out
/// all of its bits but the 23 to 31 its final state keeps, so it takes
/// within a byte of its bits over eight, plus its 4-byte state and its
/// length. What an encoder ranking alternatives needs: coding the lanes to
/// count their bytes took most of the time of ranking them. Also the
/// tables it chose: [`encode_chunk_with`] codes the same values under them
/// without choosing again.
pub(crate) fn estimated_chunk_len(
    symbols: &[Symbol],
    contexts: usize,
    lanes: usize,
    adaptive_tables: bool,
) -> (usize, ChunkTables) {
    let mut lane_bits = Vec::new();
    let tables = choose_models(
        symbols,
        contexts,
        lanes,
        adaptive_tables,
        None,
        Some(&mut lane_bits),
    );
    // round(bits / 8 − 1/2) bytes shifted out, which is the floor (`as`
    // truncates, and takes a negative estimate to 0).
    let lanes_len: usize = lane_bits
        .iter()
        .map(|&bits| {
            let len = (bits / 8.0) as usize + 4;
            varint_len(len as u32) + len
        })
        .sum();
    // Lanes with no value: a 0 length each.
    let len = tables.bytes.len() + lanes_len + (lanes - lane_bits.len());
    (len, tables)
}

/// [`encode_chunk_with`] allowing adaptive tables, the payload alone (the
/// tests' shorthand).
#[cfg(test)]
pub fn encode_chunk(symbols: &[Symbol], contexts: usize, lanes: usize) -> Vec<u8> {
    encode_chunk_with(symbols, contexts, lanes, true, None).0
}

/// Encodes `symbols` as one rANS chunk payload with `contexts` tables and
/// `lanes` lanes (SPEC §5.5.2, §5.5.3), with an adaptive table (3.9) for a
/// context where `adaptive_tables` allows it and it is smaller; and
/// whether the chunk has one. `chosen`: the tables [`estimated_chunk_len`]
/// chose for the same values, coded under as they are where adaptive tables
/// were allowed alike, or else weighed from their static tables, which do
/// not depend on it; the same payload either way.
pub(crate) fn encode_chunk_with(
    symbols: &[Symbol],
    contexts: usize,
    lanes: usize,
    adaptive_tables: bool,
    chosen: Option<&ChunkTables>,
) -> (Vec<u8>, bool) {
    let fresh;
    let tables = match chosen {
        Some(chosen) if chosen.adaptive_tables == adaptive_tables => chosen,
        _ => {
            let priced = chosen.map(|c| &c.priced[..]);
            fresh = choose_models(symbols, contexts, lanes, adaptive_tables, priced, None);
            &fresh
        }
    };
    let (mut out, models) = (tables.bytes.clone(), &tables.models[..]);
    let adaptive = models.iter().any(|m| matches!(m, Model::Adaptive { .. }));
    let mut lane_bytes: Vec<Vec<u8>> = Vec::with_capacity(lanes);
    for lane in 0..lanes {
        if lane >= symbols.len() {
            lane_bytes.push(Vec::new());
            continue;
        }
        let mut bytes = Vec::new(); // reversed
        let x = code_lane(symbols, models, adaptive, (lane, lanes), |b| bytes.push(b));
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
    (out, adaptive)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The multiplications divide exactly: for every frequency, at the
    /// multiples and their neighbours near 0 and near the largest state,
    /// and at pseudo-random states.
    #[test]
    fn the_reciprocals_divide_exactly() {
        let top = (1u64 << DIVIDEND_BITS) - 1;
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        for f in 1..=PROB_SCALE as u64 {
            let last = top / f * f;
            let mut xs = vec![0, 1, f - 1, f, f + 1, 2 * f - 1, 2 * f, top, top - 1];
            xs.extend([last - 1, last, last + 1, last - f, last - f - 1]);
            for _ in 0..64 {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                xs.push((seed >> 33) & top);
            }
            for x in xs.into_iter().filter(|&x| x <= top) {
                let (x, f) = (x as u32, f as u32);
                assert_eq!(div_rem(x, f), (x / f, x % f), "{x} / {f}");
            }
        }
    }

    #[test]
    fn the_shift_table_is_adaptive_shift() {
        for (r, row) in SHIFTS.iter().enumerate() {
            for (count, &shift) in row.iter().enumerate() {
                let rate = ADAPTIVE_RATE_MIN + r as u8;
                assert_eq!(shift as u32, adaptive_shift(count as u8, rate));
            }
        }
    }

    proptest! {
        /// The length estimated without coding the lanes is within a byte
        /// a lane of the written payload's, with static and adaptive
        /// tables, any lane count, values of every size (raw bits included)
        /// and contexts left empty; exact when no lane is coded.
        #[test]
        fn the_estimated_length_is_near_the_written_one(
            values in proptest::collection::vec((0u8..6, any::<u32>(), 0u8..5), 0..700),
            lanes in 1usize..=32,
            contexts in 1usize..=8,
            adaptive in any::<bool>(),
        ) {
            let symbols: Vec<Symbol> = values
                .iter()
                .map(|&(ctx, v, size)| {
                    let v = match size { 0 => v % 2, 1 => v % 4, 2 => v % 40, 3 => v % 70_000, _ => v };
                    (ctx % contexts as u8, v)
                })
                .collect();
            let (payload, _) = encode_chunk_with(&symbols, contexts, lanes, adaptive, None);
            let (estimated, _) = estimated_chunk_len(&symbols, contexts, lanes, adaptive);
            let used = lanes.min(symbols.len());
            prop_assert!(
                estimated.abs_diff(payload.len()) <= used,
                "estimated {} bytes, written {}, {} lanes coded", estimated, payload.len(), used
            );
        }
    }
}
