//! Position prediction for a split (SPEC §7.4).
//!
//! Once the ring partition is known, P's neighbours are C and the vertices
//! of P's arc; on a smooth surface P lies near the centroid of its
//! neighbours. C is not decoded yet, so R stands in for it. The stream then
//! codes only the residuals, which are much smaller than the edge vector.

use crate::limits::NONE;
use crate::ring::Ring;

/// Predicted positions of P and C: for each, the floor of the mean of R and
/// the real vertices of its arc (wings included), per axis, in i64. P owns
/// arc 1 (`offset ..= offset + distance`), C arc 2.
pub fn predict_split(
    positions: &[[u32; 3]],
    parent: [u32; 3],
    ring: &Ring,
    offset: usize,
    distance: usize,
) -> ([i64; 3], [i64; 3]) {
    let k = ring.len();
    let arc_1 = centroid(positions, parent, ring, offset, distance);
    let arc_2 = centroid(positions, parent, ring, offset + distance, k - distance);
    (arc_1, arc_2)
}

/// Optimal mode's prediction of C once P is known (SPEC §7.4): the floor of
/// the mean of C's arc centroid and the reflection `2R - P` of P through R
/// (an edge collapse puts R between P and C).
pub fn refine_c(c_hat: [i64; 3], parent: [u32; 3], p: [i64; 3]) -> [i64; 3] {
    core::array::from_fn(|k| (c_hat[k] + 2 * parent[k] as i64 - p[k]).div_euclid(2))
}

/// Mean of `parent` and the real ring vertices `start ..= start + len` (mod k).
fn centroid(
    positions: &[[u32; 3]],
    parent: [u32; 3],
    ring: &Ring,
    start: usize,
    len: usize,
) -> [i64; 3] {
    let vertices = ring.vertices();
    let k = vertices.len();
    // Coordinates are below 2^31 and a ring has at most 255 entries, so the
    // sums stay far below 2^63 and are never negative: unsigned division is
    // the floor division of SPEC §7.4.
    let mut sum = parent.map(|x| x as u64);
    let mut count = 1u64;
    let mut i = if start >= k { start - k } else { start };
    for _ in 0..=len {
        let v = vertices.get(i).copied().unwrap_or(NONE);
        if let Some(p) = positions.get(v as usize) {
            for a in 0..3 {
                sum[a] += p[a] as u64;
            }
            count += 1;
        }
        i += 1;
        if i == k {
            i = 0;
        }
    }
    sum.map(|s| (s / count) as i64)
}
