//! The rANS codec of a chunk (SPEC §5.5): context-modelled, lane-interleaved
//! range asymmetric numeral systems, integer-only.
//!
//! A chunk holds one table per context of its substream (a frequency table,
//! or from 3.9 an adaptive one whose probabilities follow the values), then
//! `lane_count` independent byte streams ("lanes"). Value `i` of the chunk is
//! coded in lane `i mod lane_count`: a token of the hybrid integer code
//! (§5.5.1) drawn from its context's table, then the token's raw bits. Lanes
//! share nothing (an adaptive table keeps a set of probabilities per lane),
//! so a decoder may run them on several cores or, as here, keep them in one
//! loop where their loads overlap.

use crate::Error;
use crate::bytes::u32_at;
use crate::limits::rans::{
    ADAPTIVE_BITS, ADAPTIVE_FLAG, ADAPTIVE_RATE_MIN, ADAPTIVE_START, ADAPTIVE_STATES,
    DIRECT_TOKENS, MAX_CONTEXTS, MAX_LANES, PROB_BITS, PROB_SCALE, RAW_BITS_STEP, STATE_LOW,
    TABLE_WORDS, TOKENS,
};

/// Cumulative frequencies kept per context: `cum[0..=n]` for at most
/// `TOKENS` tokens, then entries equal to `PROB_SCALE` (above every slot),
/// so that a scan for a slot's token always stops inside the table.
const CUM_LEN: usize = 48;
const _: () = assert!(CUM_LEN > TOKENS + 1);
// An adaptive table keeps its probabilities where a static one keeps its
// cumulative frequencies, and their decision counts in its bucket index.
const _: () = assert!(CUM_LEN >= ADAPTIVE_STATES && BUCKETS >= ADAPTIVE_STATES);

/// A slot's token is looked up in one of this many equal buckets of the
/// `PROB_SCALE` slots, then found by a short forward scan.
const BUCKET_BITS: u32 = 6;
const BUCKETS: usize = 1 << BUCKET_BITS;

/// `u32` words of one lane: state, cursor, end (offsets in the level).
pub const LANE_WORDS: usize = 3;

/// Most values one look-ahead decodes ([`ChunkDecoder::look_ahead`]): the
/// candidates of one batch of fans walked ahead.
pub const LOOKAHEAD: usize = 128;

// A context's cumulative frequencies (u16) and bucket index (u8) take no
// more room than the `TOKENS + 2` words per context that SPEC §9 gives a
// rANS slot.
const _: () = assert!(MAX_CONTEXTS * (2 * CUM_LEN + BUCKETS) <= 4 * TABLE_WORDS);
const _: () = assert!((2 * MAX_CONTEXTS * CUM_LEN).is_multiple_of(4));
const _: () = assert!(MAX_LANES.is_power_of_two());

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

/// Of the `contexts` tables that open a rANS chunk's `payload` (SPEC
/// §5.5.2), how many are adaptive (3.9) and how many are in use (adaptive,
/// or static with tokens): `(adaptive, in_use)`. For tools that describe a
/// stream (`splitstream info`); it reads the table bytes only.
pub fn table_kinds(payload: &[u8], contexts: usize) -> Result<(u32, u32), Error> {
    let (mut adaptive, mut in_use) = (0, 0);
    let mut at = 0;
    for _ in 0..contexts {
        let n = *payload
            .get(at)
            .ok_or(Error::InvalidRansChunk("tables run past the chunk"))? as usize;
        at += 1;
        if n & ADAPTIVE_FLAG as usize != 0 {
            adaptive += 1;
            in_use += 1;
            continue;
        }
        if n > TOKENS {
            return Err(Error::InvalidRansChunk("more tokens than the code has"));
        }
        in_use += (n > 0) as u32;
        for _ in 0..n {
            varint(payload, &mut at, payload.len())?;
        }
    }
    Ok((adaptive, in_use))
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

/// The decoding state of one rANS chunk (§5.5.2–§5.5.4), kept in a
/// substream slot's memory: per context its token count, cumulative
/// frequencies and a bucket index from slots to tokens, and per lane its
/// state, cursor and end. Lanes take values in turn (value `i` of the chunk
/// in lane `i mod lane_count`).
pub struct ChunkDecoder<'b> {
    /// Tokens of each context's table; 0 for an unused table.
    tokens: [u8; MAX_CONTEXTS],
    /// Each context's adaptation rate: 0 for a static table.
    rates: [u8; MAX_CONTEXTS],
    /// `CUM_LEN` cumulative frequencies per context, or for an adaptive
    /// table its probabilities, `m − 1` per lane, lane 0's first.
    cums: &'b mut [[u16; CUM_LEN]; MAX_CONTEXTS],
    /// Per context, the token of the first slot of each bucket, or for an
    /// adaptive table how often each probability has been used.
    buckets: &'b mut [[u8; BUCKETS]; MAX_CONTEXTS],
    /// State, cursor, end of each lane (room for the most lanes a stream
    /// may have, SPEC §9; the first `lane_count` are used).
    lanes: &'b mut [[u32; LANE_WORDS]; MAX_LANES as usize],
    lane_count: usize,
    /// Lane of the next value.
    lane: usize,
}

impl<'b> ChunkDecoder<'b> {
    /// A decoder of chunks with `lane_count` lanes over `words`, or `None`
    /// when they are fewer than the tables and lanes need (SPEC §9:
    /// `TABLE_WORDS + LANE_WORDS × lane_count`).
    pub fn new(words: &'b mut [u32], lane_count: usize) -> Option<ChunkDecoder<'b>> {
        if lane_count == 0
            || lane_count > MAX_LANES as usize
            || words.len() < TABLE_WORDS + LANE_WORDS * MAX_LANES as usize
        {
            return None;
        }
        let (table, lanes) = words.split_at_mut(TABLE_WORDS);
        let (cums, buckets) = table.split_at_mut(MAX_CONTEXTS * CUM_LEN / 2);
        let buckets = &mut buckets[..MAX_CONTEXTS * BUCKETS / 4];
        let cums: &mut [[u16; CUM_LEN]] = bytemuck::try_cast_slice_mut(cums).ok()?;
        let buckets: &mut [[u8; BUCKETS]] = bytemuck::try_cast_slice_mut(buckets).ok()?;
        let lanes: &mut [[u32; LANE_WORDS]] =
            bytemuck::try_cast_slice_mut(&mut lanes[..LANE_WORDS * MAX_LANES as usize]).ok()?;
        Some(ChunkDecoder {
            tokens: [0; MAX_CONTEXTS],
            rates: [0; MAX_CONTEXTS],
            cums: cums.try_into().ok()?,
            buckets: buckets.try_into().ok()?,
            lanes: lanes.try_into().ok()?,
            lane_count,
            lane: 0,
        })
    }

    /// Reads a chunk's tables for `contexts` contexts and its lane
    /// directory, from `bytes[at..end]`, for a chunk of `values` values
    /// (§5.5.2, §5.5.3).
    pub fn open(
        &mut self,
        bytes: &[u8],
        mut at: usize,
        end: usize,
        contexts: usize,
        values: u32,
    ) -> Result<(), Error> {
        self.read_tables(bytes, &mut at, end, contexts)?;
        self.open_lanes(bytes, at, end, values)
    }

    /// Parses the tables of `contexts` contexts at `bytes[*at..end]`
    /// (§5.5.2): per context a token count `n` (0: unused), then `n`
    /// counts, normalised here to frequencies summing to `PROB_SCALE`; or
    /// an adaptive table (3.9): `ADAPTIVE_FLAG | m` and a rate.
    fn read_tables(
        &mut self,
        bytes: &[u8],
        at: &mut usize,
        end: usize,
        contexts: usize,
    ) -> Result<(), Error> {
        self.tokens = [0; MAX_CONTEXTS];
        self.rates = [0; MAX_CONTEXTS];
        for c in 0..contexts.min(MAX_CONTEXTS) {
            if *at >= end {
                return Err(Error::InvalidRansChunk("tables run past the chunk"));
            }
            let n = bytes[*at] as usize;
            *at += 1;
            if n & ADAPTIVE_FLAG as usize != 0 {
                self.open_adaptive(c, n as u8)?;
                continue;
            }
            if n > TOKENS {
                return Err(Error::InvalidRansChunk("more tokens than the code has"));
            }
            if n == 0 {
                continue;
            }
            let mut counts = [0u32; TOKENS];
            for count in &mut counts[..n] {
                *count = varint(bytes, at, end)?;
            }
            if counts[n - 1] == 0 {
                return Err(Error::InvalidRansChunk("last token count is zero"));
            }
            normalise(&mut counts[..n])?;
            let cum = &mut self.cums[c];
            let bucket = &mut self.buckets[c];
            let mut sum = 0u32;
            for (t, &f) in counts[..n].iter().enumerate() {
                cum[t] = sum as u16;
                // Buckets whose first slot falls in this token's range.
                let first = (sum as usize).div_ceil(1 << BUCKET_BITS);
                sum += f;
                let last = (sum as usize).div_ceil(1 << BUCKET_BITS);
                bucket[first..last].fill(t as u8);
            }
            // Past cum[n] every entry reads as "above every slot".
            cum[n..].fill(PROB_SCALE as u16);
            self.tokens[c] = n as u8;
        }
        Ok(())
    }

    /// An adaptive table for context `c` from its table byte (§5.5.2,
    /// 3.9): `m` tokens and a rate, every lane's `m − 1` probabilities one
    /// half and never used.
    fn open_adaptive(&mut self, c: usize, byte: u8) -> Result<(), Error> {
        let m = (byte & 0x0F) as usize + 1;
        let rate = ADAPTIVE_RATE_MIN + ((byte >> 4) & 0x07);
        let states = (m - 1) * self.lane_count;
        if states > ADAPTIVE_STATES {
            return Err(Error::InvalidRansChunk(
                "adaptive table needs more probabilities than a table holds",
            ));
        }
        self.cums[c][..states].fill(ADAPTIVE_START);
        self.buckets[c][..states].fill(0);
        self.tokens[c] = m as u8;
        self.rates[c] = rate;
        Ok(())
    }

    /// Reads the lane directory and each lane's initial state (§5.5.3).
    fn open_lanes(
        &mut self,
        bytes: &[u8],
        mut at: usize,
        end: usize,
        values: u32,
    ) -> Result<(), Error> {
        let lanes = &mut self.lanes[..self.lane_count];
        for lane in lanes.iter_mut() {
            lane[2] = varint(bytes, &mut at, end)?;
        }
        for (i, lane) in lanes.iter_mut().enumerate() {
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
                *lane = [STATE_LOW, at as u32, at as u32];
                continue;
            }
            if len < 4 {
                return Err(Error::InvalidRansChunk("lane shorter than its state"));
            }
            let state = u32_at(bytes, at)?;
            if !(STATE_LOW..STATE_LOW << 8).contains(&state) {
                return Err(Error::InvalidRansChunk("lane state out of range"));
            }
            *lane = [state, (at + 4) as u32, lane_end as u32];
            at = lane_end;
        }
        if at != end {
            return Err(Error::InvalidRansChunk("bytes after the last lane"));
        }
        self.lane = 0;
        Ok(())
    }

    /// Whether every lane ended exactly: state back at `STATE_LOW`, every
    /// byte read.
    pub fn exhausted(&self) -> bool {
        self.lanes[..self.lane_count]
            .iter()
            .all(|l| l[0] == STATE_LOW && l[1] == l[2])
    }

    /// The tables, the lane of the next value and its number; moves on to
    /// the lane after it.
    #[inline(always)]
    fn next_lane(&mut self) -> (Tables<'_>, &mut [u32; LANE_WORDS], usize) {
        // lane < lane_count <= MAX_LANES, a power of two.
        let index = self.lane & (MAX_LANES as usize - 1);
        self.lane = if self.lane + 1 >= self.lane_count {
            0
        } else {
            self.lane + 1
        };
        let tables = Tables {
            tokens: &self.tokens,
            rates: &self.rates,
            cums: self.cums,
            buckets: self.buckets,
        };
        (tables, &mut self.lanes[index], index)
    }

    /// Decodes the next value, in `context`, from the next lane
    /// (§5.5.1, §5.5.4); `bytes` are the level's.
    #[inline(always)]
    pub fn decode(&mut self, bytes: &[u8], context: usize) -> Result<u32, Error> {
        let (tables, lane, index) = self.next_lane();
        decode_in(tables, lane, index, bytes, context)
    }

    /// [`ChunkDecoder::decode`] for a value read as a bit (a flag, SPEC
    /// §7.3): the same value, lane and table updates and errors, with a
    /// shorter path for a context of one or two tokens (one comparison, no
    /// bucket search, no raw bits). Any other table takes the general
    /// path, whose value the caller then refuses.
    #[inline(always)]
    pub fn decode_bit(&mut self, bytes: &[u8], context: usize) -> Result<u32, Error> {
        let (tables, lane, index) = self.next_lane();
        decode_bit_in(tables, lane, index, bytes, context)
    }

    /// The next bits as [`ChunkDecoder::decode`] would give them in
    /// `contexts`, one context per value, without consuming anything: `(bits,
    /// count)`, bit i the i-th next value, `count` at most
    /// [`LOOKAHEAD`] and at most `remaining` (the values left in the
    /// chunk), and nothing from a value that is not a bit or fails
    /// ([`ChunkDecoder::look_ahead`] into a look-ahead of its own).
    #[cfg(test)]
    pub fn peek_bits(&self, bytes: &[u8], contexts: &[u8], remaining: usize) -> (u128, u32) {
        let mut ahead = Lookahead::default();
        self.look_ahead(bytes, contexts, remaining, &mut ahead)
    }

    /// Decodes the next bits in `contexts` (one per value) on a copy of
    /// this decoder's state kept in `ahead`, consuming nothing here:
    /// `(bits, count)` as [`ChunkDecoder::peek_bits`]. Reading them then
    /// through [`Lookahead::next`] and taking the copy with
    /// [`ChunkDecoder::adopt`] once all are read leaves this decoder as
    /// decoding them one by one would: each is decoded once.
    pub fn look_ahead(
        &self,
        bytes: &[u8],
        contexts: &[u8],
        remaining: usize,
        ahead: &mut Lookahead,
    ) -> (u128, u32) {
        let count = self.lane_count.min(MAX_LANES as usize);
        ahead.lanes[..count].copy_from_slice(&self.lanes[..count]);
        ahead.cums.copy_from_slice(&self.cums[..]);
        ahead.buckets.copy_from_slice(&self.buckets[..]);
        let mut tables = Tables {
            tokens: &self.tokens,
            rates: &self.rates,
            cums: &mut ahead.cums,
            buckets: &mut ahead.buckets,
        };
        let mut lane = self.lane;
        // By 64-bit halves: a variable 128-bit shift is a library call on
        // 32-bit targets.
        let (mut halves, mut known) = ([0u64; 2], 0u32);
        for &context in contexts.iter().take(remaining.min(LOOKAHEAD)) {
            // Only the tables of a bit (one or two tokens): their reads
            // change nothing but the lane when they fail, and give 0 or 1
            // when they do not. Any other value is left to the reader.
            if !(1..=2).contains(&self.tokens[context as usize & (MAX_CONTEXTS - 1)]) {
                break;
            }
            let index = lane & (MAX_LANES as usize - 1);
            let l = &mut ahead.lanes[index];
            let before = *l;
            let next = if lane + 1 >= self.lane_count {
                0
            } else {
                lane + 1
            };
            match decode_bit_in(tables.reborrow(), l, index, bytes, context as usize) {
                Ok(v) => halves[known as usize / 64] |= (v as u64) << (known % 64),
                Err(_) => {
                    // The state adopted is the one after the values before.
                    *l = before;
                    break;
                }
            }
            ahead.contexts[known as usize] = context;
            lane = next;
            known += 1;
        }
        ahead.lane = lane;
        ahead.halves = halves;
        ahead.known = known;
        ahead.served = 0;
        ((halves[1] as u128) << 64 | halves[0] as u128, known)
    }

    /// Takes the state `ahead` reached after all its values
    /// ([`ChunkDecoder::look_ahead`]): the lanes, the adaptive tables'
    /// probabilities (static tables never change) and the next lane.
    pub fn adopt(&mut self, ahead: &Lookahead) {
        let count = self.lane_count.min(MAX_LANES as usize);
        self.lanes[..count].copy_from_slice(&ahead.lanes[..count]);
        for c in 0..MAX_CONTEXTS {
            if self.rates[c] != 0 {
                self.cums[c].copy_from_slice(&ahead.cums[c]);
                self.buckets[c].copy_from_slice(&ahead.buckets[c]);
            }
        }
        self.lane = ahead.lane;
    }
}

/// Values decoded ahead of a reader ([`ChunkDecoder::look_ahead`]), and
/// the decoder state after them.
#[derive(Clone)]
pub struct Lookahead {
    lanes: [[u32; LANE_WORDS]; MAX_LANES as usize],
    cums: [[u16; CUM_LEN]; MAX_CONTEXTS],
    buckets: [[u8; BUCKETS]; MAX_CONTEXTS],
    /// Lane of the value after them.
    lane: usize,
    /// The context each was decoded in.
    contexts: [u8; LOOKAHEAD],
    halves: [u64; 2],
    known: u32,
    /// How many the reader has taken ([`Lookahead::next`]).
    served: u32,
}

impl Default for Lookahead {
    fn default() -> Self {
        Lookahead {
            lanes: [[0; LANE_WORDS]; MAX_LANES as usize],
            cums: [[0; CUM_LEN]; MAX_CONTEXTS],
            buckets: [[0; BUCKETS]; MAX_CONTEXTS],
            lane: 0,
            contexts: [0; LOOKAHEAD],
            halves: [0; 2],
            known: 0,
            served: 0,
        }
    }
}

impl Lookahead {
    /// The next value decoded ahead, when the reader asks for it in the
    /// context it was decoded in; `None` otherwise (the reader went
    /// another way: [`Lookahead::taken`] tells how far it followed).
    #[inline]
    pub fn next(&mut self, context: u8) -> Option<bool> {
        let i = self.served as usize;
        if i < self.known as usize && self.contexts[i] == context {
            self.served += 1;
            Some(self.halves[i / 64] >> (i % 64) & 1 != 0)
        } else {
            None
        }
    }

    /// Whether the reader has taken every value decoded ahead.
    #[inline]
    pub fn all_taken(&self) -> bool {
        self.served == self.known
    }

    /// The contexts of the values the reader has taken, in order.
    pub fn taken(&self) -> &[u8] {
        &self.contexts[..self.served as usize]
    }
}

/// A chunk's tables, as [`decode_in`] reads them (and adapts them).
struct Tables<'a> {
    tokens: &'a [u8; MAX_CONTEXTS],
    rates: &'a [u8; MAX_CONTEXTS],
    cums: &'a mut [[u16; CUM_LEN]; MAX_CONTEXTS],
    buckets: &'a mut [[u8; BUCKETS]; MAX_CONTEXTS],
}

impl Tables<'_> {
    fn reborrow(&mut self) -> Tables<'_> {
        Tables {
            tokens: self.tokens,
            rates: self.rates,
            cums: self.cums,
            buckets: self.buckets,
        }
    }
}

/// Decodes one value in `context` from `lane`, lane number `index`
/// (§5.5.1, §5.5.4).
#[inline(always)]
fn decode_in(
    tables: Tables<'_>,
    lane: &mut [u32; LANE_WORDS],
    index: usize,
    bytes: &[u8],
    context: usize,
) -> Result<u32, Error> {
    // Contexts are below MAX_CONTEXTS (a power of two) by construction.
    let context = context & (MAX_CONTEXTS - 1);
    let n = tables.tokens[context] as usize;
    if n == 0 {
        return Err(Error::InvalidRansChunk(
            "value in a context without a table",
        ));
    }
    let rate = tables.rates[context];
    let mut x = lane[0];
    // One tail for both kinds of table: the raw bits' loop is inlined
    // wherever a value is read, so it is kept to one copy per reader.
    let token = if rate != 0 {
        adaptive_token(
            Adaptive {
                probs: &mut tables.cums[context],
                counts: &mut tables.buckets[context],
                rate,
                tokens: n,
            },
            index,
            lane,
            bytes,
            &mut x,
        )?
    } else {
        static_token(
            &tables.cums[context],
            &tables.buckets[context],
            lane,
            bytes,
            &mut x,
        )?
    };
    raw_bits(token, x, lane, bytes)
}

/// [`decode_in`] for a value read as a bit: a table of one or two tokens
/// (§5.5.2) is read with one comparison; tokens 0 and 1 have no raw bits
/// (§5.5.1). Every other table goes through [`decode_in`].
#[inline]
fn decode_bit_in(
    tables: Tables<'_>,
    lane: &mut [u32; LANE_WORDS],
    index: usize,
    bytes: &[u8],
    context: usize,
) -> Result<u32, Error> {
    let context = context & (MAX_CONTEXTS - 1);
    let n = tables.tokens[context];
    if !(1..=2).contains(&n) {
        return decode_in(tables, lane, index, bytes, context);
    }
    let mut x = lane[0];
    let bit = if tables.rates[context] == 0 {
        // cum[0] = 0 and cum[n..] = PROB_SCALE: token 1 from cum[1] on
        // (never with one token).
        let cum = &tables.cums[context];
        let slot = x & (PROB_SCALE - 1);
        let split = cum[1] as u32;
        let is_one = slot >= split;
        let mask = 0u32.wrapping_sub(is_one as u32);
        let start = split & mask;
        let freq = split ^ ((split ^ (cum[2] as u32 - split)) & mask);
        x = freq * (x >> PROB_BITS) + slot - start;
        renormalise(bytes, lane, &mut x)?;
        is_one
    } else if n == 1 {
        // An adaptive table of one token makes no decision.
        false
    } else {
        // One decision, lane `index`'s (`open_adaptive` checked the room).
        let rate = tables.rates[context];
        let (Some(q), Some(count)) = (
            tables.cums[context].get_mut(index),
            tables.buckets[context].get_mut(index),
        ) else {
            return Err(Error::InvalidRansChunk("adaptive table without room"));
        };
        decide(q, count, rate, lane, bytes, &mut x)?
    };
    lane[0] = x;
    Ok(bit as u32)
}

/// The token of a static table (§5.5.4) read from a lane with state `x`.
#[inline(always)]
fn static_token(
    cum: &[u16; CUM_LEN],
    buckets: &[u8; BUCKETS],
    lane: &mut [u32; LANE_WORDS],
    bytes: &[u8],
    x: &mut u32,
) -> Result<u32, Error> {
    let slot = *x & (PROB_SCALE - 1);
    // The token t with cum[t] <= slot < cum[t + 1]: the bucket names the
    // token of its first slot; a bucket spanning several tokens is
    // scanned forward (cum[n] and the entries after it exceed every
    // slot, so the scan stops below n).
    let mut t = buckets[(slot >> BUCKET_BITS) as usize] as usize;
    while t + 1 < CUM_LEN && cum[t + 1] as u32 <= slot {
        t += 1;
    }
    if t + 1 >= CUM_LEN {
        return Err(Error::InvalidRansChunk("slot beyond the table"));
    }
    let start = cum[t] as u32;
    let freq = cum[t + 1] as u32 - start;
    *x = freq * (*x >> PROB_BITS) + slot - start;
    renormalise(bytes, lane, x)?;
    Ok(t as u32)
}

/// One context's adaptive table (§5.5.2, 3.9), as [`adaptive_token`]
/// reads and adapts it.
struct Adaptive<'a> {
    probs: &'a mut [u16; CUM_LEN],
    counts: &'a mut [u8; BUCKETS],
    rate: u8,
    tokens: usize,
}

/// The token of an adaptive table (§5.5.4, 3.9), read from lane number
/// `index` with state `x`: decision i asks whether the token is above i,
/// with the lane's probability i of "above" (a 16-bit fraction), which then
/// moves towards the answer: by half the way the first time, a quarter the
/// second, and so on down to `2^-rate`. Not forced inline: inlined at
/// every reader it took 2 KB more Cortex-M4 code (63,368 against 61,384
/// bytes of `.text`) for 2 % fewer instructions on x86.
#[inline]
fn adaptive_token(
    table: Adaptive<'_>,
    index: usize,
    lane: &mut [u32; LANE_WORDS],
    bytes: &[u8],
    x: &mut u32,
) -> Result<u32, Error> {
    let decisions = table.tokens - 1;
    // `open_adaptive` checked decisions × lane_count <= ADAPTIVE_STATES.
    let states = index * decisions..(index + 1) * decisions;
    let (Some(probs), Some(counts)) = (
        table.probs.get_mut(states.clone()),
        table.counts.get_mut(states),
    ) else {
        return Err(Error::InvalidRansChunk("adaptive table without room"));
    };
    for (i, (q, count)) in probs.iter_mut().zip(counts.iter_mut()).enumerate() {
        if !decide(q, count, table.rate, lane, bytes, x)? {
            return Ok(i as u32);
        }
    }
    Ok(decisions as u32)
}

/// One decision of an adaptive table (§5.5.4, 3.9): whether the token is
/// above the decision's index, read with probability `q` of "above", which
/// then moves towards the answer. Without a branch on the answer (half the
/// flags of a level are set, so one would be mispredicted often).
#[inline(always)]
fn decide(
    q: &mut u16,
    count: &mut u8,
    rate: u8,
    lane: &mut [u32; LANE_WORDS],
    bytes: &[u8],
    x: &mut u32,
) -> Result<bool, Error> {
    let p = *q as u32;
    let above = (p >> (ADAPTIVE_BITS - PROB_BITS)).max(1);
    let below = PROB_SCALE - above;
    let slot = *x & (PROB_SCALE - 1);
    let is_above = slot >= below;
    // All ones when the answer is "above".
    let mask = 0u32.wrapping_sub(is_above as u32);
    let start = below & mask;
    let freq = below ^ ((below ^ above) & mask);
    *x = freq * (*x >> PROB_BITS) + slot - start;
    renormalise(bytes, lane, x)?;
    let shift = adaptive_shift(*count, rate);
    *count = count.saturating_add(1);
    let up = ((1u32 << ADAPTIVE_BITS) - p) >> shift;
    let down = p >> shift;
    *q = (p + (up & mask) - (down & !mask)) as u16;
    Ok(is_above)
}

/// How far a probability used `count` times before moves (§5.5.4, 3.9):
/// `2^-shift` of the way, `shift = min(rate, 1 + bit length of count)`.
/// (A `const fn`, so the encoder's cost tables are built from it.)
#[inline(always)]
pub const fn adaptive_shift(count: u8, rate: u8) -> u32 {
    let shift = 1 + (8 - count.leading_zeros());
    // `shift.min(rate)` (not `const`), in `min`'s own form.
    if (rate as u32) < shift {
        rate as u32
    } else {
        shift
    }
}

/// Finishes a value whose token has been read, leaving the lane's state
/// `x`: the token's raw bits (§5.5.1, §5.5.4).
#[inline(always)]
fn raw_bits(
    token: u32,
    mut x: u32,
    lane: &mut [u32; LANE_WORDS],
    bytes: &[u8],
) -> Result<u32, Error> {
    let extra = token_bits(token);
    if extra == 0 {
        lane[0] = x;
        return Ok(token);
    }
    let mut low = 0u32;
    let mut done = 0;
    while done < extra {
        let step = (extra - done).min(RAW_BITS_STEP);
        low |= (x & ((1 << step) - 1)) << done;
        x >>= step;
        renormalise(bytes, lane, &mut x)?;
        done += step;
    }
    lane[0] = x;
    Ok((1 << extra) | low)
}

/// Pulls bytes into the state `x` of `lane` until it is normalised again.
#[inline(always)]
fn renormalise(bytes: &[u8], lane: &mut [u32; LANE_WORDS], x: &mut u32) -> Result<(), Error> {
    while *x < STATE_LOW {
        let at = lane[1];
        match bytes.get(at as usize) {
            Some(&b) if at < lane[2] => {
                *x = (*x << 8) | b as u32;
                lane[1] = at + 1;
            }
            _ => return Err(Error::InvalidRansChunk("lane ran out of bytes")),
        }
    }
    Ok(())
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use crate::limits::rans::{MAX_CONTEXTS, MAX_LANES, TABLE_WORDS};
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
        let mut words = vec![0u32; TABLE_WORDS + LANE_WORDS * MAX_LANES as usize];
        let mut chunk = ChunkDecoder::new(&mut words, lanes).expect("room");
        chunk.open(payload, 0, payload.len(), n_contexts, contexts.len() as u32)?;
        let mut out = Vec::new();
        for &ctx in contexts {
            out.push(chunk.decode(payload, ctx as usize)?);
        }
        if !chunk.exhausted() {
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

    /// Skewed bits in two contexts (in the first, one in eight differs
    /// from the rest, which turn from 0 to 1 halfway), then small values in
    /// a third: contexts an encoder codes with adaptive tables.
    fn skewed(n: usize) -> Vec<Symbol> {
        (0..n)
            .map(|i| match i % 3 {
                0 => (0, ((i % 8 == 0) ^ (2 * i > n)) as u32),
                1 => (1, (i % 5 == 0) as u32),
                _ => (2, ((i * 7) % 11 % 4) as u32),
            })
            .collect()
    }

    #[test]
    fn adaptive_tables_round_trip_in_any_lane_count() {
        let symbols = skewed(3000);
        let contexts: Vec<u8> = symbols.iter().map(|s| s.0).collect();
        let expected: Vec<u32> = symbols.iter().map(|s| s.1).collect();
        for lanes in [1, 2, 3, 4, 16, 32] {
            let (payload, adaptive) =
                crate::rans_writer::encode_chunk_with(&symbols, 3, lanes, true, None);
            let (in_payload, in_use) = table_kinds(&payload, 3).unwrap();
            assert_eq!((in_payload > 0, in_use), (adaptive, 3));
            // With many lanes each lane's probabilities learn from few
            // values, and static tables may be smaller.
            if lanes <= 4 {
                assert!(adaptive, "{lanes} lanes: skewed bits pay no table");
                // The first context's table is its one adaptive byte.
                assert_ne!(payload[0] & ADAPTIVE_FLAG, 0);
            }
            assert_eq!(decode(&payload, &contexts, 3, lanes).unwrap(), expected);
            let (static_only, adaptive) =
                crate::rans_writer::encode_chunk_with(&symbols, 3, lanes, false, None);
            assert!(!adaptive);
            assert!(payload.len() <= static_only.len(), "{lanes} lanes");
            assert_eq!(table_kinds(&static_only, 3), Ok((0, 3)));
            assert_eq!(decode(&static_only, &contexts, 3, lanes).unwrap(), expected);
        }
    }

    #[test]
    fn adaptive_tables_over_their_room_are_malformed() {
        // 16 tokens in 4 lanes: 60 probabilities, over ADAPTIVE_STATES.
        let mut words = vec![0u32; TABLE_WORDS + LANE_WORDS * MAX_LANES as usize];
        let mut chunk = ChunkDecoder::new(&mut words, 4).expect("room");
        let payload = [0x8F, 0, 0, 0, 0];
        assert_eq!(
            chunk.open(&payload, 0, payload.len(), 1, 0),
            Err(Error::InvalidRansChunk(
                "adaptive table needs more probabilities than a table holds"
            ))
        );
        // 13 tokens in 4 lanes fit (48), and a table byte alone with no
        // lane directory after it runs past the chunk.
        let payload = [0x8C];
        assert_eq!(
            chunk.open(&payload, 0, payload.len(), 1, 1),
            Err(Error::InvalidRansChunk("tables run past the chunk"))
        );
    }

    #[test]
    fn a_one_token_adaptive_table_reads_zeros_from_no_bytes() {
        // Table byte 0x80: m = 1, rate 4. One lane of 4 bytes, state 2^23.
        let mut payload = vec![0x80, 4];
        payload.extend_from_slice(&STATE_LOW.to_le_bytes());
        assert_eq!(decode(&payload, &[0; 5], 1, 1).unwrap(), vec![0; 5]);
    }

    #[test]
    fn adaptive_shift_halves_then_settles_at_the_rate() {
        let shifts: Vec<u32> = [0u8, 1, 2, 3, 4, 7, 8, 63, 64, 255]
            .iter()
            .map(|&k| adaptive_shift(k, 7))
            .collect();
        assert_eq!(shifts, [1, 2, 3, 3, 4, 4, 5, 7, 7, 7]);
        assert_eq!(adaptive_shift(255, 11), 9);
        assert_eq!(adaptive_shift(0, 4), 1);
    }

    #[test]
    fn peeking_adaptive_bits_consumes_nothing() {
        let symbols: Vec<Symbol> = skewed(900).into_iter().filter(|s| s.0 < 2).collect();
        let contexts: Vec<u8> = symbols.iter().map(|s| s.0).collect();
        let (payload, adaptive) = crate::rans_writer::encode_chunk_with(&symbols, 2, 2, true, None);
        assert!(adaptive);
        let mut words = vec![0u32; TABLE_WORDS + LANE_WORDS * MAX_LANES as usize];
        let mut chunk = ChunkDecoder::new(&mut words, 2).expect("room");
        chunk
            .open(&payload, 0, payload.len(), 2, symbols.len() as u32)
            .unwrap();
        let mut at = 0;
        while at < symbols.len() {
            let (bits, known) = chunk.peek_bits(&payload, &contexts[at..], symbols.len() - at);
            assert!(known > 0);
            for i in 0..known as usize {
                let v = chunk.decode(&payload, contexts[at + i] as usize).unwrap();
                assert_eq!(v, symbols[at + i].1);
                assert_eq!(v as u128, (bits >> i) & 1, "value {}", at + i);
            }
            at += known as usize;
        }
        assert!(chunk.exhausted());
    }

    /// Each value read (or the error), with the lanes' words after it.
    type Steps = Vec<Result<(u32, Vec<u32>), Error>>;

    /// Decodes `contexts` from `payload` value by value with
    /// [`ChunkDecoder::decode`] and with [`ChunkDecoder::decode_bit`]:
    /// each value or error, and the lanes after it.
    fn both_ways(payload: &[u8], contexts: &[u8], n_contexts: usize, lanes: usize) -> [Steps; 2] {
        core::array::from_fn(|as_bit| {
            let mut words = vec![0u32; TABLE_WORDS + LANE_WORDS * MAX_LANES as usize];
            let mut chunk = ChunkDecoder::new(&mut words, lanes).expect("room");
            let mut out = Vec::new();
            if let Err(e) = chunk.open(payload, 0, payload.len(), n_contexts, contexts.len() as u32)
            {
                out.push(Err(e));
                return out;
            }
            for &ctx in contexts {
                let value = if as_bit == 1 {
                    chunk.decode_bit(payload, ctx as usize)
                } else {
                    chunk.decode(payload, ctx as usize)
                };
                let lanes: Vec<u32> = chunk.lanes[..lanes].iter().flatten().copied().collect();
                let failed = value.is_err();
                out.push(value.map(|v| (v, lanes)));
                if failed {
                    break;
                }
            }
            out
        })
    }

    proptest! {
        /// A value read as a bit takes the same value, lane steps and
        /// errors as the general read, whatever the tables: skewed bits in
        /// adaptive and static tables, larger values, and chunks with bytes
        /// changed.
        #[test]
        fn bits_read_as_any_value(
            bits in proptest::collection::vec((0u8..4, 0u32..8), 1..600),
            lanes in 1usize..=8,
            adaptive in any::<bool>(),
            edits in proptest::collection::vec((any::<prop::sample::Index>(), 1u8..=255), 0..3),
        ) {
            // Contexts 0 and 1 hold bits, 2 a bit or a constant, 3 anything.
            let symbols: Vec<Symbol> = bits
                .iter()
                .map(|&(ctx, v)| (ctx, match ctx { 0 | 1 => v & 1, 2 => (v == 0) as u32, _ => v }))
                .collect();
            let (mut payload, _) =
                crate::rans_writer::encode_chunk_with(&symbols, 4, lanes, adaptive, None);
            for (at, flip) in &edits {
                let i = at.index(payload.len());
                payload[i] ^= flip;
            }
            let contexts: Vec<u8> = symbols.iter().map(|s| s.0).collect();
            let [general, as_bit] = both_ways(&payload, &contexts, 4, lanes);
            prop_assert_eq!(general, as_bit);
        }

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
