//! Whether one collapse keeps the mesh a valid oriented 2-manifold that the
//! decoder can split back (SPEC §6, §7): link condition with the boundary
//! ghost, valence limits, wings that keep a fan, no folded triangles.
//! Read-only, so the pairs a step chooses can be checked in parallel.

use super::select::{Scale, other_placements};
use super::state::{MAX_VALENCE, State};
use crate::corner_table::{Fan, NONE, next, prev};
use crate::quadric::{cross, dot, sub};

/// What a valid collapse of (p, c) removes and records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Corner at p of triangle (p, c, A), or NONE.
    pub left: u32,
    /// Corner at p of triangle (p, B, c) = (c, p, B), or NONE.
    pub right: u32,
    pub wing_a: u32,
    pub wing_b: u32,
    /// Valence of the merged vertex, the ghost counted.
    pub valence_r: usize,
}

/// Reusable buffers so the parallel passes do not allocate per vertex.
#[derive(Default)]
pub struct CheckScratch {
    fan_p: Fan,
    fan_c: Fan,
    pub fan_x: Fan,
    np: Vec<u32>,
    nc: Vec<u32>,
}

/// Distinct neighbours of the fan's centre, sorted, with [`NONE`] (the ghost)
/// for a boundary vertex.
fn neighbours(s: &State, fan: &Fan, out: &mut Vec<u32>) {
    out.clear();
    // Each neighbour is the next vertex of one corner, except, on a
    // boundary, the end of the open fan, which is only a previous vertex.
    for &c in &fan.corners {
        out.push(s.table.v(next(c)));
    }
    if fan.boundary {
        for &c in &fan.corners {
            let x = s.table.v(prev(c));
            if !out.contains(&x) {
                out.push(x);
            }
        }
        out.push(NONE);
    }
}

/// Checks collapsing `c` into `p` (p < c survives) placed at `target`.
pub fn check_collapse(
    s: &State,
    p: u32,
    c: u32,
    target: [f64; 3],
    k: &mut CheckScratch,
) -> Result<Plan, ()> {
    s.table.fan(p, &mut k.fan_p);
    s.table.fan(c, &mut k.fan_c);
    check_walked(s, p, c, target, k)
}

impl CheckScratch {
    /// The fan of P, then (`walk_c`) of C, for [`check_walked`] to use as
    /// they are.
    pub fn walk_p(&mut self, s: &State, p: u32) -> &Fan {
        s.table.fan(p, &mut self.fan_p);
        &self.fan_p
    }

    pub fn walk_c(&mut self, s: &State, c: u32) -> &Fan {
        s.table.fan(c, &mut self.fan_c);
        &self.fan_c
    }

    /// The fans of P and C the check used.
    pub fn fans(&self) -> (&Fan, &Fan) {
        (&self.fan_p, &self.fan_c)
    }

    /// After a successful check: P, C and every neighbour of either, the
    /// vertices the collapse blocks for the rest of its step.
    pub fn neighbourhood(&self) -> impl Iterator<Item = u32> + '_ {
        self.np
            .iter()
            .chain(&self.nc)
            .copied()
            .filter(|&x| x != NONE)
    }
}

/// [`check_collapse`] on the fans `k` holds from [`CheckScratch::walk_p`]
/// and [`CheckScratch::walk_c`].
pub fn check_walked(
    s: &State,
    p: u32,
    c: u32,
    target: [f64; 3],
    k: &mut CheckScratch,
) -> Result<Plan, ()> {
    let plan = check_linked(s, p, c, k)?;
    if unfolded(s, p, c, target, k) {
        Ok(plan)
    } else {
        Err(())
    }
}

/// [`check_walked`] at `target`, the placement [`evaluate`](super::select::evaluate)
/// gives, or where that folds a triangle at the first of its
/// [`other_placements`] that does not: the placement taken, and the plan.
/// On a flat raster a quarter of the first placements folded (a
/// collapse into one end squashes a triangle onto a line of lattice
/// points), and the steps spent two fifths of their time checking
/// requests again (encoder/BENCHMARKS.md, "Flat and tilted rasters").
pub fn check_placed(
    s: &State,
    p: u32,
    c: u32,
    target: [u32; 3],
    scale: Scale,
    k: &mut CheckScratch,
) -> Result<([u32; 3], Plan), ()> {
    let plan = check_linked(s, p, c, k)?;
    if unfolded(s, p, c, s.to_metric(target), k) {
        return Ok((target, plan));
    }
    other_placements(s, p, c, target, scale)
        .find(|&other| unfolded(s, p, c, s.to_metric(other), k))
        .map(|other| (other, plan))
        .ok_or(())
}

/// Everything [`check_walked`] checks but the folds, which alone depend on
/// where the merged vertex goes.
fn check_linked(s: &State, p: u32, c: u32, k: &mut CheckScratch) -> Result<Plan, ()> {
    let t = &s.table;
    let left = k
        .fan_p
        .corners
        .iter()
        .copied()
        .find(|&x| t.v(next(x)) == c)
        .unwrap_or(NONE);
    let right = k
        .fan_p
        .corners
        .iter()
        .copied()
        .find(|&x| t.v(prev(x)) == c)
        .unwrap_or(NONE);
    if left == NONE && right == NONE {
        return Err(());
    }
    let wing_a = if left != NONE { t.v(prev(left)) } else { NONE };
    let wing_b = if right != NONE {
        t.v(next(right))
    } else {
        NONE
    };
    neighbours(s, &k.fan_p, &mut k.np);
    neighbours(s, &k.fan_c, &mut k.nc);
    // Link condition on the ghost-closed mesh: the common neighbours are
    // exactly the two wings (one may be the ghost).
    // Short unsorted lists (valences are small): a direct count beats sorting.
    let common =
        k.np.iter()
            .filter(|&&x| x != c && k.nc.contains(&x))
            .count();
    let p_side = k.np.iter().filter(|&&x| x != c).count();
    let c_side = k.nc.iter().filter(|&&x| x != p).count();
    let union = p_side + c_side - common;
    if common != 2 {
        return Err(());
    }
    let valence_r = union;
    if !(3..=MAX_VALENCE).contains(&valence_r) {
        return Err(());
    }
    // Each real wing loses a neighbour and must keep a valence of 3.
    for w in [wing_a, wing_b] {
        if w == NONE {
            continue;
        }
        if cfg!(debug_assertions) {
            t.fan(w, &mut k.fan_x);
            let walked = k.fan_x.corners.len() + if k.fan_x.boundary { 2 } else { 0 };
            debug_assert_eq!(s.valence[w as usize] as usize, walked, "valence of {w}");
        }
        if s.valence[w as usize] < 4 {
            return Err(());
        }
    }
    Ok(Plan {
        left,
        right,
        wing_a,
        wing_b,
        valence_r,
    })
}

/// Whether collapsing `c` into `p` at `target` leaves every triangle of
/// their fans (walked into `k`) unfolded.
fn unfolded(s: &State, p: u32, c: u32, target: [f64; 3], k: &CheckScratch) -> bool {
    keeps_orientation(s, p, c, target, &k.fan_p) && keeps_orientation(s, c, p, target, &k.fan_c)
}

/// Whether every triangle around `v` not containing `other` keeps a
/// non-degenerate normal within 90° of its old one when `v` moves to `target`.
/// A triangle that was degenerate (no normal: coincident or collinear
/// corners, as coarse quantization and sliver-ridden input make them) may
/// stay degenerate, since the collapse makes it no worse; if it gains a
/// normal, that is held to the normal of `v`'s whole fan. Requiring it to
/// gain one refused, for as long as the triangle stood, every collapse that
/// moved a corner whose two other corners share a grid point. On the
/// Stanford dragon at 14 bits (about 13,000 such triangles) 25,000-57,000
/// requests were refused at every step, checking them again took half of
/// the simplification's time, and the stream had 17 more rounds
/// (encoder/BENCHMARKS.md, "Triangles that stay without a normal").
fn keeps_orientation(s: &State, v: u32, other: u32, target: [f64; 3], fan: &Fan) -> bool {
    let t = &s.table;
    let pv = s.geometry(v);
    let mut fan_normal: Option<[f64; 3]> = None;
    fan.corners.iter().all(|&c| {
        let (n1, n2) = (t.v(next(c)), t.v(prev(c)));
        if n1 == other || n2 == other {
            return true;
        }
        let corners = [pv, s.geometry(n1), s.geometry(n2)];
        triangle_keeps_orientation(corners, target, || {
            *fan_normal.get_or_insert_with(|| {
                fan.corners.iter().fold([0.0; 3], |n, &c| {
                    let (a, b) = (s.geometry(t.v(next(c))), s.geometry(t.v(prev(c))));
                    let x = cross(sub(a, pv), sub(b, pv));
                    [n[0] + x[0], n[1] + x[1], n[2] + x[2]]
                })
            })
        })
    })
}

/// The rule of [`keeps_orientation`] for one triangle `[v, n1, n2]` whose
/// `v` moves to `target`; `fan_normal` gives the normal of `v`'s fan, asked
/// for only when the triangle had none. Shared with the sequential baseline
/// (`baseline::collapse`), so that both simplifiers refuse the same folds.
pub(crate) fn triangle_keeps_orientation(
    [pv, q1, q2]: [[f64; 3]; 3],
    target: [f64; 3],
    fan_normal: impl FnOnce() -> [f64; 3],
) -> bool {
    let (d1, d2) = (sub(q1, pv), sub(q2, pv));
    let mut old = cross(d1, d2);
    let old_scale = dot(d1, d1) + dot(d2, d2);
    let (e1, e2) = (sub(q1, target), sub(q2, target));
    let new = cross(e1, e2);
    let scale = dot(e1, e1) + dot(e2, e2);
    let has_normal = dot(new, new) > 1e-24 * scale * scale;
    if dot(old, old) <= 1e-24 * old_scale * old_scale {
        if !has_normal {
            return true;
        }
        old = fan_normal();
    }
    dot(old, new) > 0.0 && has_normal
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corner_table::{next, prev};
    use crate::mesh::Mesh;
    use crate::quantize::{Lattice, Quantization, Units, quantize_with};
    use crate::simplify::select::{Scale, evaluate};
    use crate::simplify::state::SimplifyOptions;

    /// A level raster whose inner samples are moved off the grid within the
    /// plane: every collapse has error 0 in every placement, and some
    /// placements fold triangles that others do not.
    fn jittered_plane(side: usize) -> Mesh {
        let mut x = 0x2545_F491u32;
        let mut jitter = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x % 61) as f64 / 100.0 - 0.3
        };
        let mut positions = Vec::new();
        for r in 0..side {
            for c in 0..side {
                let inner = (1..side - 1).contains(&r) && (1..side - 1).contains(&c);
                let (dx, dy) = if inner {
                    (jitter(), jitter())
                } else {
                    (0.0, 0.0)
                };
                positions.push([c as f64 + dx, r as f64 + dy, 0.0]);
            }
        }
        let mut triangles = Vec::new();
        for r in 0..side as u32 - 1 {
            for c in 0..side as u32 - 1 {
                let v = r * side as u32 + c;
                let s = side as u32;
                triangles.push([v, v + 1, v + s + 1]);
                triangles.push([v, v + s + 1, v + s]);
            }
        }
        Mesh {
            positions,
            triangles,
        }
    }

    /// The simplifier's state of `mesh` at 14 bits in constrained mode.
    fn constrained_state(mesh: &Mesh) -> (State, SimplifyOptions) {
        let q = quantize_with(
            mesh,
            14,
            Units::Linear,
            Quantization::Uniform,
            Lattice::Ignore,
        );
        let options = SimplifyOptions {
            constrained: true,
            ..SimplifyOptions::default()
        };
        (State::new(&q, &options), options)
    }

    /// `check_placed` takes the first placement wherever `check_walked`
    /// does, and otherwise another one only where that one passes
    /// `check_walked` itself; on this plane that saves some collapses.
    #[test]
    fn a_folding_placement_gives_way_to_an_equal_one() {
        let (mut s, options) = constrained_state(&jittered_plane(24));
        s.quadrics = s.fan_quadrics(options.boundary_weight).expect("manifold");
        let scale = Scale {
            cell: 0.0,
            flat: 1e-9,
        };
        let (mut k, mut rescued, mut valid) = (CheckScratch::default(), 0, 0);
        for corner in 0..s.table.vertex.len() as u32 {
            let (p, c) = (s.table.v(next(corner)), s.table.v(prev(corner)));
            if p > c {
                continue;
            }
            // (Collapses off the border have an error: its planes.)
            let (target, error) = evaluate(&s, p, c).expect("no locked boundary");
            if error != 0.0 {
                continue;
            }
            let first = check_collapse(&s, p, c, s.to_metric(target), &mut k);
            let placed = check_placed(&s, p, c, target, scale, &mut k);
            match (first, placed) {
                (Ok(plan), got) => {
                    assert_eq!(got, Ok((target, plan)));
                    valid += 1;
                }
                (Err(()), Ok((other, plan))) => {
                    assert_ne!(other, target);
                    assert_eq!(
                        check_collapse(&s, p, c, s.to_metric(other), &mut k),
                        Ok(plan)
                    );
                    rescued += 1;
                }
                (Err(()), Err(())) => {}
            }
        }
        assert!(
            valid > 1000 && rescued >= 10,
            "{valid} valid, {rescued} rescued"
        );
    }

    /// A 5 × 5 raster (vertex `5 row + column` at (column, row)) whose
    /// vertex 18 lies on vertex 13: triangle (12, 13, 18) has no normal.
    fn raster_with_a_zero_length_edge() -> State {
        let mut mesh = jittered_plane(5);
        for p in &mut mesh.positions {
            *p = [p[0].round(), p[1].round(), 0.0];
        }
        mesh.positions[18] = mesh.positions[13];
        constrained_state(&mesh).0
    }

    /// Collapsing 12 into 11 leaves (12, 13, 18) as it was, without a
    /// normal: allowed, where requiring a normal refused it (and every other
    /// collapse of 12 that does not remove that triangle). A triangle that
    /// has a normal must still keep one: collapsing 13 into 12 at 13's
    /// place squashes (12, 18, 17) onto the line from 13 to 17.
    #[test]
    fn a_triangle_without_a_normal_may_stay_so() {
        let s = raster_with_a_zero_length_edge();
        let mut k = CheckScratch::default();
        let at = |v: usize| s.to_metric(s.positions[v]);
        assert!(check_collapse(&s, 11, 12, at(11), &mut k).is_ok());
        assert!(check_collapse(&s, 7, 12, at(7), &mut k).is_ok());
        assert_eq!(check_collapse(&s, 12, 13, at(13), &mut k), Err(()));
        // The zero-length edge itself, and a collapse far from it.
        assert!(check_collapse(&s, 13, 18, at(13), &mut k).is_ok());
        assert!(check_collapse(&s, 0, 1, at(0), &mut k).is_ok());
    }
}
