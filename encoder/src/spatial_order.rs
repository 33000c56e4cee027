//! The mesh renumbered along a space-filling curve before it is simplified.
//!
//! The simplifier's passes walk each vertex's fan and read its neighbours'
//! quadrics, positions and requests: with neighbours numbered far apart,
//! every read is a cache miss. Input files come in any order (a mesh
//! written back from a decoder, or by a tool that renumbers, puts a fan's
//! vertices anywhere in a million), so the encoder numbers the vertices in
//! Z-order (Morton order) of their positions and the triangles by their
//! smallest vertex before it simplifies; the stream's permutation is mapped
//! back to the input's ids. On the 1M-vertex terrain the simplification
//! took 4.3 s before and 2.7 s after with the vertices in the order a
//! decoder gives them, 5.5 s and 2.5 s in a random order, and 2.5 s either
//! way in the raster's own order (encoder/BENCHMARKS.md, "Spatial order").
//!
//! The curve runs over the metric proportions of the mesh (each axis's
//! extent in metres, the largest spread over 2^21 cells): on a terrain,
//! whose heights span far fewer metres than its x and y, the curve then
//! follows x and y, where interleaving the heights' bits as equals
//! scattered neighbouring samples (slower than the raster order).

use rayon::prelude::*;

use crate::mesh::sorted_canonical;
use crate::quantize::QuantizedMesh;
use crate::simplify::Checked;

/// Bits per axis of the curve's keys (3 × 21 bits fit in a `u64`).
const KEY_BITS: u32 = 21;

/// A checked mesh (its indices in range, so the renaming cannot fail)
/// renumbered: vertices in Z-order of their metric positions (ties
/// by input id), each triangle rotated to start at its smallest new vertex
/// (the same orientation), triangles in ascending order of their three
/// vertices. Returns the renumbered mesh and `order`, where `order[new] =
/// old`. Apart from vertices at one position, the result does not depend
/// on how the input orders its vertices and triangles, or on which corner
/// each triangle starts at: the same stream comes from any such file.
pub fn spatially_ordered(checked: &Checked<'_>) -> (QuantizedMesh, Vec<u32>) {
    let mesh = checked.mesh();
    let order = vertex_order(mesh);
    let mut rank = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        rank[old as usize] = new as u32;
    }
    let positions = order
        .par_iter()
        .map(|&old| mesh.positions[old as usize])
        .collect();
    let triangles = sorted_canonical(&mesh.triangles, Some(&rank));
    (
        QuantizedMesh {
            positions,
            triangles,
            // Field by field: `..mesh.clone()` copied the whole mesh only
            // to keep these.
            bits: mesh.bits,
            origin: mesh.origin,
            scale: mesh.scale,
            metric: mesh.metric,
            on_lattice: mesh.on_lattice,
        },
        order,
    )
}

/// Input ids in Z-order of the metric positions, ties by id.
fn vertex_order(mesh: &QuantizedMesh) -> Vec<u32> {
    let top = mesh
        .positions
        .par_iter()
        .copied()
        .reduce(|| [0; 3], |a, b| std::array::from_fn(|k| a[k].max(b[k])));
    let extent: [f64; 3] = std::array::from_fn(|k| top[k] as f64 * mesh.metric[k].abs());
    let largest = extent.iter().copied().fold(0.0f64, f64::max);
    let cells = ((1u64 << KEY_BITS) - 1) as f64;
    // Grid units to curve cells per axis; a flat mesh (every extent 0) has
    // one cell, and its order is the input's.
    let factor: [f64; 3] = std::array::from_fn(|k| {
        if largest > 0.0 {
            mesh.metric[k].abs() / largest * cells
        } else {
            0.0
        }
    });
    let mut keyed: Vec<(u64, u32)> = mesh
        .positions
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let cell = |k: usize| ((p[k] as f64 * factor[k]) as u64).min(cells as u64);
            (morton(cell(0), cell(1), cell(2)), i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Interleaves the low 21 bits of x, y and z: x in bit 0, y in bit 1, z in
/// bit 2, and so on up.
fn morton(x: u64, y: u64, z: u64) -> u64 {
    spread(x) | spread(y) << 1 | spread(z) << 2
}

/// The low 21 bits of `x`, two zero bits after each.
fn spread(x: u64) -> u64 {
    let mut x = x & ((1 << KEY_BITS) - 1);
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    (x | x << 2) & 0x1249_2492_4924_9249
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::canonical_triangle;
    use crate::quantize::{Lattice, Quantization, Units, quantize_with};

    fn renumbered(q: &QuantizedMesh) -> (QuantizedMesh, Vec<u32>) {
        spatially_ordered(&Checked::new(q).expect("a valid mesh"))
    }

    fn quantized(mesh: &crate::Mesh) -> QuantizedMesh {
        quantize_with(
            mesh,
            14,
            Units::Linear,
            Quantization::PerAxis,
            Lattice::Ignore,
        )
    }

    /// A raster of `w × h` samples in row order, heights in 0..1.
    fn raster(w: usize, h: usize) -> crate::Mesh {
        let grid = crate::input::Grid {
            rows: h,
            cols: w,
            elevations: (0..w * h).map(|i| ((i * 7) % 5) as f64 * 0.25).collect(),
            origin: [0.0, 0.0],
            spacing: [10.0, 10.0],
            nodata: None,
            coordinates: None,
        };
        crate::input::grid_to_mesh(&grid)
    }

    #[test]
    fn spread_interleaves_every_bit() {
        assert_eq!(morton(1, 0, 0), 1);
        assert_eq!(morton(0, 1, 0), 2);
        assert_eq!(morton(0, 0, 1), 4);
        assert_eq!(morton(2, 0, 0), 8);
        let all = (1 << KEY_BITS) - 1;
        assert_eq!(morton(all, all, all), (1 << 63) - 1);
        assert_eq!(morton(all, 0, 0).count_ones(), KEY_BITS);
    }

    #[test]
    fn the_same_mesh_renamed_with_its_orientation() {
        let q = quantized(&raster(9, 7));
        let (ordered, order) = renumbered(&q);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..q.positions.len() as u32).collect::<Vec<_>>());
        for (new, &old) in order.iter().enumerate() {
            assert_eq!(ordered.positions[new], q.positions[old as usize]);
        }
        // Back in input ids, the same oriented triangles.
        assert_eq!(
            sorted_canonical(&ordered.triangles, Some(&order)),
            sorted_canonical(&q.triangles, None)
        );
        // Each from its smallest vertex, in ascending order.
        assert!(
            ordered
                .triangles
                .iter()
                .all(|&t| t == canonical_triangle(t))
        );
        assert!(ordered.triangles.windows(2).all(|w| w[0] < w[1]));
        assert_eq!((ordered.bits, ordered.on_lattice), (q.bits, q.on_lattice));
    }

    #[test]
    fn a_terrain_follows_x_and_y_whatever_its_heights() {
        // 16 × 16 samples 10 m apart, heights within 1.25 m: the curve's
        // first four vertices are one 2 × 2 block of samples.
        let q = quantized(&raster(16, 16));
        let (ordered, _) = renumbered(&q);
        let cells: Vec<(u32, u32)> = ordered.positions[..4]
            .iter()
            .map(|p| (p[0] / 1093, p[1] / 1093))
            .collect();
        assert!(cells.iter().all(|&c| c == cells[0]), "{cells:?}");
        // And the order does not depend on the input's.
        let mut shuffled = raster(16, 16);
        let n = shuffled.positions.len() as u32;
        let remap: Vec<u32> = (0..n).map(|i| (i * 37) % n).collect();
        let mut positions = vec![[0.0; 3]; n as usize];
        for (i, &j) in remap.iter().enumerate() {
            positions[j as usize] = shuffled.positions[i];
        }
        shuffled.positions = positions;
        for t in &mut shuffled.triangles {
            *t = t.map(|v| remap[v as usize]);
        }
        // Each triangle starting at another corner, too.
        for (i, t) in shuffled.triangles.iter_mut().enumerate() {
            t.rotate_left(i % 3);
        }
        let (again, _) = renumbered(&quantized(&shuffled));
        assert_eq!(again, ordered);
    }

    #[test]
    fn a_flat_point_mesh_keeps_the_input_order() {
        let mesh = crate::Mesh {
            positions: vec![[0.0; 3]; 3],
            triangles: vec![[0, 1, 2]],
        };
        let q = quantized(&mesh);
        let (ordered, order) = renumbered(&q);
        assert_eq!(order, vec![0, 1, 2]);
        assert_eq!(ordered.triangles, vec![[0, 1, 2]]);
    }
}
