//! Re-evaluating the edges around the merged vertices after a step.

use std::sync::atomic::AtomicU32;
use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;

use super::apply::Raw;
use super::offers::Offer;
use super::offers::prefetch_ahead;
use super::parallel::chunk_size;
use super::select::{Best, Choices, EdgeSlot, EdgesOf, Ranking, Scale, edge_slot};
use super::state::State;
use super::tracking::Tracking;
use crate::corner_table::{Fan, NONE, next, prev};
use crate::prefetch::prefetch;

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
pub(super) fn refresh_edges(
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
                let of_r = EdgesOf::new(s_now, r);
                for &(x, facing) in &edges {
                    let slot = of_r.slot(s_now, x);
                    debug_assert_eq!(slot, edge_slot(s_now, facing));
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
pub(super) struct RefreshChunk {
    updates: Vec<(u32, EdgeSlot)>,
    pub(super) offers: Vec<Offer>,
    /// The smallest and largest vertex the offers go to (`take_offers`
    /// skips the chunk in the parts of the vertex range it misses).
    pub(super) span: (u32, u32),
}

impl RefreshChunk {
    fn clear(&mut self) {
        self.updates.clear();
        self.offers.clear();
        self.span = (u32::MAX, 0);
    }

    /// Sets `span` from the offers.
    pub(super) fn measure_span(&mut self) {
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
