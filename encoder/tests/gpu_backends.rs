//! The GPU backends of the simplifier (`--backend wgpu|opencl`) on real
//! devices (Mesa lavapipe for Vulkan and pocl for OpenCL on CI): streams
//! round-trip exactly, quality stays within a few percent of the CPU
//! backend, and a missing device is a clear error.
//!
//! Without an adapter the tests print a skip note, except under CI (the
//! `CI` variable set), where they fail.

mod common;
mod roundtrip_check;

use std::process::Command;

use roundtrip_check::assert_roundtrip;
use splitstream_decoder_core::PositionMode;
use splitstream_encoder::emit::EncodeOptions;
use splitstream_encoder::input::fractal_terrain;
use splitstream_encoder::metrics::surface_distance;
use splitstream_encoder::quantize::{Units, quantize};
use splitstream_encoder::simplify::{Backend, Checked, SimplifyOptions, simplify_on};

const GPU: [Backend; 2] = [Backend::Wgpu, Backend::OpenCl];

/// Whether `backend` can run here; panics under CI when it is built in but
/// has no device. A backend left out of the build (cargo feature off; CI
/// tests OpenCL in a second run with `--features opencl`) is skipped.
fn available(backend: Backend) -> bool {
    let api = backend.api().expect("a GPU backend");
    match splitstream_kernels::gpu::describe(api) {
        Ok(_) => true,
        Err(splitstream_kernels::gpu::GpuError::NotCompiled { .. }) => {
            eprintln!("skipped {backend}: not in this build");
            false
        }
        Err(e) if std::env::var_os("CI").is_none() => {
            eprintln!("skipped {backend}: {e}");
            false
        }
        Err(e) => panic!("{backend} must be available under CI: {e}"),
    }
}

#[test]
fn terrain_and_closed_mesh_roundtrip_on_each_backend() {
    for backend in GPU.into_iter().filter(|&b| available(b)) {
        let options = EncodeOptions {
            backend,
            ..EncodeOptions::default()
        };
        assert_roundtrip(&common::bumpy_grid(33, 29, 1), &options);
        assert_roundtrip(&fractal_terrain(48, 7), &options);
        assert_roundtrip(&common::icosphere(3), &options);
    }
}

#[test]
fn constrained_and_locked_modes_roundtrip() {
    for backend in GPU.into_iter().filter(|&b| available(b)) {
        let constrained = EncodeOptions {
            backend,
            position_mode: PositionMode::Constrained,
            ..EncodeOptions::default()
        };
        assert_roundtrip(&common::icosphere(2), &constrained);
        let locked = EncodeOptions {
            backend,
            lock_boundary: true,
            levels: 3,
            ..EncodeOptions::default()
        };
        assert_roundtrip(&common::bumpy_grid(20, 18, 3), &locked);
    }
}

/// Hausdorff and RMS distance to the input of each backend's mesh at 1/16
/// of the vertices, against the CPU backend's.
#[test]
fn quality_within_a_few_percent_of_the_cpu() {
    let cases = [
        ("terrain", fractal_terrain(96, 2012)),
        ("sphere", common::icosphere(4)),
    ];
    for (name, mesh) in &cases {
        let q = quantize(mesh, 14, Units::Linear);
        let input = q.to_mesh();
        let options = SimplifyOptions {
            target_vertices: mesh.positions.len() / 16,
            ..SimplifyOptions::default()
        };
        let measure = |backend: Backend| {
            let checked = Checked::new(&q).expect("a checked mesh");
            let s = simplify_on(backend, &checked, &options, |_| {}).expect("simplify");
            assert_eq!(s.alive_count, options.target_vertices, "{backend} {name}");
            surface_distance(&input, &s.to_mesh(&q), 100_000, 3)
        };
        let cpu = measure(Backend::Cpu);
        for backend in GPU.into_iter().filter(|&b| available(b)) {
            let gpu = measure(backend);
            let (h, r) = (gpu.hausdorff / cpu.hausdorff, gpu.rms / cpu.rms);
            eprintln!("{name} {backend}: Hausdorff x{h:.3}, RMS x{r:.3} of the CPU's");
            assert!(
                h < 1.10 && r < 1.05,
                "{name} {backend}: Hausdorff x{h:.3}, RMS x{r:.3}"
            );
        }
    }
}

/// With the device hidden (Vulkan asked for a backend this build lacks;
/// OpenCL pointed at an empty vendor directory), `splitstream encode`
/// fails with one line naming the backend, and no stream is written.
#[test]
fn a_missing_device_is_a_clear_error() {
    let dir = std::env::temp_dir().join(format!("splitstream-gpu-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("tri.off");
    std::fs::write(
        &input,
        "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 1\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    let out = dir.join("out.sps");
    for (backend, var, value, expected) in [
        (
            "wgpu",
            "WGPU_BACKEND",
            "metal",
            "backend wgpu: no adapter found",
        ),
        (
            "opencl",
            "OCL_ICD_VENDORS",
            dir.to_str().unwrap(),
            "backend opencl: no adapter found",
        ),
    ] {
        if backend == "opencl" && !cfg!(feature = "opencl") {
            continue;
        }
        let output = Command::new(env!("CARGO_BIN_EXE_splitstream"))
            .args([
                "encode",
                input.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .args(["--backend", backend])
            .env(var, value)
            .env_remove("OPENCL_VENDOR_PATH")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{backend}: {stderr}");
        assert!(stderr.contains(expected), "{backend}: {stderr}");
        assert!(!out.exists(), "{backend} wrote a stream");
    }
}
