//! The CPU backend's step loop: best edges, reciprocity and local minima
//! per step (§2 steps a-c), then the winners applied and their edges
//! refreshed, until the target.

use rayon::prelude::*;

use super::apply::apply_collapses;
use super::check::check_collapse;
use super::compact::{Renumbered, compact};
use super::meter::EdgeMeter;
use super::offers::{choose, take_offers};
use super::parallel::par_filter_into;
use super::phases::Phases;
use super::quantile::admission;
use super::refresh::{RefreshChunk, refresh_edges};
use super::select::{EdgeSlot, Scale, edge_slot, pair_key};
use super::state::{NO_SPLIT, Simplification, SimplifyOptions, State};
use super::tracking::Tracking;
use super::winners::{Buffers, Step, Tally, step_winners};
use crate::corner_table::{CornerTable, NONE};
use crate::quadric::vertex_quadrics;
use crate::quantize::QuantizedMesh;

/// Share of refused checks above which a step checks its players' requests
/// before they pair up (`validate`): about 0.3 % on the meshes, 2–3 % on a
/// terrain whose x and y stay on the raster's lattice, 10–20 % on a DEM read
/// in degrees and metres (the Jacksboro DEM without `--geographic`). At
/// 2 % the lattice terrain validated every step, 25 % of its simplification
/// time for the same collapses (encoder/BENCHMARKS.md, Speed).
const VALIDATE_ABOVE: f64 = 0.05;

/// Simplifies `mesh` (quantized, checked manifold: [`super::Checked`]) with
/// the parallel algorithm.
pub(crate) fn simplify(
    mesh: &QuantizedMesh,
    options: &SimplifyOptions,
    mut progress: impl FnMut(usize),
) -> Simplification {
    let n = mesh.positions.len();
    let mut phases = Phases::default();
    phases.lap("");
    let mut s = State::new(mesh, options);
    phases.lap("table");
    s.quadrics = s.fan_quadrics(options.boundary_weight).unwrap_or_else(|| {
        let geometry: Vec<[f64; 3]> = (0..n as u32).map(|v| s.geometry(v)).collect();
        vertex_quadrics(&geometry, &mesh.triangles, options.boundary_weight)
    });
    phases.lap("quadrics");
    s.edges = initial_slots(&s);
    phases.lap("slots");
    let mut alive_count = s.alive.iter().filter(|&&a| a).count();
    let mut steps = Vec::new();
    let mut step_errors = Vec::new();
    let mut threshold = 0.0f64;
    let mut t = Tracking::new(n);
    let mut live: Vec<u32> = (0..n as u32).filter(|&v| s.alive[v as usize]).collect();
    // Who chooses at the start of a step (all vertices at the first): see
    // `refresh_edges` and `step_winners`; `offers` are the edges refreshed
    // by the last step's collapses, for their other ends.
    let mut choosers = live.clone();
    let mut offers: Vec<RefreshChunk> = Vec::new();
    let mut buffers = Buffers::default();
    // Recent refused checks and checks (see `VALIDATE_ABOVE`).
    let mut refusals = (0.0f64, 0.0f64);
    let limit = options.max_error.unwrap_or(f64::INFINITY);
    let debug = std::env::var_os("SPLITSTREAM_DEBUG").is_some();
    // The mean edge length sets the sub-grid and the flat threshold; it
    // changes slowly, so it is measured again only when a fifth of the
    // vertices are gone since the last measure (a full pass over the corners).
    let mut meter = EdgeMeter::new(&s);
    let (mut edge, mut edge_measured_at) = (meter.measure(&s), alive_count);
    // Positions and split valences by input id, of the vertices renumbered
    // away (see `compact`).
    let mut input = InputArrays {
        positions: mesh.positions.clone(),
        split_valence: vec![NO_SPLIT; n],
    };
    while alive_count > options.target_vertices {
        let state = steps.len() as u32 + 1;
        phases.lap("loop");
        if alive_count * 5 < edge_measured_at * 4 {
            let old_flat = flat_of(edge);
            edge = meter.measure(&s);
            edge_measured_at = alive_count;
            // The sub-grid and the flat threshold change with the scale:
            // every request that they can change chooses again under the
            // new one. (Requests kept from the old scale would compare keys
            // and cells of two scales; on a DEM in degrees and metres, where
            // the flat threshold is above most errors and the tie-breaks
            // decide, the steps then found few collapses each.)
            let bound = old_flat.max(flat_of(edge));
            let tr: &Tracking = &t;
            let mut changes = Vec::new();
            par_filter_into(&live, &mut changes, |&v| {
                // Listed vertices choose anyway, but for those the last
                // step merged: they chose then, under the old scale.
                let listed = tr.listed[v as usize] == state;
                if listed && tr.merged[v as usize] != state {
                    return None;
                }
                match rescaled(tr, v, bound) {
                    Rescaled::Kept => None,
                    change => Some((v, change)),
                }
            });
            let mut chose = 0usize;
            for &(v, change) in &changes {
                if change == Rescaled::Chooses {
                    t.listed[v as usize] = state;
                    choosers.push(v);
                    chose += 1;
                } else {
                    t.second[v as usize] = None;
                }
            }

            if debug {
                eprintln!("rescale: {chose} of {} requests choose again", live.len());
            }
        }
        let scale = Scale {
            cell: options.subgrid_cells * edge,
            flat: flat_of(edge),
        };
        let t_best = std::time::Instant::now();
        phases.lap("measure");
        let offered = take_offers(&s, &mut t, &offers, &mut choosers, scale, state);
        phases.lap("offers");
        let reopened = choose(&s, &mut t, &choosers, scale, state);
        phases.lap("choose");
        // Neighbours whose refused edge to a changed vertex may be valid
        // again choose too (they reopen nothing themselves: their own 1-ring
        // did not change).
        let again: Vec<u32> = reopened
            .into_iter()
            .filter(|&u| std::mem::replace(&mut t.listed[u as usize], state) != state)
            .collect();
        choose(&s, &mut t, &again, scale, state);
        let chose = choosers.len() + again.len();
        buffers.tally = Tally::default();
        // Check requests before they pair up only where they are often
        // invalid (see `validate`): on well-shaped meshes one check in a few
        // hundred fails, and checking every request would cost more than the
        // lazy refusals.
        let validating = refusals.0 > VALIDATE_ABOVE * refusals.1;
        // Raise S to the admitted quantile of the current candidate errors.
        let tr: &Tracking = &t;
        let candidate = |v: u32| {
            let b = &tr.best[v as usize];
            (b.other != NONE).then_some(b.error)
        };
        let Some(admission) = admission(&live, candidate, options.admit_quantile) else {
            break;
        };
        threshold = threshold.max(admission.quantile).min(limit);
        let largest = admission.largest;
        // Raising S starts from the smallest error above 0: errors of 0 pass
        // any S, and doubling up from the smallest positive float took about
        // a thousand empty steps (15 s on a DEM whose triangles were all
        // degenerate, where every candidate was refused).
        let smallest = admission.smallest_positive;
        let t_select = std::time::Instant::now();
        phases.lap("quantile");
        choosers.clear();
        // Nothing under S: raise it (the paper's "S is increased"), doubling
        // past the smallest candidate error, until a step finds collapses or
        // S passes every candidate error or the maximum error.
        let mut winners = loop {
            let found = step_winners(
                &mut s,
                &mut t,
                &live,
                Step {
                    state,
                    threshold,
                    scale,
                    validating,
                },
                &mut choosers,
                &mut buffers,
                &mut phases,
            );
            let can_raise = threshold < limit && threshold < largest;
            if !found.is_empty() || !can_raise {
                break found;
            }
            threshold = (2.0 * threshold)
                .max(if smallest.is_finite() { smallest } else { 0.0 })
                .max(f64::MIN_POSITIVE)
                .min(limit);
        };
        if winners.is_empty() {
            break;
        }
        // Hit the target exactly: keep the cheapest collapses of the last step.
        let room = alive_count - options.target_vertices;
        if winners.len() > room {
            winners.sort_by_key(|w| pair_key(&w.best, w.p));
            winners.truncate(room);
            winners.sort_unstable_by_key(|w| w.p);
        }
        let t_apply = std::time::Instant::now();
        phases.lap("select");
        if cfg!(debug_assertions) {
            for w in &winners {
                let target = s.to_metric(w.target);
                let check = check_collapse(&s, w.p, w.best.other, target, &mut Default::default());
                assert_eq!(
                    check,
                    Ok(w.plan),
                    "a winner's check holds at the end of its step"
                );
            }
        }
        let step_error = winners.iter().fold(0.0f64, |e, w| e.max(w.best.error));
        let collapses = apply_collapses(&mut s, &winners, &buffers.fans);
        let t_refresh = std::time::Instant::now();
        phases.lap("apply");
        let merged: Vec<u32> = winners.iter().map(|w| w.p).collect();
        // The merged vertices choose under this step's scale; should the
        // next step measure edges again, its rescale sorts them like the
        // other requests.
        refresh_edges(&mut s, &mut t, &merged, state + 1, scale, &mut offers);
        phases.lap("refresh");
        live.retain(|&v| s.alive[v as usize]);
        phases.lap("retain");
        // Renumber densely once half the vertices are gone: the passes then
        // read whole cache lines of live data instead of scattered ones.
        if live.len() * 2 < s.positions.len() {
            let pairs: Vec<(u32, u32)> = winners.iter().map(|w| (w.p, w.best.other)).collect();
            compact(
                &mut s,
                &mut t,
                Renumbered {
                    live: &mut live,
                    pairs: &pairs,
                    choosers: &mut choosers,
                    offers: &mut offers,
                    meter: &mut meter,
                    input: &mut input,
                },
            );
            phases.lap("compact");
        }
        if debug {
            let ms = |a: std::time::Instant, b: std::time::Instant| (b - a).as_secs_f64() * 1e3;
            let now = std::time::Instant::now();
            eprintln!(
                "step {}: alive {alive_count}, collapses {}, chose {chose}, offered {offered}, validated {} refused {}, ms: best {:.1} select {:.1} apply {:.1} refresh {:.1}",
                steps.len(),
                winners.len(),
                buffers.tally.checks,
                buffers.tally.refused,
                ms(t_best, t_select),
                ms(t_select, t_apply),
                ms(t_apply, t_refresh),
                ms(t_refresh, now),
            );
        }
        // Refusals per check, decaying by half a step.
        refusals = (
            0.5 * refusals.0 + buffers.tally.refused as f64,
            0.5 * refusals.1 + buffers.tally.checks as f64,
        );
        alive_count -= collapses.len();
        steps.push(collapses);
        step_errors.push(step_error);
        progress(n - alive_count);
    }
    if debug {
        eprintln!("{}", phases.report());
    }
    // Back to input ids.
    input.save(&s);
    let mut alive = vec![false; n];
    let mut corner_of = vec![NONE; n];
    for (i, &v) in s.orig.iter().enumerate() {
        alive[v as usize] = s.alive[i];
        corner_of[v as usize] = s.table.corner_of[i];
    }
    let orig = &s.orig;
    let vertex = s
        .table
        .vertex
        .par_iter()
        .map(|&v| if v == NONE { NONE } else { orig[v as usize] })
        .collect();
    Simplification {
        steps,
        table: CornerTable {
            vertex,
            opposite: s.table.opposite,
            corner_of,
        },
        positions: input.positions,
        split_valence: input.split_valence,
        alive,
        alive_count,
        step_errors,
    }
}

/// Per input id, the positions and split valences of the vertices as they
/// were last renumbered (a vertex's never change once it is gone).
pub(super) struct InputArrays {
    positions: Vec<[u32; 3]>,
    split_valence: Vec<u8>,
}

impl InputArrays {
    /// Saves every vertex of the current numbering, live or not.
    pub(super) fn save(&mut self, s: &State) {
        for (i, &v) in s.orig.iter().enumerate() {
            self.positions[v as usize] = s.positions[i];
            self.split_valence[v as usize] = s.split_valence[i];
        }
    }
}

/// The flat threshold of the tie-breaks ([`Scale::flat`]) for a mean edge
/// length: a collapse moving the surface by 1e-4 of an edge length or less
/// (error ~ area x distance^2 ~ L^2 x (1e-4 L)^2) counts as flat.
fn flat_of(edge: f64) -> f64 {
    1e-8 * edge.powi(4)
}

/// Whether the request of `v` stays what [`pick_edge`](super::select::pick_edge) would choose when the
/// scale changes and no flat threshold, old or new, reaches `flat`: its
/// error is above both (so its key is the same under both) and every other
/// candidate's key is higher (so no tie-break, whose sub-grid changed,
/// decided it); they then keep higher keys under the new scale too. A
/// runner-up with a possible tie behind it becomes unknown (the new
/// sub-grid could break the tie the other way). A vertex without a request,
/// or whose request may not be a pick's, chooses again.
fn rescaled(t: &Tracking, v: u32, flat: f64) -> Rescaled {
    let v = v as usize;
    let (best, bound) = (t.best[v], t.bound[v]);
    if best.other == NONE || best.error <= flat || bound == 0 {
        return Rescaled::Chooses;
    }
    match t.second[v] {
        Some(second) if second.other == NONE => Rescaled::Kept,
        Some(second) if second.error_key > best.error_key => {
            if bound <= second.error_key {
                Rescaled::KeptWithoutSecond
            } else {
                Rescaled::Kept
            }
        }
        Some(_) => Rescaled::Chooses,
        None if bound > best.error_key => Rescaled::Kept,
        None => Rescaled::Chooses,
    }
}

/// What a rescale does to a request ([`rescaled`]).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Rescaled {
    Kept,
    /// Kept, the runner-up made unknown.
    KeptWithoutSecond,
    /// The vertex chooses again.
    Chooses,
}

/// Every edge's slot, at the lower of its corners ([`State::slot_index`]);
/// the other corner's entry is never read.
fn initial_slots(s: &State) -> Vec<EdgeSlot> {
    let t = &s.table;
    (0..t.vertex.len() as u32)
        .into_par_iter()
        .map(|c| match t.o(c) {
            o if o != NONE && o < c => EdgeSlot::FORBIDDEN,
            _ => edge_slot(s, c),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::fractal_terrain;
    use crate::quantize::{Units, quantize};

    /// Steps the simplification of a `side` × `side` raster of heights
    /// `z(row, column)`, kept on its lattice, takes down to 64 vertices.
    fn raster_steps(side: usize, z: impl Fn(usize, usize) -> f64) -> usize {
        use crate::input::{Grid, grid_to_mesh};
        use crate::quantize::{Lattice, Quantization, quantize_with};
        let elevations = (0..side * side).map(|i| z(i / side, i % side)).collect();
        let grid = Grid {
            rows: side,
            cols: side,
            elevations,
            origin: [0.0, 0.0],
            spacing: [1.0, 1.0],
            nodata: None,
            coordinates: None,
        };
        let mesh = grid_to_mesh(&grid);
        let q = quantize_with(
            &mesh,
            14,
            Units::Linear,
            Quantization::PerAxis,
            Lattice::Keep,
        );
        let options = SimplifyOptions {
            target_vertices: 64,
            constrained: true,
            ..SimplifyOptions::default()
        };
        simplify(&q, &options, |_| {}).steps.len()
    }

    /// A tilted plane is as flat as a level one: its collapses all tie
    /// (their errors are rounding noise, `quadric::NUMERIC_ZERO`) and the
    /// sub-grid breaks the ties. With the noise ranking them instead, the
    /// ramp took about twice the steps (rounds of the stream) of the level
    /// raster.
    #[test]
    fn a_ramp_simplifies_in_about_the_steps_of_a_level_raster() {
        let level = raster_steps(80, |_, _| 0.0);
        let ramp = raster_steps(80, |r, c| (3 * r + 7 * c) as f64);
        assert!(
            ramp * 4 <= level * 5,
            "a ramp takes {ramp} steps, a level raster {level}"
        );
    }

    /// Steps a sphere of 10,242 vertices quantized to `bits` takes down to
    /// 64 vertices in constrained mode, and the vertices it is left with.
    fn sphere_steps(bits: u8) -> (usize, usize) {
        let q = quantize(&crate::input::icosphere(5), bits, Units::Linear);
        let options = SimplifyOptions {
            target_vertices: 64,
            constrained: true,
            ..SimplifyOptions::default()
        };
        let s = simplify(&q, &options, |_| {});
        (s.steps.len(), s.alive_count)
    }

    /// Quantized coarsely, a sphere has triangles with two corners on one
    /// grid point (1,092 of 20,480 at 6 bits, 13,092 at 5, 18,548 at 4).
    /// Such a triangle may stay without a normal
    /// (`check::keeps_orientation`): when every collapse of its corners had
    /// to give it one, the 5-bit sphere stopped after 2 steps and the 4-bit
    /// one found no collapse at all.
    #[test]
    fn a_coarsely_quantized_sphere_simplifies_like_a_fine_one() {
        let (fine, left) = sphere_steps(14);
        assert_eq!(left, 64);
        for bits in [4, 5, 6] {
            let (steps, left) = sphere_steps(bits);
            assert_eq!(
                left, 64,
                "{bits} bits: {left} vertices left after {steps} steps"
            );
            assert!(
                steps * 4 <= fine * 5,
                "{bits} bits: {steps} steps, 14 bits: {fine}"
            );
        }
    }

    #[test]
    fn renumbering_keeps_the_collapses() {
        // Compaction happens at every halving; a mesh small enough that the
        // loop also runs many steps after the last one.
        let q = quantize(&fractal_terrain(48, 9), 14, Units::Linear);
        for constrained in [false, true] {
            let options = SimplifyOptions {
                target_vertices: 8,
                constrained,
                ..SimplifyOptions::default()
            };
            let s = simplify(&q, &options, |_| {});
            let mut alive = vec![true; q.positions.len()];
            for c in s.steps.iter().flatten() {
                assert!(c.p < c.c, "P is the lower input id");
                assert!(alive[c.p as usize] && alive[c.c as usize]);
                alive[c.c as usize] = false;
            }
            assert_eq!(alive, s.alive);
            assert_eq!(s.alive.iter().filter(|&&a| a).count(), s.alive_count);
            for t in s.table.vertex.chunks_exact(3).filter(|t| t[0] != NONE) {
                assert!(t.iter().all(|&v| s.alive[v as usize]));
            }
        }
    }
}
