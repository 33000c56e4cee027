//! The encoder's input mesh: positions in f64 (so geographic coordinates
//! survive until quantization) and counter-clockwise triangles.

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
/// they hold the same oriented triangles (the round trips compare
/// decode(encode(M)) with M this way, through the stream's permutation).
pub fn sorted_canonical(triangles: &[[u32; 3]], rename: Option<&[u32]>) -> Vec<[u32; 3]> {
    let mut out: Vec<[u32; 3]> = triangles
        .iter()
        .map(|&t| canonical_triangle(rename.map_or(t, |r| t.map(|v| r[v as usize]))))
        .collect();
    out.sort_unstable();
    out
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
