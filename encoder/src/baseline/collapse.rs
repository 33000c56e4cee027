//! One edge collapse: the checks that keep the mesh a valid oriented
//! manifold, then the in-place edit of the corner table.

use super::state::Simplifier;
use crate::corner_table::{NONE, next, prev};
use crate::quadric::{Quadric, cross, sub};
use crate::simplify::triangle_keeps_orientation;

/// Most neighbours a vertex may end up with (boundary vertices count one
/// extra), so valences fit the stream's byte-sized fields.
pub const MAX_VALENCE: usize = 254;

/// Why a popped collapse was not performed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// The endpoints are no longer adjacent: a stale queue entry.
    NotAnEdge,
    /// Legal now-or-never rules failed (link, valence, flips, ...); the edge
    /// may become legal after a neighbouring collapse.
    Illegal,
}

/// The triangles a legal collapse removes, by the corner at `a` in each.
pub struct Plan {
    /// Corner at `a` of triangle `a, b, x` (CCW), if the edge has that side.
    left: u32,
    /// Corner at `a` of triangle `a, y, b` (CCW), if the edge has that side.
    right: u32,
}

impl Simplifier<'_> {
    /// Checks collapsing `b` into `a` placed at `p`. Leaves the fans of `a`
    /// and `b` in `self.fans[0]` and `self.fans[1]` for [`Self::apply`].
    pub fn plan(&mut self, a: u32, b: u32, p: [f64; 3]) -> Result<Plan, Refusal> {
        let mut fa = std::mem::take(&mut self.fans[0]);
        let mut fb = std::mem::take(&mut self.fans[1]);
        self.table.fan(a, &mut fa);
        self.table.fan(b, &mut fb);
        let result = self.check(a, b, p, &fa.corners, &fb.corners);
        self.fans[0] = fa;
        self.fans[1] = fb;
        result
    }

    fn check(
        &mut self,
        a: u32,
        b: u32,
        p: [f64; 3],
        fa: &[u32],
        fb: &[u32],
    ) -> Result<Plan, Refusal> {
        let token = self.next_token();
        let token_b = self.next_token();
        let t = &self.table;
        let left = fa
            .iter()
            .copied()
            .find(|&c| t.v(next(c)) == b)
            .unwrap_or(NONE);
        let right = fa
            .iter()
            .copied()
            .find(|&c| t.v(prev(c)) == b)
            .unwrap_or(NONE);
        if left == NONE && right == NONE {
            return Err(Refusal::NotAnEdge);
        }
        let interior = left != NONE && right != NONE;
        let (ba, bb) = (self.on_boundary[a as usize], self.on_boundary[b as usize]);
        // Collapsing a chord between two border vertices would pinch the
        // surface into a non-manifold vertex.
        if interior && ba && bb {
            return Err(Refusal::Illegal);
        }

        // Link condition: the shared neighbours are exactly the opposite
        // vertices of the removed triangles.
        let mut count_a = 0;
        for &c in fa {
            for w in [t.v(next(c)), t.v(prev(c))] {
                if self.mark[w as usize] != token {
                    self.mark[w as usize] = token;
                    count_a += 1;
                }
            }
        }
        let (mut count_b, mut common) = (0, 0);
        for &c in fb {
            for w in [t.v(next(c)), t.v(prev(c))] {
                let m = self.mark[w as usize];
                if m != token_b {
                    self.mark[w as usize] = token_b;
                    count_b += 1;
                    if m == token && w != a && w != b {
                        common += 1;
                    }
                }
            }
        }
        let removed = if interior { 2 } else { 1 };
        if common != removed {
            return Err(Refusal::Illegal);
        }
        let boundary = ba || bb;
        // |N(a) ∪ N(b)| without a and b themselves.
        let valence = count_a - 1 + count_b - 1 - common + usize::from(boundary);
        if valence > MAX_VALENCE {
            return Err(Refusal::Illegal);
        }
        let faces = fa.len() + fb.len() - 2 * removed;
        if faces < if boundary { 1 } else { 3 } {
            return Err(Refusal::Illegal);
        }
        // Each opposite vertex loses one triangle; it must keep a fan (two
        // triangles on a border, four inside, else it would leave a
        // doubled face, as when a tetrahedron folds flat).
        for c in [left, right] {
            if c == NONE {
                continue;
            }
            let x = if c == left {
                t.v(prev(c))
            } else {
                t.v(next(c))
            };
            let mut fx = std::mem::take(&mut self.fans[2]);
            self.table.fan(x, &mut fx);
            let need = if self.on_boundary[x as usize] { 2 } else { 4 };
            let ok = fx.corners.len() >= need;
            self.fans[2] = fx;
            if !ok {
                return Err(Refusal::Illegal);
            }
        }
        if !self.keeps_orientation(a, b, p, fa) || !self.keeps_orientation(b, a, p, fb) {
            return Err(Refusal::Illegal);
        }
        Ok(Plan { left, right })
    }

    /// Whether every triangle around `v` that survives (does not contain
    /// `other`) keeps a non-degenerate normal within 90° of its old one when
    /// `v` moves to `p`, or stays without one: the parallel simplifier's
    /// rule (`simplify::check`).
    fn keeps_orientation(&self, v: u32, other: u32, p: [f64; 3], fan: &[u32]) -> bool {
        let t = &self.table;
        let pv = self.positions[v as usize];
        let fan_normal = || {
            fan.iter().fold([0.0; 3], |n, &c| {
                let a = self.positions[t.v(next(c)) as usize];
                let b = self.positions[t.v(prev(c)) as usize];
                let x = cross(sub(a, pv), sub(b, pv));
                [n[0] + x[0], n[1] + x[1], n[2] + x[2]]
            })
        };
        fan.iter().all(|&c| {
            let (n1, n2) = (t.v(next(c)), t.v(prev(c)));
            if n1 == other || n2 == other {
                return true;
            }
            let corners = [pv, self.positions[n1 as usize], self.positions[n2 as usize]];
            triangle_keeps_orientation(corners, p, fan_normal)
        })
    }

    /// Performs a planned collapse of `b` into `a`, moving `a` to `p` with
    /// summed quadric `q`. Returns the number of triangles removed.
    pub fn apply(&mut self, a: u32, b: u32, p: [f64; 3], q: Quadric, plan: &Plan) -> usize {
        let mut fans = [
            std::mem::take(&mut self.fans[0]),
            std::mem::take(&mut self.fans[1]),
        ];
        self.table.collapse(a, b, plan.left, plan.right, &mut fans);
        let [fa, fb] = fans;
        let removed = usize::from(plan.left != NONE) + usize::from(plan.right != NONE);

        let (ai, bi) = (a as usize, b as usize);
        self.positions[ai] = p;
        self.quadrics[ai] = q;
        self.on_boundary[ai] |= self.on_boundary[bi];
        self.alive[bi] = false;
        self.alive_count -= 1;
        self.fans[0] = fa;
        self.fans[1] = fb;
        removed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baseline::BaselineOptions;

    /// A flat disc with `rim` border vertices and two centres, 0 and 1, that
    /// share the top and bottom rim vertices: merging them gives an interior
    /// vertex with exactly `rim` neighbours.
    fn two_fans(rim: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut positions = vec![[-0.01, 0.0, 0.0], [0.01, 0.0, 0.0]];
        for k in 0..rim {
            let a = std::f64::consts::TAU * f64::from(k) / f64::from(rim);
            positions.push([a.cos(), a.sin(), 0.0]);
        }
        let r = |k: u32| 2 + k % rim;
        let (top, bottom) = (rim / 4, rim / 4 + rim / 2);
        let mut triangles: Vec<[u32; 3]> = (top..bottom).map(|k| [0, r(k), r(k + 1)]).collect();
        triangles.extend((bottom..top + rim).map(|k| [1, r(k), r(k + 1)]));
        triangles.push([0, r(bottom), 1]);
        triangles.push([1, r(top), 0]);
        (positions, triangles)
    }

    fn try_merge(rim: u32) -> Result<(), Refusal> {
        let (positions, triangles) = two_fans(rim);
        let options = BaselineOptions::default();
        let mut s = Simplifier::new(&positions, &triangles, &options);
        s.plan(0, 1, [0.0; 3]).map(|_| ())
    }

    #[test]
    fn valence_limit_is_enforced_exactly() {
        assert_eq!(try_merge(MAX_VALENCE as u32), Ok(()));
        assert_eq!(try_merge(MAX_VALENCE as u32 + 1), Err(Refusal::Illegal));
    }

    #[test]
    fn flips_are_refused() {
        let (positions, triangles) = two_fans(12);
        let options = BaselineOptions::default();
        let mut s = Simplifier::new(&positions, &triangles, &options);
        assert!(s.plan(0, 1, [0.0; 3]).is_ok());
        // Far outside the disc, the fans would fold over.
        assert_eq!(s.plan(0, 1, [3.0, 0.0, 0.0]).err(), Some(Refusal::Illegal));
        // Not an edge: two rim vertices far apart.
        assert_eq!(s.plan(2, 8, [0.0; 3]).err(), Some(Refusal::NotAnEdge));
    }

    #[test]
    fn chords_between_border_vertices_are_refused() {
        // Square split by diagonal 0-2: both ends on the border.
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let triangles = vec![[0, 1, 2], [0, 2, 3]];
        let options = BaselineOptions::default();
        let mut s = Simplifier::new(&positions, &triangles, &options);
        assert_eq!(s.plan(0, 2, [0.0; 3]).err(), Some(Refusal::Illegal));
    }
}
