//! The baseline generators' speed: what the evaluation harness pays per
//! realization before any metric (`build-tool bench --only baselines`).

use crate::baselines::Baseline;
use anyhow::{ensure, Result};
use std::time::Instant;

/// Milliseconds for `baseline` to make one uniform set of `n` points: the fastest
/// of seeds `1..=repeats` (the run least disturbed by other work on the machine).
/// An error if a set has the wrong size.
pub fn best_ms_per_set(baseline: Baseline, n: usize, repeats: u64) -> Result<f64> {
    let mut best = f64::INFINITY;
    for seed in 1..=repeats {
        let t = Instant::now();
        let pts = baseline.generate(n, seed);
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        ensure!(
            pts.len() == n,
            "{baseline} made {} points, not {n}",
            pts.len()
        );
    }
    Ok(best)
}
