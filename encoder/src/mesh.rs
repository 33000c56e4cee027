//! The encoder's input mesh: positions in f64 (so geographic coordinates
//! survive until quantization) and counter-clockwise triangles.

use rayon::prelude::*;

/// Triangle `t` rotated so that its smallest vertex comes first: the same
/// oriented triangle, so two triangle lists describe the same oriented mesh
/// when their canonical forms, sorted, are equal (how every round trip
/// compares decode(encode(M)) with M).
pub fn canonical_triangle(t: [u32; 3]) -> [u32; 3] {
    let r = if t[0] <= t[1] && t[0] <= t[2] {
        0
    } else if t[1] <= t[2] {
        1
    } else {
        2
    };
    [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
}

/// `triangles`, with vertex `v` renamed `rename[v]`, in canonical form
/// ([`canonical_triangle`]) and sorted: equal for two lists exactly when
/// they hold the same oriented triangles (the encoder's exactness check and
/// the round trips compare decode(encode(M)) with M this way, through the
/// stream's permutation; the encoder orders its triangles so).
///
/// A counting sort on the first vertex, then each vertex's few triangles
/// sorted: linear in the mesh (one sort of all 2M triangles of the 1M
/// terrain took most of the exactness check's 0.3 s).
pub fn sorted_canonical(triangles: &[[u32; 3]], rename: Option<&[u32]>) -> Vec<[u32; 3]> {
    let canonical: Vec<[u32; 3]> = triangles
        .par_iter()
        .map(|&t| canonical_triangle(rename.map_or(t, |r| t.map(|v| r[v as usize]))))
        .collect();
    let buckets = canonical
        .par_iter()
        .map(|t| t[0] as usize + 1)
        .max()
        .unwrap_or(0);
    // Counted over runs of triangles in parallel, then filled and sorted
    // over parts of the vertex range in parallel: each part owns the
    // stretch of the output its first vertices fill, and reads every
    // triangle (a serial 40 ms of the 1M terrain's set-up and as much of
    // its exactness check before). Each run counts into an array of 4
    // bytes a vertex: at most 8 runs.
    let parts = rayon::current_num_threads().clamp(1, 8);
    let counts = canonical
        .par_chunks(canonical.len().div_ceil(parts).max(1))
        .map(|run| {
            let mut count = vec![0u32; buckets];
            for t in run {
                count[t[0] as usize] += 1;
            }
            count
        })
        .reduce_with(|mut a, b| {
            a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
            a
        })
        .unwrap_or_default();
    let mut start = vec![0u32; buckets + 1];
    for k in 0..buckets {
        start[k + 1] = start[k] + counts[k];
    }
    drop(counts);
    let mut sorted = vec![[0u32; 3]; canonical.len()];
    let mut shares = Vec::with_capacity(parts);
    let mut rest: &mut [[u32; 3]] = &mut sorted;
    for i in 0..parts {
        let (v0, v1) = (buckets * i / parts, buckets * (i + 1) / parts);
        let (share, tail) = rest.split_at_mut((start[v1] - start[v0]) as usize);
        shares.push((v0..v1, share));
        rest = tail;
    }
    shares.into_par_iter().for_each(|(range, share)| {
        let base = start[range.start];
        let mut fill: Vec<u32> = start[range.clone()].iter().map(|&s| s - base).collect();
        for t in &canonical {
            if let Some(slot) = (t[0] as usize)
                .checked_sub(range.start)
                .and_then(|k| fill.get_mut(k))
            {
                share[*slot as usize] = *t;
                *slot += 1;
            }
        }
        for v in range {
            share[(start[v] - base) as usize..(start[v + 1] - base) as usize].sort_unstable();
        }
    });
    sorted
}

/// An indexed triangle mesh as read from a file, before checking.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions in the file's own units.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Axis-aligned bounding box `(min, max)`; `None` for an empty mesh.
    pub fn bounding_box(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.positions.first()?;
        let mut lo = first;
        let mut hi = first;
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        Some((lo, hi))
    }

    /// Length of the bounding-box diagonal (0 for an empty mesh).
    pub fn diagonal(&self) -> f64 {
        self.bounding_box()
            .map(|(lo, hi)| {
                let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            })
            .unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sort every triangle would get: what the buckets must equal.
    fn by_full_sort(triangles: &[[u32; 3]], rename: Option<&[u32]>) -> Vec<[u32; 3]> {
        let mut out: Vec<[u32; 3]> = triangles
            .iter()
            .map(|&t| canonical_triangle(rename.map_or(t, |r| t.map(|v| r[v as usize]))))
            .collect();
        out.sort_unstable();
        out
    }

    #[test]
    fn sorted_canonical_is_the_full_sort_of_the_canonical_triangles() {
        // Pseudo-random triangles over 50 vertices, repeats and both
        // orientations included, and a renaming.
        let mut x = 12345u64;
        let mut next = |n: u64| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 33) % n) as u32
        };
        let triangles: Vec<[u32; 3]> = (0..400).map(|_| [next(50), next(50), next(50)]).collect();
        let rename: Vec<u32> = (0..50).map(|v| (v * 17 + 3) % 50).collect();
        assert_eq!(
            sorted_canonical(&triangles, None),
            by_full_sort(&triangles, None)
        );
        assert_eq!(
            sorted_canonical(&triangles, Some(&rename)),
            by_full_sort(&triangles, Some(&rename))
        );
        assert!(sorted_canonical(&[], None).is_empty());
        // The parts of the parallel fill do not change the result.
        for threads in [1, 3, 7] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(
                pool.install(|| sorted_canonical(&triangles, Some(&rename))),
                by_full_sort(&triangles, Some(&rename))
            );
            assert!(pool.install(|| sorted_canonical(&[], None)).is_empty());
        }
    }

    #[test]
    fn sorted_canonical_tells_orientation_and_rotation_apart() {
        let a = [[0, 1, 2], [2, 1, 3]];
        // The same oriented triangles, listed and rotated otherwise.
        assert_eq!(
            sorted_canonical(&a, None),
            sorted_canonical(&[[1, 3, 2], [1, 2, 0]], None)
        );
        // One of them flipped.
        assert_ne!(
            sorted_canonical(&a, None),
            sorted_canonical(&[[0, 2, 1], [2, 1, 3]], None)
        );
    }
}
