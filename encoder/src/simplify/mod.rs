//! The paper's parallel simplification (Cellier et al. 2012, §2): every step
//! collapses, at once, all edges that are reciprocal best choices of their
//! two endpoints and local minima of the quadric error among the requests
//! of their 1-ring, so the collapses of a step touch disjoint neighbourhoods
//! and can be reversed as one round of independent vertex splits.
//!
//! The data layout follows the paper's four flat arrays, so the same steps
//! port to compute kernels: per vertex (Vertex) the quantized position, its
//! metric copy, the 10-coefficient quadric, the split valence and an alive
//! flag; per corner (Triangle and its adjacency) the corner table of
//! `corner_table`; per corner again (Edge) the cached error and merged
//! position of the edge facing it (`select::EdgeSlot`). The Index array's
//! job (who was merged into whom, in which order) is the list of
//! [`Collapse`] records per step. As the mesh thins out, the CPU loop
//! renumbers the live vertices and triangles densely (a monotone compaction
//! of every array, so that every comparison of ids keeps its outcome) and
//! maps records and results back to input ids.
//!
//! Each step is three data-parallel passes over the vertex array (rayon here,
//! compute kernels later): best edge per vertex (§2 step a, with the sub-grid
//! tie-break of Fig. 2), reciprocity (step b), local minimum with index
//! priority (step c); then the winners are applied. The paper's bitonic sort
//! of the Index array is not needed on the CPU: the collapses of a step are
//! kept in ascending survivor id (a stable order) and the stream's vertex
//! order is fixed by the decoder's own rule during replay (see `emit`).
//!
//! [`simplify_on`] runs the same steps with the data-parallel passes on a
//! GPU backend (`gpu`: which step runs where is tabled there).
//!
//! Files, in the order of a CPU step (`cpu` is the loop): `state` holds the
//! arrays both backends share and the result; `offers` and `select` choose
//! each vertex's request; `winners` keeps the reciprocal local minima that
//! pass `check`; `apply` applies them in parallel; `refresh` re-evaluates
//! the edges around the merged vertices; `compact` renumbers the live
//! vertices densely once half of them are gone. `tracking` is the loop's
//! per-vertex bookkeeping, `quantile` the threshold S, `meter` the mean
//! edge length, `phases` the timer of `SPLITSTREAM_DEBUG`.

mod apply;
mod backend;
mod check;
mod compact;
mod cpu;
mod gpu;
mod meter;
mod offers;
mod parallel;
mod phases;
mod quantile;
mod refresh;
mod select;
mod state;
mod tracking;
mod winners;

pub use backend::{Backend, GpuError};
pub(crate) use check::triangle_keeps_orientation;
pub use state::{Collapse, MAX_VALENCE, NO_SPLIT, Simplification, SimplifyOptions};

use crate::input::MeshStats;
use crate::quantize::{GridError, QuantizedMesh};

/// A quantized mesh that passed [`QuantizedMesh::check`], the only way to
/// hand one to the simplifier: its steps assume a consistently oriented
/// manifold on the grid (the corner table indexes by the triangles'
/// vertices, and a fin edge or a flipped triangle breaks the fan walks of
/// its checks), so an unchecked mesh would panic or simplify into nonsense.
#[derive(Clone, Copy, Debug)]
pub struct Checked<'m> {
    mesh: &'m QuantizedMesh,
    stats: MeshStats,
}

impl<'m> Checked<'m> {
    /// Checks `mesh` (its bits, its grid, then `check_mesh` in grid
    /// coordinates).
    pub fn new(mesh: &'m QuantizedMesh) -> Result<Checked<'m>, GridError> {
        let stats = mesh.check()?;
        Ok(Checked { mesh, stats })
    }

    /// A mesh whose check the caller has just made, with its result.
    pub(crate) fn already(mesh: &'m QuantizedMesh, stats: MeshStats) -> Checked<'m> {
        Checked { mesh, stats }
    }

    pub fn mesh(&self) -> &'m QuantizedMesh {
        self.mesh
    }

    /// What the check found (vertices, edges, boundary loops, genus, …).
    pub fn stats(&self) -> &MeshStats {
        &self.stats
    }
}

/// Simplifies a checked mesh with the parallel algorithm on the CPU.
pub fn simplify(
    mesh: &Checked<'_>,
    options: &SimplifyOptions,
    progress: impl FnMut(usize),
) -> Simplification {
    cpu::simplify(mesh.mesh, options, progress)
}

/// [`simplify`] on `backend`. The CPU backend never fails; a GPU backend
/// fails when it is not compiled in, has no adapter, or its kernels fail.
pub fn simplify_on(
    backend: Backend,
    mesh: &Checked<'_>,
    options: &SimplifyOptions,
    progress: impl FnMut(usize),
) -> Result<Simplification, GpuError> {
    match backend.api() {
        None => Ok(cpu::simplify(mesh.mesh, options, progress)),
        Some(api) => gpu::simplify_gpu(api, mesh.mesh, options, progress),
    }
}
