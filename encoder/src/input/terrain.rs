//! Deterministic synthetic terrain for benchmarks and tests: a 10 km square
//! with about 1.5 km of relief, built from fractal Brownian motion of
//! gradient noise. Seeded by our own splitmix64 hash (no `rand`), so the same
//! `(side, seed)` gives bit-identical meshes on every machine and thread
//! count, which keeps benchmark numbers and golden streams comparable.

use rayon::prelude::*;

use crate::Mesh;

use super::grid::{Grid, grid_to_mesh};

/// Side of the square in metres.
const EXTENT_M: f64 = 10_000.0;
/// Elevation of the lowest point.
const BASE_M: f64 = 200.0;
/// Lowest-to-highest difference.
const RELIEF_M: f64 = 1_500.0;

/// splitmix64 finaliser: a cheap, well-mixed 64-bit hash.
#[inline]
fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Sixteen unit gradients (cos, sin of k * 22.5 degrees): a table lookup is
/// several times cheaper than `sin_cos` and looks the same after fBm.
const GRADIENTS: [(f64, f64); 16] = {
    const H: f64 = std::f64::consts::FRAC_1_SQRT_2;
    /// cos and sin of 22.5 degrees.
    const C: f64 = 0.923_879_532_511_286_7;
    const S: f64 = 0.382_683_432_365_089_8;
    [
        (1.0, 0.0),
        (C, S),
        (H, H),
        (S, C),
        (0.0, 1.0),
        (-S, C),
        (-H, H),
        (-C, S),
        (-1.0, 0.0),
        (-C, -S),
        (-H, -H),
        (-S, -C),
        (0.0, -1.0),
        (S, -C),
        (H, -H),
        (C, -S),
    ]
};

/// Pseudo-random unit gradient at a lattice point.
#[inline]
fn gradient(seed: u64, ix: i64, iy: i64) -> (f64, f64) {
    let h = splitmix64(
        seed ^ (ix as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (iy as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F),
    );
    GRADIENTS[(h >> 60) as usize]
}

/// Perlin-style gradient noise in roughly [-0.7, 0.7].
fn gradient_noise(seed: u64, x: f64, y: f64) -> f64 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i64, fy as i64);
    let (tx, ty) = (x - fx, y - fy);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let dot = |gx: i64, gy: i64, dx: f64, dy: f64| {
        let (a, b) = gradient(seed, gx, gy);
        a * dx + b * dy
    };
    let n00 = dot(ix, iy, tx, ty);
    let n10 = dot(ix + 1, iy, tx - 1.0, ty);
    let n01 = dot(ix, iy + 1, tx, ty - 1.0);
    let n11 = dot(ix + 1, iy + 1, tx - 1.0, ty - 1.0);
    let (u, v) = (fade(tx), fade(ty));
    let a = n00 + u * (n10 - n00);
    let b = n01 + u * (n11 - n01);
    a + v * (b - a)
}

/// A `side x side` vertex terrain (`side = 1000` gives 1M vertices, 2000 gives
/// 4M) with 2 (side - 1)^2 triangles, deterministic in `seed`.
///
/// Octaves run from two features across the map down to about four samples,
/// each half the amplitude of the previous (fBm with H = 1), and the result
/// is raised to the power 1.6 so valleys are broad and peaks sharp, as in
/// real mountain ranges.
pub fn fractal_terrain(side: usize, seed: u64) -> Mesh {
    let spacing = if side > 1 {
        EXTENT_M / (side - 1) as f64
    } else {
        EXTENT_M
    };
    // Base frequency 2 per side, doubling until a feature spans ~4 samples;
    // finer octaves would only alias.
    let octaves = ((side.max(4) as f64 / 2.0).log2().floor() as usize).max(1);
    let seeds: Vec<u64> = (0..octaves as u64)
        .map(|o| splitmix64(seed ^ splitmix64(o)))
        .collect();

    let mut elevations = vec![0.0f64; side * side];
    elevations
        .par_chunks_mut(side.max(1))
        .enumerate()
        .for_each(|(r, row)| {
            for (c, z) in row.iter_mut().enumerate() {
                // Map coordinates in units of the map side.
                let (u, v) = (c as f64 / side as f64, r as f64 / side as f64);
                let mut frequency = 2.0;
                let mut amplitude = 1.0;
                let mut sum = 0.0;
                for &s in &seeds {
                    sum += amplitude * gradient_noise(s, u * frequency, v * frequency);
                    frequency *= 2.0;
                    amplitude *= 0.5;
                }
                *z = sum;
            }
        });

    let (lo, hi) = elevations
        .par_iter()
        .fold(
            || (f64::INFINITY, f64::NEG_INFINITY),
            |(lo, hi), &z| (lo.min(z), hi.max(z)),
        )
        .reduce(
            || (f64::INFINITY, f64::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let range = if hi > lo { hi - lo } else { 1.0 };
    elevations.par_iter_mut().for_each(|z| {
        let t = (*z - lo) / range;
        *z = BASE_M + RELIEF_M * t.powf(1.6);
    });

    grid_to_mesh(&Grid {
        rows: side,
        cols: side,
        elevations,
        origin: [0.0, 0.0],
        spacing: [spacing, spacing],
        nodata: None,
        coordinates: None,
    })
}

#[cfg(test)]
mod tests {
    use super::super::check_mesh;
    use super::*;

    #[test]
    fn deterministic_realistic_and_valid() {
        let a = fractal_terrain(65, 7);
        let b = fractal_terrain(65, 7);
        let c = fractal_terrain(65, 8);
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(a.positions.len(), 65 * 65);
        assert_eq!(a.triangles.len(), 2 * 64 * 64);
        let (lo, hi) = a.bounding_box().unwrap();
        assert_eq!((lo[0], lo[1], hi[0], hi[1]), (0.0, 0.0, EXTENT_M, EXTENT_M));
        assert!((hi[2] - lo[2] - RELIEF_M).abs() < 1e-6, "{lo:?} {hi:?}");
        let stats = check_mesh(&a).unwrap();
        assert_eq!(
            (stats.components, stats.boundary_loops, stats.genus),
            (1, 1, 0)
        );
        // Rough, not a plane: neighbouring samples differ, but smoothly.
        let z = |r: usize, c: usize| a.positions[r * 65 + c][2];
        let steps: f64 = (0..64)
            .map(|c| (z(30, c + 1) - z(30, c)).abs())
            .sum::<f64>()
            / 64.0;
        assert!(steps > 1.0 && steps < 200.0, "mean step {steps}");
    }

    #[test]
    fn tiny_sides() {
        assert!(fractal_terrain(0, 1).positions.is_empty());
        assert_eq!(fractal_terrain(1, 1).positions.len(), 1);
    }
}
