//! A bounding-volume hierarchy over triangles for nearest-surface queries.
//!
//! Median split on the longest axis of the centroids, leaves of at most
//! [`LEAF_SIZE`] triangles, nodes in depth-first order (left child right
//! after its parent) and triangle corners copied into leaf order so a query
//! touches contiguous memory. Queries descend nearer child first and prune
//! boxes farther than the best distance so far.

use super::closest::{closest_point, dist2};

const LEAF_SIZE: usize = 4;

/// A `hint` for [`Bvh::nearest_dist2`] that names no leaf.
pub const NO_HINT: u32 = u32::MAX;

#[derive(Clone, Copy)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Leaf: first triangle. Inner: index of the right child.
    index: u32,
    /// Leaf: triangle count (> 0). Inner: 0.
    count: u32,
}

pub struct Bvh {
    nodes: Vec<Node>,
    triangles: Vec<[[f64; 3]; 3]>,
}

impl Bvh {
    /// Builds the hierarchy over the triangles of `(positions, triangles)`
    /// whose indices are in range.
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Bvh {
        let n = positions.len();
        let corners: Vec<[[f64; 3]; 3]> = triangles
            .iter()
            .filter(|t| t.iter().all(|&v| (v as usize) < n))
            .map(|t| t.map(|v| positions[v as usize]))
            .collect();
        let mut items: Vec<(u32, [f64; 3])> = corners
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let centroid = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
                (i as u32, centroid)
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * items.len() / LEAF_SIZE + 1);
        if !items.is_empty() {
            build(&mut nodes, &corners, &mut items, 0);
        }
        let triangles = items.iter().map(|&(i, _)| corners[i as usize]).collect();
        Bvh { nodes, triangles }
    }

    /// Squared distance from `p` to the nearest triangle (infinite when there
    /// are none).
    ///
    /// `hint` is a leaf to try first (any value; [`NO_HINT`] for none) and
    /// comes back as the leaf holding the nearest triangle: for samples
    /// visited in surface order the previous answer is nearly always close,
    /// so the search starts with a tight bound and prunes most of the tree.
    /// The result does not depend on the hint.
    pub fn nearest_dist2(&self, p: [f64; 3], hint: &mut u32) -> f64 {
        let mut best = f64::INFINITY;
        if self.nodes.is_empty() {
            return best;
        }
        if let Some(node) = self.nodes.get(*hint as usize).filter(|n| n.count > 0) {
            best = self.leaf_dist2(node, p);
        }
        // Median splits keep the depth under 33 for any u32 triangle count,
        // and the stack never holds more than depth + 1 entries.
        let mut stack = [(0u32, 0.0f64); 64];
        stack[0] = (0, box_dist2(&self.nodes[0], p));
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (i, d) = stack[len];
            if d >= best {
                continue;
            }
            let node = &self.nodes[i as usize];
            if node.count > 0 {
                let d = self.leaf_dist2(node, p);
                if d < best {
                    best = d;
                    *hint = i;
                }
                continue;
            }
            let (l, r) = (i + 1, node.index);
            let dl = box_dist2(&self.nodes[l as usize], p);
            let dr = box_dist2(&self.nodes[r as usize], p);
            // Push the farther child first so the nearer one is searched first.
            let (near, far) = if dl <= dr {
                ((l, dl), (r, dr))
            } else {
                ((r, dr), (l, dl))
            };
            for child in [far, near] {
                if child.1 < best {
                    stack[len] = child;
                    len += 1;
                }
            }
        }
        best
    }

    fn leaf_dist2(&self, leaf: &Node, p: [f64; 3]) -> f64 {
        let first = leaf.index as usize;
        self.triangles[first..first + leaf.count as usize]
            .iter()
            .map(|tri| dist2(p, closest_point(p, *tri)))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Appends the subtree over `items` (triangle index, centroid); `first` is
/// the position of `items[0]` in the final leaf order.
fn build(
    nodes: &mut Vec<Node>,
    corners: &[[[f64; 3]; 3]],
    items: &mut [(u32, [f64; 3])],
    first: usize,
) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let (mut clo, mut chi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (i, c) in items.iter() {
        for p in &corners[*i as usize] {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        for k in 0..3 {
            clo[k] = clo[k].min(c[k]);
            chi[k] = chi[k].max(c[k]);
        }
    }
    let me = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        index: first as u32,
        count: items.len() as u32,
    });
    if items.len() <= LEAF_SIZE {
        return;
    }
    let extent = [0, 1, 2].map(|k| chi[k] - clo[k]);
    let axis = (0..3).fold(0, |best, k| if extent[k] > extent[best] { k } else { best });
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.1[axis].total_cmp(&b.1[axis]));
    let (left, right) = items.split_at_mut(mid);
    build(nodes, corners, left, first);
    let right_index = nodes.len() as u32;
    build(nodes, corners, right, first + mid);
    nodes[me].index = right_index;
    nodes[me].count = 0;
}

fn box_dist2(node: &Node, p: [f64; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let d = (node.lo[k] - p[k]).max(p[k] - node.hi[k]).max(0.0);
            d * d
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::rng::unit;

    #[test]
    fn agrees_with_brute_force() {
        // 200 random triangles in a unit cube, 300 random queries around it.
        let positions: Vec<[f64; 3]> = (0..600)
            .map(|i| [0, 1, 2].map(|k| unit(1, 3 * i + k)))
            .collect();
        let triangles: Vec<[u32; 3]> = (0..200).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let bvh = Bvh::new(&positions, &triangles);
        let mut hint = NO_HINT;
        for q in 0..300 {
            let p = [0, 1, 2].map(|k| 3.0 * unit(2, 3 * q + k) - 1.0);
            let brute = triangles
                .iter()
                .map(|t| dist2(p, closest_point(p, t.map(|v| positions[v as usize]))))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(bvh.nearest_dist2(p, &mut hint), brute);
            // Any hint, even a wrong or stale one, gives the same answer.
            assert_eq!(bvh.nearest_dist2(p, &mut (q as u32)), brute);
        }
    }

    #[test]
    fn empty_is_infinitely_far() {
        assert_eq!(
            Bvh::new(&[], &[]).nearest_dist2([0.0; 3], &mut 0),
            f64::INFINITY
        );
    }
}
