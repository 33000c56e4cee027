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

use crate::inflate::Inflater;
use crate::level_header::LevelHeader;
use crate::limits::rans::TABLE_WORDS;
use crate::limits::substream::SLOTS;
use crate::limits::{codec, substream};
use crate::rans::{self, LANE_WORDS};
use crate::{ChecksumScope, Error, bytes::crc32};

struct Reader<'b> {
    id: u8,
    next_chunk: u32,
    end_chunk: u32,
    payload_at: usize,
    /// Byte codecs: the current chunk's raw bytes.
    buf: &'b mut [u8],
    /// rANS: the tables (`TABLE_WORDS`), then `LANE_WORDS` per lane.
    words: &'b mut [u32],
    rans: bool,
    /// Byte codecs: bytes of the chunk and bytes read; rANS: values.
    len: usize,
    pos: usize,
    /// rANS: lane of the next value.
    lane: usize,
    bit_byte: u8,
    bit_index: u8,
}

/// The open substreams of one level.
pub struct Substreams<'l, 'b> {
    level: &'l [u8],
    header: LevelHeader<'l>,
    readers: [Reader<'b>; SLOTS],
    inflater: &'b mut Inflater,
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
        let mut i = 0u8;
        let mut readers = buffers.map(|buf| {
            let id = first_id + i;
            i += 1;
            // The level header was validated: a substream's chunks are all
            // rANS or all byte codecs (SPEC §5.1).
            let rans = (0..header.chunk_count).any(|k| {
                header
                    .chunk(k)
                    .is_ok_and(|e| e.substream == id && e.codec == codec::RANS)
            });
            let words_needed = TABLE_WORDS + LANE_WORDS * lane_count as usize;
            let (buf, words): (&mut [u8], &mut [u32]) = if rans {
                let words = bytemuck::try_cast_slice_mut::<u8, u32>(buf).unwrap_or(&mut []);
                let len = words.len().min(words_needed);
                (&mut [], &mut words[..len])
            } else {
                (buf, &mut [])
            };
            Reader {
                id,
                next_chunk: 0,
                end_chunk: 0,
                payload_at: 0,
                buf,
                words,
                rans,
                len: 0,
                pos: 0,
                lane: 0,
                bit_byte: 0,
                bit_index: 8,
            }
        });
        // Chunks are ordered by substream id (validated), so each substream's
        // chunks form one run of the directory and one run of the payload.
        let mut payload = header.payload_start;
        let mut first_seen = [false; SLOTS];
        for k in 0..header.chunk_count {
            // The directory was validated when the header was parsed.
            let Ok(e) = header.chunk(k) else { break };
            let slot = e.substream.wrapping_sub(first_id) as usize;
            if let Some(r) = readers.get_mut(slot) {
                if !first_seen[slot] {
                    first_seen[slot] = true;
                    r.next_chunk = k;
                    r.payload_at = payload;
                }
                r.end_chunk = k + 1;
            }
            payload += e.stored_len as usize;
        }
        Substreams {
            level,
            header,
            readers,
            inflater,
        }
    }

    fn refill(&mut self, slot: usize) -> Result<(), Error> {
        let r = &mut self.readers[slot];
        if r.next_chunk >= r.end_chunk {
            return Err(Error::RecordCountMismatch(r.id));
        }
        let e = self.header.chunk(r.next_chunk)?;
        let stored = self
            .level
            .get(r.payload_at..r.payload_at + e.stored_len as usize)
            .ok_or(Error::Truncated)?;
        if crc32(stored) != e.crc {
            return Err(Error::ChecksumMismatch(ChecksumScope::Chunk));
        }
        let raw = e.raw_len as usize;
        if r.rans {
            open_rans_chunk(self.level, r, e.stored_len as usize, e.raw_len)?;
        } else {
            let out = r.buf.get_mut(..raw).ok_or(Error::CapacityExceeded)?;
            match e.codec {
                codec::STORED => out.copy_from_slice(stored),
                _ => self.inflater.inflate_exact(stored, out)?,
            }
        }
        r.next_chunk += 1;
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
    #[inline]
    fn rans_value(&mut self, slot: usize, context: u8) -> Result<u32, Error> {
        let r = &mut self.readers[slot];
        if r.pos == r.len {
            self.refill(slot)?;
        }
        let r = &mut self.readers[slot];
        let (table, lanes) = r.words.split_at_mut(TABLE_WORDS);
        let at = r.lane * LANE_WORDS;
        let value = rans::decode_value(
            self.level,
            table,
            context as usize,
            &mut lanes[at..at + LANE_WORDS],
        )?;
        r.pos += 1;
        r.lane += 1;
        if r.lane * LANE_WORDS == lanes.len() {
            r.lane = 0;
        }
        // The chunk's last value: every lane must end exactly here.
        if r.pos == r.len && !rans::lanes_exhausted(lanes) {
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
    #[inline]
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
            return match self.rans_value(slot, context)? {
                0 => Ok(false),
                1 => Ok(true),
                _ => Err(Error::ValueOutOfRange(self.readers[slot].id)),
            };
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

    /// Next LEB128 varint of `slot`: at most 5 bytes, at most 32 bits,
    /// minimal (a multi-byte varint does not end in a zero byte) (SPEC §5.4).
    /// Under rANS, one value of the hybrid code (SPEC §5.5).
    #[inline]
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
    #[inline]
    pub fn signed(&mut self, slot: usize, context: u8) -> Result<i32, Error> {
        let u = self.varint(slot, context)?;
        Ok(((u >> 1) as i32) ^ -((u & 1) as i32))
    }

    /// Checks that every substream was read to its end and that the padding
    /// bits of bit substreams are zero (SPEC §5.4).
    pub fn finish(&self) -> Result<(), Error> {
        for r in &self.readers {
            let padding_clear = r.bit_index == 8 || (r.bit_byte >> r.bit_index) == 0;
            if r.pos != r.len || r.next_chunk != r.end_chunk || !padding_clear {
                return Err(Error::RecordCountMismatch(r.id));
            }
        }
        Ok(())
    }
}

/// Loads a rANS chunk of `values` values whose `stored_len` payload bytes
/// start at `r.payload_at` (SPEC §5.5.2, §5.5.3): its tables and lanes.
fn open_rans_chunk(
    level: &[u8],
    r: &mut Reader<'_>,
    stored_len: usize,
    values: u32,
) -> Result<(), Error> {
    let (table, lanes) = r.words.split_at_mut(TABLE_WORDS.min(r.words.len()));
    if lanes.is_empty() {
        return Err(Error::CapacityExceeded);
    }
    let (mut at, end) = (r.payload_at, r.payload_at + stored_len);
    let contexts = substream::CONTEXTS[r.id as usize] as usize;
    rans::read_tables(level, &mut at, end, contexts, table)?;
    rans::open_lanes(level, at, end, values, lanes)?;
    r.lane = 0;
    Ok(())
}
