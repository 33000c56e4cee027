//! `GridSimplifier`: the grid-tile simplifier for JavaScript.

use splitstream_sdk_native::grid_tile::{Params, Simplifier, Stats, Tile};
use wasm_bindgen::prelude::*;

use crate::error::SdkError;

/// Simplifies regular elevation tiles (sdk-native's `grid_tile`): every
/// sample ends within T = min(H / 800, Res / 25) of the surface, and tiles
/// sharing a side meet there vertex for vertex. Reuse one simplifier for
/// many tiles of the same size: its buffers are sized once.
#[wasm_bindgen]
pub struct GridSimplifier {
    simplifier: Simplifier,
    /// `Float32Array` heights widened, and the `f32` output positions.
    heights: Vec<f64>,
    out_f32: Vec<f32>,
}

/// Figures of one simplification.
#[wasm_bindgen]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileStats {
    /// Facets (grid cells, then rectangles) before and after.
    pub cells: usize,
    pub rectangles: usize,
    #[wasm_bindgen(js_name = trianglesBefore)]
    pub triangles_before: usize,
    #[wasm_bindgen(js_name = trianglesAfter)]
    pub triangles_after: usize,
    #[wasm_bindgen(js_name = verticesAfter)]
    pub vertices_after: usize,
    /// Largest |height - surface| over the samples.
    #[wasm_bindgen(js_name = maxVerticalError)]
    pub max_vertical_error: f64,
    /// Largest |height - surface| / T(sample): at most 1.
    #[wasm_bindgen(js_name = maxErrorRatio)]
    pub max_error_ratio: f64,
    /// T of the tile's interior samples.
    pub threshold: f64,
    /// 1 - rectangles / cells.
    #[wasm_bindgen(js_name = facetReduction)]
    pub facet_reduction: f64,
}

impl From<Stats> for TileStats {
    fn from(s: Stats) -> Self {
        TileStats {
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

/// Where the tile lies and how it is seen (the arguments shared by both
/// `simplify` variants).
struct Placement<'a> {
    rows: usize,
    cols: usize,
    spacing: &'a [f64],
    origin: &'a [f64],
    viewing_height: f64,
    neighbour_res: &'a [f64],
    neighbour_tiles: &'a [u32],
}

#[wasm_bindgen]
impl GridSimplifier {
    /// A simplifier with buffers sized for `rows x cols` tiles.
    #[wasm_bindgen(constructor)]
    pub fn new(rows: usize, cols: usize) -> GridSimplifier {
        GridSimplifier {
            simplifier: Simplifier::new(rows, cols),
            heights: Vec::with_capacity(rows * cols),
            out_f32: Vec::new(),
        }
    }

    /// Simplifies a `rows x cols` tile of `heights` (row-major, row 0 at
    /// `origin[1]`, sample (col, row) at `origin + (col, row) * spacing`),
    /// seen from `viewingHeight`. `neighbourRes` (N, E, S, W; 0 or NaN for
    /// none, may be empty) gives coarser neighbours' sample spacings;
    /// `neighbourTiles` (N, E, S, W; may be empty for all 1) how many
    /// tiles share each side. Read the mesh with `positions()` /
    /// `positionsF32()` and `indices()`.
    #[allow(clippy::too_many_arguments)]
    pub fn simplify(
        &mut self,
        heights: &[f64],
        rows: usize,
        cols: usize,
        spacing: &[f64],
        origin: &[f64],
        #[wasm_bindgen(js_name = viewingHeight)] viewing_height: f64,
        #[wasm_bindgen(js_name = neighbourRes)] neighbour_res: &[f64],
        #[wasm_bindgen(js_name = neighbourTiles)] neighbour_tiles: &[u32],
    ) -> Result<TileStats, SdkError> {
        let place = Placement {
            rows,
            cols,
            spacing,
            origin,
            viewing_height,
            neighbour_res,
            neighbour_tiles,
        };
        run(&mut self.simplifier, heights, &place)
    }

    /// `simplify` for `Float32Array` heights (widened to 64 bits first).
    #[allow(clippy::too_many_arguments)]
    #[wasm_bindgen(js_name = simplifyF32)]
    pub fn simplify_f32(
        &mut self,
        heights: &[f32],
        rows: usize,
        cols: usize,
        spacing: &[f64],
        origin: &[f64],
        #[wasm_bindgen(js_name = viewingHeight)] viewing_height: f64,
        #[wasm_bindgen(js_name = neighbourRes)] neighbour_res: &[f64],
        #[wasm_bindgen(js_name = neighbourTiles)] neighbour_tiles: &[u32],
    ) -> Result<TileStats, SdkError> {
        self.heights.clear();
        self.heights.extend(heights.iter().map(|&h| h as f64));
        let place = Placement {
            rows,
            cols,
            spacing,
            origin,
            viewing_height,
            neighbour_res,
            neighbour_tiles,
        };
        run(&mut self.simplifier, &self.heights, &place)
    }

    /// The last result's vertices, x, y, z per vertex (a copy).
    pub fn positions(&self) -> js_sys::Float64Array {
        self.simplifier.result().positions.as_flattened().into()
    }

    /// The last result's vertices as 32-bit floats (a copy).
    #[wasm_bindgen(js_name = positionsF32)]
    pub fn positions_f32(&mut self) -> js_sys::Float32Array {
        self.fill_f32().into()
    }

    /// The last result's triangles, three vertex indices each,
    /// counter-clockwise seen from +z (a copy).
    pub fn indices(&self) -> js_sys::Uint32Array {
        self.simplifier.result().triangles.as_flattened().into()
    }
}

impl GridSimplifier {
    /// The simplifier wrapped (its `result()` is the last mesh).
    pub fn simplifier(&self) -> &Simplifier {
        &self.simplifier
    }

    /// The last result's positions narrowed to `f32`.
    pub fn fill_f32(&mut self) -> &[f32] {
        self.out_f32.clear();
        let p = &self.simplifier.result().positions;
        self.out_f32
            .extend(p.as_flattened().iter().map(|&c| c as f32));
        &self.out_f32
    }
}

fn run(simplifier: &mut Simplifier, heights: &[f64], p: &Placement) -> Result<TileStats, SdkError> {
    let pair = |v: &[f64], what: &str| -> Result<[f64; 2], SdkError> {
        v.try_into()
            .map_err(|_| SdkError::argument(format!("{what} wants 2 values, got {}", v.len())))
    };
    let mut params = Params::new(p.viewing_height);
    match p.neighbour_res.len() {
        0 => {}
        4 => {
            for (slot, &r) in params.neighbour_res.iter_mut().zip(p.neighbour_res) {
                *slot = (r != 0.0 && !r.is_nan()).then_some(r);
            }
        }
        n => {
            return Err(SdkError::argument(format!(
                "neighbourRes wants 4 values (N, E, S, W) or none, got {n}"
            )));
        }
    }
    match p.neighbour_tiles.len() {
        0 => {}
        4 => params.neighbour_tiles.copy_from_slice(p.neighbour_tiles),
        n => {
            return Err(SdkError::argument(format!(
                "neighbourTiles wants 4 values (N, E, S, W) or none, got {n}"
            )));
        }
    }
    let tile = Tile {
        rows: p.rows,
        cols: p.cols,
        heights,
        spacing: pair(p.spacing, "spacing")?,
        origin: pair(p.origin, "origin")?,
    };
    let (_, stats) = simplifier.simplify(&tile, &params)?;
    Ok(stats.into())
}
