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
//!
//! [`Lattice::Keep`] quantizes an axis whose coordinates all lie on a
//! regular lattice coarser than that step (a raster's columns and rows,
//! heights stored in whole metres) on the lattice itself: the axis is then
//! exact, and a split's vectors on it are small integers (one cell), which
//! the position residuals code in a few bits where a finer step leaves the
//! prediction's fractions of a cell to code.

use crate::input::{MeshError, MeshStats, check_mesh};
use crate::mesh::Mesh;
use rayon::prelude::*;

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
    /// The axes quantized on their own lattice ([`Lattice::Keep`]): exact.
    pub on_lattice: [bool; 3],
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

    /// Checks a quantized mesh as [`check_mesh`] checks an input mesh, in
    /// its grid coordinates, after its bit count (1..=31) and that every
    /// position lies on the grid: what the simplifier and the encoder
    /// assume (a mesh built by hand gets these typed errors, not a panic
    /// or a wrong stream).
    pub fn check(&self) -> Result<MeshStats, GridError> {
        if !(1..=31).contains(&self.bits) {
            return Err(GridError::Bits(self.bits));
        }
        let top = 1u64 << self.bits;
        if let Some(v) = self
            .positions
            .iter()
            .position(|p| p.iter().any(|&x| x as u64 >= top))
        {
            return Err(GridError::OffGrid {
                vertex: v,
                position: self.positions[v],
                bits: self.bits,
            });
        }
        let as_mesh = Mesh {
            positions: self.positions.iter().map(|p| p.map(f64::from)).collect(),
            triangles: self.triangles.clone(),
        };
        check_mesh(&as_mesh).map_err(GridError::Mesh)
    }
}

/// Why a quantized mesh failed [`QuantizedMesh::check`].
#[derive(Clone, Debug, PartialEq)]
pub enum GridError {
    /// A bit count outside 1..=31.
    Bits(u8),
    /// A position with a coordinate at or above `2^bits`.
    OffGrid {
        vertex: usize,
        position: [u32; 3],
        bits: u8,
    },
    /// The mesh itself (in grid coordinates).
    Mesh(MeshError),
}

impl std::fmt::Display for GridError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GridError::Bits(bits) => {
                write!(f, "the quantized mesh has {bits} bits, outside 1..=31")
            }
            GridError::OffGrid {
                vertex,
                position,
                bits,
            } => write!(
                f,
                "vertex {vertex} of the quantized mesh, {position:?}, lies outside its {bits}-bit grid"
            ),
            GridError::Mesh(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for GridError {}

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

/// Whether an axis whose coordinates lie on a regular lattice keeps it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Lattice {
    /// Every axis gets the step [`Quantization`] says.
    #[default]
    Ignore,
    /// An axis whose coordinates all lie on `lo + i * s` with `s` at least
    /// the step [`Quantization`] says is quantized with step `s`, exactly.
    Keep,
}

/// Quantizes `mesh` to `bits` (1..=31) per axis over its bounding box, each
/// axis with its own step.
pub fn quantize(mesh: &Mesh, bits: u8, units: Units) -> QuantizedMesh {
    quantize_with(mesh, bits, units, Quantization::PerAxis, Lattice::Ignore)
}

/// Quantizes `mesh` to `bits` (1..=31) per axis with the steps `how` says,
/// or on the axes' own lattices where `lattice` keeps them.
pub fn quantize_with(
    mesh: &Mesh,
    bits: u8,
    units: Units,
    how: Quantization,
    lattice: Lattice,
) -> QuantizedMesh {
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
    // The axes are searched at once: a raster's x and y each sort every
    // value (serial work that held one core of the 1M terrain's encode for
    // about 40 ms).
    let lattice_of = |k: usize| match lattice {
        Lattice::Ignore => None,
        Lattice::Keep => {
            let axis = mesh.positions.iter().map(|p| p[k]);
            lattice_step(axis, lo[k], hi[k], top).filter(|&s| s >= scale[k])
        }
    };
    let (x, (y, z)) = rayon::join(
        || lattice_of(0),
        || rayon::join(|| lattice_of(1), || lattice_of(2)),
    );
    let lattices = [x, y, z];
    let scale: [f64; 3] = std::array::from_fn(|k| lattices[k].unwrap_or(scale[k]));
    let positions = mesh
        .positions
        .par_iter()
        .map(|p| {
            std::array::from_fn(|k| ((p[k] - lo[k]) / scale[k]).round().clamp(0.0, top) as u32)
        })
        .collect();
    QuantizedMesh {
        positions,
        triangles: mesh.triangles.par_iter().copied().collect(),
        bits,
        origin: lo,
        scale,
        metric: std::array::from_fn(|k| scale[k] * metres[k]),
        on_lattice: lattices.map(|l| l.is_some()),
    }
}

/// How far (in steps) a value may lie from its lattice point: the f64
/// rounding of `origin + i * spacing` for any `i` below 2^31.
const LATTICE_TOLERANCE: f64 = 1e-6;

/// Values checked before sorting them all: enough that coordinates off any
/// lattice (a scanned mesh's) are rejected from the sample alone.
const LATTICE_SAMPLE: usize = 1024;

/// The spacing `s` of the regular lattice `lo + i * s`, `0 <= i <= top`, that
/// every one of `values` (all in `lo ..= hi`, `lo` among them) lies on, `s`
/// being the smallest gap between two values (a raster's cell); `None` when
/// they do not (or `hi == lo`).
pub fn lattice_step(
    values: impl Iterator<Item = f64> + Clone,
    lo: f64,
    hi: f64,
    top: f64,
) -> Option<f64> {
    let extent = hi - lo;
    if extent.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    // Any two values on the lattice differ by a multiple of its spacing, so
    // the smallest gap among some of them bounds the spacing from above: a
    // sample whose gaps are too fine for `top` steps rejects the whole axis
    // without sorting every value. (A sample of one distinct value, a
    // raster's first row seen along y, has no gap and decides nothing.)
    let smallest_gap = |offsets: &mut Vec<f64>| {
        // In parallel: every value of a raster's axis (the same order,
        // so the same gap).
        offsets.par_sort_unstable_by(f64::total_cmp);
        offsets.dedup();
        offsets
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min)
    };
    let fits = |gap: f64| gap.is_finite() && (extent / gap).round() <= top;
    let mut sample: Vec<f64> = values
        .clone()
        .take(LATTICE_SAMPLE)
        .map(|x| x - lo)
        .collect();
    let sample_gap = smallest_gap(&mut sample);
    if sample_gap.is_finite() && !fits(sample_gap) {
        return None;
    }
    let mut offsets: Vec<f64> = values.map(|x| x - lo).collect();
    let gap = smallest_gap(&mut offsets);
    if !fits(gap) {
        return None;
    }
    // The spacing is the gap, spread over the whole extent so that its
    // rounding does not add up across the steps.
    let step = extent / (extent / gap).round();
    let on_lattice = offsets.par_iter().all(|&x| {
        let i = x / step;
        (i - i.round()).abs() < LATTICE_TOLERANCE
    });
    on_lattice.then_some(step)
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

    /// A 5 x 3 raster: x on 10.5 + 0.25 i, y on -3 + 0.1 j, z in whole
    /// metres but for `odd_z`.
    fn raster(odd_z: Option<f64>) -> Mesh {
        let mut positions = Vec::new();
        for j in 0..3 {
            for i in 0..5 {
                let z = [100.0, 103.0, 101.0][(i + j) % 3];
                positions.push([10.5 + i as f64 * 0.25, -3.0 + j as f64 * 0.1, z]);
            }
        }
        if let Some(z) = odd_z {
            positions[7][2] = z;
        }
        let triangles = vec![[0, 1, 5], [1, 6, 5]];
        Mesh {
            positions,
            triangles,
        }
    }

    #[test]
    fn a_raster_axis_is_found_on_its_lattice() {
        let m = raster(None);
        let axis = |k: usize| m.positions.iter().map(move |p| p[k]);
        let x = lattice_step(axis(0), 10.5, 11.5, 16383.0).unwrap();
        assert!((x - 0.25).abs() < 1e-12);
        // 0.1 is not exact in binary: -3 + 2 * 0.1 still lies on the lattice.
        let y = lattice_step(axis(1), -3.0, -2.8, 16383.0).unwrap();
        assert!((y - 0.1).abs() < 1e-12);
        assert_eq!(lattice_step(axis(2), 100.0, 103.0, 16383.0), Some(1.0));
        // More lattice points than the grid has steps: no lattice.
        assert_eq!(lattice_step(axis(0), 10.5, 11.5, 3.0), None);
        // One value off the lattice, or all values equal: none either.
        let odd = raster(Some(101.3));
        assert_eq!(
            lattice_step(odd.positions.iter().map(|p| p[2]), 100.0, 103.0, 16383.0),
            None
        );
        assert_eq!(
            lattice_step([2.0, 2.0].into_iter(), 2.0, 2.0, 16383.0),
            None
        );
    }

    #[test]
    fn a_wide_rasters_rows_are_found_past_the_sample() {
        // 3 rows of 2,000 columns: the first 1,024 values of y are all row
        // 0 (no gap in the sample), and the lattice is still found.
        let y = (0..6000).map(|i| 7.0 + (i / 2000) as f64 * 0.5);
        assert_eq!(lattice_step(y, 7.0, 8.0, 16383.0), Some(0.5));
        let x = (0..6000).map(|i| (i % 2000) as f64 * 0.25);
        assert_eq!(lattice_step(x, 0.0, 499.75, 16383.0), Some(0.25));
    }

    #[test]
    fn coordinates_off_any_lattice_are_rejected_from_a_sample() {
        // A scanned mesh's coordinates: the first 1024 already have gaps far
        // too fine for 2^14 steps.
        let values = (0..5000u64).map(|i| ((i * 2_654_435_761) % 1_000_003) as f64 / 1_000_003.0);
        let (lo, hi) = values
            .clone()
            .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
        assert_eq!(lattice_step(values, lo, hi, 16383.0), None);
    }

    #[test]
    fn kept_lattices_are_exact_and_never_finer_than_the_step() {
        let m = raster(None);
        let q = quantize_with(&m, 14, Units::Linear, Quantization::PerAxis, Lattice::Keep);
        for (p, real) in q.positions.iter().zip(&m.positions) {
            let back = q.dequantize(*p);
            for k in 0..3 {
                assert!((back[k] - real[k]).abs() < 1e-9, "{back:?} {real:?}");
            }
        }
        assert_eq!(q.positions[7], [2, 1, 0]);
        assert_eq!(q.positions[14], [4, 2, 0]);
        assert_eq!(q.scale[2], 1.0);
        assert_eq!(q.on_lattice, [true; 3]);
        // Two bits give 3 steps: x's 4 cells do not fit, y's 2 and z's 3 do.
        let q = quantize_with(&m, 2, Units::Linear, Quantization::PerAxis, Lattice::Keep);
        assert!((q.scale[0] - 1.0 / 3.0).abs() < 1e-12);
        assert!((q.scale[1] - 0.1).abs() < 1e-12);
        assert_eq!(q.on_lattice, [false, true, true]);
        assert_eq!(q.scale[2], 1.0);
        // Uniform: one step of 1.0 (z's extent of 3 over 3 steps) for all
        // axes; the lattices of x (0.25) and y (0.1) are finer, so they keep
        // it; z's lattice is that step, and z stays exact.
        let q = quantize_with(&m, 2, Units::Linear, Quantization::Uniform, Lattice::Keep);
        assert_eq!(q.scale, [1.0; 3]);
        assert_eq!(q.on_lattice, [false, false, true]);
    }

    #[test]
    fn per_axis_uses_each_extent() {
        let q = quantize(&slab(), 10, Units::Linear);
        assert_eq!(q.positions[1], [1023, 0, 0]);
        assert_eq!(q.positions[2], [0, 1023, 1023]);
    }

    #[test]
    fn uniform_uses_one_step() {
        let q = quantize_with(
            &slab(),
            10,
            Units::Linear,
            Quantization::Uniform,
            Lattice::Ignore,
        );
        assert_eq!(q.scale, [1000.0 / 1023.0; 3]);
        assert_eq!(q.positions[1], [1023, 0, 0]);
        assert_eq!(q.positions[2], [0, 512, 10]);
        // Geographic: one step in metres, so degrees get a finer step.
        let geo = Mesh {
            positions: vec![[10.0, 50.0, 0.0], [10.01, 50.0, 100.0], [10.0, 50.01, 0.0]],
            triangles: vec![[0, 1, 2]],
        };
        let q = quantize_with(
            &geo,
            12,
            Units::Geographic,
            Quantization::Uniform,
            Lattice::Ignore,
        );
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
