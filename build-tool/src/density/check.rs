//! Test-only harness: generic consistency checks for any [`Density2D`], against
//! independent numerical integration of its `pdf`.

use super::Density2D;
use glam::{DMat2, DVec2};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// What to check and how tightly.
#[derive(Clone, Debug)]
pub(crate) struct Checks {
    /// Tolerance of `cdf` / `measure` / total mass against adaptive integration.
    pub tol: f64,
    /// Tolerance of the total mass by a 1024^2 midpoint rule.
    pub midpoint_tol: f64,
    /// `x` positions where the density jumps (integration splits there).
    pub x_breaks: Vec<f64>,
    /// Also require `pdf(T(u)) > 0` for `u` on the boundary of the unit square.
    pub boundary: bool,
    /// Side of the stratified grid of `u` used for the empirical-CDF check.
    pub strat: usize,
    /// Minimum recursion depth of the adaptive integration (resolves narrow peaks).
    pub min_depth: u32,
}

impl Checks {
    /// Defaults for a smooth density.
    pub fn smooth() -> Self {
        Self {
            tol: 1e-8,
            // Midpoint-rule error (h^2/24) ∫ q'' for steep Gaussians reaches ~1e-5.
            midpoint_tol: 1e-4,
            x_breaks: Vec::new(),
            boundary: false,
            strat: 256,
            min_depth: 4,
        }
    }
    /// Defaults for a density with jumps (midpoint rule only to ~1e-3).
    pub fn discontinuous() -> Self {
        Self {
            midpoint_tol: 2e-3,
            ..Self::smooth()
        }
    }
    /// Adds `x` positions of jumps.
    pub fn with_x_breaks(mut self, b: &[f64]) -> Self {
        self.x_breaks.extend_from_slice(b);
        self
    }
    /// Requires positive density at the image of boundary `u` too.
    pub fn boundary(mut self) -> Self {
        self.boundary = true;
        self
    }
}

/// Adaptive Simpson with a fixed (non-halving) absolute tolerance per interval,
/// which also converges across jumps (the interval holding a jump shrinks until
/// its contribution is below `eps`).
pub(crate) fn adaptive_simpson(
    f: &dyn Fn(f64) -> f64,
    a: f64,
    b: f64,
    eps: f64,
    min_depth: u32,
) -> f64 {
    #[allow(clippy::too_many_arguments)]
    fn rec(
        f: &dyn Fn(f64) -> f64,
        a: f64,
        b: f64,
        fa: f64,
        fm: f64,
        fb: f64,
        whole: f64,
        eps: f64,
        depth: u32,
        min_depth: u32,
    ) -> f64 {
        let m = 0.5 * (a + b);
        let lm = 0.5 * (a + m);
        let rm = 0.5 * (m + b);
        let flm = f(lm);
        let frm = f(rm);
        let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
        let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
        let delta = left + right - whole;
        if depth >= 50 || (depth >= min_depth && delta.abs() <= 15.0 * eps) {
            return left + right + delta / 15.0;
        }
        rec(f, a, m, fa, flm, fm, left, eps, depth + 1, min_depth)
            + rec(f, m, b, fm, frm, fb, right, eps, depth + 1, min_depth)
    }
    if b <= a {
        return 0.0;
    }
    let m = 0.5 * (a + b);
    let (fa, fm, fb) = (f(a), f(m), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    rec(f, a, b, fa, fm, fb, whole, eps, 0, min_depth)
}

/// `∫∫_[lo,hi] pdf` by nested adaptive Simpson, split at the `x` breaks.
pub(crate) fn integrate_box(d: &dyn Density2D, lo: DVec2, hi: DVec2, c: &Checks) -> f64 {
    let inner =
        |x: f64| adaptive_simpson(&|y| d.pdf(DVec2::new(x, y)), lo.y, hi.y, 1e-14, c.min_depth);
    let mut cuts = vec![lo.x];
    cuts.extend(c.x_breaks.iter().copied().filter(|&b| b > lo.x && b < hi.x));
    cuts.push(hi.x);
    cuts.windows(2)
        .map(|w| adaptive_simpson(&inner, w[0], w[1], 1e-12, c.min_depth))
        .sum()
}

/// Frobenius norm of a 2x2 matrix.
fn norm(m: DMat2) -> f64 {
    (m.x_axis.length_squared() + m.y_axis.length_squared()).sqrt()
}

/// Runs every generic check; panics with a message on the first failure.
pub(crate) fn check_density(d: &dyn Density2D, c: &Checks) {
    let name = d.spec();
    let mut rng = Pcg64::seed_from_u64(0x5eed_d00d);
    let mut rnd = || DVec2::new(rng.random::<f64>(), rng.random::<f64>());

    // 1. Normalization: midpoint rule and adaptive integration.
    let n = 1024;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            sum += d.pdf(DVec2::new(
                (i as f64 + 0.5) / n as f64,
                (j as f64 + 0.5) / n as f64,
            ));
        }
    }
    let mid = sum / (n * n) as f64;
    assert!(
        (mid - 1.0).abs() < c.midpoint_tol,
        "{name}: midpoint mass {mid}"
    );
    let total = integrate_box(d, DVec2::ZERO, DVec2::ONE, c);
    assert!((total - 1.0).abs() < c.tol, "{name}: adaptive mass {total}");

    // 2. CDF corners and clamping.
    assert!(
        (d.cdf(DVec2::ONE) - 1.0).abs() < 1e-12,
        "{name}: cdf(1,1) = {}",
        d.cdf(DVec2::ONE)
    );
    assert!(
        (d.cdf(DVec2::splat(3.0)) - 1.0).abs() < 1e-12,
        "{name}: cdf clamp"
    );
    for t in [0.0, 0.3, 1.0] {
        assert!(
            d.cdf(DVec2::new(0.0, t)).abs() < 1e-15,
            "{name}: cdf(0,{t})"
        );
        assert!(
            d.cdf(DVec2::new(t, 0.0)).abs() < 1e-15,
            "{name}: cdf({t},0)"
        );
        assert!(
            d.cdf(DVec2::new(-1.0, t)).abs() < 1e-15,
            "{name}: cdf(-1,{t})"
        );
    }

    // 3. CDF against integration of the pdf.
    for _ in 0..8 {
        let p = rnd();
        let num = integrate_box(d, DVec2::ZERO, p, c);
        let cdf = d.cdf(p);
        assert!(
            (cdf - num).abs() < c.tol,
            "{name}: cdf({p}) = {cdf} vs numeric {num}"
        );
    }

    // 4. Measure of random boxes.
    for _ in 0..8 {
        let (a, b) = (rnd(), rnd());
        let (lo, hi) = (a.min(b), a.max(b));
        let m = d.measure(lo, hi);
        let num = integrate_box(d, lo, hi, c);
        assert!(
            (m - num).abs() < c.tol,
            "{name}: measure({lo},{hi}) = {m} vs {num}"
        );
        let ie =
            d.cdf(hi) - d.cdf(DVec2::new(lo.x, hi.y)) - d.cdf(DVec2::new(hi.x, lo.y)) + d.cdf(lo);
        assert!(
            (m - ie).abs() < 1e-12,
            "{name}: measure vs cdf inclusion-exclusion"
        );
        assert!(
            d.measure(hi, lo) == 0.0 || d.measure(hi, lo) < 1e-15,
            "{name}: reversed box"
        );
        assert!(
            d.measure(lo, DVec2::new(lo.x, hi.y)).abs() < 1e-15,
            "{name}: flat box"
        );
    }
    assert!((d.measure(DVec2::ZERO, DVec2::ONE) - 1.0).abs() < 1e-12);

    // 5. Stratified uniform grid through the inverse CDF: empirical CDF vs cdf().
    let m = c.strat;
    let mut pts = Vec::with_capacity(m * m);
    for j in 0..m {
        for i in 0..m {
            let u = DVec2::new((i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64);
            let p = d.inverse_cdf(u);
            assert!(
                p.x >= 0.0 && p.x <= 1.0 && p.y >= 0.0 && p.y <= 1.0,
                "{name}: T({u}) = {p} outside the square"
            );
            assert!(d.pdf(p) > 0.0, "{name}: T({u}) = {p} has zero density");
            pts.push(p);
        }
    }
    let mut max_err: f64 = 0.0;
    let mut tests: Vec<DVec2> = (0..48).map(|_| rnd()).collect();
    for i in 1..=4 {
        for j in 1..=4 {
            tests.push(DVec2::new(i as f64 / 4.0, j as f64 / 4.0));
        }
    }
    for t in tests {
        let emp = pts.iter().filter(|p| p.x <= t.x && p.y <= t.y).count() as f64 / pts.len() as f64;
        max_err = max_err.max((emp - d.cdf(t)).abs());
    }
    assert!(
        max_err < 3.0 / m as f64,
        "{name}: empirical CDF error {max_err} (M = {m})"
    );

    // 6. Boundary u.
    for ux in [0.0, 1e-300, 0.5, 1.0 - 1e-16, 1.0] {
        for uy in [0.0, 1e-300, 0.5, 1.0 - 1e-16, 1.0] {
            let u = DVec2::new(ux, uy);
            let p = d.inverse_cdf(u);
            assert!(
                p.is_finite() && p.cmpge(DVec2::ZERO).all() && p.cmple(DVec2::ONE).all(),
                "{name}: T({u}) = {p}"
            );
            if c.boundary {
                assert!(d.pdf(p) > 0.0, "{name}: T({u}) = {p} has zero density");
            }
        }
    }

    // 7.-9. Jacobian vs central differences, change of variables, marginal inverse.
    let h = 1e-6;
    let mut checked = 0;
    for _ in 0..64 {
        let u = DVec2::splat(0.02) + 0.96 * rnd();
        let p = d.inverse_cdf(u);
        let j = d.inverse_cdf_jacobian(u);
        // Skip kinks: the analytic Jacobian must be locally (almost) constant.
        let near = [DVec2::new(h, 0.0), DVec2::new(0.0, h)]
            .iter()
            .flat_map(|&e| [u + e, u - e])
            .map(|v| norm(d.inverse_cdf_jacobian(v) - j) / norm(j))
            .fold(0.0_f64, f64::max);
        let fx = (d.inverse_cdf(u + DVec2::new(h, 0.0)) - d.inverse_cdf(u - DVec2::new(h, 0.0)))
            / (2.0 * h);
        let fy = (d.inverse_cdf(u + DVec2::new(0.0, h)) - d.inverse_cdf(u - DVec2::new(0.0, h)))
            / (2.0 * h);
        let fd = DMat2::from_cols(fx, fy);
        if near < 1e-3 {
            checked += 1;
            let err = norm(fd - j) / norm(j);
            assert!(
                err < 1e-5,
                "{name}: Jacobian at {u}: analytic {j} vs differences {fd}"
            );
        }
        let cov = j.determinant() * d.pdf(p);
        assert!(
            (cov - 1.0).abs() < 1e-9,
            "{name}: det J * pdf = {cov} at u = {u}"
        );
        let fx_marg = d.cdf(DVec2::new(p.x, 1.0));
        assert!(
            (fx_marg - u.x).abs() < 1e-12,
            "{name}: F_X(T(u).x) = {fx_marg} vs u.x = {}",
            u.x
        );
    }
    assert!(
        checked >= 32,
        "{name}: only {checked} Jacobians away from kinks"
    );

    // 10. Cell tabulation.
    let cells = d.cells(16);
    let total: f64 = cells.mass.iter().sum();
    assert_eq!(cells.mass.len(), cells.width * cells.height);
    assert!((total - 1.0).abs() < 1e-12, "{name}: cells sum {total}");
    for row in 0..cells.height {
        for col in 0..cells.width {
            let lo = DVec2::new(
                col as f64 / cells.width as f64,
                row as f64 / cells.height as f64,
            );
            let hi = DVec2::new(
                (col + 1) as f64 / cells.width as f64,
                (row + 1) as f64 / cells.height as f64,
            );
            let m = cells.mass[row * cells.width + col];
            assert!(m >= 0.0);
            assert!(
                (m - d.measure(lo, hi)).abs() < 1e-12,
                "{name}: cell ({col},{row})"
            );
        }
    }
}
