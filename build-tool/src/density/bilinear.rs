//! `bilinear:V00,V10,V01,V11`: bilinear interpolation of four corner values.

use super::{fmt_num, Density2D, DensityError};
use glam::{DMat2, DVec2};

/// `∫_0^t (1 - s) ds = t - t^2/2`.
fn p_int(t: f64) -> f64 {
    t - 0.5 * t * t
}

/// `∫_0^t s ds = t^2/2`.
fn q_int(t: f64) -> f64 {
    0.5 * t * t
}

/// Inverse CDF of the linear density `∝ (1-t) a + t b` on `[0,1]` (`a, b >= 0`,
/// not both 0): the stable root `t = u (a+b) / (a + sqrt((1-u) a^2 + u b^2))` of
/// `(b-a)/2 t^2 + a t = u (a+b)/2`, which degrades gracefully to `t = u` for
/// `a = b` and `t = sqrt(u)` for `a = 0`. Returns `u` if `a = b = 0`.
fn sample_linear(u: f64, a: f64, b: f64) -> f64 {
    let s = a + b;
    if s.is_nan() || s <= 0.0 {
        return u;
    }
    let den = a + ((1.0 - u) * a * a + u * b * b).sqrt();
    if den <= 0.0 {
        return 0.0;
    }
    (u * s / den).clamp(0.0, 1.0)
}

/// The bilinear density `q(x, y) = [V00 (1-x)(1-y) + V10 x (1-y) + V01 (1-x) y +
/// V11 x y] / Z` on `[0,1]^2`, `Z = (V00 + V10 + V01 + V11) / 4` (SPEC
/// `bilinear:V00,V10,V01,V11`; corner values dimensionless, finite, `>= 0`, not all
/// 0).
///
/// CDF: `F(X, Y) = [V00 P(X) P(Y) + V10 Q(X) P(Y) + V01 P(X) Q(Y) + V11 Q(X) Q(Y)] / Z`
/// with `P(t) = t - t^2/2`, `Q(t) = t^2/2`. Inverse CDF: the `x` marginal is linear,
/// `f_X(x) = (1-x) A0 + x A1` (`A0 = (V00+V01)/(2Z)`, `A1 = (V10+V11)/(2Z)`), and
/// `y | x` is linear between `L0(x) = (V00 (1-x) + V10 x)/Z` and
/// `L1(x) = (V01 (1-x) + V11 x)/Z`; both are inverted by a cancellation-free
/// quadratic root. The Jacobian is analytic (lower triangular).
///
/// Where a whole edge of the square has zero density (e.g. `V00 = V01 = 0`),
/// `inverse_cdf` maps the matching edge of the `u` square onto that edge (a
/// measure-zero set); interior `u` always land at positive density.
#[derive(Clone, Debug, PartialEq)]
pub struct Bilinear {
    /// Raw corner values `[V00, V10, V01, V11]` as given.
    values: [f64; 4],
    /// Normalized corner values (`c / Z`, summing to 4).
    c: [f64; 4],
}

impl Bilinear {
    /// Builds the density from corner values `[V00, V10, V01, V11]` at
    /// `(0,0), (1,0), (0,1), (1,1)`; errors on non-finite or negative values or
    /// all zeros.
    pub fn new(values: [f64; 4]) -> Result<Self, DensityError> {
        const NAMES: [&str; 4] = ["V00", "V10", "V01", "V11"];
        for (&value, param) in values.iter().zip(NAMES) {
            if !value.is_finite() {
                return Err(DensityError::NonFinite {
                    kind: "bilinear",
                    param,
                    value,
                });
            }
            if value < 0.0 {
                return Err(DensityError::Negative {
                    kind: "bilinear",
                    param,
                    value,
                });
            }
        }
        let max = values.iter().fold(0.0_f64, |m, &v| m.max(v));
        if max <= 0.0 {
            return Err(DensityError::ZeroMass {
                what: Self::format_spec(&values),
            });
        }
        // Scale by the maximum first so that the sum cannot overflow.
        let scaled = values.map(|v| v / max);
        let z = scaled.iter().sum::<f64>() / 4.0;
        Ok(Self {
            values,
            c: scaled.map(|v| v / z),
        })
    }

    fn format_spec(v: &[f64; 4]) -> String {
        format!(
            "bilinear:{},{},{},{}",
            fmt_num(v[0]),
            fmt_num(v[1]),
            fmt_num(v[2]),
            fmt_num(v[3])
        )
    }

    /// The corner values `[V00, V10, V01, V11]` as given (not normalized).
    pub fn values(&self) -> [f64; 4] {
        self.values
    }

    /// Edge densities `(L0(x), L1(x))` at `y = 0` and `y = 1`.
    fn edges(&self, x: f64) -> (f64, f64) {
        let [c00, c10, c01, c11] = self.c;
        (c00 * (1.0 - x) + c10 * x, c01 * (1.0 - x) + c11 * x)
    }

    /// Marginal endpoints `(A0, A1)`: `f_X(x) = (1-x) A0 + x A1`, `A0 + A1 = 2`.
    fn marginal(&self) -> (f64, f64) {
        let [c00, c10, c01, c11] = self.c;
        (0.5 * (c00 + c01), 0.5 * (c10 + c11))
    }

    /// `∫∫` over `[lo, hi]` from per-axis integrals of `(1-t)` and `t`.
    fn box_integral(&self, px: f64, qx: f64, py: f64, qy: f64) -> f64 {
        let [c00, c10, c01, c11] = self.c;
        c00 * px * py + c10 * qx * py + c01 * px * qy + c11 * qx * qy
    }
}

impl Density2D for Bilinear {
    fn spec(&self) -> String {
        Self::format_spec(&self.values)
    }

    fn pdf(&self, p: DVec2) -> f64 {
        if !((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y)) {
            return 0.0;
        }
        let (l0, l1) = self.edges(p.x);
        (l0 * (1.0 - p.y) + l1 * p.y).max(0.0)
    }

    fn cdf(&self, p: DVec2) -> f64 {
        let p = p.clamp(DVec2::ZERO, DVec2::ONE);
        self.box_integral(p_int(p.x), q_int(p.x), p_int(p.y), q_int(p.y))
            .clamp(0.0, 1.0)
    }

    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        let lo = lo.clamp(DVec2::ZERO, DVec2::ONE);
        let hi = hi.clamp(DVec2::ZERO, DVec2::ONE);
        if hi.x <= lo.x || hi.y <= lo.y {
            return 0.0;
        }
        // ∫_l^h (1-t) dt = (h-l)(1 - (h+l)/2), ∫_l^h t dt = (h-l)(h+l)/2.
        let (wx, sx) = (hi.x - lo.x, hi.x + lo.x);
        let (wy, sy) = (hi.y - lo.y, hi.y + lo.y);
        self.box_integral(
            wx * (1.0 - 0.5 * sx),
            wx * 0.5 * sx,
            wy * (1.0 - 0.5 * sy),
            wy * 0.5 * sy,
        )
        .max(0.0)
    }

    fn inverse_cdf(&self, u: DVec2) -> DVec2 {
        let u = u.clamp(DVec2::ZERO, DVec2::ONE);
        let (a0, a1) = self.marginal();
        let x = sample_linear(u.x, a0, a1);
        let (l0, l1) = self.edges(x);
        DVec2::new(x, sample_linear(u.y, l0, l1))
    }

    fn inverse_cdf_jacobian(&self, u: DVec2) -> DMat2 {
        let u = u.clamp(DVec2::ZERO, DVec2::ONE);
        let p = self.inverse_cdf(u);
        let (x, y) = (p.x, p.y);
        let (a0, a1) = self.marginal();
        let fx = (1.0 - x) * a0 + x * a1;
        let dx_du1 = 1.0 / fx;
        let (l0, l1) = self.edges(x);
        let [c00, c10, c01, c11] = self.c;
        let (d0, d1) = (c10 - c00, c11 - c01);
        // G(y; x) = (L0 P(y) + L1 Q(y)) / M, M = (L0 + L1)/2, solves G = u.y.
        let m = 0.5 * (l0 + l1);
        let g = (l0 * p_int(y) + l1 * q_int(y)) / m;
        let dg_dx = (d0 * p_int(y) + d1 * q_int(y) - g * 0.5 * (d0 + d1)) / m;
        let line = (1.0 - y) * l0 + y * l1; // = M * f_{Y|X}(y|x)
        let dy_du2 = m / line;
        let dy_du1 = -dg_dx * m / line * dx_du1;
        DMat2::from_cols(DVec2::new(dx_du1, dy_du1), DVec2::new(0.0, dy_du2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::check::{check_density, Checks};

    #[test]
    fn bilinear_generic_checks() {
        for v in [
            [1.0, 2.0, 3.0, 4.0],
            [1.0, 1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0, 0.0],
            [5.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 2.0, 3.0],
            [1e-3, 7.0, 0.5, 0.0],
        ] {
            check_density(&Bilinear::new(v).unwrap(), &Checks::smooth());
        }
    }

    #[test]
    fn bilinear_closed_form_values() {
        let d = Bilinear::new([1.0, 2.0, 3.0, 4.0]).unwrap();
        // Z = 2.5; q(0.5, 0.5) = 2.5 / 2.5 = 1; q(0,0) = 0.4.
        assert!((d.pdf(DVec2::splat(0.5)) - 1.0).abs() < 1e-15);
        assert!((d.pdf(DVec2::ZERO) - 0.4).abs() < 1e-15);
        // F(1, Y) for the marginal of y: (A0' (Y - Y^2/2) + A1' Y^2/2) with
        // A0' = (1+2)/2/2.5 = 0.6, A1' = (3+4)/2/2.5 = 1.4.
        let y: f64 = 0.3;
        let expect = 0.6 * (y - y * y / 2.0) + 1.4 * y * y / 2.0;
        assert!((d.cdf(DVec2::new(1.0, y)) - expect).abs() < 1e-15);
        assert_eq!(d.spec(), "bilinear:1,2,3,4");
    }

    #[test]
    fn sample_linear_degenerate_cases() {
        assert_eq!(sample_linear(0.25, 1.0, 1.0), 0.25);
        assert!((sample_linear(0.25, 0.0, 1.0) - 0.5).abs() < 1e-16);
        assert!((sample_linear(0.75, 1.0, 0.0) - 0.5).abs() < 1e-16);
        assert_eq!(sample_linear(0.0, 0.0, 1.0), 0.0);
        assert_eq!(sample_linear(1.0, 1.0, 0.0), 1.0);
        assert_eq!(sample_linear(0.4, 0.0, 0.0), 0.4);
        // Round trip through the linear CDF.
        for (a, b) in [(0.3, 1.7), (2.0, 0.0), (1e-9, 2.0)] {
            for i in 1..100 {
                let u = i as f64 / 100.0;
                let t = sample_linear(u, a, b);
                let f = (a * p_int(t) + b * q_int(t)) / (0.5 * (a + b));
                assert!((f - u).abs() < 1e-15, "{a} {b} {u}");
            }
        }
    }

    #[test]
    fn bilinear_rejects_bad_values() {
        assert!(matches!(
            Bilinear::new([0.0; 4]),
            Err(DensityError::ZeroMass { .. })
        ));
        assert!(matches!(
            Bilinear::new([1.0, -1.0, 1.0, 1.0]),
            Err(DensityError::Negative { param: "V10", .. })
        ));
        assert!(matches!(
            Bilinear::new([1.0, 1.0, f64::INFINITY, 1.0]),
            Err(DensityError::NonFinite { param: "V01", .. })
        ));
        assert!(Bilinear::new([f64::MAX; 4]).is_ok());
    }
}
