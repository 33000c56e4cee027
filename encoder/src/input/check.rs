//! Validation of a mesh before encoding: the simplifier and the vertex-split
//! stream assume a clean, consistently oriented 2-manifold (with boundary),
//! so anything else is rejected up front with the first offending element.
//!
//! Rules run in a fixed order and each reports its lowest-indexed offender,
//! so the same file always gives the same message. Everything is O(n log d)
//! (d = vertex degree) via bucketed half-edge tables, fast on 4M triangles.

use std::fmt;

use rayon::prelude::*;

use crate::Mesh;

use super::csr::Buckets;

/// Summary of a mesh that passed [`check_mesh`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshStats {
    pub vertices: usize,
    pub triangles: usize,
    /// Undirected edges.
    pub edges: usize,
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Closed loops formed by the boundary edges (holes and outer rims).
    pub boundary_loops: usize,
    /// Edge-connected components.
    pub components: usize,
    /// V - E + F.
    pub euler_characteristic: i64,
    /// Total genus over all components: (2C - B - chi) / 2.
    pub genus: i64,
}

impl fmt::Display for MeshStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} vertices, {} triangles, {} edges ({} boundary in {} loops), {} component(s), Euler characteristic {}, genus {}",
            self.vertices,
            self.triangles,
            self.edges,
            self.boundary_edges,
            self.boundary_loops,
            self.components,
            self.euler_characteristic,
            self.genus
        )
    }
}

/// The first rule a mesh breaks, with the element that breaks it.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshError {
    /// No vertices or no triangles.
    Empty {
        vertices: usize,
        triangles: usize,
    },
    /// More triangles than the 2^31 the edge tables can index.
    TooLarge {
        triangles: usize,
    },
    NonFiniteCoordinate {
        vertex: usize,
        position: [f64; 3],
    },
    IndexOutOfRange {
        triangle: usize,
        vertices: [u32; 3],
        vertex_count: usize,
    },
    /// A triangle uses the same vertex twice.
    DegenerateTriangle {
        triangle: usize,
        vertices: [u32; 3],
    },
    /// A triangle has the same vertex set as an earlier one (any order).
    DuplicateTriangle {
        triangle: usize,
        vertices: [u32; 3],
        earlier: usize,
        earlier_vertices: [u32; 3],
    },
    /// An undirected edge used by more than two triangles (all listed, ascending).
    NonManifoldEdge {
        edge: [u32; 2],
        positions: [[f64; 3]; 2],
        triangles: Vec<usize>,
    },
    /// Two triangles traverse the same directed edge.
    InconsistentOrientation {
        edge: [u32; 2],
        positions: [[f64; 3]; 2],
        triangles: [usize; 2],
    },
    /// The triangles around a vertex form more than one fan.
    NonManifoldVertex {
        vertex: usize,
        position: [f64; 3],
        fans: usize,
    },
    /// A vertex no triangle uses.
    UnreferencedVertex {
        vertex: usize,
        position: [f64; 3],
    },
}

struct P([f64; 3]);

impl fmt::Display for P {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {}, {})", self.0[0], self.0[1], self.0[2])
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshError::Empty {
                vertices,
                triangles,
            } => {
                write!(
                    f,
                    "mesh is empty ({vertices} vertices, {triangles} triangles)"
                )
            }
            MeshError::TooLarge { triangles } => {
                write!(
                    f,
                    "{triangles} triangles exceed the checker's limit of 2^31"
                )
            }
            MeshError::NonFiniteCoordinate { vertex, position } => {
                write!(
                    f,
                    "vertex {vertex} has a non-finite coordinate {}",
                    P(*position)
                )
            }
            MeshError::IndexOutOfRange {
                triangle,
                vertices,
                vertex_count,
            } => {
                let bad = vertices
                    .iter()
                    .find(|&&v| v as usize >= *vertex_count)
                    .copied()
                    .unwrap_or(vertices[0]);
                write!(
                    f,
                    "triangle {triangle} {vertices:?} refers to vertex {bad}, but there are only {vertex_count} vertices"
                )
            }
            MeshError::DegenerateTriangle { triangle, vertices } => {
                write!(
                    f,
                    "triangle {triangle} {vertices:?} is degenerate (repeats a vertex)"
                )
            }
            MeshError::DuplicateTriangle {
                triangle,
                vertices,
                earlier,
                earlier_vertices,
            } => write!(
                f,
                "triangle {triangle} {vertices:?} duplicates triangle {earlier} {earlier_vertices:?} (same vertices)"
            ),
            MeshError::NonManifoldEdge {
                edge,
                positions,
                triangles,
            } => write!(
                f,
                "edge {}-{} {}-{} is non-manifold: shared by {} triangles {:?} (at most 2 allowed)",
                edge[0],
                edge[1],
                P(positions[0]),
                P(positions[1]),
                triangles.len(),
                triangles
            ),
            MeshError::InconsistentOrientation {
                edge,
                positions,
                triangles,
            } => write!(
                f,
                "triangles {} and {} both traverse edge {}->{} {}-{} in the same direction (inconsistent orientation)",
                triangles[0],
                triangles[1],
                edge[0],
                edge[1],
                P(positions[0]),
                P(positions[1])
            ),
            MeshError::NonManifoldVertex {
                vertex,
                position,
                fans,
            } => write!(
                f,
                "vertex {vertex} {} is non-manifold: its triangles form {fans} separate fans",
                P(*position)
            ),
            MeshError::UnreferencedVertex { vertex, position } => {
                write!(
                    f,
                    "vertex {vertex} {} is not used by any triangle",
                    P(*position)
                )
            }
        }
    }
}

impl std::error::Error for MeshError {}

/// Half-edge record in the edge table: `far << 32 | triangle << 1 | reversed`,
/// bucketed by the smaller endpoint, so sorting a bucket groups the
/// triangles of each undirected edge in ascending triangle order.
pub(crate) fn edge_table(triangles: &[[u32; 3]], vertex_count: usize) -> Buckets<u64> {
    let mut table = Buckets::build_fixed::<3>(vertex_count, triangles.len(), |t| {
        let tri = triangles[t];
        std::array::from_fn(|k| {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let (lo, hi, rev) = if a < b { (a, b, 0) } else { (b, a, 1) };
            (lo as usize, (hi as u64) << 32 | (t as u64) << 1 | rev)
        })
    });
    table.sort_each(|s| s.sort_unstable());
    table
}

/// Link edges `src << 32 | dst` of each vertex: triangle (v, a, b) gives v the
/// edge a -> b. For an oriented edge-manifold mesh each vertex's link is a
/// union of paths and cycles; one component means one fan.
pub(crate) fn link_table(triangles: &[[u32; 3]], vertex_count: usize) -> Buckets<u64> {
    let mut table = Buckets::build_fixed::<3>(vertex_count, triangles.len(), |t| {
        let tri = triangles[t];
        std::array::from_fn(|k| {
            let (v, a, b) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            (v as usize, (a as u64) << 32 | b as u64)
        })
    });
    table.sort_each(|s| s.sort_unstable());
    table
}

/// Iterates the groups of equal `far` vertex in one sorted edge-table bucket:
/// yields `(far, records)`.
pub(crate) fn edge_groups(bucket: &[u64]) -> impl Iterator<Item = (u32, &[u64])> {
    bucket
        .chunk_by(|a, b| a >> 32 == b >> 32)
        .map(|g| ((g[0] >> 32) as u32, g))
}

#[inline]
pub(crate) fn record_triangle(rec: u64) -> usize {
    ((rec & 0xffff_ffff) >> 1) as usize
}

#[inline]
pub(crate) fn record_reversed(rec: u64) -> bool {
    rec & 1 == 1
}

/// The first index of `items` where `bad` holds: parallel over chunks,
/// each scanned in order. (rayon's `position_first` item by item took about
/// 8 ns a triangle on the 1M terrain, 16 ms a pass; a chunk's plain loop is
/// several times faster.)
fn first_where<T: Sync>(items: &[T], bad: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    const CHUNK: usize = 1 << 13;
    items
        .par_chunks(CHUNK)
        .enumerate()
        .find_map_first(|(i, chunk)| chunk.iter().position(&bad).map(|at| i * CHUNK + at))
}

/// Whether the sorted link edges `link` (not empty) form one fan: one path
/// or one cycle. Once edges are manifold and consistently oriented, each
/// link vertex starts and ends at most one link edge, so the link is a set
/// of disjoint paths and cycles; a vertex has one fan when at most one edge
/// starts a path and a walk from it (or, with none, from any edge) meets
/// every edge. The scans are quadratic in the vertex's triangle count,
/// which is small, and allocate nothing ([`count_fans`] then counts the
/// fans of the rare vertex that fails).
fn one_fan(link: &[u64]) -> bool {
    let src = |e: u64| (e >> 32) as u32;
    let dst = |e: u64| e as u32;
    let mut starts = link
        .iter()
        .filter(|&&e| !link.iter().any(|&f| dst(f) == src(e)));
    let first = starts.next().copied();
    if starts.next().is_some() {
        return false;
    }
    let start = first.unwrap_or(link[0]);
    let (mut at, mut walked) = (start, 1);
    while walked < link.len() {
        match link.iter().find(|&&f| src(f) == dst(at)) {
            Some(&next) if next != start => {
                at = next;
                walked += 1;
            }
            _ => break,
        }
    }
    walked == link.len()
}

/// Counts the fans (connected components of the link) of one vertex whose
/// sorted link edges are `link`; `scratch` avoids per-vertex allocation.
/// Only meaningful once edges are manifold and consistently oriented.
pub(crate) fn count_fans(link: &[u64], scratch: &mut (Vec<u32>, Vec<bool>)) -> usize {
    let (dsts, visited) = scratch;
    dsts.clear();
    dsts.extend(link.iter().map(|&e| e as u32));
    dsts.sort_unstable();
    visited.clear();
    visited.resize(link.len(), false);
    let find = |src: u32| link.binary_search_by_key(&src, |&e| (e >> 32) as u32).ok();
    let mut fans = 0;
    let walk = |start: usize, visited: &mut Vec<bool>| {
        let mut i = start;
        while !visited[i] {
            visited[i] = true;
            match find(link[i] as u32) {
                Some(next) => i = next,
                None => break,
            }
        }
    };
    // Open fans first: they start at a link vertex nothing points to.
    for i in 0..link.len() {
        let src = (link[i] >> 32) as u32;
        if !visited[i] && dsts.binary_search(&src).is_err() {
            fans += 1;
            walk(i, visited);
        }
    }
    // What is left are closed fans (cycles).
    for i in 0..link.len() {
        if !visited[i] {
            fans += 1;
            walk(i, visited);
        }
    }
    fans
}

/// Checks every rule in order and returns statistics for a clean mesh, or the
/// first violation.
pub fn check_mesh(mesh: &Mesh) -> Result<MeshStats, MeshError> {
    let (pos, tris) = (&mesh.positions, &mesh.triangles);
    let nv = pos.len();
    if nv == 0 || tris.is_empty() {
        return Err(MeshError::Empty {
            vertices: nv,
            triangles: tris.len(),
        });
    }
    if tris.len() >= 1 << 31 {
        return Err(MeshError::TooLarge {
            triangles: tris.len(),
        });
    }
    if let Some(v) = first_where(pos, |p| !p.iter().all(|c| c.is_finite())) {
        return Err(MeshError::NonFiniteCoordinate {
            vertex: v,
            position: pos[v],
        });
    }
    if let Some(t) = first_where(tris, |t| t.iter().any(|&v| v as usize >= nv)) {
        return Err(MeshError::IndexOutOfRange {
            triangle: t,
            vertices: tris[t],
            vertex_count: nv,
        });
    }
    if let Some(t) = first_where(tris, |&[a, b, c]| a == b || b == c || a == c) {
        return Err(MeshError::DegenerateTriangle {
            triangle: t,
            vertices: tris[t],
        });
    }
    // The three tables are independent and built at once (the whole check
    // of the 1M terrain 0.16 -> 0.13-0.14 s, BENCHMARKS.md 2026-12-04; the
    // tables, about 150 MB there by their element sizes, are freed long
    // before the encoder's peak). The checks still read them in the order
    // of the rules, so the first fault reported is the same.
    // The components' union-find is serial; it runs beside the tables
    // instead of after every check (its result is only reported once every
    // rule holds).
    let (((vertex_sets, edges), links), components) = rayon::join(
        || {
            rayon::join(
                || rayon::join(|| sorted_vertex_sets(tris, nv), || edge_table(tris, nv)),
                || link_table(tris, nv),
            )
        },
        || count_components(tris, nv),
    );
    if let Some((t, earlier)) = first_duplicate(&vertex_sets, nv) {
        return Err(MeshError::DuplicateTriangle {
            triangle: t,
            vertices: tris[t],
            earlier,
            earlier_vertices: tris[earlier],
        });
    }
    drop(vertex_sets);

    // Edges surveyed in parallel over runs of vertices, the runs' findings
    // joined in vertex order (the first offender is the one a single pass
    // in vertex order finds).
    const RUN: usize = 1 << 14;
    let EdgeSurvey {
        edges: edge_count,
        boundary,
        worst_nonmanifold,
        worst_orientation,
    } = (0..nv.div_ceil(RUN))
        .into_par_iter()
        .map(|i| EdgeSurvey::of(&edges, i * RUN..nv.min((i + 1) * RUN)))
        .reduce(EdgeSurvey::default, EdgeSurvey::then);
    let boundary_edges = boundary.len();
    // Boundary successor of each vertex: a -> b as the triangle runs it.
    let mut boundary_next = vec![u32::MAX; nv];
    for (a, b) in boundary {
        boundary_next[a as usize] = b;
    }
    drop(edges);
    if let Some((_, edge, triangles)) = worst_nonmanifold {
        let positions = edge.map(|v| pos[v as usize]);
        return Err(MeshError::NonManifoldEdge {
            edge,
            positions,
            triangles,
        });
    }
    if let Some((second, edge, first)) = worst_orientation {
        return Err(MeshError::InconsistentOrientation {
            edge,
            positions: edge.map(|v| pos[v as usize]),
            triangles: [first, second],
        });
    }

    let bad_vertex = (0..nv)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new()),
            |scratch, v| {
                let link = links.get(v);
                if link.is_empty() || one_fan(link) {
                    return None;
                }
                let fans = count_fans(link, scratch);
                (fans > 1).then_some((v, fans))
            },
        )
        .find_first(|r| r.is_some())
        .flatten();
    if let Some((v, fans)) = bad_vertex {
        return Err(MeshError::NonManifoldVertex {
            vertex: v,
            position: pos[v],
            fans,
        });
    }
    if let Some(v) = (0..nv)
        .into_par_iter()
        .position_first(|v| links.get(v).is_empty())
    {
        return Err(MeshError::UnreferencedVertex {
            vertex: v,
            position: pos[v],
        });
    }
    drop(links);

    let boundary_loops = count_loops(&boundary_next);
    let euler = nv as i64 - edge_count as i64 + tris.len() as i64;
    Ok(MeshStats {
        vertices: nv,
        triangles: tris.len(),
        edges: edge_count,
        boundary_edges,
        boundary_loops,
        components,
        euler_characteristic: euler,
        genus: (2 * components as i64 - boundary_loops as i64 - euler) / 2,
    })
}

/// What the edge table says of a run of vertices' edges (each undirected
/// edge counted at its smaller endpoint): see [`check_mesh`].
#[derive(Default)]
struct EdgeSurvey {
    edges: usize,
    /// Boundary edges `a -> b`, as their triangle runs them.
    boundary: Vec<(u32, u32)>,
    /// The edge of more than two triangles whose third triangle comes
    /// first: (third, edge, its triangles).
    worst_nonmanifold: Option<(usize, [u32; 2], Vec<usize>)>,
    /// The edge two triangles run the same way whose second triangle comes
    /// first: (second, edge as the first runs it, first).
    worst_orientation: Option<(usize, [u32; 2], usize)>,
}

impl EdgeSurvey {
    fn of(edges: &Buckets<u64>, run: std::ops::Range<usize>) -> EdgeSurvey {
        let mut out = EdgeSurvey::default();
        for lo in run {
            for (hi, group) in edge_groups(edges.get(lo)) {
                out.edges += 1;
                match group.len() {
                    1 => out.boundary.push(if record_reversed(group[0]) {
                        (hi, lo as u32)
                    } else {
                        (lo as u32, hi)
                    }),
                    2 => {
                        if record_reversed(group[0]) == record_reversed(group[1]) {
                            let second = record_triangle(group[1]);
                            if out.worst_orientation.as_ref().is_none_or(|w| second < w.0) {
                                let first = record_triangle(group[0]);
                                let [a, b] = [lo as u32, hi];
                                let edge = if record_reversed(group[0]) {
                                    [b, a]
                                } else {
                                    [a, b]
                                };
                                out.worst_orientation = Some((second, edge, first));
                            }
                        }
                    }
                    _ => {
                        let third = record_triangle(group[2]);
                        if out.worst_nonmanifold.as_ref().is_none_or(|w| third < w.0) {
                            let list = group.iter().map(|&r| record_triangle(r)).collect();
                            out.worst_nonmanifold = Some((third, [lo as u32, hi], list));
                        }
                    }
                }
            }
        }
        out
    }

    /// This run's findings followed by those of the `later` run: on equal
    /// triangles the earlier vertex's edge stays, as in one pass.
    fn then(mut self, later: EdgeSurvey) -> EdgeSurvey {
        self.edges += later.edges;
        self.boundary.extend(later.boundary);
        if let Some(w) = later.worst_nonmanifold
            && self.worst_nonmanifold.as_ref().is_none_or(|s| w.0 < s.0)
        {
            self.worst_nonmanifold = Some(w);
        }
        if let Some(w) = later.worst_orientation
            && self.worst_orientation.as_ref().is_none_or(|s| w.0 < s.0)
        {
            self.worst_orientation = Some(w);
        }
        self
    }
}

/// Returns `(t, earlier)` for the lowest-indexed triangle `t` whose vertex set
/// equals that of an earlier triangle ([`sorted_vertex_sets`]'s `table`).
fn first_duplicate(table: &Buckets<(u64, u32)>, nv: usize) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize)> = None;
    for v in 0..nv {
        for g in table.get(v).chunk_by(|a, b| a.0 == b.0) {
            if g.len() > 1 && best.is_none_or(|b| (g[1].1 as usize) < b.0) {
                best = Some((g[1].1 as usize, g[0].1 as usize));
            }
        }
    }
    best
}

/// Triangles bucketed by their smallest vertex, keyed by the other two
/// (`mid << 32 | max`) and their index; sorting groups equal vertex sets.
pub(crate) fn sorted_vertex_sets(tris: &[[u32; 3]], nv: usize) -> Buckets<(u64, u32)> {
    let mut table = Buckets::build_fixed::<1>(nv, tris.len(), |t| {
        let mut s = tris[t];
        s.sort_unstable();
        [(s[0] as usize, ((s[1] as u64) << 32 | s[2] as u64, t as u32))]
    });
    table.sort_each(|s| s.sort_unstable());
    table
}

/// Boundary edges chain into loops; with manifold vertices each vertex
/// starts at most one boundary edge, so `next` is a partial permutation.
fn count_loops(next: &[u32]) -> usize {
    let mut loops = 0;
    let mut seen = vec![false; next.len()];
    for start in 0..next.len() {
        if next[start] == u32::MAX || seen[start] {
            continue;
        }
        loops += 1;
        let mut v = start;
        while !seen[v] && next[v] != u32::MAX {
            seen[v] = true;
            v = next[v] as usize;
        }
    }
    loops
}

/// Connected components over shared vertices (union-find with path halving).
pub(crate) fn count_components(tris: &[[u32; 3]], nv: usize) -> usize {
    let mut parent: Vec<u32> = (0..nv as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let up = parent[parent[x as usize] as usize];
            parent[x as usize] = up;
            x = up;
        }
        x
    }
    for t in tris {
        let a = find(&mut parent, t[0]);
        for &v in &t[1..] {
            let b = find(&mut parent, v);
            if a != b {
                parent[b as usize] = a;
            }
        }
    }
    let mut used = vec![false; nv];
    for t in tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    (0..nv as u32)
        .filter(|&v| used[v as usize] && find(&mut parent, v) == v)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(positions: usize, triangles: &[[u32; 3]]) -> Mesh {
        Mesh {
            positions: (0..positions)
                .map(|i| [i as f64, (i * i) as f64, 0.5])
                .collect(),
            triangles: triangles.to_vec(),
        }
    }

    const TETRA: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];

    /// A torus from an n x m grid with wrap-around (genus 1, closed).
    fn torus(n: u32, m: u32) -> Mesh {
        let mut tris = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let v = |a: u32, b: u32| (a % n) * m + (b % m);
                tris.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                tris.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
        mesh((n * m) as usize, &tris)
    }

    /// The edge survey runs over runs of 16,384 vertices in parallel; the
    /// offender it names must be the one a single pass finds: the edge run
    /// the same way by two triangles whose second comes first, ties to the
    /// smaller endpoints. Checked against that pass, written plainly, on a
    /// torus of three runs with triangles flipped all over it.
    #[test]
    fn the_first_orientation_fault_does_not_depend_on_the_runs() {
        let mut state = 7u64;
        let mut next = |n: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % n
        };
        for _ in 0..8 {
            let mut m = torus(230, 200);
            let count = m.triangles.len() as u64;
            for _ in 0..1 + next(6) {
                let t = next(count) as usize;
                m.triangles[t].swap(1, 2);
            }
            // The plain pass: triangles in order, each directed edge
            // remembered with its triangle.
            let mut seen = std::collections::HashMap::new();
            let mut expected = None;
            'triangles: for (t, tri) in m.triangles.iter().enumerate() {
                let mut faults: Vec<([u32; 2], usize)> = (0..3)
                    .filter_map(|k| {
                        let edge = [tri[k], tri[(k + 1) % 3]];
                        seen.get(&edge).map(|&first| (edge, first))
                    })
                    .collect();
                faults.sort_by_key(|(e, _)| (e[0].min(e[1]), e[0].max(e[1])));
                if let Some(&(edge, first)) = faults.first() {
                    expected = Some((edge, [first, t]));
                    break 'triangles;
                }
                for k in 0..3 {
                    seen.insert([tri[k], tri[(k + 1) % 3]], t);
                }
            }
            let (edge, triangles) = expected.expect("a flipped triangle faults");
            match check_mesh(&m) {
                Err(MeshError::InconsistentOrientation {
                    edge: e,
                    triangles: t,
                    ..
                }) => assert_eq!((e, t), (edge, triangles)),
                other => panic!("expected an orientation fault, got {other:?}"),
            }
        }
    }

    #[test]
    fn stats_of_clean_meshes() {
        let s = check_mesh(&mesh(4, &TETRA)).unwrap();
        assert_eq!(
            s,
            MeshStats {
                vertices: 4,
                triangles: 4,
                edges: 6,
                boundary_edges: 0,
                boundary_loops: 0,
                components: 1,
                euler_characteristic: 2,
                genus: 0
            }
        );
        let s = check_mesh(&torus(5, 4)).unwrap();
        assert_eq!(
            (s.euler_characteristic, s.genus, s.boundary_loops),
            (0, 1, 0)
        );
        // Square with a quad hole: an annulus, one component, two loops.
        let mut tris = Vec::new();
        let v = |r: u32, c: u32| r * 4 + c;
        for r in 0..3 {
            for c in 0..3 {
                if (r, c) != (1, 1) {
                    tris.push([v(r, c), v(r, c + 1), v(r + 1, c + 1)]);
                    tris.push([v(r, c), v(r + 1, c + 1), v(r + 1, c)]);
                }
            }
        }
        let s = check_mesh(&mesh(16, &tris)).unwrap();
        assert_eq!(
            (s.boundary_loops, s.boundary_edges, s.components, s.genus),
            (2, 16, 1, 0)
        );
        // Two disjoint triangles.
        let s = check_mesh(&mesh(6, &[[0, 1, 2], [3, 4, 5]])).unwrap();
        assert_eq!((s.components, s.boundary_loops), (2, 2));
        assert!(s.to_string().contains("2 component(s)"));
    }

    #[test]
    fn each_rule_names_the_first_offender() {
        let err = |m: &Mesh| check_mesh(m).unwrap_err();
        assert_eq!(
            err(&mesh(0, &[])),
            MeshError::Empty {
                vertices: 0,
                triangles: 0
            }
        );
        assert_eq!(
            err(&mesh(3, &[])).to_string(),
            "mesh is empty (3 vertices, 0 triangles)"
        );

        let mut m = mesh(4, &TETRA);
        m.positions[2][1] = f64::NAN;
        m.positions[3][0] = f64::INFINITY;
        assert_eq!(
            err(&m).to_string(),
            "vertex 2 has a non-finite coordinate (2, NaN, 0.5)"
        );

        let e = err(&mesh(4, &[[0, 2, 1], [0, 1, 9], [0, 1, 7]]));
        assert_eq!(
            e.to_string(),
            "triangle 1 [0, 1, 9] refers to vertex 9, but there are only 4 vertices"
        );

        let e = err(&mesh(4, &[[0, 2, 1], [0, 1, 1], [2, 2, 2]]));
        assert_eq!(
            e.to_string(),
            "triangle 1 [0, 1, 1] is degenerate (repeats a vertex)"
        );

        let e = err(&mesh(4, &[[0, 2, 1], [0, 1, 3], [3, 0, 1], [1, 0, 2]]));
        assert_eq!(
            e.to_string(),
            "triangle 2 [3, 0, 1] duplicates triangle 1 [0, 1, 3] (same vertices)"
        );

        let e = err(&mesh(5, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]));
        assert_eq!(
            e.to_string(),
            "edge 0-1 (0, 0, 0.5)-(1, 1, 0.5) is non-manifold: shared by 3 triangles [0, 1, 2] (at most 2 allowed)"
        );

        let e = err(&mesh(4, &[[0, 1, 2], [0, 1, 3]]));
        assert_eq!(
            e,
            MeshError::InconsistentOrientation {
                edge: [0, 1],
                positions: [[0.0, 0.0, 0.5], [1.0, 1.0, 0.5]],
                triangles: [0, 1]
            }
        );
        assert!(e.to_string().contains("edge 0->1"));

        // Bowtie: two triangles share only vertex 0.
        let e = err(&mesh(5, &[[0, 1, 2], [0, 3, 4]]));
        assert_eq!(
            e,
            MeshError::NonManifoldVertex {
                vertex: 0,
                position: [0.0, 0.0, 0.5],
                fans: 2
            }
        );
        // Two closed fans at one vertex: two tetrahedra glued at a vertex.
        let mut tris = TETRA.to_vec();
        tris.extend(
            TETRA
                .iter()
                .map(|t| t.map(|v| if v == 0 { 0 } else { v + 3 })),
        );
        assert!(matches!(
            err(&mesh(7, &tris)),
            MeshError::NonManifoldVertex {
                vertex: 0,
                fans: 2,
                ..
            }
        ));

        let e = err(&mesh(5, &[[0, 1, 2]]));
        assert_eq!(
            e.to_string(),
            "vertex 3 (3, 9, 0.5) is not used by any triangle"
        );
    }

    #[test]
    fn fans_of_open_and_closed_links() {
        let mut scratch = (Vec::new(), Vec::new());
        let e = |a: u64, b: u64| a << 32 | b;
        let mut open = vec![e(1, 2), e(2, 3), e(3, 4)];
        open.sort_unstable();
        assert_eq!(count_fans(&open, &mut scratch), 1);
        let mut closed = vec![e(1, 2), e(2, 3), e(3, 1)];
        closed.sort_unstable();
        assert_eq!(count_fans(&closed, &mut scratch), 1);
        let mut mixed = vec![e(1, 2), e(2, 3), e(3, 1), e(5, 6)];
        mixed.sort_unstable();
        assert_eq!(count_fans(&mixed, &mut scratch), 2);
        let mut two_cycles = vec![e(1, 2), e(2, 1), e(5, 6), e(6, 7), e(7, 5)];
        two_cycles.sort_unstable();
        assert_eq!(count_fans(&two_cycles, &mut scratch), 2);
        let mut two_paths = vec![e(1, 2), e(2, 3), e(5, 6)];
        two_paths.sort_unstable();
        assert_eq!(count_fans(&two_paths, &mut scratch), 2);
        // The allocation-free test agrees on every case.
        for (link, fans) in [
            (&open, 1),
            (&closed, 1),
            (&mixed, 2),
            (&two_cycles, 2),
            (&two_paths, 2),
        ] {
            assert_eq!(one_fan(link), fans == 1, "{link:x?}");
        }
        assert!(one_fan(&[e(4, 9)]));
    }

    /// `one_fan` against `count_fans` on links made of random disjoint
    /// paths and cycles (what an edge-manifold, oriented mesh's links are).
    #[test]
    fn one_fan_agrees_with_the_fan_count() {
        let mut scratch = (Vec::new(), Vec::new());
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        for _ in 0..2000 {
            // Shuffled link vertices cut into pieces, each a path or a cycle.
            let mut vertices: Vec<u64> = (0..2 + next(10)).collect();
            for i in (1..vertices.len()).rev() {
                vertices.swap(i, next(i as u64 + 1) as usize);
            }
            let mut link = Vec::new();
            let mut rest = &vertices[..];
            while !rest.is_empty() {
                let len = (1 + next(rest.len() as u64)) as usize;
                let (piece, tail) = rest.split_at(len);
                rest = tail;
                link.extend(piece.windows(2).map(|w| w[0] << 32 | w[1]));
                if piece.len() >= 2 && next(2) == 0 {
                    link.push(piece[piece.len() - 1] << 32 | piece[0]);
                }
            }
            if link.is_empty() {
                continue;
            }
            link.sort_unstable();
            let fans = count_fans(&link, &mut scratch);
            assert_eq!(one_fan(&link), fans == 1, "{link:x?}: {fans} fans");
        }
    }
}
