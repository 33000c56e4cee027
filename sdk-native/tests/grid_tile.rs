//! Grid-tile simplifier: planes collapse, tiles stay crack-free at
//! different resolutions, the error stays bounded, bad input is typed.

use splitstream_sdk_native::grid_tile::{
    GridTileError, Params, Side, Simplifier, Tile, simplify_tile, threshold,
};

fn params(h: f64) -> Params {
    Params::new(h)
}

fn sample(rows: usize, cols: usize, mut f: impl FnMut(usize, usize) -> f64) -> Vec<f64> {
    let mut v = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            v.push(f(r, c));
        }
    }
    v
}

/// Smooth hilly terrain in metres at world position (x, y).
fn hills(x: f64, y: f64) -> f64 {
    40.0 * (x / 170.0).sin() * (y / 230.0).cos() + 15.0 * (x / 61.0 + y / 97.0).sin()
}

fn signed_area(p: &[[f64; 3]], t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|v| p[v as usize]);
    (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
}

#[test]
fn flat_tile_is_two_triangles() {
    let h = vec![12.5; 65 * 65];
    let tile = Tile {
        rows: 65,
        cols: 65,
        heights: &h,
        spacing: [32.0, 32.0],
        origin: [0.0, 0.0],
    };
    let (out, stats) = simplify_tile(&tile, &params(700.0)).unwrap();
    assert_eq!(stats.rectangles, 1);
    assert_eq!(out.triangles.len(), 2);
    assert_eq!(out.positions.len(), 4);
    assert_eq!(stats.max_vertical_error, 0.0);
    assert_eq!(stats.cells, 64 * 64);
    for &t in &out.triangles {
        assert!(signed_area(&out.positions, t) > 0.0);
    }
}

#[test]
fn tilted_plane_is_two_triangles() {
    for (rows, cols) in [(65, 65), (17, 40), (2, 9)] {
        let h = sample(rows, cols, |r, c| 3.0 + 0.75 * c as f64 - 1.25 * r as f64);
        let tile = Tile {
            rows,
            cols,
            heights: &h,
            spacing: [10.0, 10.0],
            origin: [100.0, 200.0],
        };
        let (out, stats) = simplify_tile(&tile, &params(700.0)).unwrap();
        assert_eq!(out.triangles.len(), 2, "{rows} x {cols}");
        assert_eq!(stats.rectangles, 1);
        assert!(stats.max_vertical_error < 1e-9);
    }
}

#[test]
fn mirrored_spacing_keeps_counter_clockwise() {
    let h = sample(33, 33, |r, c| hills(c as f64 * 30.0, r as f64 * 30.0));
    for spacing in [[30.0, -30.0], [-30.0, 30.0], [30.0, 30.0]] {
        let tile = Tile {
            rows: 33,
            cols: 33,
            heights: &h,
            spacing,
            origin: [0.0, 0.0],
        };
        let (out, _) = simplify_tile(&tile, &params(700.0)).unwrap();
        for &t in &out.triangles {
            assert!(signed_area(&out.positions, t) > 0.0, "{spacing:?}");
        }
    }
}

/// Every interior edge has exactly two triangles, one each way; border
/// edges one. That is the "no crack, no T-junction" property inside a tile.
fn assert_watertight(out: &splitstream_sdk_native::grid_tile::Simplified) {
    use std::collections::HashMap;
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &out.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            assert_ne!(a, b);
            *edges.entry((a, b)).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "edge {a}-{b} used {n} times the same way");
    }
    // The total area must equal the tile's: no holes, no overlaps.
    let area: f64 = out
        .triangles
        .iter()
        .map(|&t| signed_area(&out.positions, t))
        .sum();
    let (lo, hi) = out
        .positions
        .iter()
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        });
    let expected = 2.0 * (hi[0] - lo[0]) * (hi[1] - lo[1]);
    assert!(
        (area - expected).abs() < 1e-6 * expected,
        "{area} vs {expected}"
    );
}

#[test]
fn rough_tile_is_watertight_and_params() {
    let (rows, cols, d) = (65, 65, 32.0);
    let h = sample(rows, cols, |r, c| hills(c as f64 * d, r as f64 * d));
    let tile = Tile {
        rows,
        cols,
        heights: &h,
        spacing: [d, d],
        origin: [0.0, 0.0],
    };
    let mut s = Simplifier::new(rows, cols);
    let (out, stats) = s.simplify(&tile, &params(700.0)).unwrap();
    assert_watertight(out);
    let t = threshold(700.0, d);
    assert_eq!(stats.threshold, t);
    assert!(stats.rectangles < stats.cells, "{stats:?}");
    assert!(stats.rectangles > 1);
    assert!(stats.max_vertical_error <= t * (1.0 + 1e-9), "{stats:?}");
    assert!(stats.max_error_ratio <= 1.0 + 1e-9, "{stats:?}");
}

#[test]
fn error_respects_threshold_on_many_surfaces() {
    for seed in 0..6u32 {
        let (rows, cols, d) = (33, 33, 20.0);
        let a = 1.0 + seed as f64;
        let h = sample(rows, cols, |r, c| {
            let (x, y) = (c as f64 * d + 77.0 * a, r as f64 * d - 31.0 * a);
            hills(x * a / 3.0, y) + (seed as f64) * ((x * y).abs().sqrt() / 50.0).sin()
        });
        let tile = Tile {
            rows,
            cols,
            heights: &h,
            spacing: [d, d],
            origin: [0.0, 0.0],
        };
        for height in [100.0, 700.0, 5000.0] {
            let (out, stats) = simplify_tile(&tile, &params(height)).unwrap();
            assert_watertight(&out);
            assert!(
                stats.max_vertical_error <= stats.threshold * (1.0 + 1e-9),
                "seed {seed} H {height}: {stats:?}"
            );
        }
    }
}

/// A fine tile (spacing 16) east of a coarse one (spacing 32), both
/// covering 1024 m along the shared side: the fine tile's West side uses the
/// coarse threshold and keeps only samples the coarse tile has.
#[test]
fn neighbouring_tiles_at_different_resolutions_share_their_border() {
    let side = 1024.0;
    let coarse_d = 32.0;
    let fine_d = 16.0;
    let (cn, fnn) = (33, 65);
    // Coarse tile: x in [-1024, 0]; fine tile: x in [0, 1024].
    let coarse_h = sample(cn, cn, |r, c| {
        hills(-side + c as f64 * coarse_d, r as f64 * coarse_d)
    });
    let fine_h = sample(fnn, fnn, |r, c| hills(c as f64 * fine_d, r as f64 * fine_d));
    let coarse = Tile {
        rows: cn,
        cols: cn,
        heights: &coarse_h,
        spacing: [coarse_d, coarse_d],
        origin: [-side, 0.0],
    };
    let fine = Tile {
        rows: fnn,
        cols: fnn,
        heights: &fine_h,
        spacing: [fine_d, fine_d],
        origin: [0.0, 0.0],
    };
    for height in [300.0, 700.0, 3000.0] {
        let mut pc = params(height);
        pc.neighbour_res[Side::East as usize] = Some(fine_d);
        let mut pf = params(height);
        pf.neighbour_res[Side::West as usize] = Some(coarse_d);
        let (co, _) = simplify_tile(&coarse, &pc).unwrap();
        let (fo, fstats) = simplify_tile(&fine, &pf).unwrap();
        let on_border = |p: &&[f64; 3]| p[0] == 0.0;
        let mut cb: Vec<[f64; 3]> = co.positions.iter().filter(on_border).copied().collect();
        let mut fb: Vec<[f64; 3]> = fo.positions.iter().filter(on_border).copied().collect();
        cb.sort_by(|a, b| a[1].total_cmp(&b[1]));
        fb.sort_by(|a, b| a[1].total_cmp(&b[1]));
        assert!(cb.len() >= 2);
        assert_eq!(cb, fb, "H {height}: border vertices differ");
        assert_watertight(&fo);
        assert!(fstats.rectangles < fstats.cells);

        assert!(
            fstats.max_error_ratio <= 1.0 + 1e-9,
            "H {height}: {fstats:?}"
        );
    }
}

#[test]
fn same_resolution_neighbours_share_their_border() {
    let (n, d) = (65, 32.0);
    let a = sample(n, n, |r, c| hills(c as f64 * d, r as f64 * d));
    let b = sample(n, n, |r, c| hills(c as f64 * d, (r + n - 1) as f64 * d));
    let ta = Tile {
        rows: n,
        cols: n,
        heights: &a,
        spacing: [d, d],
        origin: [0.0, 0.0],
    };
    let tb = Tile {
        origin: [0.0, (n - 1) as f64 * d],
        heights: &b,
        ..ta
    };
    let (oa, _) = simplify_tile(&ta, &params(700.0)).unwrap();
    let (ob, _) = simplify_tile(&tb, &params(700.0)).unwrap();
    let y = (n - 1) as f64 * d;
    let border = |o: &splitstream_sdk_native::grid_tile::Simplified| {
        let mut v: Vec<[f64; 3]> = o.positions.iter().filter(|p| p[1] == y).copied().collect();
        v.sort_by(|a, b| a[0].total_cmp(&b[0]));
        v
    };
    assert_eq!(border(&oa), border(&ob));
}

#[test]
fn reused_simplifier_gives_the_same_result() {
    let h = sample(65, 65, |r, c| hills(c as f64 * 32.0, r as f64 * 32.0));
    let tile = Tile {
        rows: 65,
        cols: 65,
        heights: &h,
        spacing: [32.0, 32.0],
        origin: [0.0, 0.0],
    };
    let (fresh, stats) = simplify_tile(&tile, &params(700.0)).unwrap();
    let mut s = Simplifier::new(65, 65);
    for _ in 0..3 {
        let (again, stats2) = s.simplify(&tile, &params(700.0)).unwrap();
        assert_eq!(again.triangles, fresh.triangles);
        assert_eq!(stats2, stats);
    }
}

#[test]
fn garbage_input_gives_typed_errors() {
    let good = vec![0.0; 9];
    let base = Tile {
        rows: 3,
        cols: 3,
        heights: &good,
        spacing: [1.0, 1.0],
        origin: [0.0, 0.0],
    };
    let one = [1.0];
    assert_eq!(
        simplify_tile(
            &Tile {
                rows: 1,
                cols: 1,
                heights: &one,
                ..base
            },
            &params(700.0)
        )
        .unwrap_err(),
        GridTileError::TooSmall { rows: 1, cols: 1 }
    );
    assert!(matches!(
        simplify_tile(
            &Tile {
                rows: 0,
                cols: 5,
                heights: &[],
                ..base
            },
            &params(700.0)
        ),
        Err(GridTileError::TooSmall { .. })
    ));
    let mut nan = good.clone();
    nan[4] = f64::NAN;
    assert_eq!(
        simplify_tile(
            &Tile {
                heights: &nan,
                ..base
            },
            &params(700.0)
        )
        .unwrap_err(),
        GridTileError::NonFiniteHeight { row: 1, col: 1 }
    );
    for spacing in [
        [0.0, 1.0],
        [1.0, 0.0],
        [f64::NAN, 1.0],
        [1.0, f64::INFINITY],
    ] {
        assert!(matches!(
            simplify_tile(&Tile { spacing, ..base }, &params(700.0)),
            Err(GridTileError::BadSpacing { .. })
        ));
    }
    assert!(matches!(
        simplify_tile(
            &Tile {
                heights: &good[..8],
                ..base
            },
            &params(700.0)
        ),
        Err(GridTileError::LengthMismatch {
            expected: 9,
            actual: 8
        })
    ));
    for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            simplify_tile(&base, &params(h)),
            Err(GridTileError::BadViewingHeight(_))
        ));
    }
    let mut p = params(700.0);
    p.neighbour_res[Side::North as usize] = Some(-2.0);
    assert!(matches!(
        simplify_tile(&base, &p),
        Err(GridTileError::BadNeighbourResolution {
            side: Side::North,
            ..
        })
    ));
    // 2 cells per side: a neighbour 3x coarser cannot line up.
    p.neighbour_res[Side::North as usize] = Some(3.0);
    assert!(matches!(
        simplify_tile(&base, &p),
        Err(GridTileError::NeighbourMismatch {
            side: Side::North,
            ..
        })
    ));
    p.neighbour_res[Side::North as usize] = Some(1.5);
    assert!(matches!(
        simplify_tile(&base, &p),
        Err(GridTileError::NeighbourMismatch { .. })
    ));
    for (origin, spacing) in [
        ([f64::NAN, 0.0], [1.0, 1.0]),
        ([0.0, f64::INFINITY], [1.0, 1.0]),
        // A finite origin whose far corner, two spacings on, is not.
        ([f64::MAX, 0.0], [1e300, 1.0]),
    ] {
        assert!(matches!(
            simplify_tile(
                &Tile {
                    origin,
                    spacing,
                    ..base
                },
                &params(700.0)
            ),
            Err(GridTileError::BadOrigin { .. })
        ));
    }
    // Errors print one line.
    let msg = GridTileError::NonFiniteHeight { row: 1, col: 2 }.to_string();
    assert!(!msg.contains('\n'));
}

#[test]
fn smallest_tile_works() {
    let h = [0.0, 1.0, 2.0, 5.0];
    let tile = Tile {
        rows: 2,
        cols: 2,
        heights: &h,
        spacing: [1.0, 1.0],
        origin: [0.0, 0.0],
    };
    let (out, stats) = simplify_tile(&tile, &params(700.0)).unwrap();
    assert_eq!(out.triangles.len(), 2);
    assert_eq!(stats.cells, 1);
    assert_eq!(stats.max_vertical_error, 0.0);
}

#[test]
fn noisy_integer_terrain_is_watertight() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % 1000) as f64 / 1000.0
    };
    for height in [700.0, 2000.0, 5000.0] {
        let h = sample(65, 65, |r, c| {
            (hills(c as f64 * 80.0, r as f64 * 90.0) + 3.0 * rnd()).round()
        });
        let tile = Tile {
            rows: 65,
            cols: 65,
            heights: &h,
            spacing: [74.5, 92.1],
            origin: [1000.0, 2000.0],
        };
        let (out, stats) = simplify_tile(&tile, &Params::new(height)).unwrap();
        assert_watertight(&out);
        assert!(stats.max_error_ratio <= 1.0 + 1e-9, "{stats:?}");
    }
}

#[test]
fn coarser_neighbour_side_keeps_only_its_samples_and_threshold() {
    // Rough enough that the side keeps many vertices.
    let (n, d) = (65, 16.0);
    let h = sample(n, n, |r, c| hills(c as f64 * d * 3.0, r as f64 * d * 3.0));
    let tile = Tile {
        rows: n,
        cols: n,
        heights: &h,
        spacing: [d, d],
        origin: [0.0, 0.0],
    };
    let mut p = params(3000.0);
    p.neighbour_res[Side::North as usize] = Some(4.0 * d);
    let (out, stats) = simplify_tile(&tile, &p).unwrap();
    let top = (n - 1) as f64 * d;
    let on_top: Vec<f64> = out
        .positions
        .iter()
        .filter(|q| q[1] == top)
        .map(|q| q[0])
        .collect();
    assert!(on_top.len() > 2);
    for x in &on_top {
        assert_eq!(x % (4.0 * d), 0.0, "vertex at x {x} is not a coarse sample");
    }
    // T on the interior is the tile's own; on that side the coarse one.
    assert_eq!(stats.threshold, threshold(3000.0, d));
    assert!(threshold(3000.0, 4.0 * d) > 3.0 * stats.threshold);
}

/// Fuzz finding (`sdk-native/fuzz`, target `grid_tile`, 2026-12-03): heights
/// of 3.2e16 with a threshold of 0.24 simplified "successfully" with a
/// sample 6.4 thresholds off, because f64 rounding at that magnitude (one
/// ulp is 4.0) is more than the threshold. Such a tile is now refused.
#[test]
fn heights_too_large_for_the_threshold_are_refused() {
    let mut heights = vec![0.0; 25 * 25];
    heights[0] = 32300.0 * 1e12;
    heights[1] = 126.0 * 1e12;
    let tile = Tile {
        rows: 25,
        cols: 25,
        heights: &heights,
        spacing: [6.0, 6.0],
        origin: [0.0, 0.0],
    };
    let mut p = params(500.0);
    p.neighbour_res[Side::West as usize] = Some(36.0);
    let err = simplify_tile(&tile, &p).unwrap_err();
    assert_eq!(
        err,
        GridTileError::BelowPrecision {
            threshold: 0.24,
            max_abs_height: 3.23e16
        }
    );
    assert!(!err.to_string().contains('\n'));
    // A viewing height so low that T is below any height's rounding.
    let flat = vec![1.0; 25 * 25];
    let flat_tile = Tile {
        heights: &flat,
        ..tile
    };
    assert!(matches!(
        simplify_tile(&flat_tile, &params(1e-300)),
        Err(GridTileError::BelowPrecision { .. })
    ));
    // Everest in metres, seen from 500 m (T = 0.24 m) and from eye height
    // (1.7 m: T = 2.1 mm): far inside the limit.
    let everest: Vec<f64> = (0..25 * 25).map(|i| 8848.0 - (i % 25) as f64).collect();
    for h in [500.0, 1.7] {
        let (_, stats) = simplify_tile(
            &Tile {
                heights: &everest,
                ..tile
            },
            &params(h),
        )
        .unwrap();
        assert!(stats.max_error_ratio <= 1.0 + 1e-3, "{stats:?}");
    }
}
