//! The BRDF model behind `brdf:` targets and `bake --brdf`.
//!
//! An isotropic dielectric in the Disney/Burley 2012 style, in a local frame whose
//! normal is `n = +z`:
//!
//! * `alpha = roughness^2`, `h = normalize(wo + wi)`;
//! * GGX normal distribution `D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)`;
//! * separable Smith masking `G = G1(wo) G1(wi)`,
//!   `G1(w) = 2 (n.w) / ((n.w) + sqrt(alpha^2 + (1 - alpha^2) (n.w)^2))`;
//! * Schlick Fresnel `F = F0 + (1 - F0) (1 - h.wi)^5`, `F0 = 0.04`;
//! * `f_spec = D F G / (4 (n.wo) (n.wi))`;
//! * Burley diffuse `f_diff = (1/pi) (1 + (Fd90 - 1)(1 - n.wi)^5) (1 + (Fd90 - 1)(1 - n.wo)^5)`,
//!   `Fd90 = 0.5 + 2 roughness (h.wi)^2`;
//! * `f = f_diff (1 - F0) + f_spec`.
//!
//! `f` is reciprocal (`f(wo, wi) = f(wi, wo)`: `h.wi = h.wo`). It is *not* exactly
//! energy conserving: Burley's retro-reflective diffuse term has a directional
//! albedo above 1 for rough surfaces (at normal incidence the diffuse albedo is
//! `(1 - F0)(1 + 5 roughness / 84 - 1 / 42)`), which is a property of the model,
//! kept as specified.
//!
//! The target density of a `brdf:ROUGHNESS,THETA_O_DEG` spec is
//! `q(wi) ∝ cosine_weighted(view_direction(THETA_O_DEG), wi, ROUGHNESS)` on the
//! upper hemisphere.
//!
//! Everything is `f64`, `no_std` (math through `libm`), and never panics.

use core::f64::consts::PI;
use glam::DVec3;

/// Specular reflectance at normal incidence of the dielectric base layer.
pub const F0: f64 = 0.04;

/// The smallest roughness the functions use: smaller values (and NaN) are raised to
/// it, so that `alpha = roughness^2 >= 1e-6` keeps `D` finite. Specs accept
/// roughness in `(0, 1]`; values above 1 are lowered to 1.
pub const MIN_ROUGHNESS: f64 = 1e-3;

/// `roughness` clamped into `[MIN_ROUGHNESS, 1]` (NaN becomes `MIN_ROUGHNESS`).
#[inline]
pub fn clamp_roughness(roughness: f64) -> f64 {
    if roughness.is_nan() {
        MIN_ROUGHNESS
    } else {
        roughness.clamp(MIN_ROUGHNESS, 1.0)
    }
}

/// GGX width `alpha = roughness^2` (roughness clamped by [`clamp_roughness`]).
#[inline]
pub fn alpha(roughness: f64) -> f64 {
    let r = clamp_roughness(roughness);
    r * r
}

/// GGX (Trowbridge–Reitz) normal distribution
/// `D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)` for `n_dot_h = n.h > 0`
/// (0 for `n.h <= 0`). Normalized so that `∫ D(h) (n.h) dh = 1` over the hemisphere.
#[inline]
pub fn ggx_d(n_dot_h: f64, alpha: f64) -> f64 {
    if n_dot_h <= 0.0 || n_dot_h.is_nan() {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let c2 = n_dot_h.min(1.0) * n_dot_h.min(1.0);
    let t = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * t * t)
}

/// Smith masking for one direction, `G1(w) = 2 (n.w) / ((n.w) + sqrt(alpha^2 + (1 - alpha^2)(n.w)^2))`
/// with `n_dot_w = n.w` (0 for `n.w <= 0`).
#[inline]
pub fn smith_g1(n_dot_w: f64, alpha: f64) -> f64 {
    if n_dot_w <= 0.0 || n_dot_w.is_nan() {
        return 0.0;
    }
    2.0 * n_dot_w * smith_v1(n_dot_w.min(1.0), alpha)
}

/// `G1(w) / (2 n.w) = 1 / ((n.w) + sqrt(alpha^2 + (1 - alpha^2)(n.w)^2))`: the
/// masking factor with the cosine cancelled, finite at grazing angles.
#[inline]
fn smith_v1(n_dot_w: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    1.0 / (n_dot_w + libm::sqrt(a2 + (1.0 - a2) * n_dot_w * n_dot_w))
}

/// Schlick's Fresnel `F = F0 + (1 - F0)(1 - cos)^5` with `F0 = 0.04`, for
/// `h_dot_wi = h.wi` (clamped to `[0, 1]`).
#[inline]
pub fn schlick_fresnel(h_dot_wi: f64) -> f64 {
    let c = if h_dot_wi.is_nan() {
        0.0
    } else {
        h_dot_wi.clamp(0.0, 1.0)
    };
    F0 + (1.0 - F0) * pow5(1.0 - c)
}

/// Burley's diffuse lobe
/// `f_diff = (1/pi)(1 + (Fd90 - 1)(1 - n.wi)^5)(1 + (Fd90 - 1)(1 - n.wo)^5)`,
/// `Fd90 = 0.5 + 2 roughness (h.wi)^2` (without the `1 - F0` factor; cosines are
/// clamped to `[0, 1]`).
#[inline]
pub fn burley_diffuse(n_dot_wo: f64, n_dot_wi: f64, h_dot_wi: f64, roughness: f64) -> f64 {
    let r = clamp_roughness(roughness);
    let c = |x: f64| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let hw = c(h_dot_wi);
    let fd90 = 0.5 + 2.0 * r * hw * hw;
    let fi = 1.0 + (fd90 - 1.0) * pow5(1.0 - c(n_dot_wi));
    let fo = 1.0 + (fd90 - 1.0) * pow5(1.0 - c(n_dot_wo));
    fi * fo / PI
}

#[inline]
fn pow5(x: f64) -> f64 {
    let x2 = x * x;
    x2 * x2 * x
}

/// The BRDF `f(wo, wi)` of the module docs (per steradian), normal `+z`.
///
/// `wo` (view) and `wi` (light) are unit vectors; it is 0 when either is at or
/// below the horizon (`z <= 0`) or not finite. `roughness` is clamped by
/// [`clamp_roughness`]. The specular term is evaluated as
/// `D F [G1(wo)/(2 n.wo)] [G1(wi)/(2 n.wi)]`, algebraically equal to
/// `D F G / (4 (n.wo)(n.wi))` and finite at grazing angles.
pub fn brdf(wo: DVec3, wi: DVec3, roughness: f64) -> f64 {
    let (no, ni) = (wo.z, wi.z);
    if !wo.is_finite() || !wi.is_finite() || no <= 0.0 || ni <= 0.0 {
        return 0.0;
    }
    let r = clamp_roughness(roughness);
    let a = r * r;
    let sum = wo + wi;
    let len = sum.length();
    if len <= 0.0 {
        return 0.0;
    }
    let h = sum / len;
    let h_dot_wi = h.dot(wi);
    let d = ggx_d(h.z, a);
    let f = schlick_fresnel(h_dot_wi);
    let spec = d * f * smith_v1(no.min(1.0), a) * smith_v1(ni.min(1.0), a);
    let diff = burley_diffuse(no, ni, h_dot_wi, r);
    diff * (1.0 - F0) + spec
}

/// `f(wo, wi) max(n.wi, 0)`: the integrand of the directional albedo and, up to its
/// normalizer, the `brdf:` target density on the upper hemisphere.
pub fn cosine_weighted(wo: DVec3, wi: DVec3, roughness: f64) -> f64 {
    brdf(wo, wi, roughness) * wi.z.max(0.0)
}

/// The view direction of a `brdf:ROUGHNESS,THETA_O_DEG` target: the unit vector in
/// the xz-plane at `theta_o_deg` degrees from `+z`, on the `x >= 0` side:
/// `(sin theta_o, 0, cos theta_o)`.
pub fn view_direction(theta_o_deg: f64) -> DVec3 {
    let t = theta_o_deg.to_radians();
    DVec3::new(libm::sin(t), 0.0, libm::cos(t))
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::sphere::square_to_hemisphere;
    use glam::DVec2;
    use std::vec::Vec;

    /// Midpoint rule on an `m x m` grid of the equal-area hemisphere map: every cell
    /// has solid angle `2 pi / m^2`.
    fn hemisphere_quadrature(m: usize, f: impl Fn(DVec3) -> f64) -> f64 {
        let mut s = 0.0;
        for j in 0..m {
            let mut row = 0.0;
            for i in 0..m {
                let p = DVec2::new((i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64);
                row += f(square_to_hemisphere(p));
            }
            s += row;
        }
        s * 2.0 * PI / (m * m) as f64
    }

    /// `∫_0^1 g(x) dx` by composite Simpson with `n` (even) intervals.
    fn simpson(n: usize, g: impl Fn(f64) -> f64) -> f64 {
        let h = 1.0 / n as f64;
        let mut s = g(0.0) + g(1.0);
        for k in 1..n {
            s += g(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * h / 3.0
    }

    /// Specular directional albedo `∫ f_spec (n.wi) dwi` by stratified importance
    /// quadrature in half-vector space: `h` from a midpoint grid through the exact
    /// inverse CDF of `D(h)(n.h)` (`tan^2 theta_h = alpha^2 u / (1 - u)`,
    /// `phi = 2 pi v`), `wi = reflect(wo, h)`, `dwi = 4 (wo.h) dh`, so the weight is
    /// `f_spec (n.wi) 4 (wo.h) / (D (n.h))`. Resolves lobes of any width.
    fn specular_albedo(wo: DVec3, roughness: f64, m: usize) -> f64 {
        let a = alpha(roughness);
        let mut s = 0.0;
        for j in 0..m {
            for i in 0..m {
                let u = (i as f64 + 0.5) / m as f64;
                let v = (j as f64 + 0.5) / m as f64;
                let t2 = a * a * u / (1.0 - u);
                let cos_h = 1.0 / (1.0 + t2).sqrt();
                let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
                let phi = 2.0 * PI * v;
                let h = DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
                let wo_h = wo.dot(h);
                if wo_h <= 0.0 {
                    continue;
                }
                let wi = 2.0 * wo_h * h - wo;
                if wi.z <= 0.0 {
                    continue;
                }
                let spec = brdf(wo, wi, roughness) - diffuse_part(wo, wi, roughness);
                s += spec * wi.z * 4.0 * wo_h / (ggx_d(cos_h, a) * cos_h);
            }
        }
        s / (m * m) as f64
    }

    /// `f_diff (1 - F0)` for the pair.
    fn diffuse_part(wo: DVec3, wi: DVec3, roughness: f64) -> f64 {
        let h = (wo + wi).normalize();
        burley_diffuse(wo.z, wi.z, h.dot(wi), roughness) * (1.0 - F0)
    }

    /// Directional albedo: the smooth diffuse part on the equal-area grid, the
    /// specular part in half-vector space.
    fn albedo(wo: DVec3, roughness: f64, m: usize) -> (f64, f64) {
        let d = hemisphere_quadrature(m, |wi| diffuse_part(wo, wi, roughness) * wi.z);
        (d, specular_albedo(wo, roughness, m))
    }

    #[test]
    fn normal_incidence_closed_form() {
        // wo = wi = n: h = n, h.wi = 1, so F = F0, D = 1 / (pi alpha^2),
        // G1 = 2 / (1 + 1) = 1, both Burley factors are 1:
        // f = (1 - F0) / pi + F0 / (4 pi alpha^2).
        for r in [0.1, 0.3, 0.5, 0.8, 1.0] {
            let a = r * r;
            let want = (1.0 - F0) / PI + F0 / (4.0 * PI * a * a);
            let got = brdf(DVec3::Z, DVec3::Z, r);
            assert!((got - want).abs() < 1e-12 * want, "r={r}: {got} vs {want}");
        }
    }

    #[test]
    fn fresnel_and_masking_closed_forms() {
        assert!((schlick_fresnel(1.0) - 0.04).abs() < 1e-15);
        assert!((schlick_fresnel(0.0) - 1.0).abs() < 1e-15);
        // (1 - 0.5)^5 = 1/32.
        assert!((schlick_fresnel(0.5) - (0.04 + 0.96 / 32.0)).abs() < 1e-15);
        // alpha = 1: G1(w) = 2 c / (c + 1).
        for c in [0.1, 0.5, 0.9] {
            assert!((smith_g1(c, 1.0) - 2.0 * c / (c + 1.0)).abs() < 1e-15);
        }
        assert_eq!(smith_g1(1.0, 0.3), 1.0);
        assert_eq!(smith_g1(0.0, 0.3), 0.0);
        // Burley grazing retro-reflection: wo = n, wi -> horizon along +x:
        // h = (1,0,1)/sqrt2, h.wi = 1/sqrt2, Fd90 = 0.5 + r, f_diff -> Fd90 / pi.
        for r in [0.2, 0.7, 1.0] {
            let f = burley_diffuse(1.0, 0.0, core::f64::consts::FRAC_1_SQRT_2, r);
            assert!((f - (0.5 + r) / PI).abs() < 1e-14, "{f}");
        }
    }

    #[test]
    fn horizon_and_invalid_inputs_give_zero() {
        let wo = view_direction(30.0);
        assert_eq!(brdf(wo, DVec3::new(1.0, 0.0, -0.1).normalize(), 0.5), 0.0);
        assert_eq!(brdf(DVec3::new(0.0, 1.0, 0.0), DVec3::Z, 0.5), 0.0);
        assert_eq!(brdf(wo, DVec3::splat(f64::NAN), 0.5), 0.0);
        let v = brdf(wo, DVec3::Z, f64::NAN);
        assert!(v.is_finite() && v > 0.0);
        assert!(brdf(DVec3::Z, DVec3::Z, 0.0).is_finite());
        let g = view_direction(89.999999);
        assert!(brdf(g, DVec3::new(-1.0, 0.0, 1e-9).normalize(), 0.3).is_finite());
    }

    #[test]
    fn view_direction_is_in_xz_plane() {
        let v = view_direction(60.0);
        assert!((v - DVec3::new(0.75f64.sqrt(), 0.0, 0.5)).length() < 1e-15);
        assert_eq!(view_direction(0.0), DVec3::Z);
    }

    #[test]
    fn reciprocity() {
        let dirs: Vec<DVec3> = (0..40)
            .map(|k| {
                let p = DVec2::new((k as f64 * 0.618034) % 1.0, (k as f64 + 0.5) / 40.0);
                square_to_hemisphere(p)
            })
            .collect();
        for r in [0.05, 0.3, 0.6, 1.0] {
            for a in &dirs {
                for b in &dirs {
                    let (x, y) = (brdf(*a, *b, r), brdf(*b, *a, r));
                    assert!((x - y).abs() <= 1e-13 * x.abs().max(1.0), "{x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn ggx_d_is_normalized_over_projected_hemisphere() {
        // Equal-area grid for moderate widths.
        for r in [0.4, 0.6, 0.8, 1.0] {
            let a = alpha(r);
            let s = hemisphere_quadrature(1024, |h| ggx_d(h.z, a) * h.z);
            assert!((s - 1.0).abs() < 1e-4, "r={r}: {s}");
        }
        // Narrow lobes: 2 pi ∫_0^1 D(mu) mu dmu by Simpson in mu = n.h
        // (dh = dmu dphi), fine enough to resolve 1 - mu ~ alpha^2.
        for r in [0.1, 0.2, 0.3] {
            let a = alpha(r);
            let s = 2.0 * PI * simpson(4_000_000, |mu| ggx_d(mu, a) * mu);
            assert!((s - 1.0).abs() < 1e-6, "r={r}: {s}");
        }
    }

    #[test]
    fn diffuse_albedo_at_normal_incidence_closed_form() {
        // wo = n: f_diff = (1/pi)(1 + (Fd90 - 1)(1 - mu)^5), (h.wi)^2 = (1 + mu)/2,
        // Fd90 = 0.5 + r (1 + mu); with B(2,6) = 1/42 and B(3,6) = 1/168:
        // 2 ∫_0^1 f_diff pi mu dmu = 1 + 5 r / 84 - 1 / 42.
        for r in [0.1, 0.5, 1.0] {
            let want = 1.0 + 5.0 * r / 84.0 - 1.0 / 42.0;
            let got = hemisphere_quadrature(1024, |wi| {
                let h = (DVec3::Z + wi).normalize();
                PI * burley_diffuse(1.0, wi.z, h.dot(wi), r) * wi.z / PI
            });
            assert!((got - want).abs() < 5e-6, "r={r}: {got} vs {want}");
        }
    }

    #[test]
    fn specular_albedo_quadrature_agrees_with_a_uniform_grid() {
        // Two independent quadratures (uniform grid in wi vs importance grid in h)
        // agree where the uniform grid resolves the lobe.
        for r in [0.5, 0.8] {
            for t in [0.0, 45.0, 75.0] {
                let wo = view_direction(t);
                let grid = hemisphere_quadrature(1024, |wi| {
                    (brdf(wo, wi, r) - diffuse_part(wo, wi, r)) * wi.z
                });
                let hv = specular_albedo(wo, r, 1024);
                assert!((grid - hv).abs() < 1e-4, "r={r} t={t}: {grid} vs {hv}");
            }
        }
    }

    #[test]
    fn energy_bounds_of_the_directional_albedo() {
        for r in [0.05, 0.1, 0.2, 0.35, 0.5, 0.8, 1.0] {
            for t in [0.0, 20.0, 40.0, 50.0, 60.0, 75.0, 85.0] {
                let (d, s) = albedo(view_direction(t), r, 512);
                // The single-scattering microfacet term conserves energy:
                // ∫ f_spec cos = E_vndf[F G1(wi)] <= 1, and it is at least F0 G1-ish.
                assert!(s > 0.0 && s <= 1.0, "r={r} t={t}: specular albedo {s}");
                // (1 - F0) times the Burley factors, each at most max(1, 0.5 + 2r).
                let fd = (0.5 + 2.0 * r).max(1.0);
                assert!(d > 0.0 && d <= (1.0 - F0) * fd * fd, "r={r} t={t}: {d}");
                // The whole BRDF conserves energy for smooth-to-medium roughness away
                // from grazing; beyond that the model (diffuse weighted by 1 - F0, not
                // 1 - F; Burley retro-reflection) exceeds 1, as specified.
                if r <= 0.35 && t <= 40.0 {
                    assert!(d + s <= 1.0, "r={r} t={t}: albedo {}", d + s);
                }
            }
        }
    }
}
