//! Meshes shared by the encoder's integration tests.
#![allow(dead_code)]

use splitstream_encoder::Mesh;

pub use splitstream_encoder::input::icosphere;

/// A `w` x `h` height-field grid with a bumpy surface and a boundary.
pub fn bumpy_grid(w: usize, h: usize, seed: u64) -> Mesh {
    let mut positions = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f64, y as f64);
            let z = (fx * 0.7 + seed as f64).sin() * 2.0
                + (fy * 0.45).cos() * 3.0
                + ((fx * fy) * 0.05).sin();
            positions.push([fx * 10.0, fy * 10.0, z]);
        }
    }
    let mut triangles = Vec::new();
    for y in 0..h - 1 {
        for x in 0..w - 1 {
            let i = (y * w + x) as u32;
            let (r, u, ru) = (i + 1, i + w as u32, i + w as u32 + 1);
            triangles.push([i, r, ru]);
            triangles.push([i, ru, u]);
        }
    }
    Mesh {
        positions,
        triangles,
    }
}
