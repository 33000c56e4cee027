//! Regular elevation grids and their triangulation, shared by every raster
//! format (GeoTIFF, ESRI ASCII, npy/npz) and by the synthetic terrain.
//!
//! Files store rows north to south (image order); [`Grid`] stores them south
//! to north so that `y = origin_y + row * dy` grows with the row index, which
//! keeps the triangulation and any later grid-tile simplifier free of sign
//! juggling.

use crate::Mesh;

use super::repair::split_nonmanifold_vertices;

/// An elevation raster in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Number of rows (along y).
    pub rows: usize,
    /// Number of columns (along x).
    pub cols: usize,
    /// Row-major samples, row 0 is the southernmost (smallest y) row when
    /// `spacing[1] > 0`.
    pub elevations: Vec<f64>,
    /// Position `[x, y]` of the sample at row 0, column 0.
    pub origin: [f64; 2],
    /// Sample spacing `[dx, dy]`; may be negative (the triangulation keeps
    /// triangles counter-clockwise seen from +z either way).
    pub spacing: [f64; 2],
    /// Samples equal to this value are missing (NaN and infinities always are).
    pub nodata: Option<f64>,
    /// The x of every column and the y of every row (in the order of
    /// `elevations`), for a grid whose file lists them unevenly spaced (a
    /// `.npz` with a `latitude` array in Mercator rows); `origin` and
    /// `spacing` then hold the first sample and the mean step. `None`: the
    /// samples sit at `origin + index × spacing`.
    pub coordinates: Option<[Vec<f64>; 2]>,
}

impl Grid {
    /// Builds a grid from samples stored north to south (the order of GeoTIFF,
    /// ESRI ASCII and most DEM arrays): row 0 of `north_first` is the northern
    /// edge, `south_west` is the position of the south-west sample.
    ///
    /// Returns `None` when `north_first.len() != rows * cols`.
    pub fn from_north_first(
        rows: usize,
        cols: usize,
        north_first: Vec<f64>,
        south_west: [f64; 2],
        spacing: [f64; 2],
        nodata: Option<f64>,
    ) -> Option<Grid> {
        let mut grid = Grid {
            rows,
            cols,
            elevations: north_first,
            origin: south_west,
            spacing,
            nodata,
            coordinates: None,
        };
        if rows.checked_mul(cols)? != grid.elevations.len() {
            return None;
        }
        grid.reverse_rows_in_place();
        Some(grid)
    }

    /// Reverses the row order of the samples and of the rows' listed y
    /// (without touching origin/spacing).
    pub(crate) fn reverse_rows_in_place(&mut self) {
        if let Some([_, ys]) = &mut self.coordinates {
            ys.reverse();
        }
        let (rows, cols) = (self.rows, self.cols);
        if cols == 0 {
            return;
        }
        for r in 0..rows / 2 {
            let (top, bottom) = self.elevations.split_at_mut((rows - 1 - r) * cols);
            top[r * cols..(r + 1) * cols].swap_with_slice(&mut bottom[..cols]);
        }
    }

    /// Whether the sample at `index` carries a usable elevation.
    #[inline]
    pub fn is_valid(&self, index: usize) -> bool {
        let z = self.elevations[index];
        z.is_finite() && self.nodata.is_none_or(|nd| z != nd)
    }
}

/// Triangulates a grid: one vertex per valid sample, two triangles per cell
/// split along the (row, col)–(row+1, col+1) diagonal, counter-clockwise seen
/// from +z.
///
/// Missing samples (NaN, infinite, or equal to `nodata`) drop their vertex and
/// every triangle touching it; vertices left without triangles are removed
/// and the rest renumbered in row-major order. Where missing samples leave two
/// triangle fans touching at a single vertex, that vertex is duplicated so
/// the result passes [`super::check_mesh`].
///
/// # Panics
/// If `elevations.len() != rows * cols`, if `coordinates` does not list
/// `cols` x and `rows` y, or if there are more than `u32::MAX + 1` samples;
/// the file readers check all three before calling.
pub fn grid_to_mesh(grid: &Grid) -> Mesh {
    let (rows, cols) = (grid.rows, grid.cols);
    let n = rows.checked_mul(cols).expect("grid size overflows usize");
    assert_eq!(
        grid.elevations.len(),
        n,
        "grid has {} samples, expected {rows} x {cols}",
        grid.elevations.len()
    );
    assert!(
        n as u64 <= u32::MAX as u64 + 1,
        "grid too large for 32-bit indices"
    );

    if let Some([xs, ys]) = &grid.coordinates {
        assert!(
            xs.len() == cols && ys.len() == rows,
            "grid lists {} x and {} y for {cols} columns and {rows} rows",
            xs.len(),
            ys.len()
        );
    }
    let [x0, y0] = grid.origin;
    let [dx, dy] = grid.spacing;
    let x_at = |c: usize| match &grid.coordinates {
        Some([xs, _]) => xs[c],
        None => x0 + c as f64 * dx,
    };
    let y_at = |r: usize| match &grid.coordinates {
        Some([_, ys]) => ys[r],
        None => y0 + r as f64 * dy,
    };
    // With one axis decreasing the x/y axes are mirrored, so the winding
    // that is counter-clockwise in (col, row) space becomes clockwise.
    let mirrored = match &grid.coordinates {
        Some([xs, ys]) => (xs.last() < xs.first()) != (ys.last() < ys.first()),
        None => (dx < 0.0) != (dy < 0.0),
    };

    let all_valid = (0..n).all(|i| grid.is_valid(i));
    let mut positions = Vec::with_capacity(n);
    for r in 0..rows {
        let y = y_at(r);
        for c in 0..cols {
            positions.push([x_at(c), y, grid.elevations[r * cols + c]]);
        }
    }

    let cells = rows.saturating_sub(1) * cols.saturating_sub(1);
    let mut triangles = Vec::with_capacity(2 * cells);
    for r in 0..rows.saturating_sub(1) {
        for c in 0..cols.saturating_sub(1) {
            let v00 = (r * cols + c) as u32;
            let v01 = v00 + 1;
            let v10 = v00 + cols as u32;
            let v11 = v10 + 1;
            for tri in [[v00, v01, v11], [v00, v11, v10]] {
                if !all_valid && !tri.iter().all(|&v| grid.is_valid(v as usize)) {
                    continue;
                }
                triangles.push(if mirrored {
                    [tri[0], tri[2], tri[1]]
                } else {
                    tri
                });
            }
        }
    }

    let mut mesh = Mesh {
        positions,
        triangles,
    };
    if !all_valid {
        remove_unreferenced(&mut mesh);
        split_nonmanifold_vertices(&mut mesh);
    }
    mesh
}

/// Drops vertices no triangle uses, keeping the order of the others; returns
/// how many were removed.
pub(crate) fn remove_unreferenced(mesh: &mut Mesh) -> usize {
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut remap = vec![u32::MAX; mesh.positions.len()];
    let mut next = 0u32;
    let mut kept = Vec::with_capacity(mesh.positions.len());
    for (i, p) in mesh.positions.iter().enumerate() {
        if used[i] {
            remap[i] = next;
            next += 1;
            kept.push(*p);
        }
    }
    let removed = mesh.positions.len() - kept.len();
    if removed > 0 {
        mesh.positions = kept;
        for t in &mut mesh.triangles {
            for v in t.iter_mut() {
                *v = remap[*v as usize];
            }
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::check_mesh;

    fn signed_area(m: &Mesh, t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|v| m.positions[v as usize]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    }

    fn grid(rows: usize, cols: usize, spacing: [f64; 2]) -> Grid {
        Grid {
            rows,
            cols,
            elevations: (0..rows * cols).map(|i| i as f64).collect(),
            origin: [10.0, 20.0],
            spacing,
            nodata: None,
            coordinates: None,
        }
    }

    #[test]
    fn full_grid_is_ccw_and_valid() {
        for spacing in [[1.0, 2.0], [-1.0, 2.0], [1.0, -2.0], [-1.0, -2.0]] {
            let m = grid_to_mesh(&grid(4, 5, spacing));
            assert_eq!(m.positions.len(), 20);
            assert_eq!(m.triangles.len(), 2 * 3 * 4);
            for &t in &m.triangles {
                assert!(signed_area(&m, t) > 0.0, "{spacing:?}");
            }
            let stats = check_mesh(&m).unwrap();
            assert_eq!(stats.boundary_loops, 1);
        }
        let m = grid_to_mesh(&grid(3, 2, [1.0, 2.0]));
        assert_eq!(m.positions[5], [11.0, 24.0, 5.0]);
    }

    /// Listed coordinates, unevenly spaced and either way round, give the
    /// same counter-clockwise triangles; an empty grid lists nothing.
    #[test]
    fn listed_coordinates_are_ccw_either_way() {
        let (xs, ys) = (vec![0.0, 1.0, 3.0, 7.0, 8.0], vec![0.0, 2.0, 3.0, 5.0]);
        let reversed = |v: &Vec<f64>| v.iter().rev().copied().collect::<Vec<_>>();
        for (x, y) in [
            (xs.clone(), ys.clone()),
            (reversed(&xs), ys.clone()),
            (xs.clone(), reversed(&ys)),
            (reversed(&xs), reversed(&ys)),
        ] {
            let g = Grid {
                coordinates: Some([x.clone(), y.clone()]),
                ..grid(4, 5, [1.0, 1.0])
            };
            let m = grid_to_mesh(&g);
            for &t in &m.triangles {
                assert!(signed_area(&m, t) > 0.0, "{x:?} {y:?}");
            }
            assert_eq!(m.positions[6], [x[1], y[1], 6.0]);
        }
        let empty = Grid {
            coordinates: Some([vec![], vec![]]),
            ..grid(0, 0, [1.0, 1.0])
        };
        assert!(grid_to_mesh(&empty).triangles.is_empty());
    }

    #[test]
    fn north_first_rows_are_flipped() {
        let g = Grid::from_north_first(
            3,
            2,
            vec![1., 2., 3., 4., 5., 6.],
            [0.0, 0.0],
            [1.0, 1.0],
            None,
        )
        .unwrap();
        assert_eq!(g.elevations, vec![5., 6., 3., 4., 1., 2.]);
        assert!(Grid::from_north_first(3, 2, vec![1.0], [0.0, 0.0], [1.0, 1.0], None).is_none());
    }

    #[test]
    fn nodata_drops_vertices_and_triangles() {
        let mut g = grid(3, 3, [1.0, 1.0]);
        g.nodata = Some(-9999.0);
        g.elevations[4] = -9999.0; // centre
        let m = grid_to_mesh(&g);
        // The cells whose diagonal runs through the centre lose both
        // triangles, the other two cells keep the triangle away from it.
        assert_eq!(m.triangles.len(), 2);
        check_mesh(&m).unwrap();
        assert!(m.positions.iter().all(|p| p[2] != -9999.0));

        let mut g = grid(3, 3, [1.0, 1.0]);
        g.elevations[0] = f64::NAN;
        let m = grid_to_mesh(&g);
        // Both triangles of the corner cell touch the missing sample.
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.triangles.len(), 6);
        check_mesh(&m).unwrap();
    }

    #[test]
    fn bowtie_from_nodata_is_split() {
        // Valid samples form two triangles that touch only at the centre.
        let nan = f64::NAN;
        let g = Grid {
            rows: 3,
            cols: 3,
            elevations: vec![0., nan, nan, 0., 0., 0., nan, nan, 0.],
            origin: [0.0, 0.0],
            spacing: [1.0, 1.0],
            nodata: None,
            coordinates: None,
        };
        let m = grid_to_mesh(&g);
        assert_eq!(m.triangles.len(), 2);
        check_mesh(&m).unwrap();
        assert_eq!(m.positions.len(), 6);
    }

    #[test]
    fn degenerate_grids_give_no_triangles() {
        assert!(grid_to_mesh(&grid(1, 5, [1.0, 1.0])).triangles.is_empty());
        assert!(grid_to_mesh(&grid(0, 0, [1.0, 1.0])).positions.is_empty());
    }
}
