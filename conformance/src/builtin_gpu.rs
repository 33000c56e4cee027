//! The `wgpu` built-in decoder (feature `gpu`): sdk-native's GPU decoding,
//! phase 1. decoder-core reads the stream (entropy decoding, records with
//! resolved positions) and the refinement rounds run on a wgpu device
//! (splitstream-kernels' decoder kernels); the hashes reported are the
//! GPU's, read back after the seed and after every round.
//!
//! Stream faults are reported by the CPU reading path (decoder-core), which
//! meets every fault before the round reaches the GPU; ring offsets in
//! particular are checked by decoder-core's record reader (`o + d < k`)
//! before upload. The kernels check the split rules again on the device
//! (splitstream-kernels `KernelFault`), which the kernels' own tests
//! exercise.

use std::sync::OnceLock;

use splitstream_sdk_native::gpu::{Api, GpuDevice, decode};

use crate::protocol::{Outcome, Verdict};

/// One device per API for the whole run (opening one per vector would
/// dominate).
fn device(api: Api) -> Result<&'static GpuDevice, &'static str> {
    static WGPU: OnceLock<Result<GpuDevice, String>> = OnceLock::new();
    static OPENCL: OnceLock<Result<GpuDevice, String>> = OnceLock::new();
    let cell = match api {
        Api::Wgpu => &WGPU,
        Api::OpenCl => &OPENCL,
    };
    cell.get_or_init(|| GpuDevice::open(api).map_err(|e| e.to_string()))
        .as_ref()
        .map_err(String::as_str)
}

/// Decodes `stream` with the rounds on a wgpu device.
pub fn wgpu(stream: &[u8]) -> Outcome {
    on(Api::Wgpu, stream)
}

/// Decodes `stream` with the rounds on an OpenCL device (feature `opencl`).
#[cfg(feature = "opencl")]
pub fn opencl(stream: &[u8]) -> Outcome {
    on(Api::OpenCl, stream)
}

fn on(api: Api, stream: &[u8]) -> Outcome {
    let ctx = match device(api) {
        Ok(ctx) => ctx,
        Err(e) => return Outcome::broken(format!("no {api} device: {e}")),
    };
    let run = decode(ctx, stream);
    let verdict = match &run.result {
        Ok(()) => Verdict::Ok,
        Err(e) => match e.class() {
            Some(class) => Verdict::Error(class.to_string()),
            None => return Outcome::broken(e.to_string()),
        },
    };
    Outcome {
        hashes: run.hashes,
        verdict,
    }
}
