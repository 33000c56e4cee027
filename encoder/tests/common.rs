//! Meshes shared by the encoder's integration tests.
#![allow(dead_code)]

use splitstream_encoder::Mesh;
use splitstream_encoder::input::{Grid, grid_to_mesh};

pub use splitstream_encoder::input::icosphere;

/// A `w` x `h` height-field grid with a bumpy surface and a boundary.
pub fn bumpy_grid(w: usize, h: usize, seed: u64) -> Mesh {
    let elevations = (0..w * h)
        .map(|k| {
            let (fx, fy) = ((k % w) as f64, (k / w) as f64);
            (fx * 0.7 + seed as f64).sin() * 2.0
                + (fy * 0.45).cos() * 3.0
                + ((fx * fy) * 0.05).sin()
        })
        .collect();
    grid_to_mesh(&Grid {
        rows: h,
        cols: w,
        elevations,
        origin: [0.0, 0.0],
        spacing: [10.0, 10.0],
        nodata: None,
        coordinates: None,
    })
}
