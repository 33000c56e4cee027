//! GPU decoding (feature `gpu`): the refinement rounds run on a wgpu device
//! (or, with feature `opencl`, an OpenCL device) with splitstream-kernels'
//! decoder kernels (candidates by atomic append,
//! bitonic sort, prefix numbering, parallel split apply), for streams of
//! either schedule (SPEC §3.2: `split-valences`, or `every-vertex`, whose
//! candidates are every vertex and whose per-vertex bytes are valences).
//!
//! Phase 1 (this module): the CPU reads the stream with decoder-core
//! ([`capture_stream`]: headers, chunks, entropy decoding, records with
//! resolved positions; [`capture_stream_two_threads`], which [`decode`] and
//! [`verify`] use, reads a large level's records on a second thread), the
//! GPU replays every round from its flags and
//! records ([`GpuRefiner`], [`replay()`]) and its state hash is read back
//! after every round. Faults of a stream are found by decoder-core while
//! reading (ring offsets included: its record reader checks `o + d < k`
//! before the record reaches the GPU); the kernels check the same rules
//! again on the device ([`splitstream_kernels::decode::KernelFault`]).
//!
//! ```no_run
//! # let stream: &[u8] = &[];
//! use splitstream_sdk_native::gpu::{Api, GpuDevice, decode};
//! let device = GpuDevice::open(Api::Wgpu).unwrap();
//! let run = decode(&device, stream);
//! run.result.unwrap();
//! println!("final state hash {:016x}", run.hashes.last().unwrap());
//! ```

pub mod bench;
pub mod capture;
pub mod device;
pub mod error;
pub mod refiner;
pub mod replay;
pub mod stream;

pub use bench::{BenchReport, bench};
pub use capture::{Capture, CapturedRound};
pub use device::GpuDevice;
pub use error::GpuDecodeError;
pub use refiner::{GpuRefiner, snapshot_hash};
pub use replay::{GpuRun, ReplayOptions, replay};
pub use splitstream_kernels::gpu::Api;

use crate::threaded::TWO_THREADS_FROM_SPLITS;
pub use stream::{BaseState, CapturedStream, capture_stream, capture_stream_two_threads};

/// Decodes `stream`: decoder-core reads it, the GPU refines it; the hashes
/// are the GPU's, after the seed and after every round.
pub fn decode(device: &GpuDevice, stream: &[u8]) -> GpuRun {
    replay(
        device,
        &capture_stream_two_threads(stream, false, TWO_THREADS_FROM_SPLITS),
        ReplayOptions::default(),
    )
}

/// Decodes `stream` on the GPU and checks the GPU's state against
/// decoder-core's after the seed and after every round (hash and, with
/// `check_adjacency`, the corner-table adjacency).
pub fn verify(device: &GpuDevice, stream: &[u8], check_adjacency: bool) -> GpuRun {
    let options = ReplayOptions {
        compare: true,
        check_adjacency,
    };
    let captured = capture_stream_two_threads(stream, true, TWO_THREADS_FROM_SPLITS);
    replay(device, &captured, options)
}
