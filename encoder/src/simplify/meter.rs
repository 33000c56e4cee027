//! The mean live edge length, which scales the sub-grid and the flat threshold.

use rayon::prelude::*;

use super::state::State;
use crate::corner_table::NONE;

/// Mean length of the live edges, for the sub-grid cell size and the flat
/// threshold. Keeps the list of triangles that were alive at the last
/// measure, so a measure costs the live triangles, not every corner ever
/// allocated (the corner array never shrinks: with 43 measures down to the
/// seed, sweeping it cost more than some whole phases).
pub(super) struct EdgeMeter {
    pub(super) triangles: Vec<u32>,
}

impl EdgeMeter {
    pub fn new(s: &State) -> EdgeMeter {
        EdgeMeter {
            triangles: (0..(s.table.vertex.len() / 3) as u32).collect(),
        }
    }

    pub fn measure(&mut self, s: &State) -> f64 {
        let t = &s.table;
        self.triangles.retain(|&k| t.v(3 * k) != NONE);
        // Fixed chunks summed in order: the same bits whatever the thread
        // count (a rayon reduce's tree follows the work stealing).
        let sums: Vec<f64> = self
            .triangles
            .par_chunks(4096)
            .map(|chunk| {
                let mut sum = 0.0;
                for &k in chunk {
                    // Each corner's point once, its edges in corner order
                    // (corner c to next c): the same sums as before.
                    let g = [0, 1, 2].map(|j| s.geometry(t.v(3 * k + j)));
                    for j in 0..3 {
                        sum += crate::quadric::norm(crate::quadric::sub(g[j], g[(j + 1) % 3]));
                    }
                }
                sum
            })
            .collect();
        let count = 3 * self.triangles.len();
        if count == 0 {
            1.0
        } else {
            sums.iter().sum::<f64>() / count as f64
        }
    }
}
