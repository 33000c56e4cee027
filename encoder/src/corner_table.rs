//! Flat corner table (Rossignac's "Corner Table"): the connectivity both
//! simplifiers (parallel and sequential baseline) edit in place. Three flat
//! `u32` arrays and no per-vertex lists, so a 2M-triangle terrain costs about 50 MB and every
//! traversal is a few indexed loads.

use rayon::prelude::*;
use std::sync::atomic::Ordering::Relaxed;
use std::sync::atomic::{AtomicU32, AtomicU64};

/// Marks a missing opposite corner (a boundary edge), a dead triangle's
/// corners, or a vertex without a corner.
pub const NONE: u32 = u32::MAX;

/// Corner `c` of triangle `c / 3` sits at vertex `vertex[c]`; `opposite[c]`
/// is the corner across the edge facing `c` (the edge from `next(c)` to
/// `prev(c)`), or [`NONE`] on a boundary. Triangles are removed by setting
/// their corners' vertices to [`NONE`].
pub struct CornerTable {
    pub vertex: Vec<u32>,
    pub opposite: Vec<u32>,
    /// One live corner per vertex, [`NONE`] for removed or unused vertices.
    pub corner_of: Vec<u32>,
}

/// The next and previous corner of the same triangle: decoder-core's, whose
/// test for a multiple of 3 is one multiplication (corner walks run on them;
/// `c % 3` cost three more instructions a call, about 2 % of an encode).
pub use splitstream_decoder_core::{next, prev};

/// The items `0..count` that have an edge (`ends(i)`, a pair of vertex ids
/// below `vertex_count`, in either direction) as `(key, item)` with key
/// `min << 32 | max`, sorted: what sorting those pairs gives, by a counting
/// sort on the lower id and sorts of the short runs that share it. Every
/// 2-manifold vertex owns a few edges, so this is linear where a full sort
/// was the largest cost of setting up a simplification.
pub fn by_undirected_edge(
    vertex_count: usize,
    count: usize,
    ends: impl Fn(u32) -> Option<(u32, u32)>,
) -> Vec<(u64, u32)> {
    let keys: Vec<Option<u64>> = (0..count as u32)
        .map(|i| ends(i).map(|(u, v)| (u64::from(u.min(v)) << 32) | u64::from(u.max(v))))
        .collect();
    let mut start = vec![0u32; vertex_count + 1];
    for key in keys.iter().flatten() {
        start[(key >> 32) as usize + 1] += 1;
    }
    for k in 1..start.len() {
        start[k] += start[k - 1];
    }
    let mut fill = start.clone();
    let mut order = vec![(0u64, 0u32); start[vertex_count] as usize];
    for (i, key) in keys.iter().enumerate() {
        if let &Some(key) = key {
            let slot = &mut fill[(key >> 32) as usize];
            order[*slot as usize] = (key, i as u32);
            *slot += 1;
        }
    }
    for w in start.windows(2) {
        let run = &mut order[w[0] as usize..w[1] as usize];
        if run.len() > 1 {
            run.sort_unstable();
        }
    }
    order
}

/// The corners around one vertex, in fan order, and whether the fan is open.
#[derive(Default)]
pub struct Fan {
    pub corners: Vec<u32>,
    pub boundary: bool,
}

impl CornerTable {
    /// Builds the table of a consistently oriented manifold. Edges that do
    /// not pair up as exactly two opposite half-edges are left unmatched
    /// (treated as boundary) rather than trusted.
    pub fn new(vertex_count: usize, triangles: &[[u32; 3]]) -> CornerTable {
        Self::build(vertex_count, triangles).0
    }

    /// [`Self::new`], and whether every edge paired up or is used by one
    /// triangle only: then exactly the edges used once are left unmatched.
    pub fn build(vertex_count: usize, triangles: &[[u32; 3]]) -> (CornerTable, bool) {
        let vertex: Vec<u32> = bytemuck::cast_slice::<[u32; 3], u32>(triangles).to_vec();
        // Each counting run takes an array of 4 bytes a vertex: at most 8
        // of them, so that a many-core machine adds at most 32 bytes a
        // vertex, briefly, to an encoder that needs about 620. (Built
        // serially, the table was 85 ms of the 1M terrain's set-up.)
        let runs = rayon::current_num_threads().clamp(1, 8);
        let (start, order) = corners_by_lower_end(&vertex, vertex_count, runs);
        let (opposite, clean) = pair_opposites(&vertex, &start, &order);
        drop((start, order));
        let corner_of = last_corners(&vertex, vertex_count, runs);
        let table = CornerTable {
            vertex,
            opposite,
            corner_of,
        };
        (table, clean)
    }

    pub fn v(&self, c: u32) -> u32 {
        self.vertex[c as usize]
    }

    pub fn o(&self, c: u32) -> u32 {
        self.opposite[c as usize]
    }

    /// Whether corner `c`'s triangle is still part of the mesh.
    pub fn corner_alive(&self, c: u32) -> bool {
        self.vertex.get(c as usize).is_some_and(|&v| v != NONE)
    }

    /// Collects the corners around vertex `v` into `fan`: first turning one
    /// way from `corner_of[v]`, and if that hits a boundary, the other way
    /// from the start too, so open fans come out complete.
    pub fn fan(&self, v: u32, fan: &mut Fan) {
        fan.corners.clear();
        fan.boundary = false;
        let start = self.corner_of[v as usize];
        if start == NONE {
            return;
        }
        let mut c = start;
        loop {
            fan.corners.push(c);
            // Across the edge (v, vertex[next c]), which faces prev(c).
            let o = self.o(prev(c));
            if o == NONE {
                fan.boundary = true;
                break;
            }
            c = prev(o);
            if c == start {
                return;
            }
            if fan.corners.len() > self.vertex.len() {
                // Only reachable on corrupted connectivity; stop rather than spin.
                return;
            }
        }
        let mut c = start;
        loop {
            // Across the edge (vertex[prev c], v), which faces next(c).
            let o = self.o(next(c));
            if o == NONE || fan.corners.len() > self.vertex.len() {
                return;
            }
            c = next(o);
            fan.corners.push(c);
        }
    }

    /// Calls `f` on the corners around vertex `v` in the order [`Self::fan`]
    /// lists them, without collecting them (the hot loops only look).
    ///
    /// One loop with one call of `f`, so that `f` is inlined into it (with
    /// two calls, one per direction, the picks' closure stayed a call per
    /// corner).
    #[inline]
    pub fn for_each_corner(&self, v: u32, mut f: impl FnMut(u32)) {
        let start = self.corner_of[v as usize];
        if start == NONE {
            return;
        }
        let limit = self.vertex.len();
        let mut seen = 0;
        let mut c = start;
        // Turning one way from the start until a boundary, then the other
        // way from the start.
        let mut forward = true;
        loop {
            f(c);
            seen += 1;
            if forward {
                let o = self.o(prev(c));
                if o != NONE {
                    c = prev(o);
                    if c == start || seen > limit {
                        return;
                    }
                    continue;
                }
                forward = false;
                c = start;
            }
            let o = self.o(next(c));
            if o == NONE || seen > limit {
                return;
            }
            c = next(o);
        }
    }

    /// Unlinks triangle `t`: its two remaining outer neighbours become each
    /// other's opposites (the edge between them is being folded shut) and the
    /// corners are marked dead. `keep` is the corner of `t` whose facing edge
    /// is the collapsing one; the other two face the folded edges.
    pub fn remove_triangle(&mut self, keep: u32) {
        remove_triangle_in(self, keep);
    }

    /// Collapses the edge from `keep` to `gone`: `gone`'s triangles move to
    /// `keep`, and the triangles holding the edge are removed. `left` is the
    /// corner at `keep` of triangle (keep, gone, a) and `right` the corner at
    /// `keep` of triangle (keep, b, gone); either may be [`NONE`] on a boundary.
    /// The caller has checked that the collapse keeps a manifold.
    pub fn collapse(&mut self, keep: u32, gone: u32, left: u32, right: u32, fans: &mut [Fan; 2]) {
        let [fa, fb] = fans;
        self.fan(keep, fa);
        self.fan(gone, fb);
        self.collapse_fans(keep, gone, left, right, &fa.corners, &fb.corners);
    }

    /// [`Self::collapse`] given the fans of `keep` and `gone` as they are
    /// before it (the parallel simplifier has them from its check).
    pub fn collapse_fans(
        &mut self,
        keep: u32,
        gone: u32,
        left: u32,
        right: u32,
        fan_keep: &[u32],
        fan_gone: &[u32],
    ) {
        let anchors = collapse_in(self, keep, gone, left, right, fan_keep, fan_gone);
        for (x, anchor) in anchors {
            if x != NONE {
                self.corner_of[x as usize] = anchor;
            }
        }
    }

    /// A live corner at vertex `x` in the triangle of corner `c` (which must
    /// contain `x`).
    pub fn corner_at(&self, c: u32, x: u32) -> u32 {
        let base = c - c % 3;
        (base..base + 3).find(|&k| self.v(k) == x).unwrap_or(NONE)
    }
}

/// The corner arrays a collapse reads and writes, so that the one
/// implementation ([`collapse_in`]) serves the table itself and the
/// parallel simplifier's disjoint views of it.
pub trait CornerAccess {
    fn v(&self, c: u32) -> u32;
    fn o(&self, c: u32) -> u32;
    fn set_v(&mut self, c: u32, v: u32);
    fn set_o(&mut self, c: u32, o: u32);
    fn set_corner_of(&mut self, v: u32, c: u32);
}

impl CornerAccess for CornerTable {
    fn v(&self, c: u32) -> u32 {
        self.vertex[c as usize]
    }
    fn o(&self, c: u32) -> u32 {
        self.opposite[c as usize]
    }
    fn set_v(&mut self, c: u32, v: u32) {
        self.vertex[c as usize] = v;
    }
    fn set_o(&mut self, c: u32, o: u32) {
        self.opposite[c as usize] = o;
    }
    fn set_corner_of(&mut self, v: u32, c: u32) {
        self.corner_of[v as usize] = c;
    }
}

/// [`CornerTable::remove_triangle`] on any [`CornerAccess`].
pub fn remove_triangle_in<A: CornerAccess + ?Sized>(t: &mut A, keep: u32) {
    let (c1, c2) = (next(keep), prev(keep));
    let (o1, o2) = (t.o(c1), t.o(c2));
    if o1 != NONE {
        t.set_o(o1, o2);
    }
    if o2 != NONE {
        t.set_o(o2, o1);
    }
    let across = t.o(keep);
    if across != NONE {
        t.set_o(across, NONE);
    }
    for c in [keep, c1, c2] {
        t.set_v(c, NONE);
        t.set_o(c, NONE);
    }
}

/// [`CornerTable::collapse_fans`] on any [`CornerAccess`], except that the
/// wing vertices' new corners are returned as (wing, corner) pairs instead
/// of written ([`NONE`] wings where a side is open): a wing can be shared by
/// two collapses of one parallel step. Reads and writes only the triangles
/// around `keep` and `gone` (and their corners).
pub fn collapse_in<A: CornerAccess + ?Sized>(
    t: &mut A,
    keep: u32,
    gone: u32,
    left: u32,
    right: u32,
    fan_keep: &[u32],
    fan_gone: &[u32],
) -> [(u32, u32); 2] {
    let doomed = |c: u32| c != NONE && (c / 3 == left / 3 || c / 3 == right / 3);
    // Re-anchor the wing vertices on triangles that survive: the
    // neighbours across their two folded edges.
    let mut anchors = [(NONE, NONE); 2];
    for (slot, (c, is_left)) in anchors.iter_mut().zip([(left, true), (right, false)]) {
        if c == NONE {
            continue;
        }
        let x = t.v(if is_left { prev(c) } else { next(c) });
        let anchor = [c, next(c), prev(c)]
            .into_iter()
            .map(|k| t.o(k))
            .find(|&o| o != NONE && !doomed(o))
            .map(|o| {
                let base = o - o % 3;
                (base..base + 3).find(|&k| t.v(k) == x).unwrap_or(NONE)
            })
            .unwrap_or(NONE);
        *slot = (x, anchor);
    }
    for &c in fan_gone {
        if !doomed(c) {
            t.set_v(c, keep);
        }
    }
    if left != NONE {
        remove_triangle_in(t, prev(left));
    }
    if right != NONE {
        remove_triangle_in(t, next(right));
    }
    let start = fan_keep
        .iter()
        .chain(fan_gone)
        .copied()
        .find(|&c| !doomed(c))
        .unwrap_or(NONE);
    t.set_corner_of(keep, start);
    t.set_corner_of(gone, NONE);
    anchors
}

/// The corners grouped by the undirected edge they face (the corner's own
/// direction, from `next` to `prev`, tells the two sides apart): a counting
/// sort on the edge's lower vertex, each entry `upper << 32 | corner`, in
/// the order `by_undirected_edge` gives before its runs are sorted (8 bytes
/// an entry instead of 16). Counted and filled in parallel over `runs` runs
/// of corners, each with its own counts, placed where one pass over all
/// corners puts them. Returns the buckets' starts (one more than vertices)
/// and the entries.
fn corners_by_lower_end(
    vertex: &[u32],
    vertex_count: usize,
    runs: usize,
) -> (Vec<u32>, Vec<AtomicU64>) {
    let corners = vertex.len();
    let lower = |c: usize| {
        let (a, b) = (
            vertex[next(c as u32) as usize],
            vertex[prev(c as u32) as usize],
        );
        (a.min(b), a.max(b))
    };
    let run_of = |r: usize| corners * r / runs..corners * (r + 1) / runs;
    let mut counts: Vec<Vec<u32>> = (0..runs)
        .into_par_iter()
        .map(|r| {
            let mut count = vec![0u32; vertex_count];
            for c in run_of(r) {
                count[lower(c).0 as usize] += 1;
            }
            count
        })
        .collect();
    // Each run's first slot in each bucket: the buckets in vertex order,
    // and within one the runs in corner order.
    let mut start = vec![0u32; vertex_count + 1];
    let mut at = 0u32;
    for v in 0..vertex_count {
        start[v] = at;
        for count in counts.iter_mut() {
            let k = count[v];
            count[v] = at;
            at += k;
        }
    }
    start[vertex_count] = at;
    let order: Vec<AtomicU64> = (0..corners)
        .into_par_iter()
        .map(|_| AtomicU64::new(0))
        .collect();
    counts.par_iter_mut().enumerate().for_each(|(r, slot)| {
        for c in run_of(r) {
            let (lo, hi) = lower(c);
            let at = &mut slot[lo as usize];
            order[*at as usize].store((u64::from(hi) << 32) | c as u64, Relaxed);
            *at += 1;
        }
    });
    (start, order)
}

/// The opposite of each corner from the buckets of [`corners_by_lower_end`]
/// (each sorted, in parallel over runs of vertices): the two corners of an
/// edge faced from its two sides pair up, every other edge is left
/// unmatched. Also whether every edge paired up or is used by one triangle
/// only.
fn pair_opposites(vertex: &[u32], start: &[u32], order: &[AtomicU64]) -> (Vec<u32>, bool) {
    const BUCKETS: usize = 1 << 14;
    let vertex_count = start.len() - 1;
    let opposite: Vec<AtomicU32> = (0..vertex.len())
        .into_par_iter()
        .map(|_| AtomicU32::new(NONE))
        .collect();
    let from = |c: u32| vertex[next(c) as usize];
    let clean = (0..vertex_count.div_ceil(BUCKETS))
        .into_par_iter()
        .map(|i| {
            let mut clean = true;
            let mut bucket = Vec::new();
            for v in i * BUCKETS..vertex_count.min((i + 1) * BUCKETS) {
                bucket.clear();
                bucket.extend(
                    order[start[v] as usize..start[v + 1] as usize]
                        .iter()
                        .map(|e| e.load(Relaxed)),
                );
                bucket.sort_unstable();
                for run in bucket.chunk_by(|x, y| x >> 32 == y >> 32) {
                    if let [e0, e1] = *run {
                        let (c0, c1) = (e0 as u32, e1 as u32);
                        if from(c0) != from(c1) {
                            opposite[c0 as usize].store(c1, Relaxed);
                            opposite[c1 as usize].store(c0, Relaxed);
                            continue;
                        }
                    }
                    if run.len() != 1 {
                        clean = false;
                    }
                }
            }
            clean
        })
        .reduce(|| true, |a, b| a && b);
    let opposite = opposite
        .into_par_iter()
        .map(AtomicU32::into_inner)
        .collect();
    (opposite, clean)
}

/// Each vertex's last corner ([`NONE`] for a vertex without one), in
/// parallel over `runs` runs of vertices, each reading every corner.
fn last_corners(vertex: &[u32], vertex_count: usize, runs: usize) -> Vec<u32> {
    let mut corner_of = vec![NONE; vertex_count];
    let share_len = vertex_count.div_ceil(runs).max(1);
    corner_of
        .par_chunks_mut(share_len)
        .enumerate()
        .for_each(|(i, share)| {
            let v0 = i * share_len;
            for (c, &v) in vertex.iter().enumerate() {
                if let Some(slot) = (v as usize).checked_sub(v0).and_then(|k| share.get_mut(k)) {
                    *slot = c as u32;
                }
            }
        });
    corner_of
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_come_in_key_order() {
        let pairs: Vec<(u32, u32)> = (0..500u32)
            .map(|i| ((i * 37) % 23, (i * 11 + 5) % 29))
            .collect();
        let ends = |i: u32| (i % 7 != 3).then(|| pairs[i as usize]);
        let got = by_undirected_edge(29, pairs.len(), ends);
        let mut want: Vec<(u64, u32)> = (0..pairs.len() as u32)
            .filter_map(|i| ends(i).map(|(u, v)| (((u.min(v) as u64) << 32) | u.max(v) as u64, i)))
            .collect();
        want.sort_unstable();
        assert_eq!(got, want);
    }

    /// The table as one pass over every corner in order builds it: a map
    /// from each undirected edge to the corners facing it.
    fn reference_build(n: usize, tris: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>, bool) {
        let vertex: Vec<u32> = tris.iter().flatten().copied().collect();
        let mut facing: std::collections::BTreeMap<(u32, u32), Vec<u32>> = Default::default();
        for c in 0..vertex.len() as u32 {
            let (a, b) = (vertex[next(c) as usize], vertex[prev(c) as usize]);
            facing.entry((a.min(b), a.max(b))).or_default().push(c);
        }
        let (mut opposite, mut clean) = (vec![NONE; vertex.len()], true);
        for run in facing.values() {
            if let [c0, c1] = run[..]
                && vertex[next(c0) as usize] != vertex[next(c1) as usize]
            {
                opposite[c0 as usize] = c1;
                opposite[c1 as usize] = c0;
                continue;
            }
            clean &= run.len() == 1;
        }
        let mut corner_of = vec![NONE; n];
        for (c, &v) in vertex.iter().enumerate() {
            corner_of[v as usize] = c as u32;
        }
        (opposite, corner_of, clean)
    }

    #[test]
    fn the_parallel_build_is_the_one_pass_build() {
        // A grid (every vertex has several corners, edges shared by two
        // triangles), then the same with duplicated, flipped and degenerate
        // triangles and unused vertices: non-manifold edges, edges run the
        // same way twice, corners facing an edge from one vertex to itself.
        let side = 40;
        let tris = crate::input::grid_to_mesh(&crate::input::Grid {
            rows: side,
            cols: side,
            elevations: vec![0.0; side * side],
            origin: [0.0; 2],
            spacing: [1.0; 2],
            nodata: None,
            coordinates: None,
        })
        .triangles;
        let n = side * side + 7;
        let mut soup = tris.clone();
        soup.extend([
            [0, 1, 41],
            [41, 1, 0],
            [5, 5, 6],
            [7, 7, 7],
            [100, 200, 300],
        ]);
        soup.extend(
            (0..300u32).map(|i| [(i * 37) % 1600, (i * 11 + 5) % 1600, (i * 101 + 9) % 1600]),
        );
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        for tris in [&tris, &soup] {
            let (opposite, corner_of, clean) = reference_build(n, tris);
            for (table, got_clean) in [
                CornerTable::build(n, tris),
                pool.install(|| CornerTable::build(n, tris)),
            ] {
                assert_eq!(table.opposite, opposite);
                assert_eq!(table.corner_of, corner_of);
                assert_eq!(got_clean, clean);
            }
        }
        assert!(CornerTable::build(n, &tris).1);
        assert!(!CornerTable::build(n, &soup).1);
    }

    #[test]
    fn fans_of_a_square() {
        // 3---2
        // | / |
        // 0---1
        let t = CornerTable::new(4, &[[0, 1, 2], [0, 2, 3]]);
        let mut fan = Fan::default();
        t.fan(0, &mut fan);
        assert!(fan.boundary);
        assert_eq!(fan.corners.len(), 2);
        t.fan(1, &mut fan);
        assert_eq!(fan.corners, vec![1]);
        assert_eq!(t.o(1), 5, "0-1-2 and 0-2-3 share edge 0-2");
    }

    #[test]
    fn fan_of_an_interior_vertex_is_closed() {
        // Vertex 0 in the middle of a hexagon fan, triangles CCW.
        let tris: Vec<[u32; 3]> = (0..6).map(|i| [0, 1 + i, 1 + (i + 1) % 6]).collect();
        let t = CornerTable::new(7, &tris);
        let mut fan = Fan::default();
        t.fan(0, &mut fan);
        assert!(!fan.boundary);
        assert_eq!(fan.corners.len(), 6);
        t.fan(3, &mut fan);
        assert!(fan.boundary);
        assert_eq!(fan.corners.len(), 2);
    }

    #[test]
    fn corner_walk_lists_the_fan() {
        // A hexagon fan around 0 with one triangle missing: open fans too.
        let tris: Vec<[u32; 3]> = (0..5).map(|i| [0, 1 + i, 1 + (i + 1) % 6]).collect();
        let t = CornerTable::new(7, &tris);
        let mut fan = Fan::default();
        for v in 0..7 {
            t.fan(v, &mut fan);
            let mut walked = Vec::new();
            t.for_each_corner(v, |c| walked.push(c));
            assert_eq!(walked, fan.corners, "vertex {v}");
        }
        // The open fan of 0 walked from each of its corners: both ways
        // from the middle ones.
        let mut t = t;
        t.fan(0, &mut fan);
        for start in fan.corners.clone() {
            t.corner_of[0] = start;
            let mut from = Fan::default();
            t.fan(0, &mut from);
            let mut walked = Vec::new();
            t.for_each_corner(0, |c| walked.push(c));
            assert_eq!(walked, from.corners, "from corner {start}");
            assert_eq!(walked.len(), 5);
        }
    }
}
