//! Deterministic points on a mesh: its used vertices, then points uniform
//! by area. Point `i` is a pure function of `(mesh, seed, i)`, so sampling
//! parallelises without changing the result.

use rayon::prelude::*;

use super::rng::unit;
use crate::mesh::Mesh;
use crate::quadric::{cross, norm, sub};

pub struct Sampler<'m> {
    mesh: &'m Mesh,
    /// Vertices referenced by at least one in-range triangle.
    vertices: Vec<u32>,
    /// Triangles with in-range indices and their running total area.
    triangles: Vec<[u32; 3]>,
    cumulative: Vec<f64>,
    area_samples: usize,
    seed: u64,
}

impl<'m> Sampler<'m> {
    /// `area_samples` points by area (none if the mesh has no area) on top of
    /// the used vertices.
    pub fn new(mesh: &'m Mesh, area_samples: usize, seed: u64) -> Self {
        let n = mesh.positions.len();
        let triangles: Vec<[u32; 3]> = mesh
            .triangles
            .iter()
            .copied()
            .filter(|t| t.iter().all(|&v| (v as usize) < n))
            .collect();
        let mut used = vec![false; n];
        for t in &triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let vertices = (0..n as u32).filter(|&v| used[v as usize]).collect();
        let mut total = 0.0;
        let cumulative: Vec<f64> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                total += 0.5 * norm(cross(sub(b, a), sub(c, a)));
                total
            })
            .collect();
        let area_samples = if total > 0.0 && total.is_finite() {
            area_samples
        } else {
            0
        };
        Sampler {
            mesh,
            vertices,
            triangles,
            cumulative,
            area_samples,
            seed,
        }
    }

    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.vertices.len() + self.area_samples
    }

    /// All samples: the used vertices in index order, then the area samples
    /// sorted along the surface (by triangle), so that consecutive distance
    /// queries walk nearby parts of the other mesh's BVH and stay in cache.
    /// Area sample `j` draws values `3j..3j + 3` of the seed's stream.
    pub fn points(&self) -> Vec<[f64; 3]> {
        let total = self.cumulative.last().copied().unwrap_or(0.0);
        // Sorting the (unique) triangle choices first replaces a binary
        // search per sample by one merge walk over the cumulative areas.
        let mut picks: Vec<(u64, u32)> = (0..self.area_samples as u32)
            .into_par_iter()
            .map(|j| ((unit(self.seed, 3 * u64::from(j)) * total).to_bits(), j))
            .collect();
        picks.par_sort_unstable();
        let mut triangle = 0;
        let chosen: Vec<(u32, u32)> = picks
            .iter()
            .map(|&(bits, j)| {
                let target = f64::from_bits(bits);
                while triangle + 1 < self.triangles.len() && self.cumulative[triangle] <= target {
                    triangle += 1;
                }
                (triangle as u32, j)
            })
            .collect();
        let mut points: Vec<[f64; 3]> = self
            .vertices
            .iter()
            .map(|&v| self.mesh.positions[v as usize])
            .collect();
        points.par_extend(
            chosen
                .par_iter()
                .map(|&(t, j)| self.on_triangle(t as usize, 3 * u64::from(j) + 1)),
        );
        points
    }

    /// A point uniform on triangle `t` from stream values `k` and `k + 1`.
    fn on_triangle(&self, t: usize, k: u64) -> [f64; 3] {
        let [a, b, c] = self.triangles[t].map(|v| self.mesh.positions[v as usize]);
        // sqrt warps the first coordinate so that area, not parameter space,
        // is uniform.
        let s = unit(self.seed, k).sqrt();
        let r = unit(self.seed, k + 1);
        let (wa, wb, wc) = (1.0 - s, s * (1.0 - r), s * r);
        [0, 1, 2].map(|i| wa * a[i] + wb * b[i] + wc * c[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_samples_follow_area() {
        // Two triangles in z = 0, areas 1 and 3.
        let mesh = Mesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 2.0, 0.0],
                [10.0, 0.0, 0.0],
                [13.0, 0.0, 0.0],
                [10.0, 2.0, 0.0],
                [50.0, 50.0, 50.0],
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let s = Sampler::new(&mesh, 4000, 9);
        assert_eq!(s.len(), 6 + 4000, "the unused vertex is not sampled");
        let points = s.points();
        assert_eq!(points.len(), s.len());
        assert_eq!(points[..6], mesh.positions[..6]);
        let right = points[6..].iter().filter(|p| p[0] >= 10.0).count();
        assert!((right as f64 / 4000.0 - 0.75).abs() < 0.03);
        for p in &points[6..] {
            let (x, y) = if p[0] >= 10.0 {
                ((p[0] - 10.0) / 3.0, p[1] / 2.0)
            } else {
                (p[0], p[1] / 2.0)
            };
            assert!(x >= 0.0 && y >= 0.0 && x + y <= 1.0 + 1e-12 && p[2] == 0.0);
        }
        assert_eq!(points, Sampler::new(&mesh, 4000, 9).points());
        assert_ne!(points, Sampler::new(&mesh, 4000, 10).points());
    }

    #[test]
    fn meshes_without_area_give_vertices_only() {
        let mesh = Mesh {
            positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
            triangles: vec![[0, 1, 2]],
        };
        assert_eq!(Sampler::new(&mesh, 100, 1).len(), 3);
    }
}
