//! [`GpuRefiner`]: a base state on the device, refined round by round from
//! the rounds' flags and records.

use splitstream_decoder_core::{Fnv1a, MeshState, Schedule};
use splitstream_kernels::decode::adjacency::check_adjacency;
use splitstream_kernels::decode::host::{
    BaseMesh, RefineError, RoundInput, Schedule as GpuSchedule, Snapshot,
};
#[cfg(feature = "opencl")]
use splitstream_kernels::decode::ocl_refine::OclRefiner;
use splitstream_kernels::decode::refine::Refiner;

use super::capture::CapturedRound;
use super::device::GpuDevice;
use super::error::GpuDecodeError;
use super::stream::BaseState;

/// The decoder's mesh on a device.
pub struct GpuRefiner<'c> {
    inner: Inner<'c>,
    rounds: usize,
}

/// The API's own refiner (same schedule and kernels, ported).
enum Inner<'c> {
    Wgpu(Refiner<'c>),
    #[cfg(feature = "opencl")]
    OpenCl(OclRefiner<'c>),
}

impl Inner<'_> {
    fn round(&mut self, input: RoundInput<'_>) -> Result<(), RefineError> {
        match self {
            Inner::Wgpu(r) => r.round(input),
            #[cfg(feature = "opencl")]
            Inner::OpenCl(r) => r.round(input),
        }
    }

    fn snapshot(&mut self, adjacency: bool) -> Result<Snapshot, RefineError> {
        match self {
            Inner::Wgpu(r) => r.snapshot(adjacency),
            #[cfg(feature = "opencl")]
            Inner::OpenCl(r) => r.snapshot(adjacency),
        }
    }

    fn wait(&self) -> Result<(), RefineError> {
        match self {
            Inner::Wgpu(r) => r.wait(),
            #[cfg(feature = "opencl")]
            Inner::OpenCl(r) => r.wait(),
        }
    }
}

impl<'c> GpuRefiner<'c> {
    /// Uploads `base` into buffers for up to `vertex_capacity` vertices and
    /// `triangle_capacity` triangles.
    pub fn new(
        device: &'c GpuDevice,
        base: &BaseState,
        vertex_capacity: u32,
        triangle_capacity: u32,
    ) -> Result<GpuRefiner<'c>, GpuDecodeError> {
        let mesh = BaseMesh {
            positions: &base.positions,
            triangles: &base.triangles,
            deficits: &base.deficits,
            bits: base.bits,
        };
        // SPEC §3.2 (3.6): the kernels' candidates and per-vertex bytes.
        let schedule = match base.schedule {
            Schedule::SplitValences => GpuSchedule::SplitValences,
            Schedule::EveryVertex => GpuSchedule::EveryVertex,
        };
        let (vcap, tcap) = (vertex_capacity, triangle_capacity);
        let inner = match device {
            GpuDevice::Wgpu(ctx) => {
                Inner::Wgpu(Refiner::with_schedule(ctx, mesh, schedule, vcap, tcap)?)
            }
            #[cfg(feature = "opencl")]
            GpuDevice::OpenCl(ctx) => {
                Inner::OpenCl(OclRefiner::with_schedule(ctx, mesh, schedule, vcap, tcap)?)
            }
        };
        Ok(GpuRefiner { inner, rounds: 0 })
    }

    /// Uploads decoder-core's current state (e.g. right after level 0's seed).
    pub fn from_state(
        device: &'c GpuDevice,
        state: &MeshState<'_>,
        vertex_capacity: u32,
        triangle_capacity: u32,
    ) -> Result<GpuRefiner<'c>, GpuDecodeError> {
        GpuRefiner::new(
            device,
            &BaseState::of(state),
            vertex_capacity,
            triangle_capacity,
        )
    }

    /// Submits one round (does not wait); `triangle_limit` is the current
    /// level's triangle count (SPEC §7.5).
    pub fn apply_round(
        &mut self,
        round: &CapturedRound,
        triangle_limit: u32,
    ) -> Result<(), GpuDecodeError> {
        self.inner.round(RoundInput {
            candidates: round.candidates,
            flags: &round.flags,
            records: &round.records,
            triangle_limit,
        })?;
        self.rounds += 1;
        Ok(())
    }

    /// Waits for the device and reads the state back; a fault found by the
    /// kernels since the last read is an error.
    pub fn snapshot(&mut self, adjacency: bool) -> Result<Snapshot, GpuDecodeError> {
        let snapshot = self.inner.snapshot(adjacency)?;
        if let Some(fault) = snapshot.fault {
            return Err(GpuDecodeError::Kernel {
                round: self.rounds,
                fault,
            });
        }
        if adjacency
            && let Err(detail) = check_adjacency(
                &snapshot.corners,
                &snapshot.opposite,
                &snapshot.vertex_corner,
            )
        {
            return Err(GpuDecodeError::Adjacency {
                round: self.rounds,
                detail,
            });
        }
        Ok(snapshot)
    }

    /// The state hash of SPEC §8 of the device's state.
    pub fn state_hash(&mut self) -> Result<u64, GpuDecodeError> {
        Ok(snapshot_hash(&self.snapshot(false)?))
    }

    /// Waits until every submitted round has run.
    pub fn wait(&self) -> Result<(), GpuDecodeError> {
        Ok(self.inner.wait()?)
    }
}

/// SPEC §8 over a read-back state: 64-bit FNV-1a of V, T, every vertex's
/// x, y, z and deficit (under `every-vertex`: valence), every triangle's
/// corners.
pub fn snapshot_hash(s: &Snapshot) -> u64 {
    let mut h = Fnv1a::default();
    h.u32(s.positions.len() as u32);
    h.u32((s.corners.len() / 3) as u32);
    for (p, &d) in s.positions.iter().zip(&s.deficits) {
        h.u32(p[0]);
        h.u32(p[1]);
        h.u32(p[2]);
        h.bytes(&[d]);
    }
    for &v in &s.corners {
        h.u32(v);
    }
    h.finish()
}
