//! Equal-area maps between the unit square and the sphere or the upper hemisphere.
//!
//! Directions are stored and optimized as points of the unit square; these maps turn
//! them into unit vectors. Both maps preserve area up to a constant factor, so a
//! uniform density on the square becomes a uniform density on the (hemi)sphere:
//!
//! * [`square_to_sphere`]: `pdf_sphere = pdf_square / (4 pi)`;
//! * [`square_to_hemisphere`]: `pdf_hemisphere = pdf_square / (2 pi)`.
//!
//! The `DVec` maps compute in `f64`; [`square_to_sphere_real`] and
//! [`square_to_hemisphere_real`] are the same formulas in any [`Real`] precision
//! (the `f64` maps call them), which the runtime's conditional sampler evaluates in
//! `f32`, as a shader does.

use crate::real::Real;
use crate::warp::{concentric_polar, concentric_polar_inverse, safe_sqrt};
use core::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use glam::{DVec2, DVec3};

/// Equal-area octahedral map from `[0,1]^2` to the unit sphere (Clarberg 2008, as
/// pbrt-v4's `EqualAreaSquareToSphere`).
///
/// The square's centre `(0.5, 0.5)` maps to `+z`, its four corners to `-z`, and the
/// edge midpoints to the equator's `-y`, `+x`, `+y`, `-x` (bottom, right, top, left).
/// Inputs outside `[0,1]^2` are not wrapped; call [`wrap_octahedral`] first.
///
/// ```
/// # use nuld_core::sphere::square_to_sphere; use glam::{DVec2, DVec3};
/// assert_eq!(square_to_sphere(DVec2::new(0.5, 0.5)), DVec3::Z);
/// ```
pub fn square_to_sphere(p: DVec2) -> DVec3 {
    DVec3::from(square_to_sphere_real([p.x, p.y]))
}

/// [`square_to_sphere`] in any [`Real`] precision, on plain arrays: the one formula
/// the `f64` map and the runtime's `f32` map (and shaders, in the same order of
/// operations) evaluate. With `u = 2 p.x - 1`, `v = 2 p.y - 1`,
/// `d = 1 - (|u| + |v|)`, `r = 1 - |d|`, `phi = ((|v| - |u|) / r + 1) pi/4` (`pi/4`
/// when `r = 0`):
/// `(copysign(cos phi, u) s, copysign(sin phi, v) s, copysign(1 - r^2, d))` with
/// `s = r sqrt(max(2 - r^2, 0))`. Total; NaN in, NaN out.
///
/// ```
/// # use nuld_core::sphere::square_to_sphere_real;
/// assert_eq!(square_to_sphere_real([0.5f32, 0.5]), [0.0, 0.0, 1.0]);
/// ```
pub fn square_to_sphere_real<T: Real>(p: [T; 2]) -> [T; 3] {
    let two = T::of(2.0);
    let u = two * p[0] - T::ONE;
    let v = two * p[1] - T::ONE;
    let up = u.abs();
    let vp = v.abs();
    let signed_distance = T::ONE - (up + vp);
    let d = signed_distance.abs();
    let r = T::ONE - d;
    let phi = if r == T::ZERO {
        T::ONE
    } else {
        (vp - up) / r + T::ONE
    } * T::of(FRAC_PI_4);
    let z = (T::ONE - r * r).copysign(signed_distance);
    let (sin_phi, cos_phi) = phi.sin_cos();
    let (cos_phi, sin_phi) = (cos_phi.copysign(u), sin_phi.copysign(v));
    let s = r * safe_sqrt(two - r * r);
    [cos_phi * s, sin_phi * s, z]
}

/// Inverse of [`square_to_sphere`]: a unit vector to its point in `[0,1]^2`.
///
/// Uses the exact `atan` (pbrt-v4 uses a polynomial approximation), so that
/// `sphere_to_square(square_to_sphere(p)) == p` up to rounding. The input should be
/// unit length; it is not normalized here.
pub fn sphere_to_square(d: DVec3) -> DVec2 {
    DVec2::from(sphere_to_square_real(d.to_array()))
}

/// [`sphere_to_square`] in any [`Real`] precision, on plain arrays (the runtime
/// evaluates it in `f32` to place a normal on an environment sampler's condition
/// grid). With `r = sqrt(max(1 - |z|, 0))`, `phi = atan(min(|x|,|y|) / max(|x|,|y|))
/// / (pi/2)` (0 when both are 0; `1 - phi` when `|x| < |y|`), `v = phi r`, `u = r - v`;
/// for `z < 0`, `(u, v) -> (1 - v, 1 - u)`; then the signs of `x` and `y`, and
/// `((u + 1) / 2, (v + 1) / 2)`. Total; NaN in, NaN out.
pub fn sphere_to_square_real<T: Real>(d: [T; 3]) -> [T; 2] {
    let x = d[0].abs();
    let y = d[1].abs();
    let z = d[2].abs();
    let r = safe_sqrt(T::ONE - z);
    let a = x.max(y);
    let b = x.min(y);
    let ratio = if a == T::ZERO { T::ZERO } else { b / a };
    let mut phi = ratio.atan() / T::of(FRAC_PI_2);
    if x < y {
        phi = T::ONE - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d[2] < T::ZERO {
        core::mem::swap(&mut u, &mut v);
        u = T::ONE - u;
        v = T::ONE - v;
    }
    u = u.copysign(d[0]);
    v = v.copysign(d[1]);
    let half = T::of(0.5);
    [half * (u + T::ONE), half * (v + T::ONE)]
}

/// Folds a point that left `[0,1]^2` back in, so that it lands on the square point
/// of the *same* direction neighbourhood across the octahedral seam.
///
/// The octahedral layout is continuous across its edges when each edge is glued to
/// itself mirrored about its midpoint: `u<0 -> (-u, 1-v)`, `u>1 -> (2-u, 1-v)`,
/// `v<0 -> (1-u, -v)`, `v>1 -> (1-u, 2-v)`. An optimizer that steps a point across
/// an edge calls this to continue on the other side. Points further than one unit
/// outside, and non-finite inputs, are clamped into the square afterwards so the
/// result is always in `[0,1]^2`.
///
/// ```
/// # use nuld_core::sphere::wrap_octahedral; use glam::DVec2;
/// let p = wrap_octahedral(DVec2::new(-0.01, 0.66));
/// assert!((p - DVec2::new(0.01, 0.34)).length() < 1e-12);
/// ```
pub fn wrap_octahedral(mut p: DVec2) -> DVec2 {
    // Each fold moves a coordinate that is within one unit of the square inside it,
    // and may push the other one outside by mirroring; two rounds settle both.
    for _ in 0..2 {
        if p.x < 0.0 {
            p = DVec2::new(-p.x, 1.0 - p.y);
        } else if p.x > 1.0 {
            p = DVec2::new(2.0 - p.x, 1.0 - p.y);
        }
        if p.y < 0.0 {
            p = DVec2::new(1.0 - p.x, -p.y);
        } else if p.y > 1.0 {
            p = DVec2::new(1.0 - p.x, 2.0 - p.y);
        }
    }
    let clamp = |x: f64| if x.is_nan() { 0.5 } else { x.clamp(0.0, 1.0) };
    DVec2::new(clamp(p.x), clamp(p.y))
}

/// Equal-area map from `[0,1]^2` to the upper hemisphere `z >= 0`.
///
/// Shirley–Chiu's concentric map ([`crate::warp::square_to_disk`]) takes the square to
/// the unit disk preserving area (up to the factor `pi`); the lift `(x, y) -> (x s, y s, 1 - r^2)` with
/// `s = sqrt(2 - r^2)` takes the disk to the hemisphere preserving area (factor 2).
/// The square's centre maps to `+z`, its boundary to the equator.
///
/// ```
/// # use nuld_core::sphere::square_to_hemisphere; use glam::{DVec2, DVec3};
/// assert_eq!(square_to_hemisphere(DVec2::new(0.5, 0.5)), DVec3::Z);
/// let e = square_to_hemisphere(DVec2::new(1.0, 0.5));
/// assert!((e - DVec3::X).length() < 1e-12);
/// ```
pub fn square_to_hemisphere(p: DVec2) -> DVec3 {
    DVec3::from(square_to_hemisphere_real([p.x, p.y]))
}

/// [`square_to_hemisphere`] in any [`Real`] precision, on plain arrays: the one
/// formula the `f64` map and the runtime's `f32` map (and shaders, in the same order
/// of operations) evaluate. With the concentric map's signed polar form
/// `a = 2 p.x - 1`, `b = 2 p.y - 1`; `(r, theta) = (a, pi/4 (b / a))` if `|a| > |b|`,
/// else `(b, pi/2 - pi/4 (a / b))`: `(s cos theta, s sin theta, 1 - r^2)` with
/// `s = r sqrt(max(2 - r^2, 0))`, and `+z` at the centre `a = b = 0`. Total; NaN in,
/// NaN out.
///
/// ```
/// # use nuld_core::sphere::square_to_hemisphere_real;
/// assert_eq!(square_to_hemisphere_real([0.5f32, 0.5]), [0.0, 0.0, 1.0]);
/// let e = square_to_hemisphere_real([1.0f32, 0.5]);
/// assert!((e[0] - 1.0).abs() < 1e-6 && e[1].abs() < 1e-6 && e[2].abs() < 1e-6);
/// ```
pub fn square_to_hemisphere_real<T: Real>(p: [T; 2]) -> [T; 3] {
    let Some((r, theta)) = concentric_polar(p) else {
        return [T::ZERO, T::ZERO, T::ONE];
    };
    let r2 = r * r;
    let s = r * safe_sqrt(T::of(2.0) - r2);
    let (sin_theta, cos_theta) = theta.sin_cos();
    [s * cos_theta, s * sin_theta, T::ONE - r2]
}

/// Inverse of [`square_to_hemisphere`]. Directions below the horizon are mirrored
/// to `z >= 0` first (`z` is replaced by `|z|`).
pub fn hemisphere_to_square(d: DVec3) -> DVec2 {
    let r2 = (1.0 - d.z.abs()).clamp(0.0, 1.0);
    let r = libm::sqrt(r2);
    let planar = libm::sqrt(d.x * d.x + d.y * d.y);
    if r == 0.0 || planar == 0.0 {
        return DVec2::splat(0.5);
    }
    concentric_polar_inverse(r, libm::atan2(d.y, d.x))
}

/// [`hemisphere_to_square`] in any [`Real`] precision, without `atan2` (the
/// runtime's `f32` twin; a shader follows the same order of operations): the disk
/// point `r (x, y) / |(x, y)|` with `r = sqrt(1 - |z|)` is inverted per wedge of
/// the concentric map, `a = ±r, b = a atan(y / x) / (pi/4)` where `|x| >= |y|`,
/// else `b = ±r, a = b atan(x / y) / (pi/4)` (the signs of `x` and `y`). The
/// pole and NaN read as the centre.
pub fn hemisphere_to_square_real<T: Real>(d: [T; 3]) -> [T; 2] {
    let r = safe_sqrt(T::ONE - d[2].abs()).min(T::ONE);
    let (x, y) = (d[0], d[1]);
    let half = T::of(0.5);
    let planar = x != T::ZERO || y != T::ZERO;
    if r.partial_cmp(&T::ZERO) != Some(core::cmp::Ordering::Greater)
        || !planar
        || x.is_nan()
        || y.is_nan()
    {
        return [half, half];
    }
    let inv_quarter_pi = T::of(4.0 / core::f64::consts::PI);
    let (a, b) = if x.abs() >= y.abs() {
        let a = r.copysign(x);
        (a, a * (y / x).atan() * inv_quarter_pi)
    } else {
        let b = r.copysign(y);
        (b * (x / y).atan() * inv_quarter_pi, b)
    };
    [half * (a + T::ONE), half * (b + T::ONE)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    // The reference vectors of docs/metrics.md (pbrt-v4's map), verbatim (9 digits), hence the allow.
    #[allow(clippy::approx_constant)]
    const REFERENCE: [([f64; 2], [f64; 3]); 12] = [
        ([0.5, 0.5], [0.0, 0.0, 1.0]),
        ([0.0, 0.0], [0.0, 0.0, -1.0]),
        ([1.0, 1.0], [0.0, 0.0, -1.0]),
        ([0.0, 1.0], [0.0, 0.0, -1.0]),
        ([1.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.5, 0.0], [0.0, -1.0, 0.0]),
        ([1.0, 0.5], [1.0, 0.0, 0.0]),
        ([0.75, 0.5], [0.661437828, 0.0, 0.75]),
        ([0.75, 0.75], [0.707106781, 0.707106781, 0.0]),
        ([0.6, 0.7], [0.384187454, 0.665432190, 0.64]),
        ([0.1, 0.2], [-0.665432190, -0.384187454, -0.64]),
        ([0.9, 0.35], [0.922575265, -0.335789935, -0.19]),
    ];

    /// A deterministic low-discrepancy-ish grid of interior test points.
    fn grid(n: usize) -> impl Iterator<Item = DVec2> {
        (0..n).flat_map(move |i| {
            (0..n).map(move |j| {
                DVec2::new((i as f64 + 0.37) / n as f64, (j as f64 + 0.61) / n as f64)
            })
        })
    }

    #[test]
    fn sphere_map_matches_design_reference_vectors() {
        for (p, d) in REFERENCE {
            let got = square_to_sphere(DVec2::from(p));
            assert!(
                (got - DVec3::from(d)).length() < 2e-9,
                "{p:?} -> {got:?}, want {d:?}"
            );
        }
    }

    #[test]
    fn inverse_sphere_map_matches_design_reference() {
        let d = DVec3::splat(1.0 / 3f64.sqrt());
        let p = sphere_to_square(d);
        assert!((p - DVec2::splat(0.662528792)).length() < 1e-9, "{p:?}");
    }

    #[test]
    fn sphere_map_round_trips() {
        for p in grid(97) {
            let d = square_to_sphere(p);
            assert!((d.length() - 1.0).abs() < 1e-14);
            let q = sphere_to_square(d);
            assert!((p - q).length() < 1e-12, "{p:?} -> {d:?} -> {q:?}");
        }
    }

    /// Area of the image of a small square: |d/du x d/dv| * h^2 by central differences.
    fn area_element(f: impl Fn(DVec2) -> DVec3, p: DVec2) -> f64 {
        let h = 1e-6;
        let du = (f(p + DVec2::X * h) - f(p - DVec2::X * h)) / (2.0 * h);
        let dv = (f(p + DVec2::Y * h) - f(p - DVec2::Y * h)) / (2.0 * h);
        du.cross(dv).length()
    }

    #[test]
    fn sphere_map_has_constant_area_element() {
        for p in grid(41) {
            // Central differences straddling the creases |u|+|v|=1 or u,v=0.5 are not
            // smooth; the grid offsets keep every point at least 1e-3 away.
            let a = area_element(square_to_sphere, p);
            assert!((a - 4.0 * PI).abs() < 1e-5 * 4.0 * PI, "{p:?}: {a}");
        }
    }

    #[test]
    fn hemisphere_map_has_constant_area_element_and_round_trips() {
        for p in grid(41) {
            let a = area_element(square_to_hemisphere, p);
            assert!((a - 2.0 * PI).abs() < 1e-5 * 2.0 * PI, "{p:?}: {a}");
            let d = square_to_hemisphere(p);
            assert!((d.length() - 1.0).abs() < 1e-14 && d.z >= 0.0);
            let q = hemisphere_to_square(d);
            assert!((p - q).length() < 1e-12, "{p:?} -> {d:?} -> {q:?}");
        }
    }

    #[test]
    fn hemisphere_map_reference_points() {
        let cases = [
            ([0.5, 0.5], [0.0, 0.0, 1.0]),
            ([1.0, 0.5], [1.0, 0.0, 0.0]),
            ([0.5, 1.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.5], [-1.0, 0.0, 0.0]),
            ([0.5, 0.0], [0.0, -1.0, 0.0]),
            // r = 1/2 on the +x axis: z = 1 - 1/4, planar radius 0.5 * sqrt(1.75).
            ([0.75, 0.5], [0.5 * 1.75f64.sqrt(), 0.0, 0.75]),
        ];
        for (p, d) in cases {
            let got = square_to_hemisphere(DVec2::from(p));
            assert!((got - DVec3::from(d)).length() < 1e-12, "{p:?} -> {got:?}");
        }
    }

    /// The `f32` instantiation (the runtime's) stays within a few `f32` ulps of the
    /// `f64` map, on both maps, over the whole square.
    #[test]
    fn f32_maps_follow_the_f64_maps() {
        let mut worst: f64 = 0.0;
        for p in grid(257) {
            let q = [p.x as f32, p.y as f32];
            let p = DVec2::new(q[0] as f64, q[1] as f64);
            for (a, b) in [
                (square_to_hemisphere_real(q), square_to_hemisphere(p)),
                (square_to_sphere_real(q), square_to_sphere(p)),
            ] {
                worst = worst.max((DVec3::from(a.map(f64::from)) - b).length());
            }
        }
        assert!(worst < 2e-6, "{worst}");
    }

    /// The inverse map in `f32` (how the runtime places a normal on its grid)
    /// inverts the `f64` forward map to a few `f32` ulps; in `f64` it is the
    /// `DVec` inverse bit for bit.
    #[test]
    fn f32_inverse_map_inverts_the_sphere_map() {
        let mut worst: f64 = 0.0;
        for p in grid(129) {
            let d = square_to_sphere(p);
            assert_eq!(
                sphere_to_square_real(d.to_array()),
                sphere_to_square(d).to_array()
            );
            let q = sphere_to_square_real(d.as_vec3().to_array());
            // Points on the square's edge have a mirrored twin (the same direction).
            let back = square_to_sphere(DVec2::new(q[0] as f64, q[1] as f64));
            worst = worst.max((back - d).length());
        }
        // Near the poles `sqrt(1 - |z|)` amplifies the f32 rounding of `z`.
        assert!(worst < 1e-5, "{worst}");
    }

    #[test]
    fn octahedral_wrap_matches_design_examples_and_is_continuous() {
        let cases = [([-0.01, 0.66], [0.01, 0.34]), ([1.01, 1.01], [0.01, 0.01])];
        for (p, want) in cases {
            let got = wrap_octahedral(DVec2::from(p));
            assert!(
                (got - DVec2::from(want)).length() < 1e-12,
                "{p:?} -> {got:?}"
            );
        }
        // A point just outside an edge maps to a direction next to the one just inside:
        // the glued edges are the same curve on the sphere.
        for t in [0.05, 0.3, 0.5, 0.81] {
            for (inside, outside) in [
                ([1e-7, t], [-1e-7, t]),
                ([1.0 - 1e-7, t], [1.0 + 1e-7, t]),
                ([t, 1e-7], [t, -1e-7]),
                ([t, 1.0 - 1e-7], [t, 1.0 + 1e-7]),
            ] {
                let a = square_to_sphere(DVec2::from(inside));
                let b = square_to_sphere(wrap_octahedral(DVec2::from(outside)));
                assert!((a - b).length() < 1e-6, "{inside:?} vs {outside:?}");
            }
        }
        let p = wrap_octahedral(DVec2::new(f64::NAN, 7.5));
        assert!((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y));
    }
}
