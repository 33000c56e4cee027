//! A reused `Simplifier` allocates nothing once it has seen a tile of the
//! same size (counted with a wrapping global allocator).
//!
//! Only the test thread's allocations count: libtest's main thread does its
//! own bookkeeping while the test runs, and on a loaded machine (CI) that
//! once landed in the counted window as 4 allocations.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use splitstream_sdk_native::grid_tile::{Params, Side, Simplifier, Tile};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Set on the thread whose allocations count. Const-initialised and
    /// without a destructor, so reading it never allocates.
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTING.try_with(Cell::get).unwrap_or(false) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn terrain(n: usize, seed: f64) -> Vec<f64> {
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64 * 30.0, (i / n) as f64 * 30.0);
            (40.0 * (x / 170.0 + seed).sin() * (y / 230.0).cos()
                + 15.0 * (x / 61.0 + y / 97.0).sin())
            .round()
        })
        .collect()
}

#[test]
fn reused_simplifier_does_not_allocate() {
    let n = 65;
    let tiles: Vec<Vec<f64>> = (0..4).map(|s| terrain(n, s as f64)).collect();
    let mut params = Params::new(2000.0);
    params.neighbour_res[Side::East as usize] = Some(60.0);
    let mut simplifier = Simplifier::new(n, n);
    fn tile(h: &[f64]) -> Tile<'_> {
        Tile {
            rows: 65,
            cols: 65,
            heights: h,
            spacing: [30.0, 30.0],
            origin: [0.0, 0.0],
        }
    }
    // Warm up on one tile, then count over the others.
    simplifier.simplify(&tile(&tiles[0]), &params).unwrap();
    let mut rects = 0;
    // The count itself: a vector grown here would be counted.
    let mut probe: Vec<u8> = Vec::new();
    COUNTING.with(|c| c.set(true));
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    probe.push(1);
    let probed = ALLOCATIONS.load(Ordering::Relaxed);
    for h in &tiles[1..] {
        let (_, stats) = simplifier.simplify(&tile(h), &params).unwrap();
        rects += stats.rectangles;
    }
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    COUNTING.with(|c| c.set(false));
    assert_eq!(probed - before, 1, "the counter missed an allocation");
    let after = after - 1;
    assert!(rects > 3);
    assert_eq!(after - before, 0, "allocations while simplifying");
}
