//! Reading a level's substreams chunk by chunk (SPEC §5.3, §5.4).
//!
//! Each substream is a byte sequence cut into chunks of at most
//! `max_chunk_len` raw bytes; a chunk is checked against its CRC-32, then
//! copied (stored) or inflated (deflate) into that substream's buffer.
//! Values never need to be aligned to chunk boundaries.
//!
//! A substream coded with rANS (SPEC §5.5) is read value by value instead:
//! its slot's buffer then holds the chunk's frequency tables and lane states,
//! and values are decoded straight from the level's bytes.

use crate::context;
use crate::inflate::Inflater;
use crate::level_header::LevelHeader;
use crate::limits::codec;
use crate::limits::substream::SLOTS;
use crate::rans::{ChunkDecoder, Lookahead};
use crate::{ChecksumScope, Error, Schedule, bytes::crc32};

struct Reader<'b> {
    id: u8,
    next_chunk: u32,
    end_chunk: u32,
    /// Where the next chunk's directory entry starts in the directory
    /// (read on from the last one: SPEC §5.1.1), and its payload in the
    /// level.
    entry_at: usize,
    payload_at: usize,
    /// Byte codecs: the current chunk's raw bytes.
    buf: &'b mut [u8],
    /// rANS: the current chunk's tables and lanes, in the slot's memory
    /// (`None` when the slot is too small for them).
    chunk: Option<ChunkDecoder<'b>>,
    rans: bool,
    /// Byte codecs: bytes of the chunk and bytes read; rANS: values.
    len: usize,
    pos: usize,
    bit_byte: u8,
    bit_index: u8,
    /// rANS bit substreams: values decoded ahead of the reader (bit i is
    /// the i-th next value), so that [`Substreams::peek_bits`] can show
    /// them; `ahead_error` is the error of the value after them, reported
    /// only when the reader gets there.
    ahead: u64,
    ahead_len: u32,
    ahead_error: Option<Error>,
}

impl Reader<'_> {
    /// A reader with nothing to read (its slot is read elsewhere), or the
    /// start of one that `Substreams::open` gives its buffer and chunks.
    fn idle(id: u8) -> Self {
        Reader {
            id,
            next_chunk: 0,
            end_chunk: 0,
            entry_at: 0,
            payload_at: 0,
            buf: &mut [],
            chunk: None,
            rans: false,
            len: 0,
            pos: 0,
            bit_byte: 0,
            bit_index: 8,
            ahead: 0,
            ahead_len: 0,
            ahead_error: None,
        }
    }
}

/// The open substreams of one level.
pub struct Substreams<'l, 'b> {
    level: &'l [u8],
    header: LevelHeader<'l>,
    readers: [Reader<'b>; SLOTS],
    inflater: &'b mut Inflater,
    /// Bits decoded ahead by [`Substreams::peek_bits_in`] for the reader
    /// of slot `lookahead_slot` (`SLOTS`: none), served to it while it
    /// reads them in the same contexts.
    lookahead: Lookahead,
    lookahead_slot: usize,
}

impl<'l, 'b> Substreams<'l, 'b> {
    /// Opens the substreams whose ids are `first_id .. first_id + SLOTS`,
    /// slot `i` reading id `first_id + i` into `buffers[i]`; rANS chunks use
    /// `lane_count` lanes (header byte 13).
    pub fn open(
        level: &'l [u8],
        header: LevelHeader<'l>,
        first_id: u8,
        buffers: [&'b mut [u8]; SLOTS],
        inflater: &'b mut Inflater,
        lane_count: u8,
    ) -> Self {
        // Chunks are ordered by substream id (validated), so each substream's
        // chunks form one run of the directory and one run of the payload;
        // its first entry, where that starts and whether it is rANS (a
        // substream's chunks are all rANS or none, SPEC §5.1) are found in
        // one pass over the directory.
        let mut first: [Option<(u32, usize, usize)>; SLOTS] = [None; SLOTS];
        let mut ends = [0u32; SLOTS];
        let mut rans = [false; SLOTS];
        let (mut payload, mut at) = (header.payload_start, 0);
        for k in 0..header.chunk_count {
            // The directory was validated when the header was parsed.
            let Ok((e, next)) = header.entry_at(at) else {
                break;
            };
            let slot = e.substream.wrapping_sub(first_id) as usize;
            if slot < SLOTS {
                first[slot].get_or_insert((k, at, payload));
                ends[slot] = k + 1;
                rans[slot] |= e.codec == codec::RANS;
            }
            payload += e.stored_len as usize;
            at = next;
        }
        let mut i = 0;
        let readers = buffers.map(|buf| {
            let slot = i;
            i += 1;
            let (buf, chunk) = if rans[slot] {
                let words = bytemuck::try_cast_slice_mut::<u8, u32>(buf).unwrap_or(&mut []);
                (&mut [][..], ChunkDecoder::new(words, lane_count as usize))
            } else {
                (buf, None)
            };
            let (next_chunk, entry_at, payload_at) = first[slot].unwrap_or_default();
            Reader {
                buf,
                chunk,
                rans: rans[slot],
                next_chunk,
                end_chunk: ends[slot],
                entry_at,
                payload_at,
                ..Reader::idle(first_id + slot as u8)
            }
        });
        Substreams {
            level,
            header,
            readers,
            inflater,
            lookahead: Lookahead::default(),
            lookahead_slot: SLOTS,
        }
    }

    /// Moves the readers of every slot but `keep` into substreams of their
    /// own, which inflate with `inflater`: the records of a level read on
    /// one thread while its flags are read on another (`pipe.rs`). Each
    /// part reads only its own slots; the others are idle in it (no chunks,
    /// nothing to read, so [`Substreams::finish`] passes them).
    /// [`Substreams::join`] puts them back.
    pub fn split_off(&mut self, keep: usize, inflater: &'b mut Inflater) -> Substreams<'l, 'b> {
        self.settle();
        let mut i = 0;
        let readers = self.readers.each_mut().map(|r| {
            let slot = i;
            i += 1;
            let idle = Reader::idle(r.id);
            if slot == keep {
                idle
            } else {
                core::mem::replace(r, idle)
            }
        });
        Substreams {
            level: self.level,
            header: self.header,
            readers,
            inflater,
            lookahead: Lookahead::default(),
            lookahead_slot: SLOTS,
        }
    }

    /// Takes back the readers [`Substreams::split_off`] moved into `part`
    /// (all but `keep`'s, as there).
    pub fn join(&mut self, keep: usize, mut part: Substreams<'l, 'b>) {
        self.settle();
        part.settle();
        for (slot, (mine, theirs)) in self.readers.iter_mut().zip(part.readers).enumerate() {
            if slot != keep {
                *mine = theirs;
            }
        }
    }

    /// The header of the level these substreams belong to (SPEC §5.1).
    pub fn level_header(&self) -> &LevelHeader<'l> {
        &self.header
    }

    fn refill(&mut self, slot: usize) -> Result<(), Error> {
        let r = &mut self.readers[slot];
        if r.next_chunk >= r.end_chunk {
            return Err(Error::RecordCountMismatch(r.id));
        }
        let (e, next_entry) = self.header.entry_at(r.entry_at)?;
        let stored = self
            .level
            .get(r.payload_at..r.payload_at + e.stored_len as usize)
            .ok_or(Error::Truncated)?;
        if crc32(stored) != e.crc {
            return Err(Error::ChecksumMismatch(ChecksumScope::Chunk));
        }
        let raw = e.raw_len as usize;
        if r.rans {
            let contexts = context::count(
                r.id,
                self.header.deficit_contexts,
                self.header.record_order,
                self.header.schedule,
            );
            open_rans_chunk(self.level, r, e.stored_len as usize, e.raw_len, contexts)?;
        } else {
            let out = r.buf.get_mut(..raw).ok_or(Error::CapacityExceeded)?;
            match e.codec {
                codec::STORED => out.copy_from_slice(stored),
                _ => self.inflater.inflate_exact(stored, out)?,
            }
        }
        r.next_chunk += 1;
        r.entry_at = next_entry;
        r.payload_at += e.stored_len as usize;
        r.len = raw;
        r.pos = 0;
        Ok(())
    }

    /// Next raw byte of the byte-coded substream in `slot`.
    #[inline]
    fn raw_byte(&mut self, slot: usize) -> Result<u8, Error> {
        let r = &mut self.readers[slot];
        if r.pos == r.len {
            self.refill(slot)?;
        }
        let r = &mut self.readers[slot];
        let b = r.buf[r.pos];
        r.pos += 1;
        Ok(b)
    }

    /// Next value of the rANS-coded substream in `slot`, in `context` (SPEC §5.5).
    ///
    /// Inlined into every reader on the host, where the records' reads are
    /// the hot path. On 32-bit Arm one out-of-line copy: its eight inlined
    /// copies (the two wing ranks, the two split valences, the placement
    /// code, the residual vectors' signed values and the out-of-line byte
    /// and varint readers, each with the whole decode of a value) were
    /// about 4.3 KB of a thumbv7em decoder's `.text`, for a call and
    /// return per value.
    #[cfg_attr(not(target_arch = "arm"), inline(always))]
    #[cfg_attr(target_arch = "arm", inline(never))]
    fn rans_value(&mut self, slot: usize, context: u8) -> Result<u32, Error> {
        self.rans_value_as(slot, context, false)
    }

    /// [`Substreams::rans_value`], for a value read as a bit when `bit`
    /// ([`ChunkDecoder::decode_bit`]: the same value, a shorter path).
    #[inline(always)]
    fn rans_value_as(&mut self, slot: usize, context: u8, bit: bool) -> Result<u32, Error> {
        // Any read of a slot with bits looked ahead and taken (a caller of
        // this public API may mix `bit` with other reads) first brings its
        // chunk to them.
        if self.lookahead_slot == slot {
            self.settle();
        }
        let r = &mut self.readers[slot];
        if r.pos == r.len {
            self.refill(slot)?;
        }
        let r = &mut self.readers[slot];
        let Some(chunk) = r.chunk.as_mut() else {
            return Err(Error::CapacityExceeded);
        };
        let value = if bit {
            chunk.decode_bit(self.level, context as usize)?
        } else {
            chunk.decode(self.level, context as usize)?
        };
        r.pos += 1;
        // The chunk's last value: every lane must end exactly here.
        if r.pos == r.len && !chunk.exhausted() {
            return Err(Error::InvalidRansChunk("a lane did not end exactly"));
        }
        Ok(value)
    }

    /// Whether `slot` is rANS-coded in this level.
    #[inline]
    fn is_rans(&self, slot: usize) -> bool {
        self.readers[slot].rans
    }

    /// Next byte-sized value of `slot` (SPEC §5.4, §5.5).
    #[inline(always)]
    pub fn byte(&mut self, slot: usize, context: u8) -> Result<u8, Error> {
        if self.is_rans(slot) {
            let v = self.rans_value(slot, context)?;
            return u8::try_from(v).map_err(|_| Error::ValueOutOfRange(self.readers[slot].id));
        }
        self.raw_byte(slot)
    }

    /// Next bit of `slot`: least significant first within each byte for the
    /// byte codecs (SPEC §5.4), a value 0 or 1 for rANS (SPEC §5.5).
    #[inline]
    pub fn bit(&mut self, slot: usize, context: u8) -> Result<bool, Error> {
        if self.is_rans(slot) {
            if self.header.schedule == Schedule::EveryVertex {
                // Each flag has its own context (SPEC §5.5.5, 3.6): no
                // decoding ahead in one, but the bits looked ahead in
                // the contexts they are read in are served as decoded.
                if self.lookahead_slot == slot {
                    if let Some(bit) = self.lookahead.next(context) {
                        return self.served(slot, bit);
                    }
                    self.settle();
                }
                let v = self.rans_value_as(slot, context, true)?;
                return match v {
                    0 | 1 => Ok(v == 1),
                    _ => Err(Error::ValueOutOfRange(self.readers[slot].id)),
                };
            }
            if self.readers[slot].ahead_len == 0 {
                if let Some(e) = self.readers[slot].ahead_error {
                    return Err(e);
                }
                if self.readers[slot].pos == self.readers[slot].len {
                    self.refill(slot)?;
                }
                self.decode_bits_ahead(slot, context);
                let r = &self.readers[slot];
                if r.ahead_len == 0 {
                    // The very next value failed: its error is due now.
                    return Err(r.ahead_error.unwrap_or(Error::RecordCountMismatch(r.id)));
                }
            }
            let r = &mut self.readers[slot];
            let bit = r.ahead & 1 != 0;
            r.ahead >>= 1;
            r.ahead_len -= 1;
            return Ok(bit);
        }
        if self.readers[slot].bit_index == 8 {
            let b = self.raw_byte(slot)?;
            let r = &mut self.readers[slot];
            r.bit_byte = b;
            r.bit_index = 0;
        }
        let r = &mut self.readers[slot];
        let bit = (r.bit_byte >> r.bit_index) & 1 != 0;
        r.bit_index += 1;
        Ok(bit)
    }

    /// A bit of `slot` served from the look-ahead: counted as read, and
    /// once the look-ahead's last is read its state becomes the chunk's,
    /// checked at the chunk's end as [`Substreams::rans_value`] checks it.
    #[inline]
    fn served(&mut self, slot: usize, bit: bool) -> Result<bool, Error> {
        let r = &mut self.readers[slot];
        r.pos += 1;
        if self.lookahead.all_taken() {
            self.lookahead_slot = SLOTS;
            if let Some(chunk) = r.chunk.as_mut() {
                chunk.adopt(&self.lookahead);
                if r.pos == r.len && !chunk.exhausted() {
                    return Err(Error::InvalidRansChunk("a lane did not end exactly"));
                }
            }
        }
        Ok(bit)
    }

    /// Brings the look-ahead's reader to the values it has read: those it
    /// took from the look-ahead are decoded again, in their contexts, from
    /// the chunk's own state (they decode as they did ahead), and the rest
    /// is dropped. Rare: the reader follows its look-ahead to the end
    /// unless a flagged candidate blocks a later one of the same batch.
    #[cold]
    #[inline(never)]
    fn settle(&mut self) {
        let slot = core::mem::replace(&mut self.lookahead_slot, SLOTS);
        let Some(r) = self.readers.get_mut(slot) else {
            return;
        };
        if let Some(chunk) = r.chunk.as_mut() {
            for &context in self.lookahead.taken() {
                let _ = chunk.decode_bit(self.level, context as usize);
            }
        }
    }

    /// Decodes values of the current rANS chunk of bit substream `slot`
    /// ahead of the reader, up to 64 (SPEC §5.5: the values and the errors
    /// are the same as when read one by one; an error is kept until the
    /// reader reaches its value). Never loads a chunk: that happens when the
    /// reader needs one (§5.2). All of a bit substream's values share one
    /// context (the flags: context 0, §5.5.5), so decoding them early in
    /// `context` decodes them as the reader would.
    fn decode_bits_ahead(&mut self, slot: usize, context: u8) {
        while self.readers[slot].ahead_len < 64
            && self.readers[slot].ahead_error.is_none()
            && self.readers[slot].pos < self.readers[slot].len
        {
            let value = match self.rans_value_as(slot, context, true) {
                Ok(0) => 0u64,
                Ok(1) => 1,
                Ok(_) => {
                    self.readers[slot].ahead_error =
                        Some(Error::ValueOutOfRange(self.readers[slot].id));
                    break;
                }
                Err(e) => {
                    self.readers[slot].ahead_error = Some(e);
                    break;
                }
            };
            let r = &mut self.readers[slot];
            r.ahead |= value << r.ahead_len;
            r.ahead_len += 1;
        }
    }

    /// The next bits of bit substream `slot` as [`Substreams::bit`] will
    /// return them, without consuming them: `(bits, count)`, bit i of `bits`
    /// being the i-th next one, `count` at most 64. Only what the current
    /// chunk holds is shown (and nothing past a value that fails), so
    /// `count` may be 0. A decoder uses it to look ahead, never to decide.
    pub fn peek_bits(&mut self, slot: usize, context: u8) -> (u64, u32) {
        if self.is_rans(slot) {
            if self.header.schedule == Schedule::EveryVertex {
                // Contexts differ from flag to flag: see `peek_bits_in`.
                return (0, 0);
            }
            self.decode_bits_ahead(slot, context);
            let r = &self.readers[slot];
            return (r.ahead, r.ahead_len);
        }
        self.peek_byte_bits(slot)
    }

    /// [`Substreams::peek_bits`] for bits read each in its own context,
    /// `contexts[i]` for the i-th next one (the flags under the schedule
    /// `every-vertex`, SPEC §5.5.5): decoded from copies of the current rANS
    /// chunk's lanes and tables, so nothing is consumed and nothing is
    /// loaded (`count` is 0 at a chunk's end, at most 128, and at most 64
    /// for a byte codec). A decoder uses it to look ahead, never to decide.
    /// The bits are kept: while [`Substreams::bit`] then asks for them in
    /// the same contexts it gets them without decoding them again, and the
    /// chunk takes the copies' state after the last; a read in another
    /// context first brings the chunk to the bits taken. What is read is
    /// the same either way.
    pub fn peek_bits_in(&mut self, slot: usize, contexts: &[u8]) -> (u128, u32) {
        if !self.is_rans(slot) {
            let (bits, count) = self.peek_byte_bits(slot);
            return (bits as u128, count);
        }
        self.settle();
        let r = &self.readers[slot];
        if r.ahead_len > 0 || r.ahead_error.is_some() {
            // Bits decoded ahead in one context: not this reader's way.
            return (0, 0);
        }
        match r.chunk.as_ref() {
            Some(chunk) if r.pos < r.len => {
                let (bits, known) =
                    chunk.look_ahead(self.level, contexts, r.len - r.pos, &mut self.lookahead);
                if known > 0 {
                    // Served to `bit` as it reads them (each decoded once).
                    self.lookahead_slot = slot;
                }
                (bits, known)
            }
            _ => (0, 0),
        }
    }

    /// The next bits of a byte-codec bit substream, unconsumed.
    fn peek_byte_bits(&self, slot: usize) -> (u64, u32) {
        let r = &self.readers[slot];
        let (mut bits, mut count) = if r.bit_index < 8 {
            ((r.bit_byte >> r.bit_index) as u64, 8 - r.bit_index as u32)
        } else {
            (0, 0)
        };
        for &b in r.buf.get(r.pos..r.len.min(r.pos + 7)).unwrap_or(&[]) {
            bits |= (b as u64) << count;
            count += 8;
        }
        (bits, count)
    }

    /// Next LEB128 varint of `slot`: at most 5 bytes, at most 32 bits,
    /// minimal (a multi-byte varint does not end in a zero byte) (SPEC §5.4).
    /// Under rANS, one value of the hybrid code (SPEC §5.5).
    #[inline(always)]
    pub fn varint(&mut self, slot: usize, context: u8) -> Result<u32, Error> {
        if self.is_rans(slot) {
            return self.rans_value(slot, context);
        }
        let mut value = 0u32;
        for i in 0..5 {
            let b = self.raw_byte(slot)?;
            let payload = (b & 0x7F) as u32;
            if i == 4 && b > 0x0F {
                return Err(Error::InvalidVarint(self.readers[slot].id));
            }
            value |= payload << (7 * i);
            if b & 0x80 == 0 {
                if b == 0 && i > 0 {
                    return Err(Error::InvalidVarint(self.readers[slot].id));
                }
                return Ok(value);
            }
        }
        Err(Error::InvalidVarint(self.readers[slot].id))
    }

    /// Zigzag-decoded signed varint (SPEC §5.4).
    #[inline(always)]
    pub fn signed(&mut self, slot: usize, context: u8) -> Result<i32, Error> {
        Ok(zigzag(self.varint(slot, context)?))
    }

    /// Checks that every substream was read to its end and that the padding
    /// bits of bit substreams are zero (SPEC §5.4).
    pub fn finish(&self) -> Result<(), Error> {
        for r in &self.readers {
            let padding_clear = r.bit_index == 8 || (r.bit_byte >> r.bit_index) == 0;
            let all_read = r.pos == r.len && r.ahead_len == 0 && r.ahead_error.is_none();
            if !all_read || r.next_chunk != r.end_chunk || !padding_clear {
                return Err(Error::RecordCountMismatch(r.id));
            }
        }
        Ok(())
    }
}

/// The signed value of zigzag code `u` (SPEC §5.4): 0, -1, 1, -2, … for
/// 0, 1, 2, 3, …
#[inline(always)]
pub(crate) fn zigzag(u: u32) -> i32 {
    ((u >> 1) as i32) ^ -((u & 1) as i32)
}

/// Loads a rANS chunk of `values` values whose `stored_len` payload bytes
/// start at `r.payload_at` (SPEC §5.5.2, §5.5.3): its tables (one per
/// context, `contexts` of them) and lanes.
fn open_rans_chunk(
    level: &[u8],
    r: &mut Reader<'_>,
    stored_len: usize,
    values: u32,
    contexts: usize,
) -> Result<(), Error> {
    let Some(chunk) = r.chunk.as_mut() else {
        return Err(Error::CapacityExceeded);
    };
    chunk.open(
        level,
        r.payload_at,
        r.payload_at + stored_len,
        contexts,
        values,
    )
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use crate::context::SINGLE;
    use crate::header::PositionMode;
    use crate::limits::rans::TABLE_WORDS;
    use crate::limits::substream;
    use crate::rans::LANE_WORDS;
    use crate::writer::{ChunkCodec, LevelPayload, StreamParams, SubstreamWriter, frame_level};
    use alloc::vec;
    use alloc::vec::Vec;
    use proptest::prelude::*;

    /// A refinement level whose flags substream holds `bits` (the other
    /// substreams empty), framed with `codec` in chunks of `chunk` bytes
    /// or values.
    fn level(bits: &[bool], codec: ChunkCodec, chunk: u32) -> Vec<u8> {
        let mut substreams = vec![SubstreamWriter::default(); SLOTS];
        for &b in bits {
            substreams[0].bit_in(SINGLE, b);
        }
        let payload = LevelPayload {
            round_splits: vec![1],
            substreams,
            ..LevelPayload::default()
        };
        let params = StreamParams {
            framing: crate::header::Framing::Compact,
            position_mode: PositionMode::Optimal,
            bits: 14,
            origin: [0.0; 3],
            scale: [1.0; 3],
            codec,
            chunk_limit: chunk,
            rans_chunk_limit: chunk,
            schedule: crate::Schedule::SplitValences,
            adaptive_tables: true,
        };
        frame_level(&payload, None, &params).bytes
    }

    /// Memory for the substream slots of a level read with `lanes` lanes:
    /// room in each for a rANS chunk's tables and lanes or a byte chunk of
    /// 64 KiB.
    fn slot_memory(lanes: u8) -> Vec<u32> {
        vec![0u32; SLOTS * (TABLE_WORDS + LANE_WORDS * lanes as usize).max(1 << 14)]
    }

    /// `memory` ([`slot_memory`]) cut into the slots' buffers.
    fn slot_buffers(memory: &mut [u32]) -> [&mut [u8]; SLOTS] {
        let words = memory.len() / SLOTS;
        let mut rest: &mut [u32] = memory;
        core::array::from_fn(|_| {
            let (mine, tail) = core::mem::take(&mut rest).split_at_mut(words);
            rest = tail;
            bytemuck::cast_slice_mut(mine)
        })
    }

    /// Reads every flag of `bytes`, peeking before each read when `peek`
    /// says so; returns what was read, up to and including the first error,
    /// and whether the peeks always showed the bits that followed.
    fn read_all(bytes: &[u8], lanes: u8, peeks: &[bool]) -> (Vec<Result<bool, Error>>, bool) {
        let header =
            LevelHeader::parse(bytes, false, crate::LevelRules::TEST).expect("level header");
        let mut memory = slot_memory(lanes);
        let mut inflater = Inflater::new();
        let buffers = slot_buffers(&mut memory);
        let mut subs = Substreams::open(bytes, header, 1, buffers, &mut inflater, lanes);
        let mut out = Vec::new();
        let mut shown: Vec<bool> = Vec::new();
        let mut consistent = true;
        for i in 0.. {
            if peeks.get(i % peeks.len().max(1)).copied().unwrap_or(false) {
                let (bits, count) = subs.peek_bits(0, SINGLE);
                let fresh: Vec<bool> = (0..count).map(|k| bits >> k & 1 != 0).collect();
                // A peek may show more than the last one, never other bits.
                let common = fresh.len().min(shown.len());
                consistent &= fresh[..common] == shown[..common];
                if fresh.len() > shown.len() {
                    shown = fresh;
                }
            }
            let got = subs.bit(0, SINGLE);
            if let (Ok(b), Some(&s)) = (&got, shown.first()) {
                consistent &= *b == s;
            }
            if !shown.is_empty() {
                shown.remove(0);
            }
            let stop = got.is_err();
            out.push(got);
            if stop {
                break;
            }
        }
        (out, consistent)
    }

    /// A level of the schedule `every-vertex` whose flags are `flags`
    /// (context, bit), in rANS chunks of at most `chunk` values.
    fn every_vertex_level(flags: &[(u8, bool)], lanes: u8, chunk: u32, adaptive: bool) -> Vec<u8> {
        let mut substreams = vec![SubstreamWriter::default(); SLOTS];
        for &(context, b) in flags {
            substreams[0].bit_in(context, b);
        }
        let payload = LevelPayload {
            round_splits: vec![1],
            substreams,
            ..LevelPayload::default()
        };
        let params = StreamParams {
            framing: crate::header::Framing::Compact,
            position_mode: PositionMode::Constrained,
            bits: 14,
            origin: [0.0; 3],
            scale: [1.0; 3],
            codec: ChunkCodec::RansAlways { lanes },
            chunk_limit: 1 << 16,
            rans_chunk_limit: chunk,
            schedule: Schedule::EveryVertex,
            adaptive_tables: adaptive,
        };
        frame_level(&payload, None, &params).bytes
    }

    /// Reads the flags of `bytes` in `contexts` (one per flag, in order),
    /// up to and including the first error; before flag `i` where
    /// `guesses` has an entry `(i, list)`, looks `list` ahead
    /// (`peek_bits_in`).
    fn read_every_vertex(
        bytes: &[u8],
        lanes: u8,
        contexts: &[u8],
        guesses: &[(usize, Vec<u8>)],
    ) -> Vec<Result<bool, Error>> {
        let rules = crate::LevelRules {
            schedule: Schedule::EveryVertex,
            ..crate::LevelRules::TEST
        };
        let Ok(header) = LevelHeader::parse(bytes, false, rules) else {
            return vec![Err(Error::Truncated)];
        };
        let mut memory = slot_memory(lanes);
        let mut inflater = Inflater::new();
        let buffers = slot_buffers(&mut memory);
        let mut subs = Substreams::open(bytes, header, 1, buffers, &mut inflater, lanes);
        let mut out = Vec::new();
        for (i, &context) in contexts.iter().enumerate() {
            for (_, list) in guesses.iter().filter(|(at, _)| *at == i) {
                subs.peek_bits_in(0, list);
            }
            let got = subs.bit(0, context);
            let stop = got.is_err();
            out.push(got);
            if stop {
                return out;
            }
        }
        out.push(subs.finish().map(|()| true));
        out
    }

    /// Flips bits of the payload byte at `at` (an index into the payload)
    /// with `x | 1` and refreshes its chunk's CRC and the header's, so that
    /// the damage reaches the decoders rather than the CRC checks.
    fn corrupt_payload(bytes: &mut [u8], rules: crate::LevelRules, at: prop::sample::Index, x: u8) {
        let copy = bytes.to_vec();
        let header = LevelHeader::parse(&copy, false, rules).expect("header");
        let start = header.payload_start;
        if bytes.len() <= start {
            return;
        }
        let at = start + at.index(bytes.len() - start);
        bytes[at] ^= x | 1;
        // Each entry ends with its CRC, in either framing; the directory
        // ends where the header's CRC starts.
        let mut ends = Vec::new();
        let mut next = 0;
        for _ in 0..header.chunk_count {
            let (e, after) = header.entry_at(next).expect("entry");
            ends.push((e, after));
            next = after;
        }
        let directory_at = header.payload_start - 4 - next;
        let mut offset = start;
        for (e, entry_end) in ends {
            let end = offset + e.stored_len as usize;
            if (offset..end).contains(&at) {
                let crc = crate::bytes::crc32(&bytes[offset..end]);
                let crc_at = directory_at + entry_end - 4;
                bytes[crc_at..crc_at + 4].copy_from_slice(&crc.to_le_bytes());
            }
            offset = end;
        }
        let head_len = header.payload_start - 4;
        let crc = crate::bytes::crc32(&bytes[..head_len]);
        bytes[head_len..head_len + 4].copy_from_slice(&crc.to_le_bytes());
    }

    fn codec_of(which: u8, lanes: u8) -> ChunkCodec {
        match which % 3 {
            0 => ChunkCodec::Stored,
            1 => ChunkCodec::Deflate(6),
            _ => ChunkCodec::RansAlways { lanes },
        }
    }

    /// A bit looked ahead and taken, then the next value read as a byte
    /// of the same slot (the public API allows it): the byte is the value
    /// after the bit, as without the look-ahead.
    #[test]
    fn a_byte_read_after_bits_taken_from_a_look_ahead_follows_them() {
        let flags: Vec<(u8, bool)> = (0..40).map(|i| ((i % 5) as u8, i % 3 == 0)).collect();
        let bytes = every_vertex_level(&flags, 2, 200, true);
        let rules = crate::LevelRules {
            schedule: Schedule::EveryVertex,
            ..crate::LevelRules::TEST
        };
        let header = LevelHeader::parse(&bytes, false, rules).expect("level header");
        let mut memory = slot_memory(2);
        let mut inflater = Inflater::new();
        let buffers = slot_buffers(&mut memory);
        let mut subs = Substreams::open(&bytes, header, 1, buffers, &mut inflater, 2);
        let contexts: Vec<u8> = flags.iter().map(|f| f.0).collect();
        // The first read loads the chunk; the look-ahead sees the rest.
        assert_eq!(subs.bit(0, flags[0].0), Ok(flags[0].1));
        let (_, known) = subs.peek_bits_in(0, &contexts[1..]);
        assert_eq!(known, 39);
        for f in &flags[1..3] {
            assert_eq!(subs.bit(0, f.0), Ok(f.1));
        }
        assert_eq!(subs.byte(0, flags[3].0), Ok(flags[3].1 as u8));
        for f in &flags[4..] {
            assert_eq!(subs.bit(0, f.0), Ok(f.1));
        }
        assert_eq!(subs.finish(), Ok(()));
    }

    proptest! {
        /// Looking flags ahead in their contexts (`peek_bits_in`, which the
        /// rounds then read without decoding them again) changes nothing:
        /// the same bits and the same first error as reading without it,
        /// whether the reader follows the look-ahead, leaves it (a context
        /// put in or changed: a candidate blocked by a flagged one of the
        /// same batch), or reads past it; with adaptive and static tables,
        /// chunk ends inside a look-ahead, corrupted bytes, and bits asked
        /// for after the last.
        #[test]
        fn looking_ahead_never_changes_what_is_read(
            flags in proptest::collection::vec((0u8..5, 0u8..8), 1..400),
            lanes in 1u8..6,
            chunk in 1u32..200,
            adaptive in any::<bool>(),
            guesses in proptest::collection::vec(
                (any::<prop::sample::Index>(), 0usize..140, proptest::collection::vec((any::<prop::sample::Index>(), 0u8..6), 0..3)),
                0..12,
            ),
            corrupt in any::<Option<(prop::sample::Index, u8)>>(),
            extra in 0usize..3,
        ) {
            // Skewed bits, more often 0 in the higher contexts.
            let flags: Vec<(u8, bool)> = flags.iter().map(|&(c, v)| (c, v < 3 - c.min(2))).collect();
            let mut bytes = every_vertex_level(&flags, lanes, chunk, adaptive);
            if let Some((at, x)) = corrupt {
                let rules = crate::LevelRules { schedule: Schedule::EveryVertex, ..crate::LevelRules::TEST };
                corrupt_payload(&mut bytes, rules, at, x);
            }
            // The reader's contexts: the flags', then a few more past the
            // end (asked for after the last flag).
            let mut contexts: Vec<u8> = flags.iter().map(|f| f.0).collect();
            contexts.extend((0..extra).map(|k| k as u8));
            // Each look-ahead names the contexts from flag `i` on, up to
            // `len` of them, with edits: a context put in or changed.
            let n = contexts.len();
            let guesses: Vec<(usize, Vec<u8>)> = guesses
                .iter()
                .map(|(at, len, edits)| {
                    let i = at.index(n);
                    let mut list: Vec<u8> = contexts[i..(i + len).min(n)].to_vec();
                    for (pos, c) in edits {
                        let p = pos.index(list.len() + 1);
                        if *c == 5 || p == list.len() {
                            list.insert(p, *c % 5);
                        } else {
                            list[p] = *c;
                        }
                    }
                    list.truncate(128);
                    (i, list)
                })
                .collect();
            let plain = read_every_vertex(&bytes, lanes, &contexts, &[]);
            let ahead = read_every_vertex(&bytes, lanes, &contexts, &guesses);
            prop_assert_eq!(&plain, &ahead);
            if corrupt.is_none() && extra == 0 {
                let expected: Vec<Result<bool, Error>> =
                    flags.iter().map(|f| Ok(f.1)).chain([Ok(true)]).collect();
                prop_assert_eq!(plain, expected);
            }
        }

        /// Peeking changes nothing: the same bits and the same first error
        /// (here: running out, then a corrupted byte) as reading without
        /// peeks, and every peek shows exactly the bits that follow.
        #[test]
        fn peeking_never_changes_what_is_read(
            bits in proptest::collection::vec(any::<bool>(), 1..300),
            which in 0u8..3,
            lanes in 1u8..6,
            chunk in 1u32..40,
            peeks in proptest::collection::vec(any::<bool>(), 1..8),
            corrupt in any::<Option<(prop::sample::Index, u8)>>(),
        ) {
            let lanes = if which % 3 == 2 { lanes } else { 1 };
            let mut bytes = level(&bits, codec_of(which, lanes), chunk);
            if let Some((at, x)) = corrupt {
                corrupt_payload(&mut bytes, crate::LevelRules::TEST, at, x);
            }
            let (plain, _) = read_all(&bytes, lanes, &[false]);
            let (peeked, consistent) = read_all(&bytes, lanes, &peeks);
            prop_assert_eq!(&plain, &peeked);
            prop_assert!(consistent);
            if corrupt.is_none() {
                let read: Vec<bool> = plain.iter().filter_map(|r| r.ok()).collect();
                prop_assert_eq!(&read[..bits.len()], &bits[..]);
            }
        }
    }

    /// A level whose edge substream (id 6, 3 contexts) holds `values`,
    /// rANS-coded with chunks cut by the writer (`rans_segments`) up to
    /// `limit` values, and the lengths of its chunks.
    fn edge_level(values: &[(u8, i32)], lanes: u8, limit: u32) -> (Vec<u8>, Vec<u32>) {
        let mut substreams = vec![SubstreamWriter::default(); SLOTS];
        for &(context, v) in values {
            substreams[(substream::EDGE - 1) as usize].signed_in(context % 3, v);
        }
        let payload = LevelPayload {
            round_splits: vec![1],
            substreams,
            ..LevelPayload::default()
        };
        let params = StreamParams {
            codec: ChunkCodec::RansAlways { lanes },
            rans_chunk_limit: limit,
            ..StreamParams::default()
        };
        let bytes = frame_level(&payload, None, &params).bytes;
        let header =
            LevelHeader::parse(&bytes, false, crate::LevelRules::TEST).expect("level header");
        let lengths = (0..header.chunk_count)
            .map(|c| header.chunk(c).expect("chunk").raw_len)
            .collect();
        (bytes, lengths)
    }

    /// Values of a narrow spread, then a wide one, then narrow again: the
    /// writer cuts the substream where the spread changes.
    #[test]
    fn the_writer_cuts_where_the_values_change() {
        let values: Vec<(u8, i32)> = (0..3 * 40_960)
            .map(|i: usize| {
                let wide = (40_960..81_920).contains(&i);
                let v = (i.wrapping_mul(2_654_435_761) >> 7) as i32;
                ((i % 3) as u8, if wide { v % 4000 } else { v % 3 })
            })
            .collect();
        let (_, lengths) = edge_level(&values, 4, 1 << 18);
        // Cuts at the two changes (runs of 2^h aligned blocks of 4,096
        // values meet there), fewer chunks than blocks.
        let cuts: Vec<u32> = lengths
            .iter()
            .scan(0, |at, &l| {
                *at += l;
                Some(*at)
            })
            .collect();
        assert!(
            cuts.contains(&40_960) && cuts.contains(&81_920),
            "{lengths:?}"
        );
        assert_eq!(cuts.last(), Some(&122_880));
        assert!(lengths.len() < 30, "{lengths:?}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// Chunks cut at different lengths read back every value: their
        /// lengths add up, none passes the limit, and the values drift
        /// (their spread changes every `drift` values) so that cuts fall
        /// in the middle of the substream.
        #[test]
        fn values_cut_into_uneven_rans_chunks_read_back(
            n in 1usize..40_000,
            drift in 500usize..20_000,
            lanes in 1u8..6,
            limit in prop_oneof![Just(1u32 << 18), 4_097u32..40_000, 1u32..5_000],
            seed in any::<u64>(),
        ) {
            let mut x = seed | 1;
            let values: Vec<(u8, i32)> = (0..n)
                .map(|i| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    let spread = if (i / drift).is_multiple_of(2) { 4 } else { 3000 };
                    ((i % 3) as u8, (x % spread) as i32 - (spread / 2) as i32)
                })
                .collect();
            let (bytes, lengths) = edge_level(&values, lanes, limit);
            prop_assert_eq!(lengths.iter().map(|&l| l as usize).sum::<usize>(), n);
            prop_assert!(lengths.iter().all(|&l| l >= 1 && l <= limit));
            let header = LevelHeader::parse(&bytes, false, crate::LevelRules::TEST).expect("level header");
            let mut memory = slot_memory(lanes);
            let mut inflater = Inflater::new();
            let buffers = slot_buffers(&mut memory);
            let mut subs = Substreams::open(&bytes, header, 1, buffers, &mut inflater, lanes);
            let slot = (substream::EDGE - 1) as usize;
            for (i, &(context, v)) in values.iter().enumerate() {
                prop_assert_eq!(subs.signed(slot, context % 3), Ok(v), "value {}", i);
            }
            prop_assert_eq!(subs.finish(), Ok(()));
        }
    }
}
