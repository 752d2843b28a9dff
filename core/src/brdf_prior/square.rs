//! The maps from a prior table's square to the light direction, each beside
//! its inverse and its Jacobian (pbrt-v4's habit): the radial half-vector
//! square that the shared layers read ([`radial_direction`]), the stretched
//! square it generalizes ([`half_vector_direction`], for measurements), and the
//! star disc that the metal layer reads ([`star_direction`]), chosen per query
//! by [`PriorSquare`].
//!
//! **The radial square.** A table direction `s` of slope `t = |s.xy| / s.z`
//! (the tangent of its angle from the pole) is the half vector of slope `σ(t) =
//! t g(t)`, azimuth kept, with the stretch `g(t) = (k_b t^2 + k_s a^2) / (t^2 +
//! a^2)`: `k_s` near the pole (`t << a`), `k_b` far from it, `a` =
//! [`RADIAL_CROSSOVER`]. The shared layers take `k_s = roughness`, so that the
//! specular spike of a smooth dielectric or half-metal (half-vector slopes
//! about `α = roughness^2`) spans many cells, as in the metal layer, and `k_b =
//! roughness^(1/4)` ([`super::stretch`]), so that the diffuse lobe keeps the
//! share of the square it had in the stretched square (a shifted lattice
//! through a 10 x 12 x 3 prior at N = 256 on 48 held-out conditions: 0.997 of
//! the exact warp's Owen-Sobol, worst 1.563, against the stretched square's
//! 1.038 and 1.861). In terms of the unit `s` (`ρ^2 = s.x^2 + s.y^2`, `z =
//! s.z`), `g = (k_b ρ^2 + k_s a^2 z^2) / (ρ^2 + a^2 z^2)`, defined up to the
//! rim, and `h = normalize(g s.x, g s.y, z)`. Area: `|dω_h/dω_s| = g σ'(t) /
//! |(g s.x, g s.y, z)|^3` with `σ'(t) = g + 2 (k_b - k_s) ρ^2 a^2 z^2 / (ρ^2 +
//! a^2 z^2)^2 > 0` for `k_b >= k_s`; `|dwi/dω_h| = 4 (wo.h)`. The inverse
//! solves `t g(t) = σ` by a safeguarded Newton iteration (at most
//! [`RADIAL_INVERSE_STEPS`] steps).
//!
//! **The star disc.** In the half vector's slope plane `s = (h.x, h.y) / h.z`
//! the lights above the horizon are exactly the disc `|s - (tan θo, 0)| <= 1 /
//! cos θo`, a star-shaped region about the mirror direction `s = 0`: along the
//! unit direction `e` it reaches [`horizon_reach`] `R(e) = t e.x + sqrt(1 + t^2
//! e.x^2)`, `t = tan θo`. A table point `p` is the hemisphere direction `d =
//! square_to_hemisphere(p)`, then the point `q = d.xy / sqrt(1 + d.z)` of the
//! unit disc (Lambert's equal-area projection, half the area), `q = r e`; its
//! slope is `s = ρ e` with `ρ = k r / (1 - (1 - k / R(e)) r)`. Near the centre
//! `ρ ≈ k r`, the zoom `k` ([`metal_zoom`], `α = roughness^2`, the slope scale
//! of the GGX lobe), and the rim `r = 1` lands on the horizon for every view:
//! neighbouring nodes of roughness and view cut their lobes at the same place
//! of the table, so their blend follows the lobe where a stretched square's
//! does not (a shifted lattice through a 10 x 12 x 3 prior at 13 metals, N =
//! 256: 1.180 of the exact warp's Owen-Sobol, worst 1.862, against the
//! stretched metal square's `k = roughness` 1.655 and 3.044). Area:
//! `|ds/dq| = ρ dρ / (r dr) = k^2 / (1 - (1 - k/R) r)^3`, `|dω_h/ds| = (1 +
//! |s|^2)^(-3/2)`, `|dwi/dω_h| = 4 (wo.h)`, `|dq/dω_d| = 1/2`.
//!
//! Every map returns `None` where no light direction above the horizon
//! corresponds (and never panics): a table tabulated from the target holds 0
//! there.

use crate::real::Real;
use crate::sphere::{hemisphere_to_square_real, square_to_hemisphere_real};

/// The map a prior table's square point goes through to a light direction: the
/// stretched half-vector square of stretch `k` ([`half_vector_direction`]) or
/// the star disc of zoom `k` ([`star_direction`]). `O(1)`, never panics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PriorSquare<T> {
    /// The half-vector square with its slopes scaled by one stretch `k`
    /// ([`half_vector_direction`]; the shared layers' before the radial
    /// square, now for measurements).
    Stretched(T),
    /// The shared layers' radial square, stretch `k_s` near the pole and `k_b`
    /// beyond [`RADIAL_CROSSOVER`] ([`radial_direction`], [`radial_square`]).
    Radial(T, T),
    /// The metal layer's star disc, zoom `k` ([`metal_zoom`]).
    Star(T),
}

impl<T: Real> PriorSquare<T> {
    /// The light direction of the square point `p` for the unit view `wo`
    /// (`wo.z > 0`) and `|dwi/dω_p|`, the solid angle of `wi` per solid angle
    /// of `p`'s hemisphere direction ([`half_vector_direction`],
    /// [`star_direction`]); `None` where none lies above the horizon.
    #[inline]
    pub fn direction(self, wo: [T; 3], p: [T; 2]) -> Option<([T; 3], T)> {
        match self {
            Self::Stretched(k) => half_vector_direction(wo, p, k),
            Self::Radial(ks, kb) => radial_direction(wo, p, ks, kb),
            Self::Star(k) => star_direction(wo, p, k),
        }
    }

    /// The inverse of [`Self::direction`]: the square point of the unit light
    /// direction `wi` and the same Jacobian; `None` where no table point maps
    /// to `wi`.
    #[inline]
    pub fn point(self, wo: [T; 3], wi: [T; 3]) -> Option<([T; 2], T)> {
        match self {
            Self::Stretched(k) => half_vector_point(wo, wi, k),
            Self::Radial(ks, kb) => radial_point(wo, wi, ks, kb),
            Self::Star(k) => star_point(wo, wi, k),
        }
    }
}

/// The shared layers' square at `roughness` (clamped into `[MIN_ROUGHNESS,
/// MAX_ROUGHNESS]`): the radial square of `k_s = roughness` near the pole and
/// `k_b = roughness^(1/4)` ([`super::stretch`]) beyond [`RADIAL_CROSSOVER`]
/// (module docs). The same at every metallic, so that the two metallic nodes'
/// tables share the square and their blend is exact.
#[inline]
pub fn radial_square<T: Real>(roughness: T) -> PriorSquare<T> {
    PriorSquare::Radial(
        crate::brdf::clamp_roughness(roughness),
        super::stretch(roughness),
    )
}

/// The table slope `a` where the radial square's stretch turns from `k_s` to
/// `k_b` (module docs): chosen by measurement among 0.25 and 0.5 (a shifted
/// lattice at N = 256 on 48 held-out conditions, worst 1.563 against 1.636).
pub const RADIAL_CROSSOVER: f64 = 0.25;

/// The most steps of [`radial_point`]'s inverse of `σ(t)`: a Newton step where
/// it stays inside the bracket that the steps keep, else a bisection. A bound
/// on the work, not the usual count: the steps stop when the bracket can
/// shrink no more, Newton's within a few steps of the root.
pub const RADIAL_INVERSE_STEPS: usize = 64;

/// The metal layer's zoom at `roughness` (clamped into `[MIN_ROUGHNESS,
/// MAX_ROUGHNESS]`): `k = α = roughness^2`, the slope scale of the GGX lobe, so
/// that every roughness node's lobe spans the same share of its star disc.
#[inline]
pub fn metal_zoom<T: Real>(roughness: T) -> T {
    let r = crate::brdf::clamp_roughness(roughness);
    r * r
}

pub(super) fn dot<T: Real>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn normalized<T: Real>(v: [T; 3]) -> Option<[T; 3]> {
    let len = dot(v, v).sqrt();
    (len > T::ZERO && len.is_finite()).then(|| v.map(|c| c / len))
}

/// The mirror of the unit view `wo` about the unit half vector `h`, `wi = 2
/// (wo.h) h - wo` (normalized), and `wo.h`; `None` where `wo.h <= 0` (or NaN).
#[inline]
pub fn mirror<T: Real>(wo: [T; 3], h: [T; 3]) -> Option<([T; 3], T)> {
    let c = dot(wo, h);
    // NaN fails the comparison too.
    if c.partial_cmp(&T::ZERO) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let two_c = T::of(2.0) * c;
    let wi = normalized([0, 1, 2].map(|a| two_c * h[a] - wo[a]))?;
    Some((wi, c))
}

/// The half vector `h = (wo + wi) / |wo + wi|` of the unit view and light
/// directions and `wo.h`; `None` where `wi.z <= 0`, `h.z <= 0` or `wo.h <= 0`.
#[inline]
pub fn half_vector_of<T: Real>(wo: [T; 3], wi: [T; 3]) -> Option<([T; 3], T)> {
    if wi[2].partial_cmp(&T::ZERO) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let h = normalized([0, 1, 2].map(|a| wo[a] + wi[a]))?;
    let c = dot(wo, h);
    (h[2] > T::ZERO && c > T::ZERO).then_some((h, c))
}

/// The light direction of the half-vector square point `p` for the unit view
/// `wo` under the stretch `k` (module docs), `wi = 2 (wo.h) h - wo` with
/// `h = normalize(k h'.x, k h'.y, h'.z)`, `h' = square_to_hemisphere(p)`, and
/// the Jacobian `|dwi/dω_h'| = 4 (wo.h) k^2 / L^3`, `L = |(k h'.x, k h'.y,
/// h'.z)|` (`k = 1`: the plain half vector); `None` where `wo.h <= 0` or
/// `wi.z <= 0`.
#[inline]
pub fn half_vector_direction<T: Real>(wo: [T; 3], p: [T; 2], k: T) -> Option<([T; 3], T)> {
    let s = square_to_hemisphere_real(p);
    let v = [k * s[0], k * s[1], s[2]];
    let len = dot(v, v).sqrt();
    if len.partial_cmp(&T::ZERO) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let h = v.map(|c| c / len);
    let (wi, c) = mirror(wo, h)?;
    let jac = T::of(4.0) * c * k * k / (len * len * len);
    (wi[2] > T::ZERO && jac.is_finite()).then_some((wi, jac))
}

/// The inverse of [`half_vector_direction`]: the square point of the stretched
/// half vector `h' = normalize(h.x / k, h.y / k, h.z)` of `h = (wo + wi) / |wo +
/// wi|`, and the same Jacobian; `None` where no table point maps to `wi`
/// (`wi.z <= 0`, `h.z <= 0` or `wo.h <= 0`).
#[inline]
pub fn half_vector_point<T: Real>(wo: [T; 3], wi: [T; 3], k: T) -> Option<([T; 2], T)> {
    let (h, c) = half_vector_of(wo, wi)?;
    let v = [h[0] / k, h[1] / k, h[2]];
    let len = dot(v, v).sqrt();
    if !(len > T::ZERO && len.is_finite()) {
        return None;
    }
    let s = v.map(|x| x / len);
    let jac = T::of(4.0) * c * k * k * len * len * len;
    jac.is_finite().then(|| (hemisphere_to_square_real(s), jac))
}

/// The radial square's stretch `g = σ/t` and slope derivative `σ'(t)` at a
/// unit table direction of `ρ^2 = s.x^2 + s.y^2` and `z^2 = s.z^2` (module
/// docs).
#[inline]
fn radial_stretch<T: Real>(ks: T, kb: T, rho2: T, z2: T) -> (T, T) {
    let az2 = T::of(RADIAL_CROSSOVER * RADIAL_CROSSOVER) * z2;
    let d = rho2 + az2;
    let g = (kb * rho2 + ks * az2) / d;
    (g, g + T::of(2.0) * (kb - ks) * rho2 * az2 / (d * d))
}

/// The radial square's Jacobian `|dwi/dω_s| = 4 (wo.h) g σ'(t) / |v|^3`
/// (module docs), `v = (g s.x, g s.y, s.z)`, from `wo.h`, the stretch, the
/// slope derivative and `|v|`.
#[inline]
fn radial_jacobian<T: Real>(c: T, g: T, dsigma: T, len: T) -> T {
    T::of(4.0) * c * g * dsigma / (len * len * len)
}

/// The light direction of the radial square's point `p` for the unit view
/// `wo` (module docs), `wi = 2 (wo.h) h - wo` with `h = normalize(g s.x, g
/// s.y, s.z)`, `s = square_to_hemisphere(p)`, and the Jacobian `|dwi/dω_s| = 4
/// (wo.h) g σ'(t) / |(g s.x, g s.y, s.z)|^3`; `None` where `wo.h <= 0` or `wi.z
/// <= 0`. `k_s = k_b = k` is the stretched square of `k`
/// ([`half_vector_direction`]) up to rounding.
#[inline]
pub fn radial_direction<T: Real>(wo: [T; 3], p: [T; 2], ks: T, kb: T) -> Option<([T; 3], T)> {
    let s = square_to_hemisphere_real(p);
    let rho2 = s[0] * s[0] + s[1] * s[1];
    let (g, dsigma) = radial_stretch(ks, kb, rho2, s[2] * s[2]);
    let v = [g * s[0], g * s[1], s[2]];
    let len = dot(v, v).sqrt();
    if len.partial_cmp(&T::ZERO) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let (wi, c) = mirror(wo, v.map(|x| x / len))?;
    let jac = radial_jacobian(c, g, dsigma, len);
    (wi[2] > T::ZERO && jac.is_finite() && jac > T::ZERO).then_some((wi, jac))
}

/// The table slope `t >= 0` with `t g(t) = sigma` (module docs) for `k_b >=
/// k_s > 0`: inside `[sigma / k_b, sigma / k_s]`, by Newton steps kept inside
/// a shrinking bracket (bisection where a step leaves it), at most
/// [`RADIAL_INVERSE_STEPS`]. 0 for `sigma <= 0` or NaN.
fn radial_table_slope<T: Real>(ks: T, kb: T, sigma: T) -> T {
    if sigma.partial_cmp(&T::ZERO) != Some(core::cmp::Ordering::Greater) {
        return T::ZERO;
    }
    let (mut lo, mut hi) = (sigma / kb.max(ks), sigma / kb.min(ks));
    let mut t = lo;
    for _ in 0..RADIAL_INVERSE_STEPS {
        // The unit table direction of slope `t` is `(t, 1)` up to scale.
        let (g, dsigma) = radial_stretch(ks, kb, t * t, T::ONE);
        let miss = t * g - sigma;
        match miss > T::ZERO {
            true => hi = t,
            false => lo = t,
        }
        let step = t - miss / dsigma;
        let next = match step > lo && step < hi {
            true => step,
            false => T::of(0.5) * (lo + hi),
        };
        if !(next > lo && next < hi) || next == t {
            break;
        }
        t = next;
    }
    t
}

/// The inverse of [`radial_direction`]: the table point of `wi` (`h = (wo +
/// wi) / |wo + wi|`'s slope `σ` inverted by a bounded Newton iteration, azimuth
/// kept) and the same Jacobian; `None` where no table point maps to `wi`
/// (`wi.z <= 0`, `h.z <= 0`, `wo.h <= 0`, or `σ` beyond `10^18`, within
/// `10^-18` of the horizon).
#[inline]
pub fn radial_point<T: Real>(wo: [T; 3], wi: [T; 3], ks: T, kb: T) -> Option<([T; 2], T)> {
    let (h, c) = half_vector_of(wo, wi)?;
    let hxy = (h[0] * h[0] + h[1] * h[1]).sqrt();
    let sigma = hxy / h[2];
    // NaN fails the comparison too.
    if sigma.partial_cmp(&T::of(1e18)) != Some(core::cmp::Ordering::Less) {
        return None;
    }
    let e = unit_or_x([h[0], h[1]], hxy);
    let t = radial_table_slope(ks, kb, sigma);
    let z = T::ONE / (T::ONE + t * t).sqrt();
    let rho = t * z;
    let (g, dsigma) = radial_stretch(ks, kb, rho * rho, z * z);
    let len = (g * g * rho * rho + z * z).sqrt();
    let jac = radial_jacobian(c, g, dsigma, len);
    let s = [rho * e[0], rho * e[1], z];
    (jac.is_finite() && jac > T::ZERO).then(|| (hemisphere_to_square_real(s), jac))
}

/// How far the half vector's slope plane reaches above the horizon along the
/// unit direction `e` from the mirror direction (module docs): `R(e) = t e.x +
/// sqrt(1 + t^2 e.x^2)`, `t = wo.x / wo.z` (`wo.z` taken as at least `1e-6`).
/// In `(0, ∞)`: `(1 - sin θo) / cos θo` towards the viewer, `(1 + sin θo) /
/// cos θo` away from it, 1 across. Towards the viewer (`t e.x < 0`) it is
/// computed as `1 / (sqrt(1 + t^2 e.x^2) - t e.x)`, the same value without
/// the cancellation that costs `f32` three digits at grazing views.
#[inline]
pub fn horizon_reach<T: Real>(wo: [T; 3], e: [T; 2]) -> T {
    let t = wo[0] / wo[2].max(T::of(1e-6));
    let te = t * e[0];
    let root = (T::ONE + te * te).sqrt();
    match te < T::ZERO {
        true => T::ONE / (root - te),
        false => te + root,
    }
}

/// The unit direction of the plane vector `v` of length `len`, `(1, 0)` at the
/// origin (where every direction gives the same point).
fn unit_or_x<T: Real>(v: [T; 2], len: T) -> [T; 2] {
    match len > T::ZERO {
        true => [v[0] / len, v[1] / len],
        false => [T::ONE, T::ZERO],
    }
}

/// The star disc's Jacobian `|dwi/dω_d| = 4 (wo.h) |dω_h/ds| |ds/dq| / 2`
/// (module docs) at the slope radius `rho` and the radial factor `den = 1 - (1
/// - k/R) r`.
fn star_jacobian<T: Real>(c: T, rho: T, k: T, den: T) -> T {
    let len2 = T::ONE + rho * rho;
    T::of(2.0) * c * k * k / (len2 * len2.sqrt() * den * den * den)
}

/// The light direction of the star disc's square point `p` for the unit view
/// `wo` at the zoom `k > 0` (module docs), `wi = 2 (wo.h) h - wo` with `h =
/// normalize(ρ e, 1)`, and the Jacobian `|dwi/dω_d| = 2 (wo.h) k^2 / ((1 +
/// ρ^2)^(3/2) (1 - (1 - k/R) r)^3)`; `None` where `wo.h <= 0` or `wi.z <= 0`
/// (only by rounding at the rim).
#[inline]
pub fn star_direction<T: Real>(wo: [T; 3], p: [T; 2], k: T) -> Option<([T; 3], T)> {
    let d = square_to_hemisphere_real(p);
    let z = d[2].max(T::ZERO);
    let f = (T::ONE + z).sqrt();
    let q = [d[0] / f, d[1] / f];
    let r = (q[0] * q[0] + q[1] * q[1]).sqrt().min(T::ONE);
    let e = unit_or_x(q, r);
    // `1 - (1 - k/R) r` with `1 - r = z / (1 + r)` (Lambert: `z = 1 - r^2`):
    // no cancellation near the rim, where a smooth metal's horizon lies.
    let den = z / (T::ONE + r) + k / horizon_reach(wo, e) * r;
    let rho = k * r / den;
    let l = (T::ONE + rho * rho).sqrt();
    let h = [rho * e[0] / l, rho * e[1] / l, T::ONE / l];
    let (wi, c) = mirror(wo, h)?;
    let jac = star_jacobian(c, rho, k, den);
    (wi[2] > T::ZERO && jac.is_finite() && jac > T::ZERO).then_some((wi, jac))
}

/// The inverse of [`star_direction`]: the square point of `h = (wo + wi) / |wo
/// + wi|`'s slope `s = ρ e`, at disc radius `r = ρ / (k + (1 - k/R(e)) ρ)`, and
/// the same Jacobian; `None` where no table point maps to `wi` (`wi.z <= 0`,
/// `h.z <= 0`, `wo.h <= 0`, or a slope past the horizon's reach by rounding).
#[inline]
pub fn star_point<T: Real>(wo: [T; 3], wi: [T; 3], k: T) -> Option<([T; 2], T)> {
    let (h, c) = half_vector_of(wo, wi)?;
    let s = [h[0] / h[2], h[1] / h[2]];
    let rho = (s[0] * s[0] + s[1] * s[1]).sqrt();
    let e = unit_or_x(s, rho);
    let reach = horizon_reach(wo, e);
    if !(rho < reach && rho.is_finite()) {
        return None;
    }
    // `r`, `den = 1 - (1 - k/R) r` and `1 - r` as quotients by `g`: no
    // cancellation near the rim.
    let g = k + (T::ONE - k / reach) * rho;
    let r = rho / g;
    let den = k / g;
    let z = k * (reach - rho) / (reach * g) * (T::ONE + r);
    let jac = star_jacobian(c, rho, k, den);
    let lift = (T::ONE + z).sqrt();
    let d = [r * e[0] * lift, r * e[1] * lift, z];
    (jac.is_finite() && jac > T::ZERO).then(|| (hemisphere_to_square_real(d), jac))
}
