//! The metrics of one direction set against one target, as `optimize` and
//! `metrics` report them for the sphere and hemisphere domains.

use super::aggregate::Summary;
use crate::sphere::{
    cap_l2_uniform, cap_star_estimate_screened, root_with_stderr, CapMeasureTable, CapRadius,
    CapStarOptions, DirectionDensity, EnergyReference, MeasuredCaps,
};
use glam::DVec3;
use serde::Serialize;

/// Spherical cap discrepancies of a direction set (square roots).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CapMetricSummary {
    /// L2 cap discrepancy with `t = cos theta` uniform (docs/metrics.md): Stolarsky's
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
pub const TABLE_POINTS: usize = 1 << 16;
/// Whether Stolarsky's closed form gives the cap L2 discrepancy of `density`.
fn stolarsky(density: &dyn DirectionDensity) -> bool {
    density.spec() == "uniform" && density.domain() == nuld_core::blob::Domain::Sphere
}

/// Random caps (before refinement) for the cap star estimate.
pub const STAR_CAPS: usize = 20_000;

/// A direction target prepared for evaluation: what does not depend on the set is
/// computed once and reused for every set: the target side of the energy form, and
/// the random caps of the theta-uniform estimate and of the cap star search with
/// their measures (closed forms, or for targets without them the
/// [`TABLE_POINTS`]-point cap-measure table of the target's rule).
pub struct CapTarget<'a> {
    density: &'a dyn DirectionDensity,
    tabulated: bool,
    energy: Option<EnergyReference>,
    theta_caps: MeasuredCaps,
    star_caps: MeasuredCaps,
}

/// Seed of the theta-uniform estimate's caps.
const THETA_SEED: u64 = 0x7e7a;
/// Seed of the cap star search.
const STAR_SEED: u64 = 0x57a2;

impl<'a> CapTarget<'a> {
    /// Prepares `density`: its energy reference unless Stolarsky's closed form
    /// applies, and the measures of [`THETA_CAPS`] + [`STAR_CAPS`] random caps.
    pub fn new(density: &'a dyn DirectionDensity) -> Self {
        let table = (!density.has_closed_form_caps())
            .then(|| CapMeasureTable::new(&density.quadrature(TABLE_POINTS)));
        let measure = |w: DVec3, t: f64| match &table {
            Some(table) => table.measure(w, t),
            None => density.cap_measure(w, t),
        };
        let energy =
            (!stolarsky(density)).then(|| EnergyReference::new(density, CAP_QUADRATURE_POINTS));
        Self {
            density,
            tabulated: table.is_some(),
            energy,
            theta_caps: MeasuredCaps::draw(
                THETA_CAPS,
                THETA_SEED,
                CapRadius::ThetaUniform,
                measure,
            ),
            star_caps: MeasuredCaps::draw(STAR_CAPS, STAR_SEED, CapRadius::ThetaUniform, measure),
        }
    }

    /// The metrics of `points`, all on the same caps for every set.
    pub fn evaluate(&self, points: &[DVec3]) -> CapMetricSummary {
        let cap_l2 = match &self.energy {
            None => cap_l2_uniform(points),
            Some(energy) => energy.cap_l2(points),
        };
        let (d2, se2) = self.theta_caps.l2_squared(points, CapRadius::ThetaUniform);
        let (theta, se) = root_with_stderr(d2, se2);
        let options = CapStarOptions {
            random_caps: STAR_CAPS,
            ..CapStarOptions::default()
        };
        let star =
            cap_star_estimate_screened(points, self.density, &self.star_caps, &options, STAR_SEED);
        CapMetricSummary {
            cap_l2,
            cap_l2_theta: theta,
            cap_l2_theta_stderr: se,
            cap_star_lower_bound: star.lower_bound,
        }
    }

    /// One line saying how [`CapTarget::evaluate`] computed its numbers.
    pub fn method(&self) -> String {
        let l2 = if self.energy.is_none() {
            "Stolarsky closed form".to_string()
        } else {
            format!("energy form with a {CAP_QUADRATURE_POINTS}-point quadrature of the target")
        };
        let theta = if !self.tabulated {
            "closed-form cap measures".to_string()
        } else {
            format!("cap measures from a {TABLE_POINTS}-point quadrature table")
        };
        format!(
            "cap_l2: t = cos(theta) uniform, {l2}; cap_l2_theta: paper's Eq. 9, {THETA_CAPS} random caps, {theta}; \
             cap_star_lower_bound: max over {STAR_CAPS} random caps plus local refinement, exact cap measures"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::{cap_l2_theta_uniform_estimate, cap_star_estimate, parse_direction_spec};
    use glam::DVec2;
    use nuld_core::blob::Domain;
    use nuld_core::sphere::square_to_sphere;

    /// With the point-independent caps measured once, every set gets bit for bit the
    /// estimates that measure each cap as it is drawn.
    #[test]
    fn caps_measured_once_give_the_per_set_estimates() {
        for spec in ["uniform", "brdf:0.5,30"] {
            let density = parse_direction_spec(spec, Domain::Sphere).unwrap();
            let target = CapTarget::new(density.as_ref());
            assert_eq!(target.tabulated, spec != "uniform");
            assert_eq!(
                (target.theta_caps.len(), target.star_caps.len()),
                (THETA_CAPS, STAR_CAPS)
            );
            let table = target
                .tabulated
                .then(|| CapMeasureTable::new(&density.quadrature(TABLE_POINTS)));
            for seed in 0..2 {
                // An Owen-scrambled Sobol set (sobol_burley), mapped to the sphere.
                let points: Vec<DVec3> = (0..64)
                    .map(|i| {
                        let u = |d| sobol_burley::sample(i, d, seed) as f64;
                        square_to_sphere(DVec2::new(u(0), u(1)))
                    })
                    .collect();
                let theta = match &table {
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
                if spec == "uniform" {
                    assert_eq!(m.cap_star_lower_bound, star.lower_bound, "{spec}");
                } else {
                    // Screened by the table, the leaders and the refined caps scored
                    // exactly: the same search up to which leaders the table picks.
                    let rel = (m.cap_star_lower_bound / star.lower_bound - 1.0).abs();
                    assert!(
                        rel < 0.05,
                        "{spec}: {} vs {}",
                        m.cap_star_lower_bound,
                        star.lower_bound
                    );
                }
            }
        }
    }
}
