//! Quantization of f64 positions onto the stream's integer grid (SPEC §3.2).
//!
//! One uniform step on all axes keeps the quadric error isotropic; the origin
//! and step stay in f64 so geographic coordinates survive exactly enough.

use crate::mesh::Mesh;

/// A mesh on the integer grid `0 .. 2^bits` per axis.
#[derive(Clone, Debug, PartialEq)]
pub struct QuantizedMesh {
    pub positions: Vec<[u32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub bits: u8,
    pub origin: [f64; 3],
    pub scale: [f64; 3],
}

impl QuantizedMesh {
    /// Real coordinates of grid point `q`.
    pub fn dequantize(&self, q: [u32; 3]) -> [f64; 3] {
        std::array::from_fn(|k| self.origin[k] + q[k] as f64 * self.scale[k])
    }

    /// The mesh back in real coordinates.
    pub fn to_mesh(&self) -> Mesh {
        Mesh {
            positions: self.positions.iter().map(|&q| self.dequantize(q)).collect(),
            triangles: self.triangles.clone(),
        }
    }
}

/// Quantizes `mesh` to `bits` (1..=31) per axis over its bounding box.
pub fn quantize(mesh: &Mesh, bits: u8) -> QuantizedMesh {
    let (lo, hi) = mesh.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
    let top = ((1u64 << bits) - 1) as f64;
    let step = if extent > 0.0 { extent / top } else { 1.0 };
    let positions = mesh
        .positions
        .iter()
        .map(|p| std::array::from_fn(|k| ((p[k] - lo[k]) / step).round().clamp(0.0, top) as u32))
        .collect();
    QuantizedMesh {
        positions,
        triangles: mesh.triangles.clone(),
        bits,
        origin: lo,
        scale: [step; 3],
    }
}
