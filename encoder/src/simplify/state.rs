//! Working state and the step loop of the parallel simplifier.

use rayon::prelude::*;

use super::check::{CheckScratch, Plan, check_collapse};
use super::select::{Best, EdgeSlot, Scale, best_edge, best_edge_avoiding, edge_slot, pair_key};
use crate::corner_table::{CornerTable, Fan, NONE, next, prev};
use crate::quadric::{Quadric, vertex_quadrics};
use crate::quantize::QuantizedMesh;

/// Split valence stored for vertices that were never produced by a collapse.
pub const LEAF: u8 = 0xFF;
/// Largest valence (ghost included) a collapse may produce; below [`LEAF`].
pub const MAX_VALENCE: usize = 254;

/// Options of the parallel simplifier.
#[derive(Clone, Debug)]
pub struct SimplifyOptions {
    /// Stop once this many vertices remain.
    pub target_vertices: usize,
    /// Never collapse an edge whose quadric error exceeds this.
    pub max_error: Option<f64>,
    /// Constrained placement: the merged vertex sits on P, on C or at their midpoint.
    pub constrained: bool,
    pub boundary_weight: f64,
    /// Never move or remove boundary vertices (for patch borders).
    pub lock_boundary: bool,
    /// Fraction of the candidate errors admitted per step (the threshold S is
    /// raised to this quantile): lower is closer to the sequential order, higher
    /// collapses more per step.
    pub admit_quantile: f64,
    /// Sub-grid cell size in mean edge lengths (Fig. 2 tie-break); 0 disables it.
    pub subgrid_cells: f64,
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        SimplifyOptions {
            target_vertices: 0,
            max_error: None,
            constrained: false,
            boundary_weight: crate::quadric::DEFAULT_BOUNDARY_WEIGHT,
            lock_boundary: false,
            admit_quantile: 0.5,
            subgrid_cells: 2.0,
        }
    }
}

/// One collapse of P (the lower id, which survives as R) and C, recorded so
/// that a vertex split can reverse it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collapse {
    pub p: u32,
    pub c: u32,
    /// Third vertex of triangle (P, C, A); [`NONE`] for the boundary ghost.
    pub wing_a: u32,
    /// Third vertex of triangle (C, P, B); [`NONE`] for the boundary ghost.
    pub wing_b: u32,
    pub position_p: [u32; 3],
    pub position_c: [u32; 3],
    pub position_r: [u32; 3],
    /// Split valences P and C had before the collapse ([`LEAF`] if original).
    pub split_valence_p: u8,
    pub split_valence_c: u8,
    /// Quadric error of the collapse (metric units).
    pub error: f64,
    /// The error as a distance in metric units: sqrt(error / total weight of
    /// the merged quadric), an RMS distance to the planes it summarises.
    pub distance: f64,
}

/// Result: the collapses, step by step, and the simplified mesh they leave.
pub struct Simplification {
    pub steps: Vec<Vec<Collapse>>,
    pub table: CornerTable,
    pub positions: Vec<[u32; 3]>,
    /// Split valence of each surviving vertex ([`LEAF`] for originals).
    pub split_valence: Vec<u8>,
    pub alive: Vec<bool>,
    pub alive_count: usize,
    /// Largest error of any collapse, per step.
    pub step_errors: Vec<f64>,
}

pub(super) struct State {
    pub table: CornerTable,
    pub positions: Vec<[u32; 3]>,
    pub geometry: Vec<[f64; 3]>,
    pub quadrics: Vec<Quadric>,
    pub boundary: Vec<bool>,
    pub alive: Vec<bool>,
    pub split_valence: Vec<u8>,
    /// Cached collapse of the edge facing each corner.
    pub edges: Vec<EdgeSlot>,
    pub bits: u8,
    /// Grid units to metric units per axis: geometry = position * metric.
    pub metric: [f64; 3],
    pub constrained: bool,
    pub lock_boundary: bool,
}

impl State {
    /// The state before any collapse, without quadrics and edge slots
    /// (each backend computes those its own way).
    pub fn new(mesh: &QuantizedMesh, options: &SimplifyOptions) -> State {
        let n = mesh.positions.len();
        let metric = mesh.metric;
        let geometry: Vec<[f64; 3]> = mesh
            .positions
            .iter()
            .map(|p| std::array::from_fn(|k| p[k] as f64 * metric[k]))
            .collect();
        let table = CornerTable::new(n, &mesh.triangles);
        let mut boundary = vec![false; n];
        for (c, &o) in table.opposite.iter().enumerate() {
            if o == NONE {
                boundary[table.v(next(c as u32)) as usize] = true;
                boundary[table.v(prev(c as u32)) as usize] = true;
            }
        }
        let alive: Vec<bool> = table.corner_of.iter().map(|&c| c != NONE).collect();
        State {
            quadrics: Vec::new(),
            positions: mesh.positions.clone(),
            geometry,
            table,
            boundary,
            alive,
            split_valence: vec![LEAF; n],
            edges: Vec::new(),
            bits: mesh.bits,
            metric,
            constrained: options.constrained,
            lock_boundary: options.lock_boundary,
        }
    }

    pub fn geometry(&self, v: u32) -> [f64; 3] {
        self.geometry[v as usize]
    }

    /// Metric coordinates of a grid point.
    pub fn to_metric(&self, q: [u32; 3]) -> [f64; 3] {
        std::array::from_fn(|k| q[k] as f64 * self.metric[k])
    }
}

/// Simplifies `mesh` (quantized, checked manifold) with the parallel algorithm.
pub fn simplify(
    mesh: &QuantizedMesh,
    options: &SimplifyOptions,
    mut progress: impl FnMut(usize),
) -> Simplification {
    let n = mesh.positions.len();
    let mut s = State::new(mesh, options);
    s.quadrics = vertex_quadrics(&s.geometry, &mesh.triangles, options.boundary_weight);
    s.edges = (0..s.table.vertex.len() as u32)
        .into_par_iter()
        .map(|c| edge_slot(&s, c))
        .collect();
    let mut alive_count = s.alive.iter().filter(|&&a| a).count();
    let mut steps = Vec::new();
    let mut step_errors = Vec::new();
    let mut threshold = 0.0f64;
    let mut best = vec![Best::NONE; n];
    let mut live: Vec<u32> = (0..n as u32).filter(|&v| s.alive[v as usize]).collect();
    let mut dirty = vec![true; n];
    let limit = options.max_error.unwrap_or(f64::INFINITY);
    // The mean edge length sets the sub-grid and the flat threshold; it
    // changes slowly, so it is measured again only when a fifth of the
    // vertices are gone since the last measure (a full pass over the corners).
    let (mut edge, mut edge_measured_at) = (mean_edge_length(&s), alive_count);
    while alive_count > options.target_vertices {
        if alive_count * 5 < edge_measured_at * 4 {
            edge = mean_edge_length(&s);
            edge_measured_at = alive_count;
        }
        let scale = Scale {
            cell: options.subgrid_cells * edge,
            // A collapse moving the surface by 1e-4 of an edge length or less
            // (error ~ area x distance^2 ~ L^2 x (1e-4 L)^2) counts as flat.
            flat: 1e-8 * edge.powi(4),
        };
        let t_best = std::time::Instant::now();
        // Only vertices whose 2-ring changed can have a new best edge; the
        // passes below run over the live vertices only.
        let updates: Vec<(u32, Best)> = live
            .par_iter()
            .filter(|&&v| dirty[v as usize])
            .map_init(CheckScratch::default, |scratch, &v| {
                (v, best_edge(&s, v, scale, scratch))
            })
            .collect();
        for (v, b) in updates {
            best[v as usize] = b;
        }
        // Raise S to the admitted quantile of the current candidate errors.
        let mut errors: Vec<f64> = live
            .iter()
            .map(|&v| &best[v as usize])
            .filter(|b| b.other != NONE)
            .map(|b| b.error)
            .collect();
        if errors.is_empty() {
            break;
        }
        let q = ((errors.len() - 1) as f64 * options.admit_quantile.clamp(0.0, 1.0)) as usize;
        let (_, quantile, _) = errors.select_nth_unstable_by(q, f64::total_cmp);
        threshold = threshold.max(*quantile).min(limit);
        let t_select = std::time::Instant::now();
        let mut winners = step_winners(&s, &mut best, &live, threshold, scale);
        // Nothing under S: raise it (the paper's "S is increased"), doubling
        // past the smallest candidate error, until a step finds collapses or
        // S passes every candidate error or the maximum error.
        let largest = errors.iter().copied().fold(0.0f64, f64::max);
        let smallest = errors.iter().copied().fold(f64::INFINITY, f64::min);
        while winners.is_empty() && threshold < limit && threshold < largest {
            threshold = (2.0 * threshold)
                .max(smallest)
                .max(f64::MIN_POSITIVE)
                .min(limit);
            winners = step_winners(&s, &mut best, &live, threshold, scale);
        }
        if winners.is_empty() {
            break;
        }
        // Hit the target exactly: keep the cheapest collapses of the last step.
        let room = alive_count - options.target_vertices;
        if winners.len() > room {
            winners.sort_by_key(|&v| pair_key(&best[v as usize], v));
            winners.truncate(room);
            winners.sort_unstable();
        }
        let t_apply = std::time::Instant::now();
        let mut collapses = Vec::with_capacity(winners.len());
        let mut fans = [Fan::default(), Fan::default()];
        let mut step_error = 0.0f64;
        for &p in &winners {
            let b = best[p as usize];
            let collapse = apply_collapse(&mut s, p, b, &mut fans);
            step_error = step_error.max(b.error);
            collapses.push(collapse);
        }
        let t_refresh = std::time::Instant::now();
        refresh_edges(&mut s, &winners);
        live.retain(|&v| s.alive[v as usize]);
        mark_two_rings(&s, &winners, &mut dirty);
        if std::env::var_os("SPLITSTREAM_DEBUG").is_some() {
            let ms = |a: std::time::Instant, b: std::time::Instant| (b - a).as_secs_f64() * 1e3;
            let now = std::time::Instant::now();
            eprintln!(
                "step {}: alive {alive_count}, collapses {}, dirty {}, ms: best {:.1} select {:.1} apply {:.1} refresh {:.1}",
                steps.len(),
                winners.len(),
                dirty.iter().filter(|&&d| d).count(),
                ms(t_best, t_select),
                ms(t_select, t_apply),
                ms(t_apply, t_refresh),
                ms(t_refresh, now),
            );
        }
        alive_count -= collapses.len();
        steps.push(collapses);
        step_errors.push(step_error);
        progress(n - alive_count);
    }
    Simplification {
        steps,
        table: s.table,
        positions: s.positions,
        split_valence: s.split_valence,
        alive: s.alive,
        alive_count,
        step_errors,
    }
}

/// Steps b and c: reciprocal pairs under the threshold that are local minima
/// among the requests of their 1-rings. Returns the survivors (lower ids).
///
/// Steps a to c are then repeated on what they left undecided: a vertex
/// whose partner was taken by a cheaper collapse chooses again among its free
/// neighbours, and a pair blocked only by a pair that itself lost gets its
/// turn. The passes grow the step towards a maximal set of independent
/// collapses in error order, still in parallel; more collapses per step mean
/// fewer rounds and fewer flags in the stream. Vertices changed here are all
/// within the 2-ring of a collapse, so they are recomputed next step.
fn step_winners(
    s: &State,
    best: &mut [Best],
    live: &[u32],
    threshold: f64,
    scale: Scale,
) -> Vec<u32> {
    // On jacksboro the passes add 100 %, 30 %, 4 % and 0.2 % of the first
    // pass's collapses: a fourth pass is not worth its O(n) sweeps.
    const PASSES: usize = 3;
    let n = best.len();
    let mut blocked = vec![false; n];
    let mut winners = Vec::new();
    for pass in 0..PASSES {
        if pass > 0 {
            let updates: Vec<(u32, Best)> = live
                .par_iter()
                .copied()
                .filter(|&v| {
                    let b = &best[v as usize];
                    s.alive[v as usize]
                        && !blocked[v as usize]
                        && b.other != NONE
                        && blocked[b.other as usize]
                })
                .map_init(CheckScratch::default, |scratch, v| {
                    (v, best_edge_avoiding(s, v, scale, scratch, &blocked))
                })
                .collect();
            for (v, b) in updates {
                best[v as usize] = b;
            }
        }
        let best_now: &[Best] = best;
        let admitted = |v: usize| {
            let b = &best_now[v];
            !blocked[v]
                && b.other != NONE
                && b.error <= threshold
                && best_now[b.other as usize].other == v as u32
        };
        // One key per pair, taken from its lower endpoint, so that both
        // endpoints compare alike (their cached errors may come from
        // different steps).
        let admitted_keys: Vec<(u32, u64)> = live
            .par_iter()
            .filter(|&&v| admitted(v as usize))
            .map(|&v| {
                let low = v.min(best_now[v as usize].other);
                (v, pair_key(&best_now[low as usize], low))
            })
            .collect();
        let mut keys = vec![u64::MAX; n];
        for &(v, key) in &admitted_keys {
            keys[v as usize] = key;
        }
        let chosen: Vec<u32> = admitted_keys
            .par_iter()
            .map(|&(v, _)| v)
            .filter(|&v| {
                let key = keys[v as usize];
                let c = best_now[v as usize].other;
                key != u64::MAX && v < c && is_local_minimum(s, v, c, key, &keys)
            })
            .collect();
        if chosen.is_empty() {
            break;
        }
        // The chosen pairs' endpoints and neighbours leave the game.
        let touched: Vec<u32> = chosen
            .par_iter()
            .flat_map_iter(|&v| {
                let mut fan = Fan::default();
                let mut out = Vec::new();
                for x in [v, best_now[v as usize].other] {
                    out.push(x);
                    s.table.fan(x, &mut fan);
                    out.extend(fan.corners.iter().map(|&k| s.table.v(next(k))));
                    out.extend(fan.corners.iter().map(|&k| s.table.v(prev(k))));
                }
                out
            })
            .collect();
        for x in touched {
            blocked[x as usize] = true;
        }
        winners.extend_from_slice(&chosen);
    }
    winners.sort_unstable();
    winners
}

fn is_local_minimum(s: &State, p: u32, c: u32, key: u64, keys: &[u64]) -> bool {
    let mut fan = Fan::default();
    for v in [p, c] {
        s.table.fan(v, &mut fan);
        for &corner in &fan.corners {
            for x in [s.table.v(next(corner)), s.table.v(prev(corner))] {
                if x != p && x != c && keys[x as usize] < key {
                    return false;
                }
            }
        }
    }
    true
}

/// Applies the collapse chosen by `p`, returning its record.
fn apply_collapse(s: &mut State, p: u32, b: Best, fans: &mut [Fan; 2]) -> Collapse {
    try_apply_collapse(s, p, b, fans)
        .expect("the winner was checked in this step and its neighbourhood is untouched")
        .0
}

/// Applies the collapse chosen by `p` if `check_collapse` accepts it,
/// returning its record and plan; `None` leaves the state untouched (GPU
/// backends choose in f32, the CPU has the last word in f64).
pub(super) fn try_apply_collapse(
    s: &mut State,
    p: u32,
    b: Best,
    fans: &mut [Fan; 2],
) -> Option<(Collapse, Plan)> {
    let c = b.other;
    let mut scratch = CheckScratch::default();
    let plan = check_collapse(s, p, c, s.to_metric(b.target), &mut scratch).ok()?;
    let q = s.quadrics[p as usize] + s.quadrics[c as usize];
    let weight = q.c[0] + q.c[4] + q.c[7];
    let distance = if weight > 0.0 {
        (b.error / weight).sqrt()
    } else {
        0.0
    };
    let record = Collapse {
        p,
        c,
        wing_a: plan.wing_a,
        wing_b: plan.wing_b,
        position_p: s.positions[p as usize],
        position_c: s.positions[c as usize],
        position_r: b.target,
        split_valence_p: s.split_valence[p as usize],
        split_valence_c: s.split_valence[c as usize],
        error: b.error,
        distance,
    };
    s.table.collapse(p, c, plan.left, plan.right, fans);
    let (pi, ci) = (p as usize, c as usize);
    s.positions[pi] = b.target;
    s.geometry[pi] = s.to_metric(b.target);
    s.quadrics[pi] = q;
    s.boundary[pi] |= s.boundary[ci];
    s.alive[ci] = false;
    s.split_valence[pi] = plan.valence_r as u8;
    Some((record, plan))
}

/// Re-evaluates the edges around each merged vertex: only their quadric or
/// position changed.
fn refresh_edges(s: &mut State, merged: &[u32]) {
    let updates: Vec<(u32, EdgeSlot)> = merged
        .par_iter()
        .flat_map_iter(|&r| {
            let mut fan = Fan::default();
            s.table.fan(r, &mut fan);
            let mut out = Vec::with_capacity(4 * fan.corners.len());
            for &c in &fan.corners {
                // Edge (r, prev c) faces next c and, across it, the opposite
                // corner: evaluate it once for both. A boundary edge
                // (r, next c) has no other side and is evaluated on its own.
                let slot = edge_slot(s, next(c));
                out.push((next(c), slot));
                let across = s.table.o(next(c));
                if across != NONE {
                    out.push((across, slot));
                }
                if s.table.o(prev(c)) == NONE {
                    out.push((prev(c), edge_slot(s, prev(c))));
                }
            }
            out
        })
        .collect();
    for (c, slot) in updates {
        s.edges[c as usize] = slot;
    }
}

/// Marks the vertices within two edges of each merged vertex: the only
/// ones whose best collapse can have changed (errors, links, fold-overs and
/// wing valences all live in the 2-ring).
pub(super) fn mark_two_rings(s: &State, merged: &[u32], dirty: &mut [bool]) {
    dirty.fill(false);
    let touched: Vec<u32> = merged
        .par_iter()
        .flat_map_iter(|&r| {
            let mut fan = Fan::default();
            let mut inner = Fan::default();
            let mut out = vec![r];
            s.table.fan(r, &mut fan);
            for x in neighbours_of(s, &fan) {
                out.push(x);
                s.table.fan(x, &mut inner);
                out.extend(neighbours_of(s, &inner));
            }
            out
        })
        .collect();
    for v in touched {
        dirty[v as usize] = true;
    }
}

/// The neighbours of a fan's centre: the next vertex of each corner, and on
/// a boundary also the previous ones (which adds the end of the open fan).
fn neighbours_of<'a>(s: &'a State, fan: &'a Fan) -> impl Iterator<Item = u32> + 'a {
    let ends = if fan.boundary {
        fan.corners.as_slice()
    } else {
        &[]
    };
    fan.corners
        .iter()
        .map(|&k| s.table.v(next(k)))
        .chain(ends.iter().map(|&k| s.table.v(prev(k))))
}

/// Mean length of the live edges, for the sub-grid cell size.
pub(super) fn mean_edge_length(s: &State) -> f64 {
    let t = &s.table;
    let (sum, count) = (0..t.vertex.len() as u32)
        .into_par_iter()
        .filter(|&c| t.v(c) != NONE)
        .map(|c| {
            let a = s.geometry(t.v(c));
            let b = s.geometry(t.v(next(c)));
            let d = crate::quadric::norm(crate::quadric::sub(a, b));
            (d, 1usize)
        })
        .reduce(|| (0.0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
    if count == 0 { 1.0 } else { sum / count as f64 }
}

impl Simplification {
    /// The simplified mesh in real coordinates, compacted (surviving
    /// vertices in ascending id, live triangles in order).
    pub fn to_mesh(&self, mesh: &QuantizedMesh) -> crate::Mesh {
        let mut index = vec![NONE; self.alive.len()];
        let mut positions = Vec::with_capacity(self.alive_count);
        for (v, &alive) in self.alive.iter().enumerate() {
            if alive {
                index[v] = positions.len() as u32;
                positions.push(mesh.dequantize(self.positions[v]));
            }
        }
        let triangles = self
            .table
            .vertex
            .chunks_exact(3)
            .filter(|t| t[0] != NONE)
            .map(|t| {
                [
                    index[t[0] as usize],
                    index[t[1] as usize],
                    index[t[2] as usize],
                ]
            })
            .collect();
        crate::Mesh {
            positions,
            triangles,
        }
    }

    /// Largest quadric error of any collapse.
    pub fn max_error(&self) -> f64 {
        self.step_errors.iter().copied().fold(0.0, f64::max)
    }
}
