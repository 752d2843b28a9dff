//! The judge of a prior (a warp whose primary points carry no learning): at a
//! held-out condition, the cap L2 discrepancy (paper Eq. 9, `theta` uniform, Monte
//! Carlo over measured caps) of `N` points through the prior, for Owen-Sobol
//! points and for a randomly shifted rank-1 lattice, over that of Owen-Sobol
//! through the exact inverse CDF of the condition's own target (the baseline of
//! the bakes' quality checks). Shared by `eval envmap-prior` and
//! `eval brdf-prior`.

use crate::baselines::seeded_owen_sobol;
use crate::seeding::{derive_seed, rng};
use crate::sphere::metrics::{CapRadius, MeasuredCaps};
use crate::sphere::DirectionDensity;
use crate::train::lattice_generator;
use glam::{DVec2, DVec3};
use nuld_core::network::shifted_lattice_point;
use rand::Rng;
use rayon::prelude::*;

/// How many points, sets and caps a judge uses.
#[derive(Clone, Copy, Debug)]
pub struct JudgeSettings {
    /// Points per set.
    pub n: u32,
    /// Sets averaged per condition and method.
    pub instances: u32,
    /// Measured caps per condition.
    pub caps: usize,
    /// Seed of the caps, scrambles and shifts.
    pub seed: u64,
}

/// A held-out condition's caps and the baseline's mean cap L2.
pub struct Judge<C> {
    /// The condition (a normal, a BRDF condition).
    pub condition: C,
    caps: MeasuredCaps,
    baseline: f64,
}

impl<C: Sync> Judge<C> {
    /// The judge of `target` at `condition`, the `index`-th of its run (the caps'
    /// seed); `exact` is the target's exact inverse CDF (the baseline's warp of
    /// Owen-Sobol points).
    pub fn new(
        condition: C,
        target: &dyn DirectionDensity,
        exact: &(dyn Fn(DVec2) -> DVec3 + Sync),
        s: &JudgeSettings,
        index: u64,
    ) -> Self {
        let caps = MeasuredCaps::draw(
            s.caps,
            derive_seed(s.seed, index),
            CapRadius::ThetaUniform,
            |w, t| target.cap_measure(w, t),
        );
        let mut judge = Self {
            condition,
            caps,
            baseline: 0.0,
        };
        let n = s.n as usize;
        judge.baseline = mean(
            (0..s.instances as u64)
                .into_par_iter()
                .map(|k| {
                    let pts: Vec<DVec3> = seeded_owen_sobol(n, s.seed ^ (k + 1))
                        .into_iter()
                        .map(exact)
                        .collect();
                    judge.d(&pts)
                })
                .collect(),
        );
        judge
    }

    /// Cap L2 discrepancy of `pts` against the target.
    pub fn d(&self, pts: &[DVec3]) -> f64 {
        self.caps.l2_squared(pts, CapRadius::ThetaUniform).0.sqrt()
    }

    /// The baseline's mean cap L2 (what ratios divide by).
    pub fn baseline(&self) -> f64 {
        self.baseline
    }
}

/// `(mean, worst)` over the judges of Owen-Sobol and of shifted-lattice sets
/// mapped by `warp(condition, primary point)`, each over the judge's baseline.
pub fn score<C: Sync>(
    judges: &[Judge<C>],
    s: &JudgeSettings,
    warp: &(dyn Fn(&C, DVec2) -> DVec3 + Sync),
) -> ((f64, f64), (f64, f64)) {
    let n = s.n as usize;
    let g = lattice_generator(s.n);
    let through =
        |c: &C, primary: &[DVec2]| -> Vec<DVec3> { primary.iter().map(|&u| warp(c, u)).collect() };
    let (mut os, mut lat) = (Vec::new(), Vec::new());
    for (j, judge) in judges.iter().enumerate() {
        let owen: Vec<f64> = (0..s.instances as u64)
            .into_par_iter()
            .map(|k| {
                judge.d(&through(
                    &judge.condition,
                    &seeded_owen_sobol(n, s.seed ^ (k + 1)),
                ))
            })
            .collect();
        let lattice: Vec<f64> = (0..s.instances as u64)
            .into_par_iter()
            .map(|k| {
                let mut z = rng(s.seed, (j as u64) << 32 | k);
                let shift = [z.random::<f64>(), z.random::<f64>()];
                let pts: Vec<DVec2> = (0..s.n)
                    .map(|i| DVec2::from(shifted_lattice_point(i, s.n, g, shift)))
                    .collect();
                judge.d(&through(&judge.condition, &pts))
            })
            .collect();
        os.push(mean(owen) / judge.baseline);
        lat.push(mean(lattice) / judge.baseline);
    }
    let summary = |v: &[f64]| (mean(v.to_vec()), v.iter().copied().fold(0.0, f64::max));
    (summary(&os), summary(&lat))
}

fn mean(v: Vec<f64>) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}
