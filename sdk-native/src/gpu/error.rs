//! What can go wrong when decoding on the GPU.

use splitstream_decoder_core::Error;
use splitstream_kernels::decode::KernelFault;
use splitstream_kernels::decode::host::RefineError;
use splitstream_kernels::gpu::GpuError;

use super::stream::CaptureError;

/// One error for GPU decoding; [`GpuDecodeError::class`] gives the SPEC
/// §10.1 class for the faults of a stream.
#[derive(Debug)]
pub enum GpuDecodeError {
    /// The CPU reading path (decoder-core) found the stream's first fault.
    Stream(Error),
    /// The kernels found a fault in a round.
    Kernel { round: usize, fault: KernelFault },
    /// The device could not be opened or failed.
    Device(RefineError),
    /// The GPU's state hash differs from decoder-core's (`round` 0 is the
    /// seed, then rounds from 1).
    HashMismatch { round: usize, gpu: u64, cpu: u64 },
    /// The GPU's corner-table adjacency is inconsistent after a round.
    Adjacency { round: usize, detail: String },
    /// decoder-core's round procedure changed in a way the capture does not
    /// follow.
    Capture,
}

impl GpuDecodeError {
    /// The SPEC §10.1 class of a stream fault; `None` for failures of the
    /// decoder itself (device, mismatch).
    pub fn class(&self) -> Option<&'static str> {
        match self {
            GpuDecodeError::Stream(e) => Some(e.class()),
            GpuDecodeError::Kernel { fault, .. } => Some(fault.class()),
            _ => None,
        }
    }

    /// Whether the GPU is simply not there (tests skip outside CI).
    pub fn is_unavailable(&self) -> bool {
        matches!(self, GpuDecodeError::Device(RefineError::Gpu(e)) if e.is_unavailable())
    }

    /// Whether the stream's mesh is too large for the device's buffer
    /// limits (a capacity of this device, not a fault of the stream).
    pub fn is_too_large(&self) -> bool {
        matches!(
            self,
            GpuDecodeError::Device(RefineError::Gpu(GpuError::TooLarge { .. }))
        )
    }
}

impl core::fmt::Display for GpuDecodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            GpuDecodeError::Stream(e) => write!(f, "stream: {e}"),
            GpuDecodeError::Kernel { round, fault } => write!(f, "GPU, round {round}: {fault}"),
            GpuDecodeError::Device(e) => write!(f, "GPU: {e}"),
            GpuDecodeError::HashMismatch { round, gpu, cpu } => write!(
                f,
                "state hash after round {round}: GPU {gpu:016x}, decoder-core {cpu:016x}"
            ),
            GpuDecodeError::Adjacency { round, detail } => {
                write!(f, "GPU adjacency after round {round}: {detail}")
            }
            GpuDecodeError::Capture => {
                f.write_str("decoder-core asked for flags out of candidate order")
            }
        }
    }
}

impl std::error::Error for GpuDecodeError {}

impl From<RefineError> for GpuDecodeError {
    fn from(e: RefineError) -> Self {
        GpuDecodeError::Device(e)
    }
}

impl From<GpuError> for GpuDecodeError {
    fn from(e: GpuError) -> Self {
        GpuDecodeError::Device(RefineError::Gpu(e))
    }
}

impl From<CaptureError> for GpuDecodeError {
    fn from(e: CaptureError) -> Self {
        match e {
            CaptureError::Stream(e) => GpuDecodeError::Stream(e),
            CaptureError::FlagOrder => GpuDecodeError::Capture,
        }
    }
}
