//! Tests of the two-sided distance on meshes with known answers.

use super::*;

/// An `n` x `n` unit-spaced grid at height `z`.
fn grid(n: u32, z: f64) -> Mesh {
    let n = n as usize;
    crate::input::grid_to_mesh(&crate::input::Grid {
        rows: n,
        cols: n,
        elevations: vec![z; n * n],
        origin: [0.0, 0.0],
        spacing: [1.0, 1.0],
        nodata: None,
        coordinates: None,
    })
}

#[test]
fn identical_meshes_are_zero_apart() {
    let m = grid(10, 0.0);
    let r = surface_distance(&m, &m, 5000, 1);
    // Zero up to the rounding of interpolated sample points.
    assert!(r.hausdorff < 1e-12 * r.diagonal, "{r:?}");
    assert!(r.rms <= r.hausdorff && r.mean <= r.rms);
    assert!((r.diagonal - 162f64.sqrt()).abs() < 1e-12);
}

#[test]
fn offset_plane_is_half_a_unit_away() {
    let a = grid(10, 0.0);
    let b = grid(10, 0.5);
    let r = surface_distance(&a, &b, 5000, 1);
    assert!((r.hausdorff - 0.5).abs() < 1e-12);
    assert!((r.rms - 0.5).abs() < 1e-12);
    assert!((r.mean - 0.5).abs() < 1e-12);
    let back = surface_distance(&b, &a, 5000, 1);
    assert!((back.rms - 0.5).abs() < 1e-12);
}

#[test]
fn differently_triangulated_same_surface_is_zero_apart() {
    let fine = grid(9, 0.0);
    let coarse = Mesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [8.0, 0.0, 0.0],
            [8.0, 8.0, 0.0],
            [0.0, 8.0, 0.0],
        ],
        triangles: vec![[0, 1, 3], [1, 2, 3]],
    };
    let r = surface_distance(&fine, &coarse, 2000, 3);
    assert!(r.hausdorff < 1e-12);
}

#[test]
fn hausdorff_sees_a_one_sided_bump() {
    // b is a with one vertex lifted by 1: a -> b is small on average but
    // b -> a reaches exactly 1 at the lifted vertex.
    let a = grid(5, 0.0);
    let mut b = a.clone();
    b.positions[12][2] = 1.0;
    let r = surface_distance(&a, &b, 1000, 5);
    assert!((r.hausdorff - 1.0).abs() < 1e-12);
    assert!(r.rms > 0.0 && r.rms < 0.5);
    assert!(r.mean <= r.rms);
}

#[test]
fn the_farthest_sample_is_the_bump_and_the_percentile_ignores_it() {
    let a = grid(5, 0.0);
    let mut b = a.clone();
    b.positions[12][2] = 1.0;
    let r = surface_distance(&a, &b, 1000, 5);
    // Vertex 12 of the 5 x 5 grid is its centre, (2, 2), lifted to 1; it
    // lies on `b`, so the sample is on the second surface.
    let far = r.farthest.expect("samples");
    assert_eq!(far.point, [2.0, 2.0, 1.0]);
    assert!(!far.on_a);
    // Swapped, the same point lies on the first surface.
    assert!(surface_distance(&b, &a, 1000, 5).farthest.unwrap().on_a);
    // The bump's slopes reach a quarter of the grid: far more than 0.1 %
    // of the samples lie on them, so the percentile is below the spike but
    // above 0.
    assert!(r.p999 > 0.0 && r.p999 < r.hausdorff, "{r:?}");
}

#[test]
fn the_percentile_of_an_offset_plane_is_its_offset() {
    let r = surface_distance(&grid(10, 0.0), &grid(10, 0.5), 5000, 1);
    assert!((r.p999 - 0.5).abs() < 1e-12, "{r:?}");
}

#[test]
fn nearest_rank_percentiles() {
    let mut v: Vec<f64> = (1..=1000).rev().map(f64::from).collect();
    assert_eq!(percentile(&mut v, 0.999), 999.0);
    assert_eq!(percentile(&mut v, 1.0), 1000.0);
    assert_eq!(percentile(&mut v, 0.0), 1.0);
    assert_eq!(percentile(&mut [7.0], 0.999), 7.0);
    assert_eq!(percentile(&mut [], 0.999), 0.0);
}

#[test]
fn deterministic_for_a_seed() {
    let a = grid(6, 0.0);
    let mut b = a.clone();
    b.positions[7][2] = 0.3;
    let x = surface_distance(&a, &b, 3000, 42);
    assert_eq!(x, surface_distance(&a, &b, 3000, 42));
    assert_ne!(x.rms, surface_distance(&a, &b, 3000, 43).rms);
}

#[test]
fn empty_meshes() {
    let m = grid(3, 0.0);
    let empty = Mesh::default();
    let none = surface_distance(&empty, &empty, 10, 0);
    assert_eq!((none.hausdorff, none.p999, none.farthest), (0.0, 0.0, None));
    let one_sided = surface_distance(&m, &empty, 10, 0);
    assert_eq!(one_sided.hausdorff, f64::INFINITY);
    assert_eq!(one_sided.p999, f64::INFINITY);
    assert!(one_sided.farthest.unwrap().on_a);
}

/// Speed of 1M samples per side between a 1M-vertex, 2M-triangle terrain
/// and a half-resolution sampling of the same landscape:
/// `cargo test --release -p splitstream-encoder metrics_speed -- --ignored --nocapture`.
#[test]
#[ignore = "benchmark; run in release"]
fn metrics_speed_on_a_million_vertices() {
    use crate::baseline::tests::terrain;
    use std::time::Instant;

    let fine = terrain(1000);
    let coarse = terrain(708);
    let start = Instant::now();
    let r = surface_distance(&fine, &coarse, 1_000_000, 7);
    println!(
        "{} + {} samples, {} + {} triangles: {:.2} s; {r:?}",
        fine.vertex_count() + 1_000_000,
        coarse.vertex_count() + 1_000_000,
        fine.triangle_count(),
        coarse.triangle_count(),
        start.elapsed().as_secs_f64()
    );
    assert!(r.hausdorff < 0.01 * r.diagonal);
}
