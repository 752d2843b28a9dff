//! Cap L2 discrepancy: the closed forms of Stolarsky and of the energy distance,
//! and Monte Carlo over caps of a measured set (conventions: the parent module).

use crate::seeding::rng;
use crate::sphere::geometry::random_direction;
use crate::sphere::target::DirectionDensity;
use glam::DVec3;
use rand::Rng;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Caps per Monte Carlo chunk (each chunk has its own random stream).
const CAP_CHUNK: usize = 256;

/// `sum_{j,k} |x_j - x_k|` over all ordered pairs, `O(N^2)`, parallel over `j`.
fn self_distance_sum(x: &[DVec3]) -> f64 {
    let rows: Vec<f64> = (0..x.len())
        .into_par_iter()
        .map(|j| {
            let a = x[j];
            x[j + 1..].iter().map(|b| (a - *b).length()).sum::<f64>()
        })
        .collect();
    2.0 * rows.iter().sum::<f64>()
}

/// `sum_{j,k} w_j w_k |y_j - y_k|` over all ordered pairs of a weighted rule.
fn weighted_self_distance_sum(y: &[(DVec3, f64)]) -> f64 {
    let rows: Vec<f64> = (0..y.len())
        .into_par_iter()
        .map(|j| {
            let (a, wa) = y[j];
            wa * y[j + 1..]
                .iter()
                .map(|(b, wb)| wb * (a - *b).length())
                .sum::<f64>()
        })
        .collect();
    2.0 * rows.iter().sum::<f64>()
}

/// `sum_i sum_k w_k |x_i - y_k|`.
fn cross_distance_sum(x: &[DVec3], y: &[(DVec3, f64)]) -> f64 {
    let rows: Vec<f64> = x
        .par_iter()
        .map(|a| y.iter().map(|(b, w)| w * (*a - *b).length()).sum::<f64>())
        .collect();
    rows.iter().sum()
}

/// Squared cos-uniform cap L2 discrepancy against the uniform measure on the sphere,
/// by Stolarsky's invariance: `D^2 = (1/4)(4/3 - (1/N^2) sum_{j,k} |x_j - x_k|)`.
/// Points must be unit vectors. `O(N^2)`. 0 for an empty set.
pub fn cap_l2_uniform_squared(points: &[DVec3]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let n = points.len() as f64;
    0.25 * (4.0 / 3.0 - self_distance_sum(points) / (n * n))
}

/// Cos-uniform cap L2 discrepancy against the uniform measure on the sphere:
/// `sqrt` of [`cap_l2_uniform_squared`] (clamped at 0 against rounding).
pub fn cap_l2_uniform(points: &[DVec3]) -> f64 {
    cap_l2_uniform_squared(points).max(0.0).sqrt()
}

/// Squared cos-uniform cap L2 discrepancy against a general measure `mu`, by the
/// energy-distance form (docs/metrics.md):
/// `D^2 = (1/4)[(2/N) sum_i ∫|x_i - y| dmu(y) - ∫∫|x - y| dmu dmu - (1/N^2) sum_{j,k} |x_j - x_k|]`,
/// with the `mu`-integrals by the weighted rule `quadrature` (`(y_k, w_k)`, weights
/// summing to 1, e.g. [`DirectionDensity::quadrature`]). Cost
/// `O(N^2 + N K + K^2)`; `K` of 4096–16384 takes well under a second. The error is
/// that of the rule on the Lipschitz kernel `|x - y|` (for the equal-area midpoint
/// grid of `K` cells about `1e-7` in `D^2` at `K = 16384`, see the tests).
pub fn cap_l2_nonuniform_squared(points: &[DVec3], quadrature: &[(DVec3, f64)]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let n = points.len() as f64;
    energy_form(
        cross_distance_sum(points, quadrature) / n,
        weighted_self_distance_sum(quadrature),
        self_distance_sum(points) / (n * n),
    )
}

/// `D^2 = (1/4)(2 cross - target_self - set_self)` from the energy form's three
/// terms: `cross = (1/N) sum_i ∫|x_i - y| dmu`, `target_self = ∫∫|x - y| dmu dmu`,
/// `set_self = (1/N^2) sum_{j,k} |x_j - x_k|`.
fn energy_form(cross: f64, target_self: f64, set_self: f64) -> f64 {
    0.25 * (2.0 * cross - target_self - set_self)
}

/// Cos-uniform cap L2 discrepancy against a general measure: `sqrt` of
/// [`cap_l2_nonuniform_squared`] (clamped at 0).
pub fn cap_l2_nonuniform(points: &[DVec3], quadrature: &[(DVec3, f64)]) -> f64 {
    cap_l2_nonuniform_squared(points, quadrature)
        .max(0.0)
        .sqrt()
}

/// The target side of the energy form, computed once and shared by every set
/// evaluated against one target: two of the target's rules
/// ([`DirectionDensity::quadrature`], about `k` and `k/4` points) and their self
/// terms `∫∫|x - y| dmu dmu`, which cost `O(K^2)` and do not depend on the set.
///
/// [`EnergyReference::cap_l2_squared`] combines the two rules by Richardson
/// extrapolation. The energy form's error with a rule of `K` cells of size `h` is
/// dominated by the cells' self-distances, `∝ h / K ∝ K^{-3/2}` (about `1e-7` at
/// `K = 128^2` on the sphere), so with `K1 > K2` the actual rule lengths,
/// `D^2 ≈ (K1^{3/2} D^2(K1) - K2^{3/2} D^2(K2)) / (K1^{3/2} - K2^{3/2})`; for
/// Fibonacci sets of N = 256..4096 this brings the error from ~1e-7 to ~1e-8 or
/// below at `k = 128^2` (tests). The same law holds for rules whose points carry
/// equal mass rather than equal area (the `envmap` rule), where `h` is the local
/// cell size: concentrated light is resolved by many small cells.
pub struct EnergyReference {
    fine: Vec<(DVec3, f64)>,
    coarse: Vec<(DVec3, f64)>,
    fine_self: f64,
    coarse_self: f64,
}

impl EnergyReference {
    /// The rules of about `k` and `k/4` points of `density` and their self terms;
    /// cost about `1.06 k^2` distance evaluations (parallel).
    pub fn new(density: &dyn DirectionDensity, k: usize) -> Self {
        let fine = density.quadrature(k);
        let coarse = density.quadrature((k / 4).max(1));
        let fine_self = weighted_self_distance_sum(&fine);
        let coarse_self = weighted_self_distance_sum(&coarse);
        Self {
            fine,
            coarse,
            fine_self,
            coarse_self,
        }
    }

    /// Points of the finer rule.
    pub fn rule_len(&self) -> usize {
        self.fine.len()
    }

    /// Squared cos-uniform cap L2 discrepancy of `points` (unit vectors), the
    /// energy form of [`cap_l2_nonuniform_squared`] with both rules, extrapolated.
    /// `O(N^2 + N K)`. 0 for an empty set.
    pub fn cap_l2_squared(&self, points: &[DVec3]) -> f64 {
        if points.is_empty() {
            return 0.0;
        }
        let n = points.len() as f64;
        let set_self = self_distance_sum(points) / (n * n);
        let form = |rule: &[(DVec3, f64)], target_self: f64| {
            energy_form(cross_distance_sum(points, rule) / n, target_self, set_self)
        };
        let d1 = form(&self.fine, self.fine_self);
        let d2 = form(&self.coarse, self.coarse_self);
        let (k1, k2) = (
            (self.fine.len() as f64).powf(1.5),
            (self.coarse.len() as f64).powf(1.5),
        );
        if k1 > k2 {
            (k1 * d1 - k2 * d2) / (k1 - k2)
        } else {
            d1
        }
    }

    /// `sqrt` of [`EnergyReference::cap_l2_squared`] (clamped at 0).
    pub fn cap_l2(&self, points: &[DVec3]) -> f64 {
        self.cap_l2_squared(points).max(0.0).sqrt()
    }
}

/// Squared cos-uniform cap L2 discrepancy against `density`, from its own rules of
/// about `k` and `k/4` points, extrapolated ([`EnergyReference`], built for this one
/// set; build an [`EnergyReference`] once to evaluate many sets).
pub fn cap_l2_for_density_squared(
    points: &[DVec3],
    density: &dyn DirectionDensity,
    k: usize,
) -> f64 {
    EnergyReference::new(density, k).cap_l2_squared(points)
}

/// `sqrt` of [`cap_l2_for_density_squared`] (clamped at 0).
pub fn cap_l2_for_density(points: &[DVec3], density: &dyn DirectionDensity, k: usize) -> f64 {
    cap_l2_for_density_squared(points, density, k)
        .max(0.0)
        .sqrt()
}

/// How a Monte Carlo estimate draws cap radii.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CapRadius {
    /// `t = cos theta` uniform on `[-1, 1]`, integrated with `dt` (mass 2): the
    /// convention of [`cap_l2_uniform`] / [`cap_l2_nonuniform`].
    CosUniform,
    /// `theta` uniform on `[0, pi]`, a probability measure: the paper's Eq. 9.
    ThetaUniform,
}

/// Number of `points` in the closed cap `<w, x> >= t`.
pub(super) fn count_in_cap(points: &[DVec3], w: DVec3, t: f64) -> usize {
    points.iter().filter(|p| w.dot(**p) >= t).count()
}

/// Random caps drawn once with their target measures, so that many sets can be
/// scored on the same caps while each measure is paid once: `count` caps, `w`
/// uniform and the radius per `radius`, drawn in chunks of 256 caps (stream `chunk`
/// of `seed`), so the caps do not depend on the thread count.
pub struct MeasuredCaps {
    /// `(w, t, mu(C(w, t)))` in draw order.
    pub(super) caps: Vec<(DVec3, f64, f64)>,
}

impl MeasuredCaps {
    /// Draws the caps and measures each with `cap_measure(w, t)` (in parallel).
    pub fn draw(
        count: usize,
        seed: u64,
        radius: CapRadius,
        cap_measure: impl Fn(DVec3, f64) -> f64 + Sync,
    ) -> Self {
        Self::draw_with(count, seed, cap_measure, |u| match radius {
            CapRadius::CosUniform => 1.0 - 2.0 * u,
            CapRadius::ThetaUniform => (PI * u).cos(),
        })
    }

    /// [`MeasuredCaps::draw`]'s caps with `theta` uniform in `[0, max_theta]`
    /// instead (radians, clamped into `[0, pi]`): the paper's measure restricted to
    /// caps of at most that radius, a probability measure scored with
    /// [`CapRadius::ThetaUniform`]'s scale. At `max_theta = pi`, the caps of
    /// `draw(count, seed, CapRadius::ThetaUniform, ..)` bit for bit.
    pub fn draw_up_to(
        count: usize,
        seed: u64,
        max_theta: f64,
        cap_measure: impl Fn(DVec3, f64) -> f64 + Sync,
    ) -> Self {
        let max_theta = max_theta.clamp(0.0, PI);
        Self::draw_with(count, seed, cap_measure, |u| (max_theta * u).cos())
    }

    /// `count` caps all centred on the unit `center`, radii
    /// `theta_k = (k + 1/2) max_theta / count` (a midpoint rule over `theta`
    /// uniform in `[0, max_theta]`, `max_theta` clamped into `[0, pi]`): how evenly
    /// a set fills the bands about one direction (a hemisphere's normal), which
    /// caps with uniform centres seldom test. Scored with
    /// [`CapRadius::ThetaUniform`]'s scale.
    pub fn zonal(
        center: DVec3,
        count: usize,
        max_theta: f64,
        cap_measure: impl Fn(DVec3, f64) -> f64 + Sync,
    ) -> Self {
        let max_theta = max_theta.clamp(0.0, PI);
        let caps = (0..count)
            .into_par_iter()
            .map(|k| {
                let t = ((k as f64 + 0.5) / count as f64 * max_theta).cos();
                (center, t, cap_measure(center, t))
            })
            .collect();
        Self { caps }
    }

    /// The caps of `count` centres `w` uniform on the sphere, each with
    /// `t = cos theta = radius(u)` for `u` uniform in `[0, 1)`, measured.
    fn draw_with(
        count: usize,
        seed: u64,
        cap_measure: impl Fn(DVec3, f64) -> f64 + Sync,
        radius: impl Fn(f64) -> f64 + Sync,
    ) -> Self {
        let chunks = count.div_ceil(CAP_CHUNK);
        let caps = (0..chunks)
            .into_par_iter()
            .flat_map_iter(|c| {
                let mut g = rng(seed, c as u64);
                let m = CAP_CHUNK.min(count - c * CAP_CHUNK);
                let drawn: Vec<(DVec3, f64)> = (0..m)
                    .map(|_| {
                        let w = random_direction(&mut g);
                        (w, radius(g.random::<f64>()))
                    })
                    .collect();
                drawn.into_iter().map(|(w, t)| (w, t, cap_measure(w, t)))
            })
            .collect();
        Self { caps }
    }

    /// Number of caps.
    pub fn len(&self) -> usize {
        self.caps.len()
    }

    /// Whether there are no caps.
    pub fn is_empty(&self) -> bool {
        self.caps.is_empty()
    }

    /// `(s mean(r^2), s sd(r^2) / sqrt(caps))` over these caps, `s` as in
    /// [`cap_l2_mc_squared`] (these caps must have been drawn with `radius`).
    pub fn l2_squared(&self, points: &[DVec3], radius: CapRadius) -> (f64, f64) {
        if self.caps.is_empty() || points.is_empty() {
            return (0.0, 0.0);
        }
        let parts: Vec<(f64, f64)> = self
            .caps
            .par_chunks(CAP_CHUNK)
            .map(|chunk| {
                chunk.iter().fold((0.0, 0.0), |(s, s2), cap| {
                    let r2 = residual(points, cap).powi(2);
                    (s + r2, s2 + r2 * r2)
                })
            })
            .collect();
        let (s, s2) = parts
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
        let m = self.caps.len() as f64;
        let mean = s / m;
        let var = if self.caps.len() > 1 {
            ((s2 - m * mean * mean) / (m - 1.0)).max(0.0)
        } else {
            0.0
        };
        let scale = match radius {
            CapRadius::CosUniform => 2.0,
            CapRadius::ThetaUniform => 1.0,
        };
        (scale * mean, scale * (var / m).sqrt())
    }
}

/// The local discrepancy `#{x_i in C}/N - mu(C)` of a measured cap `(w, t, mu)`.
pub(super) fn residual(points: &[DVec3], &(w, t, mu): &(DVec3, f64, f64)) -> f64 {
    count_in_cap(points, w, t) as f64 / points.len() as f64 - mu
}

/// Monte Carlo estimate of the squared cap L2 discrepancy under `radius`, with its
/// standard error: `caps` caps with `w` uniform and the radius drawn per `radius`;
/// local discrepancy `r = #{x_i in C}/N - cap_measure(w, t)` by exact counting;
/// `D^2 ≈ s mean(r^2)`, `s = 2` for [`CapRadius::CosUniform`] (its `dt` has mass 2),
/// 1 otherwise; `se = s sd(r^2) / sqrt(caps)`. `O(caps (N + cost of cap_measure))`,
/// the caps of [`MeasuredCaps::draw`].
pub fn cap_l2_mc_squared(
    points: &[DVec3],
    cap_measure: impl Fn(DVec3, f64) -> f64 + Sync,
    caps: usize,
    seed: u64,
    radius: CapRadius,
) -> (f64, f64) {
    if caps == 0 || points.is_empty() {
        return (0.0, 0.0);
    }
    MeasuredCaps::draw(caps, seed, radius, cap_measure).l2_squared(points, radius)
}

/// The paper's `D_cap,2` (Eq. 9: `w` uniform, `theta` uniform on `[0, pi]`) by
/// Monte Carlo over `caps` random caps: returns `(D, se)`, `D = sqrt` of the
/// [`cap_l2_mc_squared`] estimate and `se = se(D^2) / (2 D)` (delta method; the
/// standard error of `D^2` itself if `D = 0`). `cap_measure(w, t)` gives `mu(C(w, t))`
/// (e.g. `|w, t| density.cap_measure(w, t)`).
pub fn cap_l2_theta_uniform_estimate(
    points: &[DVec3],
    cap_measure: impl Fn(DVec3, f64) -> f64 + Sync,
    caps: usize,
    seed: u64,
) -> (f64, f64) {
    let (d2, se2) = cap_l2_mc_squared(points, cap_measure, caps, seed, CapRadius::ThetaUniform);
    root_with_stderr(d2, se2)
}

/// `(D, se(D))` from `(D^2, se(D^2))`: `se = se(D^2) / (2 D)` (delta method; the
/// standard error of `D^2` itself if `D = 0`).
pub fn root_with_stderr(d2: f64, se2: f64) -> (f64, f64) {
    let d = d2.max(0.0).sqrt();
    let se = if d > 0.0 { se2 / (2.0 * d) } else { se2 };
    (d, se)
}
