//! A step's winners: reciprocal requests that are local minima of their
//! 1-ring (§2 steps b and c) and pass the collapse checks.

use std::sync::atomic::AtomicU64;
use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;

use super::check::{CheckScratch, Plan, check_placed};
use super::offers::prefetch_fan;
use super::offers::{repick, validate};
use super::parallel::{par_chunks_map, par_filter_into};
use super::phases::Phases;
use super::select::{Best, Scale, error_key, evaluate, pair_key};
use super::state::{Collapse, State};
use super::tracking::Tracking;
use crate::corner_table::{Fan, NONE, next, prev};
use crate::prefetch::prefetch;
use crate::quadric::Quadric;

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

/// Lists a step rebuilds, kept between steps for their capacity.
#[derive(Default)]
pub(super) struct Buffers {
    players: Vec<u32>,
    spare: Vec<u32>,
    again: Vec<u32>,
    admitted: Vec<(u32, u64)>,
    /// The fans of the step's winners (see [`Winner::fans`]).
    pub(super) fans: Vec<u32>,
    /// The step's checks (reset when it starts).
    pub(super) tally: Tally,
}

/// Checks made in a step and how many were refused.
#[derive(Clone, Copy, Default)]
pub(super) struct Tally {
    pub(super) checks: usize,
    pub(super) refused: usize,
}

/// A valid check's target and fans (offset into the chunk's corners,
/// lengths of P's and C's).
type Prepared = ([u32; 3], (u32, u32, u32));

/// One chunk's checks: results in order, and for the valid ones their
/// targets and their fans (offsets into `corners`).
#[derive(Default)]
pub(super) struct Checked {
    /// Each checked pair's survivor and request (read here, in the
    /// parallel pass: the serial loop over the results then touches no
    /// per-vertex array, which on the 4M terrain was a cache miss a pair).
    results: Vec<(u32, Best, Result<Plan, ()>)>,
    prepared: Vec<Prepared>,
    corners: Vec<u32>,
}

/// What one step selects with: its state number, the threshold S, the
/// scale of the tie-breaks and whether requests are checked before they
/// pair up (`validate`).
#[derive(Clone, Copy)]
pub(super) struct Step {
    pub(super) state: u32,
    pub(super) threshold: f64,
    pub(super) scale: Scale,
    pub(super) validating: bool,
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
pub(super) fn step_winners(
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
                let placed = check_placed(s_now, v, c, target, scale, &mut scratch);
                let result = placed.map(|(_, plan)| plan);
                if let Ok((target, _)) = placed {
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
pub(super) fn record(
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
