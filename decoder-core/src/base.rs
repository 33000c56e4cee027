//! Loading the base mesh and building its adjacency (SPEC §6.3).
//!
//! The base mesh arrives as plain triangles; this checks that it is a
//! consistently oriented 2-manifold (possibly with boundary) and builds its
//! adjacency without allocating: a counting sort of the corners by vertex
//! runs in the swing table's memory, used as `u32` scratch; the opposite
//! corners found there are turned into the swing table (`state.rs`) at the
//! end.

use crate::Error;
use crate::header::Schedule;
use crate::limits::{LEAF, MAX_SPLIT_VALENCE, NONE};
use crate::state::{MeshState, next, prev};

impl MeshState<'_> {
    /// `u32`s of scratch the base build needs in the swing table's
    /// memory: the opposites, the corners sorted by vertex and the start of
    /// each vertex's run (SPEC §9: `6 T0 + V0 + 1`).
    pub fn base_scratch_len(vertices: u32, triangles: u32) -> usize {
        6 * triangles as usize + vertices as usize + 1
    }

    /// Starts the state as a base mesh whose positions, triangles and
    /// deficits the caller has already written through [`MeshState::base_arrays`],
    /// then validates it and builds the adjacency (SPEC §6.3). Under the
    /// schedule `every-vertex` the deficits are not read: each vertex's
    /// byte becomes its valence.
    pub fn finish_base(&mut self, vertices: u32, triangles: u32) -> Result<(), Error> {
        let nv = vertices as usize;
        let nt = triangles as usize;
        let nc = 3 * nt;
        if vertices > self.vertex_capacity()
            || triangles > self.triangle_capacity()
            || self.swing.scratch().len() < Self::base_scratch_len(vertices, triangles)
        {
            return Err(Error::CapacityExceeded);
        }
        for tri in self.corners[..nc].chunks_exact(3) {
            if tri.iter().any(|&v| v >= vertices) {
                return Err(Error::NonManifold("vertex index out of range"));
            }
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(Error::NonManifold("degenerate triangle"));
            }
        }
        let (opposite, scratch) = self.swing.scratch().split_at_mut(nc);
        let (list, start) = scratch.split_at_mut(nc);
        let start = &mut start[..nv + 1];
        let corners = &self.corners[..nc];

        // Counting sort of corners by vertex: afterwards the corners of v are
        // list[start[v] .. start[v + 1]].
        start.fill(0);
        for &v in corners {
            start[v as usize + 1] += 1;
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        for (c, &v) in corners.iter().enumerate() {
            // Fill from the back of each range, then shift back below.
            start[v as usize + 1] -= 1;
            list[start[v as usize + 1] as usize] = c as u32;
        }
        // start[v + 1] now holds the start of v; rotate into place.
        for v in 0..nv {
            start[v] = start[v + 1];
        }
        start[nv] = nc as u32;

        let next_vertex = |c: u32| corners[next(c) as usize];
        for v in 0..nv {
            let s = start[v] as usize;
            let e = start[v + 1] as usize;
            if s == e {
                return Err(Error::NonManifold("unreferenced vertex"));
            }
            let fan = &mut list[s..e];
            // A hand-written sort on 32-bit Arm (`sort_by_key`); core's
            // elsewhere: replacing it on x86-64 moved the hot round's code
            // about (another partition into codegen units) and cost it
            // 0.25 % more instructions on a 300 × 300 terrain.
            #[cfg(target_arch = "arm")]
            sort_by_key(fan, next_vertex);
            #[cfg(not(target_arch = "arm"))]
            fan.sort_unstable_by_key(|&c| next_vertex(c));
            if fan
                .windows(2)
                .any(|w| next_vertex(w[0]) == next_vertex(w[1]))
            {
                return Err(Error::NonManifold(
                    "an edge is used twice in the same direction (non-manifold or inconsistently oriented)",
                ));
            }
            self.vertex_corner.set(v as u32, fan[0]);
        }
        // The triangle facing corner c across edge b -> d holds d -> b.
        for c in 0..nc as u32 {
            let b = corners[next(c) as usize];
            let d = corners[prev(c) as usize];
            let fan = &list[start[d as usize] as usize..start[d as usize + 1] as usize];
            opposite[c as usize] = match fan.binary_search_by_key(&b, |&x| next_vertex(x)) {
                Ok(i) => prev(fan[i]),
                Err(_) => NONE,
            };
        }

        // Every vertex must have one fan: a full disk or a single open fan.
        for v in 0..nv {
            let count = start[v + 1] - start[v];
            let valence = fan_valence(opposite, self.vertex_corner.get(v as u32), count)
                .ok_or(Error::NonManifold("a vertex has more than one fan"))?;
            if self.schedule == Schedule::EveryVertex {
                // 3.6: the byte holds the valence (SPEC §6.2, §6.3).
                self.deficit[v] = valence.min(MAX_SPLIT_VALENCE) as u8;
                continue;
            }
            let deficit = self.deficit[v];
            if deficit != LEAF && valence + deficit as usize > MAX_SPLIT_VALENCE {
                return Err(Error::ValenceOverflow);
            }
        }
        // swing[c] = next(opposite[next(c)]), packed in place.
        let after = |o: u32| if o == NONE { NONE } else { next(o) };
        self.swing
            .pack_triangles(nt, |[o0, o1, o2]| [after(o1), after(o2), after(o0)]);
        self.vertex_count = vertices;
        self.triangle_count = triangles;
        self.candidates.fill(0);
        for v in 0..vertices {
            let d = self.deficit[v as usize];
            self.set_candidate(v, d);
        }
        Ok(())
    }

    /// The arrays a base-mesh reader fills before [`MeshState::finish_base`]:
    /// positions, the flat triangle corner list and deficits.
    pub fn base_arrays(&mut self) -> (&mut [[u32; 3]], &mut [u32], &mut [u8]) {
        (self.positions, self.corners, self.deficit)
    }
}

/// Sorts `v` by `key`, ascending, for the fans of the base mesh (SPEC
/// §6.3) on 32-bit Arm: a heapsort. The keys (the corners' next vertices)
/// are distinct in a valid mesh, so any sort gives the same order as
/// core's, and an invalid mesh is rejected after the sort whatever order
/// equal keys took. Hand-written because core's `sort_unstable_by_key`
/// (quicksort, heapsort and sorting networks) took about 2 KB of a
/// thumbv7em decoder's `.text` for a step run once per stream; a heapsort
/// keeps its `O(n log n)` bound on a fan of any valence.
#[cfg(any(target_arch = "arm", test))]
fn sort_by_key(v: &mut [u32], key: impl Fn(u32) -> u32) {
    let sift_down = |v: &mut [u32], mut root: usize, end: usize| {
        loop {
            let mut child = 2 * root + 1;
            if child >= end {
                return;
            }
            if child + 1 < end && key(v[child]) < key(v[child + 1]) {
                child += 1;
            }
            if key(v[root]) >= key(v[child]) {
                return;
            }
            v.swap(root, child);
            root = child;
        }
    };
    let n = v.len();
    for root in (0..n / 2).rev() {
        sift_down(v, root, n);
    }
    for end in (1..n).rev() {
        v.swap(0, end);
        sift_down(v, 0, end);
    }
}

/// Valence of the vertex at corner `start` if its `count` corners form one
/// fan, else `None`. Interior vertices need at least 3 neighbours.
fn fan_valence(opposite: &[u32], start: u32, count: u32) -> Option<usize> {
    let mut seen = 1u32;
    let mut c = start;
    loop {
        let o = opposite[next(c) as usize];
        if o == NONE {
            break;
        }
        c = next(o);
        if c == start {
            return (seen == count && count >= 3).then_some(count as usize);
        }
        seen += 1;
        if seen > count {
            return None;
        }
    }
    // Open fan: count the clockwise side too.
    let mut c = start;
    loop {
        let o = opposite[prev(c) as usize];
        if o == NONE {
            break;
        }
        c = prev(o);
        seen += 1;
        if seen > count {
            return None;
        }
    }
    (seen == count).then_some(count as usize + 2)
}

#[cfg(test)]
mod tests {
    use super::sort_by_key;

    /// The heapsort of the base fans on Arm agrees with core's sort on
    /// distinct keys (the only ones a valid base mesh has) of every length
    /// up to 40, in orders from a fixed pseudo-random sequence, and sorts
    /// equal keys too.
    #[test]
    fn heap_sort_matches_core_sort() {
        let key = |c: u32| c.wrapping_mul(2_654_435_761) >> 7;
        let mut seed = 1u32;
        for n in 0..40u32 {
            for _ in 0..20 {
                let mut v: [u32; 40] = core::array::from_fn(|i| i as u32);
                let v = &mut v[..n as usize];
                for i in (1..v.len()).rev() {
                    seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                    v.swap(i, (seed >> 8) as usize % (i + 1));
                }
                let mut expected: [u32; 40] = [0; 40];
                expected[..v.len()].copy_from_slice(v);
                let expected = &mut expected[..v.len()];
                expected.sort_unstable_by_key(|&c| key(c));
                sort_by_key(v, key);
                assert_eq!(v, expected);
                let mut equal: [u32; 40] = [0; 40];
                for (e, &x) in equal.iter_mut().zip(v.iter()) {
                    *e = x % 3;
                }
                let equal = &mut equal[..v.len()];
                sort_by_key(equal, |c| c);
                assert!(equal.windows(2).all(|w| w[0] <= w[1]));
            }
        }
    }
}
