//! `quarter-disc`: the uniform density on the quarter disc `x^2 + y^2 < 2/pi`.

use super::numeric::{next_down, solve_increasing};
use super::Density2D;
use glam::{DMat2, DVec2};
use std::f64::consts::{FRAC_2_PI, PI};

/// `R^2 = 2/pi`: the quarter disc of this radius has area 1/2.
const R2: f64 = FRAC_2_PI;

/// `s(psi) = psi - sin(psi)`, accurate (relative) also for small `psi`.
fn psi_minus_sin(psi: f64) -> f64 {
    if psi.abs() < 0.5 {
        // psi^3 Σ_k (-1)^k psi^(2k) / (2k+3)!, k = 0..8.
        let t = psi * psi;
        let mut term = 1.0;
        let mut sum = 0.0;
        let mut k = 3.0_f64;
        let mut fact = 6.0; // (2k+3)! for k = 0
        for _ in 0..9 {
            sum += term / fact;
            term *= -t;
            fact *= (k + 1.0) * (k + 2.0);
            k += 2.0;
        }
        psi * t * sum
    } else {
        psi - psi.sin()
    }
}

/// The uniform density on the quarter disc `x^2 + y^2 < R^2`, `R^2 = 2/pi`
/// (`R ≈ 0.7979`, area 1/2), so `q = 2` inside and `0` outside (SPEC
/// `quarter-disc`).
///
/// With `x = R cos(psi/2)`, `h(x) = sqrt(R^2 - x^2) = R sin(psi/2)` and
/// `s(psi) = psi - sin psi`:
/// * column area beyond `x`: `G(x) = ∫_x^R h = (R^2/4) s(psi)`, `G(0) = 1/2`;
/// * marginal CDF `F_X(x) = 1 - 2 G(x) = 1 - s(psi)/pi`;
/// * CDF `F(X, Y) = 2 [Y min(X', t0) + G(min(X', t0)) - G(X')]`, `X' = min(X, R)`,
///   `t0 = h(min(Y, R))` (the area of the box `[0,X]x[0,Y]` inside the disc);
/// * inverse CDF: `psi` solves `s(psi) = pi (1 - u.x)` (safeguarded Newton, a few
///   ulps), `x = R cos(psi/2)`, then `y = u.y h(x)` (uniform conditional);
/// * Jacobian `[[1/(2h), 0], [-u.y x/(2h^2), h]]`, determinant `1/2 = 1/q`.
///
/// `inverse_cdf` always returns a point strictly inside the disc (the rare
/// boundary results, e.g. `u.x = 1`, are moved inward by an ulp).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuarterDisc;

impl QuarterDisc {
    /// Disc radius `R = sqrt(2/pi)`.
    pub fn radius() -> f64 {
        R2.sqrt()
    }

    /// `h(t) = sqrt(R^2 - t^2)` for `t` in `[0, R]` (0 beyond).
    fn h(t: f64) -> f64 {
        let r = Self::radius();
        let t = t.clamp(0.0, r);
        ((r - t) * (r + t)).max(0.0).sqrt()
    }

    /// `G(x) = ∫_x^R h(t) dt` for `x` in `[0, R]`.
    fn tail_area(x: f64) -> f64 {
        let r = Self::radius();
        let x = x.clamp(0.0, r);
        let psi = 2.0 * Self::h(x).atan2(x);
        0.25 * R2 * psi_minus_sin(psi)
    }

    /// Solves `s(psi) = target` for `psi` in `[0, pi]`.
    fn solve_psi(target: f64) -> f64 {
        if target.is_nan() || target <= 0.0 {
            return 0.0;
        }
        if target >= PI {
            return PI;
        }
        let x0 = (6.0 * target).cbrt().min(PI);
        solve_increasing(
            |psi| {
                let s = (0.5 * psi).sin();
                (psi_minus_sin(psi), 2.0 * s * s)
            },
            target,
            0.0,
            PI,
            x0,
        )
    }

    /// `(psi, x, h)` of the marginal inverse at `u.x`.
    fn marginal_inverse(ux: f64) -> (f64, f64, f64) {
        let psi = Self::solve_psi(PI * (1.0 - ux.clamp(0.0, 1.0)));
        let r = Self::radius();
        let (s, c) = (0.5 * psi).sin_cos();
        (psi, r * c, r * s)
    }
}

impl Density2D for QuarterDisc {
    fn spec(&self) -> String {
        "quarter-disc".to_string()
    }

    fn pdf(&self, p: DVec2) -> f64 {
        if p.x >= 0.0 && p.y >= 0.0 && p.x * p.x + p.y * p.y < R2 {
            2.0
        } else {
            0.0
        }
    }

    fn cdf(&self, p: DVec2) -> f64 {
        let p = p.clamp(DVec2::ZERO, DVec2::ONE);
        let r = Self::radius();
        let xm = p.x.min(r);
        let t0 = Self::h(p.y.min(r)).min(xm);
        let area = p.y.min(r) * t0 + Self::tail_area(t0) - Self::tail_area(xm);
        (2.0 * area).clamp(0.0, 1.0)
    }

    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        if hi.x <= lo.x || hi.y <= lo.y {
            return 0.0;
        }
        let m = self.cdf(hi) - self.cdf(DVec2::new(lo.x, hi.y)) - self.cdf(DVec2::new(hi.x, lo.y))
            + self.cdf(lo);
        m.max(0.0)
    }

    fn inverse_cdf(&self, u: DVec2) -> DVec2 {
        let (_, mut x, h) = Self::marginal_inverse(u.x);
        let mut y = u.y.clamp(0.0, 1.0) * h;
        // Move boundary results strictly inside (an ulp or a few).
        for _ in 0..64 {
            if x * x + y * y < R2 {
                break;
            }
            if y > x {
                y = next_down(y);
            } else {
                x = next_down(x);
            }
        }
        DVec2::new(x.max(0.0), y.max(0.0))
    }

    fn inverse_cdf_jacobian(&self, u: DVec2) -> DMat2 {
        let (_, x, h) = Self::marginal_inverse(u.x);
        let dx = 1.0 / (2.0 * h);
        DMat2::from_cols(DVec2::new(dx, -u.y * x * dx / h), DVec2::new(0.0, h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::check::{check_density, Checks};

    #[test]
    fn quarter_disc_generic_checks() {
        check_density(&QuarterDisc, &Checks::discontinuous().boundary());
    }

    #[test]
    fn closed_form_pieces() {
        let r = QuarterDisc::radius();
        assert!((QuarterDisc::tail_area(0.0) - 0.5).abs() < 2e-16);
        assert_eq!(QuarterDisc::tail_area(r), 0.0);
        // G(x) = (R^2 acos(x/R) - x h(x)) / 2 at a moderate x.
        let x = 0.3;
        let g = 0.5 * (R2 * (x / r).acos() - x * (R2 - x * x).sqrt());
        assert!((QuarterDisc::tail_area(x) - g).abs() < 1e-15);
        // Marginal: F_X(R/sqrt 2) = 1/2 + 1/pi (quarter circle split at 45°).
        let d = QuarterDisc;
        let f = d.cdf(DVec2::new(r / 2f64.sqrt(), 1.0));
        assert!((f - (0.5 + 1.0 / PI)).abs() < 1e-15);
        // Square box fully inside: cdf = 2 * area.
        assert!((d.cdf(DVec2::new(0.5, 0.5)) - 0.5).abs() < 1e-15);
        // The full square box contains the whole disc.
        assert!((d.cdf(DVec2::new(0.9, 0.95)) - 1.0).abs() < 1e-15);
        for p in [
            DVec2::new(0.9, 0.0),
            DVec2::new(0.6, 0.6),
            DVec2::new(-0.1, 0.1),
        ] {
            assert_eq!(d.pdf(p), 0.0);
        }
        assert!((psi_minus_sin(0.49) - (0.49 - 0.49f64.sin())).abs() < 2e-16);
        assert!((psi_minus_sin(1e-3) / (1e-9 / 6.0) - (1.0 - 1e-6 / 20.0)).abs() < 1e-14);
    }

    #[test]
    fn inverse_lands_inside_near_the_rim() {
        let d = QuarterDisc;
        for &ux in &[0.0, 0.5, 1.0 - 1e-9, 1.0 - 1e-15, 1.0] {
            for &uy in &[0.0, 0.5, 1.0 - 1e-12, 1.0] {
                let p = d.inverse_cdf(DVec2::new(ux, uy));
                assert_eq!(d.pdf(p), 2.0, "u = ({ux}, {uy}) -> {p}");
            }
        }
    }
}
