//! Scale test for the input layer: the 4M-vertex synthetic terrain must be
//! generated, checked and (no-op) repaired quickly. Full size in release
//! builds (`cargo test --release --test input_perf -- --nocapture`), a
//! smaller terrain in debug builds so the default test run stays fast.

use std::time::Instant;

use splitstream_encoder::input::{check_mesh, fractal_terrain, repair_mesh};

#[test]
fn terrain_check_and_repair_at_scale() {
    let side = if cfg!(debug_assertions) { 300 } else { 2000 };
    let t = Instant::now();
    let mesh = fractal_terrain(side, 42);
    let generate = t.elapsed();
    assert_eq!(mesh.positions.len(), side * side);

    let t = Instant::now();
    let stats = check_mesh(&mesh).unwrap();
    let check = t.elapsed();
    assert_eq!(
        (stats.components, stats.boundary_loops, stats.genus),
        (1, 1, 0)
    );

    let t = Instant::now();
    let (_, report) = repair_mesh(&mesh);
    let repair = t.elapsed();
    assert!(report.is_clean(), "{report}");

    eprintln!(
        "side {side}: {} vertices, {} triangles; terrain {generate:.2?}, check {check:.2?}, repair {repair:.2?}",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    if !cfg!(debug_assertions) {
        // Generous bound (shared CI machines); the target is well under 2 s.
        assert!(generate.as_secs_f64() < 4.0, "terrain took {generate:?}");
    }
}
