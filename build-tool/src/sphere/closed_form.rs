//! The two direction targets whose cap measure is a closed form: `uniform` and
//! `cosine`. Their standard warps are exact.

use super::geometry::{
    cosine_cap_measure, uniform_hemisphere_cap_measure, uniform_sphere_cap_measure,
};
use super::target::DirectionDensity;
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use nuld_core::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use std::f64::consts::PI;

/// [`Domain::Hemisphere`] or [`Domain::Sphere`].
fn direction_domain(hemisphere: bool) -> Domain {
    if hemisphere {
        Domain::Hemisphere
    } else {
        Domain::Sphere
    }
}

/// `uniform`: `1/(4 pi)` on the sphere, `1/(2 pi)` on `z >= 0` for the hemisphere.
/// Warp: the domain's equal-area map (exact). Cap measure: closed form
/// (`(1 - t)/2`, or the cap–hemisphere intersection area over `2 pi`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UniformDirections {
    /// Whether the target is the upper hemisphere (else the whole sphere).
    pub hemisphere: bool,
}

impl DirectionDensity for UniformDirections {
    fn has_closed_form_caps(&self) -> bool {
        true
    }

    fn spec(&self) -> String {
        "uniform".to_string()
    }

    fn domain(&self) -> Domain {
        direction_domain(self.hemisphere)
    }

    fn pdf(&self, w: DVec3) -> f64 {
        if !self.hemisphere {
            1.0 / (4.0 * PI)
        } else if w.z >= 0.0 {
            1.0 / (2.0 * PI)
        } else {
            0.0
        }
    }

    fn sample(&self, u: DVec2) -> DVec3 {
        self.domain().to_direction(u)
    }

    fn cap_measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        if self.hemisphere {
            uniform_hemisphere_cap_measure(center, cos_theta)
        } else {
            uniform_sphere_cap_measure(cos_theta)
        }
    }
}

/// `cosine`: `max(z, 0) / pi` (on both domains). Warp: Malley's method
/// ([`nuld_core::warp::square_to_cosine_hemisphere`]; exact). Cap measure: closed form
/// ([`super::geometry::cosine_cap_measure`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CosineDirections {
    /// Whether the point sets live on the hemisphere domain (the density is the same).
    pub hemisphere: bool,
}

impl DirectionDensity for CosineDirections {
    fn has_closed_form_caps(&self) -> bool {
        true
    }

    fn spec(&self) -> String {
        "cosine".to_string()
    }

    fn domain(&self) -> Domain {
        direction_domain(self.hemisphere)
    }

    fn pdf(&self, w: DVec3) -> f64 {
        cosine_hemisphere_pdf(w)
    }

    fn sample(&self, u: DVec2) -> DVec3 {
        square_to_cosine_hemisphere(u)
    }

    fn cap_measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        cosine_cap_measure(center, cos_theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeding::rng;
    use crate::sphere::geometry::random_direction;
    use nuld_core::sphere::square_to_sphere;
    use rand::Rng;

    /// `∫ pdf dω` by the midpoint rule on the sphere map.
    fn total_mass(d: &dyn DirectionDensity, m: usize) -> f64 {
        let mut s = 0.0;
        for i in 0..m * m {
            let p = DVec2::new(
                ((i % m) as f64 + 0.5) / m as f64,
                ((i / m) as f64 + 0.5) / m as f64,
            );
            s += d.pdf(square_to_sphere(p));
        }
        s * 4.0 * PI / (m * m) as f64
    }

    #[test]
    fn uniform_and_cosine_are_normalized_and_warps_follow_the_cap_measure() {
        let dens: [Box<dyn DirectionDensity>; 3] = [
            Box::new(UniformDirections { hemisphere: false }),
            Box::new(UniformDirections { hemisphere: true }),
            Box::new(CosineDirections { hemisphere: true }),
        ];
        let mut r = rng(17, 0);
        for d in &dens {
            assert!(
                (total_mass(d.as_ref(), 511) - 1.0).abs() < 1e-4,
                "{}: {}",
                d.spec(),
                total_mass(d.as_ref(), 511)
            );
            // Fraction of warped uniform samples in caps vs closed-form cap measure,
            // within 3 standard errors (binomial).
            let n = 100_000;
            let pts: Vec<DVec3> = (0..n).map(|_| d.sample_target(&mut r)).collect();
            for _ in 0..12 {
                let c = random_direction(&mut r);
                let t = 1.0 - 2.0 * r.random::<f64>();
                let mu = d.cap_measure(c, t);
                let f = pts.iter().filter(|p| c.dot(**p) >= t).count() as f64 / n as f64;
                let se = (mu * (1.0 - mu) / n as f64).sqrt().max(1e-6);
                assert!((f - mu).abs() < 3.5 * se, "{}: {f} vs {mu}", d.spec());
            }
            // The default quadrature sums to 1 and integrates z like the target.
            let q = d.quadrature(4096);
            let sum: f64 = q.iter().map(|p| p.1).sum();
            assert!((sum - 1.0).abs() < 1e-12);
        }
        // E[z] over the cosine target: ∫ z^2 / pi dω = 2/3.
        let q = CosineDirections { hemisphere: true }.quadrature(16384);
        let ez: f64 = q.iter().map(|(d, w)| d.z * w).sum();
        assert!((ez - 2.0 / 3.0).abs() < 1e-4, "{ez}");
    }
}
