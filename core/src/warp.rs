//! Warps of the unit square, each beside its density and its inverse: what a
//! baseline sampler applies to a uniform point `u` in `[0,1)^2`.
//!
//! | warp | density of the image (`u` uniform) | inverse |
//! |---|---|---|
//! | [`square_to_disk`] (Shirley–Chiu concentric map) | [`DISK_PDF`] `= 1/pi` per unit area | [`disk_to_square`] |
//! | [`square_to_cosine_hemisphere`] (Malley's method) | [`cosine_hemisphere_pdf`] `= max(z,0)/pi` per steradian | [`cosine_hemisphere_to_square`] |
//! | [`sample_ggx_vndf`] (GGX visible normals, Heitz 2018) | [`ggx_vndf_pdf`] `= G1(v) max(0,v.h) D(h) / v.z` per steradian | [`ggx_vndf_to_square`] |
//! | [`sample_ggx_vndf_reflected`] (`v` reflected about a visible normal) | [`ggx_vndf_reflected_pdf`] `= D_v(h) / (4 |v.h|)` per steradian | [`ggx_vndf_reflected_to_square`] |
//! | [`brdf_mixture_real`] (GGX lobe with probability `p_s`, else cosine; mirrored to `z >= 0`) | [`brdf_mixture_pdf`] `= p_s [v(w) + v(w')] + (1 - p_s) z / pi` per steradian | none: two lobes and the mirror reach the same direction |
//!
//! The equal-area maps of [`crate::sphere`] are warps too (constant density
//! `1/(4 pi)` and `1/(2 pi)`); the hemisphere map lifts the concentric disk of this
//! module.
//!
//! The warps are written once over [`Real`] (the `*_real` functions; the `DVec`
//! ones call them in `f64`): the build tool evaluates them in `f64`, the runtime
//! evaluates the same formulas in `f32`, as a shader does. Densities and inverses
//! are `f64` only (the tool's side). Everything is `no_std` (math through `libm`).
//! Nothing here panics; each function says what it does off its domain.

use crate::brdf::{ggx_d, smith_g1};
use crate::real::Real;
use core::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};
use glam::{DVec2, DVec3};

/// `sqrt(max(x, 0))`: rounding can push an argument that is mathematically
/// non-negative slightly below zero. NaN reads as 0 ([`Real::max`]).
#[inline]
pub(crate) fn safe_sqrt<T: Real>(x: T) -> T {
    x.max(T::ZERO).sqrt()
}

/// Density per unit area of [`square_to_disk`]'s image of a uniform point: `1/pi`
/// (the map preserves area up to the factor `pi`).
pub const DISK_PDF: f64 = 1.0 / PI;

/// Signed polar form `(r, theta)` of the concentric map (Shirley and Chiu 1997, "A
/// Low Distortion Map Between Disk and Square", as pbrt-v4's `SampleUniformDiskConcentric`):
/// the disk point is `r (cos theta, sin theta)`, `r` in `[-1, 1]`,
/// `theta` in `[-pi/4, 3pi/4]`; `None` at the square's centre. Shared by
/// [`square_to_disk`] and [`crate::sphere::square_to_hemisphere_real`], which lifts
/// it; generic so that the runtime evaluates the same formula in `f32`.
#[inline]
pub(crate) fn concentric_polar<T: Real>(u: [T; 2]) -> Option<(T, T)> {
    let two = T::of(2.0);
    let a = two * u[0] - T::ONE;
    let b = two * u[1] - T::ONE;
    if a == T::ZERO && b == T::ZERO {
        return None;
    }
    let quarter_pi = T::of(FRAC_PI_4);
    Some(if a.abs() > b.abs() {
        (a, quarter_pi * (b / a))
    } else {
        (b, T::of(FRAC_PI_2) - quarter_pi * (a / b))
    })
}

/// Inverse of [`concentric_polar`] from a radius `r` in `[0, 1]` and an angle `phi`
/// in `(-pi, pi]` (as `atan2` returns it) to the square point.
#[inline]
pub(crate) fn concentric_polar_inverse(r: f64, mut phi: f64) -> DVec2 {
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    let (a, b) = if phi < FRAC_PI_4 {
        (r, phi * r / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        (-(phi - FRAC_PI_2) * r / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        (-r, -(phi - PI) * r / FRAC_PI_4)
    } else {
        ((phi - 3.0 * FRAC_PI_2) * r / FRAC_PI_4, -r)
    };
    DVec2::new(0.5 * (a + 1.0), 0.5 * (b + 1.0))
}

/// Shirley–Chiu concentric map of `[0,1]^2` onto the unit disk: concentric squares
/// go to concentric circles, area is preserved up to the factor `pi` (density
/// [`DISK_PDF`]).
///
/// The centre maps to the origin, the edge midpoints `(1, 1/2)`, `(1/2, 1)`, ... to
/// `(1, 0)`, `(0, 1)`, ..., the corner `(1, 1)` to `(1, 1)/sqrt 2`. Inputs outside
/// `[0,1]^2` are not clamped; they land outside the disk.
///
/// ```
/// # use nuld_core::warp::square_to_disk; use glam::DVec2;
/// assert_eq!(square_to_disk(DVec2::new(0.5, 0.5)), DVec2::ZERO);
/// assert!((square_to_disk(DVec2::new(0.75, 0.5)) - DVec2::new(0.5, 0.0)).length() < 1e-15);
/// let c = square_to_disk(DVec2::ONE);
/// assert!((c - DVec2::splat(core::f64::consts::FRAC_1_SQRT_2)).length() < 1e-15);
/// ```
pub fn square_to_disk(u: DVec2) -> DVec2 {
    DVec2::from_array(square_to_disk_real(u.to_array()))
}

/// [`square_to_disk`] in any [`Real`]: with `a = 2 u.x - 1`, `b = 2 u.y - 1`,
/// `r (cos theta, sin theta)` for `(r, theta) = (a, pi/4 (b / a))` if `|a| > |b|`,
/// else `(b, pi/2 - pi/4 (a / b))`; the origin at the square's centre. The one
/// formula, which [`square_to_cosine_hemisphere_real`] lifts and the runtime
/// evaluates in `f32`.
#[inline]
pub fn square_to_disk_real<T: Real>(u: [T; 2]) -> [T; 2] {
    match concentric_polar(u) {
        None => [T::ZERO, T::ZERO],
        Some((r, theta)) => {
            let (sin_theta, cos_theta) = theta.sin_cos();
            [r * cos_theta, r * sin_theta]
        }
    }
}

/// Inverse of [`square_to_disk`]. Points outside the unit disk are first pulled
/// radially onto its rim (so the result is always in `[0,1]^2`); the origin and
/// non-finite input give the centre `(1/2, 1/2)`.
pub fn disk_to_square(d: DVec2) -> DVec2 {
    let r = libm::sqrt(d.x * d.x + d.y * d.y);
    if r == 0.0 || !r.is_finite() {
        return DVec2::splat(0.5);
    }
    concentric_polar_inverse(r.min(1.0), libm::atan2(d.y, d.x))
}

/// Cosine-weighted directions about `+z` by Malley's method (as pbrt-v4's
/// `SampleCosineHemisphere`): [`square_to_disk`], then the lift
/// `z = sqrt(1 - x^2 - y^2)`. Density [`cosine_hemisphere_pdf`]; unit vectors with
/// `z >= 0` for `u` in `[0,1]^2` (outside, the disk point leaves the disk and `z`
/// is 0).
///
/// ```
/// # use nuld_core::warp::square_to_cosine_hemisphere; use glam::{DVec2, DVec3};
/// assert_eq!(square_to_cosine_hemisphere(DVec2::splat(0.5)), DVec3::Z);
/// let d = square_to_cosine_hemisphere(DVec2::new(0.75, 0.5));
/// assert!((d - DVec3::new(0.5, 0.0, 0.75f64.sqrt())).length() < 1e-15);
/// ```
pub fn square_to_cosine_hemisphere(u: DVec2) -> DVec3 {
    DVec3::from_array(square_to_cosine_hemisphere_real(u.to_array()))
}

/// [`square_to_cosine_hemisphere`] in any [`Real`]: the one formula, which the
/// runtime evaluates in `f32`.
#[inline]
pub fn square_to_cosine_hemisphere_real<T: Real>(u: [T; 2]) -> [T; 3] {
    let [x, y] = square_to_disk_real(u);
    [x, y, safe_sqrt(T::ONE - (x * x + y * y))]
}

/// Density per steradian of [`square_to_cosine_hemisphere`]: `max(z, 0) / pi` for a
/// unit vector `d` (0 below the horizon and for NaN `z`).
#[inline]
pub fn cosine_hemisphere_pdf(d: DVec3) -> f64 {
    d.z.max(0.0) / PI
}

/// Inverse of [`square_to_cosine_hemisphere`]: [`disk_to_square`] of `(d.x, d.y)`.
/// A direction below the horizon gives the point of its mirror image `(x, y, -z)`.
pub fn cosine_hemisphere_to_square(d: DVec3) -> DVec2 {
    disk_to_square(d.truncate())
}

/// The stretched view direction `V_h = normalize(alpha wo.x, alpha wo.y, wo.z)` and
/// the orthonormal frame `(T1, T2, V_h)` of Heitz 2018, Listing 1 (isotropic
/// `alpha`): `T1 = (-V_h.y, V_h.x, 0) / |.|` (`+x` when `V_h` is `+z`),
/// `T2 = V_h x T1`. Shared by the warp and its inverse, in any [`Real`].
#[inline]
fn vndf_frame<T: Real>(wo: [T; 3], alpha: T) -> [[T; 3]; 3] {
    let (zero, one) = (T::ZERO, T::ONE);
    let vh = normalize_real([alpha * wo[0], alpha * wo[1], wo[2]]);
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if lensq > zero {
        let len = lensq.sqrt();
        // `zero - x` rather than `-x`: a zero component comes out `+0`, the bits
        // the runtime (and its shader twin) has always produced.
        [zero - vh[1] / len, vh[0] / len, zero]
    } else {
        [one, zero, zero]
    };
    let t2 = [
        vh[1] * t1[2] - t1[1] * vh[2],
        vh[2] * t1[0] - t1[2] * vh[0],
        vh[0] * t1[1] - t1[0] * vh[1],
    ];
    [vh, t1, t2]
}

/// GGX visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of
/// Visible Normals", JCGT 7(4), Listing 1), isotropic width `alpha`: a microfacet
/// normal `h` (unit, `h.z >= 0`) distributed by [`ggx_vndf_pdf`]
/// `D_v(h) = G1(v) max(0, v.h) D(h) / v.z` when `u` is uniform in `[0,1)^2`.
///
/// `wo` is the view direction `v`, a unit vector with `wo.z > 0`; `alpha > 0`
/// ([`crate::brdf::alpha`]). `u.x` is clamped into `[0, 1]`, `u.y` is an angle
/// fraction (any value). A zero `wo` or `alpha` gives NaN, not a panic.
///
/// ```
/// # use nuld_core::warp::sample_ggx_vndf; use glam::{DVec2, DVec3};
/// // alpha = 1, v = +z: D_v(h) = h.z / pi, and the warp is the polar map
/// // h = (sqrt(u.x) cos 2 pi u.y, sqrt(u.x) sin 2 pi u.y, sqrt(1 - u.x)).
/// let h = sample_ggx_vndf(DVec3::Z, 1.0, DVec2::new(0.36, 0.25));
/// assert!((h - DVec3::new(0.0, 0.6, 0.8)).length() < 1e-15);
/// ```
pub fn sample_ggx_vndf(wo: DVec3, alpha: f64, u: DVec2) -> DVec3 {
    DVec3::from_array(sample_ggx_vndf_real(wo.to_array(), alpha, u.to_array()))
}

/// `x / |x|` (NaN for a zero vector), as `glam`'s `normalize`.
#[inline]
fn normalize_real<T: Real>(x: [T; 3]) -> [T; 3] {
    let inv = T::ONE / (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    x.map(|c| c * inv)
}

/// [`sample_ggx_vndf`] in any [`Real`]: the one formula, which the runtime
/// evaluates in `f32` (`u.x` NaN counts as 0).
#[inline]
pub fn sample_ggx_vndf_real<T: Real>(wo: [T; 3], alpha: T, u: [T; 2]) -> [T; 3] {
    let (zero, one, half) = (T::ZERO, T::ONE, T::of(0.5));
    let [vh, t1, t2] = vndf_frame(wo, alpha);
    let r = u[0].max(zero).min(one).sqrt();
    let phi = T::of(2.0) * T::PI * u[1];
    let (sin_phi, cos_phi) = phi.sin_cos();
    let p1 = r * cos_phi;
    let mut p2 = r * sin_phi;
    // Squash the disk's lower half onto the part of the projected hemisphere that
    // the stretched view direction sees (Heitz 2018, §4.2).
    let s = half * (one + vh[2]);
    p2 = (one - s) * safe_sqrt(one - p1 * p1) + s * p2;
    let q = safe_sqrt(one - p1 * p1 - p2 * p2);
    let nh: [T; 3] = core::array::from_fn(|c| p1 * t1[c] + p2 * t2[c] + q * vh[c]);
    normalize_real([alpha * nh[0], alpha * nh[1], nh[2].max(zero)])
}

/// The renderer's mixture warp for a BRDF with a GGX lobe and a diffuse lobe
/// (the incumbent of paper §4's comparison, and the prior of the conditional
/// sampler's [`crate::conditional::PointWarp::BrdfMixture`]): `u.x < p_s` picks
/// [`sample_ggx_vndf_real`] reflected about the normal (`wi = 2 (wo.h) h - wo`,
/// `u.x / p_s` as its first coordinate), otherwise
/// [`square_to_cosine_hemisphere_real`] of `((u.x - p_s) / (1 - p_s), u.y)`; a
/// direction below the horizon is mirrored (`z -> |z|`). `wo` is the unit view
/// direction (`z > 0`), `alpha = roughness^2 > 0`, `p_s` in `[0, 1]` the lobe
/// probability (the specular share of the albedo), `u` in `[0,1]^2` (`u.x` clamped,
/// NaN as 0). A unit vector with `z >= 0`.
#[inline]
pub fn brdf_mixture_real<T: Real>(wo: [T; 3], alpha: T, p_s: T, u: [T; 2]) -> [T; 3] {
    let (zero, one) = (T::ZERO, T::ONE);
    let ux = u[0].max(zero).min(one);
    let wi = if ux < p_s {
        sample_ggx_vndf_reflected_real(wo, alpha, [(ux / p_s).min(one), u[1]])
    } else {
        let r = ((ux - p_s) / (one - p_s)).max(zero).min(one);
        square_to_cosine_hemisphere_real([r, u[1]])
    };
    normalize_real([wi[0], wi[1], wi[2].abs()])
}

/// Density per steradian of [`brdf_mixture_real`]'s directions (`u` uniform in
/// `[0,1)^2`) at a unit `wi`: the GGX lobe [`ggx_vndf_reflected_pdf`] `v` and the
/// cosine lobe [`cosine_hemisphere_pdf`] mixed by `p_s`; GGX directions below the
/// horizon are mirrored, so both `wi` and its mirror image `wi' = (x, y, -z)`
/// contribute: `p(wi) = p_s [v(wi) + v(wi')] + (1 - p_s) max(z, 0) / pi`, 0 for
/// `z < 0`. Same `wo`, `alpha`, `p_s` as the warp. The warp has no unique inverse
/// (two lobes, and the mirror, reach the same `wi`).
pub fn brdf_mixture_pdf(wo: DVec3, alpha: f64, p_s: f64, wi: DVec3) -> f64 {
    if wi.z < 0.0 {
        return 0.0;
    }
    let mirror = DVec3::new(wi.x, wi.y, -wi.z);
    p_s * (ggx_vndf_reflected_pdf(wo, alpha, wi) + ggx_vndf_reflected_pdf(wo, alpha, mirror))
        + (1.0 - p_s) * cosine_hemisphere_pdf(wi)
}

/// Density per steradian of [`sample_ggx_vndf`]'s normals: the distribution of
/// visible normals `D_v(h) = G1(v) max(0, v.h) D(h) / v.z` (Heitz 2018, Eq. 1) with
/// [`crate::brdf::ggx_d`] and [`crate::brdf::smith_g1`]; `wo = v` and `h` unit.
/// 0 for `h.z <= 0`, `v.h <= 0` or `v.z <= 0`.
pub fn ggx_vndf_pdf(wo: DVec3, alpha: f64, h: DVec3) -> f64 {
    let wo_h = wo.dot(h);
    if !(wo.z > 0.0 && h.z > 0.0 && wo_h > 0.0) {
        return 0.0;
    }
    smith_g1(wo.z, alpha) * wo_h * ggx_d(h.z, alpha) / wo.z
}

/// Inverse of [`sample_ggx_vndf`]: the `u` in `[0,1]^2` whose normal is `h` (a unit
/// vector with `h.z > 0` and `wo.h > 0`, i.e. in the support of [`ggx_vndf_pdf`]).
/// It undoes each step of the warp: unstretch `h`, project onto the frame, unsquash,
/// and read the disk point's polar coordinates (`u.y` in `[0, 1)`). Outside the
/// support the result is clamped into `[0,1]^2` but does not map back to `h`.
pub fn ggx_vndf_to_square(wo: DVec3, alpha: f64, h: DVec3) -> DVec2 {
    let [vh, t1, t2] = vndf_frame(wo.to_array(), alpha).map(DVec3::from_array);
    let nh = DVec3::new(h.x / alpha, h.y / alpha, h.z.max(0.0)).normalize_or_zero();
    let p1 = nh.dot(t1);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (nh.dot(t2) - (1.0 - s) * safe_sqrt(1.0 - p1 * p1)) / s;
    let mut phi = libm::atan2(p2, p1);
    if phi < 0.0 {
        phi += TAU;
    }
    let ux = p1 * p1 + p2 * p2;
    let uy = phi / TAU;
    let clamp = |x: f64| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    DVec2::new(clamp(ux), clamp(uy))
}

/// The view direction `wo` reflected about a visible normal from [`sample_ggx_vndf`]:
/// `wi = 2 (wo.h) h - wo`, the light direction of GGX importance sampling. Density
/// [`ggx_vndf_reflected_pdf`]; `wi` may lie below the horizon (`wi.z < 0`), where
/// the BRDF is zero.
pub fn sample_ggx_vndf_reflected(wo: DVec3, alpha: f64, u: DVec2) -> DVec3 {
    DVec3::from_array(sample_ggx_vndf_reflected_real(
        wo.to_array(),
        alpha,
        u.to_array(),
    ))
}

/// [`sample_ggx_vndf_reflected`] in any [`Real`]: `wi = d h - wo` with
/// `d = 2 (wo.h)` and `h` from [`sample_ggx_vndf_real`]. The one formula, which
/// [`brdf_mixture_real`] uses for its GGX lobe and the runtime evaluates in `f32`.
#[inline]
pub fn sample_ggx_vndf_reflected_real<T: Real>(wo: [T; 3], alpha: T, u: [T; 2]) -> [T; 3] {
    let h = sample_ggx_vndf_real(wo, alpha, u);
    let d = T::of(2.0) * (wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]);
    core::array::from_fn(|c| d * h[c] - wo[c])
}

/// Density per steradian of [`sample_ggx_vndf_reflected`]:
/// `D_v(h) / (4 |wo.h|) = G1(wo) D(h) / (4 wo.z)` with `h = normalize(wo + wi)`
/// (Heitz 2018, Eq. 17; the reflection's Jacobian is `1 / (4 |wo.h|)`). Defined on
/// the whole sphere of `wi` (0 where `h.z <= 0`, `wo.h <= 0` or `wo.z <= 0`).
pub fn ggx_vndf_reflected_pdf(wo: DVec3, alpha: f64, wi: DVec3) -> f64 {
    let h = (wo + wi).normalize_or_zero();
    if !(wo.z > 0.0 && h.z > 0.0 && wo.dot(h) > 0.0) {
        return 0.0;
    }
    smith_g1(wo.z, alpha) * ggx_d(h.z, alpha) / (4.0 * wo.z)
}

/// Inverse of [`sample_ggx_vndf_reflected`]: [`ggx_vndf_to_square`] of the half
/// vector `normalize(wo + wi)`; same support and clamping.
pub fn ggx_vndf_reflected_to_square(wo: DVec3, alpha: f64, wi: DVec3) -> DVec2 {
    ggx_vndf_to_square(wo, alpha, (wo + wi).normalize_or_zero())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::{square_to_hemisphere, square_to_sphere};

    /// Interior points of an `n x n` grid, kept away from the creases of the maps
    /// (the concentric map's diagonals, `u.y = 0`) where central differences straddle
    /// a kink.
    fn grid(n: usize) -> impl Iterator<Item = DVec2> {
        (0..n).flat_map(move |i| {
            (0..n).map(move |j| {
                DVec2::new((i as f64 + 0.37) / n as f64, (j as f64 + 0.61) / n as f64)
            })
        })
    }

    /// `|df/du x df/dv|` by central differences: the area (or, for unit vectors,
    /// solid-angle) element of the map at `p`, per unit area of the square.
    fn element3(f: impl Fn(DVec2) -> DVec3, p: DVec2, h: f64) -> f64 {
        let du = (f(p + DVec2::X * h) - f(p - DVec2::X * h)) / (2.0 * h);
        let dv = (f(p + DVec2::Y * h) - f(p - DVec2::Y * h)) / (2.0 * h);
        du.cross(dv).length()
    }

    /// `∫ g dω` over the sphere (or the upper hemisphere) by the midpoint rule on an
    /// `m x m` grid of the equal-area map.
    fn integrate(m: usize, hemisphere: bool, g: impl Fn(DVec3) -> f64) -> f64 {
        let mut s = 0.0;
        for k in 0..m * m {
            let p = DVec2::new(
                ((k % m) as f64 + 0.5) / m as f64,
                ((k / m) as f64 + 0.5) / m as f64,
            );
            s += g(if hemisphere {
                square_to_hemisphere(p)
            } else {
                square_to_sphere(p)
            });
        }
        let area = if hemisphere { 2.0 * PI } else { 4.0 * PI };
        s * area / (m * m) as f64
    }

    /// View directions and widths the GGX tests run over (normal to grazing view;
    /// smooth to rough).
    const VIEWS: [(f64, f64); 6] = [
        (0.0, 0.3),
        (30.0, 0.5),
        (60.0, 0.2),
        (75.0, 1.0),
        (85.0, 0.6),
        (45.0, 0.05),
    ];

    fn view(theta_deg: f64) -> DVec3 {
        let t = theta_deg.to_radians();
        DVec3::new(libm::sin(t), 0.0, libm::cos(t))
    }

    #[test]
    fn disk_round_trips_and_has_area_element_pi() {
        for p in grid(61) {
            let d = square_to_disk(p);
            assert!(d.length() <= 1.0 + 1e-15);
            let q = disk_to_square(d);
            assert!((p - q).length() < 1e-12, "{p:?} -> {d:?} -> {q:?}");
            let lift = |u: DVec2| square_to_disk(u).extend(0.0);
            let a = element3(lift, p, 1e-6);
            assert!((a * DISK_PDF - 1.0).abs() < 1e-6, "{p:?}: {a}");
        }
        assert_eq!(disk_to_square(DVec2::ZERO), DVec2::splat(0.5));
        assert_eq!(disk_to_square(DVec2::splat(f64::NAN)), DVec2::splat(0.5));
        // Outside the disk: pulled onto the rim, so the edge midpoint.
        assert!((disk_to_square(DVec2::new(3.0, 0.0)) - DVec2::new(1.0, 0.5)).length() < 1e-15);
    }

    #[test]
    fn cosine_hemisphere_round_trips_and_pdf_is_the_jacobian() {
        for p in grid(61) {
            let d = square_to_cosine_hemisphere(p);
            assert!((d.length() - 1.0).abs() < 1e-14 && d.z >= 0.0);
            let q = cosine_hemisphere_to_square(d);
            assert!((p - q).length() < 1e-12, "{p:?} -> {d:?} -> {q:?}");
            // Solid angle per unit square area is 1 / pdf (near the rim, z -> 0, the
            // lift's derivative grows like 1/z, so the step is kept small).
            let a = element3(square_to_cosine_hemisphere, p, 1e-7);
            let pdf = cosine_hemisphere_pdf(d);
            assert!((a * pdf - 1.0).abs() < 1e-4, "{p:?}: {a} {pdf}");
        }
        let mirror = cosine_hemisphere_to_square(DVec3::new(0.6, 0.0, -0.8));
        assert_eq!(
            mirror,
            cosine_hemisphere_to_square(DVec3::new(0.6, 0.0, 0.8))
        );
        assert_eq!(cosine_hemisphere_pdf(DVec3::new(0.0, 1.0, -0.0)), 0.0);
    }

    #[test]
    fn cosine_hemisphere_pdf_integrates_to_one() {
        // The kink at z = 0 lies on cell boundaries of the octahedral grid; the
        // error is O(m^-2) (-3.8e-6 at m = 1024).
        let s = integrate(1024, false, cosine_hemisphere_pdf);
        assert!((s - 1.0).abs() < 1e-5, "{s}");
    }

    #[test]
    fn vndf_round_trips() {
        for (t, a) in VIEWS {
            let wo = view(t);
            for p in grid(41) {
                let h = sample_ggx_vndf(wo, a, p);
                assert!((h.length() - 1.0).abs() < 1e-14 && h.z >= 0.0);
                assert!(wo.dot(h) >= -1e-15, "t={t} a={a}: {h:?} invisible");
                let q = ggx_vndf_to_square(wo, a, h);
                assert!((p - q).length() < 1e-9, "t={t} a={a}: {p:?} -> {q:?}");
                let wi = sample_ggx_vndf_reflected(wo, a, p);
                let q = ggx_vndf_reflected_to_square(wo, a, wi);
                assert!((p - q).length() < 1e-9, "t={t} a={a}: {p:?} -> {q:?}");
            }
        }
    }

    #[test]
    fn vndf_pdfs_are_the_jacobians_of_the_warps() {
        for (t, a) in VIEWS {
            let wo = view(t);
            for p in grid(23) {
                let h = sample_ggx_vndf(wo, a, p);
                let pdf = ggx_vndf_pdf(wo, a, h);
                let el = element3(|u| sample_ggx_vndf(wo, a, u), p, 1e-7);
                assert!(
                    (el * pdf - 1.0).abs() < 1e-4,
                    "t={t} a={a} {p:?}: {el} {pdf}"
                );
                let wi = sample_ggx_vndf_reflected(wo, a, p);
                let pdf = ggx_vndf_reflected_pdf(wo, a, wi);
                let el = element3(|u| sample_ggx_vndf_reflected(wo, a, u), p, 1e-7);
                assert!(
                    (el * pdf - 1.0).abs() < 1e-4,
                    "t={t} a={a} {p:?}: {el} {pdf}"
                );
            }
        }
    }

    #[test]
    fn vndf_pdfs_integrate_to_one() {
        // Wide lobes, which the equal-area grids resolve.
        for (t, a) in [(0.0, 0.5), (40.0, 1.0), (70.0, 0.6)] {
            let wo = view(t);
            // O(m^-2): about 1e-6 at m = 1024.
            let s = integrate(1024, true, |h| ggx_vndf_pdf(wo, a, h));
            assert!((s - 1.0).abs() < 1e-5, "t={t} a={a}: {s}");
            // Reflected directions cover the whole sphere, below the horizon too. The
            // density jumps to 0 where the half vector reaches the horizon, a curve
            // the grid cells straddle, so the midpoint rule is only O(1/m) there
            // (|error| about 2e-4 at m = 1024).
            let s = integrate(1024, false, |wi| ggx_vndf_reflected_pdf(wo, a, wi));
            assert!((s - 1.0).abs() < 6e-4, "t={t} a={a}: {s}");
        }
    }

    /// Views, widths and lobe probabilities of the mixture-warp tests (wide enough
    /// lobes for the quadratures to resolve; from nearly all-diffuse to nearly
    /// all-specular).
    const MIXTURES: [(f64, f64, f64); 3] = [(45.0, 0.09, 0.4), (10.0, 0.3, 0.8), (70.0, 0.6, 0.15)];

    fn mixture(wo: DVec3, a: f64, p_s: f64, u: DVec2) -> DVec3 {
        DVec3::from_array(brdf_mixture_real(wo.to_array(), a, p_s, u.to_array()))
    }

    #[test]
    fn mixture_pdf_integrates_to_one_and_weights_a_density_to_its_mass() {
        for (t, a, p_s) in MIXTURES {
            let wo = view(t);
            // The mirrored GGX lobe jumps to 0 where its half vector reaches the
            // horizon: O(1/m) for the midpoint rule, as in `vndf_pdfs_integrate_to_one`.
            let s = integrate(1024, true, |wi| brdf_mixture_pdf(wo, a, p_s, wi));
            // Measured |error| at most 5.5e-5.
            assert!((s - 1.0).abs() < 5e-4, "t={t} a={a} p_s={p_s}: {s}");
            // E_p[g / p] = ∫ g = 1 for the cosine density g, over a stratified grid of
            // warped points: p is the density of what the warp produces (g / p is
            // bounded by 1 / (1 - p_s)).
            let m = 1024;
            let mean = grid(m)
                .map(|u| {
                    let wi = mixture(wo, a, p_s, u);
                    cosine_hemisphere_pdf(wi) / brdf_mixture_pdf(wo, a, p_s, wi)
                })
                .sum::<f64>()
                / (m * m) as f64;
            // Measured |mean - 1| at most 3.4e-4.
            assert!((mean - 1.0).abs() < 1e-3, "t={t} a={a} p_s={p_s}: {mean}");
        }
    }

    /// A histogram of warped points on the equal-area cells of the hemisphere
    /// against the pdf integrated over each cell.
    #[test]
    fn mixture_pdf_matches_a_histogram_of_the_warp() {
        use crate::sphere::hemisphere_to_square;
        const CELLS: usize = 8;
        for (t, a, p_s) in MIXTURES {
            let wo = view(t);
            let mut counts = [[0usize; CELLS]; CELLS];
            let m = 1024;
            for u in grid(m) {
                let wi = mixture(wo, a, p_s, u);
                assert!(wi.z >= 0.0 && (wi.length() - 1.0).abs() < 1e-12);
                let q = hemisphere_to_square(wi) * CELLS as f64;
                let (i, j) = ((q.x as usize).min(CELLS - 1), (q.y as usize).min(CELLS - 1));
                counts[j][i] += 1;
            }
            // Each cell's mass by the midpoint rule on a sub x sub grid of it.
            let sub = 64;
            let cell_area = 2.0 * PI / (CELLS * CELLS) as f64;
            let mut worst = 0.0f64;
            for (j, row) in counts.iter().enumerate() {
                for (i, &count) in row.iter().enumerate() {
                    let mut mass = 0.0;
                    for k in 0..sub * sub {
                        let p = DVec2::new(
                            (i as f64 + ((k % sub) as f64 + 0.5) / sub as f64) / CELLS as f64,
                            (j as f64 + ((k / sub) as f64 + 0.5) / sub as f64) / CELLS as f64,
                        );
                        mass += brdf_mixture_pdf(wo, a, p_s, square_to_hemisphere(p));
                    }
                    mass *= cell_area / (sub * sub) as f64;
                    let frac = count as f64 / (m * m) as f64;
                    worst = worst.max((frac - mass).abs());
                }
            }
            // Cells hold about 1/64 of the mass each; measured worst 1.7e-4
            // (stratification and quadrature error).
            assert!(worst < 5e-4, "t={t} a={a} p_s={p_s}: {worst}");
        }
    }

    #[test]
    fn vndf_pdfs_are_zero_off_their_support() {
        let wo = view(30.0);
        assert_eq!(ggx_vndf_pdf(wo, 0.5, DVec3::new(0.0, 0.0, -1.0)), 0.0);
        // A normal facing away from the view.
        let back = DVec3::new(-0.99, 0.0, 0.141).normalize();
        assert_eq!(ggx_vndf_pdf(wo, 0.5, back), 0.0);
        assert_eq!(ggx_vndf_reflected_pdf(wo, 0.5, -wo), 0.0);
        assert_eq!(ggx_vndf_pdf(DVec3::new(1.0, 0.0, 0.0), 0.5, DVec3::Z), 0.0);
    }
}
