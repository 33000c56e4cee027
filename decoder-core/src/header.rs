//! The fixed 96-byte header (SPEC §3).

use crate::bytes::{crc32, f64_at, u8_at, u16_at, u32_at, u64_at};
use crate::limits::{
    HEADER_LEN, LEVEL_ENTRY_LEN, MAGIC, MAX_BITS, MAX_COMPACT_ENTRY_LEN, MAX_COMPACT_LEVELS,
    MAX_TRIANGLES, MAX_VERTICES, MIN_BITS, MIN_COMPACT_ENTRY_LEN, VERSION_MAJOR, rans::MAX_LANES,
};
use crate::{ChecksumScope, Error};

/// The compact table's declared length, checked against the bounds of
/// SPEC §3.3 (3.12): at most [`MAX_COMPACT_LEVELS`] entries of 8 to 24
/// bytes each, then the CRC.
fn compact_table_len(level_count: u16, declared: u32) -> Result<u32, Error> {
    if level_count > MAX_COMPACT_LEVELS {
        return Err(Error::InvalidHeader(
            "more than 255 levels in a compact level table",
        ));
    }
    let entries = level_count as u32;
    if declared < MIN_COMPACT_ENTRY_LEN * entries + 4
        || declared > MAX_COMPACT_ENTRY_LEN * entries + 4
    {
        return Err(Error::InvalidHeader(
            "compact level table length out of range for its level count",
        ));
    }
    Ok(declared)
}

/// How the two vertices of a split are placed relative to their parent
/// (SPEC §3.2 header flag bit 0, §7.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PositionMode {
    /// Two deltas per split: the edge vector and the parent's offset from its midpoint.
    Optimal,
    /// One delta per split plus a placement code: the parent sits on P, on C or at their midpoint.
    Constrained,
}

/// How a stream says which vertices split in which round (SPEC §3.2 header
/// flag bit 1, §6.2, §7.3; format 3.6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Schedule {
    /// The paper's: every vertex carries a split valence, coded when it is
    /// created, and the candidates of a round are the vertices whose
    /// valence has grown back to it (formats 3.0 to 3.5).
    #[default]
    SplitValences,
    /// 3.6: no split valences; every vertex is a candidate of every round
    /// and gets a flag, in a context by its valence, unless a flagged
    /// neighbour blocks it. The state keeps each vertex's valence (capped at
    /// 255) where `SplitValences` keeps its deficit.
    EveryVertex,
}

impl Schedule {
    /// The name `splitstream info` and the SPEC use.
    pub fn name(self) -> &'static str {
        match self {
            Schedule::SplitValences => "split-valences",
            Schedule::EveryVertex => "every-vertex",
        }
    }
}

/// How a stream's level table and level headers are laid out (SPEC §3.2
/// header flag bits 2 and 3, §4, §5.1; formats 3.11 and 3.12).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Framing {
    /// Fixed-width fields: 32-byte table entries, `u32` counts, 16-byte
    /// directory entries (3.0).
    #[default]
    Fixed,
    /// 3.11: the level headers' counts and lengths as varints, a directory
    /// entry's id and codec in one byte (SPEC §5.1.1): 7 to 10 bytes an
    /// entry instead of 16, one or two bytes a round instead of 4. The
    /// level table stays fixed (flag bit 2).
    CompactLevels,
    /// 3.12: the level headers as under `CompactLevels`, and the level
    /// table's entries as varints (SPEC §4.3): 8 to 12 bytes an entry
    /// instead of 32 (flag bits 2 and 3).
    Compact,
}

impl Framing {
    /// The name `splitstream info` and the SPEC use.
    pub fn name(self) -> &'static str {
        match self {
            Framing::Fixed => "fixed",
            Framing::CompactLevels => "compact-levels",
            Framing::Compact => "compact",
        }
    }

    /// Whether the level headers are laid out as in SPEC §5.1.1 (3.11).
    pub fn compact_level_headers(self) -> bool {
        self != Framing::Fixed
    }

    /// Whether the level table is laid out as in SPEC §4.3 (3.12).
    pub fn compact_table(self) -> bool {
        self == Framing::Compact
    }
}

/// The parsed header (SPEC §3.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Header {
    pub version_minor: u8,
    pub position_mode: PositionMode,
    /// Which vertices split in which round (header flag bit 1, 3.6).
    pub schedule: Schedule,
    /// How the level headers (header flag bit 2, 3.11) and the level table
    /// (bit 3, 3.12) are laid out.
    pub framing: Framing,
    /// Bytes of the level table, its CRC included: under the compact table
    /// (3.12) the header's field at offset 28 (SPEC §3.2, §4.3), under the
    /// fixed one `32 × level_count + 4`.
    pub table_len: u32,
    /// Quantization bits per axis: coordinates lie in `0 .. 2^bits`.
    pub bits: u8,
    /// Entries in the level table; entry 0 is the base mesh.
    pub level_count: u16,
    /// Vertex count after the last level.
    pub vertex_capacity: u32,
    /// Triangle count after the last level.
    pub triangle_capacity: u32,
    /// Independent rANS lanes per chunk (SPEC §5.5), 1..=32.
    pub lane_count: u8,
    /// Largest `raw_len` of a stored or deflate chunk (SPEC §3.2, §5.2; since
    /// 3.4 it does not bound rANS chunks, whose `raw_len` counts values).
    pub max_chunk_len: u32,
    /// Real coordinate of quantized value 0 on each axis.
    pub origin: [f64; 3],
    /// Real length of one quantization step on each axis.
    pub scale: [f64; 3],
    /// Bytes of the reference workspace for the whole stream (SPEC §9).
    pub workspace_bytes: u64,
}

impl Header {
    /// What this stream's level headers are checked against (SPEC §5.1).
    pub fn level_rules(&self) -> crate::LevelRules {
        crate::LevelRules {
            max_chunk_len: self.max_chunk_len,
            schedule: self.schedule,
            position_mode: self.position_mode,
            framing: self.framing,
        }
    }

    /// Parses and validates the header at the start of `bytes` (SPEC §3).
    pub fn parse(bytes: &[u8]) -> Result<Header, Error> {
        if bytes.len() < MAGIC.len() {
            return Err(Error::Truncated);
        }
        if bytes[..MAGIC.len()] != MAGIC {
            return Err(Error::BadMagic);
        }
        let major = u8_at(bytes, 8)?;
        let minor = u8_at(bytes, 9)?;
        if major != VERSION_MAJOR {
            return Err(Error::UnsupportedVersion { major, minor });
        }
        if bytes.len() < HEADER_LEN {
            return Err(Error::Truncated);
        }
        if crc32(&bytes[..HEADER_LEN - 4]) != u32_at(bytes, HEADER_LEN - 4)? {
            return Err(Error::ChecksumMismatch(ChecksumScope::Header));
        }
        let flags = u16_at(bytes, 10)?;
        if flags & !15 != 0 {
            return Err(Error::InvalidHeader("reserved flag bits set"));
        }
        let position_mode = if flags & 1 == 0 {
            PositionMode::Optimal
        } else {
            PositionMode::Constrained
        };
        let schedule = if flags & 2 == 0 {
            Schedule::SplitValences
        } else {
            Schedule::EveryVertex
        };
        let framing = match flags & 12 {
            0 => Framing::Fixed,
            4 => Framing::CompactLevels,
            12 => Framing::Compact,
            _ => {
                return Err(Error::InvalidHeader(
                    "a compact level table without compact level headers",
                ));
            }
        };
        let bits = u8_at(bytes, 12)?;
        if !(MIN_BITS..=MAX_BITS).contains(&bits) {
            return Err(Error::InvalidHeader("bits per axis outside 1..=31"));
        }
        let declared_table_len = u32_at(bytes, 28)?;
        if (!framing.compact_table() && declared_table_len != 0) || u32_at(bytes, 88)? != 0 {
            return Err(Error::InvalidHeader("reserved field not zero"));
        }
        let lane_count = u8_at(bytes, 13)?;
        if !(1..=MAX_LANES).contains(&lane_count) {
            return Err(Error::InvalidHeader("lane count outside 1..=32"));
        }
        let level_count = u16_at(bytes, 14)?;
        if level_count == 0 {
            return Err(Error::InvalidHeader("no levels"));
        }
        let table_len = if framing.compact_table() {
            compact_table_len(level_count, declared_table_len)?
        } else {
            (LEVEL_ENTRY_LEN * level_count as usize + 4) as u32
        };
        let vertex_capacity = u32_at(bytes, 16)?;
        let triangle_capacity = u32_at(bytes, 20)?;
        if vertex_capacity == 0 || vertex_capacity > MAX_VERTICES {
            return Err(Error::InvalidHeader("vertex capacity"));
        }
        if triangle_capacity == 0 || triangle_capacity > MAX_TRIANGLES {
            return Err(Error::InvalidHeader("triangle capacity"));
        }
        let max_chunk_len = u32_at(bytes, 24)?;
        if max_chunk_len == 0 {
            return Err(Error::InvalidHeader("max chunk length is 0"));
        }
        let mut origin = [0.0; 3];
        let mut scale = [0.0; 3];
        for k in 0..3 {
            origin[k] = f64_at(bytes, 32 + 8 * k)?;
            scale[k] = f64_at(bytes, 56 + 8 * k)?;
            if !origin[k].is_finite() {
                return Err(Error::InvalidHeader("origin not finite"));
            }
            if !(scale[k].is_finite() && scale[k] > 0.0) {
                return Err(Error::InvalidHeader("scale not finite and positive"));
            }
        }
        let workspace_bytes = u64_at(bytes, 80)?;
        let header = Header {
            version_minor: minor,
            position_mode,
            schedule,
            framing,
            table_len,
            bits,
            lane_count,
            level_count,
            vertex_capacity,
            triangle_capacity,
            max_chunk_len,
            origin,
            scale,
            workspace_bytes,
        };
        Ok(header)
    }

    /// Writes the header into `out` (96 bytes, SPEC §3.2), checksum included
    /// (§3.3). Used by encoders; the inverse of [`Header::parse`].
    pub fn write(&self, out: &mut [u8; HEADER_LEN]) {
        out.fill(0);
        out[..8].copy_from_slice(&MAGIC);
        out[8] = VERSION_MAJOR;
        out[9] = self.version_minor;
        let mode: u16 = match self.position_mode {
            PositionMode::Optimal => 0,
            PositionMode::Constrained => 1,
        };
        let schedule: u16 = match self.schedule {
            Schedule::SplitValences => 0,
            Schedule::EveryVertex => 2,
        };
        let framing: u16 = match self.framing {
            Framing::Fixed => 0,
            Framing::CompactLevels => 4,
            Framing::Compact => 12,
        };
        let flags = mode | schedule | framing;
        out[10..12].copy_from_slice(&flags.to_le_bytes());
        out[12] = self.bits;
        out[13] = self.lane_count;
        out[14..16].copy_from_slice(&self.level_count.to_le_bytes());
        out[16..20].copy_from_slice(&self.vertex_capacity.to_le_bytes());
        out[20..24].copy_from_slice(&self.triangle_capacity.to_le_bytes());
        out[24..28].copy_from_slice(&self.max_chunk_len.to_le_bytes());
        if self.framing.compact_table() {
            out[28..32].copy_from_slice(&self.table_len.to_le_bytes());
        }
        for k in 0..3 {
            out[32 + 8 * k..40 + 8 * k].copy_from_slice(&self.origin[k].to_le_bytes());
            out[56 + 8 * k..64 + 8 * k].copy_from_slice(&self.scale[k].to_le_bytes());
        }
        out[80..88].copy_from_slice(&self.workspace_bytes.to_le_bytes());
        let crc = crc32(&out[..HEADER_LEN - 4]);
        out[HEADER_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    }

    /// Bytes from the stream start to the end of the level table, its
    /// checksum included (SPEC §3.3, §4.1, §4.3): what a client fetches
    /// before it knows every level's byte range.
    pub fn head_len(&self) -> usize {
        HEADER_LEN.saturating_add(self.table_len as usize)
    }

    /// Real coordinates of a quantized position: `origin + q * scale` (SPEC §3.2).
    pub fn dequantize(&self, q: [u32; 3]) -> [f64; 3] {
        [
            self.origin[0] + q[0] as f64 * self.scale[0],
            self.origin[1] + q[1] as f64 * self.scale[1],
            self.origin[2] + q[2] as f64 * self.scale[2],
        ]
    }
}
