//! Input meshes of the encoded vectors; all deterministic.

use std::path::Path;

use splitstream_encoder::Mesh;
use splitstream_encoder::input::{ReadOptions, check_mesh, read_mesh, repair_mesh};

/// sin(x) from +, -, *, / only (Taylor series after reduction to
/// [-pi, pi]), so that generated meshes, and therefore the vectors, do not
/// depend on the platform's libm.
fn sin(x: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let mut x = x - tau * (x / tau).round();
    if x > std::f64::consts::FRAC_PI_2 {
        x = std::f64::consts::PI - x;
    } else if x < -std::f64::consts::FRAC_PI_2 {
        x = -std::f64::consts::PI - x;
    }
    let (mut term, mut sum) = (x, x);
    for k in 1..12 {
        term *= -x * x / ((2 * k) as f64 * (2 * k + 1) as f64);
        sum += term;
    }
    sum
}

fn cos(x: f64) -> f64 {
    sin(x + std::f64::consts::FRAC_PI_2)
}

pub use splitstream_encoder::input::icosphere;

/// A `w` x `h` bumpy height field; with `hole`, the cells `x0..x1` x
/// `y0..y1` are cut out (and the vertices left inside dropped), so the mesh
/// has an outer boundary and a hole.
pub fn grid(w: usize, h: usize, seed: u64, hole: Option<[usize; 4]>) -> Mesh {
    height_field(w, h, hole, |fx, fy| {
        sin(fx * 0.7 + seed as f64) * 2.0 + cos(fy * 0.45) * 3.0 + sin((fx * fy) * 0.05)
    })
}

/// A `w` x `h` height field of whole-unit heights 0..=3, pseudo-random from
/// `seed`: every axis lies on a lattice, so constrained mode keeps them all
/// and the small integers make the placement context's ties (SPEC §7.4)
/// happen.
pub fn stepped_grid(w: usize, h: usize, seed: u64) -> Mesh {
    height_field(w, h, None, |fx, fy| {
        // splitmix64 of the sample's index and the seed.
        let mut z = (fy as u64 * w as u64 + fx as u64) ^ seed.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) % 4) as f64
    })
}

/// Samples `z(x, y)` on a `w` x `h` grid 10 units apart, triangulated with
/// alternating diagonals, without the cells of `hole`.
fn height_field(w: usize, h: usize, hole: Option<[usize; 4]>, z: impl Fn(f64, f64) -> f64) -> Mesh {
    let mut positions = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f64, y as f64);
            positions.push([fx * 10.0, fy * 10.0, z(fx, fy)]);
        }
    }
    let mut triangles = Vec::new();
    for y in 0..h - 1 {
        for x in 0..w - 1 {
            if let Some([x0, x1, y0, y1]) = hole
                && (x0..x1).contains(&x)
                && (y0..y1).contains(&y)
            {
                continue;
            }
            let i = (y * w + x) as u32;
            let (r, u, ru) = (i + 1, i + w as u32, i + w as u32 + 1);
            // Alternate the diagonal so vertex valences vary.
            if (x + y) % 2 == 0 {
                triangles.push([i, r, ru]);
                triangles.push([i, ru, u]);
            } else {
                triangles.push([i, r, u]);
                triangles.push([r, ru, u]);
            }
        }
    }
    compact(Mesh {
        positions,
        triangles,
    })
}

/// A closed cone: an apex joined to `n` vertices of the top ring (apex
/// valence `n`), `rings` rings down the side, and a bottom cap whose centre
/// also has valence `n`.
pub fn cone(n: usize, rings: usize) -> Mesh {
    let mut positions = vec![[0.0, 0.0, 10.0]];
    for j in 0..rings {
        let radius = 1.0 + j as f64;
        let z = 10.0 - 2.5 * (j + 1) as f64;
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64 + 0.1 * j as f64;
            positions.push([radius * cos(a), radius * sin(a), z]);
        }
    }
    positions.push([0.0, 0.0, 10.0 - 2.5 * (rings + 1) as f64]);
    let bottom = (positions.len() - 1) as u32;
    let ring = |j: usize, i: usize| (1 + j * n + i % n) as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        triangles.push([0, ring(0, i), ring(0, i + 1)]);
    }
    for j in 0..rings - 1 {
        for i in 0..n {
            let (a, b) = (ring(j, i), ring(j, i + 1));
            let (d, c) = (ring(j + 1, i), ring(j + 1, i + 1));
            triangles.push([a, d, c]);
            triangles.push([a, c, b]);
        }
    }
    for i in 0..n {
        triangles.push([bottom, ring(rings - 1, i + 1), ring(rings - 1, i)]);
    }
    Mesh {
        positions,
        triangles,
    }
}

/// Drops unreferenced vertices, keeping the order of the others.
fn compact(mesh: Mesh) -> Mesh {
    let mut map = vec![u32::MAX; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            map[v as usize] = 0;
        }
    }
    let mut positions = Vec::new();
    for (v, m) in map.iter_mut().enumerate() {
        if *m == 0 {
            *m = positions.len() as u32;
            positions.push(mesh.positions[v]);
        }
    }
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| map[v as usize]))
        .collect();
    Mesh {
        positions,
        triangles,
    }
}

/// Reads a real mesh fetched by encoder/data/fetch.sh, repaired if the
/// encoder's checker rejects it.
pub fn real(dir: &Path, name: &str) -> Result<Mesh, String> {
    let path = dir.join(name);
    if !path.exists() {
        return Err(format!(
            "{} is missing: run `bash encoder/data/fetch.sh` first",
            path.display()
        ));
    }
    let mesh = read_mesh(&path, &ReadOptions::default()).map_err(|e| e.to_string())?;
    if check_mesh(&mesh).is_ok() {
        return Ok(mesh);
    }
    let (repaired, _) = repair_mesh(&mesh);
    check_mesh(&repaired).map_err(|e| format!("{name} after repair: {e}"))?;
    Ok(repaired)
}

/// Panics unless the encoder accepts `mesh`.
pub fn checked(mesh: Mesh, what: &str) -> Mesh {
    if let Err(e) = check_mesh(&mesh) {
        panic!("generator mesh {what} is not encodable: {e}");
    }
    mesh
}

#[cfg(test)]
mod tests {
    #[test]
    fn portable_sine_matches_libm() {
        for i in -2000..2000 {
            let x = i as f64 * 0.01234;
            assert!((super::sin(x) - x.sin()).abs() < 1e-13, "{x}");
            assert!((super::cos(x) - x.cos()).abs() < 1e-13, "{x}");
        }
    }
}
