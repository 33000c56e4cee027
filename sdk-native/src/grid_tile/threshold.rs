//! The straightening threshold T(V) = min(H / 800, Res / 25) and the border
//! rule: on a side next to a coarser tile, T uses the coarser resolution.

use super::{GridTileError, Params, Side, Tile};

/// T for a tile of resolution `resolution` seen from `viewing_height`.
#[inline]
pub fn threshold(viewing_height: f64, resolution: f64) -> f64 {
    (viewing_height / 800.0).min(resolution / 25.0)
}

/// The tile's resolution: its coarser sample spacing.
#[inline]
pub fn tile_resolution(spacing: [f64; 2]) -> f64 {
    spacing[0].abs().max(spacing[1].abs())
}

/// How one side of the tile is treated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SideRule {
    /// Only every `stride`-th sample of the side exists in the neighbour
    /// (1 unless the neighbour is coarser).
    pub stride: usize,
    /// Neighbouring tiles along this side: the border pass treats each
    /// one's stretch on its own, as that tile does (1 for a whole side).
    pub segments: usize,
    /// T on this side: from the coarser of the tile and its neighbour.
    pub threshold: f64,
}

/// Thresholds of the whole tile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// T of every sample not on the tile border.
    pub interior: f64,
    /// Indexed by [`Side`] as `usize`.
    pub sides: [SideRule; 4],
}

impl Thresholds {
    /// Checks the parameters and derives every side's rule.
    pub fn new(tile: &Tile, params: &Params) -> Result<Self, GridTileError> {
        let h = params.viewing_height;
        if !(h.is_finite() && h > 0.0) {
            return Err(GridTileError::BadViewingHeight(h));
        }
        let res = tile_resolution(tile.spacing);
        let mut sides = [SideRule {
            stride: 1,
            segments: 1,
            threshold: threshold(h, res),
        }; 4];
        for side in Side::ALL {
            let tiles = params.neighbour_tiles[side as usize];
            let cells = match side {
                Side::North | Side::South => tile.cols - 1,
                Side::East | Side::West => tile.rows - 1,
            };
            if tiles == 0 || !cells.is_multiple_of(tiles as usize) {
                return Err(GridTileError::NeighbourTilesMismatch { side, tiles, cells });
            }
            sides[side as usize].segments = tiles as usize;
            let Some(nres) = params.neighbour_res[side as usize] else {
                continue;
            };
            if !(nres.is_finite() && nres > 0.0) {
                return Err(GridTileError::BadNeighbourResolution {
                    side,
                    resolution: nres,
                });
            }
            let (spacing, cells) = match side {
                Side::North | Side::South => (tile.spacing[0].abs(), tile.cols - 1),
                Side::East | Side::West => (tile.spacing[1].abs(), tile.rows - 1),
            };
            let ratio = nres / spacing;
            let stride = if ratio <= 1.0 + 1e-9 {
                1
            } else {
                let k = ratio.round();
                let per_tile = cells / tiles as usize;
                if (ratio - k).abs() > 1e-6 * k
                    || k as usize == 0
                    || !per_tile.is_multiple_of(k as usize)
                {
                    return Err(GridTileError::NeighbourMismatch {
                        side,
                        resolution: nres,
                        spacing,
                        cells,
                    });
                }
                k as usize
            };
            sides[side as usize] = SideRule {
                stride,
                segments: tiles as usize,
                threshold: threshold(h, res.max(nres)),
            };
        }
        Ok(Thresholds {
            interior: threshold(h, res),
            sides,
        })
    }

    /// The smallest T of any sample (the sides' are never below the
    /// interior's, but a tile may be all border).
    pub fn smallest(&self) -> f64 {
        self.sides
            .iter()
            .map(|s| s.threshold)
            .fold(self.interior, f64::min)
    }

    /// T(V) for the sample at `(col, row)` of a `rows x cols` tile. Tile
    /// corners sit on two sides and take the larger threshold (they are
    /// never removed anyway).
    #[inline]
    pub fn at(&self, col: usize, row: usize, rows: usize, cols: usize) -> f64 {
        let mut t = f64::NEG_INFINITY;
        if row == 0 {
            t = t.max(self.sides[Side::South as usize].threshold);
        }
        if row == rows - 1 {
            t = t.max(self.sides[Side::North as usize].threshold);
        }
        if col == 0 {
            t = t.max(self.sides[Side::West as usize].threshold);
        }
        if col == cols - 1 {
            t = t.max(self.sides[Side::East as usize].threshold);
        }
        if t == f64::NEG_INFINITY {
            self.interior
        } else {
            t
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_figures() {
        // The paper's Fig. 6 tile: 32 m resolution seen from 700 m.
        assert_eq!(threshold(700.0, 32.0), 0.875);
        // Res/25 takes over for fine tiles or high viewpoints.
        assert_eq!(threshold(5000.0, 32.0), 1.28);
        assert_eq!(tile_resolution([-30.0, 20.0]), 30.0);
    }

    #[test]
    fn border_rule_uses_the_coarser_resolution() {
        let h = vec![0.0; 65 * 65];
        let tile = Tile {
            rows: 65,
            cols: 65,
            heights: &h,
            spacing: [16.0, 16.0],
            origin: [0.0, 0.0],
        };
        let mut params = Params::new(3000.0);
        params.neighbour_res[Side::East as usize] = Some(64.0);
        params.neighbour_res[Side::West as usize] = Some(8.0); // finer: own rule
        let t = Thresholds::new(&tile, &params).unwrap();
        assert_eq!(t.interior, 16.0 / 25.0);
        assert_eq!(t.sides[Side::East as usize].stride, 4);
        assert_eq!(t.sides[Side::East as usize].threshold, 64.0 / 25.0);
        assert_eq!(t.sides[Side::West as usize].stride, 1);
        assert_eq!(t.sides[Side::West as usize].threshold, 16.0 / 25.0);
        assert_eq!(t.at(64, 10, 65, 65), 64.0 / 25.0);
        assert_eq!(t.at(0, 10, 65, 65), 16.0 / 25.0);
        assert_eq!(t.at(5, 10, 65, 65), 16.0 / 25.0);
    }
}
