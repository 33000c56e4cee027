//! Ear clipping of the small simple polygons left where border vertices
//! are removed ([`super::triangulate`]).

/// Triangulates the counter-clockwise simple polygon `ids` (with grid
/// coordinates `at(id)`), appending triangles to `out`; at each step it
/// clips the valid ear of least `cost`. `work` is scratch. Returns the
/// largest cost of the triangles made, or `None`, with `out` restored, when
/// it finds no ear (only possible with runs of collinear vertices).
pub fn ear_clip(
    ids: &[u32],
    at: impl Fn(u32) -> [f64; 2],
    cost: impl Fn([u32; 3]) -> f64,
    work: &mut Vec<u32>,
    out: &mut Vec<[u32; 3]>,
) -> Option<f64> {
    const EPS: f64 = 1e-12;
    let start = out.len();
    work.clear();
    work.extend_from_slice(ids);
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
    };
    let mut worst: f64 = 0.0;
    while work.len() > 3 {
        let n = work.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..n {
            let (ip, iq) = ((i + n - 1) % n, (i + 1) % n);
            let (a, b, c) = (at(work[ip]), at(work[i]), at(work[iq]));
            if cross(a, b, c) <= EPS {
                continue;
            }
            let blocked = work.iter().enumerate().any(|(j, &v)| {
                if j == ip || j == i || j == iq {
                    return false;
                }
                let p = at(v);
                cross(a, b, p) >= -EPS && cross(b, c, p) >= -EPS && cross(c, a, p) >= -EPS
            });
            if blocked {
                continue;
            }
            let c = cost([work[ip], work[i], work[iq]]);
            if best.is_none_or(|(b, _)| c < b) {
                best = Some((c, i));
            }
        }
        let Some((c, i)) = best else {
            out.truncate(start);
            return None;
        };
        let n = work.len();
        out.push([work[(i + n - 1) % n], work[i], work[(i + 1) % n]]);
        work.remove(i);
        worst = worst.max(c);
    }
    let (a, b, c) = (at(work[0]), at(work[1]), at(work[2]));
    if cross(a, b, c) <= EPS {
        out.truncate(start);
        return None;
    }
    let t = [work[0], work[1], work[2]];
    out.push(t);
    Some(worst.max(cost(t)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn l_shape_with_collinear_points() {
        // (0,0) (1,0) (2,0) (2,1) (1,1) (1,2) (0,2) (0,1)
        let pts = [
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
            [0.0, 1.0],
        ];
        let ids: Vec<u32> = (0..8).collect();
        let mut out = Vec::new();
        assert!(
            ear_clip(
                &ids,
                |i| pts[i as usize],
                |_| 0.0,
                &mut Vec::new(),
                &mut out
            )
            .is_some()
        );
        assert_eq!(out.len(), 6);
        let area: f64 = out
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| pts[v as usize]);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
            })
            .sum();
        assert!((area - 3.0).abs() < 1e-12);
    }
}
