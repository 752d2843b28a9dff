//! Spherical-cap geometry in closed form: cap measures of the uniform and cosine
//! targets, and small helpers (random directions, tangent frames).
//!
//! A cap is `C(w, t) = {x : <w, x> >= t}` with unit centre `w` and `t = cos theta`,
//! `theta` its angular radius (docs/estimator.md, paper Eq. 7).

use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use nuld_core::sphere::wrap_octahedral;
use rand::{Rng, RngCore};
use std::f64::consts::{FRAC_PI_2, PI};

/// `acos` with its argument clamped into `[-1, 1]` (rounding can step outside).
#[inline]
pub(crate) fn acos_clamped(x: f64) -> f64 {
    x.clamp(-1.0, 1.0).acos()
}

/// Normal `k` of `count` spread over the sphere for the lab's per-normal
/// studies: a golden-angle spiral with `z` from 1 (the zenith, `k = 0`'s
/// half-step below it) down to -0.6, so that most normals see a map's sky
/// and some look below its horizon. Unit length; `count` 0 reads as 1.
pub fn spiral_normal(k: usize, count: usize) -> DVec3 {
    let z = 1.0 - (k as f64 + 0.5) / count.max(1) as f64 * 1.6;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.399963 * k as f64;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Normalized `w`, or `+z` when `w` is zero or not finite.
#[inline]
pub(crate) fn unit_or_z(w: DVec3) -> DVec3 {
    let n = w.normalize_or_zero();
    if n == DVec3::ZERO || !n.is_finite() {
        DVec3::Z
    } else {
        n
    }
}

/// The unit direction at polar angle `theta` from `+z` and azimuth `phi` from
/// `+x` toward `+y`, written out for tests to place directions independently of
/// the code under test.
#[cfg(test)]
pub(crate) fn direction_from_angles(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// Uniform measure `(1 - t)/2` of the cap `C(w, t)` on the whole sphere
/// (`t` clamped into `[-1, 1]`).
#[inline]
pub fn uniform_sphere_cap_measure(cos_theta: f64) -> f64 {
    (0.5 * (1.0 - cos_theta.clamp(-1.0, 1.0))).clamp(0.0, 1.0)
}

/// Uniform measure on the upper hemisphere `z >= 0` of the cap `C(w, t)`:
/// `area(C ∩ {z >= 0}) / (2 pi)`.
///
/// With `gamma` the polar angle of `w` and `theta = acos t`: the cap lies inside the
/// hemisphere if `gamma + theta <= pi/2` (area `2 pi (1 - t)`), contains it if
/// `theta >= gamma + pi/2` (area `2 pi`), misses it if `gamma - theta >= pi/2`;
/// otherwise the two boundary circles cross and the area of the intersection of two
/// caps (Tovchigrechko & Vakser 2001) with the second radius `pi/2` is
/// `2 [pi - acos(cos gamma / sin theta) - cos theta acos(-cos gamma cos theta / (sin gamma sin theta))]`.
pub fn uniform_hemisphere_cap_measure(center: DVec3, cos_theta: f64) -> f64 {
    let w = unit_or_z(center);
    let t = cos_theta.clamp(-1.0, 1.0);
    let theta = t.acos();
    let gamma = acos_clamped(w.z);
    if gamma + theta <= FRAC_PI_2 {
        return (1.0 - t).clamp(0.0, 1.0);
    }
    if theta >= gamma + FRAC_PI_2 {
        return 1.0;
    }
    if gamma - theta >= FRAC_PI_2 {
        return 0.0;
    }
    let (sg, cg) = (gamma.sin(), w.z.clamp(-1.0, 1.0));
    let st = theta.sin();
    if sg <= 0.0 || st <= 0.0 {
        // Unreachable in exact arithmetic (the cases above cover gamma in {0, pi}
        // and theta in {0, pi}); keep a safe answer under rounding.
        return if cg * t >= 0.0 {
            (1.0 - t).min(1.0)
        } else {
            0.0
        };
    }
    let a = acos_clamped(cg / st);
    let b = acos_clamped(-cg * t / (sg * st));
    let area = 2.0 * (PI - a - t * b);
    (area / (2.0 * PI)).clamp(0.0, 1.0)
}

/// Cosine measure (density `max(z, 0) / pi`) of the cap `C(w, t)`.
///
/// For `theta <= pi/2` this is the irradiance from a uniform spherical cap
/// (Snyder 1996, as in Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", the
/// sphere-light illuminance with horizon clipping), divided by `pi`:
/// with `c = cos gamma` (`gamma` the polar angle of `w`), `s = sin gamma`:
/// * `c^2 > sin^2 theta`: `max(c, 0) sin^2 theta` (cap fully above or below);
/// * otherwise, with `x = cot theta`, `y = -x c / s`, `g = s sqrt(1 - y^2)`:
///   `[(c acos y - x g) sin^2 theta + atan(g / x)] / pi`.
///
/// For `theta > pi/2` the complement is used: `mu(C(w, t)) = 1 - mu(C(-w, -t))`.
pub fn cosine_cap_measure(center: DVec3, cos_theta: f64) -> f64 {
    let w = unit_or_z(center);
    let t = cos_theta.clamp(-1.0, 1.0);
    if t < 0.0 {
        return (1.0 - cosine_cap_measure_small(-w, -t)).clamp(0.0, 1.0);
    }
    cosine_cap_measure_small(w, t)
}

/// [`cosine_cap_measure`] for `t >= 0` (`theta <= pi/2`).
fn cosine_cap_measure_small(w: DVec3, t: f64) -> f64 {
    let c = w.z.clamp(-1.0, 1.0);
    let sin2 = (1.0 - t * t).max(0.0);
    if c * c >= sin2 {
        return (c.max(0.0) * sin2).clamp(0.0, 1.0);
    }
    let s = (1.0 - c * c).max(0.0).sqrt();
    // Here s >= sin(theta) > 0 unless theta = 0 (then c^2 > 0 = sin2 above, or
    // c = 0 = sin2: a point cap, measure 0).
    if s <= 0.0 || sin2 <= 0.0 {
        return 0.0;
    }
    let x = t / sin2.sqrt();
    let y = (-x * c / s).clamp(-1.0, 1.0);
    let g = s * (1.0 - y * y).max(0.0).sqrt();
    let e = (c * y.acos() - x * g) * sin2 + g.atan2(x);
    (e / PI).clamp(0.0, 1.0)
}

/// A uniformly distributed unit vector (`z = 1 - 2u`, `phi = 2 pi v`).
pub fn random_direction(rng: &mut (impl RngCore + ?Sized)) -> DVec3 {
    let z = 1.0 - 2.0 * rng.random::<f64>();
    let phi = 2.0 * PI * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Two unit vectors completing the unit `w` to a right-handed orthonormal frame
/// (Duff et al. 2017).
pub fn tangent_frame(w: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(w.z);
    let a = -1.0 / (sign + w.z);
    let b = w.x * w.y * a;
    (
        DVec3::new(1.0 + sign * w.x * w.x * a, sign * b, -sign * w.x),
        DVec3::new(b, sign + w.y * w.y * a, -w.y),
    )
}

/// Brings a square point that left `[0,1]^2` back: across the octahedral seam for
/// the sphere, clamped onto the equator's square boundary for the hemisphere.
pub fn fold(domain: Domain, p: DVec2) -> DVec2 {
    match domain {
        Domain::Hemisphere => p.clamp(DVec2::ZERO, DVec2::ONE),
        _ => wrap_octahedral(p),
    }
}

/// Jacobian columns `(d dir / d p.x, d dir / d p.y)` of the domain's equal-area
/// map at `p`, by central differences through [`fold`] (so the seam is crossed
/// continuously): the chain rule from a direction's gradient to its square point.
pub fn map_jacobian(domain: Domain, p: DVec2) -> (DVec3, DVec3) {
    let h = 1e-7;
    let f = |q: DVec2| domain.to_direction(fold(domain, q));
    (
        (f(p + DVec2::X * h) - f(p - DVec2::X * h)) / (2.0 * h),
        (f(p + DVec2::Y * h) - f(p - DVec2::Y * h)) / (2.0 * h),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spiral_normals_are_unit_and_span_their_band() {
        let n: Vec<DVec3> = (0..64).map(|k| spiral_normal(k, 64)).collect();
        assert!(n.iter().all(|v| (v.length() - 1.0).abs() < 1e-12));
        assert!((n[0].z - (1.0 - 0.8 / 64.0)).abs() < 1e-12);
        assert!((n[63].z - (1.0 - 63.5 / 64.0 * 1.6)).abs() < 1e-12);
        // Consecutive normals turn by the golden angle about z.
        let turn = n[2].y.atan2(n[2].x) - n[1].y.atan2(n[1].x);
        assert!((turn.rem_euclid(std::f64::consts::TAU) - 2.399963).abs() < 1e-9);
    }
    use crate::seeding::rng;
    use glam::DVec2;
    use nuld_core::sphere::square_to_hemisphere;

    /// `∫_a^b g` by composite Simpson with `n` (even) intervals.
    fn simpson(a: f64, b: f64, n: usize, g: impl Fn(f64) -> f64) -> f64 {
        let h = (b - a) / n as f64;
        let mut s = g(a) + g(b);
        for k in 1..n {
            s += g(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * h / 3.0
    }

    /// Reference by 1D quadrature in cap-local coordinates: `x = s w + sqrt(1-s^2)
    /// (cos phi e1 + sin phi e2)`, so `z = s c + sqrt(1-s^2) sg cos phi` (up to a
    /// phase) and the phi-integrals have closed forms:
    /// `∫ 1[A + B cos phi >= 0] dphi = 2 acos(-A/B)`,
    /// `∫ max(A + B cos phi, 0) dphi = 2 (A acos(-A/B) + sqrt(B^2 - A^2))`.
    fn cap_reference(w: DVec3, t: f64, cosine: bool) -> f64 {
        let c = w.z;
        let sg = (1.0 - c * c).max(0.0).sqrt();
        let inner = |s: f64| {
            let a = s * c;
            let b = (1.0 - s * s).max(0.0).sqrt() * sg;
            let full = a >= b;
            let none = a <= -b;
            if cosine {
                if full {
                    2.0 * PI * a
                } else if none {
                    0.0
                } else {
                    let r = (-a / b).clamp(-1.0, 1.0);
                    2.0 * (a * r.acos() + (b * b - a * a).max(0.0).sqrt())
                }
            } else if full {
                2.0 * PI
            } else if none {
                0.0
            } else {
                2.0 * (-a / b).clamp(-1.0, 1.0).acos()
            }
        };
        let v = simpson(t, 1.0, 400_000, inner);
        if cosine {
            v / PI
        } else {
            v / (2.0 * PI)
        }
    }

    fn test_caps() -> Vec<(DVec3, f64)> {
        let mut r = rng(5, 0);
        let mut caps: Vec<(DVec3, f64)> = (0..60)
            .map(|_| (random_direction(&mut r), 1.0 - 2.0 * r.random::<f64>()))
            .collect();
        caps.extend([
            (DVec3::Z, 0.3),
            (-DVec3::Z, 0.3),
            (DVec3::X, 0.0),
            (DVec3::X, 0.9),
            (DVec3::new(0.6, 0.0, 0.8), -0.5),
            (DVec3::new(0.6, 0.0, -0.8), 0.5),
            (DVec3::Z, -1.0),
            (DVec3::Z, 1.0),
        ]);
        caps
    }

    #[test]
    fn hemisphere_and_cosine_cap_measures_match_quadrature() {
        for (w, t) in test_caps() {
            let u = uniform_hemisphere_cap_measure(w, t);
            let ur = cap_reference(w, t, false);
            assert!((u - ur).abs() < 2e-6, "uniform-hemi {w:?} {t}: {u} vs {ur}");
            let c = cosine_cap_measure(w, t);
            let cr = cap_reference(w, t, true);
            assert!((c - cr).abs() < 2e-7, "cosine {w:?} {t}: {c} vs {cr}");
        }
    }

    #[test]
    fn cap_measures_match_an_equal_area_grid() {
        // A second, independent reference: midpoint rule on the hemisphere map.
        let m = 1024;
        let pts: Vec<DVec3> = (0..m * m)
            .map(|k| {
                square_to_hemisphere(DVec2::new(
                    ((k % m) as f64 + 0.5) / m as f64,
                    ((k / m) as f64 + 0.5) / m as f64,
                ))
            })
            .collect();
        for (w, t) in test_caps().into_iter().take(12) {
            let (mut a, mut b) = (0.0, 0.0);
            for p in &pts {
                if w.dot(*p) >= t {
                    a += 1.0;
                    b += p.z;
                }
            }
            let a = a / (m * m) as f64;
            let b = b * 2.0 / (m * m) as f64;
            assert!((uniform_hemisphere_cap_measure(w, t) - a).abs() < 2e-4);
            assert!((cosine_cap_measure(w, t) - b).abs() < 2e-4);
        }
    }

    #[test]
    fn closed_form_special_cases() {
        assert_eq!(uniform_sphere_cap_measure(0.0), 0.5);
        // Cap about the equator with theta = pi/2: half of the hemisphere.
        assert!((uniform_hemisphere_cap_measure(DVec3::X, 0.0) - 0.5).abs() < 1e-15);
        // Upper hemisphere itself: all of the cosine mass; about +x: half.
        assert!((cosine_cap_measure(DVec3::Z, 0.0) - 1.0).abs() < 1e-15);
        assert!((cosine_cap_measure(DVec3::X, 0.0) - 0.5).abs() < 1e-15);
        // Small cap at the pole: sin^2 theta.
        assert!((cosine_cap_measure(DVec3::Z, 0.8) - 0.36).abs() < 1e-15);
        let (a, b) = tangent_frame(DVec3::new(0.48, -0.6, 0.64));
        assert!(a.dot(b).abs() < 1e-15 && (a.length() - 1.0).abs() < 1e-15);
        assert!((a.cross(b) - DVec3::new(0.48, -0.6, 0.64)).length() < 1e-15);
    }
}
