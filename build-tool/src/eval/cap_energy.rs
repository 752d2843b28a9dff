//! The non-uniform spherical cap L2 discrepancy of many point sets against one
//! target, with the target-only term computed once.
//!
//! [`crate::sphere::cap_l2_nonuniform`] evaluates the energy-distance form
//! `D^2 = (1/4)[(2/N) sum_i ∫|x_i - y| dmu(y) - ∫∫|x - y| dmu dmu - (1/N^2) sum_{j,k} |x_j - x_k|]`
//! in `O(N^2 + N K + K^2)` for a rule of `K` points; the `K^2` term does not depend
//! on the points, and with the large rules the figures need (`K = 65536`, about
//! `2 * 10^9` distances) recomputing it for every set would dominate. This type
//! keeps it, so each set costs `O(N^2 + N K)`. Tested against
//! [`crate::sphere::cap_l2_nonuniform`].

use crate::sphere::DirectionDensity;
use glam::DVec3;
use rayon::prelude::*;

/// Rows of the pair sums handled per parallel task (fixed, so that sums are
/// combined in the same order whatever the thread count).
const ROWS: usize = 64;

/// The target side of the cos-uniform cap L2 discrepancy (see the module docs).
pub struct CapL2Energy {
    rule: Vec<(DVec3, f64)>,
    /// `∫∫ |x - y| dmu dmu` by the rule.
    self_term: f64,
}

/// `sum_j sum_k w_j w_k |y_j - y_k|` over a weighted rule, or with unit weights.
fn pair_sum(y: &[(DVec3, f64)]) -> f64 {
    let parts: Vec<f64> = (0..y.len().div_ceil(ROWS))
        .into_par_iter()
        .map(|c| {
            let mut s = 0.0;
            for j in c * ROWS..((c + 1) * ROWS).min(y.len()) {
                let (a, wa) = y[j];
                s += wa
                    * y[j + 1..]
                        .iter()
                        .map(|(b, wb)| wb * (a - *b).length())
                        .sum::<f64>();
            }
            s
        })
        .collect();
    2.0 * parts.iter().sum::<f64>()
}

impl CapL2Energy {
    /// Prepares `density`'s quadrature rule of about `k` points
    /// ([`DirectionDensity::quadrature`]) and its self term (`O(K^2)`, parallel).
    pub fn new(density: &dyn DirectionDensity, k: usize) -> Self {
        let rule = density.quadrature(k);
        let self_term = pair_sum(&rule);
        Self { rule, self_term }
    }

    /// Number of points of the rule.
    pub fn rule_len(&self) -> usize {
        self.rule.len()
    }

    /// Squared cos-uniform cap L2 discrepancy of unit vectors `points` (0 for an
    /// empty set). `O(N^2 + N K)`, parallel, deterministic.
    pub fn squared(&self, points: &[DVec3]) -> f64 {
        if points.is_empty() {
            return 0.0;
        }
        let n = points.len() as f64;
        let cross: Vec<f64> = points
            .par_chunks(ROWS)
            .map(|c| {
                c.iter()
                    .map(|a| {
                        self.rule
                            .iter()
                            .map(|(b, w)| w * (*a - *b).length())
                            .sum::<f64>()
                    })
                    .sum::<f64>()
            })
            .collect();
        let cross = cross.iter().sum::<f64>() / n;
        let unit: Vec<(DVec3, f64)> = points.iter().map(|p| (*p, 1.0)).collect();
        let own = pair_sum(&unit) / (n * n);
        0.25 * (2.0 * cross - self.self_term - own)
    }

    /// The discrepancy: `sqrt` of [`CapL2Energy::squared`], clamped at 0.
    pub fn value(&self, points: &[DVec3]) -> f64 {
        self.squared(points).max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeding::rng;
    use crate::sphere::{cap_l2_nonuniform, cap_l2_uniform, parse_direction_spec};
    use nuld_core::blob::Domain;

    #[test]
    fn matches_the_sphere_module_metric() {
        let d = parse_direction_spec("cosine", Domain::Hemisphere).unwrap();
        let e = CapL2Energy::new(d.as_ref(), 4096);
        let mut g = rng(1, 2);
        let pts: Vec<DVec3> = (0..300).map(|_| d.sample_target(&mut g)).collect();
        let rule = d.quadrature(4096);
        assert_eq!(e.rule_len(), rule.len());
        let want = cap_l2_nonuniform(&pts, &rule);
        assert!(
            (e.value(&pts) - want).abs() < 1e-12 * want.max(1.0),
            "{} {want}",
            e.value(&pts)
        );
        // Uniform target: agrees with Stolarsky's closed form up to the rule's error.
        let u = parse_direction_spec("uniform", Domain::Sphere).unwrap();
        let eu = CapL2Energy::new(u.as_ref(), 16384);
        let pts: Vec<DVec3> = (0..200).map(|_| u.sample_target(&mut g)).collect();
        let (a, b) = (eu.squared(&pts), cap_l2_uniform(&pts).powi(2));
        assert!((a - b).abs() < 1e-6, "{a} {b}");
        assert_eq!(eu.squared(&[]), 0.0);
    }
}
#[cfg(test)]
mod probe {
    use super::*;
    use crate::sphere::parse_direction_spec;
    use nuld_core::blob::Domain;
    #[test]
    #[ignore]
    fn probe_rule_error() {
        for (spec, dom) in [("cosine", Domain::Hemisphere), ("brdf:0.3,45", Domain::Hemisphere), ("envmap:../../shared/data/envmaps/courtyard.hdr", Domain::Sphere)] {
            let d = parse_direction_spec(spec, dom).unwrap();
            let pts: Vec<DVec3> = crate::baselines::owen_sobol(4096, 3).iter().map(|u| d.sample(*u)).collect();
            for k in [16384, 65536] {
                let t = std::time::Instant::now();
                let e = CapL2Energy::new(d.as_ref(), k);
                let t1 = t.elapsed().as_secs_f64();
                let t = std::time::Instant::now();
                let v = e.value(&pts);
                eprintln!("{spec} K={k}: D={v:.6e} build {t1:.2}s eval {:.2}s", t.elapsed().as_secs_f64());
            }
        }
    }
}
