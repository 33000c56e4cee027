//! The vertical error: over every sample of the tile, the distance in z
//! between its reference height and the simplified surface above or below
//! it, absolute and relative to the sample's threshold T.

/// The rounding the check tolerates, relative to `1 + |h|`: plane
/// evaluation rounds to a few ulps of the heights (2^-52 each), and this
/// leaves a wide margin. The simplifier refuses a threshold that this
/// tolerance would take more than [`ROUNDING_SHARE`] of
/// ([`super::GridTileError::BelowPrecision`]), so a sample accepted ends
/// within T plus a thousandth of T.
pub const ROUNDING: f64 = 1e-12;

/// The share of a threshold that [`ROUNDING`] may take: a thousandth. A
/// millionth refused a first-person view (H = 1.7 m, so T = 2 mm) over
/// mountains 3 km high.
pub const ROUNDING_SHARE: f64 = 1e-3;

/// What [`check`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Check {
    /// Max over samples of |h - surface|.
    pub max_error: f64,
    /// Max over samples of |h - surface| / T(sample).
    pub max_ratio: f64,
}

/// A triangulated surface over the tile.
pub struct Surface<'a> {
    /// Vertices; `[2]` is the height.
    pub positions: &'a [[f64; 3]],
    /// Grid coordinates `(col, row)` of each vertex.
    pub grid: &'a [[f64; 2]],
    pub triangles: &'a [[u32; 3]],
}

/// Measures `surface` against `reference`, and pushes to `over` every
/// sample further than its `thresholds` entry from it (beyond rounding;
/// samples on shared edges are visited twice).
pub fn check(
    rows: usize,
    cols: usize,
    reference: &[f64],
    thresholds: &[f64],
    surface: Surface,
    over: &mut Vec<u32>,
) -> Check {
    let Surface {
        positions,
        grid,
        triangles,
    } = surface;
    let mut out = Check {
        max_error: 0.0,
        max_ratio: 0.0,
    };
    for &t in triangles {
        if exact_half_cell(cols, t, reference, positions, grid) {
            continue;
        }
        visit_triangle(rows, cols, t, positions, grid, |i, z| {
            let h = reference[i];
            let e = (h - z).abs();
            let t = thresholds[i];
            out.max_error = out.max_error.max(e);
            out.max_ratio = out.max_ratio.max(e / t);
            // Plane evaluation rounds: tolerate a few ulps of the heights.
            if e > t + ROUNDING * (1.0 + h.abs()) {
                over.push(i as u32);
            }
        });
    }
    out
}

/// Whether triangle `t` is half a grid cell (lattice vertices, area 1/2:
/// by Pick's theorem it holds no other sample) with its vertices at their
/// reference heights: then it is exact at every sample it holds. Most
/// triangles of a lightly simplified tile are; skipping them is most of
/// the check's speed.
fn exact_half_cell(
    cols: usize,
    t: [u32; 3],
    reference: &[f64],
    positions: &[[f64; 3]],
    grid: &[[f64; 2]],
) -> bool {
    let [a, b, c] = t.map(|v| grid[v as usize]);
    let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    area2.abs() == 1.0
        && t.iter().all(|&v| {
            let [x, y] = grid[v as usize];
            // Whole coordinates (centre vertices have halves); a cast
            // round trip is cheaper than `fract`, a libm call.
            let (xi, yi) = (x as usize, y as usize);
            xi as f64 == x
                && yi as f64 == y
                && positions[v as usize][2] == reference[yi * cols + xi]
        })
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
    let ymin = ceil_index(a[1].min(b[1]).min(c[1]) - EPS);
    let ymax = floor_index(a[1].max(b[1]).max(c[1]) + EPS).min(rows - 1);
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
        let xmin = ceil_index(lo - EPS);
        let xmax = floor_index(hi + EPS).min(cols - 1);
        for x in xmin..=xmax {
            f(y * cols + x, gx * x as f64 + gy * yf + z0);
        }
    }
}

/// `max(0, floor(v))` as an index. Casts truncate toward zero, which is
/// floor for `v >= 0`; `f64::floor` is a libm call on baseline x86-64,
/// and this runs for every row of every triangle.
#[inline]
fn floor_index(v: f64) -> usize {
    if v <= 0.0 { 0 } else { v as usize }
}

/// `max(0, ceil(v))` as an index (see [`floor_index`]).
#[inline]
fn ceil_index(v: f64) -> usize {
    if v <= 0.0 {
        return 0;
    }
    let t = v as usize;
    if (t as f64) < v { t + 1 } else { t }
}
