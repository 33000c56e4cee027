//! C ABI of the grid-tile simplifier ([`crate::grid_tile`]).

use std::ptr;

use super::error::{SsStatus, fail_argument, fail_grid, guard};
use crate::grid_tile::{Params, Simplifier, Stats, Tile};

/// A grid-tile simplifier (opaque) holding every buffer, reused tile after
/// tile. Create with `ss_grid_new`, release with `ss_grid_free`.
pub struct SsGridSimplifier {
    simplifier: Simplifier,
    /// Whether `simplifier` holds a result.
    has_result: bool,
}

/// One elevation tile: `heights[row * cols + col]` at
/// `(origin[0] + col * spacing[0], origin[1] + row * spacing[1])`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SsGridTile {
    pub rows: usize,
    pub cols: usize,
    /// `rows * cols` heights, row-major, row 0 south.
    pub heights: *const f64,
    pub spacing: [f64; 2],
    pub origin: [f64; 2],
}

/// How to simplify; sides are indexed North, East, South, West.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SsGridParams {
    /// Viewing height H, in the units of the heights.
    pub viewing_height: f64,
    /// Sample spacing of the neighbouring tile(s) on each side; 0 for none.
    pub neighbour_res: [f64; 4],
    /// How many neighbouring tiles share each side (0 or 1: one tile whose
    /// side is the whole side; 2: two tiles of half this tile's extent, …).
    pub neighbour_tiles: [u32; 4],
}

/// Figures of one simplification (see `grid_tile::Stats`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SsGridStats {
    /// Facets (rectangles) before and after.
    pub cells: usize,
    pub rectangles: usize,
    pub triangles_before: usize,
    pub triangles_after: usize,
    pub vertices_after: usize,
    /// Largest |height - surface| over the samples.
    pub max_vertical_error: f64,
    /// Largest |height - surface| / T(sample): at most 1.
    pub max_error_ratio: f64,
    /// T of interior samples.
    pub threshold: f64,
    /// 1 - rectangles / cells.
    pub facet_reduction: f64,
}

impl From<Stats> for SsGridStats {
    fn from(s: Stats) -> Self {
        SsGridStats {
            cells: s.cells,
            rectangles: s.rectangles,
            triangles_before: s.triangles_before,
            triangles_after: s.triangles_after,
            vertices_after: s.vertices_after,
            max_vertical_error: s.max_vertical_error,
            max_error_ratio: s.max_error_ratio,
            threshold: s.threshold,
            facet_reduction: s.facet_reduction(),
        }
    }
}

impl From<&SsGridParams> for Params {
    fn from(p: &SsGridParams) -> Params {
        let mut params = Params::new(p.viewing_height);
        params.neighbour_res = p.neighbour_res.map(|r| (r != 0.0).then_some(r));
        params.neighbour_tiles = p.neighbour_tiles.map(|n| n.max(1));
        params
    }
}

/// A simplifier with buffers sized for `rows x cols` tiles (others work
/// too, at the cost of growing them). Never null.
#[unsafe(no_mangle)]
pub extern "C" fn ss_grid_new(rows: usize, cols: usize) -> *mut SsGridSimplifier {
    // Absurd sizes would abort on allocation: size for nothing instead.
    let (rows, cols) = if rows.saturating_mul(cols) <= 1 << 26 {
        (rows, cols)
    } else {
        (0, 0)
    };
    Box::into_raw(Box::new(SsGridSimplifier {
        simplifier: Simplifier::new(rows, cols),
        has_result: false,
    }))
}

/// Releases a simplifier; null is ignored.
///
/// # Safety
/// `simplifier` is null or from `ss_grid_new` and not freed yet.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_grid_free(simplifier: *mut SsGridSimplifier) {
    if !simplifier.is_null() {
        // SAFETY: from `Box::into_raw` in `ss_grid_new`, freed once.
        drop(unsafe { Box::from_raw(simplifier) });
    }
}

/// Simplifies one tile; the mesh is then read with `ss_grid_positions` and
/// `ss_grid_triangles`. `stats` may be null.
///
/// # Safety
/// `simplifier` is a live handle; `tile` and `params` point to valid
/// structs, `tile->heights` to `rows * cols` doubles; `stats` is null or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_grid_simplify(
    simplifier: *mut SsGridSimplifier,
    tile: *const SsGridTile,
    params: *const SsGridParams,
    stats: *mut SsGridStats,
) -> SsStatus {
    guard(|| {
        // SAFETY: null or valid per the contract, no other reference alive.
        let (s, t, p) = match unsafe { (simplifier.as_mut(), tile.as_ref(), params.as_ref()) } {
            (Some(s), Some(t), Some(p)) => (s, t, p),
            _ => return fail_argument("null simplifier, tile or params"),
        };
        s.has_result = false;
        let Some(n) = t.rows.checked_mul(t.cols) else {
            return fail_argument("rows * cols overflows");
        };
        let heights: &[f64] = if t.heights.is_null() {
            if n != 0 {
                return fail_argument("null heights");
            }
            &[]
        } else {
            // SAFETY: non-null; the caller promises `rows * cols` doubles.
            unsafe { std::slice::from_raw_parts(t.heights, n) }
        };
        let tile = Tile {
            rows: t.rows,
            cols: t.cols,
            heights,
            spacing: t.spacing,
            origin: t.origin,
        };
        match s.simplifier.simplify(&tile, &Params::from(p)) {
            Ok((_, st)) => {
                s.has_result = true;
                if !stats.is_null() {
                    // SAFETY: non-null and writable per the contract.
                    unsafe { stats.write(st.into()) };
                }
                SsStatus::Ok
            }
            Err(e) => fail_grid(e),
        }
    })
}

/// The last result's vertices, `x, y, z` per vertex; `*vertex_count` (if
/// not null) gets their number. Null (and 0) before a successful
/// `ss_grid_simplify`. Valid until the next call on this simplifier.
///
/// # Safety
/// `simplifier` is null or a live handle; `vertex_count` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_grid_positions(
    simplifier: *const SsGridSimplifier,
    vertex_count: *mut usize,
) -> *const f64 {
    // SAFETY: null or a live handle.
    let result = unsafe { simplifier.as_ref() }
        .filter(|s| s.has_result)
        .map(|s| &s.simplifier.result().positions);
    if !vertex_count.is_null() {
        // SAFETY: non-null and writable per the contract.
        unsafe { vertex_count.write(result.map_or(0, |p| p.len())) };
    }
    result.map_or(ptr::null(), |p| p.as_ptr().cast())
}

/// The last result's triangles, three vertex indices each,
/// counter-clockwise seen from +z; `*triangle_count` (if not null) gets
/// their number. Null (and 0) before a successful `ss_grid_simplify`.
///
/// # Safety
/// `simplifier` is null or a live handle; `triangle_count` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ss_grid_triangles(
    simplifier: *const SsGridSimplifier,
    triangle_count: *mut usize,
) -> *const u32 {
    // SAFETY: null or a live handle.
    let result = unsafe { simplifier.as_ref() }
        .filter(|s| s.has_result)
        .map(|s| &s.simplifier.result().triangles);
    if !triangle_count.is_null() {
        // SAFETY: non-null and writable per the contract.
        unsafe { triangle_count.write(result.map_or(0, |t| t.len())) };
    }
    result.map_or(ptr::null(), |t| t.as_ptr().cast())
}
