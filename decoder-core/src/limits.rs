//! Every fixed limit and constant of the format, in one place (SPEC.md §2).

/// The 8-byte signature that opens every stream (SPEC §3.1). Like PNG's, it
/// catches text-mode transfers and truncation of the first bytes.
pub const MAGIC: [u8; 8] = [0x89, b'S', b'P', b'S', b'\r', b'\n', 0x1A, b'\n'];

/// Format version this crate implements (SPEC §1). It reads every 3.x
/// stream; 3.5 added a check and no feature, so no stream is written with
/// minor version 5 (the writer uses the constants below).
pub const VERSION_MAJOR: u8 = 3;
pub const VERSION_MINOR: u8 = 12;
/// The minor version written when the header selects the `compact` level
/// table (SPEC §3.2 flag bit 3, §4.3): 3.11 decoders reject the flag.
pub const VERSION_MINOR_COMPACT_TABLE: u8 = 12;
/// The minor version written when the header selects the `compact` level
/// framing (SPEC §3.2 flag bit 2, §5.1.1): 3.10 decoders reject the flag.
pub const VERSION_MINOR_COMPACT: u8 = 11;
/// The minor version written when a level uses the contexts
/// `split-history` (SPEC §5.1, §5.5.5): 3.9 decoders reject its contexts
/// byte.
pub const VERSION_MINOR_SPLIT_HISTORY: u8 = 10;
/// The minor version written when a rANS chunk has an adaptive table (SPEC
/// §5.5.2): 3.8 decoders reject its table byte.
pub const VERSION_MINOR_ADAPTIVE: u8 = 9;
/// The minor version written when a positions-first level breaks the wing
/// choices' ties by a lattice diagonal (SPEC §5.1, §7.4): 3.7 decoders
/// reject its record order byte.
pub const VERSION_MINOR_TIES: u8 = 8;
/// The first minor version with the record order `positions-first` (SPEC
/// §5.1, §7.4).
pub const VERSION_MINOR_RECORDS: u8 = 7;
/// The minor version written when a stream uses the schedule
/// `every-vertex` (SPEC §1, §3.2): 3.5 decoders reject its header flag bit.
pub const VERSION_MINOR_SCHEDULE: u8 = 6;
/// The minor version written when a rANS chunk codes more values than
/// `max_chunk_len` (SPEC §1, §5.2): 3.3 decoders reject such a chunk.
pub const VERSION_MINOR_RANS_CHUNKS: u8 = 4;
/// The minor version written when a stream uses the deficit contexts
/// `valence` and no 3.4 feature, so that 3.3 decoders read it (SPEC §1).
pub const VERSION_MINOR_DEFICITS: u8 = 3;
/// The minor version written when a stream uses a wing policy other than
/// `ranks` and no 3.3 or 3.4 feature, so that 3.2 decoders read it (SPEC §1).
pub const VERSION_MINOR_WINGS: u8 = 2;
/// The minor version written when a stream uses the plane policy `height`
/// and no 3.2, 3.3 or 3.4 feature, so that 3.1 decoders read it (SPEC §1).
pub const VERSION_MINOR_HEIGHT: u8 = 1;
/// The minor version written when a stream uses no 3.1 to 3.4 feature
/// (every reserved field zero, every chunk within `max_chunk_len`), so that
/// 3.0 decoders read it (SPEC §1).
pub const VERSION_MINOR_BASELINE: u8 = 0;

/// Size of the fixed header in bytes (SPEC §3).
pub const HEADER_LEN: usize = 96;
/// Size of one level-table entry (SPEC §4).
pub const LEVEL_ENTRY_LEN: usize = 32;
/// Most levels a stream with a compact level table declares (SPEC §3.3,
/// 3.12): its entries are read from the start, so a decoder that reads on
/// from the start for every entry it needs stays within 255 × 255 reads.
pub const MAX_COMPACT_LEVELS: u16 = 255;
/// Bounds of one compact level-table entry: four varints of 1 to 5 bytes
/// and an `f32` (SPEC §4.3).
pub const MIN_COMPACT_ENTRY_LEN: u32 = 8;
pub const MAX_COMPACT_ENTRY_LEN: u32 = 24;
/// Size of one chunk-directory entry (SPEC §5.2).
pub const CHUNK_ENTRY_LEN: usize = 16;

/// Largest valence a vertex may have when it is split, and largest split
/// valence (SPEC §6.2). Ring offsets and deficits then fit in one byte.
pub const MAX_SPLIT_VALENCE: usize = 255;
/// Deficit value marking a leaf: a vertex that never splits again (SPEC §6.2).
pub const LEAF: u8 = 0xFF;
/// Marker for "no vertex" (the ghost vertex of a boundary) and "no corner"
/// (the missing opposite of a boundary edge) (SPEC §6.1).
pub const NONE: u32 = u32::MAX;

/// Quantization bits per axis accepted (SPEC §3.2).
pub const MIN_BITS: u8 = 1;
pub const MAX_BITS: u8 = 31;

/// Largest vertex or triangle count of a stream: indices must stay below
/// [`NONE`] and corner indices (3 per triangle) must fit in a u32.
pub const MAX_TRIANGLES: u32 = (u32::MAX - 1) / 3;
pub const MAX_VERTICES: u32 = u32::MAX - 1;

/// Substream identifiers (SPEC §5.3).
pub mod substream {
    pub const FLAGS: u8 = 1;
    pub const WING_OFFSET: u8 = 2;
    pub const WING_DISTANCE: u8 = 3;
    pub const DEFICIT_P: u8 = 4;
    pub const DEFICIT_C: u8 = 5;
    pub const EDGE: u8 = 6;
    pub const PLACEMENT: u8 = 7;
    pub const BASE_POSITIONS: u8 = 8;
    pub const BASE_TRIANGLES: u8 = 9;
    pub const BASE_DEFICITS: u8 = 10;
    /// Number of substream slots a decoder keeps open at once (refinement
    /// levels use ids 1..=7, the base level 8..=10 through slots 0..=2).
    pub const SLOTS: usize = 7;
    /// Highest substream id.
    pub const LAST: u8 = BASE_DEFICITS;
    /// Human-readable names, indexed by id (0 unused).
    pub const NAMES: [&str; 11] = [
        "",
        "flags",
        "wing-offset",
        "wing-distance",
        "deficit-p",
        "deficit-c",
        "edge",
        "placement",
        "base-positions",
        "base-triangles",
        "base-deficits",
    ];
    /// Contexts of each substream under the rANS codec (SPEC §5.5), by id,
    /// in a level with the deficit contexts `plain`; `context::count` gives
    /// them for every level.
    pub const CONTEXTS: [u8; 11] = [0, 1, 8, 8, 1, 5, 3, 5, 3, 1, 1];
}

/// The plane policy byte of a level header (SPEC §5.1, §7.4): which axis of
/// each position residual is predicted from the other two.
pub mod plane {
    /// No plane prediction.
    pub const OFF: u8 = 0;
    /// The axis along which the split's normal is largest.
    pub const DOMINANT: u8 = 1;
    /// Always x, y or z.
    pub const X: u8 = 2;
    pub const Y: u8 = 3;
    pub const Z: u8 = 4;
    /// z from the surface of R's fan over the vector's x and y (format 3.1).
    pub const HEIGHT: u8 = 5;
    /// Number of policies; bytes from here on are reserved.
    pub const COUNT: u8 = 6;
    /// The normal is shifted to at most this many significant bits.
    pub const NORMAL_BITS: u32 = 15;
}

/// Chunk codecs (SPEC §5.2).
pub mod codec {
    pub const STORED: u8 = 0;
    pub const DEFLATE: u8 = 1;
    pub const RANS: u8 = 2;
}

/// The rANS codec's constants (SPEC §5.5).
pub mod rans {
    /// Frequencies of a distribution sum to `1 << PROB_BITS`.
    pub const PROB_BITS: u32 = 12;
    pub const PROB_SCALE: u32 = 1 << PROB_BITS;
    /// Lower bound of a lane's normalised state; states live in `L .. L << 8`.
    pub const STATE_LOW: u32 = 1 << 23;
    /// Tokens of the hybrid integer code: 0..=15 direct, 16..=43 by exponent.
    pub const TOKENS: usize = 44;
    /// Values below this are their own token.
    pub const DIRECT_TOKENS: u32 = 16;
    /// Raw bits are drawn from a lane at most this many at a time.
    pub const RAW_BITS_STEP: u32 = 16;
    /// Most contexts any substream has.
    pub const MAX_CONTEXTS: usize = 8;
    /// Most lanes a stream may declare (header byte 13).
    pub const MAX_LANES: u8 = 32;
    /// u32 words of one substream's rANS tables: per context the token
    /// count and the cumulative frequencies (`TOKENS + 1` entries).
    pub const TABLE_WORDS: usize = MAX_CONTEXTS * (TOKENS + 2);
    /// An adaptive table (3.9) sets this bit of its table byte; bits 4–6
    /// hold its rate less `ADAPTIVE_RATE_MIN`, bits 0–3 its token count
    /// less 1 (SPEC §5.5.2).
    pub const ADAPTIVE_FLAG: u8 = 0x80;
    /// The slowest adaptation rate is `ADAPTIVE_RATE_MIN + 7`.
    pub const ADAPTIVE_RATE_MIN: u8 = 4;
    /// Most tokens of an adaptive table.
    pub const ADAPTIVE_TOKENS: usize = 16;
    /// Most probabilities an adaptive table keeps: `(m − 1) × lane_count`
    /// for `m` tokens (SPEC §5.5.2), each with its decision count. They fit
    /// where a static table keeps its cumulative frequencies and bucket
    /// index, so the working memory is unchanged.
    pub const ADAPTIVE_STATES: usize = 48;
    /// An adaptive probability's bits (a 16-bit fraction), and its value
    /// at the start of every chunk (one half).
    pub const ADAPTIVE_BITS: u32 = 16;
    pub const ADAPTIVE_START: u16 = 1 << 15;
}
