//! Compressed bucket lists (counting sort by key), the building block of the
//! O(n) edge and vertex tables used by checking and repair.
//!
//! A `HashMap` per edge costs several times more time and memory on
//! multi-million triangle meshes; bucketing half-edges by their smaller
//! vertex and sorting each (tiny) bucket gives the same grouping,
//! deterministically.

use rayon::prelude::*;

/// Items grouped by a bucket index in `0..buckets`.
pub(crate) struct Buckets<T> {
    offsets: Vec<usize>,
    items: Vec<T>,
}

impl<T: Copy + Default + Send> Buckets<T> {
    /// Builds the buckets from `(bucket, item)` pairs; `pairs` is called twice
    /// (count, then fill) and must yield the same sequence both times.
    pub(crate) fn build<I>(buckets: usize, pairs: impl Fn() -> I) -> Self
    where
        I: Iterator<Item = (usize, T)>,
    {
        let mut offsets = vec![0usize; buckets + 1];
        for (b, _) in pairs() {
            offsets[b + 1] += 1;
        }
        for i in 0..buckets {
            offsets[i + 1] += offsets[i];
        }
        let mut cursor = offsets[..buckets].to_vec();
        let mut items = vec![T::default(); offsets[buckets]];
        for (b, item) in pairs() {
            items[cursor[b]] = item;
            cursor[b] += 1;
        }
        Buckets { offsets, items }
    }

    /// [`Self::build`] from `K` pairs per item `0..count` (`pairs(i)`,
    /// called twice per item and giving the same pairs both times), in
    /// item order: the same buckets as `build` over the flattened pairs.
    /// Plain loops over fixed arrays, where a flattening iterator's state
    /// machine cost about twice the instructions of the counting sort
    /// itself (the input check's edge and link tables).
    pub(crate) fn build_fixed<const K: usize>(
        buckets: usize,
        count: usize,
        pairs: impl Fn(usize) -> [(usize, T); K],
    ) -> Self {
        let mut offsets = vec![0usize; buckets + 1];
        for i in 0..count {
            for (b, _) in pairs(i) {
                offsets[b + 1] += 1;
            }
        }
        for i in 0..buckets {
            offsets[i + 1] += offsets[i];
        }
        let mut cursor = offsets[..buckets].to_vec();
        let mut items = vec![T::default(); offsets[buckets]];
        for i in 0..count {
            for (b, item) in pairs(i) {
                items[cursor[b]] = item;
                cursor[b] += 1;
            }
        }
        Buckets { offsets, items }
    }

    pub(crate) fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    pub(crate) fn get(&self, bucket: usize) -> &[T] {
        &self.items[self.offsets[bucket]..self.offsets[bucket + 1]]
    }

    /// Sorts every bucket with `sort` (buckets are small: vertex degrees),
    /// in parallel over contiguous runs of buckets.
    pub(crate) fn sort_each(&mut self, sort: impl Fn(&mut [T]) + Sync) {
        const RUN: usize = 1 << 14;
        let n = self.len();
        let mut runs = Vec::with_capacity(n / RUN + 1);
        let mut rest: &mut [T] = &mut self.items;
        let mut start = 0;
        while start < n {
            let end = (start + RUN).min(n);
            let (run, tail) = rest.split_at_mut(self.offsets[end] - self.offsets[start]);
            runs.push((start, end, run));
            rest = tail;
            start = end;
        }
        let offsets = &self.offsets;
        runs.into_par_iter().for_each(|(start, end, run)| {
            let base = offsets[start];
            for b in start..end {
                sort(&mut run[offsets[b] - base..offsets[b + 1] - base]);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_items_by_bucket() {
        let data = [(2usize, 'c'), (0, 'b'), (2, 'a'), (3, 'd')];
        let mut b = Buckets::build(4, || data.iter().copied());
        assert_eq!(b.len(), 4);
        assert_eq!(b.get(0), &['b']);
        assert!(b.get(1).is_empty());
        assert_eq!(b.get(2), &['c', 'a']);
        b.sort_each(|s| s.sort_unstable());
        assert_eq!(b.get(2), &['a', 'c']);
        assert_eq!(b.get(3), &['d']);
    }

    #[test]
    fn fixed_pairs_group_like_the_flattened_ones() {
        let pairs = |i: usize| [((i * 7) % 5, i as u32), ((i * 3) % 5, 100 + i as u32)];
        let fixed = Buckets::build_fixed(5, 40, pairs);
        let flat = Buckets::build(5, || (0..40).flat_map(pairs));
        assert_eq!(fixed.offsets, flat.offsets);
        assert_eq!(fixed.items, flat.items);
    }
}
