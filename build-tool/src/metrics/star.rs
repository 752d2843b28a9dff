//! Exact star discrepancy in 2D (Bundschuh–Zhu, `O(N^2)`) for any atomless target
//! measure given by its CDF, and a brute-force reference over the critical grid.

use glam::DVec2;
use rayon::prelude::*;

use crate::density::Density2D;

/// Values of `l` handled by one task in [`star_discrepancy_par`]; fixed, and the
/// reduction is a maximum, so the result does not depend on the thread count.
const L_CHUNK: usize = 128;

/// Exact star discrepancy of `points` for the measure with CDF
/// `cdf(a, b) = mu([0,a] x [0,b])` (any atomless `mu`; `|a, b| a * b` for uniform):
///
/// `D* = sup_a |#{x_i in [0,a)}/N - F(a)|`, equal to the same supremum over closed
/// boxes `[0,a]`.
///
/// Bundschuh–Zhu (docs/metrics.md): sort by `x` with sentinels `x_0 = 0`, `x_{N+1} = 1`;
/// for `l = 0..=N` let `xi_{l,1..=l}` be the sorted `y` of the first `l` points,
/// `xi_{l,0} = 0`, `xi_{l,l+1} = 1`; then
/// `D* = max_l max_{k<=l} max(k/N - F(x_l, xi_{l,k}), F(x_{l+1}, xi_{l,k+1}) - k/N)`.
/// With ties every term is still the discrepancy of some box bound (never an
/// over-estimate) and the extremal boxes are reached at the last/first members of tie
/// groups, so ties, duplicates and points on the boundary are exact.
/// `O(N^2)` time and `2 (N+1)(N+2)/2` CDF calls, `O(N)` memory; sequential.
/// Returns the discrepancy (not squared). Panics if `points` is empty.
pub fn star_discrepancy(points: &[DVec2], cdf: &dyn Fn(f64, f64) -> f64) -> f64 {
    let (xs, ys) = sorted_by_x(points);
    bundschuh_zhu(&xs, &ys, 0..xs.len() + 1, cdf)
}

/// [`star_discrepancy`] parallelized over `l` in fixed chunks (each chunk re-sorts its
/// prefix of `y` once); the maximum is exact, so the result is bit-identical to the
/// sequential one. `O(N^2)` work. Panics if `points` is empty.
pub fn star_discrepancy_par(points: &[DVec2], cdf: &(dyn Fn(f64, f64) -> f64 + Sync)) -> f64 {
    let (xs, ys) = sorted_by_x(points);
    let n = xs.len();
    (0..n / L_CHUNK + 1)
        .into_par_iter()
        .map(|chunk| {
            let start = chunk * L_CHUNK;
            let end = (start + L_CHUNK).min(n + 1);
            bundschuh_zhu(&xs, &ys, start..end, &|a, b| cdf(a, b))
        })
        .reduce(|| 0.0, f64::max)
}

/// Exact star discrepancy for the uniform measure, `F(a, b) = a b` (see
/// [`star_discrepancy`]). `O(N^2)`, parallel and deterministic. Panics if `points` is
/// empty.
pub fn star_discrepancy_uniform(points: &[DVec2]) -> f64 {
    star_discrepancy_par(points, &|a, b| a * b)
}

/// Exact star discrepancy for a target density, `F(a, b) = density.cdf((a, b))` (see
/// [`star_discrepancy`]). `O(N^2)` CDF evaluations, parallel and deterministic. Panics
/// if `points` is empty.
pub fn star_discrepancy_density(points: &[DVec2], density: &dyn Density2D) -> f64 {
    star_discrepancy_par(points, &|a, b| density.cdf(DVec2::new(a, b)))
}

/// Brute-force star discrepancy for tests: the maximum over the critical grid
/// `a in {x_i} ∪ {1}`, `b in {y_i} ∪ {1}` of both `|#{x_i in [0,a]}/N - F(a,b)|` and
/// `|F(a,b) - #{x_i in [0,a)}/N|` (closed and open boxes). `O(N^3)`; meant for
/// `N <= 64`. Panics if `points` is empty.
pub fn star_discrepancy_brute_force(points: &[DVec2], cdf: &dyn Fn(f64, f64) -> f64) -> f64 {
    assert!(
        !points.is_empty(),
        "discrepancy of an empty point set is undefined"
    );
    let n = points.len() as f64;
    let xs: Vec<f64> = points.iter().map(|p| p.x).chain([1.0]).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.y).chain([1.0]).collect();
    let mut d = 0.0f64;
    for &a in &xs {
        for &b in &ys {
            let closed = points.iter().filter(|p| p.x <= a && p.y <= b).count() as f64;
            let open = points.iter().filter(|p| p.x < a && p.y < b).count() as f64;
            let f = cdf(a, b);
            d = d.max((closed / n - f).abs()).max((f - open / n).abs());
        }
    }
    d
}

/// `x` ascending and the `y` in that order.
fn sorted_by_x(points: &[DVec2]) -> (Vec<f64>, Vec<f64>) {
    assert!(
        !points.is_empty(),
        "discrepancy of an empty point set is undefined"
    );
    let mut p = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    (
        p.iter().map(|q| q.x).collect(),
        p.iter().map(|q| q.y).collect(),
    )
}

/// The Bundschuh–Zhu maximum over `l` in `ls` (see [`star_discrepancy`]).
fn bundschuh_zhu(
    xs: &[f64],
    ys: &[f64],
    ls: std::ops::Range<usize>,
    cdf: &dyn Fn(f64, f64) -> f64,
) -> f64 {
    let n = xs.len();
    let nf = n as f64;
    let mut xi: Vec<f64> = ys[..ls.start].to_vec();
    xi.sort_by(f64::total_cmp);
    xi.reserve(ls.end.saturating_sub(ls.start));
    let mut d = 0.0f64;
    for l in ls.clone() {
        if l > ls.start {
            let y = ys[l - 1];
            let at = xi.partition_point(|&v| v <= y);
            xi.insert(at, y);
        }
        let x_l = if l == 0 { 0.0 } else { xs[l - 1] };
        let x_next = if l == n { 1.0 } else { xs[l] };
        for k in 0..=l {
            let lower = if k == 0 { 0.0 } else { xi[k - 1] };
            let upper = if k == l { 1.0 } else { xi[k] };
            let kn = k as f64 / nf;
            d = d.max(kn - cdf(x_l, lower)).max(cdf(x_next, upper) - kn);
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::test_util::{hammersley, random_points, SplitMix64};

    /// Best-known (optimal) star discrepancy for N = 1..20, docs/metrics.md (4 decimals).
    const FLOOR: [f64; 20] = [
        0.6180, 0.3660, 0.2847, 0.2500, 0.2000, 0.1667, 0.1500, 0.1328, 0.1235, 0.1111, 0.1030,
        0.0952, 0.0889, 0.0837, 0.0782, 0.0739, 0.0699, 0.0666, 0.0634, 0.0604,
    ];

    fn uniform(a: f64, b: f64) -> f64 {
        a * b
    }

    fn ramp(a: f64, b: f64) -> f64 {
        a * a * b
    }

    #[test]
    fn hammersley_reference_values() {
        for (n, reference) in [
            (16, 0.171875),
            (64, 0.053711),
            (256, 0.016052),
            (1024, 0.004665),
        ] {
            let d = star_discrepancy_uniform(&hammersley(n));
            // Printed to 6 decimals.
            assert!(
                (d - reference).abs() <= 5.000001e-7,
                "N={n}: {d} vs {reference}"
            );
        }
    }

    #[test]
    fn single_centre_point() {
        let pts = [DVec2::splat(0.5)];
        assert!((star_discrepancy_uniform(&pts) - 0.75).abs() < 1e-15);
        assert!((star_discrepancy(&pts, &uniform) - 0.75).abs() < 1e-15);
        assert!((star_discrepancy_brute_force(&pts, &uniform) - 0.75).abs() < 1e-15);
    }

    #[test]
    fn matches_brute_force_random() {
        let mut rng = SplitMix64::new(99);
        for &n in &[1usize, 2, 5, 17, 40] {
            for _ in 0..20 {
                let pts = random_points(&mut rng, n);
                for cdf in [&uniform as &dyn Fn(f64, f64) -> f64, &ramp] {
                    let (a, b) = (
                        star_discrepancy(&pts, cdf),
                        star_discrepancy_brute_force(&pts, cdf),
                    );
                    assert!((a - b).abs() < 1e-14, "n={n}: {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn matches_brute_force_with_ties_and_boundary() {
        // Lattice coordinates: ties in x and y, duplicates, points on the square's edges.
        let mut rng = SplitMix64::new(5);
        for &n in &[1usize, 2, 3, 5, 17, 40] {
            for _ in 0..30 {
                let pts: Vec<DVec2> = (0..n)
                    .map(|_| {
                        DVec2::new(
                            (rng.next_f64() * 5.0).floor() / 4.0,
                            (rng.next_f64() * 6.0).floor() / 5.0,
                        )
                    })
                    .collect();
                for cdf in [&uniform as &dyn Fn(f64, f64) -> f64, &ramp] {
                    let (a, b) = (
                        star_discrepancy(&pts, cdf),
                        star_discrepancy_brute_force(&pts, cdf),
                    );
                    assert!((a - b).abs() < 1e-14, "n={n} {pts:?}: {a} vs {b}");
                }
            }
        }
        // Corner cases by hand: one point at the origin / at (1,1).
        assert!((star_discrepancy_uniform(&[DVec2::ZERO]) - 1.0).abs() < 1e-15);
        assert!((star_discrepancy_uniform(&[DVec2::ONE]) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn parallel_matches_sequential() {
        let mut rng = SplitMix64::new(8);
        let pts = random_points(&mut rng, 700);
        let a = star_discrepancy(&pts, &ramp);
        let b = star_discrepancy_par(&pts, &ramp);
        assert_eq!(a.to_bits(), b.to_bits());
    }

    #[test]
    fn optimal_sets_are_a_floor() {
        let mut rng = SplitMix64::new(123);
        for n in 1..=20usize {
            for _ in 0..50 {
                let d = star_discrepancy_uniform(&random_points(&mut rng, n));
                assert!(
                    d >= FLOOR[n - 1] - 5e-5,
                    "n={n}: {d} below {}",
                    FLOOR[n - 1]
                );
            }
        }
        // The optimal single point (g, g), g = 1/phi, attains the N=1 floor.
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let d = star_discrepancy_uniform(&[DVec2::splat(g)]);
        assert!((d - g).abs() < 1e-12, "{d}");
    }

    struct Ramp;

    impl Density2D for Ramp {
        fn spec(&self) -> String {
            "test-ramp".into()
        }
        fn pdf(&self, p: DVec2) -> f64 {
            2.0 * p.x
        }
        fn cdf(&self, p: DVec2) -> f64 {
            let p = p.clamp(DVec2::ZERO, DVec2::ONE);
            p.x * p.x * p.y
        }
        fn inverse_cdf(&self, u: DVec2) -> DVec2 {
            DVec2::new(u.x.sqrt(), u.y)
        }
    }

    #[test]
    fn density_wrapper_uses_the_cdf() {
        let mut rng = SplitMix64::new(4);
        let pts = random_points(&mut rng, 30);
        let a = star_discrepancy_density(&pts, &Ramp);
        let b = star_discrepancy_brute_force(&pts, &ramp);
        assert!((a - b).abs() < 1e-14);
    }
}
