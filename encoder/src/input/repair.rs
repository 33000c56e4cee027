//! Opt-in mesh repair (`--repair`): the smallest set of edits that turns a
//! messy but usable mesh into one [`super::check_mesh`] accepts.
//!
//! Repair only removes triangles, flips triangles, duplicates non-manifold
//! vertices and drops unused vertices; it never moves a vertex or invents a
//! triangle, so a clean mesh comes back unchanged. Non-finite coordinates are
//! not repaired (there is no right value to put there).

use std::fmt;

use rayon::prelude::*;

use crate::Mesh;

use super::check::{edge_groups, edge_table, record_reversed, record_triangle, sorted_vertex_sets};
use super::csr::Buckets;
use super::grid::remove_unreferenced;

/// What [`repair_mesh`] did, action by action.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RepairReport {
    /// Triangles dropped because they referenced a vertex that does not exist.
    pub out_of_range_dropped: usize,
    /// Triangles dropped because they repeated a vertex.
    pub degenerate_dropped: usize,
    /// Triangles dropped because an earlier triangle had the same vertices.
    pub duplicates_dropped: usize,
    /// Edges that were shared by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Triangles dropped from those edges (all beyond the first two).
    pub nonmanifold_edge_triangles_dropped: usize,
    /// Triangles whose winding was reversed to agree with their neighbours.
    pub triangles_flipped: usize,
    /// Connected components that cannot be oriented (Moebius-like).
    pub non_orientable_components: usize,
    /// Triangles dropped to cut those components open.
    pub non_orientable_triangles_dropped: usize,
    /// Vertices whose triangles formed several fans.
    pub nonmanifold_vertices_split: usize,
    /// Vertex copies added so that each fan has its own vertex.
    pub vertex_copies_added: usize,
    /// Vertices removed because no triangle used them.
    pub unreferenced_vertices_removed: usize,
    /// Vertices with NaN/infinite coordinates (left alone: not repairable).
    pub non_finite_vertices: usize,
}

impl RepairReport {
    /// Whether the mesh came back unchanged.
    pub fn is_clean(&self) -> bool {
        *self
            == RepairReport {
                non_finite_vertices: self.non_finite_vertices,
                ..RepairReport::default()
            }
    }
}

impl fmt::Display for RepairReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let items = [
            (
                self.out_of_range_dropped,
                "triangles with out-of-range indices dropped",
            ),
            (self.degenerate_dropped, "degenerate triangles dropped"),
            (self.duplicates_dropped, "duplicate triangles dropped"),
            (self.nonmanifold_edges, "non-manifold edges"),
            (
                self.nonmanifold_edge_triangles_dropped,
                "triangles dropped from non-manifold edges",
            ),
            (self.triangles_flipped, "triangles flipped"),
            (self.non_orientable_components, "non-orientable components"),
            (
                self.non_orientable_triangles_dropped,
                "triangles dropped to orient them",
            ),
            (
                self.nonmanifold_vertices_split,
                "non-manifold vertices split",
            ),
            (self.vertex_copies_added, "vertex copies added"),
            (
                self.unreferenced_vertices_removed,
                "unreferenced vertices removed",
            ),
            (
                self.non_finite_vertices,
                "vertices with non-finite coordinates (not repairable)",
            ),
        ];
        let parts: Vec<String> = items
            .iter()
            .filter(|(n, _)| *n > 0)
            .map(|(n, what)| format!("{n} {what}"))
            .collect();
        if parts.is_empty() {
            f.write_str("nothing to repair")
        } else {
            f.write_str(&parts.join(", "))
        }
    }
}

/// Repairs what can be repaired; see the module docs for what that is.
pub fn repair_mesh(mesh: &Mesh) -> (Mesh, RepairReport) {
    let mut report = RepairReport::default();
    let nv = mesh.positions.len();

    let mut tris = Vec::with_capacity(mesh.triangles.len());
    for &t @ [a, b, c] in &mesh.triangles {
        if t.iter().any(|&v| v as usize >= nv) {
            report.out_of_range_dropped += 1;
        } else if a == b || b == c || a == c {
            report.degenerate_dropped += 1;
        } else {
            tris.push(t);
        }
    }

    report.duplicates_dropped = drop_duplicates(&mut tris, nv);
    let (edges, dropped, table) = drop_nonmanifold_edge_extras(&mut tris, nv);
    (
        report.nonmanifold_edges,
        report.nonmanifold_edge_triangles_dropped,
    ) = (edges, dropped);
    let orient = orient(&mut tris, nv, table);
    report.triangles_flipped = orient.flipped;
    report.non_orientable_components = orient.non_orientable_components;
    report.non_orientable_triangles_dropped = orient.dropped;

    let mut out = Mesh {
        positions: mesh.positions.clone(),
        triangles: tris,
    };
    (
        report.nonmanifold_vertices_split,
        report.vertex_copies_added,
    ) = split_nonmanifold_vertices(&mut out);
    report.unreferenced_vertices_removed = remove_unreferenced(&mut out);
    // Counted on what is left: an unused vertex with a NaN coordinate is
    // removed above, and was reported "not repairable" beside a success.
    report.non_finite_vertices = out
        .positions
        .iter()
        .filter(|p| !p.iter().all(|c| c.is_finite()))
        .count();
    (out, report)
}

/// Keeps the first triangle of every vertex set; returns how many were dropped.
fn drop_duplicates(tris: &mut Vec<[u32; 3]>, nv: usize) -> usize {
    let table = sorted_vertex_sets(tris, nv);
    let mut drop = vec![false; tris.len()];
    for v in 0..nv {
        for g in table.get(v).chunk_by(|a, b| a.0 == b.0) {
            for &(_, t) in &g[1..] {
                drop[t as usize] = true;
            }
        }
    }
    retain_marked(tris, &drop)
}

fn retain_marked(tris: &mut Vec<[u32; 3]>, drop: &[bool]) -> usize {
    let before = tris.len();
    let mut i = 0;
    tris.retain(|_| {
        i += 1;
        !drop[i - 1]
    });
    before - tris.len()
}

/// Keeps the two lowest-indexed triangles on every edge; returns
/// `(edges, triangles dropped, edge table if still valid)`.
fn drop_nonmanifold_edge_extras(
    tris: &mut Vec<[u32; 3]>,
    nv: usize,
) -> (usize, usize, Option<Buckets<u64>>) {
    let edges = edge_table(tris, nv);
    let mut drop = vec![false; tris.len()];
    let mut count = 0;
    for lo in 0..nv {
        for (_, group) in edge_groups(edges.get(lo)) {
            if group.len() > 2 {
                count += 1;
                for &r in &group[2..] {
                    drop[record_triangle(r)] = true;
                }
            }
        }
    }
    if count == 0 {
        return (0, 0, Some(edges));
    }
    (count, retain_marked(tris, &drop), None)
}

struct Orientation {
    flipped: usize,
    non_orientable_components: usize,
    dropped: usize,
}

/// Breadth-first orientation propagation per edge-connected component.
/// Within a component the smaller set of triangles is flipped, so a mesh
/// with a few reversed triangles gets exactly those fixed. A triangle that
/// would need two orientations at once (non-orientable component) is dropped.
/// Requires at most two triangles per edge.
fn orient(tris: &mut Vec<[u32; 3]>, nv: usize, edges: Option<Buckets<u64>>) -> Orientation {
    let mut result = Orientation {
        flipped: 0,
        non_orientable_components: 0,
        dropped: 0,
    };
    let edges = edges.unwrap_or_else(|| edge_table(tris, nv));
    let inconsistent = (0..nv).into_par_iter().any(|lo| {
        edge_groups(edges.get(lo))
            .any(|(_, g)| g.len() == 2 && record_reversed(g[0]) == record_reversed(g[1]))
    });
    if !inconsistent {
        return result;
    }
    // Neighbour records: other << 1 | same_direction.
    let adjacency: Buckets<u64> = Buckets::build(tris.len(), || {
        (0..nv)
            .flat_map(|lo| edge_groups(edges.get(lo)))
            .flat_map(|(_, g)| {
                let pair = match *g {
                    [r0, r1] => {
                        let (t0, t1) = (record_triangle(r0), record_triangle(r1));
                        let same = (record_reversed(r0) == record_reversed(r1)) as u64;
                        Some([(t0, (t1 as u64) << 1 | same), (t1, (t0 as u64) << 1 | same)])
                    }
                    _ => None,
                };
                pair.into_iter().flatten()
            })
    });
    drop(edges);

    const UNSEEN: u8 = 0;
    const KEEP: u8 = 1;
    const FLIP: u8 = 2;
    let mut state = vec![UNSEEN; tris.len()];
    let mut dropped = vec![false; tris.len()];
    let mut component = Vec::new();
    for seed in 0..tris.len() {
        if state[seed] != UNSEEN {
            continue;
        }
        component.clear();
        state[seed] = KEEP;
        component.push(seed);
        let mut head = 0;
        let mut orientable = true;
        while head < component.len() {
            let t = component[head];
            head += 1;
            for &rec in adjacency.get(t) {
                let (n, same) = ((rec >> 1) as usize, rec & 1 == 1);
                if dropped[n] {
                    continue;
                }
                let want = if same {
                    KEEP + FLIP - state[t]
                } else {
                    state[t]
                };
                if state[n] == UNSEEN {
                    state[n] = want;
                    component.push(n);
                } else if state[n] != want {
                    dropped[t] = true;
                    orientable = false;
                    break;
                }
            }
        }
        if !orientable {
            result.non_orientable_components += 1;
        }
        let live = component.iter().filter(|&&t| !dropped[t]);
        let flips = live.clone().filter(|&&t| state[t] == FLIP).count();
        let invert = 2 * flips > live.count();
        for &t in &component {
            if !dropped[t] && ((state[t] == FLIP) != invert) {
                let [a, b, c] = tris[t];
                tris[t] = [a, c, b];
                result.flipped += 1;
            }
        }
    }
    result.dropped = retain_marked(tris, &dropped);
    result
}

/// Gives every fan around a vertex beyond the first its own copy of the
/// vertex (appended at the end of `positions`); the fan holding the vertex's
/// lowest-indexed triangle keeps the original. Returns
/// `(vertices split, copies added)`. Requires manifold, consistently oriented
/// edges (both hold for grids and after the earlier repair steps).
pub(crate) fn split_nonmanifold_vertices(mesh: &mut Mesh) -> (usize, usize) {
    let nv = mesh.positions.len();
    let tris = &mesh.triangles;
    // Corner records: triangle << 2 | corner, in triangle order per vertex.
    let corners: Buckets<u64> = Buckets::build(nv, || {
        tris.iter().enumerate().flat_map(|(t, tri)| {
            tri.iter()
                .enumerate()
                .map(move |(k, &v)| (v as usize, (t as u64) << 2 | k as u64))
        })
    });
    // Per vertex (in parallel): the fan index of each corner, when there is
    // more than one fan.
    let splits: Vec<(usize, Vec<(u64, usize)>)> = (0..nv)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Vec::new()),
            |scratch, v| fans_of(tris, corners.get(v), scratch).map(|f| (v, f)),
        )
        .flatten()
        .collect();
    drop(corners);

    let mut added = 0;
    for (v, fans) in &splits {
        let first_new = mesh.positions.len();
        let count = fans.iter().map(|&(_, f)| f).max().unwrap_or(0);
        for _ in 0..count {
            mesh.positions.push(mesh.positions[*v]);
        }
        added += count;
        for &(c, fan) in fans {
            if fan > 0 {
                mesh.triangles[(c >> 2) as usize][(c & 3) as usize] = (first_new + fan - 1) as u32;
            }
        }
    }
    (splits.len(), added)
}

/// Fan index (0 = fan holding the lowest triangle) of each corner around one
/// vertex, or `None` if all corners form one fan. Fans are the connected
/// components of the vertex's link, found by union-find on link vertices.
fn fans_of(
    tris: &[[u32; 3]],
    corners: &[u64],
    (local, parent, fan_of_root): &mut (Vec<u32>, Vec<usize>, Vec<usize>),
) -> Option<Vec<(u64, usize)>> {
    if corners.len() < 2 {
        return None;
    }
    let link = |c: u64| {
        let t = tris[(c >> 2) as usize];
        let k = (c & 3) as usize;
        (t[(k + 1) % 3], t[(k + 2) % 3])
    };
    local.clear();
    for &c in corners {
        let (a, b) = link(c);
        local.push(a);
        local.push(b);
    }
    local.sort_unstable();
    local.dedup();
    parent.clear();
    parent.extend(0..local.len());
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let idx = |x: u32, local: &[u32]| local.binary_search(&x).unwrap_or(0);
    let mut components = local.len();
    for &c in corners {
        let (a, b) = link(c);
        let (ra, rb) = (find(parent, idx(a, local)), find(parent, idx(b, local)));
        if ra != rb {
            parent[rb] = ra;
            components -= 1;
        }
    }
    if components == 1 {
        return None;
    }
    fan_of_root.clear();
    fan_of_root.resize(local.len(), usize::MAX);
    let mut fans = 0;
    let mut out = Vec::with_capacity(corners.len());
    for &c in corners {
        let root = find(parent, idx(link(c).0, local));
        if fan_of_root[root] == usize::MAX {
            fan_of_root[root] = fans;
            fans += 1;
        }
        out.push((c, fan_of_root[root]));
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::{Grid, check_mesh, grid_to_mesh};
    use super::*;

    fn grid_mesh(rows: usize, cols: usize) -> Mesh {
        grid_to_mesh(&Grid {
            rows,
            cols,
            elevations: (0..rows * cols).map(|i| (i % 7) as f64).collect(),
            origin: [0.0, 0.0],
            spacing: [1.0, 1.0],
            nodata: None,
            coordinates: None,
        })
    }

    /// Found by an audit (2026-12-08): an unused vertex with a NaN
    /// coordinate was reported "not repairable" though it was removed and
    /// the mesh encoded.
    #[test]
    fn a_removed_non_finite_vertex_is_not_reported_unrepairable() {
        let mut mesh = grid_mesh(3, 3);
        mesh.positions.push([f64::NAN, 0.0, 0.0]);
        let (fixed, report) = repair_mesh(&mesh);
        assert_eq!(report.unreferenced_vertices_removed, 1);
        assert_eq!(report.non_finite_vertices, 0, "{report}");
        check_mesh(&fixed).unwrap();
        let mut mesh = grid_mesh(3, 3);
        mesh.positions[4][2] = f64::INFINITY;
        let (_, report) = repair_mesh(&mesh);
        assert_eq!(report.non_finite_vertices, 1, "{report}");
    }

    #[test]
    fn clean_mesh_is_untouched() {
        let m = grid_mesh(5, 6);
        let (r, report) = repair_mesh(&m);
        assert_eq!(r, m);
        assert!(report.is_clean());
        assert_eq!(report.to_string(), "nothing to repair");
    }

    #[test]
    fn each_repair_is_counted() {
        let m = grid_mesh(4, 4);
        let mut bad = m.clone();
        bad.triangles.push([0, 0, 1]);
        bad.triangles.push([0, 1, 99]);
        let t = bad.triangles[3];
        bad.triangles.push([t[2], t[0], t[1]]);
        bad.triangles[5] = [
            bad.triangles[5][0],
            bad.triangles[5][2],
            bad.triangles[5][1],
        ];
        bad.positions.push([9.0, 9.0, 9.0]);
        let (r, report) = repair_mesh(&bad);
        check_mesh(&r).unwrap();
        assert_eq!(report.degenerate_dropped, 1);
        assert_eq!(report.out_of_range_dropped, 1);
        assert_eq!(report.duplicates_dropped, 1);
        assert_eq!(report.triangles_flipped, 1);
        assert_eq!(report.unreferenced_vertices_removed, 1);
        assert_eq!(r, m, "minority flip restores the original exactly");
        let text = report.to_string();
        assert!(
            text.contains("1 triangles flipped") && !text.contains('\n'),
            "{text}"
        );
    }

    #[test]
    fn nonmanifold_edge_and_bowtie() {
        // Fin on an interior edge plus a bowtie at vertex 5.
        let mut m = grid_mesh(4, 4);
        let nv = m.positions.len() as u32;
        m.positions
            .extend([[0.5, 0.5, 5.0], [7.0, 7.0, 0.0], [8.0, 7.0, 0.0]]);
        m.triangles.push([5, 10, nv]);
        m.triangles.push([5, nv + 1, nv + 2]);
        let (r, report) = repair_mesh(&m);
        check_mesh(&r).unwrap();
        assert_eq!(report.nonmanifold_edges, 1);
        assert_eq!(report.nonmanifold_edge_triangles_dropped, 1);
        assert_eq!(report.nonmanifold_vertices_split, 1);
        assert_eq!(report.vertex_copies_added, 1);
        assert_eq!(report.unreferenced_vertices_removed, 1);
        assert_eq!(r.positions.len(), m.positions.len());
    }

    #[test]
    fn moebius_strip_is_cut() {
        // A Moebius strip from a 2 x n band whose ends are glued with a twist.
        let n = 8u32;
        let top = |i: u32| i;
        let bottom = |i: u32| n + i;
        let mut tris = Vec::new();
        for i in 0..n {
            // At the seam the strip's top meets its bottom (twist).
            let (a, b) = (top(i), bottom(i));
            let (c, d) = if i + 1 == n {
                (bottom(0), top(0))
            } else {
                (top(i + 1), bottom(i + 1))
            };
            tris.push([a, b, d]);
            tris.push([a, d, c]);
        }
        let m = Mesh {
            positions: (0..2 * n).map(|i| [i as f64, 0.0, 0.0]).collect(),
            triangles: tris,
        };
        let (r, report) = repair_mesh(&m);
        assert_eq!(report.non_orientable_components, 1, "{report}");
        assert!(report.non_orientable_triangles_dropped >= 1);
        check_mesh(&r).unwrap();
    }

    #[derive(Clone, Debug)]
    enum Damage {
        Duplicate(usize, u8),
        Degenerate(usize),
        Flip(usize),
        Bowtie(usize),
        Fin(usize),
        Orphan,
    }

    fn damage() -> impl Strategy<Value = Damage> {
        prop_oneof![
            (any::<usize>(), 0u8..3).prop_map(|(i, r)| Damage::Duplicate(i, r)),
            any::<usize>().prop_map(Damage::Degenerate),
            any::<usize>().prop_map(Damage::Flip),
            any::<usize>().prop_map(Damage::Bowtie),
            any::<usize>().prop_map(Damage::Fin),
            Just(Damage::Orphan),
        ]
    }

    fn apply(m: &mut Mesh, d: &Damage) {
        let nt = m.triangles.len();
        let nv = m.positions.len() as u32;
        match *d {
            Damage::Duplicate(i, r) => {
                let t = m.triangles[i % nt];
                let t = match r {
                    0 => t,
                    1 => [t[1], t[2], t[0]],
                    _ => [t[0], t[2], t[1]],
                };
                m.triangles.push(t);
            }
            Damage::Degenerate(i) => {
                let t = m.triangles[i % nt];
                m.triangles.insert(i % nt, [t[0], t[1], t[0]]);
            }
            Damage::Flip(i) => {
                let t = &mut m.triangles[i % nt];
                t.swap(1, 2);
            }
            Damage::Bowtie(i) => {
                let v = (i % nv as usize) as u32;
                m.positions.push([100.0 + i as f64, 0.0, 0.0]);
                m.positions.push([100.0 + i as f64, 1.0, 0.0]);
                m.triangles.push([v, nv, nv + 1]);
            }
            Damage::Fin(i) => {
                let t = m.triangles[i % nt];
                m.positions.push([0.5, 0.5, 10.0 + i as f64]);
                m.triangles.push([t[0], t[1], nv]);
            }
            Damage::Orphan => m.positions.push([-1.0, -1.0, -1.0]),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn repaired_meshes_pass_check(
            rows in 2usize..8,
            cols in 2usize..8,
            damages in prop::collection::vec(damage(), 0..12),
        ) {
            let mut m = grid_mesh(rows, cols);
            for d in &damages {
                apply(&mut m, d);
            }
            let (r, report) = repair_mesh(&m);
            if let Err(e) = check_mesh(&r) {
                return Err(TestCaseError::fail(format!("{e} after {report}")));
            }
            // Repair is idempotent.
            let (again, second) = repair_mesh(&r);
            prop_assert!(second.is_clean(), "{}", second);
            prop_assert_eq!(again, r);
        }
    }
}
