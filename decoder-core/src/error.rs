//! Every error a decoder must detect (SPEC §10). Each variant names the
//! section whose rule it enforces; [`Error::class`] gives the conformance
//! class that every decoder, ours or a third party's, must report.

use core::fmt;

/// Why a stream was rejected. A decoder that returned an error is poisoned:
/// its state is not meaningful any more (SPEC §10).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error {
    /// §3.1: the first 8 bytes are not the splitstream signature.
    BadMagic,
    /// §3.1: a major version other than 3.
    UnsupportedVersion { major: u8, minor: u8 },
    /// §3.2, §3.3: a header field out of its allowed range or a reserved
    /// field not zero; §9, §10.3: `workspace_bytes` not the layout's total.
    InvalidHeader(&'static str),
    /// §3.3, §4.2, §5.1, §5.2: a CRC-32 does not match.
    ChecksumMismatch(ChecksumScope),
    /// §3, §4, §5, §10.3: the bytes end before the structure they must
    /// hold, or a level's byte range is not (wholly) present.
    Truncated,
    /// §4.2: level table entries are inconsistent (offsets, counts, ordering).
    InvalidLevelTable(&'static str),
    /// §5.1, §5.2: a level header or chunk directory is malformed.
    InvalidLevelHeader(&'static str),
    /// §5.2: a deflate chunk does not inflate to exactly its declared length.
    CorruptChunk,
    /// §4.2, §9: a level-table count exceeds the capacity declared in the
    /// header (and, as a guard no valid stream meets since §5.1 bounds the
    /// seed, a seed larger than the workspace's capacities).
    CapacityExceeded,
    /// §9: the caller's workspace is smaller than the layout needs (an
    /// API-level error, §10.1; its class is `capacity-exceeded`).
    WorkspaceTooSmall { needed: usize, available: usize },
    /// §7.3: the number of set flags in a round differs from the declared split count.
    FlagCountMismatch { round: u32 },
    /// §5.4, §7.6: a substream ran out early, or holds data after the
    /// level's last record (or a chunk it never loaded), in the substream
    /// with this id.
    RecordCountMismatch(u8),
    /// §5.1, §7.5, §7.6: a level's round count, split counts or seed
    /// triangles disagree with its level-table entry, a split would take the
    /// triangle count past the entry's, or the level ended with other
    /// vertex or triangle counts.
    LevelCountMismatch,
    /// §5.4: a varint longer than 5 bytes, over 32 bits, or not minimal.
    InvalidVarint(u8),
    /// §5.5: a rANS chunk's tables or lanes are malformed, or a lane did not
    /// end exactly where its chunk ends.
    InvalidRansChunk(&'static str),
    /// §5.5: a rANS-coded value too large for its field (a bit above 1, a
    /// byte above 255), in the substream with this id.
    ValueOutOfRange(u8),
    /// §7.4, §7.5: wing ranks naming no pair of ring entries that may be
    /// wings (`d' = 0` or `o' + d' >= m`), or a wing offset or distance
    /// outside the ring of the split vertex.
    RingOffsetOutOfRange,
    /// §6.2, §6.3, §7.1, §7.5: a valence above its split valence or above
    /// 255 (a base vertex, a ring longer than 255, P or C after a split), or
    /// a wing with deficit 0.
    ValenceOverflow,
    /// §7.4: a coded split valence of P or C below that vertex's valence
    /// right after the split, or above 255.
    SplitValenceOutOfRange,
    /// §6.3: the base mesh is not a consistently oriented 2-manifold.
    NonManifold(&'static str),
    /// §6.3, §7.4: a decoded coordinate outside `0 .. 2^bits`.
    PositionOutOfRange,
    /// §7.4: the constrained-mode placement code is not 0, 1 or 2.
    InvalidPlacement,
    /// API misuse (§10.1, not a stream fault): levels must be fed in order,
    /// once each.
    LevelOutOfOrder { expected: u16, got: u16 },
    /// API misuse (§10.1, §10.2): the decoder already returned an error, or
    /// a level was abandoned half way.
    Poisoned,
    /// API misuse (§10.1): a vertex index beyond the current vertex count.
    NoSuchVertex,
    /// API misuse (§10.1, §4.1): a level index beyond the level table
    /// (`count` levels).
    NoSuchLevel { level: u16, count: u16 },
}

/// Which checksum failed (SPEC §3.3, §4.2, §5.1, §5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChecksumScope {
    Header,
    LevelTable,
    LevelHeader,
    Chunk,
}

impl Error {
    /// The conformance error class (SPEC §10, conformance/README.md).
    pub fn class(&self) -> &'static str {
        match self {
            Error::BadMagic => "bad-magic",
            Error::UnsupportedVersion { .. } => "unsupported-version",
            Error::ChecksumMismatch(_) => "checksum-mismatch",
            Error::Truncated => "truncated",
            Error::InvalidHeader(_)
            | Error::InvalidLevelTable(_)
            | Error::InvalidLevelHeader(_)
            | Error::CorruptChunk
            | Error::InvalidVarint(_)
            | Error::InvalidRansChunk(_)
            | Error::ValueOutOfRange(_)
            | Error::InvalidPlacement => "malformed",
            Error::CapacityExceeded | Error::WorkspaceTooSmall { .. } => "capacity-exceeded",
            Error::FlagCountMismatch { .. }
            | Error::RecordCountMismatch(_)
            | Error::LevelCountMismatch => "count-mismatch",
            Error::RingOffsetOutOfRange => "ring-offset-out-of-range",
            Error::ValenceOverflow | Error::SplitValenceOutOfRange => "valence-overflow",
            Error::NonManifold(_) => "non-manifold",
            Error::PositionOutOfRange => "position-out-of-range",
            Error::LevelOutOfOrder { .. }
            | Error::Poisoned
            | Error::NoSuchVertex
            | Error::NoSuchLevel { .. } => "api-misuse",
        }
    }
}

fn substream_name(id: u8) -> &'static str {
    crate::limits::substream::NAMES
        .get(id as usize)
        .copied()
        .unwrap_or("?")
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::BadMagic => write!(f, "not a splitstream file (bad signature)"),
            Error::UnsupportedVersion { major, minor } => {
                write!(
                    f,
                    "unsupported format version {major}.{minor} (this decoder reads 3.x)"
                )
            }
            Error::InvalidHeader(what) => write!(f, "invalid header: {what}"),
            Error::ChecksumMismatch(scope) => write!(f, "checksum mismatch in {scope:?}"),
            Error::Truncated => write!(f, "stream truncated"),
            Error::InvalidLevelTable(what) => write!(f, "invalid level table: {what}"),
            Error::InvalidLevelHeader(what) => write!(f, "invalid level header: {what}"),
            Error::CorruptChunk => {
                write!(f, "a deflate chunk does not inflate to its declared length")
            }
            Error::CapacityExceeded => {
                write!(f, "a count exceeds the capacity declared in the header")
            }
            Error::WorkspaceTooSmall { needed, available } => {
                write!(
                    f,
                    "workspace too small: {needed} bytes needed, {available} given"
                )
            }
            Error::FlagCountMismatch { round } => {
                write!(
                    f,
                    "round {round}: set flags differ from the declared split count"
                )
            }
            Error::RecordCountMismatch(id) => write!(
                f,
                "substream {} ran out or holds extra data",
                substream_name(*id)
            ),
            Error::LevelCountMismatch => {
                write!(
                    f,
                    "level decodes to other counts than its level-table entry"
                )
            }
            Error::InvalidVarint(id) => {
                write!(f, "substream {}: invalid varint", substream_name(*id))
            }
            Error::InvalidRansChunk(what) => write!(f, "invalid rANS chunk: {what}"),
            Error::ValueOutOfRange(id) => {
                write!(
                    f,
                    "substream {}: value out of its field's range",
                    substream_name(*id)
                )
            }
            Error::RingOffsetOutOfRange => {
                write!(f, "wing offset outside the ring of the split vertex")
            }
            Error::ValenceOverflow => write!(f, "a valence exceeds its split valence or 255"),
            Error::SplitValenceOutOfRange => write!(
                f,
                "a split valence below the vertex's valence after the split, or above 255"
            ),
            Error::NonManifold(what) => write!(f, "base mesh is not a 2-manifold: {what}"),
            Error::PositionOutOfRange => {
                write!(f, "decoded position outside the quantization grid")
            }
            Error::InvalidPlacement => write!(f, "placement code is not 0, 1 or 2"),
            Error::LevelOutOfOrder { expected, got } => {
                write!(f, "level {got} given where level {expected} was expected")
            }
            Error::Poisoned => write!(
                f,
                "decoder already failed or a level was abandoned; start a new one"
            ),
            Error::NoSuchVertex => write!(f, "vertex index beyond the current vertex count"),
            Error::NoSuchLevel { level, count } => {
                write!(
                    f,
                    "level {level} does not exist: the stream has levels 0..{count}"
                )
            }
        }
    }
}

impl core::error::Error for Error {}
