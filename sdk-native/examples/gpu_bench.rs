//! Checks and times GPU decoding of streams given as files:
//!
//! ```sh
//! cargo run --release -p splitstream-sdk-native --features gpu --example gpu_bench -- STREAM.sps...
//! ```
//!
//! For each stream: the GPU's state hash is compared with decoder-core's
//! after the seed and after every round, then `sdk_native::gpu::bench`
//! times decoder-core against the GPU refinement (best of 3).

use splitstream_sdk_native::gpu::{Api, GpuDevice, bench, verify};

fn main() -> Result<(), String> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        return Err("usage: gpu_bench STREAM.sps...".into());
    }
    // SPLITSTREAM_GPU_API=opencl picks the OpenCL port (feature `opencl`).
    let api = match std::env::var("SPLITSTREAM_GPU_API").as_deref() {
        Ok("opencl") => Api::OpenCl,
        _ => Api::Wgpu,
    };
    let ctx = GpuDevice::open(api).map_err(|e| e.to_string())?;
    for path in paths {
        let stream = std::fs::read(&path).map_err(|e| format!("{path}: {e}"))?;
        let run = verify(&ctx, &stream, false);
        run.result.map_err(|e| format!("{path}: {e}"))?;
        println!(
            "{path}: {} state hashes equal to decoder-core's",
            run.hashes.len()
        );
        let report = bench(&ctx, &stream, 3).map_err(|e| format!("{path}: {e}"))?;
        println!("{report}\n");
    }
    Ok(())
}
