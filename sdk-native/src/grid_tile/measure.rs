//! The maximum vertical error: over every original sample, the distance in
//! z between its height and the simplified surface above or below it.

/// Max over samples of |h - surface|, the surface being `triangles` over
/// vertices at grid coordinates `grid` with heights `positions[..][2]`
/// (samples on shared edges are measured twice, harmlessly).
pub fn max_vertical_error(
    rows: usize,
    cols: usize,
    heights: &[f64],
    positions: &[[f64; 3]],
    grid: &[[f64; 2]],
    triangles: &[[u32; 3]],
) -> f64 {
    let mut worst: f64 = 0.0;
    for &t in triangles {
        visit_triangle(rows, cols, t, positions, grid, |i, z| {
            worst = worst.max((heights[i] - z).abs());
        });
    }
    worst
}

/// Calls `f(sample index, surface height)` for every sample of a `rows x
/// cols` tile inside (or on the edge of) triangle `t`, row by row over the
/// triangle's x-extent, evaluating its plane.
pub fn visit_triangle(
    rows: usize,
    cols: usize,
    t: [u32; 3],
    positions: &[[f64; 3]],
    grid: &[[f64; 2]],
    mut f: impl FnMut(usize, f64),
) {
    const EPS: f64 = 1e-7;
    let [a, b, c] = t.map(|v| grid[v as usize]);
    let [za, zb, zc] = t.map(|v| positions[v as usize][2]);
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if area.abs() < 1e-12 {
        return;
    }
    // Plane z = gx * x + gy * y + z0 through the three vertices.
    let inv = 1.0 / area;
    let gx = ((zb - za) * (c[1] - a[1]) - (zc - za) * (b[1] - a[1])) * inv;
    let gy = ((zc - za) * (b[0] - a[0]) - (zb - za) * (c[0] - a[0])) * inv;
    let z0 = za - gx * a[0] - gy * a[1];
    let ymin = (a[1].min(b[1]).min(c[1]) - EPS).ceil().max(0.0) as usize;
    let ymax = ((a[1].max(b[1]).max(c[1]) + EPS).floor().max(0.0) as usize).min(rows - 1);
    for y in ymin..=ymax {
        let yf = y as f64;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (p, q) in [(a, b), (b, c), (c, a)] {
            let (py, qy) = (p[1], q[1]);
            if (py - yf) * (qy - yf) > 0.0 {
                continue;
            }
            if py == qy {
                lo = lo.min(p[0].min(q[0]));
                hi = hi.max(p[0].max(q[0]));
            } else {
                let x = p[0] + (q[0] - p[0]) * (yf - py) / (qy - py);
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
        if lo > hi {
            continue;
        }
        let xmin = (lo - EPS).ceil().max(0.0) as usize;
        let xmax = ((hi + EPS).floor().max(0.0) as usize).min(cols - 1);
        for x in xmin..=xmax {
            f(y * cols + x, gx * x as f64 + gy * yf + z0);
        }
    }
}
