//! Geometric error between two meshes, in the style of Metro (Cignoni et
//! al. 1998): sample one surface and measure the distance to the other,
//! both ways. Used to compare simplifiers (parallel versus the sequential
//! baseline) in tests and benchmarks, in the input's own units.

mod bvh;
mod closest;
mod rng;
mod sampling;

use rayon::prelude::*;

use crate::mesh::Mesh;
use bvh::Bvh;
use sampling::Sampler;

pub use closest::closest_point;

/// Two-sided surface distance between meshes `a` and `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistanceReport {
    /// Largest sampled distance in either direction.
    pub hausdorff: f64,
    /// Root mean square over all samples of both directions.
    pub rms: f64,
    /// Mean over all samples of both directions.
    pub mean: f64,
    /// Bounding-box diagonal of `a`, so callers can report fractions.
    pub diagonal: f64,
    /// The distance that 99.9 % of the samples of both directions do not
    /// exceed (nearest rank). The Hausdorff distance is one sample's, so a
    /// single spike decides it; this one moves only when many do.
    pub p999: f64,
    /// Where the Hausdorff distance was found; `None` without samples.
    pub farthest: Option<Farthest>,
}

/// The sample at the largest distance ([`DistanceReport::hausdorff`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Farthest {
    /// The sample point, in the meshes' own coordinates.
    pub point: [f64; 3],
    /// Which surface the sample lies on: `true` for `a` (its distance is to
    /// `b`), `false` for `b`.
    pub on_a: bool,
}

/// Symmetric sampled distance between surfaces `a` and `b`.
///
/// Each mesh is sampled at its used vertices plus `samples_per_mesh` points
/// uniform by area, and every sample's exact distance to the other surface
/// is found through a BVH, in parallel. The result depends only on the
/// inputs and `seed`. If one side has samples but the other has no
/// triangles the distances are infinite; two empty meshes are 0 apart.
pub fn surface_distance(a: &Mesh, b: &Mesh, samples_per_mesh: usize, seed: u64) -> DistanceReport {
    let ((bvh_a, bvh_b), (on_a, on_b)) = rayon::join(
        || {
            rayon::join(
                || Bvh::new(&a.positions, &a.triangles),
                || Bvh::new(&b.positions, &b.triangles),
            )
        },
        || {
            (
                Sampler::new(a, samples_per_mesh, seed),
                // A different stream for the other side.
                Sampler::new(b, samples_per_mesh, seed ^ 0x5851_F42D_4C95_7F2D),
            )
        },
    );
    let (points_a, points_b) = (on_a.points(), on_b.points());
    let mut distances = one_way(&points_a, &bvh_b);
    distances.extend(one_way(&points_b, &bvh_a));
    let count = distances.len();
    // Sequential sums, so the result does not depend on thread scheduling.
    let (mut max, mut sum, mut sum2) = (0.0f64, 0.0, 0.0);
    let mut farthest = None;
    for (i, &d) in distances.iter().enumerate() {
        // The first sample at the largest distance (`>`; an infinite one
        // too, where the other side has no triangles).
        if farthest.is_none() || d > max {
            max = max.max(d);
            farthest = Some(i);
        }
        sum += d;
        sum2 += d * d;
    }
    let n = count.max(1) as f64;
    let farthest = farthest.map(|i| Farthest {
        point: points_a
            .get(i)
            .copied()
            .unwrap_or_else(|| points_b[i - points_a.len()]),
        on_a: i < points_a.len(),
    });
    DistanceReport {
        hausdorff: max,
        rms: (sum2 / n).sqrt(),
        mean: sum / n,
        diagonal: a.diagonal(),
        p999: percentile(&mut distances, 0.999),
        farthest,
    }
}

/// The nearest-rank `q` quantile of `values` (0 when there are none);
/// reorders them.
fn percentile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let rank = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
    *values.select_nth_unstable_by(rank - 1, f64::total_cmp).1
}

/// Distance from every sample to the surface in `bvh`, in sample order.
fn one_way(samples: &[[f64; 3]], bvh: &Bvh) -> Vec<f64> {
    samples
        .par_iter()
        .with_min_len(1024)
        .map_init(
            || bvh::NO_HINT,
            |hint, &p| bvh.nearest_dist2(p, hint).sqrt(),
        )
        .collect()
}

#[cfg(test)]
mod tests;
