//! Reading a level's substreams chunk by chunk (SPEC §5.3, §5.4).
//!
//! Each substream is a byte sequence cut into chunks of at most
//! `max_chunk_len` raw bytes; a chunk is checked against its CRC-32, then
//! copied (stored) or inflated (deflate) into that substream's buffer.
//! Values never need to be aligned to chunk boundaries.

use crate::inflate::Inflater;
use crate::level_header::LevelHeader;
use crate::limits::{codec, substream::SLOTS};
use crate::{ChecksumScope, Error, bytes::crc32};

struct Reader<'b> {
    id: u8,
    next_chunk: u32,
    end_chunk: u32,
    payload_at: usize,
    buf: &'b mut [u8],
    len: usize,
    pos: usize,
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
    /// slot `i` reading id `first_id + i` into `buffers[i]`.
    pub fn open(
        level: &'l [u8],
        header: LevelHeader<'l>,
        first_id: u8,
        buffers: [&'b mut [u8]; SLOTS],
        inflater: &'b mut Inflater,
    ) -> Self {
        let mut i = 0u8;
        let mut readers = buffers.map(|buf| {
            let r = Reader {
                id: first_id + i,
                next_chunk: 0,
                end_chunk: 0,
                payload_at: 0,
                buf,
                len: 0,
                pos: 0,
                bit_byte: 0,
                bit_index: 8,
            };
            i += 1;
            r
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
        let out = r.buf.get_mut(..raw).ok_or(Error::CapacityExceeded)?;
        match e.codec {
            codec::STORED => out.copy_from_slice(stored),
            _ => self.inflater.inflate_exact(stored, out)?,
        }
        r.next_chunk += 1;
        r.payload_at += e.stored_len as usize;
        r.len = raw;
        r.pos = 0;
        Ok(())
    }

    /// Next byte of the substream in `slot`.
    #[inline]
    pub fn byte(&mut self, slot: usize) -> Result<u8, Error> {
        let r = &mut self.readers[slot];
        if r.pos == r.len {
            self.refill(slot)?;
        }
        let r = &mut self.readers[slot];
        let b = r.buf[r.pos];
        r.pos += 1;
        Ok(b)
    }

    /// Next bit (least significant first within each byte) of `slot`.
    #[inline]
    pub fn bit(&mut self, slot: usize) -> Result<bool, Error> {
        if self.readers[slot].bit_index == 8 {
            let b = self.byte(slot)?;
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
    #[inline]
    pub fn varint(&mut self, slot: usize) -> Result<u32, Error> {
        let mut value = 0u32;
        for i in 0..5 {
            let b = self.byte(slot)?;
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
    pub fn signed(&mut self, slot: usize) -> Result<i32, Error> {
        let u = self.varint(slot)?;
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
