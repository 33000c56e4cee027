//! Host-side corner-table adjacency for a base mesh: `opposite` and
//! `vertex_corner` as decoder-core's `MeshState` keeps them (SPEC §6.1).
//! decoder-core exposes only the normative arrays, so the GPU host rebuilds
//! the adjacency it walks rings with; any consistent choice of
//! `vertex_corner` gives the same canonical rings.

use std::collections::HashMap;

use super::layout::NONE;

/// Next corner of the same triangle.
pub fn next(c: u32) -> u32 {
    if c % 3 == 2 { c - 2 } else { c + 1 }
}

/// Previous corner of the same triangle.
pub fn prev(c: u32) -> u32 {
    if c.is_multiple_of(3) { c + 2 } else { c - 1 }
}

/// Why a mesh has no consistent corner-table adjacency.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdjacencyError {
    /// A triangle names a vertex at or above the vertex count.
    VertexOutOfRange { triangle: u32 },
    /// A directed edge is used twice (non-manifold or misoriented).
    DuplicateEdge { from: u32, to: u32 },
    /// A vertex is in no triangle.
    Unreferenced { vertex: u32 },
}

impl core::fmt::Display for AdjacencyError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            AdjacencyError::VertexOutOfRange { triangle } => {
                write!(f, "triangle {triangle} names a vertex out of range")
            }
            AdjacencyError::DuplicateEdge { from, to } => {
                write!(f, "directed edge {from}->{to} is used twice")
            }
            AdjacencyError::Unreferenced { vertex } => {
                write!(f, "vertex {vertex} is in no triangle")
            }
        }
    }
}

impl std::error::Error for AdjacencyError {}

/// `opposite` (one per corner, [`NONE`] on a boundary) and `vertex_corner`
/// (one corner per vertex) of `triangles` over `vertex_count` vertices.
pub fn build_adjacency(
    triangles: &[[u32; 3]],
    vertex_count: u32,
) -> Result<(Vec<u32>, Vec<u32>), AdjacencyError> {
    let corners = 3 * triangles.len();
    let mut opposite = vec![NONE; corners];
    let mut vertex_corner = vec![NONE; vertex_count as usize];
    // Directed edge (from, to) -> the corner facing it in its triangle.
    let mut facing: HashMap<(u32, u32), u32> = HashMap::with_capacity(corners);
    for (t, tri) in triangles.iter().enumerate() {
        for slot in 0..3u32 {
            let c = 3 * t as u32 + slot;
            let v = tri[slot as usize];
            if v >= vertex_count {
                return Err(AdjacencyError::VertexOutOfRange { triangle: t as u32 });
            }
            if vertex_corner[v as usize] == NONE {
                vertex_corner[v as usize] = c;
            }
            let from = tri[(next(c) % 3) as usize];
            let to = tri[(prev(c) % 3) as usize];
            if facing.insert((from, to), c).is_some() {
                return Err(AdjacencyError::DuplicateEdge { from, to });
            }
        }
    }
    for (&(from, to), &c) in &facing {
        if let Some(&o) = facing.get(&(to, from)) {
            opposite[c as usize] = o;
        }
    }
    if let Some(v) = vertex_corner.iter().position(|&c| c == NONE) {
        return Err(AdjacencyError::Unreferenced { vertex: v as u32 });
    }
    Ok((opposite, vertex_corner))
}

/// Checks that `opposite` and `vertex_corner` are a consistent adjacency of
/// `corners` (flat, 3 per triangle): opposite is an involution pairing the
/// two corners facing the same edge in opposite directions, and every
/// vertex's corner is one of its own. Returns a description of the first
/// inconsistency.
pub fn check_adjacency(
    corners: &[u32],
    opposite: &[u32],
    vertex_corner: &[u32],
) -> Result<(), String> {
    if opposite.len() != corners.len() {
        return Err(format!(
            "{} opposite entries for {} corners",
            opposite.len(),
            corners.len()
        ));
    }
    for c in 0..corners.len() as u32 {
        let o = opposite[c as usize];
        if o == NONE {
            continue;
        }
        if o as usize >= corners.len() || opposite[o as usize] != c {
            return Err(format!("opposite of corner {c} is {o}, not an involution"));
        }
        let edge = (corners[next(c) as usize], corners[prev(c) as usize]);
        let back = (corners[prev(o) as usize], corners[next(o) as usize]);
        if edge != back {
            return Err(format!("corners {c} and {o} do not face the same edge"));
        }
    }
    for (v, &c) in vertex_corner.iter().enumerate() {
        if c as usize >= corners.len() || corners[c as usize] != v as u32 {
            return Err(format!("vertex_corner of {v} is {c}, not a corner of it"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_is_closed_and_consistent() {
        let t = [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]];
        let (opposite, vc) = build_adjacency(&t, 4).unwrap();
        assert!(opposite.iter().all(|&o| o != NONE));
        let flat: Vec<u32> = t.iter().flatten().copied().collect();
        check_adjacency(&flat, &opposite, &vc).unwrap();
    }

    #[test]
    fn single_triangle_has_three_boundary_edges() {
        let (opposite, vc) = build_adjacency(&[[0, 1, 2]], 3).unwrap();
        assert_eq!(opposite, vec![NONE; 3]);
        assert_eq!(vc, vec![0, 1, 2]);
    }

    #[test]
    fn faults_are_typed() {
        assert_eq!(
            build_adjacency(&[[0, 1, 5]], 3),
            Err(AdjacencyError::VertexOutOfRange { triangle: 0 })
        );
        assert_eq!(
            build_adjacency(&[[0, 1, 2], [0, 1, 2]], 3).unwrap_err(),
            AdjacencyError::DuplicateEdge { from: 1, to: 2 }
        );
        assert_eq!(
            build_adjacency(&[[0, 1, 2]], 4),
            Err(AdjacencyError::Unreferenced { vertex: 3 })
        );
    }
}
