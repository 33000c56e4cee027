//! Choosing each vertex's request (§2 step a): offers of refreshed edges,
//! picks from scratch, repicks within a step, and validation.

use std::sync::atomic::AtomicU32;
use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;

use super::apply::Raw;
use super::check::{CheckScratch, check_placed};
use super::parallel::{chunk_size, par_chunks_map};
use super::refresh::RefreshChunk;
use super::select::{Best, Choices, Known, Scale, evaluate, offer, pick_edge};
use super::state::State;
use super::tracking::Tracking;
use super::winners::Tally;
use crate::corner_table::NONE;
use crate::prefetch::prefetch;

/// A refreshed edge of merged vertex `r`, offered to its other end `x`.
#[derive(Clone, Copy)]
pub(super) struct Offer {
    pub(super) x: u32,
    pub(super) r: u32,
    /// A corner facing the edge.
    pub(super) facing: u32,
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
pub(super) fn take_offers(
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
pub(super) fn prefetch_ahead(s: &State, list: &[u32], i: usize) {
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
pub(super) fn prefetch_fan(s: &State, v: u32) {
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
pub(super) fn choose(
    s: &State,
    t: &mut Tracking,
    vertices: &[u32],
    scale: Scale,
    state: u32,
) -> Vec<u32> {
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
pub(super) fn repick(s: &State, t: &mut Tracking, vertices: &[u32], scale: Scale, state: u32) {
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
pub(super) fn validate(
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
                scratch.walk_p(s_now, p);
                scratch.walk_c(s_now, c);
                let ok = check_placed(s_now, p, c, target, scale, &mut scratch).is_ok();
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
