//! The edge linearity error e(B) and the surface a rectangle stands for.

/// e(B): how far the middle height `hb` is from the straight line joining
/// `(ta, ha)` and `(tc, hc)`, where `ta < tb < tc` are positions along one
/// grid line (x for a horizontal edge, y for a vertical one). Zero means
/// A, B, C are collinear and B can go at no cost.
///
/// (The paper's printed formula for vertical edges has `y(C) - y(A)` where
/// `y(B) - y(A)` is meant; this uses the intended form for both.)
#[inline]
pub fn linearity_error(ta: f64, ha: f64, tb: f64, hb: f64, tc: f64, hc: f64) -> f64 {
    ((hc - ha) / (tc - ta) * (tb - ta) + ha - hb).abs()
}

/// Height at local coordinates `(u, v)` in `[0, 1]^2` of the two triangles
/// a rectangle is drawn as when its sides carry no other vertex: split along
/// the diagonal from corner `h00` (low x, low y) to `h11` (high x, high y).
#[inline]
pub fn rectangle_surface(h00: f64, h10: f64, h01: f64, h11: f64, u: f64, v: f64) -> f64 {
    if u >= v {
        h00 + u * (h10 - h00) + v * (h11 - h10)
    } else {
        h00 + v * (h01 - h00) + u * (h11 - h01)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collinear_is_zero() {
        assert_eq!(linearity_error(0.0, 1.0, 1.0, 2.0, 2.0, 3.0), 0.0);
        assert_eq!(linearity_error(0.0, 0.0, 1.0, 1.0, 2.0, 0.0), 1.0);
    }

    #[test]
    fn surface_hits_corners() {
        let s = |u, v| rectangle_surface(1.0, 2.0, 3.0, 5.0, u, v);
        assert_eq!(s(0.0, 0.0), 1.0);
        assert_eq!(s(1.0, 0.0), 2.0);
        assert_eq!(s(0.0, 1.0), 3.0);
        assert_eq!(s(1.0, 1.0), 5.0);
    }
}
