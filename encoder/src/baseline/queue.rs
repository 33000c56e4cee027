//! The collapse priority queue: a 4-ary min-heap of 8-byte entries.
//!
//! Profiling the 1M-vertex terrain showed `BinaryHeap::pop` over 24-byte
//! entries taking 60 % of the run, nearly all of it cache misses down a
//! 22-level tree. An entry is now one `u64`: the error rounded to `f32`
//! (whose bits order like the value) above the corner that names the edge,
//! so comparisons are one integer compare, ties break deterministically, a
//! node's four children share one cache line or two, and the tree is half
//! as deep. Rounding the error only reorders collapses whose errors agree
//! to 7 digits; the simplifier re-scores every popped edge in `f64`.
//!
//! Entries are never updated in place (lazy deletion): the simplifier skips
//! a popped entry when re-scoring its edge gives a different key.

/// A queued collapse: the edge facing `corner`, at `error`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    pub error: f32,
    pub corner: u32,
}

/// The queue's order-preserving key of an error: non-negative floats
/// compare like their bit patterns; NaN sorts last, negatives and -0
/// (never produced by [`Quadric::error`](crate::quadric::Quadric::error))
/// first, as 0.
pub fn error_key(error: f64) -> u32 {
    let e = error as f32;
    if e > 0.0 {
        e.to_bits()
    } else if e.is_nan() {
        u32::MAX
    } else {
        0
    }
}

impl Entry {
    pub fn new(error: f64, corner: u32) -> Entry {
        Entry {
            error: f32::from_bits(error_key(error)),
            corner,
        }
    }

    fn pack(self) -> u64 {
        (u64::from(self.error.to_bits()) << 32) | u64::from(self.corner)
    }

    fn unpack(x: u64) -> Entry {
        Entry {
            error: f32::from_bits((x >> 32) as u32),
            corner: x as u32,
        }
    }
}

const ARITY: usize = 4;

/// Min-heap of [`Entry`]: cheapest error first, ties by corner.
#[derive(Default)]
pub struct Queue {
    heap: Vec<u64>,
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

    fn entry(error: f64, corner: u32) -> Entry {
        Entry::new(error, corner)
    }

    #[test]
    fn cheapest_pops_first() {
        let mut q =
            Queue::from_entries([entry(3.0, 0), entry(1.0, 1), entry(2.0, 2), entry(1.0, 0)]);
        let order: Vec<(f32, u32)> =
            std::iter::from_fn(|| q.pop().map(|e| (e.error, e.corner))).collect();
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
        let mut make = |c| {
            entry(
                (rand() % 1000) as f64 * 10f64.powi((rand() % 20) as i32 - 10),
                c,
            )
        };
        let key = |e: Entry| Reverse((e.error.to_bits(), e.corner));
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
        let xs = [
            0.0,
            1e-40,
            1e-30,
            1e-13,
            0.5,
            1.0,
            3.0,
            1e30,
            1e300,
            f64::INFINITY,
        ];
        for w in xs.windows(2) {
            assert!(error_key(w[0]) <= error_key(w[1]));
        }
        assert!(error_key(1e-13) < error_key(1.1e-13));
        assert_eq!(error_key(-0.0), 0);
        assert_eq!(error_key(-1.0), 0);
        assert_eq!(error_key(f64::NAN), u32::MAX);
    }
}
