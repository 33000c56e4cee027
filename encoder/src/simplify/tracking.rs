//! Per-vertex bookkeeping of the CPU step loop: requests, runners-up and
//! the state stamps that say what is still known.

use std::sync::atomic::{AtomicU32, AtomicU64};

use rayon::prelude::*;

use super::select::{Best, Known};

/// Per-vertex bookkeeping of the CPU step loop (the GPU backends keep their
/// own on the device). The `u32` stamps hold state numbers ([`Known`]), so
/// none is ever cleared.
pub(super) struct Tracking {
    /// Each vertex's request (§2 step a), chosen without the constraints of
    /// a step's later passes.
    pub(super) best: Vec<Best>,
    /// The runner-up of each request (another partner), `None` if unknown:
    /// a vertex whose partner a collapse took falls back on it instead of
    /// walking its fan.
    pub(super) second: Vec<Option<Best>>,
    /// [`Choices::bound`](super::select::Choices::bound) of each request; 0 where the request may not be
    /// what a pick gives (chosen while neighbours were blocked).
    pub(super) bound: Vec<u32>,
    /// Requests chosen again within a step (blocked partners, refused
    /// edges), valid where `repick_at == state`; they never outlive it.
    pub(super) repick: Vec<Best>,
    pub(super) repick_at: Vec<u32>,
    /// State since which each vertex's 1-ring is what it is.
    pub(super) changed: Vec<u32>,
    /// `== state`: the vertex was merged (survived as R) at the last step.
    pub(super) merged: Vec<u32>,
    /// Latest state in which one of the vertex's edges was refused (0: none
    /// since its 1-ring last changed).
    pub(super) refusals: Vec<u32>,
    /// `== state`: a winner of this step blocks the vertex (set by the
    /// checks as they find winners, in parallel).
    pub(super) blocked: Vec<AtomicU32>,
    /// `== state`: the vertex chooses from scratch at this step.
    pub(super) listed: Vec<u32>,
    /// `== state`: the vertex was sorted into choosing or taking offers.
    pub(super) sorted: Vec<u32>,
    /// Pair key of each vertex's admitted request in the current pass,
    /// `u64::MAX` otherwise (reset after each pass, so never swept whole).
    pub(super) keys: Vec<AtomicU64>,
    /// `== pass`: the vertex was claimed by a task of [`choose`](super::offers::choose)'s pass
    /// `pass` (a list of choosers may name a vertex twice).
    pub(super) claimed: Vec<AtomicU32>,
    /// The last pass of [`choose`](super::offers::choose).
    pub(super) passes: u32,
}

impl Tracking {
    /// Arrays of zeros come zeroed from the allocator (their pages are
    /// touched by the passes); the others are filled in parallel, which
    /// also spreads their first page faults over the threads.
    pub(super) fn new(n: usize) -> Tracking {
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

    pub(super) fn known(&self, state: u32) -> Known<'_> {
        Known {
            state,
            changed: &self.changed,
            blocked: &self.blocked,
        }
    }

    /// The request of `v` in the current pass of step `state`.
    pub(super) fn request(&self, v: u32, state: u32) -> &Best {
        if self.repick_at[v as usize] == state {
            &self.repick[v as usize]
        } else {
            &self.best[v as usize]
        }
    }
}
