//! The rANS codec of a chunk (SPEC §5.5): context-modelled, lane-interleaved
//! range asymmetric numeral systems, integer-only.
//!
//! A chunk holds one frequency table per context of its substream, then
//! `lane_count` independent byte streams ("lanes"). Value `i` of the chunk is
//! coded in lane `i mod lane_count`: a token of the hybrid integer code
//! (§5.5.1) drawn from its context's table, then the token's raw bits. Lanes
//! share nothing, so a decoder may run them on several cores or, as here,
//! keep them in one loop where their loads overlap.

use crate::Error;
use crate::bytes::u32_at;
use crate::limits::rans::{
    DIRECT_TOKENS, PROB_BITS, PROB_SCALE, RAW_BITS_STEP, STATE_LOW, TABLE_WORDS, TOKENS,
};

/// Words per context in the table area: token count, then `TOKENS + 1`
/// cumulative frequencies.
const CONTEXT_WORDS: usize = TOKENS + 2;

/// Words of one lane in the lane area: state, cursor, end (level offsets).
pub const LANE_WORDS: usize = 3;

/// Raw bits that follow `token`, and the value they complete (§5.5.1).
#[inline]
pub fn token_bits(token: u32) -> u32 {
    if token < DIRECT_TOKENS { 0 } else { token - 12 }
}

/// The token of `value` and its raw bits (§5.5.1): the encoder's inverse.
#[inline]
pub fn token_of(value: u32) -> (u32, u32, u32) {
    if value < DIRECT_TOKENS {
        (value, 0, 0)
    } else {
        let exponent = 31 - value.leading_zeros();
        (12 + exponent, exponent, value & ((1 << exponent) - 1))
    }
}

/// Reads an unsigned LEB128 varint of a table or lane directory (§5.4 rules).
fn varint(bytes: &[u8], at: &mut usize, end: usize) -> Result<u32, Error> {
    let bad = Error::InvalidRansChunk("bad varint in tables");
    let mut value = 0u32;
    for i in 0..5 {
        if *at >= end {
            return Err(Error::InvalidRansChunk("tables run past the chunk"));
        }
        let b = bytes[*at];
        *at += 1;
        if i == 4 && b > 0x0F {
            return Err(bad);
        }
        value |= ((b & 0x7F) as u32) << (7 * i);
        if b & 0x80 == 0 {
            if b == 0 && i > 0 {
                return Err(bad);
            }
            return Ok(value);
        }
    }
    Err(bad)
}

/// Parses the tables of `contexts` contexts at `bytes[*at..end]` into
/// `table` (§5.5.2): per context a token count `n` (0: unused), then `n`
/// counts, normalised here to frequencies summing to `PROB_SCALE`.
pub fn read_tables(
    bytes: &[u8],
    at: &mut usize,
    end: usize,
    contexts: usize,
    table: &mut [u32],
) -> Result<(), Error> {
    for c in 0..contexts {
        let t = &mut table[c * CONTEXT_WORDS..(c + 1) * CONTEXT_WORDS];
        if *at >= end {
            return Err(Error::InvalidRansChunk("tables run past the chunk"));
        }
        let n = bytes[*at] as usize;
        *at += 1;
        if n > TOKENS {
            return Err(Error::InvalidRansChunk("more tokens than the code has"));
        }
        t[0] = n as u32;
        if n == 0 {
            continue;
        }
        // Counts into t[1..=n]; then frequencies; then cumulative in t[1..=n+1].
        for i in 0..n {
            t[1 + i] = varint(bytes, at, end)?;
        }
        if t[n] == 0 {
            return Err(Error::InvalidRansChunk("last token count is zero"));
        }
        normalise(&mut t[1..=n])?;
        let mut cum = 0u32;
        for i in 0..n {
            let f = t[1 + i];
            t[1 + i] = cum;
            cum += f;
        }
        t[1 + n] = cum;
        // Entries past cum[n] read as "above every slot" (decode_value).
        t[2 + n..].fill(PROB_SCALE);
    }
    Ok(())
}

/// Turns counts into frequencies summing to `PROB_SCALE`, in place
/// (§5.5.2): each nonzero count gets `max(1, count × PROB_SCALE / total)`,
/// then the largest frequency (the first of equals) absorbs the difference.
pub fn normalise(counts: &mut [u32]) -> Result<(), Error> {
    let total: u64 = counts.iter().map(|&c| c as u64).sum();
    if total == 0 {
        return Err(Error::InvalidRansChunk("counts cannot be normalised"));
    }
    let mut sum = 0u32;
    let mut largest = 0;
    for i in 0..counts.len() {
        let count = counts[i] as u64;
        let f = if count == 0 {
            0
        } else {
            ((count * PROB_SCALE as u64) / total).max(1) as u32
        };
        counts[i] = f;
        sum += f;
        if f > counts[largest] {
            largest = i;
        }
    }
    let fixed = counts[largest] as i64 + PROB_SCALE as i64 - sum as i64;
    if fixed < 1 {
        return Err(Error::InvalidRansChunk("counts cannot be normalised"));
    }
    counts[largest] = fixed as u32;
    Ok(())
}

/// Reads the lane directory and each lane's initial state (§5.5.3); fills
/// `lanes` with (state, cursor, end) per lane.
pub fn open_lanes(
    bytes: &[u8],
    mut at: usize,
    end: usize,
    values: u32,
    lanes: &mut [u32],
) -> Result<(), Error> {
    for lane in lanes.chunks_exact_mut(LANE_WORDS) {
        lane[2] = varint(bytes, &mut at, end)?;
    }
    for (i, lane) in lanes.chunks_exact_mut(LANE_WORDS).enumerate() {
        let len = lane[2] as usize;
        let has_values = (i as u32) < values;
        let lane_end = at
            .checked_add(len)
            .filter(|&e| e <= end)
            .ok_or(Error::InvalidRansChunk("lanes run past the chunk"))?;
        if !has_values {
            if len != 0 {
                return Err(Error::InvalidRansChunk("bytes in a lane without values"));
            }
            lane.copy_from_slice(&[STATE_LOW, at as u32, at as u32]);
            continue;
        }
        if len < 4 {
            return Err(Error::InvalidRansChunk("lane shorter than its state"));
        }
        let state = u32_at(bytes, at)?;
        if !(STATE_LOW..STATE_LOW << 8).contains(&state) {
            return Err(Error::InvalidRansChunk("lane state out of range"));
        }
        lane.copy_from_slice(&[state, (at + 4) as u32, lane_end as u32]);
        at = lane_end;
    }
    if at != end {
        return Err(Error::InvalidRansChunk("bytes after the last lane"));
    }
    Ok(())
}

/// Whether every lane ended exactly: state back at `STATE_LOW`, every byte read.
pub fn lanes_exhausted(lanes: &[u32]) -> bool {
    lanes
        .chunks_exact(LANE_WORDS)
        .all(|l| l[0] == STATE_LOW && l[1] == l[2])
}

/// Pulls bytes into `lane`'s state until it is normalised again.
#[inline]
fn renormalise(bytes: &[u8], lane: &mut [u32]) -> Result<(), Error> {
    while lane[0] < STATE_LOW {
        if lane[1] >= lane[2] {
            return Err(Error::InvalidRansChunk("lane ran out of bytes"));
        }
        lane[0] = (lane[0] << 8) | bytes[lane[1] as usize] as u32;
        lane[1] += 1;
    }
    Ok(())
}

/// Decodes one value in `context` from `lane` (§5.5.1, §5.5.4).
#[inline]
pub fn decode_value(
    bytes: &[u8],
    table: &[u32],
    context: usize,
    lane: &mut [u32],
) -> Result<u32, Error> {
    let t = &table[context * CONTEXT_WORDS..(context + 1) * CONTEXT_WORDS];
    if t[0] == 0 {
        return Err(Error::InvalidRansChunk(
            "value in a context without a table",
        ));
    }
    let x = lane[0];
    let slot = x & (PROB_SCALE - 1);
    // The token t with cum[t] <= slot < cum[t + 1] is the number of
    // cumulative frequencies cum[1..] at most slot (cum is non-decreasing,
    // and `read_tables` sets the entries past cum[n] to PROB_SCALE > slot).
    // Counting, rather than searching, has no branch to mispredict; the
    // count runs over n rounded up to 4 entries.
    let cum = &t[1..];
    let counted = ((t[0] as usize + 3) & !3).min(TOKENS);
    let mut token = 0u32;
    for quad in cum[1..=counted].chunks_exact(4) {
        token += quad.iter().map(|&c| (c <= slot) as u32).sum::<u32>();
    }
    let token = token as usize;
    let token = token.min(TOKENS - 1);
    let (start, freq) = (cum[token], cum[token + 1] - cum[token]);
    lane[0] = freq * (x >> PROB_BITS) + slot - start;
    renormalise(bytes, lane)?;
    let token = token as u32;
    let extra = token_bits(token);
    if extra == 0 {
        return Ok(token);
    }
    let mut low = 0u32;
    let mut done = 0;
    while done < extra {
        let step = (extra - done).min(RAW_BITS_STEP);
        low |= (lane[0] & ((1 << step) - 1)) << done;
        lane[0] >>= step;
        renormalise(bytes, lane)?;
        done += step;
    }
    Ok((1 << extra) | low)
}

const _: () = assert!(TABLE_WORDS == crate::limits::rans::MAX_CONTEXTS * CONTEXT_WORDS);

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use crate::limits::rans::{MAX_CONTEXTS, TABLE_WORDS};
    use crate::rans_writer::{Symbol, encode_chunk};
    use alloc::vec;
    use alloc::vec::Vec;
    use proptest::prelude::*;

    /// Decodes a chunk payload the way `Substreams` does.
    fn decode(
        payload: &[u8],
        contexts: &[u8],
        n_contexts: usize,
        lanes: usize,
    ) -> Result<Vec<u32>, Error> {
        let mut table = vec![0u32; TABLE_WORDS];
        let mut lane_words = vec![0u32; LANE_WORDS * lanes];
        let mut at = 0;
        read_tables(payload, &mut at, payload.len(), n_contexts, &mut table)?;
        open_lanes(
            payload,
            at,
            payload.len(),
            contexts.len() as u32,
            &mut lane_words,
        )?;
        let mut out = Vec::new();
        for (i, &ctx) in contexts.iter().enumerate() {
            let l = (i % lanes) * LANE_WORDS;
            out.push(decode_value(
                payload,
                &table,
                ctx as usize,
                &mut lane_words[l..l + LANE_WORDS],
            )?);
        }
        if !lanes_exhausted(&lane_words) {
            return Err(Error::InvalidRansChunk("a lane did not end exactly"));
        }
        Ok(out)
    }

    #[test]
    fn hybrid_code_edges() {
        for v in [
            0u32,
            1,
            15,
            16,
            17,
            31,
            32,
            1000,
            1 << 20,
            u32::MAX - 1,
            u32::MAX,
        ] {
            let (token, bits, low) = token_of(v);
            assert!((token as usize) < TOKENS);
            assert_eq!(token_bits(token), bits);
            let back = if bits == 0 { token } else { (1 << bits) | low };
            assert_eq!(back, v);
        }
    }

    #[test]
    fn normalise_sums_to_the_scale() {
        for counts in [
            vec![1u32],
            vec![0, 5],
            vec![1; 44],
            vec![u32::MAX, 1, 1, 0, 7],
        ] {
            let mut f = counts.clone();
            normalise(&mut f).unwrap();
            assert_eq!(f.iter().sum::<u32>(), PROB_SCALE);
            for (c, f) in counts.iter().zip(&f) {
                assert_eq!(*c == 0, *f == 0);
            }
        }
        assert!(normalise(&mut [0, 0]).is_err());
    }

    #[test]
    fn single_token_tables_cost_no_bytes() {
        let symbols: Vec<Symbol> = (0..100).map(|_| (0, 3)).collect();
        let payload = encode_chunk(&symbols, 1, 2);
        // Table: n = 4, counts 0 0 0 c; two lane lengths; two 4-byte states.
        assert!(payload.len() <= 1 + 4 + 2 + 2 + 8, "{}", payload.len());
        assert_eq!(decode(&payload, &[0; 100], 1, 2).unwrap(), vec![3; 100]);
    }

    proptest! {
        #[test]
        fn chunks_round_trip(
            values in proptest::collection::vec((0u8..8, any::<u32>(), 0u8..4), 1..400),
            lanes in 1usize..=32,
            n_contexts in 1usize..=MAX_CONTEXTS,
        ) {
            // Small values mostly, some of every size.
            let symbols: Vec<Symbol> = values
                .iter()
                .map(|&(ctx, v, size)| {
                    let v = match size { 0 => v % 4, 1 => v % 40, 2 => v % 70_000, _ => v };
                    (ctx % n_contexts as u8, v)
                })
                .collect();
            let payload = encode_chunk(&symbols, n_contexts, lanes);
            let contexts: Vec<u8> = symbols.iter().map(|s| s.0).collect();
            let decoded = decode(&payload, &contexts, n_contexts, lanes).unwrap();
            let expected: Vec<u32> = symbols.iter().map(|s| s.1).collect();
            prop_assert_eq!(decoded, expected);
        }

        #[test]
        fn corrupt_chunks_give_errors_not_panics(
            values in proptest::collection::vec((0u8..3, 0u32..100), 1..60),
            lanes in 1usize..=4,
            flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..4),
        ) {
            let symbols: Vec<Symbol> = values.clone();
            let mut payload = encode_chunk(&symbols, 3, lanes);
            for (at, x) in flips {
                let n = payload.len();
                payload[at % n] ^= x | 1;
            }
            let contexts: Vec<u8> = symbols.iter().map(|s| s.0).collect();
            let _ = decode(&payload, &contexts, 3, lanes);
        }
    }
}
