//! Buffer layouts shared by the decoder kernels and their host, mirroring
//! decoder-core's `MeshState` arrays (positions, corners, opposite,
//! vertex_corner, deficit) plus the per-round work buffers.

use bytemuck::{Pod, Zeroable};

/// "No vertex" (the ghost) and "no corner" (a boundary edge's opposite), as
/// decoder-core's `limits::NONE`.
pub const NONE: u32 = u32::MAX;
/// Deficit of a vertex that never splits again.
pub const LEAF: u32 = 0xFF;
/// Threads per workgroup of every decoder kernel.
pub const WORKGROUP: u32 = 256;
/// Words per split in the `splits` work buffer (split_apply.wgsl).
pub const SPLIT_WORDS: u32 = 8;
/// Slots of the `counts` buffer (common.wgsl).
pub const COUNT_V: usize = 0;
pub const COUNT_T: usize = 1;
pub const COUNT_CANDIDATES: usize = 2;
pub const COUNT_ERROR: usize = 3;
/// Words of the `counts` buffer.
pub const COUNT_WORDS: usize = 4;

/// One split record as the GPU reads it (split_apply.wgsl: `Record`): the
/// paper's record with positions resolved (decoder-core's `SplitRecord`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuRecord {
    pub offset: u32,
    pub distance: u32,
    /// 0 or 1: arc 1 goes to P (0) or C (1).
    pub config: u32,
    pub deficit_p: u32,
    pub deficit_c: u32,
    pub position_p: [u32; 3],
    pub position_c: [u32; 3],
    pub _pad: u32,
}

/// Per-dispatch parameters (common.wgsl: `Params`), one 256-byte slot each.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct Params {
    pub n: u32,
    pub candidates: u32,
    pub splits: u32,
    pub sort_len: u32,
    pub tri_limit: u32,
    pub pos_limit: u32,
    pub arg0: u32,
    pub arg1: u32,
    pub arg2: u32,
    /// The stream's [`Schedule`] ([`Schedule::word`]), in every slot.
    pub schedule: u32,
    pub _pad: [u32; 2],
}

/// Which vertices split in which round (SPEC §3.2 header flag bit 1, §6.2,
/// §7.3; format 3.6), as the kernels take it: the candidates, and what the
/// per-vertex `deficit` word holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Schedule {
    /// Deficits; the candidates are the deficit-0 vertices (formats 3.0-3.5).
    #[default]
    SplitValences,
    /// Valences capped at 255; every vertex below n is a candidate.
    EveryVertex,
}

impl Schedule {
    /// `Params::schedule` (common.wgsl: SCHEDULE_EVERY_VERTEX): the header
    /// flag bit's value.
    pub const fn word(self) -> u32 {
        match self {
            Schedule::SplitValences => 0,
            Schedule::EveryVertex => 1,
        }
    }
}

/// Bytes between two parameter slots (the minimum uniform-buffer offset
/// alignment every wgpu adapter supports).
pub const PARAM_SLOT: u64 = 256;

/// A fault found by the kernels, decoded from the error key
/// `(split + 1) * 8 + code` (common.wgsl). `split` is the index of the split
/// in the round (split order, 0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelFault {
    /// The GPU's candidate count or flag count differs from the host's
    /// (SPEC class count-mismatch).
    CountMismatch,
    /// A ring longer than 255 (valence-overflow).
    RingTooLong { split: u32 },
    /// A flagged vertex with a flagged neighbour. No stream can cause it
    /// (SPEC §7.2: a neighbour of a flagged vertex has no flag), so it
    /// means the host handed the kernels flags it did not read by §7.3: a
    /// driver bug, reported as the reference decoder's `api-misuse`.
    AdjacentFlags { split: u32 },
    /// `d == 0` or `o + d >= k` (ring-offset-out-of-range).
    RingOffsetOutOfRange { split: u32 },
    /// P or C outside `0 .. 2^bits` (position-out-of-range).
    PositionOutOfRange { split: u32 },
    /// Valence + deficit of P or C above 255, or a wing's deficit exhausted
    /// (valence-overflow; schedule `split-valences` only).
    ValenceOverflow { split: u32 },
    /// The split would pass the level's triangle count (count-mismatch).
    TriangleLimit { split: u32 },
}

impl KernelFault {
    /// Decodes the `counts[COUNT_ERROR]` word; `None` when no fault.
    pub fn from_key(key: u32) -> Option<KernelFault> {
        if key == NONE {
            return None;
        }
        let split = (key / 8).wrapping_sub(1);
        Some(match (key / 8, key % 8) {
            (0, _) => KernelFault::CountMismatch,
            (_, 1) => KernelFault::RingTooLong { split },
            (_, 2) => KernelFault::AdjacentFlags { split },
            (_, 3) => KernelFault::RingOffsetOutOfRange { split },
            (_, 4) => KernelFault::PositionOutOfRange { split },
            (_, 5) => KernelFault::ValenceOverflow { split },
            _ => KernelFault::TriangleLimit { split },
        })
    }

    /// The SPEC §10.1 error class.
    pub fn class(self) -> &'static str {
        match self {
            KernelFault::CountMismatch | KernelFault::TriangleLimit { .. } => "count-mismatch",
            KernelFault::RingTooLong { .. } | KernelFault::ValenceOverflow { .. } => {
                "valence-overflow"
            }
            KernelFault::AdjacentFlags { .. } => "api-misuse",
            KernelFault::RingOffsetOutOfRange { .. } => "ring-offset-out-of-range",
            KernelFault::PositionOutOfRange { .. } => "position-out-of-range",
        }
    }
}

impl core::fmt::Display for KernelFault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            KernelFault::CountMismatch => write!(f, "{}: candidate or flag count", self.class()),
            KernelFault::RingTooLong { split }
            | KernelFault::AdjacentFlags { split }
            | KernelFault::RingOffsetOutOfRange { split }
            | KernelFault::PositionOutOfRange { split }
            | KernelFault::ValenceOverflow { split }
            | KernelFault::TriangleLimit { split } => {
                write!(f, "{} at split {split} of the round", self.class())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_match_the_wgsl_structs() {
        assert_eq!(core::mem::size_of::<GpuRecord>(), 48);
        assert_eq!(core::mem::size_of::<Params>(), 48);
        assert!(core::mem::size_of::<Params>() as u64 <= PARAM_SLOT);
    }

    #[test]
    fn error_keys_decode() {
        assert_eq!(KernelFault::from_key(NONE), None);
        assert_eq!(KernelFault::from_key(0), Some(KernelFault::CountMismatch));
        assert_eq!(
            KernelFault::from_key(3 * 8 + 2),
            Some(KernelFault::AdjacentFlags { split: 2 })
        );
        assert_eq!(
            KernelFault::from_key(8 + 3).map(KernelFault::class),
            Some("ring-offset-out-of-range")
        );
    }
}
