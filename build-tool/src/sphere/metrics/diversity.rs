//! Instance diversity of a conditional sampler at one condition: whether different
//! instances are different sets, as independently randomized sets are (a renderer
//! gives each pixel its own instance, and pixel errors average out only if they are
//! independent).
//!
//! * **Union ratio**: the cap L2 discrepancy of the union of `K` instances (`K N`
//!   points) divided by the mean cap L2 of a single instance. For independent
//!   randomizations of an unbiased set the squared discrepancy of the union is the
//!   mean of the single ones over `K` (cross terms vanish in expectation), so the
//!   ratio is about `1/sqrt(K)` (`1/8` for 64 instances); identical sets give 1.
//! * **Nearest-neighbour ratio**: the mean angle from a point of instance `k` to
//!   its nearest point of instance `k + 1`, divided by the mean angle from a point
//!   to its nearest other point of the same instance; over the pairs
//!   `(0, 1), (1, 2), ..., (K-2, K-1)`. Independent Owen-Sobol sets give about 0.65;
//!   identical sets give 0.

use super::cap_l2::{root_with_stderr, CapRadius, MeasuredCaps};
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

/// Diversity figures of `K` instances at one condition (module docs).
#[derive(Clone, Debug, Serialize)]
pub struct Diversity {
    /// Instances compared, `K`.
    pub instances: usize,
    /// Cap L2 (theta-uniform) of the union of the `K` instances.
    pub union_cap_l2: f64,
    /// Mean cap L2 of one instance.
    pub single_cap_l2: f64,
    /// `union_cap_l2 / single_cap_l2`.
    pub union_ratio: f64,
    /// Mean nearest-neighbour angle (radians) from instance `k` to `k + 1`.
    pub cross_nn_angle: f64,
    /// Mean nearest-neighbour angle (radians) within an instance.
    pub within_nn_angle: f64,
    /// `cross_nn_angle / within_nn_angle`.
    pub nn_ratio: f64,
}

/// Angle between unit vectors, robust near 0 and pi.
fn angle(a: DVec3, b: DVec3) -> f64 {
    (a - b).length().atan2((a + b).length()) * 2.0
}

/// Mean over `from` of the angle to the nearest point of `to`, skipping the point
/// at the same index when `skip_same` (a set against itself). `O(|from| |to|)`.
fn mean_nearest_angle(from: &[DVec3], to: &[DVec3], skip_same: bool) -> f64 {
    let total: f64 = from
        .iter()
        .enumerate()
        .map(|(i, &a)| {
            to.iter()
                .enumerate()
                .filter(|&(j, _)| !(skip_same && i == j))
                .map(|(_, &b)| angle(a, b))
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    total / from.len() as f64
}

/// The diversity of `sets` (at least two instances of at least two points each),
/// with cap L2 discrepancies measured on `caps` (drawn with
/// [`CapRadius::ThetaUniform`] against the condition's target). Deterministic
/// (fixed-order reductions).
///
/// # Panics
/// If there are fewer than two sets or a set has fewer than two points.
pub fn diversity(sets: &[Vec<DVec3>], caps: &MeasuredCaps) -> Diversity {
    assert!(
        sets.len() >= 2 && sets.iter().all(|s| s.len() >= 2),
        "diversity needs two or more sets of two or more points"
    );
    let k = sets.len();
    let l2 = |p: &[DVec3]| {
        let (d2, se2) = caps.l2_squared(p, CapRadius::ThetaUniform);
        root_with_stderr(d2, se2).0
    };
    let single_cap_l2 = sets.iter().map(|s| l2(s)).sum::<f64>() / k as f64;
    let union: Vec<DVec3> = sets.concat();
    let union_cap_l2 = l2(&union);
    let cross: Vec<f64> = sets
        .par_windows(2)
        .map(|w| mean_nearest_angle(&w[0], &w[1], false))
        .collect();
    let within: Vec<f64> = sets
        .par_iter()
        .map(|s| mean_nearest_angle(s, s, true))
        .collect();
    let cross_nn_angle = cross.iter().sum::<f64>() / cross.len() as f64;
    let within_nn_angle = within.iter().sum::<f64>() / within.len() as f64;
    Diversity {
        instances: k,
        union_cap_l2,
        single_cap_l2,
        union_ratio: union_cap_l2 / single_cap_l2,
        cross_nn_angle,
        within_nn_angle,
        nn_ratio: cross_nn_angle / within_nn_angle,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::{BrdfTarget, DirectionDensity, TabulatedWarp};
    use nuld_core::blob::Domain;

    /// `n` points of the Owen-scrambled Sobol set of scramble `seed` (sobol_burley).
    fn owen_sobol(n: u32, seed: u32) -> Vec<glam::DVec2> {
        (0..n)
            .map(|i| {
                let u = |d| sobol_burley::sample(i, d, seed) as f64;
                glam::DVec2::new(u(0), u(1))
            })
            .collect()
    }

    #[test]
    fn angle_is_the_arc_length() {
        let a = DVec3::new(1.0, 0.0, 0.0);
        for t in [0.0, 1e-9, 0.3, 2.0, std::f64::consts::PI] {
            let b = DVec3::new(t.cos(), t.sin(), 0.0);
            assert!((angle(a, b) - t).abs() < 1e-12, "{t}");
        }
    }

    /// Independent Owen-Sobol sets warped by the exact inverse CDF of the target,
    /// and one such set repeated: the two extremes the figures are defined by.
    #[test]
    fn independent_and_identical_sets_give_the_reference_values() {
        let b = BrdfTarget::new(0.44, 45.0, Domain::Hemisphere).unwrap();
        let warp = TabulatedWarp::new(&b, 512, 2).unwrap();
        let caps = MeasuredCaps::draw(4096, 3, CapRadius::ThetaUniform, |w, t| b.cap_measure(w, t));
        let independent: Vec<Vec<DVec3>> = (0..64)
            .map(|k| warp.warp_all(&owen_sobol(64, 1000 + k)))
            .collect();
        let d = diversity(&independent, &caps);
        eprintln!("independent: {d:?}");
        // 1/sqrt(64) = 0.125 up to the spread of 64 sets and the cap sample.
        assert!((d.union_ratio - 0.125).abs() < 0.03, "{d:?}");
        assert!((d.nn_ratio - 0.65).abs() < 0.08, "{d:?}");
        let identical = vec![independent[0].clone(); 64];
        let d = diversity(&identical, &caps);
        assert!((d.union_ratio - 1.0).abs() < 1e-12, "{d:?}");
        assert_eq!(d.nn_ratio, 0.0);
        assert_eq!(d.cross_nn_angle, 0.0);
    }
}
