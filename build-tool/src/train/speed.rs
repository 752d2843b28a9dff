//! Training speed: the wall time of one training step of the conditional BRDF
//! sampler at several `N` (all threads, the default configuration otherwise), and
//! what it implies for a bake of the default step count.

use super::{TrainConfig, Trainer};
use std::time::Instant;

/// One `N`'s timing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrainTiming {
    /// Points per set.
    pub n: u32,
    /// Seconds to build the trainer (the condition pool and its baselines).
    pub setup_s: f64,
    /// Milliseconds per cap-loss step, the mean over the timed steps.
    pub ms_per_step: f64,
    /// Steps timed.
    pub timed_steps: usize,
    /// The default bake's training time this implies, in seconds: setup plus the
    /// default pretraining and training steps at `ms_per_step` (pretraining steps
    /// cost less, so this is an upper estimate of those).
    pub default_training_s: f64,
}

/// Times the default [`TrainConfig`] at each `n` of `sizes`: the trainer's setup,
/// then one untimed step (first-touch allocations) and `timed_steps(n)` timed
/// cap-loss steps (pretraining skipped, so every timed step is a training step).
pub fn measure(sizes: &[u32], timed_steps: impl Fn(u32) -> usize) -> Vec<TrainTiming> {
    let default = TrainConfig::default();
    sizes
        .iter()
        .map(|&n| {
            let steps = timed_steps(n).max(1);
            let config = TrainConfig {
                n,
                pretrain_steps: 0,
                steps: steps + 1,
                ..TrainConfig::default()
            };
            let t = Instant::now();
            let mut trainer = Trainer::new(config, None);
            let setup_s = t.elapsed().as_secs_f64();
            trainer.step();
            let t = Instant::now();
            for _ in 0..steps {
                trainer.step();
            }
            let ms_per_step = t.elapsed().as_secs_f64() * 1e3 / steps as f64;
            let total = default.pretrain_steps + default.steps;
            TrainTiming {
                n,
                setup_s,
                ms_per_step,
                timed_steps: steps,
                default_training_s: setup_s + total as f64 * ms_per_step * 1e-3,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timings_are_positive_and_scale_with_the_step_count() {
        let t = measure(&[8], |_| 2);
        assert_eq!(t.len(), 1);
        let t = t[0];
        assert_eq!((t.n, t.timed_steps), (8, 2));
        assert!(t.ms_per_step > 0.0 && t.setup_s > 0.0);
        let d = TrainConfig::default();
        let want = t.setup_s + (d.pretrain_steps + d.steps) as f64 * t.ms_per_step * 1e-3;
        assert!((t.default_training_s - want).abs() < 1e-9 * want);
    }
}
