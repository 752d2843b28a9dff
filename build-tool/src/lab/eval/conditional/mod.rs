//! Quality report of a conditional BRDF sampler (paper §4) on held-out conditions:
//! `build-tool eval conditional`.
//!
//! At each condition `(roughness, theta_o, metallic)`, a held-out
//! `(roughness, theta_o)` grid crossed with a list of metallic values, the target is
//! the glTF metallic-roughness BRDF's `q(l) = f cos / A` ([`BrdfTarget::metallic`]);
//! every sampler under test (a
//! [`ConditionalSets`]: table mode, network mode) and three references give sets
//! of the sampler's `N` directions:
//!
//! * **exact**: Owen-scrambled Sobol points warped by the exact tabulated inverse
//!   CDF of `q` ([`TabulatedWarp`]), one scramble per instance;
//! * **mixture**: the same points warped the way a renderer does
//!   ([`BrdfTarget::sample`]: GGX VNDF with probability `A_spec / A` of the
//!   metallic's BRDF, else cosine);
//! * **direct**: one set optimized for this one condition by the direction
//!   optimizer ([`optimize_directions_scheduled`], paper §3.5), at a few
//!   `(roughness, theta_o)` for the dielectric and for the metal
//!   ([`DIRECT_METALLIC`]; 5000 epochs cost about 17 s each at `N = 64` on 2
//!   cores, most of a full run).
//!
//! Each set is scored by its cap L2 discrepancy (paper Eq. 9, theta-uniform random
//! caps, with its Monte Carlo standard error; [`MeasuredCaps`]) and by the largest
//! local discrepancy found ([`cap_star_estimate_screened`], a lower bound of the cap
//! star discrepancy). The target's cap measures are computed once per condition
//! and shared by every set. Scores are means over `instances` instances; ratios are
//! the sampler's mean over a reference's mean, summarized over all conditions and
//! per metallic value. [`diversity()`] measures whether the instances are
//! different sets.
//!
//! Deterministic for a seed whatever the thread count: every random stream is
//! `derive_seed` of the condition's seed ([`condition_seed`]: the run seed and the
//! condition's own values, so a condition scores the same whatever else the list
//! holds) and a fixed stream number, and every parallel reduction runs in a fixed
//! order.

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
/// Metallic values judged unless asked otherwise (`--metallic`): the dielectric
/// and the metal, the ends of glTF's metallic and the values with direct
/// optimization, and the half blend between them (25 conditions more without
/// direct optimization: about a fifth of the run).
pub const DEFAULT_METALLIC: [f64; 3] = [0.0, 0.5, 1.0];
/// Metallic values whose conditions get direct optimization, where listed: the
/// dielectric and the metal, each its own material's reference (a blend in
/// between is a mixture of the two BRDFs).
pub const DIRECT_METALLIC: [f64; 2] = [0.0, 1.0];

/// The held-out grid, roughness-major: condition `5 i + j` is
/// `(HELD_OUT_ROUGHNESS[i], HELD_OUT_THETA_DEG[j])`.
pub fn held_out_conditions() -> Vec<[f64; 2]> {
    HELD_OUT_ROUGHNESS
        .iter()
        .flat_map(|&r| HELD_OUT_THETA_DEG.iter().map(move |&t| [r, t]))
        .collect()
}

/// `pairs` of `[roughness, theta_o_deg]` crossed with `metallic`, metallic-major:
/// condition `k * pairs.len() + i` is `[pairs[i][0], pairs[i][1], metallic[k]]`
/// (so with metallic 0 first, the first `pairs.len()` conditions are the
/// dielectric's, at the pairs' own indices).
pub fn cross_metallic(pairs: &[[f64; 2]], metallic: &[f64]) -> Vec<[f64; 3]> {
    metallic
        .iter()
        .flat_map(|&m| pairs.iter().map(move |&[r, t]| [r, t, m]))
        .collect()
}

/// Indices into [`cross_metallic`]`(pairs, metallic)` (`pairs` of them per
/// metallic value) of the pairs `direct_pairs` at each metallic value of
/// [`DIRECT_METALLIC`] that `metallic` lists, in the list's order.
pub fn direct_indices(pairs: usize, direct_pairs: &[usize], metallic: &[f64]) -> Vec<usize> {
    metallic
        .iter()
        .enumerate()
        .filter(|(_, m)| DIRECT_METALLIC.contains(m))
        .flat_map(|(k, _)| direct_pairs.iter().map(move |&i| k * pairs + i))
        .collect()
}

/// Base seed of the report.
pub const CONDITIONAL_SEED: u64 = 0xC0_4D17;

/// What a report run evaluates and how hard it looks.
#[derive(Clone, Debug, Serialize)]
pub struct ConditionalSettings {
    /// Conditions `[roughness, theta_o_deg, metallic]`.
    pub conditions: Vec<[f64; 3]>,
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
    /// The full report: the 5x5 held-out grid crossed with `metallic`
    /// ([`cross_metallic`]), 8 instances, 64 for diversity, 4096 cap L2 caps, 20000
    /// search caps with 8 refined over 8 rounds, direct optimization (5000 epochs)
    /// at [`DIRECT_CONDITIONS`] for each metallic of [`DIRECT_METALLIC`] listed, a
    /// 1024-square tabulation with 2x2 midpoints per cell.
    pub fn full(metallic: &[f64]) -> Self {
        let pairs = held_out_conditions();
        Self {
            conditions: cross_metallic(&pairs, metallic),
            instances: 8,
            union_instances: 64,
            cap_l2_caps: 4096,
            cap_star_caps: 20_000,
            cap_star_refine: 8,
            cap_star_rounds: 8,
            direct: direct_indices(pairs.len(), &DIRECT_CONDITIONS, metallic),
            direct_epochs: 5000,
            tabulation: 1024,
            tabulation_subsamples: 2,
            seed: CONDITIONAL_SEED,
            quick: false,
        }
    }

    /// The `--quick` settings: three `(roughness, theta_o)` of the grid (the
    /// sharpest, the middle, the broadest) crossed with `metallic`, 8 instances, 16
    /// for diversity, 512 / 500 caps, 2 refined over 3 rounds, direct optimization
    /// (100 epochs) at the sharpest for each metallic of [`DIRECT_METALLIC`]
    /// listed, a 512-square tabulation.
    pub fn quick(metallic: &[f64]) -> Self {
        let all = held_out_conditions();
        let pairs = [all[4], all[12], all[20]];
        Self {
            conditions: cross_metallic(&pairs, metallic),
            union_instances: 16,
            cap_l2_caps: 512,
            cap_star_caps: 500,
            cap_star_refine: 2,
            cap_star_rounds: 3,
            direct: direct_indices(pairs.len(), &[0], metallic),
            direct_epochs: 100,
            tabulation: 512,
            quick: true,
            ..Self::full(metallic)
        }
    }

    /// Checks the settings: conditions in range and distinct, at least one
    /// instance, two for diversity, positive effort, direct indices in range.
    pub fn validate(&self) -> Result<()> {
        ensure!(!self.conditions.is_empty(), "no conditions to evaluate");
        for (i, &[r, t, m]) in self.conditions.iter().enumerate() {
            ensure!(
                (0.1..=1.0).contains(&r) && (0.0..=89.0).contains(&t) && (0.0..=1.0).contains(&m),
                "condition ({r}, {t}, {m}) is outside roughness [0.1, 1] x theta_o [0, 89] x metallic [0, 1]"
            );
            ensure!(
                !self.conditions[..i].contains(&[r, t, m]),
                "condition ({r}, {t}, {m}) is listed twice (a metallic value repeated?)"
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

/// The seed of condition `c = (roughness, theta_o, metallic)` under run seed
/// `seed`: [`derive_seed`] chained over the bits of each value. It depends on
/// the condition alone, not on its place in the list, so adding or reordering
/// conditions (`--metallic 1` against `--metallic 0,0.5,1`) leaves every other
/// condition's caps, scrambles and direct optimization as they were.
pub fn condition_seed(seed: u64, c: [f64; 3]) -> u64 {
    c.iter().fold(seed, |s, v| derive_seed(s, v.to_bits()))
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
    for (ci, &[roughness, theta, metallic]) in settings.conditions.iter().enumerate() {
        progress.set_context(format!(
            "roughness {roughness}, theta_o {theta}, metallic {metallic}"
        ));
        let cond_seed = condition_seed(settings.seed, [roughness, theta, metallic]);
        let target = BrdfTarget::metallic(roughness, theta, metallic, Domain::Hemisphere)?;
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
                .map(|k| s.set(roughness, theta, metallic, k))
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
            [roughness, theta, metallic],
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

    /// Two conditions at each of `metallic`, no direct optimization: enough to
    /// check the figures.
    fn small(metallic: &[f64]) -> ConditionalSettings {
        let all = held_out_conditions();
        ConditionalSettings {
            conditions: cross_metallic(&[all[4], all[12]], metallic),
            direct: vec![],
            ..ConditionalSettings::quick(metallic)
        }
    }

    /// A sampler from a whole-set function `f(roughness, theta_o_deg, metallic,
    /// instance)`.
    struct SetFn<F>(&'static str, usize, F);

    impl<F: Fn(f64, f64, f64, u32) -> Vec<DVec3> + Sync> ConditionalSets for SetFn<F> {
        fn name(&self) -> &str {
            self.0
        }
        fn len(&self) -> usize {
            self.1
        }
        fn set(&self, r: f64, t: f64, m: f64, instance: u32) -> Vec<DVec3> {
            (self.2)(r, t, m, instance)
        }
    }

    /// The same set for every instance: instance 0 of the calibration sampler.
    fn identical(n: usize) -> impl ConditionalSets {
        let base = MixtureOwenSobol::new(n, 77);
        SetFn("identical", n, move |r, t, m, _k| base.set(r, t, m, 0))
    }

    #[test]
    fn metallic_crosses_the_grid_and_direct_runs_at_the_dielectric_and_the_metal() {
        let pairs = held_out_conditions();
        let c = cross_metallic(&pairs, &[0.0, 0.5, 1.0]);
        assert_eq!(c.len(), 75);
        // Metallic-major: the dielectric keeps the pairs' own indices.
        assert_eq!(c[DIRECT_CONDITIONS[0]], [0.13, 85.0, 0.0]);
        assert_eq!(c[25 + 7], [pairs[7][0], pairs[7][1], 0.5]);
        assert_eq!(c[50 + DIRECT_CONDITIONS[4]], [0.85, 4.0, 1.0]);
        let full = ConditionalSettings::full(&[0.0, 0.5, 1.0]);
        let direct: Vec<[f64; 3]> = full.direct.iter().map(|&i| full.conditions[i]).collect();
        assert_eq!(direct.len(), 10);
        for (k, &i) in DIRECT_CONDITIONS.iter().enumerate() {
            let [r, t] = pairs[i];
            assert_eq!(direct[k], [r, t, 0.0]);
            assert_eq!(direct[5 + k], [r, t, 1.0]);
        }
        // Without 0 or 1 in the list, no direct optimization; --quick at the sharpest.
        assert!(ConditionalSettings::full(&[0.25, 0.5]).direct.is_empty());
        let quick = ConditionalSettings::quick(&[1.0, 0.5]);
        assert_eq!(quick.conditions.len(), 6);
        assert_eq!(quick.direct, vec![0]);
        assert_eq!(quick.conditions[0], [0.13, 85.0, 1.0]);
        quick.validate().unwrap();
        // A repeated metallic value, one out of range: one-line errors.
        for (bad, says) in [
            (vec![0.0, 0.0], "listed twice"),
            (vec![1.5], "metallic [0, 1]"),
        ] {
            let e = ConditionalSettings::quick(&bad)
                .validate()
                .unwrap_err()
                .to_string();
            assert!(e.contains(says) && !e.contains('\n'), "{e}");
        }
    }

    /// The judge's target at a metal condition is the metal's: Owen-Sobol through
    /// the exact tabulated inverse CDF of `BrdfTarget::metallic(r, t, m)`, with the
    /// exact reference's own scrambles, scores exactly 1 at every metallic, while
    /// the same points through the dielectric's warp score 1 at metallic 0 only and
    /// well above it at the metal; the mixture reference differs between the two.
    #[test]
    fn a_metal_condition_is_judged_against_the_metal_target() {
        let s = small(&[0.0, 1.0]);
        let n = 64;
        let warp = |c: [f64; 3]| {
            let target = BrdfTarget::metallic(c[0], c[1], c[2], Domain::Hemisphere).unwrap();
            TabulatedWarp::new(&target, s.tabulation, s.tabulation_subsamples).unwrap()
        };
        let own: Vec<TabulatedWarp> = s.conditions.iter().map(|&c| warp(c)).collect();
        let dielectric: Vec<TabulatedWarp> = s
            .conditions
            .iter()
            .map(|&[r, t, _]| warp([r, t, 0.0]))
            .collect();
        // Instance k at condition ci: the exact reference's scramble.
        let seed = s.seed;
        let conditions = s.conditions.clone();
        let through = move |warps: Vec<TabulatedWarp>| {
            let conditions = conditions.clone();
            move |r: f64, t: f64, m: f64, k: u32| {
                let ci = conditions.iter().position(|&c| c == [r, t, m]).unwrap();
                let u = seeded_owen_sobol(
                    n,
                    derive_seed(condition_seed(seed, [r, t, m]), SCRAMBLE_STREAM + k as u64),
                );
                warps[ci].warp_all(&u)
            }
        };
        let (own, dielectric) = (through(own), through(dielectric));
        let exact = SetFn("own", n, own);
        let wrong = SetFn("dielectric", n, dielectric);
        let rep = evaluate(&[&exact, &wrong], &s).unwrap();
        assert_eq!(rep.conditions.len(), 4);
        for (c, want) in rep.conditions.iter().zip(&s.conditions) {
            assert_eq!([c.roughness, c.theta_o_deg, c.metallic], *want);
            assert_eq!(c.ratios[0].to_exact, 1.0, "{want:?}");
            if c.metallic == 0.0 {
                assert_eq!(c.ratios[1].to_exact, 1.0, "{want:?}");
            } else {
                assert!(c.ratios[1].to_exact > 1.5, "{want:?}: {:?}", c.ratios[1]);
            }
        }
        // Same (roughness, theta_o), metallic 0 then 1: different mixtures.
        for i in 0..2 {
            let (d, m) = (&rep.conditions[i], &rep.conditions[2 + i]);
            assert_ne!(d.mixture.cap_l2, m.mixture.cap_l2);
            assert_ne!(d.albedo, m.albedo);
        }
        // The per-metallic summary: the metal's worst is the dielectric warp's.
        assert_eq!(rep.by_metallic.len(), 2);
        let metal = &rep.by_metallic[1];
        assert_eq!((metal.metallic, metal.conditions), (1.0, 2));
        assert_eq!(metal.summary[0].mean_ratio_exact, 1.0);
        assert!(metal.summary[1].worst_ratio_exact > 1.5);
        assert_eq!(metal.summary[1].worst_condition[2], 1.0);
        assert_eq!(rep.by_metallic[0].summary[1].mean_ratio_exact, 1.0);
    }

    /// A condition scores the same alone as in a longer list: its seed is its
    /// own, not its place in the list (the metals come last in `[0, 1]`, first
    /// in `[1]`).
    #[test]
    fn a_condition_scores_the_same_whatever_the_list() {
        let calibration = MixtureOwenSobol::new(64, 5);
        let both = evaluate(&[&calibration], &small(&[0.0, 1.0])).unwrap();
        let metals = evaluate(&[&calibration], &small(&[1.0])).unwrap();
        assert_eq!(metals.conditions.len(), 2);
        for m in &metals.conditions {
            let b = both
                .conditions
                .iter()
                .find(|b| {
                    [b.roughness, b.theta_o_deg, b.metallic]
                        == [m.roughness, m.theta_o_deg, m.metallic]
                })
                .unwrap();
            assert_eq!(m.exact.cap_l2, b.exact.cap_l2);
            assert_eq!(m.mixture.cap_l2, b.mixture.cap_l2);
            assert_eq!(m.samplers[0].cap_l2, b.samplers[0].cap_l2);
        }
        // The seeds do differ between conditions.
        let s = small(&[0.0, 1.0]);
        let seeds: Vec<u64> = s
            .conditions
            .iter()
            .map(|&c| condition_seed(s.seed, c))
            .collect();
        for (i, a) in seeds.iter().enumerate() {
            assert!(seeds[i + 1..].iter().all(|b| b != a));
        }
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
        // The dielectric and the blend: at the metal the calibration sampler's
        // nearest-neighbour ratio runs higher than 0.65 (0.80 at roughness 0.13,
        // 85 degrees, pure VNDF).
        let s = small(&[0.0, 0.5]);
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
