//! The parallel simplifier with its data-parallel passes on a GPU backend
//! (kernels in `splitstream-kernels`), a hybrid:
//!
//! | step | where |
//! |---|---|
//! | corner table, boundary flags | CPU, once |
//! | quadric init (per-vertex gather) | device, once; read back to f64 |
//! | best edge per dirty vertex: error, optimal position with fallback, validity | device |
//! | threshold S (quantile of the candidate errors) | CPU, from the live vertices' errors (`live_errors`, 4 bytes a live vertex) |
//! | reciprocity + local minimum with index priority, 3 passes with re-picks | device |
//! | applying the collapses (corner-table surgery, records), re-checked in f64 | CPU, in parallel |
//! | 2-ring dirty marking; upload of changed triangles and vertices | CPU (in parallel) → device |
//!
//! The device works in f32 in frames local to each vertex, so its errors and
//! positions differ from the CPU's by rounding; the CPU re-checks every
//! winner with `check_collapse` in f64 before applying it and skips the
//! rare one it rejects ([`apply_winners`]). The emitted stream is then
//! checked by the replay like any other (`emit`), so it decodes exactly
//! whatever the device did.

use std::sync::atomic::AtomicU32;
use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;
use splitstream_kernels::encode::layout::{
    self, ALIVE, BOUNDARY, CONSTRAINED, LOCKED, Params, TriangleUpdate, VertexUpdate,
};
use splitstream_kernels::encode::{Engine, Updates};
use splitstream_kernels::gpu::{Api, GpuError};

use super::apply::apply_collapses;
use super::check::{CheckScratch, check_collapse};
use super::meter::EdgeMeter;
use super::parallel::par_chunks_map;
use super::phases::Phases;
use super::refresh::mark_two_rings;
use super::select::{Best, pair_key};
use super::state::{Collapse, MAX_VALENCE, Simplification, SimplifyOptions, State};
use super::winners::Winner;
use crate::corner_table::NONE;
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
    let mut phases = Phases::default();
    phases.lap("");
    let mut s = State::new(mesh, options);
    phases.lap("state");
    let corners: Vec<[u32; 2]> = s
        .table
        .vertex
        .par_iter()
        .zip(&s.table.opposite)
        .map(|(&v, &o)| [v, o])
        .collect();
    let vertices: Vec<[u32; 4]> = (0..n)
        .into_par_iter()
        .map(|v| vertex_words(&s, v))
        .collect();
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
    phases.lap("open");
    let debug = std::env::var_os("SPLITSTREAM_DEBUG").is_some();
    if debug {
        eprintln!("{api} open: {}", engine.open_times());
    }
    let local = engine.quadric_init(&base)?;
    s.quadrics = local
        .par_iter()
        .enumerate()
        .map(|(v, q)| to_global(q, s.geometry(v as u32)))
        .collect();

    let mut alive_count = s.alive.iter().filter(|&&a| a).count();
    let mut steps = Vec::new();
    let mut step_errors = Vec::new();
    let mut threshold = 0.0f64;
    let mut live: Vec<u32> = (0..n as u32).filter(|&v| s.alive[v as usize]).collect();
    let mut dirty_list = live.clone();
    // Per vertex, the last step that found it in a merged vertex's 2-ring.
    let dirty: Vec<AtomicU32> = (0..n).map(|_| AtomicU32::new(0)).collect();
    let limit = options.max_error.unwrap_or(f64::INFINITY);
    let mut meter = EdgeMeter::new(&s);
    let (mut edge, mut edge_measured_at) = (meter.measure(&s), alive_count);
    let mut rejected_total = 0usize;
    // Per vertex, the lowest winner whose neighbourhood holds it, during
    // `apply_winners` (NO_CLAIM otherwise).
    let claims: Vec<AtomicU32> = (0..n).map(|_| AtomicU32::new(NO_CLAIM)).collect();
    let mut updates = Updates::default();
    phases.lap("quadrics");
    while alive_count > options.target_vertices {
        if alive_count * 5 < edge_measured_at * 4 {
            edge = meter.measure(&s);
            edge_measured_at = alive_count;
        }
        base.cell = (options.subgrid_cells * edge) as f32;
        // f32 errors carry ~1e-7 relative noise of terms ~ edge^4: below
        // 1e-6 edge^4 they are flat (the CPU uses 1e-8 in f64).
        base.flat_error = (1e-6 * edge.powi(4)) as f32;
        phases.lap("measure");
        engine.best_edges(&base, &dirty_list)?;
        engine.set_live(&live)?;
        let mut errors = engine.live_errors(&base)?;
        phases.lap("best edges");
        if errors.is_empty() {
            break;
        }
        let q = ((errors.len() - 1) as f64 * options.admit_quantile.clamp(0.0, 1.0)) as usize;
        let (_, quantile, _) = errors.select_nth_unstable_by(q, f64::total_cmp);
        threshold = threshold.max(*quantile).min(limit);
        phases.lap("quantile");
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
        phases.lap("select");
        let room = alive_count - options.target_vertices;
        if winners.len() > room {
            winners.sort_by_key(|w| pair_key(&as_best(w), w.v));
            winners.truncate(room);
            // Back in ascending survivor id, the order `Engine::select`
            // returns and `apply_winners` keeps the first of overlapping
            // winners in.
            winners.sort_unstable_by_key(|w| w.v);
        }
        let applied = apply_winners(&mut s, &winners, &claims);
        let rejected = applied.refused + applied.overlapping;
        rejected_total += rejected;
        if applied.collapses.is_empty() {
            // Every winner failed the f64 check: the device would choose
            // them again, so stop here rather than spin.
            break;
        }
        phases.lap("apply");
        changes(&s, &applied, &mut updates);
        phases.lap("changes");
        engine.update(&base, &updates)?;
        phases.lap("update");
        let merged: Vec<u32> = applied.winners.iter().map(|w| w.p).collect();
        live = live
            .par_iter()
            .copied()
            .filter(|&v| s.alive[v as usize])
            .collect();
        let stamp = steps.len() as u32 + 1;
        mark_two_rings(&s, &merged, &dirty, stamp);
        dirty_list = live
            .par_iter()
            .copied()
            .filter(|&v| dirty[v as usize].load(Relaxed) == stamp)
            .collect();
        phases.lap("dirty");
        let collapses = applied.collapses;
        let step_error = applied
            .winners
            .iter()
            .map(|w| w.best.error)
            .fold(0.0f64, f64::max);
        if debug {
            eprintln!(
                "{api} step {}: alive {alive_count}, collapses {}, refused by the f64 check {}, overlapping {}, dirty {}",
                steps.len(),
                collapses.len(),
                applied.refused,
                applied.overlapping,
                dirty_list.len()
            );
        }
        alive_count -= collapses.len();
        steps.push(collapses);
        step_errors.push(step_error);
        progress(n - alive_count);
    }
    if debug {
        eprintln!(
            "{api}: {rejected_total} device winners refused by the f64 check or overlapping a kept one"
        );
        eprintln!("{api} {}", phases.report());
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

/// The device's winners of one step that the CPU kept and applied.
struct Applied {
    winners: Vec<Winner>,
    /// The fans of P then C of each kept winner, before its collapse
    /// ([`Winner::fans`] indexes them).
    fans: Vec<u32>,
    collapses: Vec<Collapse>,
    /// Winners the f64 check refused.
    refused: usize,
    /// Valid winners dropped because a lower valid winner's neighbourhood
    /// held one of their endpoints.
    overlapping: usize,
}

/// One chunk of [`apply_winners`]' parallel checks: the valid winners with
/// their fans (offsets into `corners`) and their neighbourhoods (ranges of
/// `hood`).
#[derive(Default)]
struct CheckedChunk {
    valid: Vec<(Winner, (u32, u32))>,
    corners: Vec<u32>,
    hood: Vec<u32>,
    refused: usize,
}

/// No winner's neighbourhood holds the vertex (see [`apply_winners`]).
const NO_CLAIM: u32 = u32::MAX;

/// Checks the device's winners again in f64, keeps those that touch
/// disjoint neighbourhoods, and applies them in parallel.
///
/// The device chooses in f32 and its output is not trusted: each winner is
/// checked (`check_collapse`) against the mesh as the step found it, as the
/// CPU backend checks its own. Then every valid winner claims its
/// neighbourhood (its endpoints and their neighbours) in `claims`, the
/// lowest index winning, and a winner is kept only if it holds both its
/// endpoints: no lower winner's neighbourhood holds one. Two kept winners
/// thus never have an endpoint in each other's neighbourhood (if one had,
/// the neighbour relation being symmetric, the lower one's neighbourhood
/// would hold an endpoint of the higher), which is the CPU backend's
/// blocking rule and what `apply_collapses`' parallel writes need: kept
/// collapses share no endpoint and no triangle. `claims` is left as found
/// (all `NO_CLAIM`).
fn apply_winners(s: &mut State, winners: &[layout::Winner], claims: &[AtomicU32]) -> Applied {
    let s_now: &State = s;
    let chunks: Vec<CheckedChunk> = par_chunks_map(winners, |chunk| {
        let mut scratch = CheckScratch::default();
        let mut out = CheckedChunk::default();
        for w in chunk {
            if !names_a_live_edge(s_now, w) {
                out.refused += 1;
                continue;
            }
            let target = s_now.to_metric(w.target);
            let Ok(plan) = check_collapse(s_now, w.v, w.other, target, &mut scratch) else {
                out.refused += 1;
                continue;
            };
            let (fan_p, fan_c) = scratch.fans();
            let start = out.corners.len() as u32;
            out.corners.extend_from_slice(&fan_p.corners);
            out.corners.extend_from_slice(&fan_c.corners);
            let hood_start = out.hood.len() as u32;
            out.hood.extend(scratch.neighbourhood());
            let winner = Winner {
                p: w.v,
                best: as_best(w),
                target: w.target,
                plan,
                fans: (
                    start,
                    fan_p.corners.len() as u32,
                    fan_c.corners.len() as u32,
                ),
            };
            out.valid
                .push((winner, (hood_start, out.hood.len() as u32)));
        }
        out
    });
    // Each valid winner's index among the valid ones, in winner order.
    let firsts: Vec<u32> = chunks
        .iter()
        .scan(0u32, |at, chunk| {
            let first = *at;
            *at += chunk.valid.len() as u32;
            Some(first)
        })
        .collect();
    let hoods = || {
        chunks
            .par_iter()
            .zip(&firsts)
            .flat_map_iter(|(chunk, &first)| {
                chunk
                    .valid
                    .iter()
                    .enumerate()
                    .map(move |(i, (_, (from, to)))| {
                        (first + i as u32, &chunk.hood[*from as usize..*to as usize])
                    })
            })
    };
    hoods().for_each(|(index, hood)| {
        for &x in hood {
            claims[x as usize].fetch_min(index, Relaxed);
        }
    });
    let holds = |index: u32, w: &Winner| {
        [w.p, w.best.other]
            .iter()
            .all(|&x| claims[x as usize].load(Relaxed) == index)
    };
    let kept_flags: Vec<Vec<bool>> = chunks
        .par_iter()
        .zip(&firsts)
        .map(|(chunk, &first)| {
            let valid = chunk.valid.iter().enumerate();
            valid
                .map(|(i, (w, _))| holds(first + i as u32, w))
                .collect()
        })
        .collect();
    hoods().for_each(|(_, hood)| {
        for &x in hood {
            claims[x as usize].store(NO_CLAIM, Relaxed);
        }
    });
    let mut kept = Vec::with_capacity(winners.len());
    let mut fans = Vec::new();
    let (mut refused, mut overlapping) = (0, 0);
    for (chunk, flags) in chunks.into_iter().zip(kept_flags) {
        refused += chunk.refused;
        let base = fans.len() as u32;
        fans.extend_from_slice(&chunk.corners);
        for ((mut winner, _), keep) in chunk.valid.into_iter().zip(flags) {
            if !keep {
                overlapping += 1;
                continue;
            }
            winner.fans.0 += base;
            kept.push(winner);
        }
    }
    let collapses = apply_collapses(s, &kept, &fans);
    Applied {
        winners: kept,
        fans,
        collapses,
        refused,
        overlapping,
    }
}

/// Whether a device winner names two distinct live vertices and a target on
/// the quantization grid: what must hold before `check_collapse` walks
/// their fans (it then refuses a pair that is not an edge).
fn names_a_live_edge(s: &State, w: &layout::Winner) -> bool {
    let live = |v: u32| s.alive.get(v as usize).copied().unwrap_or(false);
    let top = (1u64 << s.bits) - 1;
    w.v != w.other && live(w.v) && live(w.other) && w.target.iter().all(|&x| u64::from(x) <= top)
}

/// A device winner as the CPU's request of P.
fn as_best(w: &layout::Winner) -> Best {
    Best {
        other: w.other,
        error: w.error as f64,
        error_key: w.key,
        corner: NONE,
    }
}

/// Fills `updates` with the triangles and vertices a step's collapses
/// rewrote: every triangle around each merged vertex (their corners moved to
/// it, their opposites across the folded edges changed), the removed
/// triangles, and the merged, removed and wing vertices (corners
/// re-anchored).
///
/// The triangles are those of P's and C's fans before the collapse, which
/// its check walked: the merged vertex's fan after it plus the removed
/// ones, with no walk.
fn changes(s: &State, applied: &Applied, updates: &mut Updates) {
    let kept = &applied.winners;
    let mut triangles: Vec<u32> = kept
        .par_iter()
        .flat_map_iter(|w| {
            let (start, np, nc) = (w.fans.0 as usize, w.fans.1 as usize, w.fans.2 as usize);
            applied.fans[start..start + np + nc].iter().map(|&k| k / 3)
        })
        .collect();
    let mut vertices: Vec<u32> = kept
        .par_iter()
        .flat_map_iter(|w| [w.p, w.best.other, w.plan.wing_a, w.plan.wing_b])
        .filter(|&v| v != NONE)
        .collect();
    triangles.par_sort_unstable();
    triangles.dedup();
    vertices.par_sort_unstable();
    vertices.dedup();
    let (triangle_updates, vertex_updates) = updates.fill(triangles.len(), vertices.len());
    triangle_updates
        .par_iter_mut()
        .zip(&triangles)
        .for_each(|(u, &t)| {
            let k = 3 * t as usize;
            *u = TriangleUpdate {
                triangle: t,
                vertex: std::array::from_fn(|i| s.table.vertex[k + i]),
                opposite: std::array::from_fn(|i| s.table.opposite[k + i]),
            };
        });
    vertex_updates
        .par_iter_mut()
        .zip(&vertices)
        .for_each(|(u, &v)| {
            let words = vertex_words(s, v as usize);
            *u = VertexUpdate {
                vertex: v,
                position: [words[0], words[1], words[2]],
                flags: words[3],
                corner_of: s.table.corner_of[v as usize],
                quadric: to_local(&s.quadrics[v as usize], s.geometry(v)),
            };
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corner_table::{Fan, next};
    use crate::input::fractal_terrain;
    use crate::quantize::{Units, quantize};
    use crate::simplify::state::live_mesh;

    /// A device winner collapsing `c` into `p` at `p`'s position.
    fn winner(s: &State, p: u32, c: u32) -> layout::Winner {
        layout::Winner {
            v: p,
            other: c,
            error: 0.0,
            key: 0,
            target: s.positions[p as usize],
        }
    }

    /// The state of a 16 x 16 terrain as the GPU loop starts from.
    fn terrain_state() -> State {
        terrain().1
    }

    fn terrain() -> (QuantizedMesh, State) {
        let q = quantize(&fractal_terrain(16, 3), 14, Units::Linear);
        let options = SimplifyOptions::default();
        let mut s = State::new(&q, &options);
        s.quadrics = s
            .fan_quadrics(options.boundary_weight)
            .expect("a manifold terrain");
        (q, s)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

        /// Whatever the device returns (vertices dead, missing or repeated,
        /// pairs that are no edge or overlap, targets anywhere on or off
        /// the grid, in any order), the host applies only collapses that
        /// leave a manifold mesh of the same topology, one vertex fewer each.
        #[test]
        fn any_device_winners_leave_a_manifold_of_the_same_topology(
            steps in proptest::collection::vec(
                proptest::collection::vec((0u32..300, 0u32..300, 0u8..8), 0..48),
                1..5,
            )
        ) {
            let (q, mut s) = terrain();
            let claims = no_claims(&s);
            let before = check_mesh_of(&s, &q);
            let mut collapses = 0;
            for step in steps {
                let winners: Vec<layout::Winner> = step
                    .iter()
                    .map(|&(v, pick, kind)| {
                        // Mostly a real edge of a live vertex (kinds 0-5),
                        // else any pair.
                        let live = s.alive.get(v as usize).copied().unwrap_or(false);
                        let ring = if live { neighbours(&s, v) } else { Vec::new() };
                        let other = match ring.len() {
                            len if kind < 6 && len > 0 => ring[pick as usize % len],
                            _ => pick,
                        };
                        let position = |x: u32| s.positions.get(x as usize).copied();
                        let target = match pick % 4 {
                            0 => position(v),
                            1 => position(other),
                            2 => Some([v * 50, other * 50, 1 << 14]),
                            _ => position(v).zip(position(other)).map(|(a, b)| {
                                std::array::from_fn(|k| (a[k] + b[k]) / 2)
                            }),
                        };
                        layout::Winner {
                            v,
                            other,
                            error: 0.0,
                            key: 0,
                            target: target.unwrap_or([0; 3]),
                        }
                    })
                    .collect();
                let applied = apply_winners(&mut s, &winners, &claims);
                proptest::prop_assert_eq!(
                    applied.collapses.len() + applied.refused + applied.overlapping,
                    winners.len()
                );
                collapses += applied.collapses.len();
            }
            let after = check_mesh_of(&s, &q);
            proptest::prop_assert_eq!(after.vertices, before.vertices - collapses);
            proptest::prop_assert_eq!(after.euler_characteristic, before.euler_characteristic);
            proptest::prop_assert_eq!(after.boundary_loops, before.boundary_loops);
            proptest::prop_assert_eq!(after.components, 1);
            proptest::prop_assert!(claims.iter().all(|c| c.load(Relaxed) == NO_CLAIM));
        }
    }

    fn check_mesh_of(s: &State, q: &QuantizedMesh) -> crate::input::MeshStats {
        crate::input::check_mesh(&live_mesh(&s.table, &s.alive, &s.positions, q))
            .expect("a manifold mesh")
    }

    fn no_claims(s: &State) -> Vec<AtomicU32> {
        (0..s.alive.len())
            .map(|_| AtomicU32::new(NO_CLAIM))
            .collect()
    }

    fn neighbours(s: &State, v: u32) -> Vec<u32> {
        let mut fan = Fan::default();
        s.table.fan(v, &mut fan);
        fan.corners.iter().map(|&k| s.table.v(next(k))).collect()
    }

    #[test]
    fn overlapping_device_winners_keep_the_first() {
        let mut s = terrain_state();
        // An interior vertex, one of its neighbours, and a second pair whose
        // survivor is another neighbour: it lies in the first pair's
        // neighbourhood, so only the first may be kept. A third pair far
        // away is independent of both.
        let p = 5 * 16 + 5;
        let ring = neighbours(&s, p);
        let (c, p2) = (ring[0], ring[2]);
        let c2 = *neighbours(&s, p2)
            .iter()
            .find(|&&x| x != p && !ring.contains(&x))
            .expect("a neighbour of p2 outside p's ring");
        let far = 12 * 16 + 12;
        let far_c = neighbours(&s, far)[0];
        let mut winners = vec![winner(&s, p, c), winner(&s, p2, c2), winner(&s, far, far_c)];
        winners.sort_unstable_by_key(|w| w.v);
        let alive_before = s.alive.iter().filter(|&&a| a).count();
        let claims = no_claims(&s);
        let applied = apply_winners(&mut s, &winners, &claims);
        assert_eq!(applied.refused, 0);
        assert_eq!(applied.overlapping, 1);
        let kept: Vec<u32> = applied.winners.iter().map(|w| w.p).collect();
        let first = p.min(p2);
        assert_eq!(
            kept,
            [first, far],
            "the lower survivor of the overlapping pair is kept"
        );
        assert_eq!(applied.collapses.len(), 2);
        let alive_after = s.alive.iter().filter(|&&a| a).count();
        assert_eq!(alive_before - alive_after, 2);
        // Claims last for one call: the dropped pair alone is kept at the
        // next step.
        assert!(claims.iter().all(|c| c.load(Relaxed) == NO_CLAIM));
        let dropped = if first == p { (p2, c2) } else { (p, c) };
        let w = winner(&s, dropped.0, dropped.1);
        let again = apply_winners(&mut s, &[w], &claims);
        assert_eq!(
            (again.refused, again.overlapping, again.collapses.len()),
            (0, 0, 1)
        );
    }

    #[test]
    fn device_garbage_is_refused_not_applied() {
        let mut s = terrain_state();
        let p = 5 * 16 + 5;
        let ring = neighbours(&s, p);
        let far = 12 * 16 + 12;
        let mut off_grid = winner(&s, p, ring[0]);
        off_grid.target[2] = 1 << 14;
        let garbage = [
            winner(&s, p, p),         // not a pair
            winner(&s, p, far),       // not an edge
            winner(&s, p, 4_000_000), // no such vertex
            off_grid,                 // off the grid
        ];
        let n = s.alive.len();
        let claims = no_claims(&s);
        for (i, w) in garbage.iter().enumerate() {
            let applied = apply_winners(&mut s, std::slice::from_ref(w), &claims);
            assert_eq!(
                (applied.refused, applied.collapses.len()),
                (1, 0),
                "case {i}"
            );
        }
        // A collapse applied, then a winner naming its removed vertex.
        let w = winner(&s, p, ring[0]);
        let applied = apply_winners(&mut s, &[w], &claims);
        assert_eq!(applied.collapses.len(), 1);
        let w = winner(&s, ring[1], ring[0]);
        let dead = apply_winners(&mut s, &[w], &claims);
        assert_eq!((dead.refused, dead.collapses.len()), (1, 0));
        assert_eq!(s.alive.iter().filter(|&&a| a).count(), n - 1);
    }

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
