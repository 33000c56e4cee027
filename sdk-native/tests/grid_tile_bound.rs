//! The error bound and crack-free borders of the grid-tile simplifier on
//! random grids (proptest): every sample within its T of the surface, the
//! mesh watertight, and tiles sharing a side (of equal extent, or a coarse
//! tile next to two finer ones of half its extent) meeting vertex for
//! vertex.

use proptest::prelude::*;
use splitstream_sdk_native::grid_tile::{Params, Side, Simplified, Tile, simplify_tile};

/// Heights of a random terrain: a few waves plus integer noise, as DEMs
/// store whole metres.
fn terrain(rows: usize, cols: usize, d: f64, waves: &[(f64, f64, f64)], noise: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            let (x, y) = (c as f64 * d, r as f64 * d);
            let mut h: f64 = waves
                .iter()
                .map(|&(a, fx, fy)| a * (x * fx + y * fy).sin())
                .sum();
            h += noise[(r * cols + c) % noise.len()];
            out.push(h.round());
        }
    }
    out
}

/// Each directed edge once; the area that of the tile.
fn assert_watertight(out: &Simplified, rows: usize, cols: usize, d: [f64; 2]) {
    let mut edges = std::collections::HashSet::new();
    let mut area = 0.0;
    for t in &out.triangles {
        for k in 0..3 {
            assert!(edges.insert((t[k], t[(k + 1) % 3])), "edge used twice");
        }
        let [a, b, c] = t.map(|v| out.positions[v as usize]);
        area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
    }
    let expected = (rows - 1) as f64 * d[0] * (cols - 1) as f64 * d[1];
    assert!((area - expected.abs()).abs() < 1e-6 * expected.abs());
}

/// Vertices of `out` on the line `axis == at`, sorted along the other axis.
fn on_line(out: &Simplified, axis: usize, at: f64) -> Vec<[f64; 3]> {
    let mut v: Vec<[f64; 3]> = out
        .positions
        .iter()
        .filter(|p| (p[axis] - at).abs() < 1e-9)
        .copied()
        .collect();
    v.sort_by(|a, b| a[1 - axis].total_cmp(&b[1 - axis]));
    v
}

fn waves() -> impl Strategy<Value = Vec<(f64, f64, f64)>> {
    prop::collection::vec((0.0..40.0f64, -0.05..0.05f64, -0.05..0.05f64), 1..4)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn every_sample_within_its_threshold(
        rows in 2usize..40,
        cols in 2usize..40,
        d in 5.0..100.0f64,
        h in 50.0..8000.0f64,
        w in waves(),
        noise in prop::collection::vec(-3.0..3.0f64, 1..50),
        coarse in prop::collection::vec(prop::option::of(1usize..4), 4),
    ) {
        let heights = terrain(rows, cols, d, &w, &noise);
        let tile = Tile { rows, cols, heights: &heights, spacing: [d, d], origin: [0.0, 0.0] };
        let mut params = Params::new(h);
        // Coarser neighbours where the stride divides the side.
        for side in Side::ALL {
            let cells = match side {
                Side::North | Side::South => cols - 1,
                Side::East | Side::West => rows - 1,
            };
            if let Some(k) = coarse[side as usize].filter(|&k| k > 1 && cells % k == 0) {
                params.neighbour_res[side as usize] = Some(k as f64 * d);
            }
        }
        let (out, stats) = simplify_tile(&tile, &params).unwrap();
        prop_assert!(stats.max_error_ratio <= 1.0 + 1e-9, "{stats:?}");
        assert_watertight(&out, rows, cols, [d, d]);
    }

    #[test]
    fn same_size_neighbours_meet_vertex_for_vertex(
        n in 3usize..34,
        d in (5u32..100).prop_map(f64::from),
        h in 50.0..8000.0f64,
        w in waves(),
        noise in prop::collection::vec(-3.0..3.0f64, 1..50),
    ) {
        // One terrain, cut into two tiles sharing the column x = (n-1) d.
        let wide = terrain(n, 2 * n - 1, d, &w, &noise);
        let cut = |c0: usize| -> Vec<f64> {
            (0..n).flat_map(|r| wide[r * (2 * n - 1) + c0..][..n].to_vec()).collect()
        };
        let (west, east) = (cut(0), cut(n - 1));
        let x = (n - 1) as f64 * d;
        let tw = Tile { rows: n, cols: n, heights: &west, spacing: [d, d], origin: [0.0, 0.0] };
        let te = Tile { heights: &east, origin: [x, 0.0], ..tw };
        let (ow, sw) = simplify_tile(&tw, &Params::new(h)).unwrap();
        let (oe, se) = simplify_tile(&te, &Params::new(h)).unwrap();
        prop_assert!(sw.max_error_ratio <= 1.0 + 1e-9 && se.max_error_ratio <= 1.0 + 1e-9);
        prop_assert_eq!(on_line(&ow, 0, x), on_line(&oe, 0, x));
    }

    #[test]
    fn coarse_tile_meets_two_half_size_tiles(
        half in 1usize..17,
        // Whole metres: every coordinate both tiles compute is exact.
        d in (5u32..60).prop_map(f64::from),
        h in 50.0..8000.0f64,
        w in waves(),
        noise in prop::collection::vec(-3.0..3.0f64, 1..50),
    ) {
        // Fine tiles: (2 half + 1)^2 samples at spacing d; the coarse tile
        // west of both: the same sample count at 2 d, twice the extent.
        let m = 2 * half + 1; // samples a side of every tile
        let fine_d = d;
        let coarse_d = 2.0 * d;
        let extent = (m - 1) as f64 * coarse_d; // of the coarse tile
        let world = |x: f64, y: f64| -> f64 {
            let h: f64 = w.iter().map(|&(a, fx, fy)| a * (x * fx + y * fy).sin()).sum();
            let i = ((x / fine_d).round() as i64 * 31 + (y / fine_d).round() as i64 * 17)
                .rem_euclid(noise.len() as i64) as usize;
            (h + noise[i]).round()
        };
        let grid = |x0: f64, y0: f64, s: f64| -> Vec<f64> {
            (0..m).flat_map(|r| (0..m).map(move |c| (r, c)))
                .map(|(r, c)| world(x0 + c as f64 * s, y0 + r as f64 * s))
                .collect()
        };
        let coarse_h = grid(-extent, 0.0, coarse_d);
        let south_h = grid(0.0, 0.0, fine_d);
        let north_h = grid(0.0, extent / 2.0, fine_d);
        let coarse = Tile { rows: m, cols: m, heights: &coarse_h, spacing: [coarse_d; 2], origin: [-extent, 0.0] };
        let south = Tile { heights: &south_h, spacing: [fine_d; 2], origin: [0.0, 0.0], ..coarse };
        let north = Tile { heights: &north_h, origin: [0.0, extent / 2.0], ..south };

        let mut pc = Params::new(h);
        pc.neighbour_tiles[Side::East as usize] = 2;
        let mut pf = Params::new(h);
        pf.neighbour_res[Side::West as usize] = Some(coarse_d);
        let (oc, sc) = simplify_tile(&coarse, &pc).unwrap();
        let (os, ss) = simplify_tile(&south, &pf).unwrap();
        let (on, sn) = simplify_tile(&north, &pf).unwrap();
        for s in [sc, ss, sn] {
            prop_assert!(s.max_error_ratio <= 1.0 + 1e-9, "{s:?}");
        }
        let mut fine = on_line(&os, 0, 0.0);
        let north_side = on_line(&on, 0, 0.0);
        // The shared corner appears in both fine tiles.
        prop_assert_eq!(fine.last(), north_side.first());
        fine.extend_from_slice(&north_side[1..]);
        prop_assert_eq!(on_line(&oc, 0, 0.0), fine);
    }
}
