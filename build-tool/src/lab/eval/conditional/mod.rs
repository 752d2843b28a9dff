//! Quality report of a conditional BRDF sampler (paper §4) on held-out conditions:
//! `build-tool eval conditional`.
//!
//! At each condition `(roughness, theta_o)` of a held-out grid the target is the
//! glTF BRDF's `q(l) = f cos / A` ([`BrdfTarget`]); every sampler under test (a
//! [`ConditionalSets`]: table mode, network mode) and three references give sets
//! of the sampler's `N` directions:
//!
//! * **exact**: Owen-scrambled Sobol points warped by the exact tabulated inverse
//!   CDF of `q` ([`TabulatedWarp`]), one scramble per instance;
//! * **mixture**: the same points warped the way a renderer does
//!   ([`BrdfTarget::sample`]: GGX VNDF with probability `A_spec / A`, else cosine);
//! * **direct**: one set optimized for this one condition by the direction
//!   optimizer ([`optimize_directions_scheduled`], paper §3.5), at a few
//!   conditions (it costs about a minute each at `N = 64`).
//!
//! Each set is scored by its cap L2 discrepancy (paper Eq. 9, theta-uniform random
//! caps, with its Monte Carlo standard error; [`MeasuredCaps`]) and by the largest
//! local discrepancy found ([`cap_star_estimate_screened`], a lower bound of the cap
//! star discrepancy). The target's cap measures are computed once per condition
//! and shared by every set. Scores are means over `instances` instances; ratios are
//! the sampler's mean over a reference's mean. [`diversity()`] measures whether the
//! instances are different sets.
//!
//! Deterministic for a seed whatever the thread count: every random stream is
//! `derive_seed` of the run seed, the condition's index and a fixed stream number,
//! and every parallel reduction runs in a fixed order.

pub mod report;
pub mod sets;

pub use crate::sphere::metrics::{diversity, Diversity};
pub use report::{ConditionResult, ConditionalReport, MethodScore, References};
pub use sets::{blob_sets, ConditionalSets, MixtureOwenSobol, SampleFnSets};

use crate::baselines::seeded_owen_sobol;
use crate::optimize::directions::{optimize_directions_scheduled, CapSchedule, DirectionConfig};
use crate::progress::Progress;
use crate::seeding::derive_seed;
use crate::sphere::{
    cap_star_estimate_screened, root_with_stderr, BrdfTarget, CapRadius, CapStarOptions,
    DirectionDensity, MeasuredCaps, TabulatedWarp,
};
use anyhow::{ensure, Result};
use glam::DVec3;
use nuld_core::blob::Domain;
use rayon::prelude::*;
use serde::Serialize;

/// Held-out roughness values: each at least 0.3 of a cell away from the nodes of
/// uniform grids of 10 and of 16 nodes over `[0.1, 1]` (0.13, 0.25 and 0.85 sit
/// exactly between two nodes of the 16-node grid).
pub const HELD_OUT_ROUGHNESS: [f64; 5] = [0.13, 0.25, 0.44, 0.66, 0.85];
/// Held-out view angles (degrees): each at least 0.2 of a cell away from the nodes
/// of uniform grids of 10 and of 16 nodes over `[0, 89]`, and of 10-degree steps.
pub const HELD_OUT_THETA_DEG: [f64; 5] = [4.0, 26.0, 45.0, 63.0, 85.0];
/// Indices into [`held_out_conditions`] of the conditions where sets are optimized
/// directly: the anti-diagonal, from the sharpest lobe (roughness 0.13 at 85
/// degrees) to the broadest (0.85 at 4 degrees).
pub const DIRECT_CONDITIONS: [usize; 5] = [4, 8, 12, 16, 20];

/// The held-out grid, roughness-major: condition `5 i + j` is
/// `(HELD_OUT_ROUGHNESS[i], HELD_OUT_THETA_DEG[j])`.
pub fn held_out_conditions() -> Vec<[f64; 2]> {
    HELD_OUT_ROUGHNESS
        .iter()
        .flat_map(|&r| HELD_OUT_THETA_DEG.iter().map(move |&t| [r, t]))
        .collect()
}

/// Base seed of the report.
pub const CONDITIONAL_SEED: u64 = 0xC0_4D17;

/// What a report run evaluates and how hard it looks.
#[derive(Clone, Debug, Serialize)]
pub struct ConditionalSettings {
    /// Conditions `[roughness, theta_o_deg]`.
    pub conditions: Vec<[f64; 2]>,
    /// Instances scored per (condition, method); scores are their means.
    pub instances: usize,
    /// Instances whose union and pairs measure [`diversity()`] (at least 2).
    pub union_instances: usize,
    /// Random caps of the cap L2 estimate (theta-uniform).
    pub cap_l2_caps: usize,
    /// Random caps of the largest-local-discrepancy search.
    pub cap_star_caps: usize,
    /// Best random caps refined by the search.
    pub cap_star_refine: usize,
    /// Hill-climbing rounds per refined cap.
    pub cap_star_rounds: usize,
    /// Indices into `conditions` where one set is optimized directly.
    pub direct: Vec<usize>,
    /// Epochs of the direct optimization.
    pub direct_epochs: usize,
    /// Side of the grid of the exact tabulated inverse CDF.
    pub tabulation: usize,
    /// Midpoints per cell side when tabulating.
    pub tabulation_subsamples: usize,
    /// Run seed.
    pub seed: u64,
    /// Whether these are the reduced `--quick` settings.
    pub quick: bool,
}

impl ConditionalSettings {
    /// The full report: the 5x5 held-out grid, 8 instances, 64 for diversity, 4096
    /// cap L2 caps, 20000 search caps with 8 refined over 8 rounds, direct
    /// optimization (5000 epochs) at [`DIRECT_CONDITIONS`], a 1024-square
    /// tabulation with 2x2 midpoints per cell.
    pub fn full() -> Self {
        Self {
            conditions: held_out_conditions(),
            instances: 8,
            union_instances: 64,
            cap_l2_caps: 4096,
            cap_star_caps: 20_000,
            cap_star_refine: 8,
            cap_star_rounds: 8,
            direct: DIRECT_CONDITIONS.to_vec(),
            direct_epochs: 5000,
            tabulation: 1024,
            tabulation_subsamples: 2,
            seed: CONDITIONAL_SEED,
            quick: false,
        }
    }

    /// The `--quick` settings: three conditions of the grid (the sharpest, the
    /// middle, the broadest), 8 instances, 16 for diversity, 512 / 500 caps, 2
    /// refined over 3 rounds, direct optimization (100 epochs) at the sharpest, a
    /// 512-square tabulation.
    pub fn quick() -> Self {
        let all = held_out_conditions();
        Self {
            conditions: vec![all[4], all[12], all[20]],
            union_instances: 16,
            cap_l2_caps: 512,
            cap_star_caps: 500,
            cap_star_refine: 2,
            cap_star_rounds: 3,
            direct: vec![0],
            direct_epochs: 100,
            tabulation: 512,
            quick: true,
            ..Self::full()
        }
    }

    /// Checks the settings: conditions in range, at least one instance, two for
    /// diversity, positive effort, direct indices in range.
    pub fn validate(&self) -> Result<()> {
        ensure!(!self.conditions.is_empty(), "no conditions to evaluate");
        for &[r, t] in &self.conditions {
            ensure!(
                (0.1..=1.0).contains(&r) && (0.0..=89.0).contains(&t),
                "condition ({r}, {t}) is outside roughness [0.1, 1] x theta_o [0, 89]"
            );
        }
        ensure!(
            self.instances >= 1,
            "instances per condition must be at least 1"
        );
        ensure!(
            self.union_instances >= 2,
            "--n-instances must be at least 2"
        );
        ensure!(
            self.cap_l2_caps >= 2 && self.cap_star_caps >= 1 && self.tabulation >= 1,
            "metric settings must be positive"
        );
        ensure!(
            self.direct.iter().all(|&i| i < self.conditions.len()),
            "direct-optimization condition out of range"
        );
        Ok(())
    }

    fn star_options(&self) -> CapStarOptions {
        CapStarOptions {
            random_caps: self.cap_star_caps,
            refine: self.cap_star_refine,
            rounds: self.cap_star_rounds,
            ..CapStarOptions::default()
        }
    }

    /// Sets scored in all, for the progress bar: per condition, every sampler's
    /// instances, the exact reference's union instances, the mixture's instances,
    /// and one direct set where asked.
    fn total_steps(&self, samplers: usize) -> u64 {
        let per = samplers * self.instances.max(self.union_instances)
            + self.instances.max(self.union_instances)
            + self.instances;
        (self.conditions.len() * per + self.direct.len()) as u64
    }
}

/// Stream numbers of [`derive_seed`] under a condition's seed.
const CAPS_L2_STREAM: u64 = 1;
const CAPS_STAR_STREAM: u64 = 2;
const STAR_SEARCH_STREAM: u64 = 3;
const DIRECT_STREAM: u64 = 4;
/// Instance `k` of the references uses scramble stream `SCRAMBLE_STREAM + k`.
const SCRAMBLE_STREAM: u64 = 1 << 20;

/// One condition's shared measuring tools.
struct Judge<'a> {
    target: &'a BrdfTarget,
    l2_caps: MeasuredCaps,
    star_caps: MeasuredCaps,
    star: CapStarOptions,
    star_seed: u64,
}

impl Judge<'_> {
    /// `(cap L2, its MC standard error, largest local discrepancy found)`.
    fn score(&self, points: &[DVec3]) -> (f64, f64, f64) {
        let (d2, se2) = self.l2_caps.l2_squared(points, CapRadius::ThetaUniform);
        let (d, se) = root_with_stderr(d2, se2);
        let star = cap_star_estimate_screened(
            points,
            self.target,
            &self.star_caps,
            &self.star,
            self.star_seed,
        );
        (d, se, star.lower_bound)
    }

    /// The mean score of `sets` (in parallel over sets, collected in order).
    fn score_sets(&self, method: &str, sets: &[Vec<DVec3>], progress: &Progress) -> MethodScore {
        let scores: Vec<(f64, f64, f64)> = sets
            .par_iter()
            .map(|s| {
                let v = self.score(s);
                progress.inc(1);
                v
            })
            .collect();
        MethodScore::from_scores(method, &scores)
    }
}

/// Evaluates `samplers` (all with the same `N >= 2`) at every condition of
/// `settings` against the references (module docs); reports progress in sets.
pub fn evaluate(
    samplers: &[&dyn ConditionalSets],
    settings: &ConditionalSettings,
) -> Result<ConditionalReport> {
    settings.validate()?;
    ensure!(!samplers.is_empty(), "no sampler to evaluate");
    let n = samplers[0].len();
    ensure!(n >= 2, "sets of {n} points: need at least 2");
    ensure!(
        samplers.iter().all(|s| s.len() == n),
        "samplers differ in their number of points per set"
    );
    ensure!(
        n <= crate::baselines::OWEN_SOBOL_MAX_POINTS,
        "N = {n} exceeds the Owen-Sobol baseline's 65536"
    );
    let progress = Progress::stderr(
        "eval conditional",
        settings.total_steps(samplers.len()),
        "set",
    );
    let star = settings.star_options();
    let per_instance = settings.instances.max(settings.union_instances);
    let mut results = Vec::with_capacity(settings.conditions.len());
    for (ci, &[roughness, theta]) in settings.conditions.iter().enumerate() {
        progress.set_context(format!("roughness {roughness}, theta_o {theta}"));
        let cond_seed = derive_seed(settings.seed, ci as u64);
        let target = BrdfTarget::new(roughness, theta, Domain::Hemisphere)?;
        let measure = |w: DVec3, t: f64| target.cap_measure(w, t);
        let judge = Judge {
            target: &target,
            l2_caps: MeasuredCaps::draw(
                settings.cap_l2_caps,
                derive_seed(cond_seed, CAPS_L2_STREAM),
                CapRadius::ThetaUniform,
                measure,
            ),
            star_caps: MeasuredCaps::draw(
                settings.cap_star_caps,
                derive_seed(cond_seed, CAPS_STAR_STREAM),
                CapRadius::ThetaUniform,
                measure,
            ),
            star,
            star_seed: derive_seed(cond_seed, STAR_SEARCH_STREAM),
        };
        let scrambles: Vec<Vec<glam::DVec2>> = (0..per_instance as u64)
            .map(|k| seeded_owen_sobol(n, derive_seed(cond_seed, SCRAMBLE_STREAM + k)))
            .collect();
        let exact_sets: Vec<Vec<DVec3>> = {
            let warp =
                TabulatedWarp::new(&target, settings.tabulation, settings.tabulation_subsamples)?;
            scrambles.iter().map(|u| warp.warp_all(u)).collect()
        };
        let mixture_sets: Vec<Vec<DVec3>> = scrambles[..settings.instances]
            .iter()
            .map(|u| u.iter().map(|&p| target.sample(p)).collect())
            .collect();

        let mut methods = Vec::new();
        let mut diversities = Vec::new();
        let mut examples = Vec::new();
        for s in samplers {
            let mut sets: Vec<Vec<DVec3>> = (0..per_instance as u32)
                .into_par_iter()
                .map(|k| s.set(roughness, theta, k))
                .collect();
            ensure!(
                sets.iter().all(|p| p.len() == n),
                "sampler {} returned a set of the wrong size",
                s.name()
            );
            methods.push(judge.score_sets(s.name(), &sets[..settings.instances], &progress));
            progress.inc((per_instance - settings.instances) as u64);
            diversities.push((
                s.name().to_string(),
                diversity(&sets[..settings.union_instances], &judge.l2_caps),
            ));
            examples.push((s.name().to_string(), sets.swap_remove(0)));
        }
        let exact = judge.score_sets(report::EXACT, &exact_sets[..settings.instances], &progress);
        progress.inc((per_instance - settings.instances) as u64);
        diversities.push((
            report::EXACT.to_string(),
            diversity(&exact_sets[..settings.union_instances], &judge.l2_caps),
        ));
        examples.push((report::EXACT.to_string(), exact_sets[0].clone()));
        let mixture = judge.score_sets(report::MIXTURE, &mixture_sets, &progress);
        let direct = if settings.direct.contains(&ci) {
            let cfg = DirectionConfig {
                epochs: settings.direct_epochs,
                seed: derive_seed(cond_seed, DIRECT_STREAM),
                ..DirectionConfig::default()
            };
            progress.set_message("optimizing directly");
            let schedule = CapSchedule::new(&target, &cfg);
            let square = optimize_directions_scheduled(&target, n, &cfg, &schedule, &mut |_| {});
            let dirs: Vec<DVec3> = square
                .iter()
                .map(|&p| Domain::Hemisphere.to_direction(p))
                .collect();
            progress.set_message("");
            Some(judge.score_sets(report::DIRECT, &[dirs], &progress))
        } else {
            None
        };
        results.push(ConditionResult::new(
            [roughness, theta],
            target.albedo(),
            methods,
            [exact, mixture],
            direct,
            diversities,
            examples,
        ));
    }
    progress.finish();
    Ok(ConditionalReport::new(
        settings,
        samplers.iter().map(|s| s.name().to_string()).collect(),
        n,
        results,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two conditions, no direct optimization: enough to check the figures.
    fn small() -> ConditionalSettings {
        let all = held_out_conditions();
        ConditionalSettings {
            conditions: vec![all[4], all[12]],
            direct: vec![],
            ..ConditionalSettings::quick()
        }
    }

    /// The same set for every instance: instance 0 of the calibration sampler.
    fn identical(n: usize) -> impl ConditionalSets {
        let base = MixtureOwenSobol::new(n, 77);
        SampleFnSets::new("identical", n, move |r, t, _k, i| {
            base.set(r, t, 0)[i as usize]
        })
    }

    #[test]
    fn held_out_conditions_avoid_uniform_grid_nodes() {
        // Distance to the nearest node of an n-node uniform grid over [lo, hi], in
        // cells.
        let off = |v: f64, lo: f64, hi: f64, n: usize| {
            let f = (v - lo) / (hi - lo) * (n - 1) as f64;
            (f - f.round()).abs()
        };
        for r in HELD_OUT_ROUGHNESS {
            for n in [10, 16] {
                assert!(off(r, 0.1, 1.0, n) >= 0.29, "roughness {r}, {n} nodes");
            }
        }
        for t in HELD_OUT_THETA_DEG {
            for (n, hi) in [(10, 89.0), (16, 89.0), (10, 90.0)] {
                assert!(off(t, 0.0, hi, n) >= 0.2, "theta {t}, {n} nodes to {hi}");
            }
        }
        assert_eq!(held_out_conditions()[DIRECT_CONDITIONS[0]], [0.13, 85.0]);
        assert_eq!(held_out_conditions()[DIRECT_CONDITIONS[4]], [0.85, 4.0]);
    }

    #[test]
    fn synthetic_samplers_give_the_reference_figures_at_any_thread_count() {
        let s = small();
        let calibration = MixtureOwenSobol::new(64, 5);
        let same = identical(64);
        let samplers: [&dyn ConditionalSets; 2] = [&calibration, &same];
        let rep = evaluate(&samplers, &s).unwrap();
        let k = s.union_instances as f64;
        for c in &rep.conditions {
            // The calibration sampler is the mixture reference with other scrambles.
            let r = &c.ratios[0];
            assert!((0.75..1.33).contains(&r.to_mixture), "{r:?}");
            let d = c.diversity_of("calibration").unwrap();
            assert!((d.nn_ratio - 0.65).abs() < 0.1, "{d:?}");
            // Its union follows the mixture, not q: at or above 1/sqrt(K).
            assert!(
                d.union_ratio > 0.8 / k.sqrt() && d.union_ratio < 0.6,
                "{d:?}"
            );
            // Identical sets: union = one set, no distance between instances.
            let d = c.diversity_of("identical").unwrap();
            assert!((d.union_ratio - 1.0).abs() < 1e-12, "{d:?}");
            assert_eq!(d.nn_ratio, 0.0);
            // The exact reference's independent scrambles: about 1/sqrt(K).
            let d = c.diversity_of(report::EXACT).unwrap();
            assert!((d.union_ratio * k.sqrt() - 1.0).abs() < 0.25, "{d:?}");
            assert!((d.nn_ratio - 0.65).abs() < 0.1, "{d:?}");
            // Standard errors are positive and small against the values.
            for m in c.samplers.iter().chain([&c.exact, &c.mixture]) {
                assert!(m.cap_l2 > 0.0 && m.cap_l2_se > 0.0 && m.cap_l2_se < 0.3 * m.cap_l2);
                assert!(m.cap_star > 0.0 && m.cap_star < 1.0);
            }
        }
        assert_eq!(rep.summary[2].sampler, report::EXACT);
        assert_eq!(rep.summary[2].mean_ratio_exact, 1.0);
        // Bit for bit on one thread.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| evaluate(&samplers, &s).unwrap());
        assert_eq!(
            serde_json::to_string(&rep).unwrap(),
            serde_json::to_string(&one).unwrap()
        );
    }
}
