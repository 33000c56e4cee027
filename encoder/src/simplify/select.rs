//! Step a of §2: each vertex's best incident edge, with the sub-grid tie-break.

use super::check::{CheckScratch, check_collapse};
use super::state::State;
use crate::corner_table::{NONE, next, prev};
use crate::quadric::collapse_target;

/// A vertex's chosen collapse; `other == NONE` when it has none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Best {
    pub other: u32,
    pub error: f64,
    /// Error rounded to f32 bits (flat regions flushed to 0) so that equal
    /// errors tie exactly and the tie-breaks decide.
    pub error_key: u32,
    pub target: [u32; 3],
}

impl Best {
    pub const NONE: Best = Best {
        other: NONE,
        error: f64::INFINITY,
        error_key: u32::MAX,
        target: [0; 3],
    };
}

/// Total order of collapse requests: error first, then the lower id wins
/// (the paper's index priority).
pub fn pair_key(b: &Best, v: u32) -> u64 {
    ((b.error_key as u64) << 32) | v.min(b.other) as u64
}

/// Where the collapse of edge (v, u) puts the merged vertex, and its error
/// (`None` when locked boundaries forbid it). Computed from the lower id
/// first, so both endpoints get identical results.
pub fn evaluate(s: &State, v: u32, u: u32) -> Option<([u32; 3], f64)> {
    let (p, c) = (v.min(u), v.max(u));
    let (pi, ci) = (p as usize, c as usize);
    let q = s.quadrics[pi] + s.quadrics[ci];
    let (pp, pc) = (s.positions[pi], s.positions[ci]);
    let target = if s.lock_boundary && (s.boundary[pi] || s.boundary[ci]) {
        match (s.boundary[pi], s.boundary[ci]) {
            (true, true) => return None,
            (true, false) => pp,
            _ => pc,
        }
    } else if s.constrained {
        // P, C or the integer midpoint P + ((C - P) >> 1) (SPEC §7.4).
        let mid: [u32; 3] =
            std::array::from_fn(|k| (pp[k] as i64 + ((pc[k] as i64 - pp[k] as i64) >> 1)) as u32);
        let mut best = (pp, q.error(s.geometry[pi]));
        for cand in [pc, mid] {
            let e = q.error(s.to_metric(cand));
            if e < best.1 {
                best = (cand, e);
            }
        }
        best.0
    } else {
        let (t, _) = collapse_target(&q, s.geometry[pi], s.geometry[ci], false);
        let top = ((1u64 << s.bits) - 1) as f64;
        std::array::from_fn(|k| (t[k] / s.metric[k]).round().clamp(0.0, top) as u32)
    };
    Some((target, q.error(s.to_metric(target))))
}

/// Cached collapse of the edge facing one corner (the paper's Edge array).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeSlot {
    pub error: f64,
    pub target: [u32; 3],
}

impl EdgeSlot {
    pub const FORBIDDEN: EdgeSlot = EdgeSlot {
        error: f64::INFINITY,
        target: [0; 3],
    };
}

/// The slot of the edge facing corner `c` (the edge from next(c) to prev(c)).
pub fn edge_slot(s: &State, c: u32) -> EdgeSlot {
    let (a, b) = (s.table.v(next(c)), s.table.v(prev(c)));
    if a == NONE {
        return EdgeSlot::FORBIDDEN;
    }
    match evaluate(s, a, b) {
        Some((target, error)) => EdgeSlot { error, target },
        None => EdgeSlot::FORBIDDEN,
    }
}

/// Scale of the current mesh, for the tie-breaks.
#[derive(Clone, Copy, Debug)]
pub struct Scale {
    /// Sub-grid cell size (0: no sub-grid).
    pub cell: f64,
    /// Errors below this count as flat (exactly 0).
    pub flat: f64,
}

fn cell_of(p: [f64; 3], cell: f64) -> [i64; 3] {
    p.map(|x| (x / cell).floor() as i64)
}

/// The best valid collapse of `v` (§2 step a), from the cached edge slots.
pub fn best_edge(s: &State, v: u32, scale: Scale, scratch: &mut CheckScratch) -> Best {
    best_edge_avoiding(s, v, scale, scratch, &[])
}

/// [`best_edge`] among the neighbours `u` with `blocked[u] == false`
/// (`blocked` empty: all of them).
pub fn best_edge_avoiding(
    s: &State,
    v: u32,
    scale: Scale,
    scratch: &mut CheckScratch,
    blocked: &[bool],
) -> Best {
    if !s.alive[v as usize] {
        return Best::NONE;
    }
    let mut fan = std::mem::take(&mut scratch.fan_v);
    s.table.fan(v, &mut fan);
    let mut candidates = std::mem::take(&mut scratch.candidates);
    candidates.clear();
    let home = (scale.cell > 0.0).then(|| cell_of(s.geometry(v), scale.cell));
    for &c in &fan.corners {
        // Edge (v, next c) faces prev c; edge (v, prev c) faces next c.
        for (u, facing) in [(s.table.v(next(c)), prev(c)), (s.table.v(prev(c)), next(c))] {
            if candidates.iter().any(|x: &Candidate| x.other == u)
                || blocked.get(u as usize).copied().unwrap_or(false)
            {
                continue;
            }
            let slot = s.edges[facing as usize];
            if slot.error == f64::INFINITY {
                continue;
            }
            let error_key = if slot.error <= scale.flat {
                0
            } else {
                (slot.error as f32).to_bits()
            };
            let other_cell = home.is_some_and(|h| h != cell_of(s.geometry(u), scale.cell));
            candidates.push(Candidate {
                rank: (error_key, other_cell, s.positions[u as usize], u),
                other: u,
                best: Best {
                    other: u,
                    error: slot.error,
                    error_key,
                    target: slot.target,
                },
            });
        }
    }
    candidates.sort_unstable_by_key(|x| x.rank);
    let mut found = Best::NONE;
    for cand in &candidates {
        let (p, c) = (v.min(cand.other), v.max(cand.other));
        if check_collapse(s, p, c, s.to_metric(cand.best.target), scratch).is_ok() {
            found = cand.best;
            break;
        }
    }
    scratch.fan_v = fan;
    scratch.candidates = candidates;
    found
}

/// A candidate edge of one vertex, ranked by error, then same sub-grid cell,
/// then minimal coordinates of the other end (Fig. 2), then id.
#[derive(Clone, Copy, Debug)]
pub struct Candidate {
    rank: (u32, bool, [u32; 3], u32),
    other: u32,
    best: Best,
}

impl Default for Candidate {
    fn default() -> Self {
        Candidate {
            rank: (u32::MAX, true, [0; 3], NONE),
            other: NONE,
            best: Best::NONE,
        }
    }
}
