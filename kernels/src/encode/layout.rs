//! Buffer layouts shared by the host and the kernels (WGSL and OpenCL C
//! declare the same fields in the same order).

use bytemuck::{Pod, Zeroable};

/// Marks a missing vertex, corner or partner, as in the encoder's corner table.
pub const NONE: u32 = u32::MAX;
/// Vertex flag: still in the mesh.
pub const ALIVE: u32 = 1;
/// Vertex flag: on a boundary edge.
pub const BOUNDARY: u32 = 2;
/// `Params::flags` bit: merged vertex on P, C or their midpoint.
pub const CONSTRAINED: u32 = 1;
/// `Params::flags` bit: boundary vertices never move or go.
pub const LOCKED: u32 = 2;
/// `Params::mode` of `best_edge`: evaluate every listed vertex.
pub const MODE_ALL: u32 = 0;
/// `Params::mode` of `best_edge`: re-pick, avoiding blocked partners, only
/// for free vertices whose partner is blocked (selection passes after the first).
pub const MODE_REPICK: u32 = 1;
/// Threads per workgroup of every WGSL kernel (`GROUP` in params.wgsl).
pub const GROUP: u32 = 256;
/// Error the kernels write for "no collapse" (the largest finite f32).
pub const NO_ERROR: f32 = 3.4e38;

/// Per-dispatch parameters (`Params` in params.wgsl and encode_common.cl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub vertex_count: u32,
    pub corner_count: u32,
    /// Items the dispatch walks (list entries, winners, update records).
    pub list_len: u32,
    /// best_edge: [`MODE_ALL`] or [`MODE_REPICK`]; block and updates: the
    /// first record's offset (in records for block, in words for updates).
    pub mode: u32,
    /// Largest grid coordinate, `2^bits - 1`.
    pub top: u32,
    /// [`CONSTRAINED`] | [`LOCKED`].
    pub flags: u32,
    /// Largest valence a merged vertex may get (ghost counted).
    pub max_valence: u32,
    pub pad0: u32,
    /// Grid units to metric units per axis (the fourth is unused).
    pub metric: [f32; 4],
    /// Sub-grid cell size in metric units (0: no sub-grid tie-break).
    pub cell: f32,
    /// Errors at or below this rank as flat (key 0).
    pub flat_error: f32,
    /// The step's threshold S.
    pub threshold: f32,
    pub boundary_weight: f32,
}

/// A vertex's chosen collapse (`Best` in the kernels); `other == NONE` for none.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Best {
    pub other: u32,
    pub error: f32,
    /// `error` as f32 bits, 0 when flat: equal errors tie exactly.
    pub key: u32,
    /// Merged vertex on the quantization grid.
    pub target: [u32; 3],
}

/// A selected collapse: the lower endpoint `v` and its [`Best`] fields.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Winner {
    pub v: u32,
    pub other: u32,
    pub error: f32,
    pub key: u32,
    pub target: [u32; 3],
}

/// One triangle rewritten by the CPU: its three corners' vertices and opposites.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct TriangleUpdate {
    pub triangle: u32,
    pub vertex: [u32; 3],
    pub opposite: [u32; 3],
}

/// One vertex rewritten by the CPU.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct VertexUpdate {
    pub vertex: u32,
    pub position: [u32; 3],
    /// [`ALIVE`] | [`BOUNDARY`].
    pub flags: u32,
    pub corner_of: u32,
    /// Quadric in the vertex's own frame (origin at its position, metric
    /// units): a2 ab ac ad b2 bc bd c2 cd d2.
    pub quadric: [f32; 10],
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_sizes_match_the_kernels() {
        assert_eq!(size_of::<Params>(), 64);
        assert_eq!(size_of::<Best>(), 24);
        assert_eq!(size_of::<Winner>(), 28);
        assert_eq!(size_of::<TriangleUpdate>(), 7 * 4);
        assert_eq!(size_of::<VertexUpdate>(), 16 * 4);
    }
}
