//! The level table: where each level's bytes lie and what it yields (SPEC §4).

use crate::bytes::{Cursor, crc32, f32_at, u32_at, u64_at};
use crate::level_header::LevelRules;
use crate::limits::{HEADER_LEN, LEVEL_ENTRY_LEN};
use crate::{ChecksumScope, Error, Header, LevelHeader};

/// One level-table entry (SPEC §4.1). Level 0 is the base mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelInfo {
    /// Byte offset of the level from the start of the stream.
    pub offset: u64,
    /// Byte length of the level: fetch `offset .. offset + length`.
    pub length: u32,
    /// Vertex count after this level is applied.
    pub vertex_count: u32,
    /// Triangle count after this level is applied.
    pub triangle_count: u32,
    /// Refinement rounds in this level (0 for the base mesh).
    pub round_count: u32,
    /// Encoder's estimate of the distance from this level's surface to the
    /// original, in model units (informative; decoders do not interpret it).
    pub geometric_error: f32,
}

/// What [`LevelTable::get`] answers past the table's end.
const EMPTY_ENTRY: LevelInfo = LevelInfo {
    offset: 0,
    length: 0,
    vertex_count: 0,
    triangle_count: 0,
    round_count: 0,
    geometric_error: 0.0,
};

/// The validated level table, borrowed from the stream: fixed 32-byte
/// entries (SPEC §4.1) or, 3.12, compact ones (§4.3).
#[derive(Clone, Copy, Debug)]
pub struct LevelTable<'h> {
    /// The entries, without the table's CRC.
    bytes: &'h [u8],
    count: u16,
    compact: bool,
    /// Where level 0 starts: the end of the table.
    head_len: u64,
}

/// Bytes from the stream start to the end of a fixed level table, checksum
/// included (SPEC §4.1, §4.2); [`Header::head_len`] for either table.
pub fn fixed_head_len(level_count: u16) -> usize {
    HEADER_LEN + LEVEL_ENTRY_LEN * level_count as usize + 4
}

/// A table entry as read, its counts in exact integers so that a count
/// past its capacity is found before it is narrowed (SPEC §4.2, §4.3).
struct ReadEntry {
    info: LevelInfo,
    vertex_count: u64,
    triangle_count: u64,
}

/// Reads compact entries from the start (SPEC §4.3): offsets from the
/// lengths before, counts as the sums of their steps.
struct CompactEntries<'h> {
    cursor: Cursor<'h>,
    offset: u64,
    vertex_count: u64,
    triangle_count: u64,
}

impl<'h> CompactEntries<'h> {
    fn new(table: &LevelTable<'h>) -> Self {
        CompactEntries {
            cursor: Cursor::new(table.bytes),
            offset: table.head_len,
            vertex_count: 0,
            triangle_count: 0,
        }
    }

    /// `varint()` and `f32` of SPEC §4.3: past the table's end is
    /// `malformed` (its bytes are there and their CRC matched, so the
    /// declared length is what is wrong).
    fn next_entry(&mut self) -> Result<ReadEntry, Error> {
        let past_end = |e: Error| match e {
            Error::Truncated => Error::InvalidLevelTable("an entry runs past the table's length"),
            other => other,
        };
        let c = &mut self.cursor;
        let length = c.varint(Error::InvalidLevelTable).map_err(past_end)?;
        let vertex_step = c.varint(Error::InvalidLevelTable).map_err(past_end)?;
        let triangle_step = c.varint(Error::InvalidLevelTable).map_err(past_end)?;
        let round_count = c.varint(Error::InvalidLevelTable).map_err(past_end)?;
        let geometric_error = c.f32().map_err(past_end)?;
        self.vertex_count += vertex_step as u64;
        self.triangle_count += triangle_step as u64;
        let info = LevelInfo {
            offset: self.offset,
            length,
            vertex_count: self.vertex_count as u32,
            triangle_count: self.triangle_count as u32,
            round_count,
            geometric_error,
        };
        self.offset += length as u64;
        Ok(ReadEntry {
            info,
            vertex_count: self.vertex_count,
            triangle_count: self.triangle_count,
        })
    }
}

impl<'h> LevelTable<'h> {
    /// Parses and validates the table following the header (SPEC §4.2,
    /// §4.3).
    pub fn parse(stream_head: &'h [u8], header: &Header) -> Result<LevelTable<'h>, Error> {
        let end = header.head_len();
        let bytes = stream_head.get(HEADER_LEN..end).ok_or(Error::Truncated)?;
        // A parsed header's table holds its CRC at least; a header built
        // by hand may say otherwise.
        let body_len = bytes
            .len()
            .checked_sub(4)
            .ok_or(Error::InvalidHeader("level table shorter than its CRC"))?;
        let body = &bytes[..body_len];
        if crc32(body) != u32_at(bytes, body.len())? {
            return Err(Error::ChecksumMismatch(ChecksumScope::LevelTable));
        }
        let table = LevelTable {
            bytes: body,
            count: header.level_count,
            compact: header.framing.compact_table(),
            head_len: end as u64,
        };
        table.validate(header)?;
        Ok(table)
    }

    fn validate(&self, header: &Header) -> Result<(), Error> {
        let mut expected_offset = self.head_len;
        let mut previous: Option<LevelInfo> = None;
        let mut compact = CompactEntries::new(self);
        for k in 0..self.count {
            let read = if self.compact {
                // Contiguous by construction; no reserved field.
                compact.next_entry()?
            } else {
                let e = self.fixed_entry(k);
                if u32_at(self.bytes, k as usize * LEVEL_ENTRY_LEN + 28)? != 0 {
                    return Err(Error::InvalidLevelTable("reserved field not zero"));
                }
                if e.offset != expected_offset {
                    return Err(Error::InvalidLevelTable("levels are not contiguous"));
                }
                expected_offset = e.offset + e.length as u64;
                ReadEntry {
                    info: e,
                    vertex_count: e.vertex_count as u64,
                    triangle_count: e.triangle_count as u64,
                }
            };
            let e = read.info;
            if !(e.geometric_error.is_finite() && e.geometric_error >= 0.0) {
                return Err(Error::InvalidLevelTable(
                    "geometric error not finite and >= 0",
                ));
            }
            if read.vertex_count > header.vertex_capacity as u64
                || read.triangle_count > header.triangle_capacity as u64
            {
                return Err(Error::CapacityExceeded);
            }
            match previous {
                None => {
                    if e.vertex_count == 0
                        || e.triangle_count == 0
                        || e.round_count > e.vertex_count
                    {
                        return Err(Error::InvalidLevelTable("base level counts"));
                    }
                }
                Some(p) => {
                    // Every round splits at least one vertex; each split adds
                    // one vertex and one or two triangles (SPEC §7).
                    let added = e.vertex_count.checked_sub(p.vertex_count);
                    let ok = matches!(added, Some(a) if a >= e.round_count && e.round_count > 0)
                        && e.triangle_count > p.triangle_count
                        && (e.triangle_count - p.triangle_count) as u64
                            >= (e.vertex_count - p.vertex_count) as u64
                        && (e.triangle_count - p.triangle_count) as u64
                            <= 2 * (e.vertex_count - p.vertex_count) as u64;
                    if !ok {
                        return Err(Error::InvalidLevelTable(
                            "level counts do not grow consistently",
                        ));
                    }
                }
            }
            previous = Some(e);
        }
        if self.compact && compact.cursor.at != self.bytes.len() {
            return Err(Error::InvalidLevelTable(
                "bytes left after the last entry of a compact table",
            ));
        }
        let last = previous.ok_or(Error::InvalidLevelTable("empty"))?;
        if last.vertex_count != header.vertex_capacity
            || last.triangle_count != header.triangle_capacity
        {
            return Err(Error::InvalidLevelTable(
                "last level differs from the declared capacity",
            ));
        }
        Ok(())
    }

    pub fn len(&self) -> u16 {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The entries in level order, each read once (a compact table from
    /// its start, SPEC §4.3).
    pub fn iter(&self) -> impl Iterator<Item = LevelInfo> + '_ {
        let mut compact = CompactEntries::new(self);
        (0..self.count).map(move |k| {
            if self.compact {
                compact.next_entry().map(|e| e.info).unwrap_or(EMPTY_ENTRY)
            } else {
                self.fixed_entry(k)
            }
        })
    }

    /// Entry `k` (the table was validated on parse; zeros past its end).
    /// A compact table is read from its start (SPEC §4.3): at most 255
    /// entries of up to 24 bytes.
    pub fn get(&self, k: u16) -> LevelInfo {
        if self.compact {
            let mut entries = CompactEntries::new(self);
            let mut e = Err(Error::Truncated);
            for _ in 0..=k.min(self.count) {
                e = entries.next_entry();
            }
            return e.map(|e| e.info).unwrap_or(EMPTY_ENTRY);
        }
        self.fixed_entry(k)
    }

    fn fixed_entry(&self, k: u16) -> LevelInfo {
        let at = k as usize * LEVEL_ENTRY_LEN;
        // The table length was checked in `parse`, so these reads succeed.
        let read = |o: usize| u32_at(self.bytes, at + o).unwrap_or(0);
        LevelInfo {
            offset: u64_at(self.bytes, at).unwrap_or(0),
            length: read(8),
            vertex_count: read(12),
            triangle_count: read(16),
            round_count: read(20),
            geometric_error: f32_at(self.bytes, at + 24).unwrap_or(0.0),
        }
    }

    /// The coarsest level within `max_error` ([`level_within_error`] over
    /// this table).
    pub fn level_within_error(&self, max_error: f32) -> u16 {
        level_within_error(self.iter(), max_error).unwrap_or(0)
    }

    /// Parses level `k`'s header from exactly its bytes (`bytes.len()` is
    /// entry k's length, `Truncated` otherwise) and checks it against
    /// entry `k` (SPEC §5.1): the same round count, no round without
    /// splits, and the splits taking the vertex count from entry `k − 1`'s
    /// (the seed's for the base level) to entry `k`'s.
    pub fn level_header<'l>(
        &self,
        k: u16,
        bytes: &'l [u8],
        rules: LevelRules,
    ) -> Result<LevelHeader<'l>, Error> {
        if k >= self.count {
            return Err(Error::NoSuchLevel {
                level: k,
                count: self.count,
            });
        }
        let info = self.get(k);
        if bytes.len() as u64 != info.length as u64 {
            return Err(Error::Truncated);
        }
        let is_base = k == 0;
        let header = LevelHeader::parse(bytes, is_base, rules)?;
        if header.round_count != info.round_count {
            return Err(Error::LevelCountMismatch);
        }
        let before = if is_base {
            header.seed_vertices as u64
        } else {
            self.get(k - 1).vertex_count as u64
        };
        let mut added = 0u64;
        for s in header.split_counts() {
            if s == 0 {
                return Err(Error::InvalidLevelHeader("a round without splits"));
            }
            added += s as u64;
        }
        if before + added != info.vertex_count as u64 {
            return Err(Error::LevelCountMismatch);
        }
        // 3.5: every split adds triangles, so the seed holds at most level
        // 0's; failing here, before the seed is read, gives every decoder
        // the same class whether its memory holds level 0 or the stream.
        if is_base && header.seed_triangles > info.triangle_count {
            return Err(Error::LevelCountMismatch);
        }
        Ok(header)
    }

    /// End of the stream: offset just past the last level (SPEC §4.2
    /// `stream_len`).
    pub fn stream_len(&self) -> u64 {
        let last = self.get(self.count - 1);
        last.offset + last.length as u64
    }
}

/// The coarsest level whose geometric error (SPEC §4.1) is at most
/// `max_error`: the first of `levels`, in level order, with
/// `geometric_error <= max_error`, or the last level when none is (or when
/// `max_error` is NaN). A client decodes levels 0 ..= that one to stay
/// within the bound, for example `max_error` = the model-space size of a
/// pixel at the object's distance (screen-space error selection). `None`
/// only for an empty table. The field is the encoder's estimate, in model
/// units (metres for a DEM encoded with `--geographic`); the format does
/// not interpret it, so this is a client's choice, not a decoding rule.
pub fn level_within_error(
    levels: impl IntoIterator<Item = LevelInfo>,
    max_error: f32,
) -> Option<u16> {
    let mut last = None;
    for (k, level) in levels.into_iter().enumerate() {
        let k = u16::try_from(k).ok()?;
        if level.geometric_error <= max_error {
            return Some(k);
        }
        last = Some(k);
    }
    last
}

/// Serialises a level table (entries then CRC-32) for encoders.
pub fn write_level_table(entries: &[LevelInfo], out: &mut [u8]) {
    for (k, e) in entries.iter().enumerate() {
        let o = &mut out[k * LEVEL_ENTRY_LEN..(k + 1) * LEVEL_ENTRY_LEN];
        o.fill(0);
        o[0..8].copy_from_slice(&e.offset.to_le_bytes());
        o[8..12].copy_from_slice(&e.length.to_le_bytes());
        o[12..16].copy_from_slice(&e.vertex_count.to_le_bytes());
        o[16..20].copy_from_slice(&e.triangle_count.to_le_bytes());
        o[20..24].copy_from_slice(&e.round_count.to_le_bytes());
        o[24..28].copy_from_slice(&e.geometric_error.to_le_bytes());
    }
    let body = entries.len() * LEVEL_ENTRY_LEN;
    let crc = crc32(&out[..body]);
    out[body..body + 4].copy_from_slice(&crc.to_le_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    fn levels(errors: &[f32]) -> impl Iterator<Item = LevelInfo> + '_ {
        errors.iter().map(|&geometric_error| LevelInfo {
            offset: 0,
            length: 0,
            vertex_count: 0,
            triangle_count: 0,
            round_count: 0,
            geometric_error,
        })
    }

    #[test]
    fn the_coarsest_level_within_the_bound_is_chosen() {
        let errors = [4.0, 2.0, 1.0, 0.5, 0.0];
        assert_eq!(level_within_error(levels(&errors), 10.0), Some(0));
        assert_eq!(level_within_error(levels(&errors), 4.0), Some(0));
        assert_eq!(level_within_error(levels(&errors), 3.9), Some(1));
        assert_eq!(level_within_error(levels(&errors), 0.7), Some(3));
        assert_eq!(level_within_error(levels(&errors), 0.0), Some(4));
        // Nothing is that exact, or the bound is not a number: the finest.
        assert_eq!(level_within_error(levels(&errors), -1.0), Some(4));
        assert_eq!(level_within_error(levels(&errors), f32::NAN), Some(4));
        assert_eq!(level_within_error(levels(&[]), 1.0), None);
    }

    #[test]
    fn a_level_header_is_checked_against_its_entry() {
        use crate::handmade::tetra_stream;
        use crate::writer::ChunkCodec;
        let stream = tetra_stream(ChunkCodec::Deflate(6));
        let header = Header::parse(&stream).unwrap();
        let table = LevelTable::parse(&stream, &header).unwrap();
        let bytes = |k: u16| {
            let e = table.get(k);
            &stream[e.offset as usize..(e.offset + e.length as u64) as usize]
        };
        for k in 0..table.len() {
            let level = table
                .level_header(k, bytes(k), header.level_rules())
                .unwrap();
            assert_eq!(level.round_count, table.get(k).round_count);
        }
        // Not exactly the level's bytes, or a level that is not there.
        let short = &bytes(0)[..bytes(0).len() - 1];
        assert_eq!(
            table.level_header(0, short, header.level_rules()).err(),
            Some(Error::Truncated)
        );
        let beyond = table.len();
        assert_eq!(
            table
                .level_header(beyond, bytes(0), header.level_rules())
                .err(),
            Some(Error::NoSuchLevel {
                level: beyond,
                count: table.len()
            })
        );
    }

    #[test]
    fn a_hand_built_header_with_a_table_too_short_is_refused() {
        use crate::handmade::tetra_stream;
        use crate::writer::ChunkCodec;
        let stream = tetra_stream(ChunkCodec::Stored);
        let mut header = Header::parse(&stream).unwrap();
        for table_len in [0, 3, u32::MAX] {
            header.table_len = table_len;
            assert!(LevelTable::parse(&stream, &header).is_err(), "{table_len}");
        }
    }

    #[test]
    fn an_estimate_that_grows_again_does_not_hide_the_first_level_within() {
        // Estimates need not fall level by level: the first within wins.
        let errors = [3.0, 1.0, 2.0, 0.0];
        assert_eq!(level_within_error(levels(&errors), 1.5), Some(1));
        assert_eq!(level_within_error(levels(&errors), 2.5), Some(1));
    }
}
