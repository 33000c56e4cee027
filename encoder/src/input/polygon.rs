//! Polygons of four or more corners, as the PLY, OFF and OBJ readers meet
//! them: fanned from their first corner while the file is read (the
//! positions may come later), then, once every position is known, a
//! polygon that is not convex in its own plane is cut again by ear
//! clipping. A fan of an L-shaped hexagon (an audit's file, 2026-12-08)
//! had a triangle turned over and lying outside the polygon, folding the
//! surface without any error; a convex polygon keeps its fan, so the
//! meshes (and streams) of convex quads are unchanged.

use crate::Mesh;

/// Polygons larger than this keep their fan even when concave: ear
/// clipping tests every corner against every candidate ear, O(n³) at worst.
const MAX_CLIPPED_CORNERS: usize = 256;

/// The fanned polygons of one file: `(first triangle, corner count)`, in
/// the order they were read, and the corners of the one being read.
#[derive(Default)]
pub(crate) struct Polygons {
    pub(crate) corners: Vec<u32>,
    fanned: Vec<(usize, usize)>,
}

impl Polygons {
    /// Appends the fan (c0, ci, ci+1) of `self.corners` to `triangles`,
    /// which keeps the polygon's winding, and notes a polygon of four or
    /// more corners for [`Self::untangle`].
    pub(crate) fn fan_into(&mut self, triangles: &mut Vec<[u32; 3]>) {
        let c = &self.corners;
        if c.len() > 3 {
            self.fanned.push((triangles.len(), c.len()));
        }
        for k in 1..c.len().saturating_sub(1) {
            triangles.push([c[0], c[k], c[k + 1]]);
        }
    }

    /// Notes a polygon of `n` corners fanned by the caller into the
    /// triangles from `first` on (the OBJ reader, which fans corners it
    /// resolves only at the end of the file).
    pub(crate) fn note(&mut self, first: usize, n: usize) {
        if n > 3 {
            self.fanned.push((first, n));
        }
    }

    /// Cuts again, by ear clipping, every noted polygon that is not convex
    /// in its plane; its triangles keep their places in `mesh.triangles`.
    /// Polygons with corners out of range or not finite are left to the
    /// input check.
    pub(crate) fn untangle(&self, mesh: &mut Mesh) {
        let mut corners = Vec::new();
        for &(first, n) in &self.fanned {
            let Some(fan) = mesh.triangles.get(first..first + n - 2) else {
                continue;
            };
            corners.clear();
            corners.extend([fan[0][0], fan[0][1]]);
            corners.extend(fan.iter().map(|t| t[2]));
            if n > MAX_CLIPPED_CORNERS {
                continue;
            }
            let Some(points) = plane_points(&corners, &mesh.positions) else {
                continue;
            };
            if is_convex(&points) {
                continue;
            }
            if let Some(ears) = ear_clip(&points) {
                for (slot, [a, b, c]) in mesh.triangles[first..first + n - 2].iter_mut().zip(ears) {
                    *slot = [corners[a], corners[b], corners[c]];
                }
            }
        }
    }
}

/// The corners projected on the coordinate plane most nearly parallel to
/// the polygon (Newell's normal), turned so that the polygon runs
/// counter-clockwise; `None` for a polygon without area or with a corner
/// that is missing or not finite.
fn plane_points(corners: &[u32], positions: &[[f64; 3]]) -> Option<Vec<[f64; 2]>> {
    let mut p = Vec::with_capacity(corners.len());
    for &c in corners {
        let q = *positions.get(c as usize)?;
        if !q.iter().all(|x| x.is_finite()) {
            return None;
        }
        p.push(q);
    }
    let mut normal = [0.0f64; 3];
    for (i, a) in p.iter().enumerate() {
        let b = p[(i + 1) % p.len()];
        normal[0] += (a[1] - b[1]) * (a[2] + b[2]);
        normal[1] += (a[2] - b[2]) * (a[0] + b[0]);
        normal[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    let axis = (0..3).max_by(|&i, &j| normal[i].abs().total_cmp(&normal[j].abs()))?;
    if normal[axis] == 0.0 || !normal[axis].is_finite() {
        return None;
    }
    // Dropping `axis` keeps the cyclic order (x, y, z): the polygon's turn
    // in that plane has the sign of the normal's component.
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let turn = normal[axis].signum();
    Some(p.iter().map(|q| [q[u], turn * q[v]]).collect())
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// No corner turns clockwise (collinear corners allowed).
fn is_convex(p: &[[f64; 2]]) -> bool {
    let n = p.len();
    (0..n).all(|i| cross(p[(i + n - 1) % n], p[i], p[(i + 1) % n]) >= 0.0)
}

/// Triangles of a counter-clockwise simple polygon, as corner positions in
/// the polygon's order (so each keeps its winding), cut one ear at a time;
/// `None` where no ear is found (a self-crossing polygon), and the caller
/// keeps the fan.
fn ear_clip(p: &[[f64; 2]]) -> Option<Vec<[usize; 3]>> {
    let mut left: Vec<usize> = (0..p.len()).collect();
    let mut ears = Vec::with_capacity(p.len() - 2);
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (left[(i + m - 1) % m], left[i], left[(i + 1) % m]);
            cross(p[a], p[b], p[c]) > 0.0
                && !left.iter().any(|&j| {
                    j != a
                        && j != b
                        && j != c
                        && cross(p[a], p[b], p[j]) >= 0.0
                        && cross(p[b], p[c], p[j]) >= 0.0
                        && cross(p[c], p[a], p[j]) >= 0.0
                })
        })?;
        ears.push([left[(ear + m - 1) % m], left[ear], left[(ear + 1) % m]]);
        left.remove(ear);
    }
    ears.push([left[0], left[1], left[2]]);
    Some(ears)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(t: [u32; 3], pos: &[[f64; 3]]) -> f64 {
        let [a, b, c] = t.map(|v| pos[v as usize]);
        cross([a[0], a[1]], [b[0], b[1]], [c[0], c[1]]) / 2.0
    }

    /// The audit's L-shaped hexagon: its fan from corner 0 turned a
    /// triangle over; the cut keeps every triangle counter-clockwise and
    /// the area whole.
    #[test]
    fn a_concave_hexagon_is_cut_into_upright_triangles() {
        let positions = vec![
            [2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
        ];
        let mut polygons = Polygons {
            corners: vec![0, 1, 2, 3, 4, 5],
            ..Polygons::default()
        };
        let mut triangles = vec![[9, 9, 9]];
        polygons.fan_into(&mut triangles);
        let mut mesh = Mesh {
            positions,
            triangles,
        };
        assert!(
            mesh.triangles[1..]
                .iter()
                .any(|&t| area(t, &mesh.positions) < 0.0)
        );
        polygons.untangle(&mut mesh);
        assert_eq!(mesh.triangles[0], [9, 9, 9]);
        assert_eq!(mesh.triangles.len(), 5);
        let areas: Vec<f64> = mesh.triangles[1..]
            .iter()
            .map(|&t| area(t, &mesh.positions))
            .collect();
        assert!(areas.iter().all(|&a| a > 0.0), "{areas:?}");
        assert_eq!(areas.iter().sum::<f64>(), 3.0);
    }

    /// A convex quad keeps its fan, and a clockwise concave polygon (seen
    /// from +z) is cut with its own, clockwise, winding.
    #[test]
    fn convex_polygons_keep_their_fan_and_windings_are_kept() {
        let square = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let mut polygons = Polygons {
            corners: vec![0, 1, 2, 3],
            ..Polygons::default()
        };
        let mut triangles = Vec::new();
        polygons.fan_into(&mut triangles);
        let mut mesh = Mesh {
            positions: square,
            triangles,
        };
        polygons.untangle(&mut mesh);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);

        // The hexagon above, corners reversed, lifted out of the xy plane.
        let positions: Vec<[f64; 3]> = [
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
            [0.0, 0.0],
            [2.0, 0.0],
        ]
        .iter()
        .map(|&[x, y]| [x, y, 0.25 * x])
        .collect();
        let mut polygons = Polygons {
            corners: vec![5, 4, 3, 2, 1, 0],
            ..Polygons::default()
        };
        let mut triangles = Vec::new();
        polygons.fan_into(&mut triangles);
        let mut mesh = Mesh {
            positions,
            triangles,
        };
        polygons.untangle(&mut mesh);
        let areas: Vec<f64> = mesh
            .triangles
            .iter()
            .map(|&t| area(t, &mesh.positions))
            .collect();
        assert!(areas.iter().all(|&a| a < 0.0), "{areas:?}");
    }
}
