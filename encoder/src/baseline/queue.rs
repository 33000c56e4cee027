//! The collapse priority queue: a 4-ary min-heap of 16-byte entries.
//!
//! Profiling the 1M-vertex terrain showed `BinaryHeap::pop` (24-byte
//! entries, binary) taking 60 % of the run, nearly all of it cache misses
//! down a 22-level tree. Packing an entry into one `u128` (error bits, then
//! the vertex pair) makes comparisons a single integer compare and the
//! ordering total and deterministic, and four children per node halve the
//! depth, with a node's children sharing one or two cache lines.
//!
//! Entries are never updated in place (lazy deletion): the simplifier
//! re-scores a popped edge and skips it when the error no longer matches.

/// A queued collapse of edge `(u, v)` into `u`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    pub error: f64,
    pub u: u32,
    pub v: u32,
}

/// Order-preserving bits of an error: non-negative floats compare like
/// their bit patterns; NaN sorts last, -0 and negatives (never produced by
/// [`Quadric::error`](crate::quadric::Quadric::error)) first.
pub fn error_key(error: f64) -> u64 {
    if error > 0.0 {
        error.to_bits()
    } else if error.is_nan() {
        u64::MAX
    } else {
        0
    }
}

impl Entry {
    fn pack(self) -> u128 {
        (u128::from(error_key(self.error)) << 64) | (u128::from(self.u) << 32) | u128::from(self.v)
    }

    fn unpack(x: u128) -> Entry {
        Entry {
            error: f64::from_bits((x >> 64) as u64),
            u: (x >> 32) as u32,
            v: x as u32,
        }
    }
}

const ARITY: usize = 4;

/// Min-heap of [`Entry`]: cheapest error first, ties by `(u, v)`.
#[derive(Default)]
pub struct Queue {
    heap: Vec<u128>,
}

impl Queue {
    /// Heapifies in O(n).
    pub fn from_entries(entries: impl IntoIterator<Item = Entry>) -> Queue {
        let mut q = Queue {
            heap: entries.into_iter().map(Entry::pack).collect(),
        };
        for i in (0..q.heap.len() / ARITY + 1).rev() {
            q.sift_down(i);
        }
        q
    }

    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    pub fn push(&mut self, entry: Entry) {
        let x = entry.pack();
        let mut i = self.heap.len();
        self.heap.push(x);
        while i > 0 {
            let parent = (i - 1) / ARITY;
            if self.heap[parent] <= x {
                break;
            }
            self.heap[i] = self.heap[parent];
            i = parent;
        }
        self.heap[i] = x;
    }

    pub fn pop(&mut self) -> Option<Entry> {
        let last = self.heap.pop()?;
        let Some(&top) = self.heap.first() else {
            return Some(Entry::unpack(last));
        };
        self.heap[0] = last;
        self.sift_down(0);
        Some(Entry::unpack(top))
    }

    fn sift_down(&mut self, mut i: usize) {
        let n = self.heap.len();
        let Some(&x) = self.heap.get(i) else { return };
        loop {
            let first = ARITY * i + 1;
            if first >= n {
                break;
            }
            let end = (first + ARITY).min(n);
            let mut best = first;
            for c in first + 1..end {
                if self.heap[c] < self.heap[best] {
                    best = c;
                }
            }
            if self.heap[best] >= x {
                break;
            }
            self.heap[i] = self.heap[best];
            i = best;
        }
        self.heap[i] = x;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(error: f64, u: u32) -> Entry {
        Entry { error, u, v: 0 }
    }

    #[test]
    fn cheapest_pops_first() {
        let mut q =
            Queue::from_entries([entry(3.0, 0), entry(1.0, 1), entry(2.0, 2), entry(1.0, 0)]);
        let order: Vec<(f64, u32)> =
            std::iter::from_fn(|| q.pop().map(|e| (e.error, e.u))).collect();
        assert_eq!(order, vec![(1.0, 0), (1.0, 1), (2.0, 2), (3.0, 0)]);
    }

    #[test]
    fn matches_std_binary_heap() {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        // Errors spanning many magnitudes, pushes and pops interleaved.
        let mut x = 12345u64;
        let mut rand = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut make = |u| {
            entry(
                (rand() % 1000) as f64 * 10f64.powi((rand() % 20) as i32 - 10),
                u,
            )
        };
        let key = |e: Entry| Reverse((error_key(e.error), e.u, e.v));
        let initial: Vec<Entry> = (0..500).map(&mut make).collect();
        let mut reference: BinaryHeap<_> = initial.iter().map(|&e| key(e)).collect();
        let mut q = Queue::from_entries(initial);
        for i in 0..3000u32 {
            if i.is_multiple_of(3) {
                let e = make(1000 + i);
                q.push(e);
                reference.push(key(e));
            } else {
                assert_eq!(q.pop().map(key), reference.pop());
            }
        }
        assert_eq!(q.len(), reference.len());
    }

    #[test]
    fn error_keys_order_like_floats() {
        let xs = [0.0, 1e-300, 1e-13, 0.5, 1.0, 3.0, 1e300, f64::INFINITY];
        for w in xs.windows(2) {
            assert!(error_key(w[0]) < error_key(w[1]));
        }
        assert_eq!(error_key(-0.0), 0);
        assert_eq!(error_key(f64::NAN), u64::MAX);
    }
}
