//! The parallel simplifier with its data-parallel passes on a GPU backend
//! (kernels in `splitstream-kernels`), a hybrid:
//!
//! | step | where |
//! |---|---|
//! | corner table, boundary flags | CPU, once |
//! | quadric init (per-vertex gather) | device, once; read back to f64 |
//! | best edge per dirty vertex: error, optimal position with fallback, validity | device |
//! | threshold S (quantile of the candidate errors) | CPU, from the read-back errors |
//! | reciprocity + local minimum with index priority, 3 passes with re-picks | device |
//! | applying the collapses (corner-table surgery, records), re-checked in f64 | CPU |
//! | 2-ring dirty marking; upload of changed triangles and vertices | CPU → device |
//!
//! The device works in f32 in frames local to each vertex, so its errors and
//! positions differ from the CPU's by rounding; the CPU re-checks every
//! winner with `check_collapse` in f64 before applying it and skips the
//! rare one it rejects. The emitted stream is then checked by the replay
//! like any other (`emit`), so it decodes exactly whatever the device did.

use splitstream_kernels::encode::Engine;
use splitstream_kernels::encode::layout::{
    self, ALIVE, BOUNDARY, CONSTRAINED, LOCKED, Params, TriangleUpdate, VertexUpdate,
};
use splitstream_kernels::gpu::{Api, GpuError};

use super::select::{Best, pair_key};
use super::state::{
    Collapse, EdgeMeter, MAX_VALENCE, Simplification, SimplifyOptions, State, mark_two_rings,
    try_apply_collapse,
};
use crate::corner_table::{Fan, NONE};
use crate::quadric::Quadric;
use crate::quantize::QuantizedMesh;

/// Passes of steps a-c per step, as on the CPU (`step_winners`).
const PASSES: usize = 3;

/// Simplifies `mesh` with the data-parallel passes on `api`.
pub fn simplify_gpu(
    api: Api,
    mesh: &QuantizedMesh,
    options: &SimplifyOptions,
    mut progress: impl FnMut(usize),
) -> Result<Simplification, GpuError> {
    let n = mesh.positions.len();
    let mut s = State::new(mesh, options);
    let corners: Vec<[u32; 2]> = s
        .table
        .vertex
        .iter()
        .zip(&s.table.opposite)
        .map(|(&v, &o)| [v, o])
        .collect();
    let vertices: Vec<[u32; 4]> = (0..n).map(|v| vertex_words(&s, v)).collect();
    let mut engine = Engine::open(
        api,
        &splitstream_kernels::encode::MeshData {
            corners: &corners,
            corner_of: &s.table.corner_of,
            vertices: &vertices,
        },
    )?;
    let mut base = Params {
        vertex_count: n as u32,
        corner_count: corners.len() as u32,
        top: ((1u64 << mesh.bits) - 1) as u32,
        flags: if options.constrained { CONSTRAINED } else { 0 }
            | if options.lock_boundary { LOCKED } else { 0 },
        max_valence: MAX_VALENCE as u32,
        metric: [
            mesh.metric[0] as f32,
            mesh.metric[1] as f32,
            mesh.metric[2] as f32,
            0.0,
        ],
        boundary_weight: options.boundary_weight as f32,
        ..Params::default()
    };
    let local = engine.quadric_init(&base)?;
    s.quadrics = local
        .iter()
        .enumerate()
        .map(|(v, q)| to_global(q, s.geometry(v as u32)))
        .collect();

    let mut alive_count = s.alive.iter().filter(|&&a| a).count();
    let mut steps = Vec::new();
    let mut step_errors = Vec::new();
    let mut threshold = 0.0f64;
    let mut live: Vec<u32> = (0..n as u32).filter(|&v| s.alive[v as usize]).collect();
    let mut dirty_list = live.clone();
    let mut dirty = vec![false; n];
    let limit = options.max_error.unwrap_or(f64::INFINITY);
    let mut meter = EdgeMeter::new(&s);
    let (mut edge, mut edge_measured_at) = (meter.measure(&s), alive_count);
    let mut rejected_total = 0usize;
    let debug = std::env::var_os("SPLITSTREAM_DEBUG").is_some();
    while alive_count > options.target_vertices {
        if alive_count * 5 < edge_measured_at * 4 {
            edge = meter.measure(&s);
            edge_measured_at = alive_count;
        }
        base.cell = (options.subgrid_cells * edge) as f32;
        // f32 errors carry ~1e-7 relative noise of terms ~ edge^4: below
        // 1e-6 edge^4 they are flat (the CPU uses 1e-8 in f64).
        base.flat_error = (1e-6 * edge.powi(4)) as f32;
        let best = engine.best_edges(&base, &dirty_list)?;
        let mut errors: Vec<f64> = live
            .iter()
            .map(|&v| &best[v as usize])
            .filter(|b| b.other != layout::NONE)
            .map(|b| b.error as f64)
            .collect();
        if errors.is_empty() {
            break;
        }
        let q = ((errors.len() - 1) as f64 * options.admit_quantile.clamp(0.0, 1.0)) as usize;
        let (_, quantile, _) = errors.select_nth_unstable_by(q, f64::total_cmp);
        threshold = threshold.max(*quantile).min(limit);
        engine.set_live(&live)?;
        let select = |engine: &mut Engine, threshold: f64| {
            let params = Params {
                threshold: threshold as f32,
                ..base
            };
            engine.select(&params, PASSES)
        };
        let mut winners = select(&mut engine, threshold)?;
        let largest = errors.iter().copied().fold(0.0f64, f64::max);
        let smallest = errors.iter().copied().fold(f64::INFINITY, f64::min);
        while winners.is_empty() && threshold < limit && threshold < largest {
            threshold = (2.0 * threshold)
                .max(smallest)
                .max(f64::MIN_POSITIVE)
                .min(limit);
            winners = select(&mut engine, threshold)?;
        }
        if winners.is_empty() {
            break;
        }
        let as_best = |w: &layout::Winner| Best {
            other: w.other,
            error: w.error as f64,
            error_key: w.key,
            corner: NONE,
        };
        let room = alive_count - options.target_vertices;
        if winners.len() > room {
            winners.sort_by_key(|w| pair_key(&as_best(w), w.v));
            winners.truncate(room);
            winners.sort_unstable_by_key(|w| w.v);
        }
        let mut collapses: Vec<Collapse> = Vec::with_capacity(winners.len());
        let mut merged = Vec::with_capacity(winners.len());
        let mut removed = Vec::new();
        let mut fans = [Fan::default(), Fan::default()];
        let mut step_error = 0.0f64;
        let mut rejected = 0usize;
        for w in &winners {
            let b = as_best(w);
            match try_apply_collapse(&mut s, w.v, b, w.target, &mut fans) {
                Some((collapse, plan)) => {
                    step_error = step_error.max(b.error);
                    merged.push(w.v);
                    removed.extend([plan.left, plan.right].into_iter().filter(|&c| c != NONE));
                    collapses.push(collapse);
                }
                None => rejected += 1,
            }
        }
        rejected_total += rejected;
        if collapses.is_empty() {
            // Every winner failed the f64 check: the device would choose
            // them again, so stop here rather than spin.
            break;
        }
        let (triangles, vertices) = changes(&s, &collapses, &removed);
        engine.update(&base, &triangles, &vertices)?;
        live.retain(|&v| s.alive[v as usize]);
        mark_two_rings(&s, &merged, &mut dirty);
        dirty_list.clear();
        dirty_list.extend(live.iter().copied().filter(|&v| dirty[v as usize]));
        if debug {
            eprintln!(
                "{api} step {}: alive {alive_count}, collapses {}, rejected by the f64 check {rejected}, dirty {}",
                steps.len(),
                collapses.len(),
                dirty_list.len()
            );
        }
        alive_count -= collapses.len();
        steps.push(collapses);
        step_errors.push(step_error);
        progress(n - alive_count);
    }
    if debug {
        eprintln!("{api}: {rejected_total} device winners rejected by the f64 check");
    }
    Ok(Simplification {
        steps,
        table: s.table,
        positions: s.positions,
        split_valence: s.split_valence,
        alive: s.alive,
        alive_count,
        step_errors,
    })
}

/// Position and flags of vertex `v` as the kernels store them.
fn vertex_words(s: &State, v: usize) -> [u32; 4] {
    let p = s.positions[v];
    let flags = if s.alive[v] { ALIVE } else { 0 } | if s.boundary[v] { BOUNDARY } else { 0 };
    [p[0], p[1], p[2], flags]
}

/// A quadric in the frame at `o` (f32, a2 ab ac ad b2 bc bd c2 cd d2) moved
/// to the global frame in f64: q(x - o).
fn to_global(q: &[f32; 10], o: [f64; 3]) -> Quadric {
    let c = q.map(f64::from);
    let a = [[c[0], c[1], c[2]], [c[1], c[4], c[5]], [c[2], c[5], c[7]]];
    let b = [c[3], c[6], c[8]];
    let ao: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| a[i][j] * o[j]).sum());
    let d = crate::quadric::dot(o, ao) - 2.0 * crate::quadric::dot(b, o) + c[9];
    let nb: [f64; 3] = std::array::from_fn(|i| b[i] - ao[i]);
    Quadric {
        c: [c[0], c[1], c[2], nb[0], c[4], c[5], nb[1], c[7], nb[2], d],
    }
}

/// A global quadric in the frame at `o`, in f32: x -> q(x + o).
fn to_local(q: &Quadric, o: [f64; 3]) -> [f32; 10] {
    let c = q.c;
    let a = [[c[0], c[1], c[2]], [c[1], c[4], c[5]], [c[2], c[5], c[7]]];
    let b = [c[3], c[6], c[8]];
    let ao: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| a[i][j] * o[j]).sum());
    let nb: [f64; 3] = std::array::from_fn(|i| b[i] + ao[i]);
    let d = crate::quadric::dot(o, ao) + 2.0 * crate::quadric::dot(b, o) + c[9];
    [c[0], c[1], c[2], nb[0], c[4], c[5], nb[1], c[7], nb[2], d].map(|x| x as f32)
}

/// The triangles and vertices a step's collapses rewrote: every triangle
/// around each merged vertex (their corners moved to it, their opposites
/// across the folded edges changed), the removed triangles, and the merged,
/// removed and wing vertices (corners re-anchored).
fn changes(
    s: &State,
    collapses: &[Collapse],
    removed: &[u32],
) -> (Vec<TriangleUpdate>, Vec<VertexUpdate>) {
    let mut triangles: Vec<u32> = removed.iter().map(|&c| c / 3).collect();
    let mut vertices = Vec::with_capacity(4 * collapses.len());
    let mut fan = Fan::default();
    for c in collapses {
        s.table.fan(c.p, &mut fan);
        triangles.extend(fan.corners.iter().map(|&k| k / 3));
        vertices.extend(
            [c.p, c.c, c.wing_a, c.wing_b]
                .into_iter()
                .filter(|&v| v != NONE),
        );
    }
    triangles.sort_unstable();
    triangles.dedup();
    vertices.sort_unstable();
    vertices.dedup();
    let triangles = triangles
        .into_iter()
        .map(|t| {
            let k = 3 * t as usize;
            TriangleUpdate {
                triangle: t,
                vertex: std::array::from_fn(|i| s.table.vertex[k + i]),
                opposite: std::array::from_fn(|i| s.table.opposite[k + i]),
            }
        })
        .collect();
    let vertices = vertices
        .into_iter()
        .map(|v| {
            let words = vertex_words(s, v as usize);
            VertexUpdate {
                vertex: v,
                position: [words[0], words[1], words[2]],
                flags: words[3],
                corner_of: s.table.corner_of[v as usize],
                quadric: to_local(&s.quadrics[v as usize], s.geometry(v)),
            }
        })
        .collect();
    (triangles, vertices)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_round_trip() {
        let q = Quadric::from_plane([0.6, 0.0, 0.8], -3.0, 2.0)
            + Quadric::from_plane([0.0, 1.0, 0.0], 1.0, 0.5);
        let o = [10.0, -4.0, 7.0];
        let local = to_local(&q, o);
        let back = to_global(&local, o);
        for p in [[10.0, -4.0, 7.0], [11.0, -3.5, 7.25]] {
            let want = q.error(p);
            assert!((back.error(p) - want).abs() < 1e-4 * (1.0 + want), "{p:?}");
        }
        // In the local frame the vertex sits at the origin.
        let e0 = local[9] as f64;
        assert!((e0 - q.error(o)).abs() < 1e-4 * (1.0 + e0));
    }
}
