//! Grouping simplification steps into levels of about double the vertex
//! count each (the paper's batches), from the base mesh up.

use crate::simplify::Simplification;

/// Levels in decoding order: for each level, the simplification steps it
/// reverses (latest step first), and each level's error estimate.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelPlan {
    /// `rounds[l]` lists the step indices whose reversal forms level `l`;
    /// level 0 starts from the seed mesh (what the simplification left).
    pub rounds: Vec<Vec<usize>>,
    /// Geometric error after each level (metric units).
    pub errors: Vec<f32>,
}

/// Picks `levels` level boundaries (as numbers of rounds undone): level 0
/// ends closest to `base_vertices`, the others are as close as possible to
/// a geometric sequence from there to the full mesh. The last level always
/// ends at the full mesh, so with one level `base_vertices` has no effect.
pub fn plan_levels(s: &Simplification, levels: usize, base_vertices: usize) -> LevelPlan {
    let steps = s.steps.len();
    // Vertex count after undoing the last i steps (i = 0: the seed).
    let mut counts = vec![s.alive_count as f64];
    for k in (0..steps).rev() {
        counts.push(counts.last().copied().unwrap_or(0.0) + s.steps[k].len() as f64);
    }
    let log_distance =
        |i: usize, target: f64| (counts[i].max(1.0).ln() - target.max(1.0).ln()).abs();
    let closest = |lo: usize, hi: usize, target: f64| {
        (lo..=hi)
            .min_by(|&a, &b| log_distance(a, target).total_cmp(&log_distance(b, target)))
            .unwrap_or(hi)
    };
    let refinement = (levels.max(1) - 1).min(steps);
    let base_end = if refinement == 0 {
        steps
    } else {
        closest(0, steps - refinement, base_vertices as f64)
    };
    let mut bounds = vec![base_end];
    let (base, full) = (counts[base_end].max(1.0), counts[steps].max(1.0));
    for i in 1..=refinement {
        let previous = bounds[bounds.len() - 1];
        let target = base * (full / base).powf(i as f64 / refinement as f64);
        let hi = steps - (refinement - i);
        bounds.push(if i == refinement {
            steps
        } else {
            closest(previous + 1, hi, target)
        });
    }
    // Error still present after undoing i rounds: the largest distance of a
    // collapse not undone yet (steps 0 .. steps - i).
    let mut prefix_max = vec![0.0f64; steps + 1];
    for k in 0..steps {
        let step_max = s.steps[k].iter().map(|c| c.distance).fold(0.0f64, f64::max);
        prefix_max[k + 1] = prefix_max[k].max(step_max);
    }
    let error_after = |undone: usize| prefix_max[steps - undone] as f32;
    let mut rounds = Vec::with_capacity(bounds.len());
    let mut errors = Vec::with_capacity(bounds.len());
    let mut start = 0;
    for &b in &bounds {
        rounds.push((start..b).map(|i| steps - 1 - i).collect());
        errors.push(error_after(b));
        start = b;
    }
    LevelPlan { rounds, errors }
}
