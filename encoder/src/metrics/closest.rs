//! Exact closest point on a triangle (Ericson, "Real-Time Collision
//! Detection", 5.1.5): classify the point into one of the seven Voronoi
//! regions (three vertices, three edges, the face) with barycentric tests.

use crate::quadric::{dot, sub};

fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}

/// Closest point to `p` on segment `ab`.
fn closest_on_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    if len2 <= 0.0 {
        return a;
    }
    lerp(a, b, (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0))
}

/// The point of triangle `[a, b, c]` closest to `p`. Degenerate triangles
/// (collinear or coincident corners) fall back to their edges.
pub fn closest_point(p: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> [f64; 3] {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return lerp(a, b, d1 / (d1 - d3));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return lerp(a, c, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return lerp(b, c, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let sum = va + vb + vc;
    if sum <= 0.0 || !sum.is_finite() {
        return degenerate(p, [a, b, c]);
    }
    let (v, w) = (vb / sum, vc / sum);
    [
        a[0] + ab[0] * v + ac[0] * w,
        a[1] + ab[1] * v + ac[1] * w,
        a[2] + ab[2] * v + ac[2] * w,
    ]
}

fn degenerate(p: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> [f64; 3] {
    [(a, b), (b, c), (c, a)]
        .map(|(s, t)| closest_on_segment(p, s, t))
        .into_iter()
        .min_by(|x, y| dist2(p, *x).total_cmp(&dist2(p, *y)))
        .unwrap_or(a)
}

pub fn dist2(p: [f64; 3], q: [f64; 3]) -> f64 {
    let d = sub(p, q);
    dot(d, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    fn check(p: [f64; 3], want: [f64; 3]) {
        let got = closest_point(p, T);
        assert!(
            dist2(got, want) < 1e-24,
            "{p:?}: got {got:?}, want {want:?}"
        );
        // Every corner order gives the same point.
        for tri in [[T[1], T[2], T[0]], [T[2], T[0], T[1]], [T[0], T[2], T[1]]] {
            assert!(dist2(closest_point(p, tri), want) < 1e-24);
        }
    }

    #[test]
    fn vertex_regions() {
        check([-1.0, -1.0, 1.0], T[0]);
        check([2.0, -1.0, 0.0], T[1]);
        check([3.0, 0.5, -2.0], T[1]);
        check([-1.0, 2.0, 0.0], T[2]);
    }

    #[test]
    fn edge_regions() {
        check([0.5, -1.0, 0.0], [0.5, 0.0, 0.0]);
        check([-1.0, 0.5, 2.0], [0.0, 0.5, 0.0]);
        check([1.0, 1.0, 3.0], [0.5, 0.5, 0.0]);
    }

    #[test]
    fn face_region() {
        check([0.2, 0.2, 5.0], [0.2, 0.2, 0.0]);
        check([0.25, 0.5, -1.0], [0.25, 0.5, 0.0]);
    }

    #[test]
    fn degenerate_triangles_use_their_edges() {
        let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let got = closest_point([1.5, 1.0, 0.0], line);
        assert!(dist2(got, [1.5, 0.0, 0.0]) < 1e-24);
        let point = [[1.0, 1.0, 1.0]; 3];
        assert_eq!(closest_point([0.0; 3], point), [1.0, 1.0, 1.0]);
    }
}
