//! A half-vector square whose slopes are stretched by a function of their own
//! size, and optionally more along the view's plane: a candidate table space of
//! the BRDF prior ([`super::brdf_prior::PriorSpace::Radial`]), for measurements.
//!
//! The blob's square divides the half vector's slopes by one stretch `k` at a
//! roughness (`roughness^(1/4)` shared by metallic 0 and 1,
//! [`nuld_core::brdf_prior::stretch`]). One `k` must serve the specular spike,
//! whose slopes scale with `alpha = roughness^2`, and the diffuse lobe, whose
//! half vectors reach slopes near 1; at a smooth half-metal the spike carries
//! half the mass in one or two table cells. Here a table direction of slope `t`
//! (`tan` of its angle from the pole) has the half vector of slope
//!
//! `σ(t) = t (k_b t^2 + k_s a^2) / (t^2 + a^2)`,
//!
//! `k_s` near the pole (`t << a`) and `k_b` far from it (`t >> a`): with `k_s =
//! roughness` the spike spans many cells as in the metal layer, with `k_b =
//! roughness^(1/4)` the diffuse lobe keeps the blob's share of the square, and the
//! map is the blob's plain stretch when `k_s = k_b`. `σ` is increasing
//! (`σ/t` runs from `k_s` to `k_b`), azimuth is kept.
//!
//! At a grazing view the map from half vectors to directions shrinks the axis
//! across the view's plane by about `cos θo` and keeps the one in it, so a set
//! even on the table is squeezed 1 : `cos θo` on the sphere. The *anisotropy*
//! `β = max(cos θo, 0.05)^q` divides the in-plane slope further (`h =
//! normalize(β h1.x, h1.y, h1.z)`, `h1` the radial map's half vector): `q = 1`
//! makes the map conformal at the normal.
//!
//! Jacobians, solid angle per solid angle: the radial map's `(σ/t) σ'(t) ((1 +
//! t^2) / (1 + σ^2))^(3/2)` (`σ/t -> k_s` at the pole), the anisotropy's `β /
//! |(β h1.x, h1.y, h1.z)|^3`, the reflection's `4 (wo.h)`.

use super::horizon_disc::{half_vector_of, reflect};
use glam::{DVec2, DVec3};
use nuld_core::sphere::{hemisphere_to_square, square_to_hemisphere};

/// The map's constants at one condition (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialMap {
    /// `k_s`, the stretch near the pole.
    pub k_small: f64,
    /// `k_b`, the stretch far from it.
    pub k_big: f64,
    /// `a`, the table slope where one gives way to the other (> 0).
    pub crossover: f64,
    /// `β`, the in-plane slope's extra divisor (1: none).
    pub aniso: f64,
}

impl RadialMap {
    /// `σ(t)` and `σ'(t)` (module docs).
    pub fn slope(&self, t: f64) -> (f64, f64) {
        let (ks, kb, a2) = (self.k_small, self.k_big, self.crossover * self.crossover);
        let n = kb * t * t + ks * a2;
        let d = t * t + a2;
        (
            t * n / d,
            ((n + 2.0 * kb * t * t) * d - 2.0 * t * t * n) / (d * d),
        )
    }

    /// The table slope `t` of the half-vector slope `σ` (`σ >= 0`), by bisection
    /// on `[0, σ / min(k_s, k_b)]`, where `σ(t)` is increasing.
    fn table_slope(&self, sigma: f64) -> f64 {
        let (mut lo, mut hi) = (0.0f64, sigma / self.k_small.min(self.k_big));
        for _ in 0..128 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            match self.slope(mid).0 < sigma {
                true => lo = mid,
                false => hi = mid,
            }
        }
        0.5 * (lo + hi)
    }

    /// `dω_h / dω_table` of the radial map alone at table slope `t`, whose
    /// [`Self::slope`] is `(sigma, dsigma)`.
    fn radial_jacobian(&self, t: f64, (sigma, dsigma): (f64, f64)) -> f64 {
        let ratio = if t > 0.0 { sigma / t } else { self.k_small };
        ratio * dsigma * ((1.0 + t * t) / (1.0 + sigma * sigma)).powf(1.5)
    }

    /// The light direction of the table point `p` for the unit view `wo`
    /// (in the `xz` plane) and `|dwi/dω_p|`; `None` where `wo.h <= 0` or the
    /// direction is below the horizon.
    pub fn direction(&self, wo: DVec3, p: DVec2) -> Option<(DVec3, f64)> {
        let s = square_to_hemisphere(p);
        if s.z <= 0.0 {
            return None;
        }
        let rho = s.truncate().length();
        let t = rho / s.z;
        let slope = self.slope(t);
        let sigma = slope.0;
        let e = if rho > 0.0 {
            s.truncate() / rho
        } else {
            DVec2::X
        };
        let h1 = DVec3::new(sigma * e.x, sigma * e.y, 1.0).normalize();
        let v = DVec3::new(self.aniso * h1.x, h1.y, h1.z);
        let len = v.length();
        let h = v / len;
        let (wi, c) = reflect(wo, h)?;
        let jac = 4.0 * c * self.radial_jacobian(t, slope) * self.aniso / (len * len * len);
        (wi.z > 0.0 && jac.is_finite() && jac > 0.0).then_some((wi, jac))
    }

    /// The inverse of [`Self::direction`]: the table point of `wi` and the same
    /// Jacobian; `None` where no table point maps to `wi`.
    pub fn point(&self, wo: DVec3, wi: DVec3) -> Option<(DVec2, f64)> {
        let (h, c) = half_vector_of(wo, wi)?;
        let v = DVec3::new(h.x / self.aniso, h.y, h.z);
        let back = v.length();
        let h1 = v / back;
        let rho = h1.truncate().length();
        let t = self.table_slope(rho / h1.z);
        let e = if rho > 0.0 {
            h1.truncate() / rho
        } else {
            DVec2::X
        };
        let s = DVec3::new(t * e.x, t * e.y, 1.0).normalize();
        let jac =
            4.0 * c * self.radial_jacobian(t, self.slope(t)) * self.aniso * back * back * back;
        jac.is_finite().then(|| (hemisphere_to_square(s), jac))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::table_map_checks::check_inverse_and_jacobian;
    use nuld_core::brdf::view_direction;
    use nuld_core::brdf_prior::half_vector_direction;

    /// With `k_s = k_b = k` and no anisotropy the map is the blob's
    /// ([`half_vector_direction`], written apart in core).
    #[test]
    fn equal_stretches_are_the_blobs_square() {
        for (k, t) in [(0.5623, 30.0), (0.1, 80.0), (1.0, 5.0)] {
            let map = RadialMap {
                k_small: k,
                k_big: k,
                crossover: 0.5,
                aniso: 1.0,
            };
            let wo = view_direction(t);
            for p in [[0.5, 0.5], [0.52, 0.47], [0.3, 0.8], [0.9, 0.15]] {
                let got = map.direction(wo, DVec2::from_array(p));
                let want = half_vector_direction(wo.to_array(), p, k);
                match (got, want) {
                    (Some((wi, jac)), Some((w, j))) => {
                        assert!((wi - DVec3::from_array(w)).length() < 1e-12);
                        assert!((jac - j).abs() < 1e-9 * j, "{jac} {j}");
                    }
                    (None, None) => {}
                    other => panic!("{other:?} at {p:?}"),
                }
            }
        }
    }

    /// At the blob's numbers (`k_s = roughness`, `k_b = roughness^(1/4)`, `a =
    /// 0.25`, no anisotropy) the map is core's radial square
    /// ([`nuld_core::brdf_prior::radial_square`], written apart there), both ways.
    #[test]
    fn the_blobs_numbers_are_cores_radial_square() {
        use nuld_core::brdf_prior::{radial_square, stretch, RADIAL_CROSSOVER};
        let mut checked = 0;
        for (r, t) in [(0.1, 85.0), (0.13, 40.0), (0.5, 70.0), (1.0, 5.0)] {
            let map = RadialMap {
                k_small: r,
                k_big: stretch(r),
                crossover: RADIAL_CROSSOVER,
                aniso: 1.0,
            };
            let wo = view_direction(t);
            let core = radial_square(r);
            for p in [
                [0.5, 0.5],
                [0.52, 0.47],
                [0.3, 0.8],
                [0.9, 0.15],
                [0.61, 0.44],
            ] {
                let got = map.direction(wo, DVec2::from_array(p));
                match (got, core.direction(wo.to_array(), p)) {
                    (Some((wi, jac)), Some((w, j))) => {
                        assert!((wi - DVec3::from_array(w)).length() < 1e-12);
                        assert!((jac - j).abs() < 1e-9 * j, "{jac} {j}");
                        let (q, back) = core.point(wo.to_array(), w).unwrap();
                        let (lab, lab_jac) = map.point(wo, wi).unwrap();
                        assert!((lab - DVec2::from_array(q)).length() < 1e-9);
                        assert!((lab_jac - back).abs() < 1e-9 * back);
                        checked += 1;
                    }
                    (None, None) => {}
                    other => panic!("{other:?} at {p:?}"),
                }
            }
        }
        assert!(checked >= 12, "{checked}");
    }

    /// `point` inverts `direction`, and the Jacobian is the area ratio of a small
    /// table square's image (central differences).
    #[test]
    fn point_inverts_direction_and_the_jacobian_is_the_area_ratio() {
        let map = RadialMap {
            k_small: 0.12,
            k_big: 0.6,
            crossover: 0.5,
            aniso: 0.2,
        };
        let wo = view_direction(78.0);
        let checked = check_inverse_and_jacobian(|p| map.direction(wo, p), |wi| map.point(wo, wi));
        assert!(checked > 200, "{checked}");
    }
}
