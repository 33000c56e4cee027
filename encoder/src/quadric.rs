//! Garland–Heckbert quadric error metric: the 10 coefficients of a symmetric
//! 4x4 matrix, shared by the parallel simplifier and the sequential baseline.

use core::ops::{Add, AddAssign};

/// Errors at most this fraction of `a²x² + b²y² + c²z² + d²` are rounding
/// noise and count as 0. A plane quadric is positive semidefinite, so each
/// of [`Quadric::error`]'s ten terms is at most that sum (Cauchy–Schwarz:
/// `|2ab·xy| ≤ a²x² + b²y²`), and the error of a point on every plane,
/// truly 0, comes out as up to some 3e-14 of it (measured on tilted planes
/// of 800 triangles, the test below; rounding grows with the planes
/// merged into a quadric, hence the margin). There the noise ranked the flat
/// collapses by chance instead of by the sub-grid tie-break, and it sat
/// around the flat threshold: a 300 × 300 ramp took 186 rounds and 8.76
/// bits per vertex instead of 77 and 8.18 (encoder/BENCHMARKS.md, "Flat
/// and tilted rasters"). A real deviation is far above: one step of 14-bit
/// quantization over the extent is about 4e-9 of the sum.
pub const NUMERIC_ZERO: f64 = 1e-12;

/// A symmetric quadric `Q` such that the error of a point `p` is
/// `[p 1] Q [p 1]^T`, stored as its upper triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quadric {
    /// a² ab ac ad b² bc bd c² cd d², the paper's a…k.
    pub c: [f64; 10],
}

impl Quadric {
    pub const ZERO: Quadric = Quadric { c: [0.0; 10] };

    /// The quadric of the plane `n·p + d = 0` (n unit), scaled by `weight`.
    pub fn from_plane(n: [f64; 3], d: f64, weight: f64) -> Quadric {
        let [a, b, c] = n;
        let w = weight;
        Quadric {
            c: [
                w * a * a,
                w * a * b,
                w * a * c,
                w * a * d,
                w * b * b,
                w * b * c,
                w * b * d,
                w * c * c,
                w * c * d,
                w * d * d,
            ],
        }
    }

    /// The area-weighted plane quadric of triangle `(p0, p1, p2)`; zero for a
    /// degenerate triangle.
    pub fn from_triangle(p0: [f64; 3], p1: [f64; 3], p2: [f64; 3]) -> Quadric {
        let n = cross(sub(p1, p0), sub(p2, p0));
        let len = norm(n);
        if len == 0.0 || !len.is_finite() {
            return Quadric::ZERO;
        }
        let unit = [n[0] / len, n[1] / len, n[2] / len];
        let d = -dot(unit, p0);
        // len is twice the area.
        Quadric::from_plane(unit, d, 0.5 * len)
    }

    /// Error of point `p`; exactly 0 where it is within the rounding noise
    /// of its own terms ([`NUMERIC_ZERO`]).
    pub fn error(&self, p: [f64; 3]) -> f64 {
        let [a2, ab, ac, ad, b2, bc, bd, c2, cd, d2] = self.c;
        let [x, y, z] = p;
        let (xx, yy, zz) = (a2 * x * x, b2 * y * y, c2 * z * z);
        let e = xx
            + 2.0 * ab * x * y
            + 2.0 * ac * x * z
            + 2.0 * ad * x
            + yy
            + 2.0 * bc * y * z
            + 2.0 * bd * y
            + zz
            + 2.0 * cd * z
            + d2;
        // Below 0 is rounding too, and NaN (terms that overflowed) stays 0
        // as `max(0.0)` made it before; an infinite error stays infinite.
        if e > NUMERIC_ZERO * (xx + yy + zz + d2) || e == f64::INFINITY {
            e
        } else {
            0.0
        }
    }

    /// [`Self::error`] of two points, `[error(p), error(q)]` bit for bit:
    /// the same operations in the same order, in the two lanes of SSE2
    /// registers on x86-64 (about a third of constrained mode's edge
    /// evaluation, the simplifier's largest cost, was its three scalar
    /// errors).
    #[inline]
    pub fn error_pair(&self, p: [f64; 3], q: [f64; 3]) -> [f64; 2] {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: SSE2 is part of the x86-64 baseline: every x86-64
            // CPU runs `error_pair_sse2`.
            unsafe { self.error_pair_sse2(p, q) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            [self.error(p), self.error(q)]
        }
    }

    /// [`Self::error_pair`] in SSE2 lanes: lane 0 is `p`, lane 1 is `q`,
    /// and each lane does what [`Self::error`] does (no fused operations:
    /// every product and sum rounds as there).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse2")]
    fn error_pair_sse2(&self, p: [f64; 3], q: [f64; 3]) -> [f64; 2] {
        use std::arch::x86_64::*;
        let [a2, ab, ac, ad, b2, bc, bd, c2, cd, d2] = self.c;
        // _mm_set_pd takes the high lane first.
        let (x, y, z) = (
            _mm_set_pd(q[0], p[0]),
            _mm_set_pd(q[1], p[1]),
            _mm_set_pd(q[2], p[2]),
        );
        let k = _mm_set1_pd;
        let mul = _mm_mul_pd;
        let add = _mm_add_pd;
        let xx = mul(mul(k(a2), x), x);
        let yy = mul(mul(k(b2), y), y);
        let zz = mul(mul(k(c2), z), z);
        let mut e = add(xx, mul(mul(k(2.0 * ab), x), y));
        e = add(e, mul(mul(k(2.0 * ac), x), z));
        e = add(e, mul(k(2.0 * ad), x));
        e = add(e, yy);
        e = add(e, mul(mul(k(2.0 * bc), y), z));
        e = add(e, mul(k(2.0 * bd), y));
        e = add(e, zz);
        e = add(e, mul(k(2.0 * cd), z));
        e = add(e, k(d2));
        let floor = mul(k(NUMERIC_ZERO), add(add(add(xx, yy), zz), k(d2)));
        // Kept where above the noise or infinite, else +0.0 (NaN too).
        let kept = _mm_or_pd(_mm_cmpgt_pd(e, floor), _mm_cmpeq_pd(e, k(f64::INFINITY)));
        let e = _mm_and_pd(kept, e);
        [_mm_cvtsd_f64(e), _mm_cvtsd_f64(_mm_unpackhi_pd(e, e))]
    }

    /// The point minimising the error, or `None` when the 3x3 system is
    /// (nearly) singular, e.g. on a flat region or a straight crease.
    pub fn minimizer(&self) -> Option<[f64; 3]> {
        let [a2, ab, ac, ad, b2, bc, bd, c2, cd, _] = self.c;
        let m = [[a2, ab, ac], [ab, b2, bc], [ac, bc, c2]];
        let rhs = [-ad, -bd, -cd];
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        let scale = a2.abs().max(b2.abs()).max(c2.abs());
        if !det.is_finite() || scale == 0.0 || det.abs() <= 1e-10 * scale * scale * scale {
            return None;
        }
        let inv = 1.0 / det;
        let x = (rhs[0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (rhs[1] * m[2][2] - m[1][2] * rhs[2])
            + m[0][2] * (rhs[1] * m[2][1] - m[1][1] * rhs[2]))
            * inv;
        let y = (m[0][0] * (rhs[1] * m[2][2] - m[1][2] * rhs[2])
            - rhs[0] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * rhs[2] - rhs[1] * m[2][0]))
            * inv;
        let z = (m[0][0] * (m[1][1] * rhs[2] - rhs[1] * m[2][1])
            - m[0][1] * (m[1][0] * rhs[2] - rhs[1] * m[2][0])
            + rhs[0] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
            * inv;
        let p = [x, y, z];
        p.iter().all(|v| v.is_finite()).then_some(p)
    }
}

impl Add for Quadric {
    type Output = Quadric;
    fn add(mut self, rhs: Quadric) -> Quadric {
        self += rhs;
        self
    }
}

impl AddAssign for Quadric {
    fn add_assign(&mut self, rhs: Quadric) {
        for (a, b) in self.c.iter_mut().zip(rhs.c) {
            *a += b;
        }
    }
}

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Default weight of the boundary penalty planes in [`vertex_quadrics`].
///
/// A face quadric is weighted by its area (about `|e|²/2` for a triangle with
/// edges of length `|e|`), a boundary plane by `weight * |e|²`, so with 1000
/// sliding a border vertex off its border costs as much as tilting about two
/// thousand neighbouring faces by the same distance: far more than any
/// interior collapse of a terrain, so tile borders and map edges stay put,
/// yet small enough that the summed quadrics stay well conditioned in f64
/// (the face terms are still ~1e-3 of the boundary terms, well above the
/// ~1e-16 rounding) and collapses *along* a straight border remain free.
pub const DEFAULT_BOUNDARY_WEIGHT: f64 = 1000.0;

/// Per-vertex quadrics of a mesh: the sum of the area-weighted plane quadrics
/// of the vertex's triangles, plus, for every boundary edge (an undirected
/// edge used by exactly one triangle), a penalty plane through the edge and
/// perpendicular to its triangle, weighted by `boundary_weight * |edge|²` and
/// added to both endpoints.
///
/// Both the parallel simplifier and the sequential baseline start from this
/// function so that their errors are directly comparable. Triangles with an
/// out-of-range index are skipped (the input checker reports them); the sum
/// is taken in triangle order, so the result is deterministic.
pub fn vertex_quadrics(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    boundary_weight: f64,
) -> Vec<Quadric> {
    use rayon::prelude::*;

    let n = positions.len();
    let valid = |t: &[u32; 3]| t.iter().all(|&v| (v as usize) < n);
    let face: Vec<Quadric> = triangles
        .par_iter()
        .map(|t| {
            if valid(t) {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                Quadric::from_triangle(a, b, c)
            } else {
                Quadric::ZERO
            }
        })
        .collect();
    let mut quadrics = vec![Quadric::ZERO; n];
    for (t, q) in triangles.iter().zip(&face) {
        if valid(t) {
            for &v in t {
                quadrics[v as usize] += *q;
            }
        }
    }
    if boundary_weight == 0.0 {
        return quadrics;
    }

    // Each triangle edge (3 * triangle + edge slot) grouped by undirected
    // edge in key order; an edge used once is a boundary edge.
    let ends = |e: u32| {
        let t = &triangles[e as usize / 3];
        let k = e as usize % 3;
        valid(t).then(|| (t[k], t[(k + 1) % 3]))
    };
    let edges = crate::corner_table::by_undirected_edge(n, 3 * triangles.len(), ends);
    for run in edges.chunk_by(|x, y| x.0 == y.0) {
        if let [(_, corner)] = *run {
            let corner = corner as usize;
            let t = triangles[corner / 3];
            let k = corner % 3;
            let (u, v, w) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let [pu, pv, pw] = [u, v, w].map(|x| positions[x as usize]);
            let q = boundary_quadric(pu, pv, pw, boundary_weight);
            quadrics[u as usize] += q;
            quadrics[v as usize] += q;
        }
    }
    quadrics
}

/// Penalty quadric of boundary edge `(p, q)` of triangle `(p, q, r)`: the
/// plane containing the edge and the triangle's normal.
pub(crate) fn boundary_quadric(p: [f64; 3], q: [f64; 3], r: [f64; 3], weight: f64) -> Quadric {
    let e = sub(q, p);
    let n = cross(e, sub(r, p));
    let m = cross(e, n);
    let len = norm(m);
    if len == 0.0 || !len.is_finite() {
        return Quadric::ZERO;
    }
    let unit = [m[0] / len, m[1] / len, m[2] / len];
    Quadric::from_plane(unit, -dot(unit, p), weight * dot(e, e))
}

/// Where an edge `(a, b)` with summed quadric `q` collapses to, and the
/// error there.
///
/// Unconstrained: the quadric's minimizer when it exists and lies within
/// twice the edge length of the midpoint (further away means the system is
/// ill-conditioned, e.g. a nearly flat region, and the "optimum" is a spike);
/// otherwise, and always when `constrained`, the best of `a`, `b` and the
/// midpoint, preferring them in that order on ties so that flat regions keep
/// existing vertex positions. Shared by both simplifiers so they place
/// vertices identically.
pub fn collapse_target(
    q: &Quadric,
    a: [f64; 3],
    b: [f64; 3],
    constrained: bool,
) -> ([f64; 3], f64) {
    let mid = [
        0.5 * (a[0] + b[0]),
        0.5 * (a[1] + b[1]),
        0.5 * (a[2] + b[2]),
    ];
    let mut best = (a, q.error(a));
    for p in [b, mid] {
        let e = q.error(p);
        if e < best.1 {
            best = (p, e);
        }
    }
    if !constrained && let Some(m) = q.minimizer() {
        let reach = 2.0 * norm(sub(b, a));
        let e = q.error(m);
        // The minimizer can only lose to a candidate through rounding.
        if norm(sub(m, mid)) <= reach && e < best.1 {
            best = (m, e);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `error_pair` is `error` twice, bit for bit, on quadrics of random
    /// planes and sums of them, at points on and off them, huge, tiny,
    /// infinite and NaN.
    #[test]
    fn error_pair_is_error_twice() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut rand = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let specials = [
            0.0,
            -0.0,
            1e300,
            -1e300,
            1e-300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let mut checked = 0;
        for round in 0..2000 {
            let mut q = Quadric::ZERO;
            for _ in 0..1 + round % 5 {
                let n = [rand(), rand(), rand()];
                let len = norm(n);
                if len == 0.0 {
                    continue;
                }
                let n = n.map(|v| v / len);
                q += Quadric::from_plane(n, 1000.0 * rand(), 1.0 + 100.0 * rand().abs());
            }
            let scale = 10f64.powi((round % 9) as i32);
            let mut point = || [rand() * scale, rand() * scale, rand() * scale];
            let (mut p, mut r) = (point(), point());
            if round % 7 == 0 {
                p[round % 3] = specials[round % specials.len()];
            }
            if round % 11 == 0 {
                // On a plane through p: the noise floor decides.
                r = p;
            }
            let [ep, er] = q.error_pair(p, r);
            assert_eq!(ep.to_bits(), q.error(p).to_bits(), "{q:?} at {p:?}");
            assert_eq!(er.to_bits(), q.error(r).to_bits(), "{q:?} at {r:?}");
            checked += 1;
        }
        assert!(checked > 1000);
    }

    #[test]
    fn plane_error_is_squared_distance() {
        let q = Quadric::from_plane([0.0, 0.0, 1.0], -2.0, 1.0);
        assert!((q.error([5.0, -3.0, 5.0]) - 9.0).abs() < 1e-12);
        assert_eq!(q.minimizer(), None, "one plane is singular");
    }

    /// The triangles of a tilted plane far from the origin, merged as a
    /// vertex's quadric: a point on the plane has no error at all (its
    /// evaluation is rounding noise), a point a step off it has its
    /// squared distance.
    #[test]
    fn a_tilted_plane_has_no_error_on_it() {
        let z = |x: f64, y: f64| 1.5 * x - 2.25 * y + 333.0;
        let mut q = Quadric::ZERO;
        for i in 0..20 {
            for j in 0..20 {
                let (x, y) = (123.0 + i as f64, 77.0 + j as f64);
                let p = |dx: f64, dy: f64| [x + dx, y + dy, z(x + dx, y + dy)];
                q += Quadric::from_triangle(p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0));
                q += Quadric::from_triangle(p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0));
            }
        }
        let mut noisy = 0;
        for i in 0..=20 {
            for j in 0..=20 {
                let (x, y) = (123.0 + i as f64 + 0.5, 77.0 + j as f64 + 0.25);
                assert_eq!(q.error([x, y, z(x, y)]), 0.0, "({x}, {y})");
                // Without the noise floor these are not 0.
                let [a2, ab, ac, ad, b2, bc, bd, c2, cd, d2] = q.c;
                let p = [x, y, z(x, y)];
                let raw = a2 * p[0] * p[0]
                    + 2.0 * ab * p[0] * p[1]
                    + 2.0 * ac * p[0] * p[2]
                    + 2.0 * ad * p[0]
                    + b2 * p[1] * p[1]
                    + 2.0 * bc * p[1] * p[2]
                    + 2.0 * bd * p[1]
                    + c2 * p[2] * p[2]
                    + 2.0 * cd * p[2]
                    + d2;
                noisy += usize::from(raw > 0.0);
                // A hundredth off the plane along z (about one step of
                // 14-bit quantization over this extent): the distance is
                // 0.01 / |n|, n = (1.5, -2.25, -1), times the 800
                // triangles' area, 400 |n|.
                let off = q.error([x, y, z(x, y) + 0.01]);
                let n2: f64 = 1.5 * 1.5 + 2.25 * 2.25 + 1.0;
                let want = 400.0 * 1e-4 / n2.sqrt();
                assert!((off - want).abs() < 1e-4 * want, "{off} against {want}");
            }
        }
        assert!(noisy > 100, "the plane is noisy enough to test: {noisy}");
    }

    #[test]
    fn three_planes_meet_in_a_point() {
        let q = Quadric::from_plane([1.0, 0.0, 0.0], -1.0, 1.0)
            + Quadric::from_plane([0.0, 1.0, 0.0], -2.0, 1.0)
            + Quadric::from_plane([0.0, 0.0, 1.0], -3.0, 1.0);
        let p = q.minimizer().unwrap();
        for (got, want) in p.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-9);
        }
        assert!(q.error(p) < 1e-12);
    }

    /// A unit square in z = 0 split into two CCW triangles.
    fn square() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        (p, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn vertex_quadrics_without_boundary_are_face_sums() {
        let (p, t) = square();
        let q = vertex_quadrics(&p, &t, 0.0);
        // Vertex 0 sees both triangles: plane z = 0 with total area 1.
        assert!((q[0].error([0.3, 0.7, 2.0]) - 4.0).abs() < 1e-12);
        assert!((q[1].error([0.3, 0.7, 2.0]) - 2.0).abs() < 1e-12);
        // Sliding within the plane is free.
        assert!(q[0].error([5.0, -3.0, 0.0]) < 1e-12);
    }

    #[test]
    fn boundary_planes_pin_border_vertices() {
        let (p, t) = square();
        let q = vertex_quadrics(&p, &t, 10.0);
        // Vertex 1 lies on border edges y = 0 (0-1) and x = 1 (1-2), each of
        // length 1: moving it off both by 0.5 costs 10 * (0.25 + 0.25).
        assert!((q[1].error([1.5, -0.5, 0.0]) - 5.0).abs() < 1e-9);
        // Along its border edge y = 0 only the x = 1 plane costs.
        assert!((q[1].error([0.5, 0.0, 0.0]) - 2.5).abs() < 1e-9);
        // The shared diagonal 0-2 is interior: no penalty for crossing it.
        let free = vertex_quadrics(&p, &t, 0.0);
        assert!((q[0].error([0.0, 0.0, 0.0]) - free[0].error([0.0, 0.0, 0.0])).abs() < 1e-12);
        // Vertex 0 is a corner on borders x = 0 and y = 0, both length 1.
        assert!((q[0].error([-1.0, -1.0, 0.0]) - 20.0).abs() < 1e-9);
    }

    #[test]
    fn boundary_planes_are_perpendicular_to_their_triangle() {
        let (p, t) = square();
        let q = vertex_quadrics(&p, &t, 1.0);
        let face = vertex_quadrics(&p, &t, 0.0);
        // Lifting vertex 1 out of the plane is charged by the faces only.
        let lift = [1.0, 0.0, 3.0];
        assert!((q[1].error(lift) - face[1].error(lift)).abs() < 1e-9);
    }

    #[test]
    fn out_of_range_triangles_are_skipped() {
        let (p, mut t) = square();
        t.push([0, 1, 9]);
        let q = vertex_quadrics(&p, &t, 1.0);
        assert_eq!(q.len(), 4);
    }

    #[test]
    fn collapse_target_uses_a_nearby_minimizer() {
        let q = Quadric::from_plane([1.0, 0.0, 0.0], -1.0, 1.0)
            + Quadric::from_plane([0.0, 1.0, 0.0], -1.0, 1.0)
            + Quadric::from_plane([0.0, 0.0, 1.0], -1.0, 1.0);
        let (p, e) = collapse_target(&q, [0.0, 1.0, 1.0], [2.0, 1.0, 1.0], false);
        assert!(norm(sub(p, [1.0, 1.0, 1.0])) < 1e-9);
        assert!(e < 1e-12);
        // Constrained: the midpoint is the best of {a, b, mid}.
        let (p, e) = collapse_target(&q, [0.0, 1.0, 1.0], [2.0, 1.0, 1.0], true);
        assert_eq!(p, [1.0, 1.0, 1.0]);
        assert!(e < 1e-12);
        let (p, e) = collapse_target(&q, [0.0, 1.0, 1.0], [1.5, 1.0, 1.0], true);
        assert_eq!(p, [0.75, 1.0, 1.0]);
        assert!((e - 0.0625).abs() < 1e-12);
    }

    #[test]
    fn collapse_target_rejects_a_far_minimizer() {
        // Minimizer at (10, 10, 10), far from the short edge near the origin.
        let q = Quadric::from_plane([1.0, 0.0, 0.0], -10.0, 1.0)
            + Quadric::from_plane([0.0, 1.0, 0.0], -10.0, 1.0)
            + Quadric::from_plane([0.0, 0.0, 1.0], -10.0, 1.0);
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 1.0, 1.0];
        let (p, e) = collapse_target(&q, a, b, false);
        assert_eq!(p, b);
        assert!((e - 3.0 * 81.0).abs() < 1e-9);
    }

    #[test]
    fn collapse_target_prefers_endpoints_on_ties() {
        // Flat: the minimizer is singular and every candidate costs 0.
        let q = Quadric::from_plane([0.0, 0.0, 1.0], 0.0, 1.0);
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        assert_eq!(collapse_target(&q, a, b, false), (a, 0.0));
        assert_eq!(collapse_target(&q, a, b, true), (a, 0.0));
        // b wins when a costs more.
        let q = Quadric::from_plane([1.0, 0.0, 0.0], -1.0, 1.0);
        assert_eq!(collapse_target(&q, a, b, false), (b, 0.0));
    }
}
