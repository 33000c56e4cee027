//! A level's own header: rounds, the plane and wing policies, the deficit
//! contexts, split counts and the chunk directory (SPEC §5.1, §5.2).

use crate::bytes::{crc32, u8_at, u16_at, u32_at};
use crate::context::DeficitContexts;
use crate::header::{PositionMode, Schedule};
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
/// flags' table count, the deficit contexts allowed) and the position mode
/// (where `positions-first` is allowed). [`crate::Header::level_rules`]
/// gives a stream's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelRules {
    pub max_chunk_len: u32,
    pub schedule: Schedule,
    pub position_mode: PositionMode,
}

impl LevelRules {
    /// Rules for unit tests that frame levels by hand: 64 KiB chunks,
    /// split valences, constrained mode.
    #[cfg(test)]
    pub(crate) const TEST: LevelRules = LevelRules {
        max_chunk_len: 1 << 16,
        schedule: Schedule::SplitValences,
        position_mode: PositionMode::Constrained,
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
        let LevelRules {
            max_chunk_len,
            schedule,
            position_mode: mode,
        } = rules;
        let round_count = u32_at(level, 0)?;
        let chunk_count = u32_at(level, 4)?;
        let counts_at = split_counts_at(is_base);
        if level.len() < counts_at {
            return Err(Error::Truncated);
        }
        let (seed_vertices, seed_triangles) = if is_base {
            (u32_at(level, SEED_AT)?, u32_at(level, SEED_AT + 4)?)
        } else {
            (0, 0)
        };
        let plane_byte = u8_at(level, PLANE_AT)?;
        let wing_byte = u8_at(level, PLANE_AT + 1)?;
        let deficit_byte = u8_at(level, PLANE_AT + 2)?;
        let record_byte = u8_at(level, PLANE_AT + 3)?;
        let splits_len = (round_count as usize)
            .checked_mul(4)
            .ok_or(Error::Truncated)?;
        let dir_len = (chunk_count as usize)
            .checked_mul(CHUNK_ENTRY_LEN)
            .ok_or(Error::Truncated)?;
        let dir_start = counts_at.checked_add(splits_len).ok_or(Error::Truncated)?;
        let crc_at = dir_start.checked_add(dir_len).ok_or(Error::Truncated)?;
        let payload_start = crc_at.checked_add(4).ok_or(Error::Truncated)?;
        if level.len() < payload_start {
            return Err(Error::Truncated);
        }
        if crc32(&level[..crc_at]) != u32_at(level, crc_at)? {
            return Err(Error::ChecksumMismatch(ChecksumScope::LevelHeader));
        }
        let header = LevelHeader {
            round_count,
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
            mode,
            schedule,
            seed_vertices,
            seed_triangles,
            split_counts: &level[counts_at..dir_start],
            directory: &level[dir_start..crc_at],
            chunk_count,
            payload_start,
        };
        header.validate(level.len(), is_base, max_chunk_len)?;
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
        for k in 0..self.chunk_count {
            let e = self.chunk(k)?;
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

    /// Declared split count of round `r` (SPEC §5.1).
    pub fn split_count(&self, r: u32) -> u32 {
        u32_at(self.split_counts, r as usize * 4).unwrap_or(0)
    }

    /// Directory entry `k` (SPEC §5.2).
    pub fn chunk(&self, k: u32) -> Result<ChunkEntry, Error> {
        let at = k as usize * CHUNK_ENTRY_LEN;
        if u16_at(self.directory, at + 2)? != 0 {
            return Err(Error::InvalidLevelHeader("reserved field not zero"));
        }
        Ok(ChunkEntry {
            substream: u8_at(self.directory, at)?,
            codec: u8_at(self.directory, at + 1)?,
            raw_len: u32_at(self.directory, at + 4)?,
            stored_len: u32_at(self.directory, at + 8)?,
            crc: u32_at(self.directory, at + 12)?,
        })
    }
}
