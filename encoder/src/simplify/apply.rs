//! Applying a step's winners in parallel (their neighbourhoods are disjoint).

use rayon::prelude::*;

use super::parallel::chunk_size;
use super::state::{Collapse, State};
use super::winners::{Winner, record};
use crate::corner_table::{CornerAccess, NONE, collapse_in};
use crate::prefetch::prefetch_at;

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
pub(super) struct Raw<T> {
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
    pub(super) fn new(items: &mut [T]) -> Raw<T> {
        Raw {
            ptr: items.as_mut_ptr(),
            len: items.len(),
        }
    }

    /// [`prefetch`](crate::prefetch::prefetch) of element `i` (reads nothing the program sees).
    pub(super) fn prefetch(self, i: usize) {
        if i < self.len {
            prefetch_at(self.ptr.wrapping_add(i).cast_const());
        }
    }

    /// # Safety
    /// No other task writes element `i` meanwhile.
    pub(super) unsafe fn get(self, i: usize) -> T {
        assert!(i < self.len);
        // SAFETY: in bounds; no concurrent write (the caller's promise).
        unsafe { *self.ptr.add(i) }
    }

    /// # Safety
    /// No other task reads or writes element `i` meanwhile.
    pub(super) unsafe fn set(self, i: usize, value: T) {
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
