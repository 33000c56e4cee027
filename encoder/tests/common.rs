//! Meshes shared by the encoder's integration tests.
#![allow(dead_code)]

use splitstream_encoder::Mesh;

/// An icosphere: `subdivisions` rounds of 4-to-1 splits of an icosahedron,
/// projected to the unit sphere. Closed, genus 0, counter-clockwise outside.
pub fn icosphere(subdivisions: usize) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(triangles.len() * 4);
        let mut mid = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (pa, pb) = (positions[a as usize], positions[b as usize]);
                positions.push(std::array::from_fn(|k| (pa[k] + pb[k]) / 2.0));
                (positions.len() - 1) as u32
            })
        };
        for &[a, b, c] in &triangles {
            let ab = mid(a, b, &mut positions);
            let bc = mid(b, c, &mut positions);
            let ca = mid(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    for p in &mut positions {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        *p = p.map(|x| x / l);
    }
    Mesh {
        positions,
        triangles,
    }
}

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
