//! The simplifier's options, its working state and its result.

use rayon::prelude::*;

use super::select::EdgeSlot;
use crate::corner_table::{CornerTable, NONE, next, prev};
use crate::quadric::Quadric;
use crate::quantize::QuantizedMesh;

/// Split valence stored for vertices that were never produced by a
/// collapse (they never split). A real split valence is at least 3, so 0
/// is free, and every split valence the format allows, 3 to 255, has its
/// own value (SPEC §6.2). (The stream marks a leaf by its deficit instead:
/// decoder-core's `limits::LEAF`.)
pub const NO_SPLIT: u8 = 0;
/// Largest valence (ghost included) a collapse may produce: the format's
/// largest split valence (SPEC §6.2, `MAX_SPLIT_VALENCE`).
pub const MAX_VALENCE: usize = splitstream_decoder_core::limits::MAX_SPLIT_VALENCE;

/// Options of the parallel simplifier.
#[derive(Clone, Debug)]
pub struct SimplifyOptions {
    /// Stop once this many vertices remain.
    pub target_vertices: usize,
    /// Never collapse an edge whose quadric error exceeds this.
    pub max_error: Option<f64>,
    /// Constrained placement: the merged vertex sits on P, on C or at their midpoint.
    pub constrained: bool,
    pub boundary_weight: f64,
    /// Never move or remove boundary vertices (for patch borders).
    pub lock_boundary: bool,
    /// Fraction of the candidate errors admitted per step (the threshold S is
    /// raised to this quantile): lower is closer to the sequential order, higher
    /// collapses more per step.
    pub admit_quantile: f64,
    /// Sub-grid cell size in mean edge lengths (Fig. 2 tie-break); 0 disables it.
    pub subgrid_cells: f64,
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        SimplifyOptions {
            target_vertices: 0,
            max_error: None,
            constrained: false,
            boundary_weight: crate::quadric::DEFAULT_BOUNDARY_WEIGHT,
            lock_boundary: false,
            admit_quantile: 0.5,
            subgrid_cells: 2.0,
        }
    }
}

/// One collapse of P (the lower id, which survives as R) and C, recorded so
/// that a vertex split can reverse it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collapse {
    pub p: u32,
    pub c: u32,
    /// Third vertex of triangle (P, C, A); [`NONE`] for the boundary ghost.
    pub wing_a: u32,
    /// Third vertex of triangle (C, P, B); [`NONE`] for the boundary ghost.
    pub wing_b: u32,
    pub position_p: [u32; 3],
    pub position_c: [u32; 3],
    pub position_r: [u32; 3],
    /// Split valences P and C had before the collapse ([`NO_SPLIT`] if original).
    pub split_valence_p: u8,
    pub split_valence_c: u8,
    /// Quadric error of the collapse (metric units).
    pub error: f64,
    /// The error as a distance in metric units: sqrt(error / total weight of
    /// the merged quadric), an RMS distance to the planes it summarises.
    pub distance: f64,
}

/// Result: the collapses, step by step, and the simplified mesh they leave.
pub struct Simplification {
    pub steps: Vec<Vec<Collapse>>,
    pub table: CornerTable,
    pub positions: Vec<[u32; 3]>,
    /// Split valence of each surviving vertex ([`NO_SPLIT`] for originals).
    pub split_valence: Vec<u8>,
    pub alive: Vec<bool>,
    pub alive_count: usize,
    /// Largest error of any collapse, per step.
    pub step_errors: Vec<f64>,
}

pub(super) struct State {
    pub table: CornerTable,
    pub positions: Vec<[u32; 3]>,
    pub quadrics: Vec<Quadric>,
    pub boundary: Vec<bool>,
    /// Valence of each vertex with the boundary ghost counted (triangles,
    /// plus 2 on a boundary: the fan's extra neighbour and the ghost), kept
    /// up to date by the collapses so that a check reads the wings' valences
    /// instead of walking their fans.
    pub valence: Vec<u32>,
    pub alive: Vec<bool>,
    pub split_valence: Vec<u8>,
    /// Cached collapse of the edge facing each corner.
    pub edges: Vec<EdgeSlot>,
    pub bits: u8,
    /// Grid units to metric units per axis: geometry = position * metric.
    pub metric: [f64; 3],
    pub constrained: bool,
    pub lock_boundary: bool,
    /// Whether each vertex's fan holds all its corners and only the edges
    /// used once are unmatched (see [`State::new`]).
    pub manifold: bool,
    /// Input id of each vertex: the CPU loop renumbers the live vertices
    /// and triangles densely as they thin out ([`compact`](super::compact::compact)); records and
    /// results are in input ids.
    pub orig: Vec<u32>,
}

impl State {
    /// The state before any collapse, without quadrics and edge slots
    /// (each backend computes those its own way).
    pub fn new(mesh: &QuantizedMesh, options: &SimplifyOptions) -> State {
        let n = mesh.positions.len();
        let metric = mesh.metric;
        let (table, clean) = CornerTable::build(n, &mesh.triangles);
        // Boundary flags and valences from each vertex's fan, in parallel;
        // that holds where every vertex has one fan holding all its corners
        // and the only unmatched edges are those used once (a checked mesh),
        // which the fans' corner count tells.
        let fans: Vec<(bool, u32)> = (0..n as u32)
            .into_par_iter()
            .map(|v| {
                let (mut open, mut count) = (false, 0);
                table.for_each_corner(v, |c| {
                    count += 1;
                    open |= table.o(prev(c)) == NONE;
                });
                (open, count)
            })
            .collect();
        let manifold =
            clean && fans.iter().map(|&(_, k)| k as usize).sum::<usize>() == table.vertex.len();
        let (boundary, valence) = if manifold {
            fans.into_iter()
                .map(|(open, count)| (open, count + if open { 2 } else { 0 }))
                .unzip()
        } else {
            let mut boundary = vec![false; n];
            for (c, &o) in table.opposite.iter().enumerate() {
                if o == NONE {
                    boundary[table.v(next(c as u32)) as usize] = true;
                    boundary[table.v(prev(c as u32)) as usize] = true;
                }
            }
            let mut valence: Vec<u32> = boundary.iter().map(|&b| if b { 2 } else { 0 }).collect();
            for &v in &table.vertex {
                valence[v as usize] += 1;
            }
            (boundary, valence)
        };
        let alive: Vec<bool> = table.corner_of.par_iter().map(|&c| c != NONE).collect();
        State {
            quadrics: Vec::new(),
            positions: mesh.positions.clone(),
            table,
            boundary,
            valence,
            alive,
            split_valence: vec![NO_SPLIT; n],
            edges: Vec::new(),
            bits: mesh.bits,
            metric,
            constrained: options.constrained,
            lock_boundary: options.lock_boundary,
            orig: (0..n as u32).collect(),
            manifold,
        }
    }

    /// [`vertex_quadrics`](crate::quadric::vertex_quadrics) of the input, summed per vertex over its fan in
    /// parallel, in the same order (its triangles ascending, then its
    /// boundary edges by key), so the same bits; `None` where the fans do not
    /// cover the mesh ([`State::manifold`]).
    pub fn fan_quadrics(&self, boundary_weight: f64) -> Option<Vec<Quadric>> {
        if !self.manifold {
            return None;
        }
        let t = &self.table;
        // Each triangle's quadric is computed by each of its vertices: three
        // times the arithmetic, but no 80-byte-a-triangle array to fill and
        // read back.
        let face = |k: u32| {
            let [a, b, c] = [0, 1, 2].map(|j| self.geometry(t.v(3 * k + j)));
            Quadric::from_triangle(a, b, c)
        };
        let n = self.positions.len() as u32;
        let quadrics = (0..n)
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(triangles, edges): &mut (Vec<u32>, Vec<(u64, [u32; 3])>), v| {
                    triangles.clear();
                    t.for_each_corner(v, |c| triangles.push(c / 3));
                    triangles.sort_unstable();
                    let mut q = Quadric::ZERO;
                    for &k in triangles.iter() {
                        q += face(k);
                    }
                    if boundary_weight == 0.0 || !self.boundary[v as usize] {
                        return q;
                    }
                    // The boundary edge facing corner f runs from next f to
                    // prev f, with f's vertex third.
                    edges.clear();
                    t.for_each_corner(v, |c| {
                        for f in [prev(c), next(c)] {
                            if t.o(f) == NONE {
                                let (a, b) = (t.v(next(f)), t.v(prev(f)));
                                let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
                                edges.push((key, [a, b, t.v(f)]));
                            }
                        }
                    });
                    edges.sort_unstable_by_key(|e| e.0);
                    for &(_, ends) in edges.iter() {
                        let [a, b, c] = ends.map(|x| self.geometry(x));
                        q += crate::quadric::boundary_quadric(a, b, c, boundary_weight);
                    }
                    q
                },
            )
            .collect();
        Some(quadrics)
    }

    /// Metric coordinates of vertex `v`, computed from its grid position
    /// (three products beat a load from a second, twice as large array).
    #[inline]
    pub fn geometry(&self, v: u32) -> [f64; 3] {
        self.to_metric(self.positions[v as usize])
    }

    /// Where the slot of the edge facing corner `c` is kept: at the lower of
    /// its two corners, so a refresh writes it once.
    pub fn slot_index(&self, c: u32) -> usize {
        let o = self.table.o(c);
        if o != NONE && o < c {
            o as usize
        } else {
            c as usize
        }
    }

    /// The slot of the edge facing corner `c`.
    pub fn slot(&self, c: u32) -> &EdgeSlot {
        &self.edges[self.slot_index(c)]
    }

    /// Metric coordinates of a grid point.
    pub fn to_metric(&self, q: [u32; 3]) -> [f64; 3] {
        std::array::from_fn(|k| q[k] as f64 * self.metric[k])
    }
}

/// The live vertices and triangles of a simplification state as a mesh in
/// real coordinates, compacted (surviving vertices in ascending id, live
/// triangles in order).
pub(super) fn live_mesh(
    table: &CornerTable,
    alive: &[bool],
    positions: &[[u32; 3]],
    mesh: &QuantizedMesh,
) -> crate::Mesh {
    let mut index = vec![NONE; alive.len()];
    let mut real = Vec::new();
    for v in (0..alive.len()).filter(|&v| alive[v]) {
        index[v] = real.len() as u32;
        real.push(mesh.dequantize(positions[v]));
    }
    let triangles = table
        .vertex
        .chunks_exact(3)
        .filter(|t| t[0] != NONE)
        .map(|t| std::array::from_fn(|k| index[t[k] as usize]))
        .collect();
    crate::Mesh {
        positions: real,
        triangles,
    }
}

impl Simplification {
    /// The simplified mesh in real coordinates, compacted (surviving
    /// vertices in ascending id, live triangles in order).
    pub fn to_mesh(&self, mesh: &QuantizedMesh) -> crate::Mesh {
        live_mesh(&self.table, &self.alive, &self.positions, mesh)
    }

    /// Largest quadric error of any collapse.
    pub fn max_error(&self) -> f64 {
        self.step_errors.iter().copied().fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::{fractal_terrain, icosphere};
    use crate::quadric::vertex_quadrics;
    use crate::quantize::{Units, quantize};

    /// A terrain with a square hole cut out (inner boundary edges too).
    fn holed_terrain() -> crate::Mesh {
        let mut mesh = fractal_terrain(24, 5);
        let side = 24u32;
        let inside = |v: u32| (8..14).contains(&(v % side)) && (8..14).contains(&(v / side));
        mesh.triangles.retain(|t| !t.iter().all(|&v| inside(v)));
        mesh
    }

    #[test]
    fn fan_quadrics_are_the_vertex_quadrics_bit_for_bit() {
        for mesh in [fractal_terrain(40, 3), icosphere(3), holed_terrain()] {
            let q = quantize(&mesh, 14, Units::Linear);
            let s = State::new(&q, &SimplifyOptions::default());
            assert!(s.manifold);
            let geometry: Vec<[f64; 3]> = (0..q.positions.len() as u32)
                .map(|v| s.geometry(v))
                .collect();
            for weight in [0.0, crate::quadric::DEFAULT_BOUNDARY_WEIGHT] {
                let want = vertex_quadrics(&geometry, &q.triangles, weight);
                let got = s.fan_quadrics(weight).expect("manifold");
                assert_eq!(got, want);
            }
        }
    }
}
