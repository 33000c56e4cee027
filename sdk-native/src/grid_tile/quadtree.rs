//! Recursive 2 x 2 split of the tile down to single cells, then bottom-up
//! merging of neighbouring rectangles across each split line (the paper's
//! Fig. 1), with its merge rules.
//!
//! Two rectangles sharing a whole edge CD merge into one when:
//! * neither C nor D is pinned by the border pass ([`super::border`]);
//! * e(C) <= T(C) and e(D) <= T(D), each measured along the merged side that
//!   straightens through it;
//! * both are single grid cells (rule 2.1: no sample lies inside), or else
//!   straightening is safe (rule 2.2): every sample of the merged rectangle,
//!   its sides included, lies within its own T of the surface the merged
//!   rectangle is drawn as. This is where neighbouring rectangles come in:
//!   a sample on a straightened side that a neighbour still uses as a corner
//!   stays a vertex (a T-vertex of the merged rectangle, see
//!   [`super::triangulate`]), and this check bounds how far the neighbour's
//!   edge at that vertex is from the straight side, so the fan drawn through
//!   it stays within the bound.
//!
//! The paper also merges on e(C) = e(D) = 0 alone (rule 1); we still run the
//! surface check there, since collinear shared vertices say nothing about
//! the samples inside the two rectangles.

use super::Rect;
use super::edge::{linearity_error, rectangle_surface};

/// Read-only inputs of the merge pass.
pub struct Field<'a> {
    pub rows: usize,
    pub cols: usize,
    /// Heights after the border pass.
    pub heights: &'a [f64],
    /// T(V) of every sample.
    pub thresholds: &'a [f64],
    /// Border samples that must stay vertices.
    pub pinned: &'a [bool],
}

/// Builds the rectangles of the whole tile into `rects` (cleared first;
/// merged-away rectangles stay in place with `alive == false`). `slot` is
/// scratch of at least `max(rows, cols)` entries.
pub fn build(field: &Field, rects: &mut Vec<Rect>, slot: &mut Vec<u32>) {
    rects.clear();
    slot.clear();
    slot.resize(field.rows.max(field.cols), u32::MAX);
    split_merge(field, rects, slot, 0, 0, field.cols - 2, field.rows - 2);
}

/// Cells `x1..=x2`, `y1..=y2` (cell `(x, y)` spans samples x..x+1, y..y+1).
#[allow(clippy::too_many_arguments)]
fn split_merge(
    f: &Field,
    rects: &mut Vec<Rect>,
    slot: &mut [u32],
    x1: usize,
    y1: usize,
    x2: usize,
    y2: usize,
) {
    let mx = (x1 + x2) / 2;
    let my = (y1 + y2) / 2;
    if x1 == x2 && y1 == y2 {
        rects.push(Rect {
            col0: x1 as u32,
            row0: y1 as u32,
            col1: x1 as u32 + 1,
            row1: y1 as u32 + 1,
            alive: true,
        });
    } else if x1 == x2 {
        let a = rects.len();
        split_merge(f, rects, slot, x1, y1, x1, my);
        let b = rects.len();
        split_merge(f, rects, slot, x1, my + 1, x1, y2);
        merge_rows(f, rects, slot, a, b, my + 1);
    } else if y1 == y2 {
        let a = rects.len();
        split_merge(f, rects, slot, x1, y1, mx, y1);
        let b = rects.len();
        split_merge(f, rects, slot, mx + 1, y1, x2, y1);
        merge_cols(f, rects, slot, a, b, mx + 1);
    } else {
        let a = rects.len();
        split_merge(f, rects, slot, x1, y1, mx, my);
        let b = rects.len();
        split_merge(f, rects, slot, mx + 1, y1, x2, my);
        let c = rects.len();
        merge_cols(f, rects, slot, a, b, mx + 1);
        split_merge(f, rects, slot, x1, my + 1, mx, y2);
        let d = rects.len();
        split_merge(f, rects, slot, mx + 1, my + 1, x2, y2);
        merge_cols(f, rects, slot, c, d, mx + 1);
        merge_rows(f, rects, slot, a, c, my + 1);
    }
}

/// Merges rectangles of `rects[a..b]` (west) ending at column `x` with
/// rectangles of `rects[b..]` (east) starting there.
fn merge_cols(f: &Field, rects: &mut [Rect], slot: &mut [u32], a: usize, b: usize, x: usize) {
    let x = x as u32;
    for (i, r) in rects.iter().enumerate().skip(b) {
        if r.alive && r.col0 == x {
            slot[r.row0 as usize] = i as u32;
        }
    }
    for w in a..b {
        let west = rects[w];
        if !west.alive || west.col1 != x {
            continue;
        }
        let e = slot[west.row0 as usize];
        if e == u32::MAX {
            continue;
        }
        let east = rects[e as usize];
        if east.row1 != west.row1 {
            continue;
        }
        let merged = Rect {
            col1: east.col1,
            ..west
        };
        let c = (x as usize, west.row0 as usize);
        let d = (x as usize, west.row1 as usize);
        if removable_along_x(f, c, merged.col0 as usize, merged.col1 as usize)
            && removable_along_x(f, d, merged.col0 as usize, merged.col1 as usize)
            && (is_cell(&west) && is_cell(&east) || surface_fits(f, &merged))
        {
            rects[w] = merged;
            rects[e as usize].alive = false;
        }
    }
    for r in &rects[b..] {
        if r.col0 == x {
            slot[r.row0 as usize] = u32::MAX;
        }
    }
}

/// Merges rectangles of `rects[a..b]` (south) ending at row `y` with
/// rectangles of `rects[b..]` (north) starting there.
fn merge_rows(f: &Field, rects: &mut [Rect], slot: &mut [u32], a: usize, b: usize, y: usize) {
    let y = y as u32;
    for (i, r) in rects.iter().enumerate().skip(b) {
        if r.alive && r.row0 == y {
            slot[r.col0 as usize] = i as u32;
        }
    }
    for s in a..b {
        let south = rects[s];
        if !south.alive || south.row1 != y {
            continue;
        }
        let n = slot[south.col0 as usize];
        if n == u32::MAX {
            continue;
        }
        let north = rects[n as usize];
        if north.col1 != south.col1 {
            continue;
        }
        let merged = Rect {
            row1: north.row1,
            ..south
        };
        let c = (south.col0 as usize, y as usize);
        let d = (south.col1 as usize, y as usize);
        if removable_along_y(f, c, merged.row0 as usize, merged.row1 as usize)
            && removable_along_y(f, d, merged.row0 as usize, merged.row1 as usize)
            && (is_cell(&south) && is_cell(&north) || surface_fits(f, &merged))
        {
            rects[s] = merged;
            rects[n as usize].alive = false;
        }
    }
    for r in &rects[b..] {
        if r.row0 == y {
            slot[r.col0 as usize] = u32::MAX;
        }
    }
}

#[inline]
fn is_cell(r: &Rect) -> bool {
    r.col1 - r.col0 == 1 && r.row1 - r.row0 == 1
}

/// Whether sample `(x, y)` may leave the horizontal side from `xa` to `xc`.
fn removable_along_x(f: &Field, (x, y): (usize, usize), xa: usize, xc: usize) -> bool {
    let i = y * f.cols + x;
    if f.pinned[i] {
        return false;
    }
    let h = |x: usize| f.heights[y * f.cols + x];
    linearity_error(xa as f64, h(xa), x as f64, h(x), xc as f64, h(xc)) <= f.thresholds[i]
}

/// Whether sample `(x, y)` may leave the vertical side from `ya` to `yc`.
fn removable_along_y(f: &Field, (x, y): (usize, usize), ya: usize, yc: usize) -> bool {
    let i = y * f.cols + x;
    if f.pinned[i] {
        return false;
    }
    let h = |y: usize| f.heights[y * f.cols + x];
    linearity_error(ya as f64, h(ya), y as f64, h(y), yc as f64, h(yc)) <= f.thresholds[i]
}

/// Rule 2.2's safety check: every sample of `r` within its T of the two
/// triangles `r` is drawn as.
fn surface_fits(f: &Field, r: &Rect) -> bool {
    let (x0, y0, x1, y1) = (
        r.col0 as usize,
        r.row0 as usize,
        r.col1 as usize,
        r.row1 as usize,
    );
    let h = |x: usize, y: usize| f.heights[y * f.cols + x];
    let (h00, h10, h01, h11) = (h(x0, y0), h(x1, y0), h(x0, y1), h(x1, y1));
    let (w, ht) = ((x1 - x0) as f64, (y1 - y0) as f64);
    for y in y0..=y1 {
        let v = (y - y0) as f64 / ht;
        let row = y * f.cols;
        for x in x0..=x1 {
            let u = (x - x0) as f64 / w;
            let s = rectangle_surface(h00, h10, h01, h11, u, v);
            if (s - f.heights[row + x]).abs() > f.thresholds[row + x] {
                return false;
            }
        }
    }
    true
}
