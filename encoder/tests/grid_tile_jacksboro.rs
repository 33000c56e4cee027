//! The grid-tile simplifier (sdk-native) on a real DEM, the Jacksboro fault
//! tiles (`encoder/data/real/jacksboro_fault_dem.npz`, fetched by
//! `encoder/data/fetch.sh`; skipped with a note when absent): every sample
//! within its T of the surface, each tile watertight, and neighbouring
//! tiles meeting vertex for vertex, at equal resolution and where a coarse
//! tile borders two finer ones.

use std::collections::HashSet;
use std::path::Path;

use splitstream_encoder::input::{Grid, ReadOptions, read_grid};
use splitstream_sdk_native::grid_tile::{Params, Side, Simplifier, Tile, threshold};

fn dem() -> Option<Grid> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real/jacksboro_fault_dem.npz");
    if !path.is_file() {
        eprintln!(
            "note: {} missing (bash encoder/data/fetch.sh): test skipped",
            path.display()
        );
        return None;
    }
    let mut g = read_grid(&path, &ReadOptions::default()).expect("read the DEM");
    // Degrees to metres, as `splitstream grid --geographic` does.
    let mid_lat = g.origin[1] + 0.5 * (g.rows as f64 - 1.0) * g.spacing[1];
    let (mx, my) = (111_320.0 * mid_lat.to_radians().cos(), 110_574.0);
    g.origin = [g.origin[0] * mx, g.origin[1] * my];
    g.spacing = [g.spacing[0] * mx, g.spacing[1] * my];
    assert!(g.elevations.iter().all(|h| h.is_finite()));
    Some(g)
}

/// Samples `rows0.., cols0..`, every `step`-th, `n` a side.
fn cut(g: &Grid, col0: usize, row0: usize, n: usize, step: usize) -> Vec<f64> {
    let mut h = Vec::with_capacity(n * n);
    for r in 0..n {
        for c in 0..n {
            h.push(g.elevations[(row0 + r * step) * g.cols + col0 + c * step]);
        }
    }
    h
}

/// The tile's vertices in whole-grid sample coordinates `(col, row)` with
/// their exact heights (bits), so tiles can be compared without rounding.
type Vertex = (i64, i64, u64);

fn vertices(g: &Grid, positions: &[[f64; 3]], keep: impl Fn(i64, i64) -> bool) -> HashSet<Vertex> {
    positions
        .iter()
        .filter_map(|p| {
            let c = (p[0] - g.origin[0]) / g.spacing[0];
            let r = (p[1] - g.origin[1]) / g.spacing[1];
            let (ci, ri) = (c.round() as i64, r.round() as i64);
            ((c - ci as f64).abs() < 1e-6 && (r - ri as f64).abs() < 1e-6 && keep(ci, ri))
                .then_some((ci, ri, p[2].to_bits()))
        })
        .collect()
}

fn watertight(triangles: &[[u32; 3]]) {
    let mut edges = HashSet::new();
    for t in triangles {
        for k in 0..3 {
            assert!(edges.insert((t[k], t[(k + 1) % 3])), "directed edge twice");
        }
    }
}

#[test]
fn jacksboro_tiles_within_threshold_and_crack_free() {
    let Some(g) = dem() else { return };
    let side = 64;
    let n = side + 1;
    let mut simplifier = Simplifier::new(n, n);
    for h in [700.0, 2000.0, 5000.0] {
        let params = Params::new(h);
        let t = threshold(h, g.spacing[0].abs().max(g.spacing[1].abs()));
        // Vertices on each tile's east and north sides, by tile.
        let mut east = Vec::new();
        let mut north = Vec::new();
        let mut tiles = 0;
        for ty in (0..g.rows - side).step_by(side) {
            for tx in (0..g.cols - side).step_by(side) {
                let heights = cut(&g, tx, ty, n, 1);
                let tile = Tile {
                    rows: n,
                    cols: n,
                    heights: &heights,
                    spacing: g.spacing,
                    origin: [
                        g.origin[0] + tx as f64 * g.spacing[0],
                        g.origin[1] + ty as f64 * g.spacing[1],
                    ],
                };
                let (out, stats) = simplifier.simplify(&tile, &params).unwrap();
                assert!(
                    stats.max_error_ratio <= 1.0 + 1e-9
                        && stats.max_vertical_error <= t * (1.0 + 1e-9),
                    "H {h} tile ({tx}, {ty}): {stats:?}"
                );
                watertight(&out.triangles);
                let (x0, y0) = (tx as i64, ty as i64);
                let s = side as i64;
                east.push(((tx, ty), vertices(&g, &out.positions, |c, _| c == x0 + s)));
                north.push(((tx, ty), vertices(&g, &out.positions, |_, r| r == y0 + s)));
                // The west and south sides, to compare with the neighbours'.
                let west = vertices(&g, &out.positions, |c, _| c == x0);
                let south = vertices(&g, &out.positions, |_, r| r == y0);
                if let Some((_, e)) = east.iter().find(|((x, y), _)| *x + side == tx && *y == ty) {
                    assert_eq!(
                        e,
                        &west,
                        "H {h}: tiles at x {} and {tx} differ on their side",
                        tx - side
                    );
                }
                if let Some((_, nn)) = north.iter().find(|((x, y), _)| *x == tx && *y + side == ty)
                {
                    assert_eq!(
                        nn,
                        &south,
                        "H {h}: tiles at y {} and {ty} differ on their side",
                        ty - side
                    );
                }
                tiles += 1;
            }
        }
        assert!(tiles >= 20, "{tiles} tiles");
    }
}

#[test]
fn jacksboro_coarse_tile_meets_two_finer_ones() {
    let Some(g) = dem() else { return };
    let side = 64;
    let n = side + 1;
    // A coarse tile over samples 0..=128 at every other sample, and east of
    // it two fine tiles over columns 128..=192, rows 0..=64 and 64..=128.
    let coarse_h = cut(&g, 0, 0, n, 2);
    let coarse = Tile {
        rows: n,
        cols: n,
        heights: &coarse_h,
        spacing: [2.0 * g.spacing[0], 2.0 * g.spacing[1]],
        origin: g.origin,
    };
    for h in [700.0, 2000.0, 5000.0] {
        let mut pc = Params::new(h);
        pc.neighbour_tiles[Side::East as usize] = 2;
        let mut pf = Params::new(h);
        pf.neighbour_res[Side::West as usize] = Some(2.0 * g.spacing[1].abs());
        let (oc, sc) = Simplifier::new(n, n)
            .simplify(&coarse, &pc)
            .map(|(o, s)| (o.clone(), s))
            .unwrap();
        assert!(sc.max_error_ratio <= 1.0 + 1e-9, "{sc:?}");
        let shared = 2 * side as i64;
        let coarse_side = vertices(&g, &oc.positions, |c, _| c == shared);
        let mut fine_side = HashSet::new();
        for row0 in [0, side] {
            let fine_h = cut(&g, 2 * side, row0, n, 1);
            let fine = Tile {
                rows: n,
                cols: n,
                heights: &fine_h,
                spacing: g.spacing,
                origin: [
                    g.origin[0] + (2 * side) as f64 * g.spacing[0],
                    g.origin[1] + row0 as f64 * g.spacing[1],
                ],
            };
            let mut s = Simplifier::new(n, n);
            let (of, sf) = s.simplify(&fine, &pf).unwrap();
            assert!(sf.max_error_ratio <= 1.0 + 1e-9, "{sf:?}");
            watertight(&of.triangles);
            fine_side.extend(vertices(&g, &of.positions, |c, _| c == shared));
        }
        assert!(coarse_side.len() >= 3);
        assert_eq!(
            coarse_side, fine_side,
            "H {h}: the coarse and fine tiles differ on their side"
        );
    }
}
