//! Client-side simplification of regular elevation tiles.
//!
//! A tile of `rows x cols` heights is split recursively into 2 x 2 regions
//! down to single cells, then merged back bottom-up: two rectangles sharing
//! a whole edge across a split line become one when both shared vertices
//! can be straightened away (edge linearity error e(B) within the threshold
//! T(B)) and the straightening is safe (`quadtree.rs` lists the rules). The
//! threshold is T(V) = min(H / 800, Res / 25) for a viewing height H and a
//! tile resolution Res (the coarser sample spacing); a side next to a
//! coarser tile uses the coarser tile's resolution instead (`threshold.rs`),
//! and both tiles fix that side the same way before merging (`border.rs`).
//! The rectangles are then triangulated without cracks or T-junctions
//! (`triangulate.rs`) and the largest vertical error is measured
//! (`measure.rs`).
//!
//! Error bound: every sample of the tile ends within its T of the surface
//! drawn (T of the side, from the coarser resolution, on a side next to a
//! coarser tile), give or take a thousandth of T of f64 rounding: a
//! threshold too small for that, against the heights' magnitude, is
//! refused ([`GridTileError::BelowPrecision`]). The merges alone do not ensure it: a rectangle fanned
//! through vertices on its sides, or re-triangulated where a border corner
//! is removed, can drift up to about 2 T (5 T next to borders). So after
//! triangulating, the simplifier measures every sample and splits the
//! rectangles around any sample over its T in halves, then triangulates
//! again, until none is over. This ends: single cells are exact, and next
//! to the border the strip of cells left is within T (border samples lie
//! within T of the border polyline by the border pass).
//!
//! The reference heights are the tile's own, except on a side next to a
//! coarser tile: samples the neighbour lacks are measured against the
//! straight edge between the neighbour's samples around them (the paper
//! draws that side at the coarser resolution; nothing finer can match the
//! neighbour without a crack). [`Stats::max_vertical_error`] and
//! [`Stats::max_error_ratio`] report the figures.
//!
//! Crack-free borders: two tiles sharing a side pick that side's vertices
//! with the same pass over the samples they share and draw it with exactly
//! those vertices ([`border`](self) module docs), also when a coarse tile's
//! side is shared by several finer tiles ([`Params::neighbour_tiles`]).
//!
//! Memory: a [`Simplifier`] sizes every buffer from the tile size once;
//! simplifying further tiles of that size allocates nothing.
//!
//! ```
//! use splitstream_sdk_native::grid_tile::{Params, Side, Simplifier, Tile};
//!
//! // A 65 x 65 tilted plane at 32 m spacing, a coarser tile to the west.
//! let heights: Vec<f64> = (0..65 * 65).map(|i| 0.1 * (i % 65) as f64).collect();
//! let tile = Tile {
//!     rows: 65,
//!     cols: 65,
//!     heights: &heights,
//!     spacing: [32.0, 32.0],
//!     origin: [0.0, 0.0],
//! };
//! let mut params = Params::new(700.0);
//! params.neighbour_res[Side::West as usize] = Some(64.0);
//! let mut simplifier = Simplifier::new(65, 65);
//! let (mesh, stats) = simplifier.simplify(&tile, &params).unwrap();
//! assert_eq!((stats.cells, stats.rectangles), (4096, 1));
//! assert_eq!(mesh.triangles.len(), 2);
//! assert!(stats.max_vertical_error < 1e-9);
//! assert!(stats.max_error_ratio <= 1.0);
//! ```

mod border;
mod earclip;
mod edge;
mod error;
mod measure;
mod quadtree;
mod refine;
mod threshold;
mod triangulate;

pub use edge::linearity_error;
pub use error::GridTileError;
pub use threshold::{threshold, tile_resolution};

/// A side of the tile. South is row 0 and West column 0 (with positive
/// spacings, the smallest y and x).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    North = 0,
    East = 1,
    South = 2,
    West = 3,
}

impl Side {
    /// In index order: North, East, South, West.
    pub const ALL: [Side; 4] = [Side::North, Side::East, Side::South, Side::West];
}

/// One elevation tile: `heights[row * cols + col]` at
/// `(origin[0] + col * spacing[0], origin[1] + row * spacing[1])`.
#[derive(Clone, Copy, Debug)]
pub struct Tile<'a> {
    pub rows: usize,
    pub cols: usize,
    pub heights: &'a [f64],
    pub spacing: [f64; 2],
    pub origin: [f64; 2],
}

/// How to simplify.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Viewing height H, in the units of the heights.
    pub viewing_height: f64,
    /// Resolution (sample spacing) of the neighbouring tile on each side,
    /// indexed by [`Side`] as `usize`; `None` when there is none or it is
    /// not coarser. A coarser one must be a whole multiple of this tile's
    /// spacing along that side.
    pub neighbour_res: [Option<f64>; 4],
    /// How many neighbouring tiles share each side, indexed by [`Side`]:
    /// 1 when one tile's side is the whole side (tiles of equal extent), 2
    /// when two tiles of half this tile's extent line it, and so on. Their
    /// corners are kept on this side, so that each of them and this tile
    /// agree on the vertices. Must divide the cells of the side.
    pub neighbour_tiles: [u32; 4],
}

impl Params {
    /// Viewing height `h`, no coarser neighbour, one neighbour tile a side.
    pub fn new(viewing_height: f64) -> Self {
        Params {
            viewing_height,
            neighbour_res: [None; 4],
            neighbour_tiles: [1; 4],
        }
    }
}

/// A rectangle of the simplified tile, in sample indices: it spans columns
/// `col0..=col1` and rows `row0..=row1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub col0: u32,
    pub row0: u32,
    pub col1: u32,
    pub row1: u32,
    /// False for rectangles merged into another (internal).
    pub(crate) alive: bool,
}

/// Figures of one simplification.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// Facets before: the grid cells.
    pub cells: usize,
    /// Facets after: the rectangles.
    pub rectangles: usize,
    /// Triangles of the plain grid (two per cell).
    pub triangles_before: usize,
    /// Triangles of the simplified mesh.
    pub triangles_after: usize,
    pub vertices_after: usize,
    /// Max over the samples of |h - simplified surface|, h the reference
    /// height (see the module docs: the tile's own except for samples a
    /// coarser neighbour lacks).
    pub max_vertical_error: f64,
    /// Max over the samples of |h - surface| / T(sample): at most 1, give
    /// or take a thousandth of rounding (`BelowPrecision` refuses tiles
    /// where rounding could take more).
    pub max_error_ratio: f64,
    /// T of interior samples.
    pub threshold: f64,
    /// Rounds of splitting that the error check needed (0: the merged
    /// rectangles were within T at once).
    pub refinements: usize,
}

impl Stats {
    /// Fraction of facets removed, `1 - rectangles / cells`.
    pub fn facet_reduction(&self) -> f64 {
        1.0 - self.rectangles as f64 / self.cells as f64
    }
}

/// The result: rectangles and a mesh ready to draw.
#[derive(Clone, Debug, Default)]
pub struct Simplified {
    pub rectangles: Vec<Rect>,
    /// Vertices `[x, y, z]`: samples (border ones possibly with adjusted
    /// heights) and the centres of fanned rectangles.
    pub positions: Vec<[f64; 3]>,
    /// Counter-clockwise seen from +z.
    pub triangles: Vec<[u32; 3]>,
}

/// Reusable simplifier holding every buffer.
#[derive(Debug, Default)]
pub struct Simplifier {
    out: Simplified,
    work: Vec<Rect>,
    heights: Vec<f64>,
    reference: Vec<f64>,
    thresholds: Vec<f64>,
    pinned: Vec<bool>,
    keep: Vec<bool>,
    stack: Vec<(usize, usize)>,
    slot: Vec<u32>,
    tri: triangulate::Scratch,
    grid: Vec<[f64; 2]>,
    refine: refine::Scratch,
}

impl Simplifier {
    /// A simplifier with buffers sized for `rows x cols` tiles.
    pub fn new(rows: usize, cols: usize) -> Self {
        let n = rows * cols;
        let cells = rows.saturating_sub(1) * cols.saturating_sub(1);
        Simplifier {
            out: Simplified {
                rectangles: Vec::with_capacity(cells),
                positions: Vec::with_capacity(n + cells),
                triangles: Vec::with_capacity(4 * n),
            },
            // Merged-away rectangles stay in place; splits add at most one
            // live rectangle each, and there are never more than `cells`.
            work: Vec::with_capacity(2 * cells),
            heights: Vec::with_capacity(n),
            reference: Vec::with_capacity(n),
            thresholds: Vec::with_capacity(n),
            pinned: Vec::with_capacity(n),
            keep: Vec::with_capacity(rows.max(cols)),
            stack: Vec::with_capacity(2 * rows.max(cols)),
            slot: Vec::with_capacity(rows.max(cols)),
            tri: triangulate::Scratch {
                used: Vec::with_capacity(n),
                vertex_of: Vec::with_capacity(n),
                perimeter: Vec::with_capacity(2 * (rows + cols)),
                incident: Vec::with_capacity(16 * (rows + cols)),
                added: Vec::with_capacity(16 * (rows + cols)),
                fan: Vec::with_capacity(64),
                chain: Vec::with_capacity(64),
                work: Vec::with_capacity(2 * (rows + cols)),
                new_tris: Vec::with_capacity(64),
                remap: Vec::with_capacity(n + cells),
            },
            grid: Vec::with_capacity(n + cells),
            refine: refine::Scratch::new(n, cells),
        }
    }

    /// The last result (empty before the first successful
    /// [`Simplifier::simplify`]).
    pub fn result(&self) -> &Simplified {
        &self.out
    }

    /// Simplifies one tile; the result stays valid until the next call.
    pub fn simplify(
        &mut self,
        tile: &Tile,
        params: &Params,
    ) -> Result<(&Simplified, Stats), GridTileError> {
        self.out.rectangles.clear();
        self.out.positions.clear();
        self.out.triangles.clear();
        let max_abs_height = check(tile)?;
        let th = threshold::Thresholds::new(tile, params)?;
        check_precision(max_abs_height, &th)?;
        let (rows, cols) = (tile.rows, tile.cols);
        let n = rows * cols;

        self.heights.clear();
        self.heights.extend_from_slice(tile.heights);
        self.reference.clear();
        self.reference.extend_from_slice(tile.heights);
        self.pinned.clear();
        self.pinned.resize(n, false);
        self.thresholds.clear();
        for y in 0..rows {
            for x in 0..cols {
                self.thresholds.push(th.at(x, y, rows, cols));
            }
        }
        border::reference_heights(tile, &th, &mut self.reference);
        border::fix_border(
            tile,
            &th,
            &mut self.heights,
            &mut self.pinned,
            &mut self.keep,
            &mut self.stack,
        );
        let field = quadtree::Field {
            rows,
            cols,
            heights: &self.heights,
            thresholds: &self.thresholds,
            pinned: &self.pinned,
        };
        quadtree::build(&field, &mut self.work, &mut self.slot);

        let layout = triangulate::Layout {
            rows,
            cols,
            heights: &self.heights,
            reference: &self.reference,
            thresholds: &self.thresholds,
            origin: tile.origin,
            spacing: tile.spacing,
        };
        // Triangulate, check, split where over T, until nothing is.
        let mut refinements = 0;
        let measured = loop {
            self.refine.over.clear();
            triangulate::triangulate(
                &layout,
                &self.work,
                &self.pinned,
                &mut self.tri,
                triangulate::Mesh {
                    positions: &mut self.out.positions,
                    triangles: &mut self.out.triangles,
                    grid: &mut self.grid,
                },
                &mut self.refine.over,
            );
            let measured = measure::check(
                rows,
                cols,
                &self.reference,
                &self.thresholds,
                measure::Surface {
                    positions: &self.out.positions,
                    grid: &self.grid,
                    triangles: &self.out.triangles,
                },
                &mut self.refine.over,
            );
            if self.refine.over.is_empty()
                || !refine::split_around(rows, cols, &mut self.work, &mut self.refine)
            {
                break measured;
            }
            refinements += 1;
        };
        self.out
            .rectangles
            .extend(self.work.iter().filter(|r| r.alive).copied());
        let cells = (rows - 1) * (cols - 1);
        let stats = Stats {
            cells,
            rectangles: self.out.rectangles.len(),
            triangles_before: 2 * cells,
            triangles_after: self.out.triangles.len(),
            vertices_after: self.out.positions.len(),
            max_vertical_error: measured.max_error,
            max_error_ratio: measured.max_ratio,
            threshold: th.interior,
            refinements,
        };
        Ok((&self.out, stats))
    }
}

/// Simplifies one tile with a fresh [`Simplifier`].
pub fn simplify_tile(tile: &Tile, params: &Params) -> Result<(Simplified, Stats), GridTileError> {
    let mut s = Simplifier::new(tile.rows, tile.cols);
    let (out, stats) = s.simplify(tile, params)?;
    Ok((out.clone(), stats))
}

/// Refuses thresholds that f64 cannot honour for heights up to
/// `max_abs_height` (see [`GridTileError::BelowPrecision`]).
fn check_precision(max_abs_height: f64, th: &threshold::Thresholds) -> Result<(), GridTileError> {
    let threshold = th.smallest();
    if measure::ROUNDING * (1.0 + max_abs_height) > measure::ROUNDING_SHARE * threshold {
        return Err(GridTileError::BelowPrecision {
            threshold,
            max_abs_height,
        });
    }
    Ok(())
}

/// Checks the tile's sizes, spacing, origin and heights; returns the
/// largest |height|, found in the same pass as the non-finite ones.
fn check(tile: &Tile) -> Result<f64, GridTileError> {
    let (rows, cols) = (tile.rows, tile.cols);
    if rows < 2 || cols < 2 {
        return Err(GridTileError::TooSmall { rows, cols });
    }
    let Some(n) = rows.checked_mul(cols) else {
        return Err(GridTileError::TooLarge { rows, cols });
    };
    // Centres of fanned rectangles add vertices: keep room for them.
    if n as u64 * 2 > u32::MAX as u64 {
        return Err(GridTileError::TooLarge { rows, cols });
    }
    if tile.heights.len() != n {
        return Err(GridTileError::LengthMismatch {
            expected: n,
            actual: tile.heights.len(),
        });
    }
    let [dx, dy] = tile.spacing;
    if !(dx.is_finite() && dy.is_finite() && dx != 0.0 && dy != 0.0) {
        return Err(GridTileError::BadSpacing { dx, dy });
    }
    let [x, y] = tile.origin;
    let far = [x + (cols - 1) as f64 * dx, y + (rows - 1) as f64 * dy];
    if !(x.is_finite() && y.is_finite() && far.iter().all(|c| c.is_finite())) {
        return Err(GridTileError::BadOrigin { x, y });
    }
    let mut max_abs_height = 0.0f64;
    for (i, h) in tile.heights.iter().enumerate() {
        if !h.is_finite() {
            return Err(GridTileError::NonFiniteHeight {
                row: i / cols,
                col: i % cols,
            });
        }
        max_abs_height = max_abs_height.max(h.abs());
    }
    Ok(max_abs_height)
}
