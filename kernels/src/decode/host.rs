//! Host-side types shared by the wgpu (`refine`, feature `wgpu`) and OpenCL
//! (`ocl_refine`, feature `opencl`) refiners, and the checks both make before a round.

use super::adjacency::AdjacencyError;
pub use super::layout::Schedule;
use super::layout::{GpuRecord, KernelFault, WORKGROUP};
use crate::gpu::{Api, GpuError};

/// Largest 1-D dispatch, in workgroups (WebGPU's per-dimension minimum).
pub const MAX_GROUPS: u64 = 65_535;

/// The base state uploaded once (decoder-core's state after level 0's seed).
#[derive(Clone, Copy, Debug)]
pub struct BaseMesh<'a> {
    pub positions: &'a [[u32; 3]],
    pub triangles: &'a [[u32; 3]],
    /// The per-vertex bytes of SPEC §6.2: deficits, or under the schedule
    /// `every-vertex` valences (the refiner's [`Schedule`]).
    pub deficits: &'a [u8],
    /// Quantization bits per axis (SPEC §3.2).
    pub bits: u8,
}

/// One round as the stream gives it.
#[derive(Clone, Copy, Debug)]
pub struct RoundInput<'a> {
    /// Candidates at round start (the number of flags read): under
    /// `every-vertex`, the vertex count.
    pub candidates: u32,
    /// One bit per candidate in ascending candidate order, LSB first.
    pub flags: &'a [u32],
    /// The flagged splits' records, in split order.
    pub records: &'a [GpuRecord],
    /// Triangle count the current level may reach (SPEC §7.5).
    pub triangle_limit: u32,
}

/// Why the refiner could not be set up or run.
#[derive(Debug)]
pub enum RefineError {
    Gpu(GpuError),
    /// The base mesh has no consistent adjacency.
    Base(AdjacencyError),
    /// More vertices or triangles than the buffers were sized for.
    Capacity {
        what: &'static str,
        needed: u64,
        capacity: u64,
    },
    /// The round's input is inconsistent (flags too short for the count).
    Input(&'static str),
}

impl core::fmt::Display for RefineError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RefineError::Gpu(e) => write!(f, "{e}"),
            RefineError::Base(e) => write!(f, "base mesh: {e}"),
            RefineError::Capacity {
                what,
                needed,
                capacity,
            } => {
                write!(f, "{what}: {needed} needed, room for {capacity}")
            }
            RefineError::Input(what) => write!(f, "round input: {what}"),
        }
    }
}

impl std::error::Error for RefineError {}

impl From<GpuError> for RefineError {
    fn from(e: GpuError) -> Self {
        RefineError::Gpu(e)
    }
}

/// A failure of the API itself (launch, transfer, mapping).
pub fn kernel_error(api: Api, detail: impl ToString) -> RefineError {
    RefineError::Gpu(GpuError::Kernel {
        api,
        detail: detail.to_string(),
    })
}

/// The state read back from the device.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Snapshot {
    pub positions: Vec<[u32; 3]>,
    pub deficits: Vec<u8>,
    /// Flat corners, 3 per triangle.
    pub corners: Vec<u32>,
    /// Present when asked for.
    pub opposite: Vec<u32>,
    pub vertex_corner: Vec<u32>,
    /// The first fault of the last round that had one, if any.
    pub fault: Option<KernelFault>,
}

/// A state buffer a snapshot reads back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateBuffer {
    /// Three words per vertex.
    Positions,
    /// One word per vertex (a byte's value).
    Deficit,
    /// Three words per triangle.
    Corners,
    /// Three words per triangle.
    Opposite,
    /// One word per vertex.
    VertexCorner,
}

impl Snapshot {
    /// The state of `v` vertices and `t` triangles (and their adjacency
    /// when `adjacency`), each buffer read by `read(buffer, words)`: both
    /// hosts' snapshots, after their own read of the counts.
    pub fn read(
        v: usize,
        t: usize,
        adjacency: bool,
        fault: Option<KernelFault>,
        mut read: impl FnMut(StateBuffer, usize) -> Result<Vec<u32>, RefineError>,
    ) -> Result<Snapshot, RefineError> {
        let positions = read(StateBuffer::Positions, 3 * v)?;
        let deficits = read(StateBuffer::Deficit, v)?;
        let corners = read(StateBuffer::Corners, 3 * t)?;
        let (opposite, vertex_corner) = if adjacency {
            (
                read(StateBuffer::Opposite, 3 * t)?,
                read(StateBuffer::VertexCorner, v)?,
            )
        } else {
            (Vec::new(), Vec::new())
        };
        Ok(Snapshot {
            positions: positions
                .chunks_exact(3)
                .map(|p| [p[0], p[1], p[2]])
                .collect(),
            deficits: deficits.iter().map(|&d| d as u8).collect(),
            corners,
            opposite,
            vertex_corner,
            fault,
        })
    }
}

/// Checks a base mesh against the capacities both hosts allocate.
pub fn check_base(
    base: &BaseMesh<'_>,
    vertex_capacity: u32,
    triangle_capacity: u32,
) -> Result<(), RefineError> {
    if base.deficits.len() != base.positions.len() {
        return Err(RefineError::Input("one deficit per base vertex"));
    }
    for (what, needed, capacity) in [
        (
            "vertices",
            base.positions.len() as u64,
            vertex_capacity as u64,
        ),
        (
            "triangles",
            base.triangles.len() as u64,
            triangle_capacity as u64,
        ),
        (
            "vertices per dispatch",
            vertex_capacity as u64,
            MAX_GROUPS * WORKGROUP as u64,
        ),
    ] {
        if needed > capacity {
            return Err(RefineError::Capacity {
                what,
                needed,
                capacity,
            });
        }
    }
    Ok(())
}

/// Checks a round's input against the host's vertex count `n` and the
/// capacities.
pub fn check_round(
    input: &RoundInput<'_>,
    n: u32,
    vertex_capacity: u32,
    split_capacity: u32,
) -> Result<(), RefineError> {
    let s = input.records.len() as u64;
    if (input.flags.len() as u64) * 32 < input.candidates as u64 {
        return Err(RefineError::Input("fewer flag bits than candidates"));
    }
    if input.candidates > n {
        return Err(RefineError::Input("more candidates than vertices"));
    }
    if n as u64 + s > vertex_capacity as u64 || s > split_capacity as u64 {
        return Err(RefineError::Capacity {
            what: "vertices",
            needed: n as u64 + s,
            capacity: vertex_capacity as u64,
        });
    }
    Ok(())
}

/// The most splits one round can hold, the room of the per-round record
/// and split buffers: a round of `s` splits starts with `n >= s` vertices
/// (the flagged ones are distinct) and ends with `n + s <= vertex_capacity`,
/// so `s <= vertex_capacity / 2`; and `s <= vertex_capacity - v0`.
pub fn round_split_capacity(vertex_capacity: u32, v0: u32) -> u32 {
    (vertex_capacity / 2)
        .min(vertex_capacity.saturating_sub(v0))
        .max(1)
}

/// 2^bits, or 0 when every u32 is a valid coordinate.
pub fn position_limit(bits: u8) -> u32 {
    if bits >= 32 { 0 } else { 1u32 << bits }
}

#[cfg(test)]
mod tests {
    use super::round_split_capacity;

    #[test]
    fn a_round_holds_at_most_half_the_capacity() {
        // 4M vertices from a 16-vertex seed: 2,097,152 splits a round at
        // most (48-byte records: 100 MB, under lavapipe's 128 MiB binding).
        assert_eq!(round_split_capacity(4_194_304, 16), 2_097_152);
        // A seed of most of the vertices: the splits left bound it.
        assert_eq!(round_split_capacity(10, 8), 2);
        assert_eq!(round_split_capacity(10, 10), 1);
        assert_eq!(round_split_capacity(1, 1), 1);
        assert_eq!(round_split_capacity(u32::MAX, 0), u32::MAX / 2);
    }
}
