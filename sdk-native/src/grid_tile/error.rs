//! Typed errors of the grid-tile simplifier: bad input never panics.

use std::fmt;

use super::Side;

/// Why a tile could not be simplified.
#[derive(Clone, Debug, PartialEq)]
pub enum GridTileError {
    /// The tile needs at least 2 x 2 samples (one cell).
    TooSmall { rows: usize, cols: usize },
    /// `heights.len()` is not `rows * cols`.
    LengthMismatch { expected: usize, actual: usize },
    /// More samples than 32-bit triangle indices can address.
    TooLarge { rows: usize, cols: usize },
    /// A height is NaN or infinite (missing samples are not supported).
    NonFiniteHeight { row: usize, col: usize },
    /// A spacing is zero, negative zero or not finite.
    BadSpacing { dx: f64, dy: f64 },
    /// The origin is not finite, or the tile's far corner (origin plus
    /// the extent) is not: the vertices would come out NaN or infinite.
    BadOrigin { x: f64, y: f64 },
    /// The viewing height is not finite and positive.
    BadViewingHeight(f64),
    /// A neighbour resolution is not finite and positive.
    BadNeighbourResolution { side: Side, resolution: f64 },
    /// A coarser neighbour's resolution is not a whole multiple of the
    /// spacing along that side, or that multiple does not divide the side.
    NeighbourMismatch {
        side: Side,
        resolution: f64,
        spacing: f64,
        cells: usize,
    },
    /// A threshold is too small for the heights in f64: the error check
    /// tolerates rounding of 1e-12 times `1 + |h|` (`measure::ROUNDING`),
    /// which must stay under a thousandth of every threshold, so that the
    /// samples end within T up to that thousandth. Terrain in metres is
    /// far from it: a threshold of 2 mm allows heights up to 2,000 km.
    BelowPrecision { threshold: f64, max_abs_height: f64 },
    /// The neighbour tile count of a side is zero or does not divide the
    /// cells of that side.
    NeighbourTilesMismatch {
        side: Side,
        tiles: u32,
        cells: usize,
    },
}

impl fmt::Display for GridTileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GridTileError::TooSmall { rows, cols } => {
                write!(f, "tile of {rows} x {cols} samples: at least 2 x 2 needed")
            }
            GridTileError::LengthMismatch { expected, actual } => {
                write!(f, "tile has {actual} heights, expected {expected}")
            }
            GridTileError::TooLarge { rows, cols } => {
                write!(
                    f,
                    "tile of {rows} x {cols} samples is too large for 32-bit indices"
                )
            }
            GridTileError::NonFiniteHeight { row, col } => {
                write!(f, "height at row {row}, column {col} is not finite")
            }
            GridTileError::BadSpacing { dx, dy } => {
                write!(f, "spacing ({dx}, {dy}) must be finite and non-zero")
            }
            GridTileError::BadOrigin { x, y } => write!(
                f,
                "origin ({x}, {y}) and the tile's far corner must be finite"
            ),
            GridTileError::BadViewingHeight(h) => {
                write!(f, "viewing height {h} must be finite and positive")
            }
            GridTileError::BadNeighbourResolution { side, resolution } => write!(
                f,
                "{side:?} neighbour resolution {resolution} must be finite and positive"
            ),
            GridTileError::NeighbourMismatch {
                side,
                resolution,
                spacing,
                cells,
            } => write!(
                f,
                "{side:?} neighbour resolution {resolution} is not a whole multiple of the \
                 spacing {spacing} dividing the {cells} cells of that side (per neighbour tile)"
            ),
            GridTileError::BelowPrecision {
                threshold,
                max_abs_height,
            } => write!(
                f,
                "threshold {threshold} (min(H / 800, resolution / 25)) is too small for \
                 heights up to {max_abs_height}: f64 rounding would take more than a \
                 thousandth of it (are the heights and the spacing in the same units?)"
            ),
            GridTileError::NeighbourTilesMismatch { side, tiles, cells } => write!(
                f,
                "{side:?} side: {tiles} neighbour tiles cannot share its {cells} cells evenly"
            ),
        }
    }
}

impl std::error::Error for GridTileError {}
