//! Independent uniform random points: the Monte Carlo baseline.

use glam::DVec2;
use rand::Rng;

use super::streams;
use crate::seeding::rng;

/// `n` independent uniform points in `[0,1)^2`, drawn from
/// [`crate::seeding::rng`]`(seed, ..)` (PCG64-MCG, 53-bit floats). For `n` iid points
/// the expected squared L2-star and average squared discrepancies are both
/// `(5/36)/n` (docs/metrics.md). `O(n)`.
pub fn random(n: usize, seed: u64) -> Vec<DVec2> {
    let mut r = rng(seed, streams::RANDOM);
    (0..n)
        .map(|_| DVec2::new(r.random::<f64>(), r.random::<f64>()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::asd_uniform_squared;

    #[test]
    fn coordinates_are_uniform() {
        let pts = random(200_000, 7);
        assert!(pts
            .iter()
            .all(|p| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)));
        let n = pts.len() as f64;
        for c in [0, 1] {
            let mean = pts.iter().map(|p| p[c]).sum::<f64>() / n;
            let var = pts.iter().map(|p| (p[c] - mean).powi(2)).sum::<f64>() / (n - 1.0);
            // s.e. of the mean: sqrt(1/12 / n) = 6.5e-4; of the variance: ~1.7e-4.
            assert!(
                (mean - 0.5).abs() < 4.0 * (1.0 / 12.0 / n).sqrt(),
                "mean {mean}"
            );
            assert!((var - 1.0 / 12.0).abs() < 1e-3, "var {var}");
        }
        let cov = pts.iter().map(|p| (p.x - 0.5) * (p.y - 0.5)).sum::<f64>() / n;
        assert!(cov.abs() < 4.0 * (1.0 / 144.0 / n).sqrt(), "cov {cov}");
    }

    #[test]
    fn expected_asd_is_five_36ths_over_n() {
        let n = 64;
        let sets = 4000u64;
        let v: Vec<f64> = (0..sets)
            .map(|s| asd_uniform_squared(&random(n, s)))
            .collect();
        let m = v.iter().sum::<f64>() / sets as f64;
        let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (sets as f64 - 1.0);
        let se = (var / sets as f64).sqrt();
        let want = 5.0 / 36.0 / n as f64;
        assert!(
            (m - want).abs() < 3.0 * se,
            "mean {m} vs {want} (s.e. {se})"
        );
    }

    #[test]
    fn seed_fixes_the_output() {
        assert_eq!(random(10, 3), random(10, 3));
        assert_ne!(random(10, 3), random(10, 4));
    }
}
