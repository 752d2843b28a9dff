//! A table space whose rim is the horizon at every view: a candidate square of
//! the BRDF prior's metal layer ([`super::brdf_prior::PriorSpace::Horizon`]),
//! for measurements.
//!
//! In the half-vector square the horizon (`wi.z = 0`) is a curve whose place on
//! the table moves with the view and with the roughness's stretch, so two
//! roughness nodes of a grazing metal cut their lobes at different places and
//! their blend has the shape of neither (docs/results/brdf-prior.md). Here the
//! horizon is the table's boundary for every condition:
//!
//! * In the half vector's slope plane `s = (h.x, h.y) / h.z`, for the view `wo =
//!   (sin θo, 0, cos θo)`, the light `wi = 2 (wo.h) h - wo` lies above the
//!   horizon exactly on the disc `|s - (tan θo, 0)| <= 1 / cos θo` (expand
//!   `wi.z >= 0` with `h = (s, 1) / |(s, 1)|`). Its point `z = cos θo s - (sin θo, 0)`
//!   on the unit disc takes the mirror direction (`s = 0`) to `-sin θo`.
//! * The disc automorphism `w = (z + sin θo) / (1 + sin θo z)` (complex numbers)
//!   takes the mirror direction to the centre and keeps the unit circle, the
//!   horizon. It is conformal: near the centre `s = cos θo w`.
//! * A radial zoom `|w| = g(r) = k r / (1 - (1 - k) r)` of the table's disc
//!   point `q = r e` (`g(0) = 0`, `g(1) = 1`, `g'(0) = k`) gives the lobe, about
//!   `α / cos θo` wide in `w` (`α = roughness^2`), half the table's radius when
//!   `k = c α / cos^P θo` with `P = 1` (`c` and `P` the map's constants, `k` at
//!   most 1). With the
//!   *anisotropy* `β`, the zoom is `k / sqrt(e.x^2 + β^2 e.y^2)` in the direction
//!   `e`, so that `β = cos θo` undoes the reflection's squeeze of the axis across
//!   the view's plane by `cos θo` at the mirror direction.
//! * The table's disc is the equal-area square's hemisphere flattened by
//!   Lambert's map, `q = d.xy / sqrt(1 + d.z)` (solid angle `2 dq`).
//!
//! Jacobian, solid angle of `wi` per solid angle of the table's direction:
//! `4 (wo.h) (1 + |s|^2)^(-3/2) cos^-2 θo |dz/dw|^2 (g ∂g/∂r / r) / 2`, with
//! `|dz/dw| = cos^2 θo / |1 - sin θo w|^2`.
//!
//! [`StarDisc`] draws the same slope disc from the mirror direction instead,
//! each direction of the table reaching the horizon at the table's rim, and keeps
//! the slope plane only scaled near the mirror direction.
//!
//! Measured (docs/results/brdf-prior.md#horizon-disc), a shifted lattice at
//! N = 256 through the prior at 13 metals: the automorphism's disc brings the
//! smooth ones seen at grazing views nearer their exact warp and takes the rough
//! ones far from it (its conformal factor spans eleven orders of magnitude at 85°);
//! the star disc with `k = α` serves both, 1.18 of Owen-Sobol through the exact
//! inverse CDF where the stretched metal square (`k = roughness`) read 1.66. The
//! blob's metal layer is now `star:100_200_0`, written in core
//! ([`nuld_core::brdf_prior::star_direction`]; the test below holds the two
//! together).

use glam::{DVec2, DVec3};
use nuld_core::brdf_prior::{half_vector_of as core_half_vector_of, horizon_reach, mirror};
use nuld_core::sphere::{hemisphere_to_square, square_to_hemisphere};

/// The map's constants at one condition (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HorizonDisc {
    /// `k`, the zoom's slope at the centre, in `(0, 1]` (divided by the
    /// anisotropy's factor across the view's plane).
    pub zoom: f64,
    /// `β`, the zoom's extra divisor across the view's plane (1: none).
    pub aniso: f64,
}

impl HorizonDisc {
    /// The map for roughness `roughness` and the unit view `wo` (in the `xz`
    /// plane): `k = min(c α / cos^P θo, 1)` with `c = constant` and `P =
    /// view_power`, and `β = max(cos θo, 0.05)^q`.
    pub fn at(wo: DVec3, roughness: f64, constant: f64, q: f64, view_power: f64) -> Self {
        let cos = wo.z.max(1e-6);
        let alpha = roughness * roughness;
        Self {
            zoom: (constant * alpha / cos.powf(view_power)).clamp(1e-6, 1.0),
            aniso: wo.z.max(0.05).powf(q),
        }
    }

    /// The zoom's slope at the centre in the direction `e` (a unit vector).
    fn zoom_along(&self, e: DVec2) -> f64 {
        self.zoom / (e.x * e.x + self.aniso * self.aniso * e.y * e.y).sqrt()
    }

    /// The light direction of the table point `p` for the unit view `wo` (in
    /// the `xz` plane, `wo.z > 0`) and `|dwi/dω_p|`; `None` on the rim, where
    /// the light lies on the horizon.
    pub fn direction(&self, wo: DVec3, p: DVec2) -> Option<(DVec3, f64)> {
        let (r, e) = on_disc(p);
        let k = self.zoom_along(e);
        let den = 1.0 - (1.0 - k) * r;
        let g = k * r / den;
        // g ∂g/∂r / r, whose limit at the centre is k^2.
        let area = k * k / (den * den * den);
        let w = g * e;
        let (sin, cos) = (wo.x, wo.z.max(1e-6));
        let one_minus = DVec2::new(1.0 - sin * w.x, -sin * w.y);
        let z = complex_div(DVec2::new(w.x - sin, w.y), one_minus);
        let dz = cos * cos / one_minus.length_squared();
        let s = DVec2::new(z.x + sin, z.y) / cos;
        let len2 = 1.0 + s.length_squared();
        let h = DVec3::new(s.x, s.y, 1.0) / len2.sqrt();
        let (wi, c) = reflect(wo, h)?;
        let jac = 4.0 * c / (len2 * len2.sqrt()) / (cos * cos) * dz * dz * area / 2.0;
        (wi.z > 0.0 && jac.is_finite() && jac > 0.0).then_some((wi, jac))
    }

    /// The inverse of [`Self::direction`]: the table point of `wi` and the same
    /// Jacobian; `None` where no table point maps to `wi`.
    pub fn point(&self, wo: DVec3, wi: DVec3) -> Option<(DVec2, f64)> {
        let (h, c) = half_vector_of(wo, wi)?;
        let (sin, cos) = (wo.x, wo.z.max(1e-6));
        let s = h.truncate() / h.z;
        let z = DVec2::new(cos * s.x - sin, cos * s.y);
        let w = complex_div(
            DVec2::new(z.x + sin, z.y),
            DVec2::new(1.0 + sin * z.x, sin * z.y),
        );
        let (p, area) = self.unzoom(w)?;
        let one_minus = DVec2::new(1.0 - sin * w.x, -sin * w.y);
        let dz = cos * cos / one_minus.length_squared();
        let len2 = 1.0 + s.length_squared();
        let jac = 4.0 * c / (len2 * len2.sqrt()) / (cos * cos) * dz * dz * area / 2.0;
        jac.is_finite().then_some((p, jac))
    }

    /// The table point of the zoomed disc point `w` and the zoom's area ratio
    /// `g ∂g/∂r / r`; `None` outside the disc.
    fn unzoom(&self, w: DVec2) -> Option<(DVec2, f64)> {
        let gw = w.length();
        if gw >= 1.0 {
            return None;
        }
        let e = if gw > 0.0 { w / gw } else { DVec2::X };
        let k = self.zoom_along(e);
        let r = gw / (k + (1.0 - k) * gw);
        let den = 1.0 - (1.0 - k) * r;
        let area = k * k / (den * den * den);
        Some((off_disc(r, e), area))
    }
}

/// The half vector's disc drawn from its centre: a table point at radius `r` and
/// direction `e` of the table's disc has the half vector at radius
/// `ρ = k r / (1 - (1 - k / ρ_max(e)) r)` in direction `e`, where `ρ_max(e)` is
/// the radius of the horizon along `e`. The radius is the slope `|s|`
/// ([`Self::lambert`] false; the horizon's at `t e.x + sqrt(1 + t^2 e.x^2)`,
/// `t = tan θo`, the slope disc's boundary) or the half vector's Lambert radius
/// `sqrt(1 - h.z)` (true; equal-area in `h`, as the blob's half-vector square).
/// So the rim is the horizon, the centre the mirror direction, and near it the
/// radius is `k r`. The radial map's area ratio:
/// `ρ ∂ρ/∂r / r = k^2 / (1 - (1 - k / ρ_max) r)^3`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StarDisc {
    /// `k`, the radius per table radius at the centre.
    pub zoom: f64,
    /// Whether the radius is the half vector's Lambert radius (else its slope).
    pub lambert: bool,
    /// `β`: the zoom along `e` is `k / sqrt(e.x^2 + β^2 e.y^2)`, so that `β = cos
    /// θo` undoes the reflection's squeeze across the view's plane (1: none).
    pub aniso: f64,
}

impl StarDisc {
    /// The zoom's radius per table radius at the centre along `e`.
    fn zoom_along(&self, e: DVec2) -> f64 {
        self.zoom / (e.x * e.x + self.aniso * self.aniso * e.y * e.y).sqrt()
    }

    /// `ρ_max(e)`: the horizon's radius along `e`.
    fn reach(&self, wo: DVec3, e: DVec2) -> f64 {
        let slope = horizon_reach(wo.to_array(), e.to_array());
        if self.lambert {
            // 1 - 1 / sqrt(1 + x^2) without cancellation.
            let root = (1.0 + slope * slope).sqrt();
            (slope * slope / (root * (root + 1.0))).sqrt()
        } else {
            slope
        }
    }

    /// The half vector at radius `rho` in direction `e` and `dω_h / dA`, solid
    /// angle per area of the radial plane.
    fn half_vector(&self, rho: f64, e: DVec2) -> (DVec3, f64) {
        if self.lambert {
            let lift = (2.0 - rho * rho).max(0.0).sqrt();
            (
                DVec3::new(rho * lift * e.x, rho * lift * e.y, 1.0 - rho * rho),
                2.0,
            )
        } else {
            let len2 = 1.0 + rho * rho;
            (
                DVec3::new(rho * e.x, rho * e.y, 1.0) / len2.sqrt(),
                1.0 / (len2 * len2.sqrt()),
            )
        }
    }

    /// The light direction of the table point `p` for the unit view `wo` (in
    /// the `xz` plane, `wo.z > 0`) and `|dwi/dω_p|`; `None` on the rim.
    pub fn direction(&self, wo: DVec3, p: DVec2) -> Option<(DVec3, f64)> {
        let (r, e) = on_disc(p);
        let k = self.zoom_along(e);
        let den = 1.0 - (1.0 - k / self.reach(wo, e)) * r;
        let rho = k * r / den;
        let area = k * k / (den * den * den);
        let (h, per_area) = self.half_vector(rho, e);
        let (wi, c) = reflect(wo, h)?;
        let jac = 4.0 * c * per_area * area / 2.0;
        (wi.z > 0.0 && jac.is_finite() && jac > 0.0).then_some((wi, jac))
    }

    /// The inverse of [`Self::direction`]: the table point of `wi` and the same
    /// Jacobian; `None` where no table point maps to `wi`.
    pub fn point(&self, wo: DVec3, wi: DVec3) -> Option<(DVec2, f64)> {
        let (h, c) = half_vector_of(wo, wi)?;
        let (rho, e) = if self.lambert {
            let u = h.truncate() / (1.0 + h.z).sqrt();
            (u.length(), u)
        } else {
            let s = h.truncate() / h.z;
            (s.length(), s)
        };
        let e = if rho > 0.0 { e / rho } else { DVec2::X };
        let k = self.zoom_along(e);
        let reach = self.reach(wo, e);
        if rho >= reach {
            return None;
        }
        let r = rho / (k + (1.0 - k / reach) * rho);
        let den = 1.0 - (1.0 - k / reach) * r;
        let area = k * k / (den * den * den);
        let per_area = self.half_vector(rho, e).1;
        let jac = 4.0 * c * per_area * area / 2.0;
        jac.is_finite().then(|| (off_disc(r, e), jac))
    }
}

/// One of the module's two maps, for a caller that chooses at run time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HorizonMap {
    /// The slope disc moved by the automorphism ([`HorizonDisc`]).
    Moved(HorizonDisc),
    /// The slope disc drawn from the mirror direction ([`StarDisc`]).
    Star(StarDisc),
}

impl HorizonMap {
    /// The map's `direction` ([`HorizonDisc::direction`], [`StarDisc::direction`]).
    pub fn direction(&self, wo: DVec3, p: DVec2) -> Option<(DVec3, f64)> {
        match self {
            Self::Moved(m) => m.direction(wo, p),
            Self::Star(m) => m.direction(wo, p),
        }
    }

    /// The map's `point` ([`HorizonDisc::point`], [`StarDisc::point`]).
    pub fn point(&self, wo: DVec3, wi: DVec3) -> Option<(DVec2, f64)> {
        match self {
            Self::Moved(m) => m.point(wo, wi),
            Self::Star(m) => m.point(wo, wi),
        }
    }
}

/// The light `wi = 2 (wo.h) h - wo` of the half vector `h` for the view `wo`, and
/// `wo.h`; `None` where `wo.h <= 0` (or NaN): core's [`mirror`] on `glam` vectors.
pub fn reflect(wo: DVec3, h: DVec3) -> Option<(DVec3, f64)> {
    mirror(wo.to_array(), h.to_array()).map(|(wi, c)| (DVec3::from_array(wi), c))
}

/// The half vector `h = (wo + wi) / |wo + wi|` of the light `wi` for the view
/// `wo`, and `wo.h`: the inverse of [`reflect`]; `None` where `wi` is not above
/// the horizon, `h.z <= 0` or `wo.h <= 0`: core's [`core_half_vector_of`] on
/// `glam` vectors.
pub fn half_vector_of(wo: DVec3, wi: DVec3) -> Option<(DVec3, f64)> {
    core_half_vector_of(wo.to_array(), wi.to_array()).map(|(h, c)| (DVec3::from_array(h), c))
}

/// The table point `p`'s place on the unit disc, Lambert's flattening `q = d.xy /
/// sqrt(1 + d.z)` of its equal-area direction `d` (solid angle `2 dq`): the
/// radius and the direction (`+x` at the centre).
fn on_disc(p: DVec2) -> (f64, DVec2) {
    let d = square_to_hemisphere(p);
    let q = d.truncate() / (1.0 + d.z.max(0.0)).sqrt();
    let r = q.length();
    (r, if r > 0.0 { q / r } else { DVec2::X })
}

/// The inverse of [`on_disc`]: the table point at radius `r` in direction `e`.
fn off_disc(r: f64, e: DVec2) -> DVec2 {
    let lift = (2.0 - r * r).max(0.0).sqrt();
    hemisphere_to_square(DVec3::new(r * e.x * lift, r * e.y * lift, 1.0 - r * r))
}

/// `a / b` for complex numbers held as `(re, im)`.
fn complex_div(a: DVec2, b: DVec2) -> DVec2 {
    let n = b.length_squared();
    DVec2::new(a.x * b.x + a.y * b.y, a.y * b.x - a.x * b.y) / n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::table_map_checks::check_inverse_and_jacobian;
    use nuld_core::brdf::view_direction;

    /// Every table point but the rim maps above the horizon, the rim to it, and
    /// the table's centre to the mirror direction.
    #[test]
    fn the_rim_is_the_horizon_and_the_centre_the_mirror() {
        for (t, rough, q) in [
            (0.0, 0.3, 0.0),
            (60.0, 0.13, 1.0),
            (85.0, 0.25, 0.0),
            (89.0, 0.1, 1.0),
        ] {
            let wo = view_direction(t);
            let disc = HorizonDisc::at(wo, rough, 1.0, q, 1.0);
            let star = StarDisc {
                zoom: rough,
                lambert: false,
                aniso: 1.0,
            };
            let starl = StarDisc {
                zoom: rough,
                lambert: true,
                aniso: wo.z.max(0.05),
            };
            let maps: [&dyn Fn(DVec2) -> Option<(DVec3, f64)>; 3] = [
                &|p| disc.direction(wo, p),
                &|p| star.direction(wo, p),
                &|p| starl.direction(wo, p),
            ];
            for map in maps {
                let (wi, _) = map(DVec2::splat(0.5)).unwrap();
                let mirror = DVec3::new(-wo.x, -wo.y, wo.z);
                assert!((wi - mirror).length() < 1e-9, "{wi} {mirror}");
                for i in 0..=64 {
                    let v = i as f64 / 64.0;
                    for p in [[v, 1e-9], [1.0 - 1e-9, v], [v, 1.0 - 1e-9], [1e-9, v]] {
                        if let Some((wi, _)) = map(DVec2::from_array(p)) {
                            assert!(wi.z < 1e-4, "{wi} at {p:?}, θo {t}");
                        }
                    }
                }
            }
        }
    }

    /// `point` inverts `direction`, and the Jacobian is the area ratio of a small
    /// table square's image (central differences).
    #[test]
    fn point_inverts_direction_and_the_jacobian_is_the_area_ratio() {
        let mut checked = 0;
        for (t, rough, q) in [(30.0, 0.3, 0.0), (78.0, 0.15, 1.0), (86.0, 0.2, 0.5)] {
            let wo = view_direction(t);
            let map = HorizonDisc::at(wo, rough, 1.0, q, 1.0);
            checked += check_inverse_and_jacobian(|p| map.direction(wo, p), |wi| map.point(wo, wi));
        }
        for (t, k, lambert) in [
            (30.0, 0.3, false),
            (86.0, 0.02, false),
            (60.0, 1.5, false),
            (30.0, 0.3, true),
            (86.0, 0.02, true),
            (85.0, 0.8, true),
        ] {
            let wo = view_direction(t);
            let map = StarDisc {
                zoom: k,
                lambert,
                aniso: if lambert { 0.3 } else { 1.0 },
            };
            checked += check_inverse_and_jacobian(|p| map.direction(wo, p), |wi| map.point(wo, wi));
        }
        assert!(checked > 1500, "{checked}");
    }

    /// The blob's metal layer (core's star disc, [`nuld_core::brdf_prior::star_direction`],
    /// written apart in `f32`-ready form) is this module's `star:100_200_0`:
    /// the same directions and Jacobians both ways.
    #[test]
    fn core_star_disc_is_the_lab_star_100_200_0() {
        use nuld_core::brdf_prior::{metal_zoom, PriorSquare};
        let mut checked = 0;
        for (t, rough) in [
            (0.0, 0.5),
            (45.0, 0.13),
            (85.0, 0.1),
            (89.0, 0.7),
            (70.0, 1.0),
        ] {
            let wo = view_direction(t);
            let alpha = metal_zoom(rough);
            let lab = StarDisc {
                zoom: alpha,
                lambert: false,
                aniso: 1.0,
            };
            let core = PriorSquare::Star(alpha);
            // Inside the rim, which is the horizon itself.
            for i in 1..40 {
                for j in 1..40 {
                    let p = DVec2::new(i as f64, j as f64) / 40.0;
                    let (Some((a, ja)), Some((b, jb))) = (
                        lab.direction(wo, p),
                        core.direction(wo.to_array(), p.to_array()),
                    ) else {
                        continue;
                    };
                    let b = DVec3::from_array(b);
                    assert!((a - b).length() < 1e-9, "{a} {b} at {p}, θo {t}");
                    assert!((ja / jb - 1.0).abs() < 1e-6, "{ja} {jb} at {p}, θo {t}");
                    let (q, _) = core.point(wo.to_array(), b.to_array()).unwrap();
                    let (r, _) = lab.point(wo, a).unwrap();
                    assert!((DVec2::from_array(q) - r).length() < 1e-6, "{q:?} {r}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 7000, "{checked}");
    }
}
