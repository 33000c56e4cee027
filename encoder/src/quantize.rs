//! Quantization of f64 positions onto the stream's integer grid (SPEC §3.2).
//!
//! By default each axis gets its own step over its own extent, so a
//! terrain's heights get the full precision and geographic longitudes and
//! latitudes survive in their own units. [`Quantization::Uniform`] uses one
//! step (in metres for geographic input) for all axes, the largest extent
//! over the grid, as Draco quantizes at the same bit count: for terrain that
//! quantizes heights as coarsely as the kilometres of x and y, but it is the
//! fair setting for size comparisons with such codecs. The simplifier
//! measures errors in metric space through separate per-axis factors
//! ([`QuantizedMesh::metric`]), not in grid units.

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

/// How the quantization step is chosen per axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Quantization {
    /// Each axis over its own extent (the default).
    #[default]
    PerAxis,
    /// One step for all axes: the largest extent (in metres for
    /// geographic input) over the grid.
    Uniform,
}

/// Quantizes `mesh` to `bits` (1..=31) per axis over its bounding box, each
/// axis with its own step.
pub fn quantize(mesh: &Mesh, bits: u8, units: Units) -> QuantizedMesh {
    quantize_with(mesh, bits, units, Quantization::PerAxis)
}

/// Quantizes `mesh` to `bits` (1..=31) per axis with the steps `how` says.
pub fn quantize_with(mesh: &Mesh, bits: u8, units: Units, how: Quantization) -> QuantizedMesh {
    let (lo, hi) = mesh.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
    let top = ((1u64 << bits) - 1) as f64;
    let metres = units.metres_per_unit(lo, hi);
    let scale: [f64; 3] = match how {
        Quantization::PerAxis => std::array::from_fn(|k| {
            let extent = hi[k] - lo[k];
            if extent > 0.0 { extent / top } else { 1.0 }
        }),
        Quantization::Uniform => {
            let largest = (0..3)
                .map(|k| (hi[k] - lo[k]) * metres[k])
                .fold(0.0f64, f64::max);
            let step = if largest > 0.0 { largest / top } else { 1.0 };
            std::array::from_fn(|k| step / metres[k])
        }
    };
    let positions = mesh
        .positions
        .iter()
        .map(|p| {
            std::array::from_fn(|k| ((p[k] - lo[k]) / scale[k]).round().clamp(0.0, top) as u32)
        })
        .collect();
    QuantizedMesh {
        positions,
        triangles: mesh.triangles.clone(),
        bits,
        origin: lo,
        scale,
        metric: std::array::from_fn(|k| scale[k] * metres[k]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slab() -> Mesh {
        Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1000.0, 0.0, 0.0], [0.0, 500.0, 10.0]],
            triangles: vec![[0, 1, 2]],
        }
    }

    #[test]
    fn per_axis_uses_each_extent() {
        let q = quantize(&slab(), 10, Units::Linear);
        assert_eq!(q.positions[1], [1023, 0, 0]);
        assert_eq!(q.positions[2], [0, 1023, 1023]);
    }

    #[test]
    fn uniform_uses_one_step() {
        let q = quantize_with(&slab(), 10, Units::Linear, Quantization::Uniform);
        assert_eq!(q.scale, [1000.0 / 1023.0; 3]);
        assert_eq!(q.positions[1], [1023, 0, 0]);
        assert_eq!(q.positions[2], [0, 512, 10]);
        // Geographic: one step in metres, so degrees get a finer step.
        let geo = Mesh {
            positions: vec![[10.0, 50.0, 0.0], [10.01, 50.0, 100.0], [10.0, 50.01, 0.0]],
            triangles: vec![[0, 1, 2]],
        };
        let q = quantize_with(&geo, 12, Units::Geographic, Quantization::Uniform);
        let metric: Vec<f64> = q.metric.to_vec();
        assert!(
            metric
                .iter()
                .all(|m| (m - metric[0]).abs() < 1e-9 * metric[0])
        );
        // The largest extent is y's 0.01 degree (about 1106 m): 100 m of z
        // are about 370 steps of 0.27 m, where per-axis steps give z 4095.
        assert!(
            (365..=375).contains(&q.positions[1][2]),
            "{:?}",
            q.positions
        );
        let per_axis = quantize(&geo, 12, Units::Geographic);
        assert_eq!(per_axis.positions[1][2], 4095);
    }
}
