//! A lower bound of the cap star discrepancy `sup_C |#{x_i in C}/N - mu(C)|` (paper
//! Eq. 8) by search: random caps, then sweeps of the radius about promising
//! centres.

use super::cap_l2::{count_in_cap, residual, CapRadius, MeasuredCaps};
use crate::seeding::rng;
use crate::sphere::geometry::{tangent_frame, unit_or_z};
use crate::sphere::target::DirectionDensity;
use glam::DVec3;
use rand::Rng;
use rayon::prelude::*;

/// Search effort of [`cap_star_estimate_with`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CapStarOptions {
    /// Random caps of the first phase (`w` uniform, `theta` uniform on `[0, pi]`).
    pub random_caps: usize,
    /// Best caps of the first phase that are refined.
    pub refine: usize,
    /// Hill-climbing rounds per refined cap.
    pub rounds: usize,
    /// Perturbed centres tried per round.
    pub tries: usize,
    /// First perturbation step (radians); each round multiplies it by 0.6.
    pub initial_step: f64,
}

impl Default for CapStarOptions {
    fn default() -> Self {
        Self {
            random_caps: 20_000,
            refine: 16,
            rounds: 12,
            tries: 4,
            initial_step: 0.1,
        }
    }
}

/// A lower bound of the cap star discrepancy and the cap attaining it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CapStarEstimate {
    /// `max |#{x_i in C}/N - mu(C)|` over the caps examined: a lower bound of
    /// `D*_cap` (up to the accuracy of `cap_measure` for tabulated targets).
    pub lower_bound: f64,
    /// Centre of the extremal cap.
    pub center: DVec3,
    /// `cos theta` of the extremal cap.
    pub cos_theta: f64,
    /// `true` if the extremal cap is the closed cap `<w, x> >= t` holding too many
    /// points (`#{<w,x> >= t}/N - mu`); `false` if it holds too few, as the limit of
    /// caps shrinking to it (`mu - #{<w,x> > t}/N`).
    pub excess: bool,
    /// Best value among the random caps alone (before refinement).
    pub random_best: f64,
    /// Centres swept over all critical radii during refinement.
    pub sweeps: usize,
}

/// For centre `w`: the supremum over all radii of the local discrepancy, using
/// `density.cap_measure_profile` at the critical radii (where a point enters).
/// Returns `(value, t, excess)`.
pub(super) fn sweep(
    points: &[DVec3],
    density: &dyn DirectionDensity,
    w: DVec3,
) -> (f64, f64, bool) {
    let n = points.len();
    let mut d: Vec<f64> = points.iter().map(|p| w.dot(*p)).collect();
    d.sort_by(|a, b| b.total_cmp(a));
    let mu = density.cap_measure_profile(w, &d);
    let nf = n as f64;
    let mut best = (f64::NEG_INFINITY, 1.0, true);
    let mut k = 0;
    while k < n {
        // Group of ties d[k..j].
        let mut j = k + 1;
        while j < n && d[j] == d[k] {
            j += 1;
        }
        let m = mu[k];
        let closed = j as f64 / nf - m;
        let open = m - k as f64 / nf;
        if closed > best.0 {
            best = (closed, d[k], true);
        }
        if open > best.0 {
            best = (open, d[k], false);
        }
        k = j;
    }
    best
}

/// [`CapStarEstimate`] with [`CapStarOptions::default`] but `caps` random caps.
pub fn cap_star_estimate(
    points: &[DVec3],
    density: &dyn DirectionDensity,
    caps: usize,
    seed: u64,
) -> CapStarEstimate {
    let options = CapStarOptions {
        random_caps: caps,
        ..CapStarOptions::default()
    };
    cap_star_estimate_with(points, density, &options, seed)
}

/// A lower bound of the cap star discrepancy `D*_cap` (paper Eq. 8) of unit vectors
/// `points` against `density`:
///
/// 1. `random_caps` random caps (`w` uniform, `theta` uniform on `[0, pi]`), local
///    discrepancy by exact counts and `cap_measure`; O(N) each.
/// 2. For the `refine` best, the centre is *swept*: all radii where a point enters
///    the cap are examined at once (sort the points by `<w, x>`, `O(N log N)`, plus
///    one `cap_measure_profile`), which gives the exact supremum over radii for that
///    centre (up to the profile's accuracy).
/// 3. Hill climbing on the centre: `rounds` rounds of `tries` random perturbations
///    of decreasing size, each swept; improvements are kept.
/// 4. The best cap of each refined candidate is re-evaluated with exact counts and
///    `cap_measure`, so the reported value does not rest on the (possibly coarser)
///    profile.
///
/// The result is the largest value found, a lower bound of the supremum; no
/// standard error applies. Deterministic for a given `seed` (streams per chunk /
/// candidate, fixed-order reductions). Cost
/// `O(random_caps N + refine rounds tries (N log N + profile))`; with the defaults
/// and N = 4096 a few seconds at most.
pub fn cap_star_estimate_with(
    points: &[DVec3],
    density: &dyn DirectionDensity,
    options: &CapStarOptions,
    seed: u64,
) -> CapStarEstimate {
    let screened = MeasuredCaps::draw(
        options.random_caps,
        seed,
        CapRadius::ThetaUniform,
        |w, t| density.cap_measure(w, t),
    );
    cap_star_estimate_screened(points, density, &screened, options, seed)
}

/// [`cap_star_estimate_with`] whose random caps (phase 1) are `screened`: drawn
/// once with [`CapRadius::ThetaUniform`] (`options.random_caps` is ignored) and
/// measured beforehand, possibly by something cheaper than the exact
/// `cap_measure` (e.g. a [`CapMeasureTable`](crate::sphere::CapMeasureTable) of a target whose exact
/// measure costs `O(H)`), so that many sets share the cost. The `refine` best of
/// them are scored again with the exact `density.cap_measure`, as are the refined
/// caps: the reported value rests on exact measures only.
pub fn cap_star_estimate_screened(
    points: &[DVec3],
    density: &dyn DirectionDensity,
    screened: &MeasuredCaps,
    options: &CapStarOptions,
    seed: u64,
) -> CapStarEstimate {
    let n = points.len();
    let empty = CapStarEstimate {
        lower_bound: 0.0,
        center: DVec3::Z,
        cos_theta: 1.0,
        excess: true,
        random_best: 0.0,
        sweeps: 0,
    };
    if n == 0 {
        return empty;
    }
    let nf = n as f64;
    // Phase 1: random caps.
    let mut found: Vec<(f64, usize, DVec3, f64, bool)> = screened
        .caps
        .par_iter()
        .enumerate()
        .map(|(i, cap)| {
            let r = residual(points, cap);
            (r.abs(), i, cap.0, cap.1, r >= 0.0)
        })
        .collect();
    found.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    // The leaders are scored again with the exact measure and re-ranked.
    let leaders = options.refine.max(1).min(found.len());
    found[..leaders].par_iter_mut().for_each(|f| {
        let r = count_in_cap(points, f.2, f.3) as f64 / nf - density.cap_measure(f.2, f.3);
        (f.0, f.4) = (r.abs(), r >= 0.0);
    });
    found[..leaders].sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut best = match found.first() {
        Some(&(v, _, w, t, e)) => CapStarEstimate {
            lower_bound: v,
            center: w,
            cos_theta: t,
            excess: e,
            random_best: v,
            sweeps: 0,
        },
        None => empty,
    };
    // Phases 2-4: sweep and hill-climb the best centres (plus a few fixed ones so
    // that something is refined even without random caps).
    let mut starts: Vec<DVec3> = found.iter().take(options.refine).map(|f| f.2).collect();
    if starts.is_empty() && options.refine > 0 {
        starts.extend([
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
        ]);
        starts.truncate(options.refine);
    }
    let refined: Vec<(CapStarEstimate, usize)> = starts
        .par_iter()
        .enumerate()
        .map(|(k, &w0)| {
            let mut g = rng(seed, (1u64 << 40) + k as u64);
            let mut w = w0;
            let mut cur = sweep(points, density, w);
            let mut sweeps = 1;
            let mut step = options.initial_step;
            for _ in 0..options.rounds {
                let (e1, e2) = tangent_frame(w);
                let mut round_best = (cur, w);
                for _ in 0..options.tries {
                    let (a, b) = loop {
                        let a = 2.0 * g.random::<f64>() - 1.0;
                        let b = 2.0 * g.random::<f64>() - 1.0;
                        if a * a + b * b <= 1.0 {
                            break (a, b);
                        }
                    };
                    let cand = unit_or_z(w + step * (a * e1 + b * e2));
                    let s = sweep(points, density, cand);
                    sweeps += 1;
                    if s.0 > round_best.0 .0 {
                        round_best = (s, cand);
                    }
                }
                (cur, w) = round_best;
                step *= 0.6;
            }
            // Exact re-evaluation of the swept cap.
            let t = cur.1;
            let mu = density.cap_measure(w, t);
            let closed = count_in_cap(points, w, t) as f64 / nf - mu;
            let above = points.iter().filter(|p| w.dot(**p) > t).count() as f64;
            let open = mu - above / nf;
            let (v, excess) = if closed >= open {
                (closed, true)
            } else {
                (open, false)
            };
            (
                CapStarEstimate {
                    lower_bound: v,
                    center: w,
                    cos_theta: t,
                    excess,
                    random_best: 0.0,
                    sweeps: 0,
                },
                sweeps,
            )
        })
        .collect();
    let mut total_sweeps = 0;
    for (r, s) in refined {
        total_sweeps += s;
        if r.lower_bound > best.lower_bound {
            best = CapStarEstimate {
                random_best: best.random_best,
                ..r
            };
        }
    }
    best.sweeps = total_sweeps;
    best
}
