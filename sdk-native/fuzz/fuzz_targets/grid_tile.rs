//! The grid-tile simplifier on arbitrary tiles and parameters: sizes from
//! 0 to 33 samples a side, heights over many scales (with NaN, infinities
//! and subnormals), odd spacings, origins, viewing heights and neighbours.
//! Bad input must give a `GridTileError`, never a panic or a hang; a tile
//! that simplifies must keep the module's promises:
//! - every sample is within its threshold, give or take the thousandth
//!   that rounding may take (`max_error_ratio <= 1 + 1e-3`);
//! - the vertices are finite and the triangles index them;
//! - a reused `Simplifier` gives what a fresh one gives.
#![no_main]

use libfuzzer_sys::fuzz_target;
use splitstream_sdk_native::grid_tile::{Params, Simplifier, Tile, simplify_tile};
use splitstream_sdk_native_fuzz::Bytes;

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let rows = b.u8() as usize % 34;
    let cols = b.u8() as usize % 34;
    let spacing = [b.f64(1.0), b.f64(1.0)];
    let origin = [b.f64(1e5), b.f64(1e5)];
    let mut params = Params::new(b.f64(100.0));
    for side in 0..4 {
        let flags = b.u8();
        if flags & 1 != 0 {
            // Mostly a whole multiple of the spacing along that side.
            params.neighbour_res[side] = Some(b.f64(spacing[side % 2].abs()));
        }
        params.neighbour_tiles[side] = [1, 1, 2, 4, 0, 3][flags as usize / 2 % 6];
    }
    // Heights: i16 steps at one of five scales, or (scale 0) any f64.
    let scale = [0.0, 1e-3, 1.0, 10.0, 1e6, 1e12][b.u8() as usize % 6];
    let n = rows * cols;
    // Now and then one height too many or too few.
    let len = match b.u8() % 16 {
        0 => n + 1,
        1 => n.saturating_sub(1),
        _ => n,
    };
    let special = b.u8();
    let mut heights: Vec<f64> = (0..len)
        .map(|_| {
            if scale == 0.0 {
                b.f64(1.0)
            } else {
                b.i16() as f64 * scale
            }
        })
        .collect();
    if special % 4 == 0 && !heights.is_empty() {
        let at = special as usize % heights.len();
        heights[at] =
            [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e-310][special as usize / 4 % 4];
    }
    let tile = Tile {
        rows,
        cols,
        heights: &heights,
        spacing,
        origin,
    };
    let Ok((fresh, stats)) = simplify_tile(&tile, &params) else {
        return;
    };
    assert!(
        stats.max_error_ratio <= 1.0 + 1e-3,
        "a sample is over its threshold: {stats:?}"
    );
    assert!(
        fresh.positions.iter().flatten().all(|c| c.is_finite()),
        "a vertex is not finite"
    );
    let count = fresh.positions.len();
    for t in &fresh.triangles {
        assert!(
            t.iter().all(|&v| (v as usize) < count),
            "triangle {t:?} of {count} positions"
        );
    }
    // Reused buffers give the same result: simplify another tile first.
    let mut simplifier = Simplifier::new(rows, cols);
    let flat = vec![0.0; n];
    let other = Tile {
        heights: &flat,
        ..tile
    };
    let _ = simplifier.simplify(&other, &params);
    let (again, stats_again) = simplifier
        .simplify(&tile, &params)
        .expect("it simplified once");
    assert_eq!(stats_again, stats);
    assert_eq!(again.triangles, fresh.triangles);
    assert_eq!(again.rectangles, fresh.rectangles);
});
