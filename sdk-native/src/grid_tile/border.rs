//! The tile border, decided before the quad-tree runs so that two tiles
//! sharing a side always agree on it.
//!
//! For each side, the samples that the neighbour also has (every `stride`-th
//! one) form a profile. A Douglas–Peucker pass over that profile, with the
//! side's threshold, picks the vertices to keep ("pinned"). It only reads the
//! profile, counts positions in whole strides, and walks in increasing x or
//! y, so the neighbour running the same pass on the same profile picks the
//! same vertices bit for bit. Every other border sample gets the height of
//! the kept polyline at its position (the paper's "adjust h(D)", Fig. 3): it
//! then lies exactly on the neighbour's straight edge, so wherever the
//! quad-tree keeps it as a corner it cannot open a crack.
//!
//! A side shared with several tiles (a coarse tile next to two tiles of
//! half its extent, say, `Params::neighbour_tiles`) is cut at their corners
//! first, which both sides keep: each stretch is then the whole side of one
//! neighbour and both run the pass on the same profile.
//!
//! The reference heights of a side next to a coarser tile: between two
//! samples the neighbour has, the neighbour draws a straight edge at best,
//! so the samples it lacks are measured against that edge (their linear
//! interpolation), not against their own heights.

use super::threshold::Thresholds;
use super::{Side, Tile};

/// Sample indices (into the row-major tile) of one side, in increasing x or y.
fn side_index(side: Side, rows: usize, cols: usize, p: usize) -> usize {
    match side {
        Side::South => p,
        Side::North => (rows - 1) * cols + p,
        Side::West => p * cols,
        Side::East => p * cols + cols - 1,
    }
}

fn side_len(side: Side, rows: usize, cols: usize) -> usize {
    match side {
        Side::South | Side::North => cols,
        Side::East | Side::West => rows,
    }
}

/// Overwrites the border entries of `reference` (a copy of the tile
/// heights) that a coarser neighbour lacks with the interpolation of those
/// it has.
pub fn reference_heights(tile: &Tile, thresholds: &Thresholds, reference: &mut [f64]) {
    let (rows, cols) = (tile.rows, tile.cols);
    for side in Side::ALL {
        let k = thresholds.sides[side as usize].stride;
        let n = side_len(side, rows, cols);
        for a in (0..n - 1).step_by(k) {
            let ha = tile.heights[side_index(side, rows, cols, a)];
            let hb = tile.heights[side_index(side, rows, cols, a + k)];
            for p in a + 1..a + k {
                let t = (p - a) as f64 / k as f64;
                reference[side_index(side, rows, cols, p)] = ha + (hb - ha) * t;
            }
        }
    }
}

/// Fills `pinned` (kept border samples) and overwrites the border entries of
/// `heights` (a copy of the tile heights) with their adjusted values.
/// `keep` and `stack` are scratch buffers.
pub fn fix_border(
    tile: &Tile,
    thresholds: &Thresholds,
    heights: &mut [f64],
    pinned: &mut [bool],
    keep: &mut Vec<bool>,
    stack: &mut Vec<(usize, usize)>,
) {
    let (rows, cols) = (tile.rows, tile.cols);
    for side in Side::ALL {
        let rule = thresholds.sides[side as usize];
        let n = side_len(side, rows, cols);
        let k = rule.stride;
        let m = (n - 1) / k; // profile has m + 1 points
        let h = |q: usize| tile.heights[side_index(side, rows, cols, q * k)];
        keep.clear();
        keep.resize(m + 1, false);
        stack.clear();
        // Each neighbour tile's stretch on its own, its ends kept.
        let per = m / rule.segments;
        for s in 0..rule.segments {
            keep[s * per] = true;
            stack.push((s * per, (s + 1) * per));
        }
        keep[m] = true;
        while let Some((a, b)) = stack.pop() {
            if b - a < 2 {
                continue;
            }
            let (ha, hb) = (h(a), h(b));
            let mut worst = (0.0, a);
            for q in a + 1..b {
                let t = (q - a) as f64 / (b - a) as f64;
                let e = (ha + (hb - ha) * t - h(q)).abs();
                if e > worst.0 {
                    worst = (e, q);
                }
            }
            if worst.0 > rule.threshold {
                keep[worst.1] = true;
                stack.push((a, worst.1));
                stack.push((worst.1, b));
            }
        }
        // Adjust every sample between two kept profile points.
        let mut a = 0;
        for (b, _) in keep.iter().enumerate().skip(1).filter(|&(_, &kept)| kept) {
            let (ha, hb) = (h(a), h(b));
            let (pa, pb) = (a * k, b * k);
            for p in pa + 1..pb {
                let t = (p - pa) as f64 / (pb - pa) as f64;
                heights[side_index(side, rows, cols, p)] = ha + (hb - ha) * t;
            }
            a = b;
        }
        for (q, &kept) in keep.iter().enumerate() {
            if kept {
                let i = side_index(side, rows, cols, q * k);
                pinned[i] = true;
                heights[i] = tile.heights[i];
            }
        }
    }
}
