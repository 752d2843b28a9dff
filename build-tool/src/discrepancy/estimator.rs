//! Residuals, loss and the surrogate gradient of the quadrant-box estimator, with a
//! banded fast path and the dense reference it is tested against.

use super::counting::quadrant_counts;
use super::QUADRANTS;
use crate::density::Density2D;
use glam::DVec2;
use rayon::prelude::*;

/// Beyond `|alpha * sdf| > SIGMOID_BAND` the sigmoid's derivative is below
/// `e^-16 ~ 1.1e-7` of its peak, and the fast path skips the point.
pub const SIGMOID_BAND: f64 = 16.0;

/// Fixed number of work chunks the anchors are split into: results are summed in
/// chunk order, so they do not depend on the thread count.
const CHUNKS: usize = 32;

/// How the target measure `mu(B)` of a box is obtained.
#[derive(Clone, Copy)]
pub enum AreaModel<'a> {
    /// From the density's CDF: closed form, or exact summed-area tables for
    /// tabulated densities.
    Exact(&'a dyn Density2D),
    /// The paper's Eq. 11 with `p ∝ q`: the fraction of shared samples drawn from
    /// the target that fall in the box.
    MonteCarlo(&'a [DVec2]),
}

/// Which gradient implementation to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum GradientPath {
    /// Only points within `SIGMOID_BAND / alpha` of the cross through each anchor,
    /// found by binary search on sorted coordinates.
    Fast,
    /// Every point against every box, O(N M): the reference.
    Dense,
}

/// `mu` of the four quadrant boxes around each anchor, in [`QUADRANTS`] order.
///
/// Exact: three CDF evaluations per anchor, `F(u)`, `F(u.x, 1)`, `F(1, u.y)`.
pub fn quadrant_measures(area: AreaModel<'_>, anchors: &[DVec2]) -> Vec<[f64; 4]> {
    match area {
        AreaModel::Exact(density) => anchors
            .par_iter()
            .map(|&u| {
                let f = density.cdf(u);
                let fx = density.cdf(DVec2::new(u.x, 1.0));
                let fy = density.cdf(DVec2::new(1.0, u.y));
                [f, fy - f, fx - f, 1.0 - fx - fy + f]
            })
            .collect(),
        AreaModel::MonteCarlo(samples) => {
            let k = samples.len() as u32;
            let inv = 1.0 / samples.len().max(1) as f64;
            quadrant_counts(samples, anchors)
                .into_iter()
                .map(|c| c.quadrants(k).map(|q| q as f64 * inv))
                .collect()
        }
    }
}

/// Residuals `r = count / N - mu` of the four quadrant boxes around each anchor,
/// from exact counts.
pub fn residuals(points: &[DVec2], anchors: &[DVec2], measures: &[[f64; 4]]) -> Vec<[f64; 4]> {
    let n = points.len() as u32;
    let inv_n = 1.0 / points.len().max(1) as f64;
    quadrant_counts(points, anchors)
        .iter()
        .zip(measures)
        .map(|(c, mu)| {
            let q = c.quadrants(n);
            [0, 1, 2, 3].map(|k| q[k] as f64 * inv_n - mu[k])
        })
        .collect()
}

/// `alpha * sigma'(alpha * sdf)` with `sigma'(z) = e^-|z| / (1 + e^-|z|)^2`: the
/// derivative of the mollified indicator `sigma(alpha * sdf)` with respect to `sdf`
/// (paper §3.1), shared by the box and cap estimators.
#[inline]
pub(crate) fn sigmoid_slope(alpha: f64, sdf: f64) -> f64 {
    let e = (-(alpha * sdf).abs()).exp();
    alpha * e / ((1.0 + e) * (1.0 + e))
}

/// `sum_c r_c * d sigma(alpha sdf(B_c(u), p)) / dp` over the four quadrant boxes
/// around `u` (without the `2 / (M' N)` factor).
///
/// The signed distance to a quadrant box with only its two interior faces: inside,
/// the distance to the nearer face; outside, minus the distance to the box.
#[inline]
fn point_gradient(p: DVec2, u: DVec2, r: &[f64; 4], alpha: f64) -> DVec2 {
    let d = p - u;
    let mut g = DVec2::ZERO;
    for (c, &(sx, sy)) in QUADRANTS.iter().enumerate() {
        // Coordinates that are positive inside the box along each axis.
        let ex = sx * d.x;
        let ey = sy * d.y;
        let (sdf, gx, gy) = if ex > 0.0 && ey > 0.0 {
            if ex < ey {
                (ex, 1.0, 0.0)
            } else {
                (ey, 0.0, 1.0)
            }
        } else {
            let ox = ex.min(0.0);
            let oy = ey.min(0.0);
            let len = (ox * ox + oy * oy).sqrt();
            if len == 0.0 {
                continue; // exactly on the corner: no defined direction
            }
            (-len, -ox / len, -oy / len)
        };
        let s = r[c] * sigmoid_slope(alpha, sdf);
        g += DVec2::new(s * sx * gx, s * sy * gy);
    }
    g
}

/// [`point_gradient`] for a point near the vertical line through `u` but at least
/// `SIGMOID_BAND / alpha` from the horizontal one: the two boxes on the far side of
/// the horizontal line are negligible, and for the two on the near side the signed
/// distance is `-+|dx|`, with gradient `(sx, 0)`; so one exponential serves both.
#[inline]
fn vertical_face_gradient(p: DVec2, u: DVec2, r: &[f64; 4], alpha: f64) -> DVec2 {
    let dx = p.x - u.x;
    let slope = sigmoid_slope(alpha, dx);
    // Boxes below u are indices 0 (left) and 1 (right); above, 2 and 3.
    let (left, right) = if p.y < u.y {
        (r[0], r[1])
    } else {
        (r[2], r[3])
    };
    DVec2::new(slope * (right - left), 0.0)
}

/// The mirror image of [`vertical_face_gradient`] for the horizontal line.
#[inline]
fn horizontal_face_gradient(p: DVec2, u: DVec2, r: &[f64; 4], alpha: f64) -> DVec2 {
    let dy = p.y - u.y;
    let slope = sigmoid_slope(alpha, dy);
    let (below, above) = if p.x < u.x {
        (r[0], r[2])
    } else {
        (r[1], r[3])
    };
    DVec2::new(0.0, slope * (above - below))
}

/// Sums per-chunk `(loss, gradient)` partials in chunk order into `grad` (then
/// scaled by `scale`) and returns the summed loss: a fixed-order reduction, so the
/// result does not depend on how rayon scheduled the chunks.
pub(crate) fn sum_partials<V>(partials: Vec<(f64, Vec<V>)>, grad: &mut [V], scale: f64) -> f64
where
    V: Copy + Default + std::ops::AddAssign + std::ops::MulAssign<f64>,
{
    grad.iter_mut().for_each(|g| *g = V::default());
    let mut loss = 0.0;
    for (l, g) in partials {
        loss += l;
        for (a, b) in grad.iter_mut().zip(g) {
            *a += b;
        }
    }
    grad.iter_mut().for_each(|g| *g *= scale);
    loss
}

/// Points sorted along one axis, with their original indices.
struct Sorted {
    keys: Vec<f64>,
    points: Vec<(DVec2, u32)>,
}

impl Sorted {
    fn new(points: &[DVec2], key: fn(&DVec2) -> f64) -> Self {
        let mut v: Vec<(DVec2, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, p)| (*p, i as u32))
            .collect();
        v.sort_unstable_by(|a, b| key(&a.0).total_cmp(&key(&b.0)));
        Self {
            keys: v.iter().map(|(p, _)| key(p)).collect(),
            points: v,
        }
    }
    /// The points with key in `[lo, hi)`.
    fn band(&self, lo: f64, hi: f64) -> &[(DVec2, u32)] {
        let a = self.keys.partition_point(|&k| k < lo);
        let b = self.keys.partition_point(|&k| k < hi);
        &self.points[a..b]
    }
}

/// Loss `(1/M') sum r^2` and its surrogate gradient with respect to each point,
/// written to `grad` (`grad.len() == points.len()`, overwritten).
///
/// `residuals` come from [`residuals`] for the same points and anchors. The result
/// is bit-identical for any rayon thread count.
pub fn loss_and_gradient(
    points: &[DVec2],
    anchors: &[DVec2],
    residuals: &[[f64; 4]],
    alpha: f64,
    path: GradientPath,
    grad: &mut [DVec2],
) -> f64 {
    let m_boxes = 4.0 * anchors.len() as f64;
    let n = points.len();
    let chunk = anchors.len().div_ceil(CHUNKS).max(1);
    let width = SIGMOID_BAND / alpha;
    let (by_x, by_y) = match path {
        GradientPath::Fast => (
            Some(Sorted::new(points, |p| p.x)),
            Some(Sorted::new(points, |p| p.y)),
        ),
        GradientPath::Dense => (None, None),
    };
    let partials: Vec<(f64, Vec<DVec2>)> = anchors
        .par_chunks(chunk)
        .zip(residuals.par_chunks(chunk))
        .map(|(us, rs)| {
            let mut g = vec![DVec2::ZERO; n];
            let mut loss = 0.0;
            for (&u, r) in us.iter().zip(rs) {
                loss += r.iter().map(|v| v * v).sum::<f64>();
                match (&by_x, &by_y) {
                    (Some(bx), Some(by)) => {
                        let (xlo, xhi) = (u.x - width, u.x + width);
                        let (ylo, yhi) = (u.y - width, u.y + width);
                        let in_y_band = |p: DVec2| p.y >= ylo && p.y < yhi;
                        for &(p, i) in bx.band(xlo, xhi) {
                            g[i as usize] += if in_y_band(p) {
                                point_gradient(p, u, r, alpha)
                            } else {
                                vertical_face_gradient(p, u, r, alpha)
                            };
                        }
                        for &(p, i) in by.band(ylo, yhi) {
                            // Points in both bands were handled with the x band.
                            if !(p.x >= xlo && p.x < xhi) {
                                g[i as usize] += horizontal_face_gradient(p, u, r, alpha);
                            }
                        }
                    }
                    _ => {
                        for (gi, &p) in g.iter_mut().zip(points) {
                            *gi += point_gradient(p, u, r, alpha);
                        }
                    }
                }
            }
            (loss, g)
        })
        .collect();
    let loss = sum_partials(partials, grad, 2.0 / (m_boxes * n as f64));
    loss / m_boxes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::{Density2D, TabulatedDensity, Uniform};
    use rand::{Rng, SeedableRng};

    fn random_points(n: usize, seed: u64) -> Vec<DVec2> {
        let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        (0..n).map(|_| DVec2::new(r.random(), r.random())).collect()
    }

    fn smooth_indicator_sum(p: DVec2, u: DVec2, r: &[f64; 4], alpha: f64) -> f64 {
        // sum_c r_c sigma(alpha sdf_c(p)), with the quadrant SDFs written out directly.
        let mut s = 0.0;
        for (c, &(sx, sy)) in QUADRANTS.iter().enumerate() {
            let (ex, ey) = (sx * (p.x - u.x), sy * (p.y - u.y));
            let sdf = if ex > 0.0 && ey > 0.0 {
                ex.min(ey)
            } else {
                -(ex.min(0.0).powi(2) + ey.min(0.0).powi(2)).sqrt()
            };
            s += r[c] / (1.0 + (-alpha * sdf).exp());
        }
        s
    }

    #[test]
    fn point_gradient_is_the_derivative_of_the_sigmoid_of_the_sdf() {
        let r = [0.3, -0.2, 0.05, -0.15];
        let u = DVec2::new(0.4, 0.55);
        let h = 1e-7;
        for p in random_points(200, 1) {
            let g = point_gradient(p, u, &r, 30.0);
            let fd = DVec2::new(
                (smooth_indicator_sum(p + DVec2::X * h, u, &r, 30.0)
                    - smooth_indicator_sum(p - DVec2::X * h, u, &r, 30.0))
                    / (2.0 * h),
                (smooth_indicator_sum(p + DVec2::Y * h, u, &r, 30.0)
                    - smooth_indicator_sum(p - DVec2::Y * h, u, &r, 30.0))
                    / (2.0 * h),
            );
            assert!(
                (g - fd).length() <= 1e-5 * (1.0 + fd.length()),
                "{p:?}: {g:?} vs {fd:?}"
            );
        }
    }

    fn fast_vs_dense(density: &dyn Density2D, points: &[DVec2], alpha: f64) {
        let anchors = random_points(300, 7);
        let mu = quadrant_measures(AreaModel::Exact(density), &anchors);
        let res = residuals(points, &anchors, &mu);
        let mut fast = vec![DVec2::ZERO; points.len()];
        let mut dense = fast.clone();
        let lf = loss_and_gradient(points, &anchors, &res, alpha, GradientPath::Fast, &mut fast);
        let ld = loss_and_gradient(
            points,
            &anchors,
            &res,
            alpha,
            GradientPath::Dense,
            &mut dense,
        );
        assert_eq!(lf, ld);
        let scale = dense.iter().map(|g| g.length()).fold(0.0, f64::max);
        assert!(scale > 0.0);
        for (i, (a, b)) in fast.iter().zip(&dense).enumerate() {
            assert!(
                (*a - *b).length() <= 1e-6 * scale,
                "point {i}: {a:?} vs {b:?}"
            );
        }
    }

    #[test]
    fn fast_gradient_equals_dense_reference() {
        let tab = TabulatedDensity::from_grid(3, 2, vec![1.0, 5.0, 0.5, 2.0, 0.0, 3.0]).unwrap();
        for (n, a) in [(64, 2.0), (256, 8.0), (1000, 40.0), (500, 300.0)] {
            let alpha = a * (n as f64).sqrt();
            fast_vs_dense(&Uniform, &random_points(n, n as u64), alpha);
            fast_vs_dense(&tab, &random_points(n, 3 + n as u64), alpha);
        }
    }

    /// Mean and standard error of the per-anchor loss over `m` fresh anchors.
    fn mc_mean(density: &dyn Density2D, points: &[DVec2], m: usize, seed: u64) -> (f64, f64) {
        let anchors = random_points(m, seed);
        let mu = quadrant_measures(AreaModel::Exact(density), &anchors);
        let per: Vec<f64> = residuals(points, &anchors, &mu)
            .iter()
            .map(|r| r.iter().map(|v| v * v).sum::<f64>() / 4.0)
            .collect();
        let mean = per.iter().sum::<f64>() / m as f64;
        let var = per.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (m - 1) as f64;
        (mean, (var / m as f64).sqrt())
    }

    #[test]
    fn estimator_mean_converges_to_closed_form_uniform() {
        for (n, seed) in [(16, 1), (100, 2), (700, 3)] {
            let pts = random_points(n, seed);
            let exact = crate::metrics::asd_uniform_squared(&pts);
            let (mean, se) = mc_mean(&Uniform, &pts, 400_000, 10 + seed);
            assert!(
                (mean - exact).abs() < 3.0 * se,
                "n={n}: {mean} ± {se} vs {exact}"
            );
            assert!(
                se < 0.02 * exact,
                "the test must be sharp: se {se} vs {exact}"
            );
        }
    }

    #[test]
    fn estimator_mean_converges_to_closed_form_piecewise_constant() {
        let tab = TabulatedDensity::from_grid(
            4,
            3,
            vec![1.0, 5.0, 0.5, 2.0, 0.0, 3.0, 1.5, 0.2, 4.0, 1.0, 2.5, 0.7],
        )
        .unwrap();
        let grid = tab.cells(0);
        for (n, seed) in [(16, 4), (200, 5)] {
            // Points from the target (warped random), as an optimizer would see them.
            let pts: Vec<DVec2> = random_points(n, seed)
                .iter()
                .map(|&u| tab.inverse_cdf(u))
                .collect();
            let exact = crate::metrics::asd_cells_squared(&pts, &grid);
            let (mean, se) = mc_mean(&tab, &pts, 400_000, 20 + seed);
            assert!(
                (mean - exact).abs() < 3.0 * se,
                "n={n}: {mean} ± {se} vs {exact}"
            );
            assert!(
                se < 0.02 * exact,
                "the test must be sharp: se {se} vs {exact}"
            );
        }
    }

    #[test]
    fn monte_carlo_areas_converge_to_exact_areas() {
        let tab = TabulatedDensity::from_grid(2, 2, vec![1.0, 3.0, 0.0, 2.0]).unwrap();
        let anchors = random_points(50, 9);
        let exact = quadrant_measures(AreaModel::Exact(&tab), &anchors);
        let samples: Vec<DVec2> = random_points(200_000, 11)
            .iter()
            .map(|&u| tab.inverse_cdf(u))
            .collect();
        let mc = quadrant_measures(AreaModel::MonteCarlo(&samples), &anchors);
        for (a, b) in exact.iter().zip(&mc) {
            for k in 0..4 {
                // Binomial standard error of a fraction out of 200k is at most 1.2e-3.
                assert!((a[k] - b[k]).abs() < 5e-3, "{a:?} vs {b:?}");
            }
        }
    }
}
