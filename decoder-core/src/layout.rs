//! How much memory a decoder needs, and where each array lives in it (SPEC §9).
//!
//! Everything a decoder touches is carved from one caller-owned byte buffer:
//! no allocation, and one number for the caller to size.

use crate::Error;
use crate::corner_refs::{self, CornerRefs};
use crate::limits::rans::{MAX_LANES, TABLE_WORDS};
use crate::limits::substream::SLOTS;
use crate::rans::LANE_WORDS;

/// Bytes of a substream slot under rANS: tables, then the lanes (SPEC §9).
pub const RANS_SLOT_BYTES: u64 = 4 * (TABLE_WORDS + LANE_WORDS * MAX_LANES as usize) as u64;
use crate::state::{MeshState, StateMemory};

/// Alignment of every region, and of the buffer start the layout assumes.
pub const ALIGN: usize = 8;

/// Byte ranges of the workspace regions for given capacities. Sizes are
/// computed in u64 so that 32-bit targets (wasm32) cannot overflow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub vertex_capacity: u32,
    pub triangle_capacity: u32,
    pub max_chunk_len: u32,
    ranges: [(u64, u64); 7],
    chunk_buffer_len: u64,
    /// Bytes per corner reference (the swing table, a corner per vertex): 3 when
    /// every corner index fits in 24 bits, else 4 (SPEC §9).
    pub corner_ref_width: usize,
    /// Total bytes, from an 8-aligned start.
    pub total: u64,
}

fn round_up(n: u64) -> u64 {
    n.div_ceil(ALIGN as u64) * ALIGN as u64
}

impl Layout {
    /// Layout for a decoder that holds up to `vertex_capacity` vertices and
    /// `triangle_capacity` triangles of a stream whose base mesh has
    /// `base_vertices` and `base_triangles`, with chunks up to `max_chunk_len`.
    pub fn new(
        vertex_capacity: u32,
        triangle_capacity: u32,
        base_vertices: u32,
        base_triangles: u32,
        max_chunk_len: u32,
    ) -> Layout {
        let v = vertex_capacity as u64;
        let t = triangle_capacity as u64;
        let width = corner_refs::width_for(3 * t);
        let base_scratch = 4 * MeshState::base_scratch_len(base_vertices, base_triangles) as u64;
        // A slot holds a byte-codec chunk, or a rANS chunk's tables and lanes.
        let chunk_buffer_len = round_up((max_chunk_len as u64).max(RANS_SLOT_BYTES));
        let sizes = [
            12 * v,
            12 * t,
            corner_refs::bytes_for(3 * t, width).max(base_scratch),
            corner_refs::bytes_for(v, width),
            v,
            3 * 8 * v.div_ceil(64),
            SLOTS as u64 * chunk_buffer_len,
        ];
        let mut ranges = [(0u64, 0u64); 7];
        let mut at = 0;
        for (range, size) in ranges.iter_mut().zip(sizes) {
            *range = (at, at + size);
            at = round_up(at + size);
        }
        Layout {
            vertex_capacity,
            triangle_capacity,
            max_chunk_len,
            ranges,
            chunk_buffer_len,
            corner_ref_width: width,
            total: at,
        }
    }

    /// Bytes a caller must provide when it cannot guarantee an 8-aligned
    /// buffer: the SPEC §9 total and 7 bytes of alignment slack.
    pub fn bytes_unaligned(&self) -> u64 {
        self.total + ALIGN as u64 - 1
    }

    /// Whether `buffer` holds this layout (SPEC §9) once aligned.
    pub fn fits(&self, buffer: &[u8]) -> bool {
        let skip = buffer.as_ptr().align_offset(ALIGN).min(ALIGN);
        buffer.len().saturating_sub(skip) as u64 >= self.total
    }

    /// Carves `buffer` into the state arrays and the per-substream chunk
    /// buffers: the regions of SPEC §9, in its order.
    pub fn carve<'ws>(
        &self,
        buffer: &'ws mut [u8],
    ) -> Result<(StateMemory<'ws>, [&'ws mut [u8]; SLOTS]), Error> {
        let skip = buffer.as_ptr().align_offset(ALIGN).min(ALIGN);
        let too_small = Error::WorkspaceTooSmall {
            needed: usize::try_from(self.total)
                .unwrap_or(usize::MAX)
                .saturating_add(skip),
            available: buffer.len(),
        };
        if !self.fits(buffer) {
            return Err(too_small);
        }
        // fits() proved total <= buffer.len(), so these conversions succeed.
        let r = self.ranges.map(|(a, b)| (a as usize, b as usize));
        let (_, rest) = buffer.split_at_mut(skip);
        let (region, _) = rest.split_at_mut(self.total as usize);
        let (positions, rest) = take(region, r[0], 0);
        let (corners, rest) = take(rest, r[1], r[0].1);
        let (swing, rest) = take(rest, r[2], r[1].1);
        let (vertex_corner, rest) = take(rest, r[3], r[2].1);
        let (deficit, rest) = take(rest, r[4], r[3].1);
        let (candidates, rest) = take(rest, r[5], r[4].1);
        let (buffers, _) = take(rest, r[6], r[5].1);
        let mut buffers = buffers;
        let mut slots: [&mut [u8]; SLOTS] = Default::default();
        for slot in slots.iter_mut() {
            let (head, tail) = buffers.split_at_mut(self.chunk_buffer_len as usize);
            *slot = head;
            buffers = tail;
        }
        let memory = StateMemory {
            positions: cast(positions)?,
            corners: cast(corners)?,
            swing: CornerRefs::new(swing, self.corner_ref_width),
            vertex_corner: CornerRefs::new(vertex_corner, self.corner_ref_width),
            deficit,
            candidates: cast(candidates)?,
        };
        Ok((memory, slots))
    }
}

/// Splits region `range` (absolute offsets) off `rest`, which starts at `at`.
fn take(rest: &mut [u8], range: (usize, usize), at: usize) -> (&mut [u8], &mut [u8]) {
    let (_, rest) = rest.split_at_mut(range.0 - at);
    rest.split_at_mut(range.1 - range.0)
}

fn cast<T: bytemuck::Pod>(bytes: &mut [u8]) -> Result<&mut [T], Error> {
    let len = bytes.len();
    bytemuck::try_cast_slice_mut(bytes).map_err(|_| Error::WorkspaceTooSmall {
        needed: len + core::mem::size_of::<T>(),
        available: len,
    })
}
