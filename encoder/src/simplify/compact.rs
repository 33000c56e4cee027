//! Dense renumbering of the live vertices and triangles between steps.

use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;

use super::cpu::InputArrays;
use super::meter::EdgeMeter;
use super::offers::Offer;
use super::refresh::RefreshChunk;
use super::select::Best;
use super::state::State;
use super::tracking::Tracking;
use crate::corner_table::{CornerTable, NONE};

/// What the loop keeps in current ids besides the state and tracking, for
/// [`compact`].
pub(super) struct Renumbered<'a> {
    /// The live vertices, ascending (become 0..n).
    pub(super) live: &'a mut Vec<u32>,
    /// (P, C) of the step just applied: requests still naming C (its
    /// neighbours take their offers at the next step) name P instead, who
    /// was merged at that step and so counts as taken just the same.
    pub(super) pairs: &'a [(u32, u32)],
    pub(super) choosers: &'a mut Vec<u32>,
    pub(super) offers: &'a mut [RefreshChunk],
    pub(super) meter: &'a mut EdgeMeter,
    pub(super) input: &'a mut InputArrays,
}

/// Renumbers the live vertices (in `live` order, ascending) and the live
/// triangles (in order) densely, between two steps. Every comparison of ids
/// (index priority, tie-breaks, the lower corner of an edge) keeps its
/// outcome, so the collapses are the same, only cheaper to find: once most
/// vertices are gone, each pass otherwise reads one live vertex per cache
/// line and per page. The state numbers in the tracking stamps carry over.
pub(super) fn compact(s: &mut State, t: &mut Tracking, r: Renumbered<'_>) {
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
