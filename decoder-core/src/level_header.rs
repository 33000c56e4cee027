//! A level's own header: rounds, the plane and wing policies, the deficit
//! contexts, split counts and the chunk directory (SPEC §5.1, §5.2), in
//! the `fixed` framing or (3.11) the `compact` one (SPEC §5.1.1).

use crate::bytes::{Cursor, crc32, u8_at, u16_at, u32_at};
use crate::context::DeficitContexts;
use crate::header::{Framing, PositionMode, Schedule};
use crate::limits::{CHUNK_ENTRY_LEN, codec, substream};
use crate::positions_first::{RecordOrder, Ties};
use crate::predict::PlanePolicy;
use crate::wing_order::WingPolicy;
use crate::{ChecksumScope, Error};

/// Offset of the plane policy byte (SPEC §5.1), followed by the wing policy
/// byte (3.2), the deficit contexts byte (3.3) and the record order byte
/// (3.7).
const PLANE_AT: usize = 8;
/// Offset of level 0's seed counts (SPEC §5.1).
const SEED_AT: usize = 12;
/// Offset of the split counts: `H` of SPEC §5.1.
const fn split_counts_at(is_base: bool) -> usize {
    if is_base { 20 } else { 12 }
}

/// What a level header is checked against that the stream header says
/// (SPEC §5.1): the largest stored or deflate chunk, the schedule (the
/// flags' table count, the deficit contexts allowed), the position mode
/// (where `positions-first` is allowed) and the framing (how the header is
/// laid out, 3.11). [`crate::Header::level_rules`] gives a stream's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelRules {
    pub max_chunk_len: u32,
    pub schedule: Schedule,
    pub position_mode: PositionMode,
    pub framing: Framing,
}

impl LevelRules {
    /// Rules for unit tests that frame levels with the writer's defaults:
    /// 64 KiB chunks, split valences, constrained mode, compact framing.
    #[cfg(test)]
    pub(crate) const TEST: LevelRules = LevelRules {
        max_chunk_len: 1 << 16,
        schedule: Schedule::SplitValences,
        position_mode: PositionMode::Constrained,
        framing: Framing::Compact,
    };
}

/// One chunk-directory entry (SPEC §5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChunkEntry {
    pub substream: u8,
    pub codec: u8,
    pub raw_len: u32,
    pub stored_len: u32,
    pub crc: u32,
}

/// The parsed level header, borrowing the level's bytes.
#[derive(Clone, Copy, Debug)]
pub struct LevelHeader<'l> {
    pub round_count: u32,
    /// How this level's position residuals use the split's plane (SPEC
    /// §5.1, §7.4); the raw byte is checked by [`LevelHeader::parse`].
    pub plane_policy: PlanePolicy,
    plane_byte: u8,
    /// How this level codes the wings (SPEC §5.1, §7.4; format 3.2); the
    /// raw byte is checked by [`LevelHeader::parse`].
    pub wing_policy: WingPolicy,
    wing_byte: u8,
    /// Which contexts code the level's split-valence symbols (SPEC §5.1,
    /// §5.5.5; format 3.3); the raw byte is checked by [`LevelHeader::parse`].
    pub deficit_contexts: DeficitContexts,
    deficit_byte: u8,
    /// How this level's split records are read (SPEC §5.1, §7.4; format
    /// 3.7); the raw byte is checked by [`LevelHeader::parse`].
    pub record_order: RecordOrder,
    /// Under `positions-first`, how the wing choices' ties are broken
    /// (the same byte; format 3.8).
    pub ties: Ties,
    record_byte: u8,
    /// The stream's position mode: `positions-first` needs constrained
    /// mode.
    mode: PositionMode,
    /// The stream's schedule (SPEC §3.2, 3.6): it sets how many contexts
    /// the flags substream has, and forbids deficit contexts other than
    /// `plain` under `every-vertex`.
    pub schedule: Schedule,
    /// Level 0 only: vertex and triangle counts of the seed mesh its rounds
    /// start from (SPEC §5.1, §6.3); `(0, 0)` for other levels.
    pub seed_vertices: u32,
    pub seed_triangles: u32,
    /// How the split counts and the directory are coded (3.11).
    pub framing: Framing,
    split_counts: &'l [u8],
    directory: &'l [u8],
    pub chunk_count: u32,
    /// Offset of the first chunk payload within the level bytes.
    pub payload_start: usize,
}

impl<'l> LevelHeader<'l> {
    /// Parses and validates the level header of `level` (SPEC §5.1) of a
    /// stream whose header sets `rules` (SPEC §3.2).
    /// `is_base` selects which substream ids are allowed.
    pub fn parse(level: &'l [u8], is_base: bool, rules: LevelRules) -> Result<Self, Error> {
        let fields = match rules.framing {
            Framing::Fixed => Fields::fixed(level, is_base)?,
            Framing::CompactLevels | Framing::Compact => Fields::compact(level, is_base)?,
        };
        let crc_at = fields.crc_at;
        if crc32(&level[..crc_at]) != u32_at(level, crc_at)? {
            return Err(Error::ChecksumMismatch(ChecksumScope::LevelHeader));
        }
        let [plane_byte, wing_byte, deficit_byte, record_byte] = fields.policies;
        let header = LevelHeader {
            round_count: fields.round_count,
            plane_policy: PlanePolicy::from_byte(plane_byte).unwrap_or(PlanePolicy::Off),
            plane_byte,
            wing_policy: WingPolicy::from_byte(wing_byte).unwrap_or(WingPolicy::Ranks),
            wing_byte,
            deficit_contexts: DeficitContexts::from_byte(deficit_byte)
                .unwrap_or(DeficitContexts::Plain),
            deficit_byte,
            record_order: RecordOrder::from_byte(record_byte).unwrap_or_default(),
            ties: Ties::from_record_byte(record_byte).unwrap_or_default(),
            record_byte,
            mode: rules.position_mode,
            schedule: rules.schedule,
            seed_vertices: fields.seed[0],
            seed_triangles: fields.seed[1],
            framing: rules.framing,
            split_counts: &level[fields.counts_at..fields.dir_start],
            directory: &level[fields.dir_start..crc_at],
            chunk_count: fields.chunk_count,
            payload_start: crc_at + 4,
        };
        header.validate(level.len(), is_base, rules.max_chunk_len)?;
        Ok(header)
    }

    fn validate(&self, level_len: usize, is_base: bool, max_chunk_len: u32) -> Result<(), Error> {
        if PlanePolicy::from_byte(self.plane_byte).is_none() {
            return Err(Error::InvalidLevelHeader("unknown plane policy"));
        }
        if WingPolicy::from_byte(self.wing_byte).is_none() {
            return Err(Error::InvalidLevelHeader("unknown wing policy"));
        }
        match DeficitContexts::from_byte(self.deficit_byte) {
            None => return Err(Error::InvalidLevelHeader("unknown contexts")),
            Some(DeficitContexts::Valence) if self.schedule == Schedule::EveryVertex => {
                return Err(Error::InvalidLevelHeader(
                    "deficit contexts valence under the schedule every-vertex",
                ));
            }
            Some(DeficitContexts::SplitHistory) if self.schedule == Schedule::SplitValences => {
                return Err(Error::InvalidLevelHeader(
                    "flag contexts split-history under the schedule split-valences",
                ));
            }
            Some(_) => {}
        }
        match RecordOrder::from_byte(self.record_byte) {
            None => return Err(Error::InvalidLevelHeader("unknown record order")),
            Some(RecordOrder::PositionsFirst)
                if self.mode != PositionMode::Constrained
                    || self.plane_policy != PlanePolicy::Height =>
            {
                return Err(Error::InvalidLevelHeader(
                    "record order positions-first outside constrained mode or the plane policy height",
                ));
            }
            Some(_) => {}
        }
        if is_base && (self.seed_vertices == 0 || self.seed_triangles == 0) {
            return Err(Error::InvalidLevelHeader("empty seed mesh"));
        }
        let allowed = if is_base {
            substream::FLAGS..=substream::BASE_DEFICITS
        } else {
            substream::FLAGS..=substream::PLACEMENT
        };
        let mut previous_id = 0u8;
        let mut previous_rans = false;
        let mut payload = self.payload_start as u64;
        for e in self.chunks() {
            let e = e?;
            if !allowed.contains(&e.substream) {
                return Err(Error::InvalidLevelHeader(
                    "substream id not allowed in this level",
                ));
            }
            if e.substream < previous_id {
                return Err(Error::InvalidLevelHeader("chunks not ordered by substream"));
            }
            let rans = e.codec == codec::RANS;
            if e.substream == previous_id && rans != previous_rans {
                return Err(Error::InvalidLevelHeader(
                    "a substream mixes rANS and byte-codec chunks",
                ));
            }
            previous_id = e.substream;
            previous_rans = rans;
            // `max_chunk_len` bounds what a decoder buffers: byte-codec
            // chunks. A rANS chunk needs only its tables and lanes, whatever
            // its value count (SPEC §5.2, format 3.4).
            if e.raw_len == 0 || (!rans && e.raw_len > max_chunk_len) {
                return Err(Error::InvalidLevelHeader(
                    "chunk raw length 0, or a byte-codec chunk above the header maximum",
                ));
            }
            match e.codec {
                codec::STORED if e.stored_len != e.raw_len => {
                    return Err(Error::InvalidLevelHeader("stored chunk lengths differ"));
                }
                codec::STORED | codec::DEFLATE | codec::RANS => {}
                _ => return Err(Error::InvalidLevelHeader("unknown codec")),
            }
            payload += e.stored_len as u64;
        }
        if payload != level_len as u64 {
            return Err(if payload > level_len as u64 {
                Error::Truncated
            } else {
                Error::InvalidLevelHeader("bytes after the last chunk")
            });
        }
        Ok(())
    }

    /// The declared split counts of the rounds, in order (SPEC §5.1,
    /// §5.1.1): under the compact framing a round's count is found only by
    /// reading the ones before it, so a decoder keeps this iterator.
    pub fn split_counts(&self) -> SplitCounts<'l> {
        SplitCounts {
            cursor: Cursor::new(self.split_counts),
            framing: self.framing,
        }
    }

    /// The directory entries in order (SPEC §5.1, §5.1.1).
    pub fn chunks(&self) -> impl Iterator<Item = Result<ChunkEntry, Error>> + 'l {
        let header = *self;
        let mut at = 0;
        (0..self.chunk_count).map(move |_| {
            let (e, next) = header.entry_at(at)?;
            at = next;
            Ok(e)
        })
    }

    /// Directory entry `k` (SPEC §5.1): reads the `k` entries before it
    /// under the compact framing; decoders walk [`Self::entry_at`] instead.
    pub fn chunk(&self, k: u32) -> Result<ChunkEntry, Error> {
        self.chunks()
            .nth(k as usize)
            .unwrap_or(Err(Error::Truncated))
    }

    /// The directory entry that starts `at` bytes into the directory, and
    /// where the next one starts (SPEC §5.1, §5.1.1).
    pub fn entry_at(&self, at: usize) -> Result<(ChunkEntry, usize), Error> {
        let mut c = Cursor {
            bytes: self.directory,
            at,
        };
        let e = match self.framing {
            Framing::Fixed => {
                if u16_at(self.directory, at + 2)? != 0 {
                    return Err(Error::InvalidLevelHeader("reserved field not zero"));
                }
                c.at += CHUNK_ENTRY_LEN;
                ChunkEntry {
                    substream: u8_at(self.directory, at)?,
                    codec: u8_at(self.directory, at + 1)?,
                    raw_len: u32_at(self.directory, at + 4)?,
                    stored_len: u32_at(self.directory, at + 8)?,
                    crc: u32_at(self.directory, at + 12)?,
                }
            }
            Framing::CompactLevels | Framing::Compact => {
                let id_codec = c.byte()?;
                ChunkEntry {
                    substream: id_codec & 0x0F,
                    codec: id_codec >> 4,
                    raw_len: c.varint(Error::InvalidLevelHeader)?,
                    stored_len: c.varint(Error::InvalidLevelHeader)?,
                    crc: c.u32()?,
                }
            }
        };
        Ok((e, c.at))
    }
}

/// Where a level header's parts lie, found before its CRC is checked.
struct Fields {
    round_count: u32,
    chunk_count: u32,
    policies: [u8; 4],
    seed: [u32; 2],
    counts_at: usize,
    dir_start: usize,
    crc_at: usize,
}

impl Fields {
    /// The fixed framing (SPEC §5.1): every part at an offset computed from
    /// the two counts.
    fn fixed(level: &[u8], is_base: bool) -> Result<Fields, Error> {
        let round_count = u32_at(level, 0)?;
        let chunk_count = u32_at(level, 4)?;
        let counts_at = split_counts_at(is_base);
        if level.len() < counts_at {
            return Err(Error::Truncated);
        }
        let seed = if is_base {
            [u32_at(level, SEED_AT)?, u32_at(level, SEED_AT + 4)?]
        } else {
            [0, 0]
        };
        let policies = core::array::from_fn(|i| level[PLANE_AT + i]);
        let splits_len = (round_count as usize)
            .checked_mul(4)
            .ok_or(Error::Truncated)?;
        let dir_len = (chunk_count as usize)
            .checked_mul(CHUNK_ENTRY_LEN)
            .ok_or(Error::Truncated)?;
        let dir_start = counts_at.checked_add(splits_len).ok_or(Error::Truncated)?;
        let crc_at = dir_start.checked_add(dir_len).ok_or(Error::Truncated)?;
        if level.len() < crc_at.checked_add(4).ok_or(Error::Truncated)? {
            return Err(Error::Truncated);
        }
        Ok(Fields {
            round_count,
            chunk_count,
            policies,
            seed,
            counts_at,
            dir_start,
            crc_at,
        })
    }

    /// The compact framing (SPEC §5.1.1, 3.11): read field by field, each
    /// step at least one byte, so a count larger than the level ends in
    /// `Truncated` after at most the level's length in steps.
    fn compact(level: &[u8], is_base: bool) -> Result<Fields, Error> {
        let mut c = Cursor::new(level);
        let round_count = c.varint(Error::InvalidLevelHeader)?;
        let chunk_count = c.varint(Error::InvalidLevelHeader)?;
        let policies = [c.byte()?, c.byte()?, c.byte()?, c.byte()?];
        let seed = if is_base {
            [
                c.varint(Error::InvalidLevelHeader)?,
                c.varint(Error::InvalidLevelHeader)?,
            ]
        } else {
            [0, 0]
        };
        let counts_at = c.at;
        for _ in 0..round_count {
            c.varint(Error::InvalidLevelHeader)?;
        }
        let dir_start = c.at;
        for _ in 0..chunk_count {
            c.byte()?;
            c.varint(Error::InvalidLevelHeader)?;
            c.varint(Error::InvalidLevelHeader)?;
            c.u32()?;
        }
        let crc_at = c.at;
        c.u32()?;
        Ok(Fields {
            round_count,
            chunk_count,
            policies,
            seed,
            counts_at,
            dir_start,
            crc_at,
        })
    }
}

/// The split counts of a level's rounds, in order
/// ([`LevelHeader::split_counts`]); 0 past the last (a validated header
/// has none).
#[derive(Clone, Copy, Debug)]
pub struct SplitCounts<'l> {
    cursor: Cursor<'l>,
    framing: Framing,
}

impl Iterator for SplitCounts<'_> {
    type Item = u32;

    fn next(&mut self) -> Option<u32> {
        if self.cursor.at >= self.cursor.bytes.len() {
            return None;
        }
        match self.framing {
            Framing::Fixed => self.cursor.u32().ok(),
            Framing::CompactLevels | Framing::Compact => {
                self.cursor.varint(Error::InvalidLevelHeader).ok()
            }
        }
    }
}
