//! Sequential Garland–Heckbert edge-collapse simplification: the paper's
//! "QSlim" reference.
//!
//! This module exists only as the yardstick for the parallel simplifier:
//! benchmarks and tests run both on the same input, with the same
//! [`vertex_quadrics`](crate::quadric::vertex_quadrics) and
//! [`collapse_target`](crate::quadric::collapse_target), and compare vertex
//! counts, errors and time (Cellier et al. 2012 report the parallel version
//! keeps 10–15 % more points for about a tenth of the time). It always takes
//! the globally cheapest legal collapse from one priority queue, which is
//! what makes it sequential. It is not used by the encoder itself.
//!
//! Connectivity is a flat corner table edited in place; the queue holds one
//! lazily deleted entry per scored edge. A collapse is refused if it would
//! break the link condition, pinch two border vertices together, fold a
//! closed component below a tetrahedron, flip or flatten a surviving
//! triangle, or give a vertex more than [`MAX_VALENCE`] neighbours. A refused
//! edge is scored again once a neighbouring collapse may have made it legal.

mod collapse;
mod queue;
mod state;
#[cfg(test)]
pub(crate) mod tests;

use std::time::Instant;

use crate::mesh::Mesh;
use crate::quadric::DEFAULT_BOUNDARY_WEIGHT;
use collapse::Refusal;
use queue::error_key;
use state::Simplifier;

pub use collapse::MAX_VALENCE;

/// What to simplify to.
#[derive(Clone, Debug, PartialEq)]
pub struct BaselineOptions {
    /// Stop once this many vertices remain.
    pub target_vertices: usize,
    /// Stop once the cheapest legal collapse costs more than this quadric
    /// error (squared distance times area, the units of
    /// [`Quadric::error`](crate::quadric::Quadric::error)).
    pub max_error: Option<f64>,
    /// Place merged vertices only at an endpoint or the midpoint.
    pub constrained: bool,
    /// Weight of the boundary penalty planes (see
    /// [`vertex_quadrics`](crate::quadric::vertex_quadrics)).
    pub boundary_weight: f64,
    /// Never move a boundary vertex: border-to-border edges are not
    /// collapsed and an interior vertex merging with a border vertex goes to
    /// the border vertex's position.
    pub lock_boundary: bool,
}

impl Default for BaselineOptions {
    fn default() -> Self {
        BaselineOptions {
            target_vertices: 0,
            max_error: None,
            constrained: false,
            boundary_weight: DEFAULT_BOUNDARY_WEIGHT,
            lock_boundary: false,
        }
    }
}

/// The simplified mesh and how it got there.
#[derive(Clone, Debug, PartialEq)]
pub struct BaselineResult {
    /// Only the surviving vertices (in their original order) and triangles.
    pub mesh: Mesh,
    pub collapses: usize,
    /// The largest quadric error of any performed collapse (0 if none).
    pub max_collapse_error: f64,
    /// Wall time of the whole call, setup and compaction included.
    pub seconds: f64,
}

/// Simplifies `mesh` (a consistently oriented manifold, with or without
/// boundary) by repeatedly collapsing the cheapest legal edge, until
/// `target_vertices` remain, the cheapest legal collapse costs more than
/// `max_error`, or no legal collapse is left. Vertices no triangle uses are
/// dropped from the start.
pub fn simplify_sequential(mesh: &Mesh, options: &BaselineOptions) -> BaselineResult {
    let start = Instant::now();
    let mut s = Simplifier::new(&mesh.positions, &mesh.triangles, options);
    s.fill_queue();
    let mut collapses = 0;
    let mut max_collapse_error = 0.0f64;
    while s.alive_count > options.target_vertices {
        let Some(entry) = s.heap.pop() else { break };
        if !s.table.corner_alive(entry.corner) {
            continue;
        }
        // Lazy deletion: an entry is current only if re-scoring the edge
        // gives the same key; otherwise a fresher entry exists.
        let (u, v) = s.edge(entry.corner);
        let Some((p, error, q)) = s.target(u, v) else {
            continue;
        };
        if error_key(error) != entry.error.to_bits() {
            continue;
        }
        if options.max_error.is_some_and(|m| error > m) {
            break;
        }
        match s.plan(u, v, p) {
            Ok(plan) => {
                s.apply(u, v, p, q, &plan);
                s.requeue_around(u);
                collapses += 1;
                max_collapse_error = max_collapse_error.max(error);
            }
            Err(Refusal::Illegal) => {
                s.refused[u as usize] = true;
                s.refused[v as usize] = true;
            }
            Err(Refusal::NotAnEdge) => {}
        }
    }
    let mesh = compact(&s);
    BaselineResult {
        mesh,
        collapses,
        max_collapse_error,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// The live part of the corner table as a fresh indexed mesh.
fn compact(s: &Simplifier) -> Mesh {
    let mut remap = vec![u32::MAX; s.positions.len()];
    let mut positions = Vec::with_capacity(s.alive_count);
    for (v, (&alive, p)) in s.alive.iter().zip(&s.positions).enumerate() {
        if alive {
            remap[v] = positions.len() as u32;
            positions.push(*p);
        }
    }
    let triangles = s
        .table
        .vertex
        .chunks_exact(3)
        .filter(|t| t[0] != crate::corner_table::NONE)
        .map(|t| {
            [
                remap[t[0] as usize],
                remap[t[1] as usize],
                remap[t[2] as usize],
            ]
        })
        .collect();
    Mesh {
        positions,
        triangles,
    }
}
