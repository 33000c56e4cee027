//! GPU decoding (feature `gpu`; OpenCL too with feature `opencl`) checked
//! against decoder-core after the seed and after EVERY round, on every valid
//! vector and on a 100k-vertex terrain, plus the GPU built-ins against the
//! whole vector set. Runs on Mesa lavapipe (WGPU_BACKEND=vulkan) and pocl in
//! CI; without a device the tests print a skip note, except under `CI`,
//! where they fail.
#![cfg(feature = "gpu")]

use std::time::Instant;

use splitstream_conformance::builtin_gpu;
use splitstream_conformance::manifest::{Manifest, default_vector_dir, hex};
use splitstream_conformance::protocol::Outcome;
use splitstream_conformance::runner::run_vectors;
use splitstream_decoder_core::Schedule;
use splitstream_encoder::emit::{EncodeOptions, encode};
use splitstream_encoder::input::fractal_terrain;
use splitstream_sdk_native::gpu::{Api, GpuDevice, verify};

/// Every API compiled in whose device opens.
fn devices() -> Vec<GpuDevice> {
    // Tests run in parallel threads; the OpenCL ICD loader (pocl) can report
    // no device when two threads enumerate at once.
    static OPENING: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = OPENING.lock().unwrap_or_else(|e| e.into_inner());
    let mut apis = vec![Api::Wgpu];
    if cfg!(feature = "opencl") {
        apis.push(Api::OpenCl);
    }
    apis.into_iter().filter_map(open).collect()
}

fn open(api: Api) -> Option<GpuDevice> {
    match GpuDevice::open(api) {
        Ok(device) => Some(device),
        Err(e) if e.is_unavailable() && std::env::var_os("CI").is_none() => {
            eprintln!("skipping {api}: {e} (lavapipe: WGPU_BACKEND=vulkan; pocl: pocl-opencl-icd)");
            None
        }
        Err(e) => panic!("no {api} device under CI: {e}"),
    }
}

fn manifest() -> Manifest {
    Manifest::load(&default_vector_dir().join("manifest.json")).expect("committed manifest")
}

#[test]
fn every_valid_vector_matches_decoder_core_after_every_round() {
    let manifest = manifest();
    for device in devices() {
        let mut checked = 0;
        for v in manifest.vectors.iter().filter(|v| v.valid) {
            let stream = std::fs::read(default_vector_dir().join(&v.file)).expect("vector");
            let run = verify(&device, &stream, true);
            if let Err(e) = &run.result {
                panic!("{} on {}: {e}", v.name, device.info());
            }
            let hashes: Vec<String> = run.hashes.iter().map(|&h| hex(h)).collect();
            assert_eq!(hashes, v.round_hashes, "{} on {}", v.name, device.info());
            checked += 1;
        }
        assert!(checked > 0, "no valid vectors");
    }
}

/// A built-in decoder's function.
type Decode = fn(&[u8]) -> Outcome;

#[test]
fn gpu_builtins_pass_the_whole_vector_set() {
    let mut builtins: Vec<(Api, Decode)> = vec![(Api::Wgpu, builtin_gpu::wgpu)];
    #[cfg(feature = "opencl")]
    builtins.push((Api::OpenCl, builtin_gpu::opencl));
    let opened: Vec<Api> = devices().iter().map(|d| d.info().api).collect();
    for (api, decode) in builtins {
        if !opened.contains(&api) {
            continue;
        }
        let report =
            run_vectors(&manifest(), &default_vector_dir(), decode).expect("vectors readable");
        assert_eq!(report.failed(), 0, "{api}:\n{}", report.table());
    }
}

#[test]
fn terrain_of_100k_vertices_matches_decoder_core_after_every_round() {
    let devices = devices();
    if devices.is_empty() {
        return;
    }
    let mesh = fractal_terrain(320, 7);
    assert!(mesh.positions.len() >= 100_000);
    // Both schedules (SPEC §3.2): every vertex a candidate (the default,
    // 3.6), and the split valences' candidates, sorted on the device.
    for schedule in [Schedule::EveryVertex, Schedule::SplitValences] {
        let t = Instant::now();
        let options = EncodeOptions {
            schedule,
            ..EncodeOptions::default()
        };
        let encoded = encode(&mesh, &options, |_| {}).expect("encode");
        eprintln!(
            "terrain 320 x 320, {}: {} vertices, encoded in {:.1} s",
            schedule.name(),
            mesh.positions.len(),
            t.elapsed().as_secs_f64()
        );
        for device in &devices {
            let t = Instant::now();
            let run = verify(device, &encoded.stream, false);
            if let Err(e) = &run.result {
                panic!("terrain ({}) on {}: {e}", schedule.name(), device.info());
            }
            assert_eq!(run.hashes.len(), encoded.rounds + 1);
            eprintln!(
                "{}: {} hashes equal to decoder-core's in {:.1} s",
                device.info(),
                run.hashes.len(),
                t.elapsed().as_secs_f64()
            );
        }
    }
}
