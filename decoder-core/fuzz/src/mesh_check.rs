//! Topological invariants of a decoded mesh, shared by the property tests
//! (`#[path]`-included) and usable from fuzz targets.

#![allow(dead_code)]

use std::collections::{HashMap, HashSet};

/// Checks that `triangles` over `vertex_count` vertices form a consistently
/// oriented 2-manifold, possibly with boundary: indices in range, no
/// degenerate triangle, every directed edge at most once, every vertex used
/// and its link a single path (boundary vertex) or a single cycle (interior).
/// Returns the Euler characteristic V - E + F.
pub fn check_oriented_manifold(vertex_count: usize, triangles: &[[u32; 3]]) -> Result<i64, String> {
    let mut directed = HashSet::new();
    let mut link: Vec<HashMap<u32, u32>> = vec![HashMap::new(); vertex_count];
    for (i, t) in triangles.iter().enumerate() {
        if t.iter().any(|&v| v as usize >= vertex_count) {
            return Err(format!("triangle {i} {t:?}: index out of range"));
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(format!("triangle {i} {t:?}: degenerate"));
        }
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            if !directed.insert((a, b)) {
                return Err(format!("directed edge {a}->{b} twice"));
            }
            // Link of a: b -> c.
            if link[a as usize].insert(b, c).is_some() {
                return Err(format!("vertex {a}: link edge from {b} twice"));
            }
        }
    }
    for (v, l) in link.iter().enumerate() {
        if l.is_empty() {
            return Err(format!("vertex {v} unreferenced"));
        }
        let targets: HashSet<u32> = l.values().copied().collect();
        if targets.len() != l.len() {
            return Err(format!("vertex {v}: link not a path or cycle"));
        }
        let starts: Vec<u32> = l.keys().copied().filter(|k| !targets.contains(k)).collect();
        let (start, is_path) = match starts.as_slice() {
            [] => (*l.keys().next().unwrap(), false),
            [s] => (*s, true),
            _ => {
                return Err(format!(
                    "vertex {v}: more than one fan ({} open)",
                    starts.len()
                ));
            }
        };
        let mut steps = 0;
        let mut x = start;
        while let Some(&y) = l.get(&x) {
            steps += 1;
            x = y;
            if !is_path && x == start {
                break;
            }
            if steps > l.len() {
                return Err(format!("vertex {v}: link walk does not end"));
            }
        }
        if steps != l.len() {
            return Err(format!(
                "vertex {v}: link has {} edges, one fan holds {steps}",
                l.len()
            ));
        }
        if !is_path && l.len() < 3 {
            return Err(format!("vertex {v}: interior with valence {}", l.len()));
        }
    }
    let mut undirected = HashSet::new();
    for &(a, b) in &directed {
        undirected.insert((a.min(b), a.max(b)));
    }
    Ok(vertex_count as i64 - undirected.len() as i64 + triangles.len() as i64)
}
