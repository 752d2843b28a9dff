//! Separable Gaussian densities: `gaussian:MX,MY,SIGMA` (an isotropic Gaussian
//! truncated to the square) and `step-gaussian` (`∝ 1[x < 1/pi] exp(-x^2 - y^2)`).
//!
//! Both are products of two 1D truncated normals, so the CDF, the measure of a box
//! and the inverse CDF factor per axis. The 1D masses are differences of `erf`
//! values computed without cancellation and without underflow (tail masses are
//! carried as `v * exp(-z(anchor)^2)`), so even a mean far outside the square (an
//! essentially exponential density) is normalized exactly.

use super::numeric::{next_down, solve_increasing};
use super::special::{erf, erfcx};
use super::{fmt_num, Density2D, DensityError};
use glam::{DMat2, DVec2};
use std::f64::consts::{FRAC_1_PI, FRAC_2_SQRT_PI, SQRT_2};

/// A non-negative mass `v * exp(-z(anchor)^2)` (in units of `erf` differences,
/// i.e. `(2/sqrt(pi)) ∫ exp(-t^2) dt`), where `anchor` is an `x` position and
/// `z(x) = (x - mean)/scale`. Keeping the anchor as an `x` lets exponents be formed
/// from exact `x` differences, so far tails keep their relative accuracy.
#[derive(Clone, Copy, Debug)]
struct Mass {
    v: f64,
    anchor: f64,
}

/// The 1D normal density `∝ exp(-(x - mean)^2 / (2 sigma^2))` restricted to
/// `[lo, hi]` and normalized there.
#[derive(Clone, Debug)]
pub(crate) struct TruncNormal {
    lo: f64,
    hi: f64,
    mean: f64,
    /// `sigma * sqrt(2)`: `z = (x - mean) / scale` is the `erf` argument.
    scale: f64,
    total: Mass,
    /// `(2/sqrt(pi)) / (scale * total.v)`: the pdf is
    /// `pdf_coef * exp(z(anchor)^2 - z(x)^2)`.
    pdf_coef: f64,
}

impl TruncNormal {
    /// `None` if the mass over `[lo, hi]` is zero or not finite.
    pub(crate) fn new(mean: f64, sigma: f64, lo: f64, hi: f64) -> Option<Self> {
        let scale = sigma * SQRT_2;
        let mut t = Self {
            lo,
            hi,
            mean,
            scale,
            total: Mass {
                v: 0.0,
                anchor: mean,
            },
            pdf_coef: 0.0,
        };
        t.total = t.mass(lo, hi);
        t.pdf_coef = FRAC_2_SQRT_PI / (scale * t.total.v);
        let ok = t.total.v > 0.0 && t.total.v.is_finite() && t.pdf_coef.is_finite();
        if !ok {
            return None;
        }
        Some(t)
    }

    fn z(&self, x: f64) -> f64 {
        (x - self.mean) / self.scale
    }

    /// `z(a)^2 - z(b)^2`, from the exact differences `b - a` and `a + b - 2 mean`.
    fn sq_diff(&self, a: f64, b: f64) -> f64 {
        -((b - a) / self.scale) * ((a - self.mean) + (b - self.mean)) / self.scale
    }

    /// `erf(z(b)) - erf(z(a))` for `a <= b`, accurately in both tails, without
    /// underflow.
    fn mass(&self, a: f64, b: f64) -> Mass {
        if b <= a {
            return Mass {
                v: 0.0,
                anchor: self.mean,
            };
        }
        let (p, q) = (self.z(a), self.z(b));
        if p >= 0.5 {
            // Upper tail: erfc(p) - erfc(q) = exp(-p^2) (erfcx(p) - erfcx(q) exp(p^2 - q^2)).
            Mass {
                v: erfcx(p) - erfcx(q) * self.sq_diff(a, b).exp(),
                anchor: a,
            }
        } else if q <= -0.5 {
            // Lower tail, by symmetry: exp(-q^2) (erfcx(-q) - erfcx(-p) exp(q^2 - p^2)).
            Mass {
                v: erfcx(-q) - erfcx(-p) * (-self.sq_diff(a, b)).exp(),
                anchor: b,
            }
        } else {
            Mass {
                v: erf(q) - erf(p),
                anchor: self.mean,
            }
        }
    }

    /// `m / total`.
    fn ratio(&self, m: Mass) -> f64 {
        if m.v == 0.0 {
            return 0.0;
        }
        // exp(z(m.anchor)^2 - z(total.anchor)^2) * m.v / total.v, exponent <= 0.
        let e = self.sq_diff(m.anchor, self.total.anchor);
        (m.v / self.total.v * (-e).exp()).min(1.0)
    }

    /// Normalized density at `x` (0 outside `[lo, hi]`).
    pub(crate) fn pdf(&self, x: f64) -> f64 {
        if !(self.lo..=self.hi).contains(&x) {
            return 0.0;
        }
        self.pdf_inside(x)
    }

    fn pdf_inside(&self, x: f64) -> f64 {
        self.pdf_coef * self.sq_diff(self.total.anchor, x).exp()
    }

    /// `P(X <= x)`, clamped to `[0, 1]`.
    pub(crate) fn cdf(&self, x: f64) -> f64 {
        if x <= self.lo {
            0.0
        } else if x >= self.hi {
            1.0
        } else {
            self.ratio(self.mass(self.lo, x))
        }
    }

    /// `P(a <= X <= b)`, computed directly (no difference of CDFs).
    pub(crate) fn prob(&self, a: f64, b: f64) -> f64 {
        self.ratio(self.mass(a.max(self.lo), b.min(self.hi)))
    }

    /// `F^-1(u)` in `[lo, hi]`, to a few ulps of `u` (safeguarded Newton).
    pub(crate) fn inv(&self, u: f64) -> f64 {
        if u.is_nan() || u <= 0.0 {
            return self.lo;
        }
        if u >= 1.0 {
            return self.hi;
        }
        let x0 = self.lo + u * (self.hi - self.lo);
        solve_increasing(
            |x| (self.cdf(x), self.pdf_inside(x)),
            u,
            self.lo,
            self.hi,
            x0,
        )
    }
}

/// The product of two 1D truncated normals, `q(x, y) = f_X(x) f_Y(y)`.
#[derive(Clone, Debug)]
struct Product {
    gx: TruncNormal,
    gy: TruncNormal,
}

impl Product {
    fn pdf(&self, p: DVec2) -> f64 {
        self.gx.pdf(p.x) * self.gy.pdf(p.y)
    }
    fn cdf(&self, p: DVec2) -> f64 {
        self.gx.cdf(p.x) * self.gy.cdf(p.y)
    }
    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        self.gx.prob(lo.x, hi.x) * self.gy.prob(lo.y, hi.y)
    }
    fn inverse_cdf(&self, u: DVec2) -> DVec2 {
        DVec2::new(self.gx.inv(u.x), self.gy.inv(u.y))
    }
    fn jacobian(&self, u: DVec2) -> DMat2 {
        let p = self.inverse_cdf(u);
        DMat2::from_diagonal(DVec2::new(
            1.0 / self.gx.pdf_inside(p.x),
            1.0 / self.gy.pdf_inside(p.y),
        ))
    }
}

/// `gaussian:MX,MY,SIGMA`: the isotropic Gaussian
/// `q(x, y) = exp(-((x-MX)^2 + (y-MY)^2) / (2 SIGMA^2)) / Z` truncated to `[0,1]^2`,
/// with `Z = 2 pi SIGMA^2 (Φ((1-MX)/SIGMA) - Φ(-MX/SIGMA)) (Φ((1-MY)/SIGMA) - Φ(-MY/SIGMA))`
/// (`Φ` the standard normal CDF). MX, MY are in square units and may lie outside
/// `[0,1]`; SIGMA > 0 in square units.
///
/// Separable: `F(x, y) = F_X(x) F_Y(y)`; the inverse CDF solves each 1D truncated
/// normal CDF by safeguarded Newton to a few ulps; its Jacobian is
/// `diag(1/f_X(x), 1/f_Y(y))`.
#[derive(Clone, Debug)]
pub struct TruncatedGaussian {
    mx: f64,
    my: f64,
    sigma: f64,
    inner: Product,
}

impl TruncatedGaussian {
    /// Builds the density; errors if a parameter is not finite, `sigma <= 0`, or
    /// the mass over the square is zero / not finite in `f64`.
    pub fn new(mx: f64, my: f64, sigma: f64) -> Result<Self, DensityError> {
        for (param, value) in [("MX", mx), ("MY", my), ("SIGMA", sigma)] {
            if !value.is_finite() {
                return Err(DensityError::NonFinite {
                    kind: "gaussian",
                    param,
                    value,
                });
            }
        }
        if sigma <= 0.0 {
            return Err(DensityError::NonPositive {
                kind: "gaussian",
                param: "SIGMA",
                value: sigma,
            });
        }
        let spec = format!(
            "gaussian:{},{},{}",
            fmt_num(mx),
            fmt_num(my),
            fmt_num(sigma)
        );
        let gx = TruncNormal::new(mx, sigma, 0.0, 1.0);
        let gy = TruncNormal::new(my, sigma, 0.0, 1.0);
        match (gx, gy) {
            (Some(gx), Some(gy)) => Ok(Self {
                mx,
                my,
                sigma,
                inner: Product { gx, gy },
            }),
            _ => Err(DensityError::ZeroMass { what: spec }),
        }
    }

    /// The mean `(MX, MY)` of the untruncated Gaussian.
    pub fn mean(&self) -> DVec2 {
        DVec2::new(self.mx, self.my)
    }

    /// The standard deviation SIGMA of the untruncated Gaussian.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }
}

impl Density2D for TruncatedGaussian {
    fn spec(&self) -> String {
        format!(
            "gaussian:{},{},{}",
            fmt_num(self.mx),
            fmt_num(self.my),
            fmt_num(self.sigma)
        )
    }
    fn pdf(&self, p: DVec2) -> f64 {
        self.inner.pdf(p)
    }
    fn cdf(&self, p: DVec2) -> f64 {
        self.inner.cdf(p)
    }
    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        self.inner.measure(lo, hi)
    }
    fn inverse_cdf(&self, u: DVec2) -> DVec2 {
        self.inner.inverse_cdf(u)
    }
    fn inverse_cdf_jacobian(&self, u: DVec2) -> DMat2 {
        self.inner.jacobian(u)
    }
}

/// `step-gaussian`: `q(x, y) = 1[x < 1/pi] exp(-x^2 - y^2) / Z` on `[0,1]^2`, with
/// `Z = (pi/4) erf(1/pi) erf(1) ≈ 0.2317`.
///
/// Separable: `x` is a normal (mean 0, sigma `1/sqrt 2`) truncated to
/// `[0, 1/pi)`, `y` the same truncated to `[0, 1]`. The inverse CDF never returns
/// `x >= 1/pi` (the largest `x` it returns is the `f64` just below `1/pi`), so it
/// never lands where the density is 0.
#[derive(Clone, Debug)]
pub struct StepGaussian {
    inner: Product,
}

impl StepGaussian {
    /// The `x` where the density steps to zero: `1/pi` (as an `f64`).
    pub const X_STEP: f64 = FRAC_1_PI;

    /// Builds the density (it has no parameters).
    pub fn new() -> Self {
        let sigma = std::f64::consts::FRAC_1_SQRT_2;
        let gx = TruncNormal::new(0.0, sigma, 0.0, Self::X_STEP).expect("positive mass");
        let gy = TruncNormal::new(0.0, sigma, 0.0, 1.0).expect("positive mass");
        Self {
            inner: Product { gx, gy },
        }
    }
}

impl Default for StepGaussian {
    fn default() -> Self {
        Self::new()
    }
}

impl Density2D for StepGaussian {
    fn spec(&self) -> String {
        "step-gaussian".to_string()
    }
    fn pdf(&self, p: DVec2) -> f64 {
        if p.x < Self::X_STEP {
            self.inner.pdf(p)
        } else {
            0.0
        }
    }
    fn cdf(&self, p: DVec2) -> f64 {
        self.inner.cdf(p)
    }
    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        self.inner.measure(lo, hi)
    }
    fn inverse_cdf(&self, u: DVec2) -> DVec2 {
        let p = self.inner.inverse_cdf(u);
        DVec2::new(p.x.min(next_down(Self::X_STEP)), p.y)
    }
    fn inverse_cdf_jacobian(&self, u: DVec2) -> DMat2 {
        self.inner.jacobian(u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::check::{check_density, Checks};
    use crate::density::special::erfc;

    #[test]
    fn gaussian_generic_checks() {
        for (mx, my, s) in [
            (0.5, 0.5, 0.15),
            (0.3, 0.7, 0.05),
            (0.2, 0.9, 1.0),
            (-0.5, 1.3, 0.2),
            (0.5, 0.5, 100.0),
        ] {
            let g = TruncatedGaussian::new(mx, my, s).unwrap();
            check_density(&g, &Checks::smooth());
        }
    }

    #[test]
    fn step_gaussian_generic_checks() {
        let d = StepGaussian::new();
        check_density(
            &d,
            &Checks::discontinuous()
                .with_x_breaks(&[FRAC_1_PI])
                .boundary(),
        );
        // Z = (pi/4) erf(1/pi) erf(1): compare the density at the origin.
        let z = std::f64::consts::PI / 4.0 * erf(FRAC_1_PI) * erf(1.0);
        assert!((d.pdf(DVec2::ZERO) - 1.0 / z).abs() < 1e-13 / z);
        assert_eq!(d.pdf(DVec2::new(FRAC_1_PI, 0.2)), 0.0);
        assert_eq!(d.pdf(DVec2::new(0.9, 0.2)), 0.0);
        assert_eq!(d.cdf(DVec2::new(FRAC_1_PI, 1.0)), 1.0);
        let top = d.inverse_cdf(DVec2::ONE);
        assert!(top.x < FRAC_1_PI && d.pdf(top) > 0.0);
    }

    #[test]
    fn gaussian_normalization_matches_closed_form() {
        // Z = 2 pi s^2 (Φ((1-m)/s) - Φ(-m/s))^2 for mx = my = m.
        let (m, s) = (0.3, 0.2);
        let phi = |t: f64| 0.5 * erfc(-t / SQRT_2);
        let one = phi((1.0 - m) / s) - phi(-m / s);
        let z = 2.0 * std::f64::consts::PI * s * s * one * one;
        let g = TruncatedGaussian::new(m, m, s).unwrap();
        assert!((g.pdf(DVec2::new(m, m)) * z - 1.0).abs() < 1e-14);
    }

    #[test]
    fn gaussian_extreme_parameters() {
        // Mean far outside the square, tiny sigma: an essentially exponential
        // density concentrated at the edge, still normalized and invertible.
        // (Near x = 1 the f64 grid is coarser than near 0, so a density squeezed
        // against x = 1 can only be inverted to pdf * 1.1e-16 in u; keep the
        // steepest case against 0.)
        for (mx, my, s) in [(-3.0, 0.5, 0.05), (0.5, 40.0, 0.1), (-1e3, 0.5, 1e-3)] {
            let g = TruncatedGaussian::new(mx, my, s).unwrap();
            assert!((g.cdf(DVec2::ONE) - 1.0).abs() < 1e-15);
            for &u in &[1e-12, 1e-3, 0.25, 0.5, 0.75, 0.999, 1.0 - 1e-12] {
                let uu = DVec2::new(u, 1.0 - u);
                let p = g.inverse_cdf(uu);
                assert!(g.pdf(p) > 0.0 && g.pdf(p).is_finite(), "{mx} {my} {s} {u}");
                let fx = g.cdf(DVec2::new(p.x, 1.0));
                let fy = g.cdf(DVec2::new(1.0, p.y));
                assert!((fx - uu.x).abs() <= 2e-12, "{fx} vs {}", uu.x);
                assert!((fy - uu.y).abs() <= 2e-12, "{fy} vs {}", uu.y);
                let j = g.inverse_cdf_jacobian(uu);
                assert!((j.determinant() * g.pdf(p) - 1.0).abs() < 1e-12);
            }
        }
        let g = TruncatedGaussian::new(0.5, 2e3, 1e-3).unwrap();
        for &u in &[1e-12, 0.5, 1.0] {
            let p = g.inverse_cdf(DVec2::new(0.5, u));
            assert!(g.pdf(p) > 0.0 && g.pdf(p).is_finite());
        }
        // Very large sigma: essentially uniform.
        assert!(TruncatedGaussian::new(0.5, 0.5, 1e12).is_ok());
    }

    #[test]
    fn gaussian_rejects_bad_parameters() {
        assert!(matches!(
            TruncatedGaussian::new(0.5, 0.5, 0.0),
            Err(DensityError::NonPositive { .. })
        ));
        assert!(matches!(
            TruncatedGaussian::new(f64::NAN, 0.5, 0.1),
            Err(DensityError::NonFinite { .. })
        ));
        assert!(matches!(
            TruncatedGaussian::new(0.5, 0.5, f64::MAX),
            Err(DensityError::ZeroMass { .. })
        ));
    }

    #[test]
    fn tail_probabilities_are_relatively_accurate() {
        // Mass of [0, 0.01] for a Gaussian centred at 0.9 with sigma 0.05:
        // (erf(z(0.01)) - erf(z(0))) / (erf(z(1)) - erf(z(0))), all in the lower tail.
        let g = TruncNormal::new(0.9, 0.05, 0.0, 1.0).unwrap();
        let p = g.prob(0.0, 0.01);
        let z = |x: f64| (x - 0.9) / (0.05 * SQRT_2);
        let expect = (erfc(-z(0.01)) - erfc(-z(0.0))) / (erfc(-z(1.0)) - erfc(-z(0.0)));
        assert!(
            p > 0.0 && ((p - expect) / expect).abs() < 1e-12,
            "{p} vs {expect}"
        );
    }
}
