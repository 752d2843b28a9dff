//! L2 discrepancies for the uniform measure on `[0,1]^2`: Warnock's origin-anchored
//! L2-star and the all-corner average squared discrepancy (docs/metrics.md).

use glam::DVec2;

use super::pairs::{asd_pair_term, l2_star_pair_term};
use super::sum::sum;

/// Squared L2-star discrepancy of `points` for the uniform measure, Warnock's formula
/// (d = 2):
///
/// `(D2*)^2 = 3^-2 - (2/N) sum_i prod_j (1 - x_ij^2)/2
///            + (1/N^2) sum_i sum_k prod_j (1 - max(x_ij, x_kj))`,
///
/// i.e. `∫_{[0,1]^2} (#{x_i <= a}/N - a_x a_y)^2 da`. Exact in `O(N log N)` (the
/// point–point term by [`super::l2_star_pair_term`]); deterministic.
/// Clamped at 0 against rounding. Panics if `points` is empty.
pub fn l2_star_uniform_squared(points: &[DVec2]) -> f64 {
    let n = non_empty(points);
    let cross = sum(points
        .iter()
        .map(|p| 0.25 * (1.0 - p.x * p.x) * (1.0 - p.y * p.y)));
    (1.0 / 9.0 - 2.0 * cross / n + l2_star_pair_term(points)).max(0.0)
}

/// L2-star discrepancy `D2*` of `points` for the uniform measure: the square root of
/// [`l2_star_uniform_squared`] (what scipy's `discrepancy(method='L2-star')` returns).
/// `O(N log N)`. Panics if `points` is empty.
pub fn l2_star_uniform(points: &[DVec2]) -> f64 {
    l2_star_uniform_squared(points).sqrt()
}

/// Squared average squared discrepancy (all-corner anchored L2) of `points` for the
/// uniform measure, closed form (d = 2):
///
/// `(D2asd)^2 = 3^-2 - (2/N) sum_i prod_j (1 + 2x_ij - 2x_ij^2)/4
///              + (1/N^2) sum_i sum_k prod_j (1 - |x_ij - x_kj|)/2`,
///
/// i.e. `E_{u,c}[(#{x_i in B(u,c)}/N - |B(u,c)|)^2]` over `u ~ U[0,1]^2` and the four
/// corners `c`. Exact in `O(N log N)` (the point–point term by
/// [`super::asd_pair_term`]); deterministic. Clamped at 0 against
/// rounding. Panics if `points` is empty.
pub fn asd_uniform_squared(points: &[DVec2]) -> f64 {
    let n = non_empty(points);
    let cross = sum(points
        .iter()
        .map(|p| (1.0 + 2.0 * p.x - 2.0 * p.x * p.x) * (1.0 + 2.0 * p.y - 2.0 * p.y * p.y) / 16.0));
    (1.0 / 9.0 - 2.0 * cross / n + asd_pair_term(points)).max(0.0)
}

/// Average squared discrepancy `D2asd` of `points` for the uniform measure: the square
/// root of [`asd_uniform_squared`]. `O(N log N)`. Panics if `points` is empty.
pub fn asd_uniform(points: &[DVec2]) -> f64 {
    asd_uniform_squared(points).sqrt()
}

/// `N` as `f64`, panicking on an empty set (the discrepancy of no points is undefined).
pub(crate) fn non_empty(points: &[DVec2]) -> f64 {
    assert!(
        !points.is_empty(),
        "discrepancy of an empty point set is undefined"
    );
    points.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::test_util::{hammersley, random_points, SplitMix64};

    /// docs/metrics.md reference values (sqrt), 7 significant digits.
    const HAMMERSLEY: [(usize, f64, f64); 4] = [
        (16, 6.929084e-2, 4.794558e-2),
        (64, 2.120511e-2, 1.533232e-2),
        (256, 6.277231e-3, 4.714085e-3),
        (1024, 1.813240e-3, 1.405811e-3),
    ];

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn hammersley_reference_values() {
        for (n, l2, asd) in HAMMERSLEY {
            let pts = hammersley(n);
            let (a, b) = (l2_star_uniform(&pts), asd_uniform(&pts));
            // Printed to 7 significant digits: half a unit in the last place is
            // <= 5e-7 relative.
            assert!(close(a, l2, 6e-7), "N={n}: L2-star {a:e} vs {l2:e}");
            assert!(close(b, asd, 6e-7), "N={n}: asd {b:e} vs {asd:e}");
        }
    }

    #[test]
    fn single_centre_point() {
        let pts = [DVec2::splat(0.5)];
        assert!((l2_star_uniform_squared(&pts) - 23.0 / 288.0).abs() < 1e-15);
        assert!((asd_uniform_squared(&pts) - 23.0 / 288.0).abs() < 1e-15);
    }

    #[test]
    fn random_sets_expectation() {
        // E[(D2*)^2] = E[(D2asd)^2] = (5/36)/N for N iid uniform points.
        let (n, sets) = (32usize, 400usize);
        let mut rng = SplitMix64::new(2024);
        let expected = 5.0 / 36.0 / n as f64;
        let mut l2 = Vec::with_capacity(sets);
        let mut asd = Vec::with_capacity(sets);
        for _ in 0..sets {
            let pts = random_points(&mut rng, n);
            l2.push(l2_star_uniform_squared(&pts));
            asd.push(asd_uniform_squared(&pts));
        }
        for (name, v) in [("L2-star", l2), ("asd", asd)] {
            let m = v.iter().sum::<f64>() / sets as f64;
            let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (sets - 1) as f64;
            let se = (var / sets as f64).sqrt();
            assert!(
                (m - expected).abs() < 3.0 * se,
                "{name}: mean {m:e} vs {expected:e} (se {se:e})"
            );
        }
    }

    #[test]
    fn definition_by_quadrature() {
        // Brute-force the defining integrals with Gauss-Legendre on the sub-rectangles
        // cut by the point coordinates (the integrands are polynomial there).
        let mut rng = SplitMix64::new(5);
        let pts = random_points(&mut rng, 7);
        let n = pts.len() as f64;
        let star = crate::metrics::test_util::integrate_pieces(&pts, &[], &[], |a| {
            let c = pts.iter().filter(|p| p.x <= a.x && p.y <= a.y).count() as f64;
            (c / n - a.x * a.y).powi(2)
        });
        assert!(close(l2_star_uniform_squared(&pts), star, 1e-12));
        let asd = crate::metrics::test_util::integrate_pieces(&pts, &[], &[], |u| {
            let mut acc = 0.0;
            for (lo, hi) in crate::metrics::test_util::corner_boxes(u) {
                let c = pts
                    .iter()
                    .filter(|p| p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y)
                    .count() as f64;
                let vol = (hi.x - lo.x) * (hi.y - lo.y);
                acc += 0.25 * (c / n - vol).powi(2);
            }
            acc
        });
        assert!(close(asd_uniform_squared(&pts), asd, 1e-12));
    }
}
