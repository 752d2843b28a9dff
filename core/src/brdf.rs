//! The BRDF model behind `brdf:` targets and `bake --brdf`: the glTF 2.0
//! metallic-roughness BRDF (Khronos, *glTF 2.0 Specification*, Appendix B, "BRDF
//! Implementation"), the model real-time and shader-side renderers implement, with
//! base colour 1: the dielectric (metallic = 0) of `brdf:` targets, and the whole
//! metallic range `m` in `[0, 1]` ([`gltf_metallic`]); Burley's 2012 dielectric stays
//! available as [`BrdfModel::Burley`].
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
//! **glTF 2.0 with metallic `m`** ([`gltf_metallic`], [`gltf_metallic_parts`]): the
//! spec's `mix(dielectric_brdf, metal_brdf, m)` with base colour 1. The metal's
//! Fresnel term is Schlick's with `F0 =` base colour `= 1`, which is exactly 1, so
//! the metal is `D Vis` with no diffuse lobe, and
//!
//! * `f = (1 - m) ((1 - F)/pi + F D Vis) + m D Vis`, with `F`, `D` and `Vis` as
//!   above (the dielectric's `F`, `F0 = 0.04`), split into the diffuse part
//!   `(1 - m)(1 - F)/pi` and the specular part `((1 - m) F + m) D Vis`.
//!
//! A condition of this model is `(roughness, theta_o, metallic)`, `metallic` in
//! `[0, 1]` ([`MIN_METALLIC`], [`MAX_METALLIC`]); values outside are clamped and NaN
//! becomes 0 ([`clamp_metallic`]). At `m = 0` both functions are [`gltf_parts`] and
//! [`gltf`] bit for bit: the dielectric *is* the `m = 0` case of the same expression
//! (`1 x = x` and `F + 0 = F` are exact). The target `f (n.l)` is linear in `m`
//! before normalization: `f_m = (1 - m) f_0 + m f_1`, so its albedo is
//! `A(m) = (1 - m) A(0) + m A(1)`, and the normalized target is the mixture of the
//! two normalized ones with weights `(1 - m) A(0) / A(m)` and `m A(1) / A(m)` (not
//! `1 - m` and `m`). The metal alone conserves energy: its albedo is at most 1, from
//! about `1 - alpha^2` for narrow lobes at normal incidence (`1 - 1.0e-4` at
//! roughness 0.1) down to `1 - ln 2 ≈ 0.307` at roughness 1 (where `D = 1/pi` and
//! the albedo is `1 - mu ln(1 + 1/mu)`, `mu = n.v`, which rises towards 1 at grazing
//! views); the mixture exceeds 1 where the dielectric's excess outweighs the metal's
//! loss (1.28 at roughness 0.1, 85° and `m = 0.5`).
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

/// The smallest metallic value; smaller values and NaN are raised to it (the
/// dielectric).
pub const MIN_METALLIC: f64 = 0.0;

/// The largest metallic value; larger values are lowered to it (the metal).
pub const MAX_METALLIC: f64 = 1.0;

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
    /// The diffuse layer: `(1 - F) / pi` for glTF (`(1 - m)(1 - F) / pi` with
    /// metallic `m`), `(1 - F0) f_diff` for Burley.
    pub diffuse: T,
    /// The microfacet layer: `F D Vis` for glTF (`((1 - m) F + m) D Vis` with
    /// metallic `m`), `D F G / (4 (n.v)(n.l))` for Burley.
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

/// `metallic` clamped into `[MIN_METALLIC, MAX_METALLIC]`; NaN becomes
/// [`MIN_METALLIC`] (the dielectric).
///
/// ```
/// # use nuld_core::brdf::clamp_metallic;
/// assert_eq!(clamp_metallic(0.25f64), 0.25);
/// assert_eq!(clamp_metallic(-3.0f64), 0.0);
/// assert_eq!(clamp_metallic(7.0f32), 1.0);
/// assert_eq!(clamp_metallic(f64::NAN), 0.0);
/// ```
#[inline]
pub fn clamp_metallic<T: Real>(metallic: T) -> T {
    // `max` before `min`: IEEE maxNum turns NaN into the lower bound.
    metallic.max(T::of(MIN_METALLIC)).min(T::of(MAX_METALLIC))
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
/// `alpha > 0` (the tests take it towards 0): the `m = 0` case of
/// [`gltf_metallic_parts_of`], whose extra operations `1 x` and `F + 0` are exact.
#[inline]
fn gltf_parts_of<T: Real>(c: [T; 4], alpha: T) -> BrdfParts<T> {
    gltf_metallic_parts_of(c, alpha, T::ZERO)
}

/// [`gltf_metallic_parts`] from the pair's cosines `[n.v, n.l, n.h, v.h]`, an
/// unclamped `alpha > 0` and a metallic value already clamped into `[0, 1]`.
#[inline]
fn gltf_metallic_parts_of<T: Real>(c: [T; 4], alpha: T, metallic: T) -> BrdfParts<T> {
    let [nv, nl, nh, vh] = c;
    let f = schlick_fresnel(vh);
    let dielectric = T::ONE - metallic;
    BrdfParts {
        diffuse: dielectric * ((T::ONE - f) / T::PI),
        specular: (dielectric * f + metallic) * ggx_d(nh, alpha) * smith_vis(nv, nl, alpha),
    }
}

/// The diffuse `(1 - m)(1 - F) / pi` and specular `((1 - m) F + m) D Vis` parts of
/// the glTF 2.0 BRDF with metallic `m` and base colour 1 (module docs) for unit
/// vectors `wo` (view) and `wi` (light), normal `+z`, in `f32` or `f64`.
///
/// Both parts are 0 when either direction is at or below the horizon (`z <= 0`) or
/// not finite. `roughness` is clamped by [`clamp_roughness`], `metallic` by
/// [`clamp_metallic`] (NaN is the dielectric). At `metallic = 0` the result is
/// [`gltf_parts`] bit for bit. Never panics; finite for every input.
///
/// ```
/// # use nuld_core::brdf::{gltf_metallic_parts, gltf_parts};
/// use core::f64::consts::PI;
/// let n = [0.0, 0.0, 1.0];
/// // The metal (m = 1) at wo = wi = n and roughness 1: D = 1/pi, Vis = 1/4, no
/// // diffuse lobe.
/// let p = gltf_metallic_parts(n, n, 1.0f64, 1.0);
/// assert_eq!(p.diffuse, 0.0);
/// assert!((p.specular - 1.0 / (4.0 * PI)).abs() < 1e-15);
/// // Halfway: F = 0.04, so the specular weight is 0.5 * 0.04 + 0.5 = 0.52.
/// let p = gltf_metallic_parts(n, n, 1.0f64, 0.5);
/// assert!((p.diffuse - 0.5 * 0.96 / PI).abs() < 1e-15);
/// assert!((p.specular - 0.52 / (4.0 * PI)).abs() < 1e-15);
/// // The dielectric is the m = 0 case.
/// let wo = [0.6, 0.0, 0.8];
/// let wi = [-0.28, 0.0, 0.96];
/// assert_eq!(gltf_metallic_parts(wo, wi, 0.3, 0.0), gltf_parts(wo, wi, 0.3));
/// ```
pub fn gltf_metallic_parts<T: Real>(
    wo: [T; 3],
    wi: [T; 3],
    roughness: T,
    metallic: T,
) -> BrdfParts<T> {
    match pair_cosines(wo, wi) {
        Some(c) => gltf_metallic_parts_of(c, alpha(roughness), clamp_metallic(metallic)),
        None => BrdfParts::ZERO,
    }
}

/// The glTF 2.0 BRDF with metallic `m` and base colour 1,
/// `f(wo, wi) = (1 - m)((1 - F)/pi + F D Vis) + m D Vis` (per steradian): the sum of
/// [`gltf_metallic_parts`], with its domain and clamping. At `metallic = 0` it is
/// [`gltf`] bit for bit.
///
/// ```
/// # use nuld_core::brdf::gltf_metallic;
/// use core::f64::consts::PI;
/// // wo = wi = n, roughness 1, the metal: D Vis = (1/pi)(1/4).
/// let n = [0.0, 0.0, 1.0];
/// assert!((gltf_metallic(n, n, 1.0f64, 1.0) - 1.0 / (4.0 * PI)).abs() < 1e-15);
/// // Out-of-range metallic values are clamped (here in f32).
/// let n = [0.0f32, 0.0, 1.0];
/// assert_eq!(gltf_metallic(n, n, 0.5, 3.0), gltf_metallic(n, n, 0.5, 1.0));
/// ```
#[inline]
pub fn gltf_metallic<T: Real>(wo: [T; 3], wi: [T; 3], roughness: T, metallic: T) -> T {
    gltf_metallic_parts(wo, wi, roughness, metallic).total()
}

/// [`gltf_metallic`] at metallic 0 and at metallic 1, `[f_0, f_1]`, for one pair
/// of directions: bit for bit the two calls' values, with the pair's cosines
/// worked out once (a tabulation of both ends of the metallic axis at the same
/// directions, whose blend is every metallic, needs both).
///
/// ```
/// # use nuld_core::brdf::{gltf_metallic, gltf_metallic_ends};
/// let (wo, wi) = ([0.6, 0.0, 0.8], [-0.28, 0.0, 0.96]);
/// let [f0, f1] = gltf_metallic_ends(wo, wi, 0.3f64);
/// assert_eq!(f0, gltf_metallic(wo, wi, 0.3, 0.0));
/// assert_eq!(f1, gltf_metallic(wo, wi, 0.3, 1.0));
/// ```
#[inline]
pub fn gltf_metallic_ends<T: Real>(wo: [T; 3], wi: [T; 3], roughness: T) -> [T; 2] {
    match pair_cosines(wo, wi) {
        Some(c) => {
            let a = alpha(roughness);
            [T::ZERO, T::ONE].map(|m| gltf_metallic_parts_of(c, a, m).total())
        }
        None => [BrdfParts::ZERO.total(); 2],
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
    let (sin_t, cos_t) = t.sin_cos();
    [sin_t, T::ZERO, cos_t]
}

#[cfg(test)]
mod tests;
