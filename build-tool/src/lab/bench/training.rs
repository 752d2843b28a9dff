//! Training speed: the wall time of one training step of the conditional BRDF
//! sampler at several `N` (all threads, the default configuration otherwise), and
//! what it implies for a bake of the default step count.

use crate::train::{TrainConfig, Trainer};
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
}

impl TrainTiming {
    /// Seconds of a run of `steps` steps at this rate, setup included (the
    /// pretraining steps of a bake cost less, so counting them as steps gives an
    /// upper estimate).
    pub fn run_seconds(&self, steps: usize) -> f64 {
        self.setup_s + steps as f64 * self.ms_per_step * 1e-3
    }
}

/// Times the default [`TrainConfig`] at each `(n, steps)` of `sizes`: the
/// trainer's setup, then one untimed step (first-touch allocations) and `steps`
/// (at least 1) timed cap-loss steps (pretraining skipped, so every timed step is
/// a training step).
pub fn measure(sizes: &[(u32, usize)]) -> Vec<TrainTiming> {
    sizes
        .iter()
        .map(|&(n, steps)| {
            let steps = steps.max(1);
            let config = TrainConfig {
                n,
                pretrain_steps: 0,
                steps: steps + 1,
                ..TrainConfig::default()
            };
            let t = Instant::now();
            let mut trainer = Trainer::new(config, None).expect("the BRDF pool reads no file");
            let setup_s = t.elapsed().as_secs_f64();
            trainer.step();
            let t = Instant::now();
            for _ in 0..steps {
                trainer.step();
            }
            TrainTiming {
                n,
                setup_s,
                ms_per_step: t.elapsed().as_secs_f64() * 1e3 / steps as f64,
                timed_steps: steps,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_size_is_timed_with_its_step_count() {
        let t = measure(&[(8, 2), (4, 0)]);
        assert_eq!(
            t.iter().map(|t| (t.n, t.timed_steps)).collect::<Vec<_>>(),
            [(8, 2), (4, 1)]
        );
        assert!(t
            .iter()
            .all(|t| t.ms_per_step.is_finite() && t.ms_per_step > 0.0 && t.setup_s > 0.0));
    }

    #[test]
    fn run_seconds_adds_the_setup_to_the_steps() {
        let t = TrainTiming {
            n: 64,
            setup_s: 1.5,
            ms_per_step: 20.0,
            timed_steps: 3,
        };
        assert_eq!(t.run_seconds(100), 3.5);
    }
}
