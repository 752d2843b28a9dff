//! Gradient descent as every optimizer here runs it (paper §3.4): Adam on a loss
//! whose sigmoid sharpens on a schedule while the step decays.
//!
//! * [`adam`]: Adam on 2D points or on a network's flat weights, with optional
//!   per-parameter step scales;
//! * [`schedule`]: the sharpness ramp and the cosine step decay;
//! * [`local_units`]: the per-point factor of concentrated targets;
//! * here: [`EpochLoss`], what a loss tells the descent each epoch, and
//!   [`Descent::epoch`], the one epoch step that the 2D optimizer
//!   ([`crate::optimize::optimize`]), the direction optimizer
//!   ([`crate::optimize::directions`]) and the network trainer ([`crate::train`])
//!   all take.

pub mod adam;
pub mod local_units;
pub mod schedule;

pub use adam::{Adam, AdamParam};
pub use local_units::{local_factor, MAX_LOCAL_FACTOR};
pub use schedule::{epoch_schedule, Schedule};

use serde::Serialize;

/// Parameters per task when a step's work parameter by parameter (Adam's
/// update, a trainer's sum of gradients) runs on the thread pool: a network's
/// tens of thousands of weights split, a point set of a few hundred does not.
pub(crate) const PARAMETER_CHUNK: usize = 1 << 13;

/// A loss that a [`Descent`] minimizes over parameters of type `P`.
pub trait EpochLoss<P> {
    /// The loss at `params` in epoch `epoch`, with sigmoid sharpness `alpha` (the
    /// schedule's value over the descent's spacing); writes `dL/dparams` into
    /// `grad`, which holds zeros on entry (so a loss may sum into it).
    fn loss_and_gradient(&mut self, epoch: usize, alpha: f64, params: &[P], grad: &mut [P]) -> f64;

    /// Per-parameter multipliers of this epoch's step (see [`Adam::step_scaled`]),
    /// asked after [`Self::loss_and_gradient`]; `None` (the default) is 1 for all.
    fn step_scales(&self) -> Option<&[f64]> {
        None
    }

    /// Brings the parameters back into their domain after a step; the default
    /// leaves them as they are.
    fn project(&self, _params: &mut [P]) {}
}

/// What one epoch did.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EpochReport {
    /// 0-based epoch index (in the schedule).
    pub epoch: usize,
    /// The loss before the step.
    pub loss: f64,
    /// Sigmoid sharpness used (the schedule's over the spacing).
    pub alpha: f64,
    /// Step size used, in the parameters' units.
    pub learning_rate: f64,
}

/// A descent: Adam state, a gradient buffer, the schedule and the units.
#[derive(Clone, Debug)]
pub struct Descent<P: AdamParam> {
    /// The optimizer's state.
    pub adam: Adam<P>,
    /// The annealing.
    pub schedule: Schedule,
    /// Step size at a ratio of 1, in the parameters' units.
    pub learning_rate: f64,
    /// The point spacing the schedule's sharpness is measured in (1 when the loss
    /// takes it in inverse spacings itself).
    pub spacing: f64,
    grad: Vec<P>,
}

impl<P: AdamParam> Descent<P> {
    /// A descent of `adam`'s parameters (as many as its state holds).
    pub fn new(adam: Adam<P>, schedule: Schedule, learning_rate: f64, spacing: f64) -> Self {
        let grad = vec![P::ZERO; adam.len()];
        Self {
            adam,
            schedule,
            learning_rate,
            spacing,
            grad,
        }
    }

    /// One epoch: the schedule at `epoch`, the loss and its gradient at `params`,
    /// one Adam step (scaled by the loss's step scales), the loss's projection.
    ///
    /// # Panics
    /// If `params` has another length than the Adam state.
    pub fn epoch(
        &mut self,
        epoch: usize,
        params: &mut [P],
        loss: &mut impl EpochLoss<P>,
    ) -> EpochReport {
        let (alpha_spacings, lr_ratio) = self.schedule.at(epoch);
        let alpha = alpha_spacings / self.spacing;
        let lr = self.learning_rate * lr_ratio;
        self.grad.fill(P::ZERO);
        let value = loss.loss_and_gradient(epoch, alpha, params, &mut self.grad);
        self.adam
            .step_scaled(params, &self.grad, lr, loss.step_scales());
        loss.project(params);
        EpochReport {
            epoch,
            loss: value,
            alpha,
            learning_rate: lr,
        }
    }

    /// Every epoch of the schedule in turn, calling `on_epoch` after each.
    pub fn run(
        &mut self,
        params: &mut [P],
        loss: &mut impl EpochLoss<P>,
        on_epoch: &mut dyn FnMut(&EpochReport),
    ) {
        for epoch in 0..self.schedule.epochs {
            let report = self.epoch(epoch, params, loss);
            on_epoch(&report);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(x - target)^2` per coordinate; the sharpness is recorded, not used.
    struct Quadratic {
        target: f64,
        alphas: Vec<f64>,
    }

    impl EpochLoss<f64> for Quadratic {
        fn loss_and_gradient(&mut self, _: usize, alpha: f64, x: &[f64], g: &mut [f64]) -> f64 {
            self.alphas.push(alpha);
            let mut l = 0.0;
            for (g, &x) in g.iter_mut().zip(x) {
                *g += 2.0 * (x - self.target);
                l += (x - self.target).powi(2);
            }
            l
        }

        fn project(&self, x: &mut [f64]) {
            x.iter_mut().for_each(|v| *v = v.min(1.0));
        }
    }

    #[test]
    fn a_descent_follows_its_schedule_and_minimizes() {
        let schedule = Schedule {
            epochs: 400,
            alpha: (8.0, 128.0),
            final_learning_rate_ratio: 0.1,
        };
        let mut d = Descent::new(Adam::<f64>::new(2), schedule, 0.05, 0.5);
        let mut x = vec![3.0, -2.0];
        let mut loss = Quadratic {
            target: 0.25,
            alphas: vec![],
        };
        let mut reports = vec![];
        d.run(&mut x, &mut loss, &mut |r| reports.push(*r));
        assert_eq!(reports.len(), 400);
        // Sharpness in spacings over the spacing, the step decayed to its end.
        assert_eq!(loss.alphas[0], 16.0);
        assert_eq!(loss.alphas[399], 256.0);
        assert_eq!(reports[0].learning_rate, 0.05);
        assert!((reports[399].learning_rate - 0.005).abs() < 1e-15);
        assert!(reports[0].loss > reports[399].loss);
        assert!(x.iter().all(|v| (v - 0.25).abs() < 1e-2), "{x:?}");
        // The loss's projection follows each step: Adam's first step is 0.05 per
        // coordinate, so 3 would stay at 2.95 without it.
        let mut d = Descent::new(Adam::<f64>::new(2), schedule, 0.05, 0.5);
        let mut x = vec![3.0, -2.0];
        d.epoch(0, &mut x, &mut loss);
        assert_eq!(x[0], 1.0);
        assert!((x[1] - -1.95).abs() < 1e-12, "{x:?}");
    }

    #[test]
    fn an_epoch_is_one_plain_adam_step() {
        // Without step scales and projection, an epoch is Adam::step at the
        // schedule's rate, bit for bit.
        struct Linear;
        impl EpochLoss<f64> for Linear {
            fn loss_and_gradient(&mut self, _: usize, _: f64, x: &[f64], g: &mut [f64]) -> f64 {
                g.iter_mut().zip(x).for_each(|(g, x)| *g += 0.3 + x);
                0.0
            }
        }
        let schedule = Schedule {
            epochs: 5,
            alpha: (1.0, 2.0),
            final_learning_rate_ratio: 0.5,
        };
        let mut d = Descent::new(Adam::<f64>::new(3), schedule, 0.1, 1.0);
        let mut adam = Adam::<f64>::new(3);
        let (mut p, mut q) = (vec![0.1, -0.2, 0.7], vec![0.1, -0.2, 0.7]);
        for e in 0..5 {
            d.epoch(e, &mut p, &mut Linear);
            let g: Vec<f64> = q.iter().map(|x| 0.0 + (0.3 + x)).collect();
            adam.step(&mut q, &g, 0.1 * schedule.at(e).1);
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&p), bits(&q));
    }
}
