//! The BRDF model behind `brdf:` targets and `bake --brdf`: the glTF 2.0
//! metallic-roughness BRDF (Khronos, *glTF 2.0 Specification*, Appendix B, "BRDF
//! Implementation"), the model real-time and shader-side renderers implement, with
//! metallic = 0 and base colour 1; Burley's 2012 dielectric stays available as
//! [`BrdfModel::Burley`].
//!
//! **Conventions.** Local frame with the normal `n = +z`; view `v = wo` and light
//! `l = wi` unit vectors on the upper hemisphere; `h = normalize(v + l)`;
//! `alpha = roughness^2`. A condition is `(roughness, theta_o)` with the view
//! `v = (sin theta_o, 0, cos theta_o)` ([`view_direction`]); its range is roughness in
//! `[0.1, 1]` and `theta_o` in `[0°, 89°]`, values outside are clamped
//! ([`clamp_roughness`], [`clamp_theta_o_deg`]) and NaN becomes the lower end.
//!
//! **glTF 2.0** ([`gltf`], [`gltf_parts`]):
//!
//! * `D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)` (GGX, [`ggx_d`]);
//! * `Vis = 0.5 / ((n.l) sqrt(alpha^2 + (1 - alpha^2)(n.v)^2) + (n.v) sqrt(alpha^2 + (1 - alpha^2)(n.l)^2))`,
//!   the height-correlated Smith term `G2 / (4 (n.l)(n.v))` with
//!   `G2 = 1 / (1 + Λ(v) + Λ(l))` ([`smith_vis`]);
//! * `F = 0.04 + 0.96 (1 - |v.h|)^5` (Schlick, [`schlick_fresnel`]);
//! * `f = (1 - F) / pi + F D Vis` (the spec's `fresnel_mix` of a diffuse and a
//!   specular layer).
//!
//! `f` is reciprocal (`v.h = l.h`, `Vis` symmetric). It is *not* energy conserving,
//! as the glTF spec says of `fresnel_mix`: the directional albedo
//! `A = ∫ f (n.l) dl` exceeds 1 at grazing views (about 1.57 at roughness 0.1 and
//! 85°), which is kept as specified.
//!
//! **Burley** ([`burley_parts`]): GGX `D`, separable Smith `G1(v) G1(l)`
//! ([`smith_g1`]), Schlick `F` with `F0 = 0.04`, `f_spec = D F G / (4 (n.v)(n.l))`, and
//! Burley's retro-reflective diffuse lobe ([`burley_diffuse`]) weighted by `1 - F0`.
//!
//! **Precision.** The glTF formulas are written once over [`Real`], so the build
//! tool evaluates them in `f64` and a runtime or shader in `f32` with the same
//! expression order; Burley exists only in `f64` (a tool-side alternative).
//! Everything is `no_std` (math through `libm`) and never panics.
//!
//! The directional albedo is a quadrature; it lives in the build tool, whose
//! results ship as tables.

use crate::real::Real;
use glam::DVec3;

/// Specular reflectance at normal incidence (`F0`) of the dielectric layer.
pub const F0: f64 = 0.04;

/// The smallest roughness of the condition range; smaller values and NaN are raised
/// to it.
pub const MIN_ROUGHNESS: f64 = 0.1;

/// The largest roughness of the condition range; larger values are lowered to it.
pub const MAX_ROUGHNESS: f64 = 1.0;

/// The largest view angle of the condition range, degrees from the normal; larger
/// values are lowered to it.
pub const MAX_THETA_O_DEG: f64 = 89.0;

/// Lower corner of the condition range `(roughness, theta_o in degrees)`:
/// `(MIN_ROUGHNESS, 0)`.
pub const CONDITION_MIN: [f64; 2] = [MIN_ROUGHNESS, 0.0];

/// Upper corner of the condition range `(roughness, theta_o in degrees)`:
/// `(MAX_ROUGHNESS, MAX_THETA_O_DEG)`.
pub const CONDITION_MAX: [f64; 2] = [MAX_ROUGHNESS, MAX_THETA_O_DEG];

/// Which BRDF a `brdf:` target or a bake uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BrdfModel {
    /// glTF 2.0 metallic-roughness, metallic 0, base colour 1 ([`gltf_parts`]).
    #[default]
    Gltf,
    /// Burley 2012 dielectric ([`burley_parts`]).
    Burley,
}

impl BrdfModel {
    /// Short lower-case name: `gltf` or `burley`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gltf => "gltf",
            Self::Burley => "burley",
        }
    }

    /// The diffuse and specular parts of `f(wo, wi)` (per steradian); see
    /// [`gltf_parts`] and [`burley_parts`] for their domains.
    pub fn parts(self, wo: DVec3, wi: DVec3, roughness: f64) -> BrdfParts<f64> {
        match self {
            Self::Gltf => gltf_parts(wo.to_array(), wi.to_array(), roughness),
            Self::Burley => burley_parts(wo, wi, roughness),
        }
    }

    /// `f(wo, wi)` (per steradian), the sum of [`BrdfModel::parts`].
    pub fn eval(self, wo: DVec3, wi: DVec3, roughness: f64) -> f64 {
        self.parts(wo, wi, roughness).total()
    }

    /// `f(wo, wi) max(n.wi, 0)`: the integrand of the directional albedo and, up to
    /// its normalizer, the `brdf:` target density on the upper hemisphere.
    pub fn cosine_weighted(self, wo: DVec3, wi: DVec3, roughness: f64) -> f64 {
        self.eval(wo, wi, roughness) * wi.z.max(0.0)
    }
}

/// The two layers of a BRDF value (per steradian).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BrdfParts<T> {
    /// The diffuse layer: `(1 - F) / pi` for glTF, `(1 - F0) f_diff` for Burley.
    pub diffuse: T,
    /// The microfacet layer: `F D Vis` for glTF, `D F G / (4 (n.v)(n.l))` for Burley.
    pub specular: T,
}

impl<T: Real> BrdfParts<T> {
    /// `diffuse + specular`.
    #[inline]
    pub fn total(self) -> T {
        self.diffuse + self.specular
    }

    const ZERO: Self = Self {
        diffuse: T::ZERO,
        specular: T::ZERO,
    };
}

/// `roughness` clamped into `[MIN_ROUGHNESS, MAX_ROUGHNESS]`; NaN becomes
/// [`MIN_ROUGHNESS`].
#[inline]
pub fn clamp_roughness<T: Real>(roughness: T) -> T {
    // `max` before `min`: IEEE maxNum turns NaN into the lower bound.
    roughness
        .max(T::of(MIN_ROUGHNESS))
        .min(T::of(MAX_ROUGHNESS))
}

/// `theta_o_deg` clamped into `[0, MAX_THETA_O_DEG]`; NaN becomes 0 (normal
/// incidence).
#[inline]
pub fn clamp_theta_o_deg<T: Real>(theta_o_deg: T) -> T {
    theta_o_deg.max(T::ZERO).min(T::of(MAX_THETA_O_DEG))
}

/// GGX width `alpha = roughness^2`, roughness clamped by [`clamp_roughness`]
/// (so `alpha` is in `[0.01, 1]`).
#[inline]
pub fn alpha<T: Real>(roughness: T) -> T {
    let r = clamp_roughness(roughness);
    r * r
}

/// GGX (Trowbridge–Reitz) normal distribution
/// `D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)` for `n_dot_h = n.h > 0`
/// (0 for `n.h <= 0` or NaN; `n.h` above 1 counts as 1). Normalized so that
/// `∫ D(h) (n.h) dh = 1` over the hemisphere. `alpha` is used as given (the caller
/// clamps it); it must be positive for `D` to be finite.
#[inline]
pub fn ggx_d<T: Real>(n_dot_h: T, alpha: T) -> T {
    if n_dot_h.is_nan() || n_dot_h <= T::ZERO {
        return T::ZERO;
    }
    let c = n_dot_h.min(T::ONE);
    let a2 = alpha * alpha;
    let t = c * c * (a2 - T::ONE) + T::ONE;
    a2 / (T::PI * t * t)
}

/// Smith masking for one direction,
/// `G1(w) = 2 (n.w) / ((n.w) + sqrt(alpha^2 + (1 - alpha^2)(n.w)^2)) = 1 / (1 + Λ(w))`,
/// for `n_dot_w = n.w` (0 for `n.w <= 0` or NaN; above 1 counts as 1). The masking
/// factor of visible-normal sampling (Heitz 2018).
#[inline]
pub fn smith_g1<T: Real>(n_dot_w: T, alpha: T) -> T {
    if n_dot_w.is_nan() || n_dot_w <= T::ZERO {
        return T::ZERO;
    }
    let c = n_dot_w.min(T::ONE);
    let a2 = alpha * alpha;
    T::of(2.0) * c / (c + (a2 + (T::ONE - a2) * c * c).sqrt())
}

/// Height-correlated Smith visibility of glTF 2.0,
/// `Vis = 0.5 / ((n.l) sqrt(alpha^2 + (1 - alpha^2)(n.v)^2) + (n.v) sqrt(alpha^2 + (1 - alpha^2)(n.l)^2))`
/// `= G2 / (4 (n.l)(n.v))`. Cosines are clamped to `[0, 1]` (NaN to 0); 0 when both
/// are 0. Finite for every `alpha > 0`, also at grazing angles.
#[inline]
pub fn smith_vis<T: Real>(n_dot_v: T, n_dot_l: T, alpha: T) -> T {
    let nv = n_dot_v.max(T::ZERO).min(T::ONE);
    let nl = n_dot_l.max(T::ZERO).min(T::ONE);
    let a2 = alpha * alpha;
    let denom =
        nl * (a2 + (T::ONE - a2) * nv * nv).sqrt() + nv * (a2 + (T::ONE - a2) * nl * nl).sqrt();
    if denom > T::ZERO {
        T::of(0.5) / denom
    } else {
        T::ZERO
    }
}

/// Schlick's Fresnel `F = F0 + (1 - F0)(1 - |v.h|)^5`, `F0 = 0.04`, for
/// `v_dot_h = v.h` (`|v.h|` above 1 counts as 1; NaN gives `F = 1`).
#[inline]
pub fn schlick_fresnel<T: Real>(v_dot_h: T) -> T {
    let c = v_dot_h.abs().max(T::ZERO).min(T::ONE);
    let m = T::ONE - c;
    let m2 = m * m;
    T::of(F0) + T::of(1.0 - F0) * m2 * m2 * m
}

/// `(n.v, n.l, n.h, v.h)` of a pair, or `None` when either direction is at or below
/// the horizon, not finite, or the pair is degenerate (`v + l = 0`).
#[inline]
fn pair_cosines<T: Real>(wo: [T; 3], wi: [T; 3]) -> Option<[T; 4]> {
    let finite = wo.iter().chain(wi.iter()).all(|x| x.is_finite());
    if !finite || wo[2] <= T::ZERO || wi[2] <= T::ZERO {
        return None;
    }
    let s = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    if len.is_nan() || len <= T::ZERO {
        return None;
    }
    let h = [s[0] / len, s[1] / len, s[2] / len];
    let v_dot_h = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2];
    Some([wo[2].min(T::ONE), wi[2].min(T::ONE), h[2], v_dot_h])
}

/// The diffuse `(1 - F) / pi` and specular `F D Vis` parts of the glTF 2.0 BRDF
/// (module docs) for unit vectors `wo` (view) and `wi` (light), normal `+z`, in
/// `f32` or `f64`.
///
/// Both parts are 0 when either direction is at or below the horizon (`z <= 0`) or
/// not finite. `roughness` is clamped by [`clamp_roughness`]. Never panics; finite
/// for every input.
///
/// ```
/// # use nuld_core::brdf::{gltf_parts, F0};
/// // wo = wi = n: h = n, F = F0, Vis = 1/4 and D = 1 / (pi alpha^2), at
/// // roughness 1: D = 1/pi.
/// let p = gltf_parts([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], 1.0f64);
/// assert!((p.diffuse - (1.0 - F0) / core::f64::consts::PI).abs() < 1e-15);
/// assert!((p.specular - F0 / (4.0 * core::f64::consts::PI)).abs() < 1e-15);
/// ```
pub fn gltf_parts<T: Real>(wo: [T; 3], wi: [T; 3], roughness: T) -> BrdfParts<T> {
    match pair_cosines(wo, wi) {
        Some(c) => gltf_parts_of(c, alpha(roughness)),
        None => BrdfParts::ZERO,
    }
}

/// [`gltf_parts`] from the pair's cosines `[n.v, n.l, n.h, v.h]` and an unclamped
/// `alpha > 0` (the tests take it towards 0).
#[inline]
fn gltf_parts_of<T: Real>(c: [T; 4], alpha: T) -> BrdfParts<T> {
    let [nv, nl, nh, vh] = c;
    let f = schlick_fresnel(vh);
    BrdfParts {
        diffuse: (T::ONE - f) / T::PI,
        specular: f * ggx_d(nh, alpha) * smith_vis(nv, nl, alpha),
    }
}

/// The glTF 2.0 BRDF `f(wo, wi) = (1 - F)/pi + F D Vis` (per steradian): the sum of
/// [`gltf_parts`], with its domain.
#[inline]
pub fn gltf<T: Real>(wo: [T; 3], wi: [T; 3], roughness: T) -> T {
    gltf_parts(wo, wi, roughness).total()
}

/// The default model's BRDF `f(wo, wi)` in `f64`: [`gltf`].
pub fn brdf(wo: DVec3, wi: DVec3, roughness: f64) -> f64 {
    BrdfModel::Gltf.eval(wo, wi, roughness)
}

/// The default model's `f(wo, wi) max(n.wi, 0)` in `f64`
/// ([`BrdfModel::cosine_weighted`] of [`BrdfModel::Gltf`]).
pub fn cosine_weighted(wo: DVec3, wi: DVec3, roughness: f64) -> f64 {
    BrdfModel::Gltf.cosine_weighted(wo, wi, roughness)
}

/// Burley's diffuse lobe
/// `f_diff = (1/pi)(1 + (Fd90 - 1)(1 - n.wi)^5)(1 + (Fd90 - 1)(1 - n.wo)^5)`,
/// `Fd90 = 0.5 + 2 roughness (h.wi)^2` (without the `1 - F0` factor; cosines are
/// clamped to `[0, 1]`, NaN to 0; roughness by [`clamp_roughness`]).
#[inline]
pub fn burley_diffuse(n_dot_wo: f64, n_dot_wi: f64, h_dot_wi: f64, roughness: f64) -> f64 {
    let r = clamp_roughness(roughness);
    let c = |x: f64| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let hw = c(h_dot_wi);
    let fd90 = 0.5 + 2.0 * r * hw * hw;
    let p5 = |x: f64| x * x * x * x * x;
    let fi = 1.0 + (fd90 - 1.0) * p5(1.0 - c(n_dot_wi));
    let fo = 1.0 + (fd90 - 1.0) * p5(1.0 - c(n_dot_wo));
    fi * fo / core::f64::consts::PI
}

/// The diffuse `(1 - F0) f_diff` and specular `D F G1(wo) G1(wi) / (4 (n.wo)(n.wi))`
/// parts of the Burley model (module docs), same domain as [`gltf_parts`]. The
/// specular part is evaluated as `D F [G1(wo)/(2 n.wo)] [G1(wi)/(2 n.wi)]`, finite at
/// grazing angles.
pub fn burley_parts(wo: DVec3, wi: DVec3, roughness: f64) -> BrdfParts<f64> {
    let Some([nv, nl, nh, vh]) = pair_cosines(wo.to_array(), wi.to_array()) else {
        return BrdfParts::ZERO;
    };
    let a = alpha(roughness);
    let half_g1 = |c: f64| 0.5 * smith_g1(c, a) / c;
    BrdfParts {
        diffuse: (1.0 - F0) * burley_diffuse(nv, nl, vh, roughness),
        specular: ggx_d(nh, a) * schlick_fresnel(vh) * half_g1(nv) * half_g1(nl),
    }
}

/// The view direction of a condition: the unit vector in the xz-plane at
/// `theta_o_deg` degrees from `+z` on the `x >= 0` side,
/// `(sin theta_o, 0, cos theta_o)`, with `theta_o_deg` clamped by
/// [`clamp_theta_o_deg`].
pub fn view_direction(theta_o_deg: f64) -> DVec3 {
    DVec3::from_array(view_direction_real(theta_o_deg))
}

/// [`view_direction`] in any [`Real`] (the runtime's `f32` twin):
/// `(sin t, 0, cos t)`, `t` the clamped angle times `pi / 180`.
#[inline]
pub fn view_direction_real<T: Real>(theta_o_deg: T) -> [T; 3] {
    let t = clamp_theta_o_deg(theta_o_deg) * T::of(core::f64::consts::PI / 180.0);
    [t.sin(), T::ZERO, t.cos()]
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use core::f64::consts::{FRAC_PI_2, PI};
    use std::vec::Vec;

    // The test's own quadrature, independent of the build tool's (which integrates
    // over half-vectors with Gauss–Legendre): adaptive Gauss–Kronrod 7/15 over the
    // light direction in spherical coordinates, split at the mirror direction.

    /// Kronrod nodes on `[-1, 1]` (non-negative half) and their 15-point weights,
    /// QUADPACK `qk15`.
    const XGK: [f64; 8] = [
        0.991_455_371_120_812_6,
        0.949_107_912_342_758_5,
        0.864_864_423_359_769_1,
        0.741_531_185_599_394_4,
        0.586_087_235_467_691_1,
        0.405_845_151_377_397_2,
        0.207_784_955_007_898_5,
        0.0,
    ];
    const WGK: [f64; 8] = [
        0.022_935_322_010_529_22,
        0.063_092_092_629_978_55,
        0.104_790_010_322_250_2,
        0.140_653_259_715_525_9,
        0.169_004_726_639_267_9,
        0.190_350_578_064_785_4,
        0.204_432_940_075_298_9,
        0.209_482_141_084_727_8,
    ];
    /// 7-point Gauss weights at `XGK[1], XGK[3], XGK[5], XGK[7]`.
    const WG: [f64; 4] = [
        0.129_484_966_168_869_7,
        0.279_705_391_489_276_7,
        0.381_830_050_505_118_9,
        0.417_959_183_673_469_4,
    ];

    /// `(K15, G7, ∫|f|)` estimates on `[a, b]`.
    fn gk15(f: &mut dyn FnMut(f64) -> f64, a: f64, b: f64) -> (f64, f64, f64) {
        let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
        let (mut k, mut g, mut abs) = (0.0, 0.0, 0.0);
        for j in 0..8 {
            let x = XGK[j] * h;
            let (s, sa) = if j == 7 {
                let y = f(c);
                (y, y.abs())
            } else {
                let (y0, y1) = (f(c - x), f(c + x));
                (y0 + y1, y0.abs() + y1.abs())
            };
            k += WGK[j] * s;
            abs += WGK[j] * sa;
            if j % 2 == 1 {
                g += WG[j / 2] * s;
            }
        }
        (k * h, g * h, abs * h)
    }

    /// `∫_a^b f` to about `tol` absolute, by bisection until `|K15 - G7|` is below
    /// the interval's share of `tol` or below `1e-9 ∫|f|`. The second bound is the
    /// noise level of the integrand: at the peak, `D` divides by
    /// `(n.h)^2 (alpha^2 - 1) + 1 ~ alpha^2`, computed from `(n.h)^2 ~ 1`, so its
    /// relative rounding error is `1e-16 / alpha^2` (up to `1e-10` here), and a
    /// tolerance below the noise would bisect forever.
    fn adaptive(f: &mut dyn FnMut(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32) -> f64 {
        let (k, g, abs) = gk15(f, a, b);
        if (k - g).abs() <= tol.max(1e-9 * abs) || depth == 0 {
            return k;
        }
        let m = 0.5 * (a + b);
        adaptive(f, a, m, 0.5 * tol, depth - 1) + adaptive(f, m, b, 0.5 * tol, depth - 1)
    }

    /// `∫_a^b f` over the pieces between consecutive `breaks` (sorted, from `a` to
    /// `b`).
    fn piecewise(f: &mut dyn FnMut(f64) -> f64, breaks: &[f64], tol: f64) -> f64 {
        let pieces = (breaks.len() - 1) as f64;
        breaks
            .windows(2)
            .filter(|w| w[1] > w[0])
            .map(|w| adaptive(f, w[0], w[1], tol / pieces, 40))
            .sum()
    }

    /// `∫ g(l) dl` over the upper hemisphere for a `g` even in `l.y` (true for every
    /// BRDF with the view in the xz-plane):
    /// `2 ∫_0^{pi/2} sin(theta) ∫_0^pi g(theta, phi) dphi dtheta`, split in `theta`
    /// at `peak_theta` (the mirror direction's polar angle, where the specular lobe
    /// sits at `phi = pi`).
    fn hemisphere_integral(peak_theta: f64, g: &dyn Fn(DVec3) -> f64) -> f64 {
        let mut outer = |theta: f64| {
            let (s, c) = (theta.sin(), theta.cos());
            let mut inner = |phi: f64| g(DVec3::new(s * phi.cos(), s * phi.sin(), c));
            s * piecewise(&mut inner, &[0.0, FRAC_PI_2, PI], 1e-11)
        };
        2.0 * piecewise(&mut outer, &[0.0, peak_theta, FRAC_PI_2], 1e-10)
    }

    /// `(diffuse, specular)` directional albedo of the glTF model at a condition.
    fn albedo(roughness: f64, theta_o_deg: f64) -> (f64, f64) {
        let v = view_direction(theta_o_deg);
        let t = theta_o_deg.to_radians();
        let part = |spec: bool| {
            hemisphere_integral(t, &|l: DVec3| {
                let p = gltf_parts(v.to_array(), l.to_array(), roughness);
                (if spec { p.specular } else { p.diffuse }) * l.z
            })
        };
        (part(false), part(true))
    }

    include!("../tests/data/gltf_albedo_reference.rs");

    #[test]
    fn gauss_kronrod_rule_is_exact_for_polynomials() {
        // K15 is exact to degree 22, G7 to degree 13.
        let (k, _, _) = gk15(&mut |x| x.powi(22), 0.0, 1.0);
        assert!((k - 1.0 / 23.0).abs() < 1e-15, "{k}");
        let (_, g, _) = gk15(&mut |x| x.powi(13), 0.0, 1.0);
        assert!((g - 1.0 / 14.0).abs() < 1e-15, "{g}");
        let (k, g, _) = gk15(&mut |x| x.powi(14), -1.0, 1.0);
        assert!((k - 2.0 / 15.0).abs() < 1e-15 && (g - 2.0 / 15.0).abs() > 1e-6);
    }

    #[test]
    fn lambert_integrates_to_one() {
        for t in [0.0, 0.7, 1.4] {
            let s = hemisphere_integral(t, &|l: DVec3| l.z / PI);
            assert!((s - 1.0).abs() < 1e-12, "{s}");
        }
    }

    #[test]
    fn ggx_d_is_normalized_over_projected_half_vectors() {
        // ∫ D(n.h) (n.h) dh = 1, from the narrowest lobe of the range (alpha 0.01) to
        // the widest.
        for r in [0.1, 0.2, 0.5, 1.0] {
            let a = alpha(r);
            let s = hemisphere_integral(0.0, &|h: DVec3| ggx_d(h.z, a) * h.z);
            assert!((s - 1.0).abs() < 1e-10, "r={r}: {s}");
        }
    }

    #[test]
    fn directional_albedo_matches_reference_table() {
        for (i, r) in REFERENCE_ROUGHNESSES.iter().enumerate() {
            for (j, t) in REFERENCE_THETAS.iter().enumerate() {
                let (d, s) = albedo(*r, *t);
                let want = REFERENCE_ALBEDO[i][j];
                assert!(
                    (d + s - want).abs() < 1e-5,
                    "r={r} t={t}: {} vs {want}",
                    d + s
                );
                // The diffuse part does not depend on roughness.
                let wd = REFERENCE_DIFFUSE[j];
                assert!((d - wd).abs() < 1e-5, "r={r} t={t}: diffuse {d} vs {wd}");
                if i == 0 {
                    let ws = REFERENCE_SPECULAR_R01[j];
                    assert!((s - ws).abs() < 1e-5, "t={t}: specular {s} vs {ws}");
                }
            }
        }
    }

    #[test]
    fn smooth_surface_specular_albedo_at_normal_incidence_is_f0() {
        // As alpha -> 0, D tends to a delta at h = n, where F = F0 and G2 = 1, so
        // ∫ F D Vis (n.l) dl -> F0. Below the condition range, through the unclamped
        // evaluation.
        let v = [0.0, 0.0, 1.0];
        for (a, tol) in [(1e-3, 1e-7), (1e-2, 1e-5)] {
            let s = hemisphere_integral(0.0, &|l: DVec3| match pair_cosines(v, l.to_array()) {
                Some(c) => gltf_parts_of(c, a).specular * l.z,
                None => 0.0,
            });
            assert!((s - F0).abs() < tol, "alpha={a}: {s}");
        }
    }

    #[test]
    fn normal_incidence_closed_form() {
        // wo = wi = n: h = n, F = F0, D = 1 / (pi alpha^2), Vis = 0.5 / 2.
        for r in [0.1, 0.3, 0.5, 0.8, 1.0] {
            let a = r * r;
            let want = (1.0 - F0) / PI + F0 / (4.0 * PI * a * a);
            let got = brdf(DVec3::Z, DVec3::Z, r);
            assert!((got - want).abs() < 1e-12 * want, "r={r}: {got} vs {want}");
        }
    }

    #[test]
    fn fresnel_and_visibility_closed_forms() {
        assert!((schlick_fresnel(1.0) - 0.04).abs() < 1e-15);
        assert!((schlick_fresnel(0.0) - 1.0).abs() < 1e-15);
        assert!((schlick_fresnel(-0.5) - (0.04 + 0.96 / 32.0)).abs() < 1e-15);
        // Vis = G2 / (4 (n.l)(n.v)) with G2 = 1 / (1 + Λ(v) + Λ(l)),
        // Λ(w) = (sqrt(1 + alpha^2 tan^2 theta_w) - 1) / 2 (Heitz 2014, eq. 72, 99).
        let lambda =
            |c: f64, a: f64| (((1.0 + a * a * (1.0 - c * c) / (c * c)).sqrt()) - 1.0) / 2.0;
        for a in [0.01, 0.3, 1.0] {
            for (nv, nl) in [(0.9, 0.2), (0.05, 0.7), (1.0, 1.0), (0.3, 0.3)] {
                let g2 = 1.0 / (1.0 + lambda(nv, a) + lambda(nl, a));
                let want = g2 / (4.0 * nv * nl);
                let got = smith_vis(nv, nl, a);
                assert!((got - want).abs() < 1e-12 * want, "a={a}: {got} vs {want}");
                // G1 = 1 / (1 + Λ).
                let g1 = smith_g1(nv, a);
                assert!((g1 - 1.0 / (1.0 + lambda(nv, a))).abs() < 1e-12);
            }
        }
        assert_eq!(smith_g1(0.0, 0.3), 0.0);
        assert_eq!(smith_vis(0.0, 0.0, 0.3), 0.0);
    }

    fn directions() -> Vec<DVec3> {
        (0..40)
            .map(|k| {
                let z = (k as f64 + 0.5) / 40.0;
                let phi = k as f64 * 2.399_963;
                let s = (1.0 - z * z).sqrt();
                DVec3::new(s * phi.cos(), s * phi.sin(), z)
            })
            .collect()
    }

    #[test]
    fn reciprocity() {
        let dirs = directions();
        for r in [0.1, 0.3, 0.6, 1.0] {
            for a in &dirs {
                for b in &dirs {
                    for m in [BrdfModel::Gltf, BrdfModel::Burley] {
                        let (x, y) = (m.eval(*a, *b, r), m.eval(*b, *a, r));
                        assert!((x - y).abs() <= 1e-13 * x.abs().max(1.0), "{x} vs {y}");
                    }
                    let (x, y) = (
                        gltf(a.as_vec3().to_array(), b.as_vec3().to_array(), r as f32),
                        gltf(b.as_vec3().to_array(), a.as_vec3().to_array(), r as f32),
                    );
                    assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn f32_evaluation_follows_f64() {
        // The same expression in f32. At the narrowest lobe's peak
        // `(n.h)^2 (alpha^2 - 1) + 1` cancels down to about alpha^2 = 1e-4, so f32
        // keeps about 3 significant digits there (as in any f32 shader).
        let dirs = directions();
        let mut worst: f64 = 0.0;
        for r in [0.1, 0.25, 0.6, 1.0] {
            for a in &dirs {
                for b in &dirs {
                    let x = brdf(*a, *b, r);
                    let y = gltf(a.as_vec3().to_array(), b.as_vec3().to_array(), r as f32);
                    worst = worst.max((f64::from(y) - x).abs() / x);
                }
            }
        }
        assert!(worst < 2e-3, "{worst}");
    }

    #[test]
    fn condition_clamping_and_invalid_inputs() {
        let wo = view_direction(30.0);
        let wi = DVec3::new(-0.3, 0.2, 0.9).normalize();
        assert_eq!(brdf(wo, wi, 0.05), brdf(wo, wi, MIN_ROUGHNESS));
        assert_eq!(brdf(wo, wi, f64::NAN), brdf(wo, wi, MIN_ROUGHNESS));
        assert_eq!(brdf(wo, wi, 3.0), brdf(wo, wi, 1.0));
        assert_ne!(brdf(wo, wi, 0.5), brdf(wo, wi, 0.6));
        assert_eq!(clamp_roughness(f32::NAN), 0.1f32);
        assert_eq!(view_direction(f64::NAN), DVec3::Z);
        assert_eq!(view_direction(-5.0), DVec3::Z);
        assert_eq!(view_direction(95.0), view_direction(MAX_THETA_O_DEG));
        let v = view_direction(60.0);
        assert!((v - DVec3::new(0.75f64.sqrt(), 0.0, 0.5)).length() < 1e-15);
        // Below the horizon, degenerate or non-finite: 0.
        for m in [BrdfModel::Gltf, BrdfModel::Burley] {
            assert_eq!(m.eval(wo, DVec3::new(1.0, 0.0, -0.1).normalize(), 0.5), 0.0);
            assert_eq!(m.eval(DVec3::new(0.0, 1.0, 0.0), DVec3::Z, 0.5), 0.0);
            assert_eq!(m.eval(wo, DVec3::splat(f64::NAN), 0.5), 0.0);
            assert_eq!(m.eval(wo, DVec3::new(f64::INFINITY, 0.0, 1.0), 0.5), 0.0);
            // Grazing pairs stay finite.
            let g = DVec3::new(1.0, 0.0, 1e-12).normalize();
            let x = m.eval(g, DVec3::new(-1.0, 0.0, 1e-12).normalize(), 0.1);
            assert!(x.is_finite() && x >= 0.0);
        }
    }

    #[test]
    fn burley_closed_forms() {
        // wo = wi = n: both Burley factors are 1, G1 = 1:
        // f = (1 - F0) / pi + F0 / (4 pi alpha^2).
        for r in [0.1, 0.5, 1.0] {
            let a = r * r;
            let want = (1.0 - F0) / PI + F0 / (4.0 * PI * a * a);
            let got = BrdfModel::Burley.eval(DVec3::Z, DVec3::Z, r);
            assert!((got - want).abs() < 1e-12 * want, "r={r}: {got} vs {want}");
        }
        // Grazing retro-reflection: wo = n, wi -> horizon along +x:
        // h.wi = 1/sqrt2, Fd90 = 0.5 + r, f_diff -> Fd90 / pi.
        for r in [0.2, 0.7, 1.0] {
            let f = burley_diffuse(1.0, 0.0, core::f64::consts::FRAC_1_SQRT_2, r);
            assert!((f - (0.5 + r) / PI).abs() < 1e-14, "{f}");
        }
        // Diffuse albedo at normal incidence: (1 - F0)(1 + 5 r / 84 - 1 / 42)
        // (with (h.wi)^2 = (1 + mu)/2 and B(2,6) = 1/42, B(3,6) = 1/168).
        for r in [0.1, 0.5, 1.0] {
            let want = (1.0 - F0) * (1.0 + 5.0 * r / 84.0 - 1.0 / 42.0);
            let got =
                hemisphere_integral(0.0, &|l: DVec3| burley_parts(DVec3::Z, l, r).diffuse * l.z);
            assert!((got - want).abs() < 1e-10, "r={r}: {got} vs {want}");
        }
    }
}
