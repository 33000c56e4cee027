//! Quantization of f64 positions onto the stream's integer grid (SPEC §3.2).
//!
//! Each axis gets its own step over its own extent, so a terrain's heights
//! get the full precision and geographic longitudes and latitudes survive in
//! their own units. The simplifier measures errors in metric space through
//! separate per-axis factors ([`QuantizedMesh::metric`]), not in grid units.

use crate::mesh::Mesh;

/// A mesh on the integer grid `0 .. 2^bits` per axis.
#[derive(Clone, Debug, PartialEq)]
pub struct QuantizedMesh {
    pub positions: Vec<[u32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub bits: u8,
    pub origin: [f64; 3],
    pub scale: [f64; 3],
    /// Grid units to metric units per axis: `scale` times the factor that
    /// turns file units into metres (1 for projected data, about 111 km per
    /// degree for longitude/latitude).
    pub metric: [f64; 3],
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

/// How file units relate to metres, per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Units {
    /// x, y, z in one linear unit (meshes, projected terrain).
    Linear,
    /// x = longitude and y = latitude in degrees, z in metres: x and y are
    /// scaled to metres at the mean latitude (equirectangular), for the
    /// error metric only.
    Geographic,
}

impl Units {
    /// Metres per file unit on each axis for a mesh with this bounding box.
    pub fn metres_per_unit(self, lo: [f64; 3], hi: [f64; 3]) -> [f64; 3] {
        match self {
            Units::Linear => [1.0; 3],
            Units::Geographic => {
                let latitude = (0.5 * (lo[1] + hi[1])).to_radians();
                [111_320.0 * latitude.cos(), 110_574.0, 1.0]
            }
        }
    }
}

/// Quantizes `mesh` to `bits` (1..=31) per axis over its bounding box.
pub fn quantize(mesh: &Mesh, bits: u8, units: Units) -> QuantizedMesh {
    let (lo, hi) = mesh.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
    let top = ((1u64 << bits) - 1) as f64;
    let scale: [f64; 3] = std::array::from_fn(|k| {
        let extent = hi[k] - lo[k];
        if extent > 0.0 { extent / top } else { 1.0 }
    });
    let positions = mesh
        .positions
        .iter()
        .map(|p| {
            std::array::from_fn(|k| ((p[k] - lo[k]) / scale[k]).round().clamp(0.0, top) as u32)
        })
        .collect();
    let metres = units.metres_per_unit(lo, hi);
    QuantizedMesh {
        positions,
        triangles: mesh.triangles.clone(),
        bits,
        origin: lo,
        scale,
        metric: std::array::from_fn(|k| scale[k] * metres[k]),
    }
}
