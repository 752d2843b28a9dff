//! The metrics of one direction set against one target, as `optimize` and
//! `metrics` report them for the sphere and hemisphere domains.

use super::aggregate::Summary;
use crate::sphere::{
    cap_l2_for_density, cap_l2_theta_uniform_estimate, cap_l2_uniform, cap_star_estimate_with,
    CapMeasureTable, CapStarOptions, DirectionDensity,
};
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use rand::RngCore;
use serde::Serialize;
use std::collections::HashMap;
use std::sync::Mutex;

/// Spherical cap discrepancies of a direction set (square roots).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CapMetricSummary {
    /// L2 cap discrepancy with `t = cos theta` uniform (DESIGN.md §5): Stolarsky's
    /// closed form for the uniform sphere, the energy-distance form with the target's
    /// quadrature rule otherwise.
    pub cap_l2: f64,
    /// The paper's Eq. 9 (theta uniform in `[0, pi]`), Monte-Carlo estimate.
    pub cap_l2_theta: f64,
    /// Standard error of [`CapMetricSummary::cap_l2_theta`].
    pub cap_l2_theta_stderr: f64,
    /// Cap star discrepancy: the largest local discrepancy found over a large random
    /// cap set refined locally — a lower bound of the supremum.
    pub cap_star_lower_bound: f64,
}

impl Summary for CapMetricSummary {
    const LABELS: &'static [&'static str] = &["cap L2", "theta-unif", "cap D* >="];

    fn values(&self) -> Vec<f64> {
        vec![self.cap_l2, self.cap_l2_theta, self.cap_star_lower_bound]
    }

    /// Standard errors are combined as for a mean of independent estimates.
    fn mean(items: &[CapMetricSummary]) -> CapMetricSummary {
        let n = items.len().max(1) as f64;
        let avg = |f: fn(&CapMetricSummary) -> f64| items.iter().map(f).sum::<f64>() / n;
        CapMetricSummary {
            cap_l2: avg(|m| m.cap_l2),
            cap_l2_theta: avg(|m| m.cap_l2_theta),
            cap_l2_theta_stderr: items
                .iter()
                .map(|m| m.cap_l2_theta_stderr.powi(2))
                .sum::<f64>()
                .sqrt()
                / n,
            cap_star_lower_bound: avg(|m| m.cap_star_lower_bound),
        }
    }

    fn ratio(&self, baseline: &CapMetricSummary) -> CapMetricSummary {
        CapMetricSummary {
            cap_l2: self.cap_l2 / baseline.cap_l2,
            cap_l2_theta: self.cap_l2_theta / baseline.cap_l2_theta,
            cap_l2_theta_stderr: f64::NAN,
            cap_star_lower_bound: self.cap_star_lower_bound / baseline.cap_star_lower_bound,
        }
    }
}

/// Quadrature points used for non-uniform cap L2 metrics.
pub const CAP_QUADRATURE_POINTS: usize = 128 * 128;
/// Random caps for the theta-uniform estimate.
pub const THETA_CAPS: usize = 100_000;
/// Quadrature points of the cap-measure table used by the theta-uniform estimate for
/// targets without closed-form cap measures (brdf, envmap).
pub const TABLE_POINTS: usize = 1 << 18;
/// Random caps (before refinement) for the cap star estimate.
pub const STAR_CAPS: usize = 20_000;

/// The cap star search: [`STAR_CAPS`] random caps, refined as by default.
fn star_options() -> CapStarOptions {
    CapStarOptions {
        random_caps: STAR_CAPS,
        ..CapStarOptions::default()
    }
}

/// Seed of the theta-uniform estimate's caps: every set is measured on the same caps.
const THETA_SEED: u64 = 0x7e7a;
/// Seed of the cap star estimate's caps.
const STAR_SEED: u64 = 0x57a2;

/// A cap `C(center, cos_theta)` by the bits of its parameters (exact identity).
type CapKey = [u64; 4];

fn cap_key(center: DVec3, cos_theta: f64) -> CapKey {
    [
        center.x.to_bits(),
        center.y.to_bits(),
        center.z.to_bits(),
        cos_theta.to_bits(),
    ]
}

/// A cap-measure function as the estimators take it.
type MeasureFn<'a> = dyn Fn(DVec3, f64) -> f64 + Sync + 'a;

/// Target measures of the caps an estimator draws whatever the points (its random
/// caps depend only on its seed), recorded once so that measuring another set
/// costs only the point counts. Values are those of the measure recorded, so
/// results are bit for bit those of measuring each cap as it is drawn.
#[derive(Default)]
struct KnownCaps(HashMap<CapKey, f64>);

impl KnownCaps {
    /// Runs `enumerate` with a measure that evaluates `measure` and records every
    /// cap it is asked for.
    fn record(measure: &MeasureFn<'_>, enumerate: impl FnOnce(&MeasureFn<'_>)) -> Self {
        let seen = Mutex::new(Vec::new());
        enumerate(&|c, t| {
            let m = measure(c, t);
            let mut seen = seen.lock().unwrap_or_else(|e| e.into_inner());
            seen.push((cap_key(c, t), m));
            m
        });
        Self(
            seen.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .into_iter()
                .collect(),
        )
    }

    /// The recorded measure of `C(c, t)`, else `measure(c, t)`.
    fn measure(&self, c: DVec3, t: f64, measure: &MeasureFn<'_>) -> f64 {
        self.0
            .get(&cap_key(c, t))
            .copied()
            .unwrap_or_else(|| measure(c, t))
    }
}

/// `density` with its cap measures taken from `measure`; everything else forwarded.
struct MeasuredBy<'a> {
    density: &'a dyn DirectionDensity,
    measure: &'a MeasureFn<'a>,
}

impl DirectionDensity for MeasuredBy<'_> {
    fn spec(&self) -> String {
        self.density.spec()
    }
    fn domain(&self) -> Domain {
        self.density.domain()
    }
    fn pdf(&self, w: DVec3) -> f64 {
        self.density.pdf(w)
    }
    fn sample(&self, u: DVec2) -> DVec3 {
        self.density.sample(u)
    }
    fn sample_target(&self, rng: &mut dyn RngCore) -> DVec3 {
        self.density.sample_target(rng)
    }
    fn has_closed_form_caps(&self) -> bool {
        self.density.has_closed_form_caps()
    }
    fn cap_measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        (self.measure)(center, cos_theta)
    }
    fn cap_measure_profile(&self, center: DVec3, cos_thetas: &[f64]) -> Vec<f64> {
        self.density.cap_measure_profile(center, cos_thetas)
    }
    fn quadrature(&self, k: usize) -> Vec<(DVec3, f64)> {
        self.density.quadrature(k)
    }
}

/// A direction target prepared for evaluation, once for any number of sets: the
/// cap-measure table of a target without closed-form cap measures, and the target
/// measures of the caps both estimators draw whatever the points.
pub struct CapTarget<'a> {
    density: &'a dyn DirectionDensity,
    table: Option<CapMeasureTable>,
    /// The [`THETA_CAPS`] caps of the theta-uniform estimate.
    theta_caps: KnownCaps,
    /// The [`STAR_CAPS`] random caps of the cap star estimate (its refinement
    /// follows the points and is measured per set).
    star_caps: KnownCaps,
}

impl<'a> CapTarget<'a> {
    /// Prepares `density`: builds its [`TABLE_POINTS`]-point table if needed, and
    /// measures the estimators' point-independent caps (the cost of measuring
    /// about one set).
    pub fn new(density: &'a dyn DirectionDensity) -> Self {
        let table = (!density.has_closed_form_caps())
            .then(|| CapMeasureTable::new(&density.quadrature(TABLE_POINTS)));
        let mut target = Self {
            density,
            table,
            theta_caps: KnownCaps::default(),
            star_caps: KnownCaps::default(),
        };
        // Estimates of a one-point set, discarded: they enumerate the caps.
        let one = [DVec3::Z];
        target.theta_caps = KnownCaps::record(&|c, t| target.theta_measure(c, t), |m| {
            cap_l2_theta_uniform_estimate(&one, m, THETA_CAPS, THETA_SEED);
        });
        target.star_caps = KnownCaps::record(&|c, t| density.cap_measure(c, t), |m| {
            let random_only = CapStarOptions {
                refine: 0,
                ..star_options()
            };
            let by = MeasuredBy {
                density,
                measure: m,
            };
            cap_star_estimate_with(&one, &by, &random_only, STAR_SEED);
        });
        target
    }

    fn stolarsky(&self) -> bool {
        self.density.spec() == "uniform" && self.density.domain() == Domain::Sphere
    }

    /// `mu(C(center, cos_theta))` as the theta-uniform estimate takes it: closed
    /// form, or from the table.
    fn theta_measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        match &self.table {
            None => self.density.cap_measure(center, cos_theta),
            Some(table) => table.measure(center, cos_theta),
        }
    }

    /// The metrics of `points`, with fixed estimator seeds (so two sets are compared
    /// on the same caps).
    pub fn evaluate(&self, points: &[DVec3]) -> CapMetricSummary {
        let density = self.density;
        let cap_l2 = if self.stolarsky() {
            cap_l2_uniform(points)
        } else {
            cap_l2_for_density(points, density, CAP_QUADRATURE_POINTS)
        };
        let theta = |c, t| self.theta_measure(c, t);
        let (cap_l2_theta, cap_l2_theta_stderr) = cap_l2_theta_uniform_estimate(
            points,
            |c, t| self.theta_caps.measure(c, t, &theta),
            THETA_CAPS,
            THETA_SEED,
        );
        let exact = |c, t| density.cap_measure(c, t);
        let star_measure = |c, t| self.star_caps.measure(c, t, &exact);
        let by = MeasuredBy {
            density,
            measure: &star_measure,
        };
        CapMetricSummary {
            cap_l2,
            cap_l2_theta,
            cap_l2_theta_stderr,
            cap_star_lower_bound: cap_star_estimate_with(points, &by, &star_options(), STAR_SEED)
                .lower_bound,
        }
    }

    /// One line saying how [`CapTarget::evaluate`] computed its numbers.
    pub fn method(&self) -> String {
        let l2 = if self.stolarsky() {
            "Stolarsky closed form".to_string()
        } else {
            format!("energy form with a {CAP_QUADRATURE_POINTS}-point quadrature of the target")
        };
        let theta = if self.table.is_none() {
            "closed-form cap measures".to_string()
        } else {
            format!("cap measures from a {TABLE_POINTS}-point quadrature table")
        };
        format!(
            "cap_l2: t = cos(theta) uniform, {l2}; cap_l2_theta: paper's Eq. 9, {THETA_CAPS} random caps, {theta}; \
             cap_star_lower_bound: max over {STAR_CAPS} random caps plus local refinement"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baselines::owen_sobol;
    use crate::sphere::{cap_star_estimate, parse_direction_spec};
    use nuld_core::sphere::square_to_sphere;

    /// With the point-independent caps measured once, every set gets bit for bit the
    /// estimates that measure each cap as it is drawn.
    #[test]
    fn caps_measured_once_give_the_per_set_estimates() {
        for spec in ["uniform", "brdf:0.5,30"] {
            let density = parse_direction_spec(spec, Domain::Sphere).unwrap();
            let target = CapTarget::new(density.as_ref());
            assert_eq!(target.table.is_some(), spec != "uniform");
            assert_eq!(
                (target.theta_caps.0.len(), target.star_caps.0.len()),
                (THETA_CAPS, STAR_CAPS)
            );
            for seed in 0..2 {
                let points: Vec<DVec3> = owen_sobol(64, seed)
                    .into_iter()
                    .map(square_to_sphere)
                    .collect();
                let theta = match &target.table {
                    None => cap_l2_theta_uniform_estimate(
                        &points,
                        |c, t| density.cap_measure(c, t),
                        THETA_CAPS,
                        THETA_SEED,
                    ),
                    Some(table) => cap_l2_theta_uniform_estimate(
                        &points,
                        |c, t| table.measure(c, t),
                        THETA_CAPS,
                        THETA_SEED,
                    ),
                };
                let star = cap_star_estimate(&points, density.as_ref(), STAR_CAPS, STAR_SEED);
                let m = target.evaluate(&points);
                assert_eq!((m.cap_l2_theta, m.cap_l2_theta_stderr), theta, "{spec}");
                assert_eq!(m.cap_star_lower_bound, star.lower_bound, "{spec}");
            }
        }
    }
}
