//! Garland–Heckbert quadric error metric: the 10 coefficients of a symmetric
//! 4x4 matrix, shared by the parallel simplifier and the sequential baseline.

use core::ops::{Add, AddAssign};

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

    /// Error of point `p`.
    pub fn error(&self, p: [f64; 3]) -> f64 {
        let [a2, ab, ac, ad, b2, bc, bd, c2, cd, d2] = self.c;
        let [x, y, z] = p;
        let e = a2 * x * x
            + 2.0 * ab * x * y
            + 2.0 * ac * x * z
            + 2.0 * ad * x
            + b2 * y * y
            + 2.0 * bc * y * z
            + 2.0 * bd * y
            + c2 * z * z
            + 2.0 * cd * z
            + d2;
        e.max(0.0)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_error_is_squared_distance() {
        let q = Quadric::from_plane([0.0, 0.0, 1.0], -2.0, 1.0);
        assert!((q.error([5.0, -3.0, 5.0]) - 9.0).abs() < 1e-12);
        assert_eq!(q.minimizer(), None, "one plane is singular");
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
}
