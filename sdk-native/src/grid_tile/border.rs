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
//! This needs the shared side to be a whole side of both tiles (tiles of
//! equal extent, as in a quad-tree of tiles one level apart on that side
//! after the coarser one is split, or tiles of one level): a coarse tile
//! whose side spans two fine tiles runs one pass over the whole side, the
//! fine tiles one each over their halves, and those can disagree.

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
        keep[0] = true;
        keep[m] = true;
        stack.clear();
        stack.push((0, m));
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
