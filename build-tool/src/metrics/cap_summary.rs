//! The metrics of one direction set against one target, as `optimize` and
//! `metrics` report them for the sphere and hemisphere domains.

use super::aggregate::Summary;
use crate::sphere::{
    cap_l2_for_density, cap_l2_theta_uniform_estimate, cap_l2_uniform, cap_star_estimate,
    CapMeasureTable, DirectionDensity,
};
use glam::DVec3;
use serde::Serialize;

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

/// A direction target prepared for evaluation: the cap-measure table of a target
/// without closed-form cap measures is built once and reused for every set.
pub struct CapTarget<'a> {
    density: &'a dyn DirectionDensity,
    table: Option<CapMeasureTable>,
}

impl<'a> CapTarget<'a> {
    /// Prepares `density` (builds its [`TABLE_POINTS`]-point table if needed).
    pub fn new(density: &'a dyn DirectionDensity) -> Self {
        let table = (!density.has_closed_form_caps())
            .then(|| CapMeasureTable::new(&density.quadrature(TABLE_POINTS)));
        Self { density, table }
    }

    fn stolarsky(&self) -> bool {
        self.density.spec() == "uniform" && self.density.domain() == nuld_core::blob::Domain::Sphere
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
        let (theta, se) = match &self.table {
            None => cap_l2_theta_uniform_estimate(
                points,
                |c, t| density.cap_measure(c, t),
                THETA_CAPS,
                0x7e7a,
            ),
            Some(table) => cap_l2_theta_uniform_estimate(
                points,
                |c, t| table.measure(c, t),
                THETA_CAPS,
                0x7e7a,
            ),
        };
        CapMetricSummary {
            cap_l2,
            cap_l2_theta: theta,
            cap_l2_theta_stderr: se,
            cap_star_lower_bound: cap_star_estimate(points, density, STAR_CAPS, 0x57a2).lower_bound,
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
