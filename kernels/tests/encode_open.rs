//! Opening the encoder's engine reports where its time went
//! (`Engine::open_times`, printed by the encoder under `SPLITSTREAM_DEBUG`),
//! on each API compiled in (lavapipe and pocl in CI). Without a device the
//! test skips with a note, except under CI.
#![cfg(any(feature = "wgpu", feature = "opencl"))]

use std::time::{Duration, Instant};

use splitstream_kernels::encode::layout::{ALIVE, BOUNDARY, NONE};
use splitstream_kernels::encode::{Engine, MeshData};
use splitstream_kernels::gpu::{Api, GpuError};

fn available(opened: Result<Engine, GpuError>) -> Option<Engine> {
    match opened {
        Ok(engine) => Some(engine),
        Err(e) if e.is_unavailable() && std::env::var_os("CI").is_none() => {
            eprintln!("skipping {}: {e}", e.api());
            None
        }
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn opening_reports_where_its_time_went() {
    // One triangle, every edge on the boundary.
    let corners = [[0, NONE], [1, NONE], [2, NONE]];
    let corner_of = [0, 1, 2];
    let flags = ALIVE | BOUNDARY;
    let vertices = [[0, 0, 0, flags], [8, 0, 0, flags], [0, 8, 0, flags]];
    let mesh = MeshData {
        corners: &corners,
        corner_of: &corner_of,
        vertices: &vertices,
    };
    let apis = [
        #[cfg(feature = "wgpu")]
        Api::Wgpu,
        #[cfg(feature = "opencl")]
        Api::OpenCl,
    ];
    for api in apis {
        let started = Instant::now();
        let Some(engine) = available(Engine::open(api, &mesh)) else {
            continue;
        };
        let wall = started.elapsed();
        let times = engine.open_times();
        eprintln!("{api} open: {times}");
        assert!(
            times.compile > Duration::ZERO,
            "{api}: compiling takes time"
        );
        let parts = times.context + times.compile + times.buffers + times.upload;
        assert!(parts <= wall, "{api}: {parts:?} of parts in {wall:?}");
        let line = times.to_string();
        for part in ["context", "compile", "buffers", "upload"] {
            assert!(line.contains(part), "{line}");
        }
    }
}
