//! Grouping simplification steps into levels of about double the vertex
//! count each (the paper's batches), from the base mesh up.

use crate::simplify::Simplification;

/// Levels in decoding order: for each refinement level, the simplification
/// steps it reverses (latest step first), and each level's error estimate.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelPlan {
    /// `rounds[l]` lists step indices for refinement level `l + 1`.
    pub rounds: Vec<Vec<usize>>,
    /// Geometric error after each level, base first (model units).
    pub errors: Vec<f32>,
}

/// Splits the steps into at most `levels - 1` refinement levels whose vertex
/// counts are as close as possible to a geometric sequence from the base
/// size to the full size. Errors are in the simplifier's metric units.
pub fn plan_levels(s: &Simplification, levels: usize) -> LevelPlan {
    let steps = s.steps.len();
    // Vertex count after undoing the last i steps (i = 0: the base).
    let mut counts = vec![s.alive_count as f64];
    for k in (0..steps).rev() {
        counts.push(counts.last().copied().unwrap_or(0.0) + s.steps[k].len() as f64);
    }
    let base = counts[0].max(1.0);
    let full = counts[steps].max(1.0);
    let wanted = (levels.max(1) - 1).min(steps);
    // Boundaries b_1 < ... < b_wanted = steps (numbers of rounds undone).
    let mut bounds = Vec::with_capacity(wanted);
    let mut previous = 0usize;
    for i in 1..=wanted {
        let remaining = wanted - i;
        let target = base * (full / base).powf(i as f64 / wanted as f64);
        let lo = previous + 1;
        let hi = steps - remaining;
        let best = (lo..=hi)
            .min_by(|&a, &b| {
                let da = (counts[a].ln() - target.ln()).abs();
                let db = (counts[b].ln() - target.ln()).abs();
                da.total_cmp(&db)
            })
            .unwrap_or(hi);
        bounds.push(if i == wanted { steps } else { best });
        previous = *bounds.last().unwrap_or(&0);
    }
    // Error estimate still present after undoing i rounds: the largest
    // distance of a collapse not undone yet (steps 0 .. steps - i).
    let mut prefix_max = vec![0.0f64; steps + 1];
    for k in 0..steps {
        let step_max = s.steps[k]
            .iter()
            .map(|c| c.distance)
            .fold(0.0f64, f64::max);
        prefix_max[k + 1] = prefix_max[k].max(step_max);
    }
    let error_after = |undone: usize| prefix_max[steps - undone] as f32;
    let mut rounds = Vec::with_capacity(bounds.len());
    let mut errors = vec![error_after(0)];
    let mut start = 0;
    for &b in &bounds {
        rounds.push((start..b).map(|i| steps - 1 - i).collect());
        errors.push(error_after(b));
        start = b;
    }
    LevelPlan { rounds, errors }
}
