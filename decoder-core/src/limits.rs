//! Every fixed limit and constant of the format, in one place (SPEC.md §2).

/// The 8-byte signature that opens every stream (SPEC §3.1). Like PNG's, it
/// catches text-mode transfers and truncation of the first bytes.
pub const MAGIC: [u8; 8] = [0x89, b'S', b'P', b'S', b'\r', b'\n', 0x1A, b'\n'];

/// Format version this crate reads and writes (SPEC §1).
pub const VERSION_MAJOR: u8 = 1;
pub const VERSION_MINOR: u8 = 0;

/// Size of the fixed header in bytes (SPEC §3).
pub const HEADER_LEN: usize = 96;
/// Size of one level-table entry (SPEC §4).
pub const LEVEL_ENTRY_LEN: usize = 32;
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
    pub const CONFIG: u8 = 4;
    pub const DEFICIT_P: u8 = 5;
    pub const DEFICIT_C: u8 = 6;
    pub const EDGE: u8 = 7;
    pub const PLACEMENT: u8 = 8;
    pub const BASE_POSITIONS: u8 = 9;
    pub const BASE_TRIANGLES: u8 = 10;
    pub const BASE_DEFICITS: u8 = 11;
    /// Number of substream slots a decoder keeps open at once (refinement
    /// levels use ids 1..=8, the base level 9..=11 through slots 0..=2).
    pub const SLOTS: usize = 8;
    /// Human-readable names, indexed by id (0 unused).
    pub const NAMES: [&str; 12] = [
        "",
        "flags",
        "wing-offset",
        "wing-distance",
        "config",
        "deficit-p",
        "deficit-c",
        "edge",
        "placement",
        "base-positions",
        "base-triangles",
        "base-deficits",
    ];
}

/// Chunk codecs (SPEC §5.2).
pub mod codec {
    pub const STORED: u8 = 0;
    pub const DEFLATE: u8 = 1;
}
