//! End-to-end tests of the sequential baseline on generated meshes.

use std::collections::HashMap;

use super::*;

/// An `n` x `n` vertex grid on [0, 1]², heights from `height`.
pub fn grid(n: u32, height: impl Fn(f64, f64) -> f64) -> Mesh {
    let step = 1.0 / f64::from(n - 1);
    let elevations = (0..n * n)
        .map(|k| height(f64::from(k % n) * step, f64::from(k / n) * step))
        .collect();
    let n = n as usize;
    crate::input::grid_to_mesh(&crate::input::Grid {
        rows: n,
        cols: n,
        elevations,
        origin: [0.0, 0.0],
        spacing: [step, step],
        nodata: None,
        coordinates: None,
    })
}

/// A unit icosphere subdivided `levels` times (CCW seen from outside).
pub fn icosphere(levels: u32) -> Mesh {
    crate::input::icosphere(levels as usize)
}

/// Checks that `mesh` is an oriented manifold: indices in range, no
/// degenerate index triples, every directed edge used once, every undirected
/// edge by one or two triangles. Returns (edges, boundary edges).
fn assert_oriented_manifold(mesh: &Mesh) -> (usize, usize) {
    let mut directed = HashMap::new();
    for t in &mesh.triangles {
        assert!(t.iter().all(|&v| (v as usize) < mesh.positions.len()));
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[2] != t[0],
            "degenerate {t:?}"
        );
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            assert!(
                directed.insert(e, ()).is_none(),
                "directed edge {e:?} twice"
            );
        }
    }
    let edges = directed
        .keys()
        .filter(|&&(a, b)| a < b || !directed.contains_key(&(b, a)))
        .count();
    let boundary = directed
        .keys()
        .filter(|&&(a, b)| !directed.contains_key(&(b, a)))
        .count();
    // Every vertex is used and has a single fan (no pinched vertices).
    let mut used = vec![0usize; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] += 1;
        }
    }
    assert!(
        used.iter().all(|&u| u > 0),
        "compacted output has unused vertices"
    );
    (edges, boundary)
}

fn options(target_vertices: usize) -> BaselineOptions {
    BaselineOptions {
        target_vertices,
        ..BaselineOptions::default()
    }
}

#[test]
fn flat_grid_collapses_to_almost_nothing() {
    let mesh = grid(20, |_, _| 0.0);
    let r = simplify_sequential(
        &mesh,
        &BaselineOptions {
            max_error: Some(1e-12),
            ..options(0)
        },
    );
    let (_, boundary) = assert_oriented_manifold(&r.mesh);
    assert!(
        r.mesh.vertex_count() <= 8,
        "{} vertices left",
        r.mesh.vertex_count()
    );
    assert!(boundary >= 3);
    assert!(
        r.max_collapse_error < 1e-12,
        "error {}",
        r.max_collapse_error
    );
    assert_eq!(r.collapses, 400 - r.mesh.vertex_count());
    // Still covers the unit square: the corners cannot move.
    let area: f64 = r
        .mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| r.mesh.positions[v as usize]);
            0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
        })
        .sum();
    assert!((area - 1.0).abs() < 1e-9, "area {area}");
    for p in &r.mesh.positions {
        assert!(p[2].abs() < 1e-12);
    }
}

#[test]
fn sphere_stays_a_closed_manifold() {
    let mesh = icosphere(3); // 642 vertices
    for target in [300, 100, 20, 4] {
        let r = simplify_sequential(&mesh, &options(target));
        let (edges, boundary) = assert_oriented_manifold(&r.mesh);
        assert_eq!(boundary, 0);
        let (v, f) = (r.mesh.vertex_count(), r.mesh.triangle_count());
        assert_eq!(
            v as i64 - edges as i64 + f as i64,
            2,
            "Euler at target {target}"
        );
        assert_eq!(v, target, "target {target} met exactly");
    }
}

#[test]
fn closed_mesh_never_goes_below_a_tetrahedron() {
    let r = simplify_sequential(&icosphere(1), &options(0));
    let (edges, _) = assert_oriented_manifold(&r.mesh);
    assert_eq!(r.mesh.vertex_count(), 4);
    assert_eq!((edges, r.mesh.triangle_count()), (6, 4));
}

#[test]
fn targets_on_open_terrain_are_met_exactly() {
    let mesh = grid(30, |x, y| (6.0 * x).sin() * (4.0 * y).cos() * 0.2);
    for target in [600, 200, 50] {
        let r = simplify_sequential(&mesh, &options(target));
        assert_oriented_manifold(&r.mesh);
        assert_eq!(r.mesh.vertex_count(), target);
        assert_eq!(r.collapses, 900 - target);
    }
}

#[test]
fn max_error_stops_early() {
    let mesh = grid(30, |x, y| (6.0 * x).sin() * (4.0 * y).cos() * 0.2);
    let full = simplify_sequential(&mesh, &options(0));
    let limit = 1e-6;
    let r = simplify_sequential(
        &mesh,
        &BaselineOptions {
            max_error: Some(limit),
            ..options(0)
        },
    );
    assert_oriented_manifold(&r.mesh);
    assert!(r.max_collapse_error <= limit);
    assert!(r.mesh.vertex_count() > full.mesh.vertex_count());
    assert!(r.mesh.vertex_count() < 900);
}

#[test]
fn locked_boundary_does_not_move() {
    let mesh = grid(15, |x, y| x * y);
    let r = simplify_sequential(
        &mesh,
        &BaselineOptions {
            lock_boundary: true,
            ..options(0)
        },
    );
    assert_oriented_manifold(&r.mesh);
    let on_border = |p: &[f64; 3]| p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0;
    let border_in = mesh.positions.iter().filter(|p| on_border(p)).count();
    let border_out = r.mesh.positions.iter().filter(|p| on_border(p)).count();
    assert_eq!(
        border_in, border_out,
        "all 56 border vertices survive in place"
    );
}

#[test]
fn constrained_placement_keeps_original_or_midpoint_coordinates() {
    let mesh = icosphere(2);
    let r = simplify_sequential(
        &mesh,
        &BaselineOptions {
            constrained: true,
            ..options(60)
        },
    );
    assert_oriented_manifold(&r.mesh);
    assert_eq!(r.mesh.vertex_count(), 60);
}

#[test]
fn valence_stays_bounded() {
    // A fan of 300 triangles around one centre vertex (a disc).
    let n = 300u32;
    let mut positions = vec![[0.0, 0.0, 0.0]];
    for i in 0..n {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
        positions.push([a.cos(), a.sin(), 0.0]);
    }
    let triangles = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    let mesh = Mesh {
        positions,
        triangles,
    };
    let r = simplify_sequential(&mesh, &options(3));
    assert_oriented_manifold(&r.mesh);
    let mut valence = vec![0usize; r.mesh.vertex_count()];
    for t in &r.mesh.triangles {
        for &v in t {
            valence[v as usize] += 1;
        }
    }
    // Faces around a border vertex = neighbours - 1, so neighbours + 1
    // (the extra border count) = faces + 2.
    assert!(valence.iter().all(|&f| f + 2 <= MAX_VALENCE));
}

#[test]
fn empty_and_tiny_inputs() {
    let r = simplify_sequential(&Mesh::default(), &options(0));
    assert_eq!(r.mesh, Mesh::default());
    let tri = Mesh {
        positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [9.0; 3]],
        triangles: vec![[0, 1, 2]],
    };
    let r = simplify_sequential(&tri, &options(0));
    assert_eq!(r.mesh.triangle_count(), 1, "a lone triangle cannot shrink");
    assert_eq!(r.mesh.vertex_count(), 3, "unused vertex dropped");
    let mut bad = tri.clone();
    bad.triangles.push([0, 2, 99]);
    let r = simplify_sequential(&bad, &options(0));
    assert_eq!(r.mesh.triangle_count(), 1, "out-of-range triangle skipped");
}

/// A rough synthetic terrain: a few octaves of sines plus hashed jitter.
pub fn terrain(n: u32) -> Mesh {
    grid(n, |x, y| {
        let h = ((x * 1e4).to_bits() ^ (y * 1e4).to_bits().rotate_left(29))
            .wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let jitter = (h >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        0.1 * (7.0 * x).sin() * (5.0 * y).cos()
            + 0.03 * (31.0 * x + 3.0 * y).sin()
            + 0.01 * (97.0 * y - 13.0 * x).cos()
            + 0.002 * jitter
    })
}

/// Speed on a 1M-vertex, 2M-triangle terrain to 50 %:
/// `cargo test --release -p splitstream-encoder baseline_speed -- --ignored --nocapture`.
#[test]
#[ignore = "benchmark; run in release"]
fn baseline_speed_half_of_a_million_vertices() {
    speed(500_000);
}

/// The same terrain down to 1 % of its vertices.
#[test]
#[ignore = "benchmark; run in release"]
fn baseline_speed_one_percent_of_a_million_vertices() {
    speed(10_000);
}

fn speed(target: usize) {
    let mesh = terrain(1000);
    let r = simplify_sequential(&mesh, &options(target));
    println!(
        "{} -> {} vertices, {} triangles, {} collapses, max error {:.3e}, {:.2} s",
        mesh.vertex_count(),
        r.mesh.vertex_count(),
        r.mesh.triangle_count(),
        r.collapses,
        r.max_collapse_error,
        r.seconds
    );
    assert_eq!(r.mesh.vertex_count(), target);
    assert_oriented_manifold(&r.mesh);
}
