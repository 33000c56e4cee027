//! Working state and the step loop of the parallel simplifier.

use std::sync::atomic::Ordering::Relaxed;
use std::sync::atomic::{AtomicU32, AtomicU64};

use rayon::prelude::*;

use super::check::{CheckScratch, Plan, check_collapse, check_walked};
use super::quantile::admission;
use super::select::{
    Best, Choices, EdgeSlot, Known, Ranking, Scale, edge_slot, error_key, evaluate, offer,
    pair_key, pick_edge,
};
use crate::corner_table::{CornerAccess, CornerTable, Fan, NONE, collapse_in, next, prev};
use crate::prefetch::{prefetch, prefetch_at};
use crate::quadric::{Quadric, vertex_quadrics};
use crate::quantize::QuantizedMesh;

/// Share of refused checks above which a step checks its players' requests
/// before they pair up (`validate`): about 0.3 % on the meshes, 2–3 % on a
/// terrain whose x and y stay on the raster's lattice, 10–20 % on a DEM read
/// in degrees and metres (the Jacksboro DEM without `--geographic`). At
/// 2 % the lattice terrain validated every step, 25 % of its simplification
/// time for the same collapses (encoder/BENCHMARKS.md, Speed).
const VALIDATE_ABOVE: f64 = 0.05;

/// Split valence stored for vertices that were never produced by a
/// collapse (they never split). A real split valence is at least 3, so 0
/// is free, and every split valence the format allows, 3 to 255, has its
/// own value (SPEC §6.2). (The stream marks a leaf by its deficit instead:
/// decoder-core's `limits::LEAF`.)
pub const NO_SPLIT: u8 = 0;
/// Largest valence (ghost included) a collapse may produce: the format's
/// largest split valence (SPEC §6.2, `MAX_SPLIT_VALENCE`).
pub const MAX_VALENCE: usize = splitstream_decoder_core::limits::MAX_SPLIT_VALENCE;

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
    /// Split valences P and C had before the collapse ([`NO_SPLIT`] if original).
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
    /// Split valence of each surviving vertex ([`NO_SPLIT`] for originals).
    pub split_valence: Vec<u8>,
    pub alive: Vec<bool>,
    pub alive_count: usize,
    /// Largest error of any collapse, per step.
    pub step_errors: Vec<f64>,
}

pub(super) struct State {
    pub table: CornerTable,
    pub positions: Vec<[u32; 3]>,
    pub quadrics: Vec<Quadric>,
    pub boundary: Vec<bool>,
    /// Valence of each vertex with the boundary ghost counted (triangles,
    /// plus 2 on a boundary: the fan's extra neighbour and the ghost), kept
    /// up to date by the collapses so that a check reads the wings' valences
    /// instead of walking their fans.
    pub valence: Vec<u32>,
    pub alive: Vec<bool>,
    pub split_valence: Vec<u8>,
    /// Cached collapse of the edge facing each corner.
    pub edges: Vec<EdgeSlot>,
    pub bits: u8,
    /// Grid units to metric units per axis: geometry = position * metric.
    pub metric: [f64; 3],
    pub constrained: bool,
    pub lock_boundary: bool,
    /// Whether each vertex's fan holds all its corners and only the edges
    /// used once are unmatched (see [`State::new`]).
    pub manifold: bool,
    /// Input id of each vertex: the CPU loop renumbers the live vertices
    /// and triangles densely as they thin out ([`compact`]); records and
    /// results are in input ids.
    pub orig: Vec<u32>,
}

impl State {
    /// The state before any collapse, without quadrics and edge slots
    /// (each backend computes those its own way).
    pub fn new(mesh: &QuantizedMesh, options: &SimplifyOptions) -> State {
        let n = mesh.positions.len();
        let metric = mesh.metric;
        let (table, clean) = CornerTable::build(n, &mesh.triangles);
        // Boundary flags and valences from each vertex's fan, in parallel;
        // that holds where every vertex has one fan holding all its corners
        // and the only unmatched edges are those used once (a checked mesh),
        // which the fans' corner count tells.
        let fans: Vec<(bool, u32)> = (0..n as u32)
            .into_par_iter()
            .map(|v| {
                let (mut open, mut count) = (false, 0);
                table.for_each_corner(v, |c| {
                    count += 1;
                    open |= table.o(prev(c)) == NONE;
                });
                (open, count)
            })
            .collect();
        let manifold =
            clean && fans.iter().map(|&(_, k)| k as usize).sum::<usize>() == table.vertex.len();
        let (boundary, valence) = if manifold {
            fans.into_iter()
                .map(|(open, count)| (open, count + if open { 2 } else { 0 }))
                .unzip()
        } else {
            let mut boundary = vec![false; n];
            for (c, &o) in table.opposite.iter().enumerate() {
                if o == NONE {
                    boundary[table.v(next(c as u32)) as usize] = true;
                    boundary[table.v(prev(c as u32)) as usize] = true;
                }
            }
            let mut valence: Vec<u32> = boundary.iter().map(|&b| if b { 2 } else { 0 }).collect();
            for &v in &table.vertex {
                valence[v as usize] += 1;
            }
            (boundary, valence)
        };
        let alive: Vec<bool> = table.corner_of.par_iter().map(|&c| c != NONE).collect();
        State {
            quadrics: Vec::new(),
            positions: mesh.positions.clone(),
            table,
            boundary,
            valence,
            alive,
            split_valence: vec![NO_SPLIT; n],
            edges: Vec::new(),
            bits: mesh.bits,
            metric,
            constrained: options.constrained,
            lock_boundary: options.lock_boundary,
            orig: (0..n as u32).collect(),
            manifold,
        }
    }

    /// [`vertex_quadrics`] of the input, summed per vertex over its fan in
    /// parallel, in the same order (its triangles ascending, then its
    /// boundary edges by key), so the same bits; `None` where the fans do not
    /// cover the mesh ([`State::manifold`]).
    pub fn fan_quadrics(&self, boundary_weight: f64) -> Option<Vec<Quadric>> {
        if !self.manifold {
            return None;
        }
        let t = &self.table;
        // Each triangle's quadric is computed by each of its vertices: three
        // times the arithmetic, but no 80-byte-a-triangle array to fill and
        // read back.
        let face = |k: u32| {
            let [a, b, c] = [0, 1, 2].map(|j| self.geometry(t.v(3 * k + j)));
            Quadric::from_triangle(a, b, c)
        };
        let n = self.positions.len() as u32;
        let quadrics = (0..n)
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(triangles, edges): &mut (Vec<u32>, Vec<(u64, [u32; 3])>), v| {
                    triangles.clear();
                    t.for_each_corner(v, |c| triangles.push(c / 3));
                    triangles.sort_unstable();
                    let mut q = Quadric::ZERO;
                    for &k in triangles.iter() {
                        q += face(k);
                    }
                    if boundary_weight == 0.0 || !self.boundary[v as usize] {
                        return q;
                    }
                    // The boundary edge facing corner f runs from next f to
                    // prev f, with f's vertex third.
                    edges.clear();
                    t.for_each_corner(v, |c| {
                        for f in [prev(c), next(c)] {
                            if t.o(f) == NONE {
                                let (a, b) = (t.v(next(f)), t.v(prev(f)));
                                let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
                                edges.push((key, [a, b, t.v(f)]));
                            }
                        }
                    });
                    edges.sort_unstable_by_key(|e| e.0);
                    for &(_, ends) in edges.iter() {
                        let [a, b, c] = ends.map(|x| self.geometry(x));
                        q += crate::quadric::boundary_quadric(a, b, c, boundary_weight);
                    }
                    q
                },
            )
            .collect();
        Some(quadrics)
    }

    /// Metric coordinates of vertex `v`, computed from its grid position
    /// (three products beat a load from a second, twice as large array).
    #[inline]
    pub fn geometry(&self, v: u32) -> [f64; 3] {
        self.to_metric(self.positions[v as usize])
    }

    /// Where the slot of the edge facing corner `c` is kept: at the lower of
    /// its two corners, so a refresh writes it once.
    pub fn slot_index(&self, c: u32) -> usize {
        let o = self.table.o(c);
        if o != NONE && o < c {
            o as usize
        } else {
            c as usize
        }
    }

    /// The slot of the edge facing corner `c`.
    pub fn slot(&self, c: u32) -> &EdgeSlot {
        &self.edges[self.slot_index(c)]
    }

    /// Metric coordinates of a grid point.
    pub fn to_metric(&self, q: [u32; 3]) -> [f64; 3] {
        std::array::from_fn(|k| q[k] as f64 * self.metric[k])
    }
}

/// Time spent per phase over the whole simplification, printed under
/// `SPLITSTREAM_DEBUG`.
#[derive(Default)]
pub(super) struct Phases {
    at: Option<std::time::Instant>,
    seconds: Vec<(&'static str, f64)>,
}

impl Phases {
    /// Charges the time since the last lap to `name`.
    pub(super) fn lap(&mut self, name: &'static str) {
        let now = std::time::Instant::now();
        if let Some(at) = self.at {
            let dt = (now - at).as_secs_f64();
            match self.seconds.iter_mut().find(|(n, _)| *n == name) {
                Some((_, s)) => *s += dt,
                None => self.seconds.push((name, dt)),
            }
        }
        self.at = Some(now);
    }

    pub(super) fn report(&self) -> String {
        let total: f64 = self.seconds.iter().map(|(_, s)| s).sum();
        let parts: Vec<String> = self
            .seconds
            .iter()
            .map(|(n, s)| format!("{n} {:.0}", s * 1e3))
            .collect();
        format!(
            "simplify phases, ms (total {:.0}): {}",
            total * 1e3,
            parts.join(", ")
        )
    }
}

/// Per-vertex bookkeeping of the CPU step loop (the GPU backends keep their
/// own on the device). The `u32` stamps hold state numbers ([`Known`]), so
/// none is ever cleared.
struct Tracking {
    /// Each vertex's request (§2 step a), chosen without the constraints of
    /// a step's later passes.
    best: Vec<Best>,
    /// The runner-up of each request (another partner), `None` if unknown:
    /// a vertex whose partner a collapse took falls back on it instead of
    /// walking its fan.
    second: Vec<Option<Best>>,
    /// [`Choices::bound`] of each request; 0 where the request may not be
    /// what a pick gives (chosen while neighbours were blocked).
    bound: Vec<u32>,
    /// Requests chosen again within a step (blocked partners, refused
    /// edges), valid where `repick_at == state`; they never outlive it.
    repick: Vec<Best>,
    repick_at: Vec<u32>,
    /// State since which each vertex's 1-ring is what it is.
    changed: Vec<u32>,
    /// `== state`: the vertex was merged (survived as R) at the last step.
    merged: Vec<u32>,
    /// Latest state in which one of the vertex's edges was refused (0: none
    /// since its 1-ring last changed).
    refusals: Vec<u32>,
    /// `== state`: a winner of this step blocks the vertex (set by the
    /// checks as they find winners, in parallel).
    blocked: Vec<AtomicU32>,
    /// `== state`: the vertex chooses from scratch at this step.
    listed: Vec<u32>,
    /// `== state`: the vertex was sorted into choosing or taking offers.
    sorted: Vec<u32>,
    /// Pair key of each vertex's admitted request in the current pass,
    /// `u64::MAX` otherwise (reset after each pass, so never swept whole).
    keys: Vec<AtomicU64>,
    /// `== pass`: the vertex was claimed by a task of [`choose`]'s pass
    /// `pass` (a list of choosers may name a vertex twice).
    claimed: Vec<AtomicU32>,
    /// The last pass of [`choose`].
    passes: u32,
}

impl Tracking {
    /// Arrays of zeros come zeroed from the allocator (their pages are
    /// touched by the passes); the others are filled in parallel, which
    /// also spreads their first page faults over the threads.
    fn new(n: usize) -> Tracking {
        fn filled<T: Clone + Send + Sync>(n: usize, x: T) -> Vec<T> {
            rayon::iter::repeat_n(x, n).collect()
        }
        fn atomics<T: Send>(n: usize, make: impl Fn() -> T + Sync + Send) -> Vec<T> {
            (0..n).into_par_iter().map(|_| make()).collect()
        }
        Tracking {
            best: filled(n, Best::NONE),
            second: filled(n, None),
            bound: filled(n, u32::MAX),
            repick: filled(n, Best::NONE),
            repick_at: vec![0; n],
            changed: vec![0; n],
            merged: vec![0; n],
            refusals: vec![0; n],
            blocked: atomics(n, || AtomicU32::new(0)),
            // Every vertex is on the first step's list.
            listed: filled(n, 1),
            sorted: vec![0; n],
            keys: atomics(n, || AtomicU64::new(u64::MAX)),
            claimed: atomics(n, || AtomicU32::new(0)),
            passes: 0,
        }
    }

    fn known(&self, state: u32) -> Known<'_> {
        Known {
            state,
            changed: &self.changed,
            blocked: &self.blocked,
        }
    }

    /// The request of `v` in the current pass of step `state`.
    fn request(&self, v: u32, state: u32) -> &Best {
        if self.repick_at[v as usize] == state {
            &self.repick[v as usize]
        } else {
            &self.best[v as usize]
        }
    }
}

/// A collapse chosen and checked in this step, with what applying it needs.
pub(super) struct Winner {
    pub p: u32,
    pub best: Best,
    /// Where the merged vertex goes.
    pub target: [u32; 3],
    pub plan: Plan,
    /// The fans of P then C as its check walked them, at `fans` in
    /// [`Buffers::fans`]: applying the collapse needs no walk.
    pub fans: (u32, u32, u32),
}

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
struct InputArrays {
    positions: Vec<[u32; 3]>,
    split_valence: Vec<u8>,
}

impl InputArrays {
    /// Saves every vertex of the current numbering, live or not.
    fn save(&mut self, s: &State) {
        for (i, &v) in s.orig.iter().enumerate() {
            self.positions[v as usize] = s.positions[i];
            self.split_valence[v as usize] = s.split_valence[i];
        }
    }
}

/// What the loop keeps in current ids besides the state and tracking, for
/// [`compact`].
struct Renumbered<'a> {
    /// The live vertices, ascending (become 0..n).
    live: &'a mut Vec<u32>,
    /// (P, C) of the step just applied: requests still naming C (its
    /// neighbours take their offers at the next step) name P instead, who
    /// was merged at that step and so counts as taken just the same.
    pairs: &'a [(u32, u32)],
    choosers: &'a mut Vec<u32>,
    offers: &'a mut [RefreshChunk],
    meter: &'a mut EdgeMeter,
    input: &'a mut InputArrays,
}

/// Renumbers the live vertices (in `live` order, ascending) and the live
/// triangles (in order) densely, between two steps. Every comparison of ids
/// (index priority, tie-breaks, the lower corner of an edge) keeps its
/// outcome, so the collapses are the same, only cheaper to find: once most
/// vertices are gone, each pass otherwise reads one live vertex per cache
/// line and per page. The state numbers in the tracking stamps carry over.
fn compact(s: &mut State, t: &mut Tracking, r: Renumbered<'_>) {
    let Renumbered {
        live,
        pairs,
        choosers,
        offers,
        meter,
        input,
    } = r;
    let n = s.positions.len();
    // The input arrays are saved beside the maps' serial scans (both only
    // read the state).
    let s_now: &State = s;
    let ((), (vmap, (tmap, triangles))) = rayon::join(
        || input.save(s_now),
        || {
            let mut vmap = vec![NONE; n];
            for (i, &v) in live.iter().enumerate() {
                vmap[v as usize] = i as u32;
            }
            for &(p, c) in pairs {
                vmap[c as usize] = vmap[p as usize];
            }
            let mut tmap = vec![NONE; s_now.table.vertex.len() / 3];
            let mut triangles = Vec::with_capacity(2 * live.len());
            for (k, slot) in tmap.iter_mut().enumerate() {
                if s_now.table.vertex[3 * k] != NONE {
                    *slot = triangles.len() as u32;
                    triangles.push(k as u32);
                }
            }
            (vmap, (tmap, triangles))
        },
    );
    let cmap = |c: u32| {
        if c == NONE || tmap[(c / 3) as usize] == NONE {
            NONE
        } else {
            3 * tmap[(c / 3) as usize] + c % 3
        }
    };
    let vmap_of = |v: u32| if v == NONE { NONE } else { vmap[v as usize] };
    // In place, in ascending order: every element moves down or stays, and
    // is read before anything lands on it; no fresh pages to fault in.
    let corners: Vec<u32> = triangles
        .iter()
        .flat_map(|&k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect();
    let m = live.len();
    let remap = |b: Best| {
        debug_assert!(b.other == NONE || vmap[b.other as usize] != NONE);
        Best {
            other: vmap_of(b.other),
            corner: cmap(b.corner),
            ..b
        }
    };
    let live_now: &[u32] = live;
    let corners = &corners[..];
    let CornerTable {
        vertex,
        opposite,
        corner_of,
    } = &mut s.table;
    // Each array on its own: they are independent.
    rayon::scope(|scope| {
        scope.spawn(|_| gather_map(vertex, corners, vmap_of));
        scope.spawn(|_| gather_map(opposite, corners, cmap));
        scope.spawn(|_| gather_map(&mut s.edges, corners, |e| e));
        scope.spawn(|_| gather_map(&mut s.quadrics, live_now, |x| x));
        scope.spawn(|_| {
            gather_map(corner_of, live_now, cmap);
            gather_map(&mut s.positions, live_now, |x| x);
            gather_map(&mut s.boundary, live_now, |x| x);
            gather_map(&mut s.valence, live_now, |x| x);
            gather_map(&mut s.split_valence, live_now, |x| x);
            gather_map(&mut s.orig, live_now, |x| x);
            s.alive.truncate(m);
            s.alive.fill(true);
        });
        scope.spawn(|_| gather_map(&mut t.best, live_now, remap));
        scope.spawn(|_| gather_map(&mut t.second, live_now, |b| b.map(remap)));
        scope.spawn(|_| {
            gather_map(&mut t.bound, live_now, |x| x);
            gather_map(&mut t.changed, live_now, |x| x);
            gather_map(&mut t.merged, live_now, |x| x);
            gather_map(&mut t.refusals, live_now, |x| x);
            for (i, &v) in live_now.iter().enumerate() {
                let blocked = t.blocked[v as usize].load(Relaxed);
                t.blocked[i].store(blocked, Relaxed);
            }
            t.blocked.truncate(m);
            gather_map(&mut t.listed, live_now, |x| x);
            gather_map(&mut t.sorted, live_now, |x| x);
            t.repick.truncate(m);
            t.repick_at.truncate(m);
            t.repick_at.fill(0);
            t.keys.truncate(m);
            for key in &t.keys {
                key.store(u64::MAX, Relaxed);
            }
            // Older passes' claims: whatever they say, no pass claims again.
            t.claimed.truncate(m);
        });
    });
    choosers.par_iter_mut().for_each(|v| *v = vmap[*v as usize]);
    offers.par_iter_mut().for_each(|chunk| {
        for o in chunk.offers.iter_mut() {
            *o = Offer {
                x: vmap[o.x as usize],
                r: vmap[o.r as usize],
                facing: cmap(o.facing),
            };
        }
        chunk.measure_span();
    });
    meter.triangles = meter
        .triangles
        .par_iter()
        .filter_map(|&k| Some(tmap[k as usize]).filter(|&k| k != NONE))
        .collect();
    *live = (0..m as u32).collect();
}

/// `items[i] = f(items[from[i]])` for each `i` in order, then `items` cut to
/// `from.len()`: with `from` ascending and `from[i] >= i`, every element is
/// read before it is overwritten.
fn gather_map<T: Copy>(items: &mut Vec<T>, from: &[u32], f: impl Fn(T) -> T) {
    for (i, &k) in from.iter().enumerate() {
        debug_assert!(k as usize >= i);
        items[i] = f(items[k as usize]);
    }
    items.truncate(from.len());
}

/// The flat threshold of the tie-breaks ([`Scale::flat`]) for a mean edge
/// length: a collapse moving the surface by 1e-4 of an edge length or less
/// (error ~ area x distance^2 ~ L^2 x (1e-4 L)^2) counts as flat.
fn flat_of(edge: f64) -> f64 {
    1e-8 * edge.powi(4)
}

/// Whether the request of `v` stays what [`pick_edge`] would choose when the
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

/// A refreshed edge of merged vertex `r`, offered to its other end `x`.
#[derive(Clone, Copy)]
struct Offer {
    x: u32,
    r: u32,
    /// A corner facing the edge.
    facing: u32,
}

/// Sorts the neighbours of the last step's merged vertices into those that
/// must choose from scratch (appended to `choosers`) and those whose choices
/// the refreshed edges update. Returns how many took offers.
///
/// A neighbour x of R has the same quadric, position and other neighbours
/// as before, so its candidates are the old ones without its edges to P and
/// C, plus its edges to merged vertices, which are offered: the old best
/// (or, if that went to P or C, the runner-up) and the offers give what
/// [`pick_edge`] would. Only a vertex that lost both, or has refused edges
/// (now stale), walks its fan again. Most of a step's changed vertices are
/// such neighbours, and an offer costs no fan walk.
fn take_offers(
    s: &State,
    t: &mut Tracking,
    offers: &[RefreshChunk],
    choosers: &mut Vec<u32>,
    scale: Scale,
    state: u32,
) -> usize {
    let gone =
        |merged: &[u32], u: u32| u != NONE && (!s.alive[u as usize] || merged[u as usize] == state);
    // Each part of the vertex range takes the offers to its own vertices,
    // in the order of `offers` (the parts scan the whole list: a compare
    // per offer), so the requests come out as one pass in order gives them.
    let n = t.best.len();
    let size = part_size(n);
    let Tracking {
        best,
        second,
        bound,
        listed,
        sorted,
        merged,
        refusals,
        ..
    } = t;
    let (merged, refusals): (&[u32], &[u32]) = (merged, refusals);
    let parts: Vec<(Vec<u32>, usize)> = best
        .par_chunks_mut(size)
        .zip(second.par_chunks_mut(size))
        .zip(bound.par_chunks_mut(size))
        .zip(listed.par_chunks_mut(size))
        .zip(sorted.par_chunks_mut(size))
        .enumerate()
        .map(|(k, ((((best, second), bound), listed), sorted))| {
            let lo = k * size;
            let mut choose = Vec::new();
            let mut offered = 0;
            let hi = lo + best.len();
            let chunks = offers
                .iter()
                .filter(|chunk| (chunk.span.0 as usize) < hi && chunk.span.1 as usize >= lo);
            for offers in chunks.map(|chunk| &chunk.offers) {
                for (i, o) in offers.iter().enumerate() {
                    let x = (o.x as usize).wrapping_sub(lo);
                    if x >= best.len() {
                        continue;
                    }
                    // What the offers ahead read at random: the request, and
                    // the slot (through its corner's opposite).
                    if let Some(ahead) = offers.get(i + 8) {
                        let y = (ahead.x as usize).wrapping_sub(lo);
                        if y < best.len() {
                            prefetch(best, y);
                            prefetch(second, y);
                            prefetch(&s.table.opposite, ahead.facing as usize);
                            prefetch(&s.edges, ahead.facing as usize);
                        }
                    }
                    if sorted[x] != state {
                        sorted[x] = state;
                        if listed[x] != state {
                            let runner_up = second[x];
                            let second_gone = runner_up.is_none_or(|b| gone(merged, b.other));
                            let best_gone = gone(merged, best[x].other);
                            if refusals[o.x as usize] != 0 || (best_gone && second_gone) {
                                listed[x] = state;
                                choose.push(o.x);
                            } else {
                                offered += 1;
                                // Either way the bound of what comes after the
                                // runner-up now bounds what comes after the best.
                                if best_gone {
                                    // The runner-up is the best of what is left;
                                    // what comes after it is not known.
                                    let b = runner_up.unwrap_or(Best::NONE);
                                    best[x] = b;
                                    second[x] = (b.other == NONE).then_some(Best::NONE);
                                } else if second_gone {
                                    second[x] = None;
                                }
                            }
                        }
                    }
                    if listed[x] == state {
                        continue;
                    }
                    let mut choices = Choices {
                        best: best[x],
                        second: second[x],
                        bound: bound[x],
                    };
                    offer(s, o.x, &mut choices, o.r, o.facing, scale);
                    best[x] = choices.best;
                    second[x] = choices.second;
                    bound[x] = choices.bound;
                }
            }
            (choose, offered)
        })
        .collect();
    let mut offered = 0;
    for (choose, count) in parts {
        choosers.extend(choose);
        offered += count;
    }
    // Every chooser's refused edges are stale now (its 1-ring changed, or
    // it was refused and chooses without the refused edge).
    for &v in choosers.iter() {
        if t.changed[v as usize] == state {
            t.refusals[v as usize] = 0;
        }
    }
    offered
}

/// Prefetches, while the vertex at `i` of `list` is processed, what the
/// fan walks of the next ones start from: the corner of the vertex 16
/// ahead, and the first triangle (corners, opposites, edge slots) of the
/// vertex 8 ahead. A fan walk is a chain of dependent loads; without this,
/// each link waits for memory in turn.
#[inline(always)]
fn prefetch_ahead(s: &State, list: &[u32], i: usize) {
    if let Some(&w) = list.get(i + 16) {
        prefetch(&s.table.corner_of, w as usize);
    }
    if let Some(&w) = list.get(i + 8) {
        prefetch_fan(s, w);
    }
}

/// Prefetches the first triangle of the fan of `v` (whose corner should be
/// in cache already), its position and quadric.
#[inline(always)]
fn prefetch_fan(s: &State, v: u32) {
    let c = s.table.corner_of[v as usize];
    if c != NONE {
        let base = (c - c % 3) as usize;
        prefetch(&s.table.vertex, base);
        prefetch(&s.table.opposite, base);
        prefetch(&s.edges, base);
        prefetch(&s.edges, base + 2);
    }
}

/// Size of the parts a per-vertex array is cut into when every part scans
/// one list for the entries it owns (see `take_offers`): two parts per
/// thread, so the scans stay cheap and the work still balances.
fn part_size(n: usize) -> usize {
    n.div_ceil(2 * rayon::current_num_threads()).max(4096)
}

/// §2 step a for `vertices`, in parallel: their requests are replaced.
/// Returns the neighbours whose refused edges the choosers found reopened.
///
/// The requests are written from the parallel part, each by the task that
/// picks it: a vertex listed twice (an end of an edge refused in the last
/// step that a rescale lists again, or that a renumbering merged into
/// another chooser) is claimed by one task, and a pick reads neither
/// requests nor bounds. Its picks are the same whichever task makes them,
/// and the reopened neighbours are the same set.
fn choose(s: &State, t: &mut Tracking, vertices: &[u32], scale: Scale, state: u32) -> Vec<u32> {
    t.passes += 1;
    let pass = t.passes;
    let known = Known {
        state,
        changed: &t.changed,
        blocked: &t.blocked,
    };
    let claimed: &[AtomicU32] = &t.claimed;
    let (best, second, bound) = (
        Raw::new(&mut t.best),
        Raw::new(&mut t.second),
        Raw::new(&mut t.bound),
    );
    let reopened = par_chunks_map(vertices, |chunk| {
        let mut reopened = Vec::new();
        for (i, &v) in chunk.iter().enumerate() {
            if claimed[v as usize].swap(pass, Relaxed) == pass {
                continue;
            }
            prefetch_ahead(s, chunk, i);
            let choices = pick_edge(s, v, scale, known, &mut reopened);
            let v = v as usize;
            // SAFETY: this task claimed vertex `v` in this pass, and no
            // other code reads or writes requests and bounds meanwhile.
            unsafe {
                best.set(v, choices.best);
                second.set(v, choices.second);
                bound.set(v, choices.bound);
            }
        }
        reopened
    });
    reopened.concat()
}

/// Re-picks, within the step, the request of each of `vertices` whose
/// partner a winner blocked: a vertex still on its unconstrained request
/// whose runner-up is free takes it (everything else ranks after the
/// runner-up); the others walk their fans again. In parallel, each task
/// writing the re-picks it makes: a vertex listed twice (a refused end
/// whose partner is also blocked) is claimed by one task, and its re-pick
/// is the same whichever task makes it (a re-pick reads no re-pick).
fn repick(s: &State, t: &mut Tracking, vertices: &[u32], scale: Scale, state: u32) {
    t.passes += 1;
    let pass = t.passes;
    let known = Known {
        state,
        changed: &t.changed,
        blocked: &t.blocked,
    };
    let (claimed, second): (&[AtomicU32], &[Option<Best>]) = (&t.claimed, &t.second);
    let (repick, repick_at) = (Raw::new(&mut t.repick), Raw::new(&mut t.repick_at));
    vertices
        .par_chunks(chunk_size(vertices.len()))
        .for_each(|chunk| {
            let mut reopened = Vec::new();
            for (i, &v) in chunk.iter().enumerate() {
                if claimed[v as usize].swap(pass, Relaxed) == pass {
                    continue;
                }
                let free = |b: &Best| {
                    b.other == NONE
                        || (known.blocked[b.other as usize].load(Relaxed) != state
                            && !known.refused(s.slot(b.corner), v, b.other))
                };
                let v = v as usize;
                // SAFETY (here and below): this task claimed vertex `v` in
                // this pass; no other code reads or writes re-picks meanwhile.
                let repicked = unsafe { repick_at.get(v) } == state;
                let b = match second[v] {
                    Some(b) if !repicked && free(&b) => b,
                    _ => {
                        prefetch_ahead(s, chunk, i);
                        pick_edge(s, v as u32, scale, known, &mut reopened).best
                    }
                };
                unsafe {
                    repick.set(v, b);
                    repick_at.set(v, state);
                }
            }
        });
}

/// Checks the requests of `vertices` that are not known to be valid and
/// stamps their slots; a vertex whose request is invalid chooses again
/// (its request, or its overlay within the step), until every request is
/// valid or known refused. The ends of a refused overlay request are
/// appended to `refused_ends` to choose from scratch at the next step.
/// Counts its checks and refusals in `tally`.
///
/// Without it a request is only checked once its pair is chosen: a vertex
/// whose partner wants another edge keeps an invalid request for as long as
/// its 1-ring stands, and the neighbours that want it wait with it. On
/// badly shaped input (a DEM in degrees and metres, where cheap edges often
/// fold) the steps then find few collapses each.
fn validate(
    s: &mut State,
    t: &mut Tracking,
    vertices: &[u32],
    scale: Scale,
    state: u32,
    refused_ends: &mut Vec<u32>,
    tally: &mut Tally,
) {
    let mut list: Vec<u32> = Vec::new();
    let mut first = true;
    loop {
        let items = if first { vertices } else { &list[..] };
        first = false;
        let tr: &Tracking = t;
        let s_now: &State = s;
        let known = tr.known(state);
        let results: Vec<Vec<(u32, bool)>> = par_chunks_map(items, |chunk| {
            let mut scratch = CheckScratch::default();
            let mut out = Vec::new();
            for &v in chunk {
                let b = tr.request(v, state);
                if b.other == NONE || known.valid(s_now.slot(b.corner), v, b.other) {
                    continue;
                }
                let (p, c) = (v.min(b.other), v.max(b.other));
                let (target, _) =
                    evaluate(s_now, p, c).expect("an edge with a finite error has a placement");
                let ok = check_collapse(s_now, p, c, s_now.to_metric(target), &mut scratch).is_ok();
                out.push((v, ok));
            }
            out
        });
        let (mut again, mut overlay) = (Vec::new(), Vec::new());
        for (v, ok) in results.into_iter().flatten() {
            tally.checks += 1;
            let b = *t.request(v, state);
            let slot = s.slot_index(b.corner);
            if ok {
                s.edges[slot].valid = state;
                continue;
            }
            s.edges[slot].refused = state;
            tally.refused += 1;
            let in_step = t.repick_at[v as usize] == state;
            if in_step {
                overlay.push(v);
            } else {
                again.push(v);
            }
            for x in [v, b.other] {
                t.refusals[x as usize] = state;
                // The other end may keep the refused edge as its request
                // until its 1-ring changes: a rescale must not keep it.
                t.bound[x as usize] = 0;
                if in_step && t.listed[x as usize] != state + 1 {
                    t.listed[x as usize] = state + 1;
                    refused_ends.push(x);
                }
            }
        }
        if again.is_empty() && overlay.is_empty() {
            return;
        }
        choose(s, t, &again, scale, state);
        // Chosen without the step's blocked neighbours: a rescale must not
        // keep these requests (`rescaled`).
        for &v in &again {
            t.bound[v as usize] = 0;
        }
        let picks = pick_all(s, t, &overlay, scale, state);
        for (v, c) in picks.into_iter().flat_map(|(picks, _)| picks) {
            t.repick[v as usize] = c.best;
        }
        list = again;
        list.append(&mut overlay);
    }
}

/// One chunk's picks (vertex and choices, in order) and reopened neighbours.
type PickedChunk = (Vec<(u32, Choices)>, Vec<u32>);

/// [`pick_edge`] for each of `vertices`, in parallel: per chunk of
/// `vertices`, its requests in order and the reopened neighbours.
fn pick_all(
    s: &State,
    t: &Tracking,
    vertices: &[u32],
    scale: Scale,
    state: u32,
) -> Vec<PickedChunk> {
    let known = t.known(state);
    par_chunks_map(vertices, |chunk| {
        let mut reopened = Vec::new();
        let picks: Vec<(u32, Choices)> = chunk
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                prefetch_ahead(s, chunk, i);
                (v, pick_edge(s, v, scale, known, &mut reopened))
            })
            .collect();
        (picks, reopened)
    })
}

/// The values `f` gives for `items`, in order, into `out` (cleared first):
/// the step's large lists keep their capacity from step to step instead of
/// faulting fresh pages in (a few percent of the run).
fn par_filter_into<T: Sync, U: Send>(
    items: &[T],
    out: &mut Vec<U>,
    f: impl Fn(&T) -> Option<U> + Sync + Send,
) {
    out.clear();
    for part in par_chunks_map(items, |chunk| {
        chunk.iter().filter_map(&f).collect::<Vec<U>>()
    }) {
        out.extend(part);
    }
}

/// Lists a step rebuilds, kept between steps for their capacity.
#[derive(Default)]
struct Buffers {
    players: Vec<u32>,
    spare: Vec<u32>,
    again: Vec<u32>,
    admitted: Vec<(u32, u64)>,
    /// The fans of the step's winners (see [`Winner::fans`]).
    fans: Vec<u32>,
    /// The step's checks (reset when it starts).
    tally: Tally,
}

/// Checks made in a step and how many were refused.
#[derive(Clone, Copy, Default)]
struct Tally {
    checks: usize,
    refused: usize,
}

/// A valid check's target and fans (offset into the chunk's corners,
/// lengths of P's and C's).
type Prepared = ([u32; 3], (u32, u32, u32));

/// One chunk's checks: results in order, and for the valid ones their
/// targets and their fans (offsets into `corners`).
#[derive(Default)]
struct Checked {
    /// Each checked pair's survivor and request (read here, in the
    /// parallel pass: the serial loop over the results then touches no
    /// per-vertex array, which on the 4M terrain was a cache miss a pair).
    results: Vec<(u32, Best, Result<Plan, ()>)>,
    prepared: Vec<Prepared>,
    corners: Vec<u32>,
}

/// `f` over consecutive chunks of `items` in parallel, the results in
/// order. Each chunk fills its own buffers: no allocation per item and no
/// merging copies (rayon's fold/reduce re-copies at every level).
pub(super) fn par_chunks_map<T: Sync, R: Send>(
    items: &[T],
    f: impl Fn(&[T]) -> R + Sync + Send,
) -> Vec<R> {
    items.par_chunks(chunk_size(items.len())).map(f).collect()
}

/// The chunk length of the data-parallel passes over `len` items.
fn chunk_size(len: usize) -> usize {
    (len / (8 * rayon::current_num_threads())).clamp(512, 16384)
}

/// What one step selects with: its state number, the threshold S, the
/// scale of the tie-breaks and whether requests are checked before they
/// pair up (`validate`).
#[derive(Clone, Copy)]
struct Step {
    state: u32,
    threshold: f64,
    scale: Scale,
    validating: bool,
}

/// Steps b and c: reciprocal pairs under the threshold that are local minima
/// among the requests of their 1-rings, each then checked (`check_collapse`);
/// returns the valid ones in ascending survivor id (the lower id).
///
/// Steps a to c are then repeated on what they left undecided: a vertex
/// whose partner was taken by a cheaper collapse chooses again among its free
/// neighbours, the two ends of a refused pair choose again without that edge,
/// and a pair blocked only by a pair that itself lost gets its turn. The
/// passes grow the step towards a maximal set of independent collapses in
/// error order, still in parallel; more collapses per step mean fewer rounds
/// and fewer flags in the stream. Choices made again here last for the step
/// only (`Tracking::repick`); the ends of refused pairs are appended to
/// `refused_ends` to choose from scratch at the next step.
fn step_winners(
    s: &mut State,
    t: &mut Tracking,
    live: &[u32],
    step: Step,
    refused_ends: &mut Vec<u32>,
    buffers: &mut Buffers,
    phases: &mut Phases,
) -> Vec<Winner> {
    let Step {
        state,
        threshold,
        scale,
        validating,
    } = step;
    // Passes that find winners; on jacksboro they add 100 %, 30 %, 4 % and
    // 0.2 % of the first pass's collapses: a fourth is not worth its O(n)
    // sweeps. A pass whose chosen pairs are all refused does not count, up
    // to a few: on badly scaled input (a DEM in degrees and metres) a step
    // near a raised threshold could otherwise sweep its players for dozens
    // of passes of one or two refused pairs each; refused ends choose again
    // at the next step anyway.
    const PASSES: usize = 3;
    const MAX_PASSES: usize = 2 * PASSES;
    let mut winners: Vec<Winner> = Vec::new();
    let mut refused_now: Vec<u32> = Vec::new();
    let (mut counted, mut passes) = (0, 0);
    let mut first = true;
    // Only vertices whose request's key is not above S's can take part:
    // choosing again among fewer neighbours never gives a lower key. (Not
    // the error: requests of equal key, all flat ones in particular, are
    // ordered by the tie-breaks, so a vertex whose request is over S may
    // choose again an edge of the same key under it; on a flat DEM that is
    // most of the early steps' collapses.)
    let threshold_key = error_key(threshold, scale);
    let tr: &Tracking = t;
    let Buffers {
        players,
        spare,
        again,
        admitted: admitted_keys,
        fans,
        tally,
        ..
    } = buffers;
    fans.clear();
    par_filter_into(live, players, |&v| {
        let b = &tr.best[v as usize];
        (b.other != NONE && (b.error <= threshold || b.error_key <= threshold_key)).then_some(v)
    });
    // The players' requests are checked before they pair up (see `validate`).
    if validating {
        validate(s, t, players, scale, state, refused_ends, tally);
    }
    phases.lap("validate");
    loop {
        if !first {
            let tr: &Tracking = t;
            par_filter_into(players, again, |&v| {
                let b = tr.request(v, state);
                (tr.blocked[v as usize].load(Relaxed) != state
                    && b.other != NONE
                    && (b.error <= threshold || b.error_key <= threshold_key)
                    && tr.blocked[b.other as usize].load(Relaxed) == state)
                    .then_some(v)
            });
            // The ends of a refused pair are never blocked: a winner of the
            // same pass would be in their 1-ring, and both cannot be local
            // minima.
            again.append(&mut refused_now);
            phases.lap("repick scan");
            repick(s, t, again, scale, state);
            phases.lap("repick");
            if validating {
                validate(s, t, again, scale, state, refused_ends, tally);
            }
            phases.lap("validate");
        }
        first = false;
        let tr: &Tracking = t;
        let admitted = |v: u32| {
            let b = tr.request(v, state);
            tr.blocked[v as usize].load(Relaxed) != state
                && b.other != NONE
                && b.error <= threshold
                && tr.blocked[b.other as usize].load(Relaxed) != state
                && tr.request(b.other, state).other == v
        };
        // One key per pair, taken from its lower endpoint, so that both
        // endpoints compare alike (their cached errors may come from
        // different steps).
        par_filter_into(players, admitted_keys, |&v| {
            admitted(v).then(|| {
                let other = tr.request(v, state).other;
                let low = v.min(other);
                let key = pair_key(tr.request(low, state), low);
                // Both ends (the partner may not be a player: its
                // request's key can date from another scale); both write
                // the same key, and nothing reads keys until the pass's
                // minima.
                tr.keys[v as usize].store(key, Relaxed);
                tr.keys[other as usize].store(key, Relaxed);
                (v, key)
            })
        });
        phases.lap("admit");
        let tr: &Tracking = t;
        let s_now: &State = s;
        // Local minima, checked; a valid one blocks its endpoints and their
        // neighbours (from the fans its check walked).
        let checked: Vec<Checked> = par_chunks_map(admitted_keys, |chunk| {
            let mut scratch = CheckScratch::default();
            let mut out = Checked::default();
            for (i, &(v, key)) in chunk.iter().enumerate() {
                // Both fans and quadrics of the pairs ahead (see
                // `prefetch_ahead`).
                if let Some(&(w, _)) = chunk.get(i + 12) {
                    let u = tr.request(w, state).other;
                    if w < u {
                        prefetch(&s_now.table.corner_of, w as usize);
                        prefetch(&s_now.table.corner_of, u as usize);
                    }
                }
                if let Some(&(w, _)) = chunk.get(i + 6) {
                    let u = tr.request(w, state).other;
                    if w < u {
                        prefetch_fan(s_now, w);
                        prefetch_fan(s_now, u);
                        prefetch(&s_now.quadrics, w as usize);
                        prefetch(&s_now.quadrics, u as usize);
                    }
                }
                let b = tr.request(v, state);
                let c = b.other;
                if v > c {
                    continue;
                }
                // C's fan only if P's neighbours do not already beat the pair.
                // The check reads every neighbour's position: ask for them
                // as soon as the fans are known.
                let fan = scratch.walk_p(s_now, v);
                prefetch_neighbours(s_now, fan);
                if !is_local_minimum(s_now, v, c, key, &tr.keys, fan) {
                    continue;
                }
                let fan = scratch.walk_c(s_now, c);
                prefetch_neighbours(s_now, fan);
                if !is_local_minimum(s_now, v, c, key, &tr.keys, fan) {
                    continue;
                }
                // The merged position, as the slot's evaluation found it.
                let (target, error) =
                    evaluate(s_now, v, c).expect("an edge with a finite error has a placement");
                debug_assert_eq!(error, b.error, "slot of ({v}, {c}) up to date");
                let result = check_walked(s_now, v, c, s_now.to_metric(target), &mut scratch);
                if result.is_ok() {
                    // The winner's endpoints and neighbours leave the
                    // game; no check of this pass reads the flags.
                    for x in scratch.neighbourhood() {
                        tr.blocked[x as usize].store(state, Relaxed);
                    }
                    let (fan_p, fan_c) = scratch.fans();
                    let start = out.corners.len() as u32;
                    out.corners.extend_from_slice(&fan_p.corners);
                    out.corners.extend_from_slice(&fan_c.corners);
                    out.prepared.push((
                        target,
                        (
                            start,
                            fan_p.corners.len() as u32,
                            fan_c.corners.len() as u32,
                        ),
                    ));
                }
                out.results.push((v, *b, result));
            }
            out
        });
        let tr: &Tracking = t;
        admitted_keys.par_iter().for_each(|&(v, _)| {
            let other = tr.request(v, state).other;
            tr.keys[v as usize].store(u64::MAX, Relaxed);
            tr.keys[other as usize].store(u64::MAX, Relaxed);
        });
        phases.lap("minima+check");
        if checked.iter().all(|out| out.results.is_empty()) {
            break;
        }
        let mut found = false;
        for out in &checked {
            let base = fans.len() as u32;
            fans.extend_from_slice(&out.corners);
            let mut prepared = out.prepared.iter();
            for &(p, b, result) in &out.results {
                tally.checks += 1;
                match result {
                    Ok(plan) => {
                        found = true;
                        let &(target, (start, np, nc)) = prepared
                            .next()
                            .expect("one prepared collapse per valid check");
                        winners.push(Winner {
                            p,
                            best: b,
                            target,
                            plan,
                            fans: (base + start, np, nc),
                        });
                    }
                    Err(()) => {
                        tally.refused += 1;
                        let slot = s.slot_index(b.corner);
                        s.edges[slot].refused = state;
                        for x in [p, b.other] {
                            t.refusals[x as usize] = state;
                            refused_now.push(x);
                            if t.listed[x as usize] != state + 1 {
                                t.listed[x as usize] = state + 1;
                                refused_ends.push(x);
                            }
                        }
                    }
                }
            }
        }
        passes += 1;
        if !found {
            if passes == MAX_PASSES {
                break;
            }
            continue;
        }
        phases.lap("block");
        counted += 1;
        if counted == PASSES || passes == MAX_PASSES {
            break;
        }
        // Blocked players take no further part in the step: the next
        // passes sweep the others only.
        let tr: &Tracking = t;
        par_filter_into(players, spare, |&v| {
            (tr.blocked[v as usize].load(Relaxed) != state).then_some(v)
        });
        std::mem::swap(players, spare);
        phases.lap("retain players");
    }
    // Survivor ids are distinct: any sort gives the one order.
    winners.par_sort_unstable_by_key(|w| w.p);
    winners
}

/// Prefetches the positions of the vertices of `fan`'s triangles.
fn prefetch_neighbours(s: &State, fan: &Fan) {
    for &corner in &fan.corners {
        prefetch(&s.positions, s.table.v(next(corner)) as usize);
        prefetch(&s.positions, s.table.v(prev(corner)) as usize);
    }
}

/// Whether no neighbour in `fan` (of P or C) other than P and C has an
/// admitted request with a key below `key`.
fn is_local_minimum(s: &State, p: u32, c: u32, key: u64, keys: &[AtomicU64], fan: &Fan) -> bool {
    let beaten = |x: u32| x != p && x != c && keys[x as usize].load(Relaxed) < key;
    // Each neighbour once: the next vertex of every corner, and the previous
    // one where the fan is open after it.
    fan.corners.iter().all(|&corner| {
        !beaten(s.table.v(next(corner)))
            && (s.table.o(next(corner)) != NONE || !beaten(s.table.v(prev(corner))))
    })
}

/// The record of the collapse of `p` and `b.other` to `target`, given the
/// merged quadric and the positions and split valences of P and C.
fn record(
    b: Best,
    p: u32,
    target: [u32; 3],
    plan: Plan,
    q: &Quadric,
    ends: [([u32; 3], u8); 2],
    orig: &[u32],
) -> Collapse {
    let weight = q.c[0] + q.c[4] + q.c[7];
    let distance = if weight > 0.0 {
        (b.error / weight).sqrt()
    } else {
        0.0
    };
    let input = |v: u32| if v == NONE { NONE } else { orig[v as usize] };
    Collapse {
        p: input(p),
        c: input(b.other),
        wing_a: input(plan.wing_a),
        wing_b: input(plan.wing_b),
        position_p: ends[0].0,
        position_c: ends[1].0,
        position_r: target,
        split_valence_p: ends[0].1,
        split_valence_c: ends[1].1,
        error: b.error,
        distance,
    }
}

/// Applies a step's winners, in parallel, returning their records in order.
///
/// The collapses of a step touch disjoint parts of the mesh: the triangles
/// around P and C, and P's and C's own entries, belong to one collapse each
/// (the endpoints of two winners are never neighbours: each winner blocks
/// its endpoints' 1-rings, here in `step_winners`, for the GPU backends in
/// `gpu::apply_winners`' claims). Only a wing can be shared, so the wings' new
/// corners and valences are set afterwards, in winner order, as one
/// collapse after the other would leave them.
pub(super) fn apply_collapses(s: &mut State, winners: &[Winner], fans: &[u32]) -> Vec<Collapse> {
    // The unsafe writes below rely on this; debug builds (every test run)
    // check it.
    #[cfg(debug_assertions)]
    assert_disjoint(winners, fans);
    let table = TableView {
        vertex: Raw::new(&mut s.table.vertex),
        opposite: Raw::new(&mut s.table.opposite),
        corner_of: Raw::new(&mut s.table.corner_of),
    };
    let positions = Raw::new(&mut s.positions);
    let quadrics = Raw::new(&mut s.quadrics);
    let boundary = Raw::new(&mut s.boundary);
    let alive = Raw::new(&mut s.alive);
    let split_valence = Raw::new(&mut s.split_valence);
    let valence = Raw::new(&mut s.valence);
    let orig: &[u32] = &s.orig;
    let applied: Vec<(Collapse, [(u32, u32); 2])> = winners
        .par_chunks(chunk_size(winners.len()))
        .flat_map_iter(|chunk| {
            chunk.iter().enumerate().map(move |(i, w)| {
                // The next winners' vertices and fans (see `prefetch_ahead`).
                if let Some(w) = chunk.get(i + 4) {
                    for x in [w.p, w.best.other] {
                        quadrics.prefetch(x as usize);
                        positions.prefetch(x as usize);
                    }
                    let start = w.fans.0 as usize;
                    for &c in &fans[start..start + (w.fans.1 + w.fans.2) as usize] {
                        table.vertex.prefetch(c as usize);
                        table.opposite.prefetch(c as usize);
                    }
                }
                let (start, np, nc) = (w.fans.0 as usize, w.fans.1 as usize, w.fans.2 as usize);
                let fan_p = &fans[start..start + np];
                let fan_c = &fans[start + np..start + np + nc];
                let (p, c) = (w.p as usize, w.best.other as usize);
                // SAFETY: P's and C's entries belong to this collapse alone
                // (see above), and nothing else reads these arrays meanwhile.
                let (q, ends) = unsafe {
                    (
                        quadrics.get(p) + quadrics.get(c),
                        [p, c].map(|v| (positions.get(v), split_valence.get(v))),
                    )
                };
                // Built from P and C before the collapse, as its check saw them.
                let record = record(w.best, w.p, w.target, w.plan, &q, ends, orig);
                let mut view = table;
                let anchors = collapse_in(
                    &mut view,
                    w.p,
                    w.best.other,
                    w.plan.left,
                    w.plan.right,
                    fan_p,
                    fan_c,
                );
                // SAFETY: as above.
                unsafe {
                    positions.set(p, w.target);
                    quadrics.set(p, q);
                    boundary.set(p, boundary.get(p) | boundary.get(c));
                    alive.set(c, false);
                    split_valence.set(p, w.plan.valence_r as u8);
                    valence.set(p, w.plan.valence_r as u32);
                }
                (record, anchors)
            })
        })
        .collect();
    let mut records = Vec::with_capacity(applied.len());
    for (w, (record, anchors)) in winners.iter().zip(applied) {
        for (x, corner) in anchors {
            if x != NONE {
                s.table.corner_of[x as usize] = corner;
            }
        }
        for wing in [w.plan.wing_a, w.plan.wing_b] {
            if wing != NONE {
                s.valence[wing as usize] -= 1;
            }
        }
        records.push(record);
    }
    records
}

/// Panics unless the winners' endpoints and the triangles around them
/// (their fans, as the checks walked them) belong to one winner each: what
/// makes the parallel writes of [`apply_collapses`] disjoint.
#[cfg(debug_assertions)]
fn assert_disjoint(winners: &[Winner], fans: &[u32]) {
    let mut owner: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    let mut endpoints = std::collections::HashSet::new();
    for (i, w) in winners.iter().enumerate() {
        for v in [w.p, w.best.other] {
            assert!(
                endpoints.insert(v),
                "vertex {v} is an endpoint of two collapses"
            );
        }
        let (start, np, nc) = (w.fans.0 as usize, w.fans.1 as usize, w.fans.2 as usize);
        for &c in &fans[start..start + np + nc] {
            let j = *owner.entry(c / 3).or_insert(i);
            assert_eq!(j, i, "collapses {j} and {i} share triangle {}", c / 3);
        }
    }
}

/// A slice's elements for writes from parallel tasks, each to elements no
/// other task touches (see [`apply_collapses`]).
struct Raw<T> {
    ptr: *mut T,
    len: usize,
}

impl<T> Clone for Raw<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Raw<T> {}

// SAFETY: a `Raw` is only used for disjoint accesses (see `apply_collapses`).
unsafe impl<T: Send> Send for Raw<T> {}
unsafe impl<T: Send> Sync for Raw<T> {}

impl<T: Copy> Raw<T> {
    fn new(items: &mut [T]) -> Raw<T> {
        Raw {
            ptr: items.as_mut_ptr(),
            len: items.len(),
        }
    }

    /// [`prefetch`] of element `i` (reads nothing the program sees).
    fn prefetch(self, i: usize) {
        if i < self.len {
            prefetch_at(self.ptr.wrapping_add(i).cast_const());
        }
    }

    /// # Safety
    /// No other task writes element `i` meanwhile.
    unsafe fn get(self, i: usize) -> T {
        assert!(i < self.len);
        // SAFETY: in bounds; no concurrent write (the caller's promise).
        unsafe { *self.ptr.add(i) }
    }

    /// # Safety
    /// No other task reads or writes element `i` meanwhile.
    unsafe fn set(self, i: usize, value: T) {
        assert!(i < self.len);
        // SAFETY: in bounds; no concurrent access (the caller's promise).
        unsafe { *self.ptr.add(i) = value }
    }
}

/// The corner table as [`Raw`] views, for one collapse of a parallel step:
/// it reads and writes only its own triangles (see [`collapse_in`]).
#[derive(Clone, Copy)]
struct TableView {
    vertex: Raw<u32>,
    opposite: Raw<u32>,
    corner_of: Raw<u32>,
}

// SAFETY (all methods): a `TableView` exists only inside `apply_collapses`,
// whose collapses touch disjoint corners and vertices.
impl CornerAccess for TableView {
    fn v(&self, c: u32) -> u32 {
        unsafe { self.vertex.get(c as usize) }
    }
    fn o(&self, c: u32) -> u32 {
        unsafe { self.opposite.get(c as usize) }
    }
    fn set_v(&mut self, c: u32, v: u32) {
        unsafe { self.vertex.set(c as usize, v) }
    }
    fn set_o(&mut self, c: u32, o: u32) {
        unsafe { self.opposite.set(c as usize, o) }
    }
    fn set_corner_of(&mut self, v: u32, c: u32) {
        unsafe { self.corner_of.set(v as usize, c) }
    }
}

/// Re-evaluates the edges around each merged vertex (only their quadric or
/// position changed) and stamps the merged vertices and their neighbours as
/// changed in `next_state` (their 1-rings are new). Their neighbours get the
/// refreshed edges as offers (into `offers`, see `take_offers`): no other
/// vertex's request can change.
///
/// The merged vertices choose here under `scale`, from the slots just
/// evaluated (a pick at the next step would see the same fresh slots, no
/// refusal and nothing blocked; should the next step measure edges again,
/// its rescale sorts these requests like the others).
fn refresh_edges(
    s: &mut State,
    t: &mut Tracking,
    merged: &[u32],
    next_state: u32,
    scale: Scale,
    chunks: &mut Vec<RefreshChunk>,
) {
    // The slots are written from the parallel part: each merged vertex
    // writes the slots of its own edges, and the merged vertices of one
    // step are never adjacent (their collapses' fans were disjoint), so no
    // slot is written twice. Nothing in the parallel part reads the slots
    // (the refreshed ones are computed, and rankings take them as
    // arguments), so they are taken out of the state meanwhile. Debug
    // builds check that the written slots are distinct.
    let mut taken_slots = std::mem::take(&mut s.edges);
    let slots = Raw::new(&mut taken_slots);
    // So is each merged vertex's bookkeeping, by the task that refreshes it.
    let mine = MergedView {
        changed: Raw::new(&mut t.changed),
        merged: Raw::new(&mut t.merged),
        listed: Raw::new(&mut t.listed),
        best: Raw::new(&mut t.best),
        second: Raw::new(&mut t.second),
        bound: Raw::new(&mut t.bound),
        refusals: Raw::new(&mut t.refusals),
    };
    let s_now: &State = s;
    let size = chunk_size(merged.len());
    let count = merged.len().div_ceil(size);
    if chunks.len() < count {
        chunks.resize_with(count, RefreshChunk::default);
    }
    // Chunks past this step's keep their capacity and nothing else.
    for chunk in &mut chunks[count..] {
        chunk.clear();
    }
    merged
        .par_chunks(size)
        .zip(chunks[..count].par_iter_mut())
        .for_each(|(chunk, out)| {
            out.clear();
            let mut edges: Vec<(u32, u32)> = Vec::with_capacity(16);
            for (i, &r) in chunk.iter().enumerate() {
                prefetch_ahead(s_now, chunk, i);
                // Edge (r, prev c) faces next c; a boundary edge (r, next c)
                // faces prev c.
                edges.clear();
                s_now.table.for_each_corner(r, |c| {
                    edges.push((s_now.table.v(prev(c)), next(c)));
                    if s_now.table.o(prev(c)) == NONE {
                        edges.push((s_now.table.v(next(c)), prev(c)));
                    }
                });
                // The neighbours' quadrics are the evaluations' cache misses:
                // ask for them all at once.
                for &(x, facing) in &edges {
                    prefetch(&s_now.quadrics, x as usize);
                    prefetch(&s_now.positions, x as usize);
                    slots.prefetch(s_now.slot_index(facing));
                }
                let mut ranking = Ranking::new(s_now, r, scale);
                for &(x, facing) in &edges {
                    let slot = edge_slot(s_now, facing);
                    let index = s_now.slot_index(facing);
                    #[cfg(debug_assertions)]
                    out.updates.push((index as u32, slot));
                    // SAFETY: no other task writes or reads slot `index`
                    // (see above).
                    unsafe { slots.set(index, slot) };
                    out.offers.push(Offer { x, r, facing });
                    ranking.consider(x, facing, &slot);
                }
                // SAFETY: merged vertices are distinct; only this task
                // touches vertex `r`'s bookkeeping.
                unsafe { mine.refreshed(r, next_state, ranking.choices()) };
            }
            out.measure_span();
        });
    s.edges = taken_slots;
    #[cfg(debug_assertions)]
    {
        let mut written: Vec<u32> = chunks
            .iter()
            .flat_map(|c| c.updates.iter().map(|u| u.0))
            .collect();
        written.sort_unstable();
        assert!(
            written.windows(2).all(|w| w[0] != w[1]),
            "a refreshed slot is written by two merged vertices"
        );
    }
    for o in chunks.iter().flat_map(|chunk| chunk.offers.iter()) {
        t.changed[o.x as usize] = next_state;
    }
}

/// The bookkeeping of the merged vertices, written by the refresh's tasks.
#[derive(Clone, Copy)]
struct MergedView {
    changed: Raw<u32>,
    merged: Raw<u32>,
    listed: Raw<u32>,
    best: Raw<Best>,
    second: Raw<Option<Best>>,
    bound: Raw<u32>,
    refusals: Raw<u32>,
}

impl MergedView {
    /// Merged vertex `r` is new in `next_state` (its 1-ring changed), and
    /// its request is `choices`.
    ///
    /// # Safety
    /// No other task reads or writes vertex `r`'s entries meanwhile.
    unsafe fn refreshed(self, r: u32, next_state: u32, choices: Choices) {
        let v = r as usize;
        // SAFETY: the caller's promise.
        unsafe {
            self.changed.set(v, next_state);
            self.merged.set(v, next_state);
            // Never listed already: merged vertices are not refused ends.
            self.listed.set(v, next_state);
            self.best.set(v, choices.best);
            self.second.set(v, choices.second);
            self.bound.set(v, choices.bound);
            // Its edges are all fresh: nothing refused to forget.
            self.refusals.set(v, 0);
        }
    }
}

/// One chunk's part of a refresh, kept from step to step for its capacity:
/// the refreshed slots (index, slot; debug builds only, to check that no two
/// vertices write one slot) and the offers to the other ends. The offers
/// stay until the next step takes them.
#[derive(Default)]
struct RefreshChunk {
    updates: Vec<(u32, EdgeSlot)>,
    offers: Vec<Offer>,
    /// The smallest and largest vertex the offers go to (`take_offers`
    /// skips the chunk in the parts of the vertex range it misses).
    span: (u32, u32),
}

impl RefreshChunk {
    fn clear(&mut self) {
        self.updates.clear();
        self.offers.clear();
        self.span = (u32::MAX, 0);
    }

    /// Sets `span` from the offers.
    fn measure_span(&mut self) {
        self.span = self
            .offers
            .iter()
            .fold((u32::MAX, 0), |(lo, hi), o| (lo.min(o.x), hi.max(o.x)));
    }
}

/// Stamps with `stamp` the vertices within two edges of each merged vertex:
/// the only ones whose best collapse can have changed (errors, links,
/// fold-overs and wing valences all live in the 2-ring).
pub(super) fn mark_two_rings(s: &State, merged: &[u32], dirty: &[AtomicU32], stamp: u32) {
    merged.par_iter().for_each_init(
        || (Fan::default(), Fan::default()),
        |(fan, inner), &r| {
            dirty[r as usize].store(stamp, Relaxed);
            s.table.fan(r, fan);
            for x in neighbours_of(s, fan) {
                dirty[x as usize].store(stamp, Relaxed);
                s.table.fan(x, inner);
                for y in neighbours_of(s, inner) {
                    dirty[y as usize].store(stamp, Relaxed);
                }
            }
        },
    );
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

/// Mean length of the live edges, for the sub-grid cell size and the flat
/// threshold. Keeps the list of triangles that were alive at the last
/// measure, so a measure costs the live triangles, not every corner ever
/// allocated (the corner array never shrinks: with 43 measures down to the
/// seed, sweeping it cost more than some whole phases).
pub(super) struct EdgeMeter {
    triangles: Vec<u32>,
}

impl EdgeMeter {
    pub fn new(s: &State) -> EdgeMeter {
        EdgeMeter {
            triangles: (0..(s.table.vertex.len() / 3) as u32).collect(),
        }
    }

    pub fn measure(&mut self, s: &State) -> f64 {
        let t = &s.table;
        self.triangles.retain(|&k| t.v(3 * k) != NONE);
        // Fixed chunks summed in order: the same bits whatever the thread
        // count (a rayon reduce's tree follows the work stealing).
        let sums: Vec<f64> = self
            .triangles
            .par_chunks(4096)
            .map(|chunk| {
                let mut sum = 0.0;
                for &k in chunk {
                    for c in 3 * k..3 * k + 3 {
                        let a = s.geometry(t.v(c));
                        let b = s.geometry(t.v(next(c)));
                        sum += crate::quadric::norm(crate::quadric::sub(a, b));
                    }
                }
                sum
            })
            .collect();
        let count = 3 * self.triangles.len();
        if count == 0 {
            1.0
        } else {
            sums.iter().sum::<f64>() / count as f64
        }
    }
}

/// The live vertices and triangles of a simplification state as a mesh in
/// real coordinates, compacted (surviving vertices in ascending id, live
/// triangles in order).
pub(super) fn live_mesh(
    table: &CornerTable,
    alive: &[bool],
    positions: &[[u32; 3]],
    mesh: &QuantizedMesh,
) -> crate::Mesh {
    let mut index = vec![NONE; alive.len()];
    let mut real = Vec::new();
    for v in (0..alive.len()).filter(|&v| alive[v]) {
        index[v] = real.len() as u32;
        real.push(mesh.dequantize(positions[v]));
    }
    let triangles = table
        .vertex
        .chunks_exact(3)
        .filter(|t| t[0] != NONE)
        .map(|t| std::array::from_fn(|k| index[t[k] as usize]))
        .collect();
    crate::Mesh {
        positions: real,
        triangles,
    }
}

impl Simplification {
    /// The simplified mesh in real coordinates, compacted (surviving
    /// vertices in ascending id, live triangles in order).
    pub fn to_mesh(&self, mesh: &QuantizedMesh) -> crate::Mesh {
        live_mesh(&self.table, &self.alive, &self.positions, mesh)
    }

    /// Largest quadric error of any collapse.
    pub fn max_error(&self) -> f64 {
        self.step_errors.iter().copied().fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::{fractal_terrain, icosphere};
    use crate::quantize::{Units, quantize};

    /// A terrain with a square hole cut out (inner boundary edges too).
    fn holed_terrain() -> crate::Mesh {
        let mut mesh = fractal_terrain(24, 5);
        let side = 24u32;
        let inside = |v: u32| (8..14).contains(&(v % side)) && (8..14).contains(&(v / side));
        mesh.triangles.retain(|t| !t.iter().all(|&v| inside(v)));
        mesh
    }

    #[test]
    fn fan_quadrics_are_the_vertex_quadrics_bit_for_bit() {
        for mesh in [fractal_terrain(40, 3), icosphere(3), holed_terrain()] {
            let q = quantize(&mesh, 14, Units::Linear);
            let s = State::new(&q, &SimplifyOptions::default());
            assert!(s.manifold);
            let geometry: Vec<[f64; 3]> = (0..q.positions.len() as u32)
                .map(|v| s.geometry(v))
                .collect();
            for weight in [0.0, crate::quadric::DEFAULT_BOUNDARY_WEIGHT] {
                let want = vertex_quadrics(&geometry, &q.triangles, weight);
                let got = s.fan_quadrics(weight).expect("manifold");
                assert_eq!(got, want);
            }
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
