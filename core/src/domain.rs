//! Where the points of a set live, and the map between the stored square point and
//! the point's direction.
//!
//! Point sets are stored and optimized as points of the unit square; a direction
//! domain names the equal-area map ([`crate::sphere`]) that turns them into unit
//! vectors. Blobs record the domain by its code ([`Domain::from_code`]).

use crate::real::Real;
use crate::sphere::{
    hemisphere_to_square, sphere_to_square, square_to_hemisphere_real, square_to_sphere_real,
};
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// Where the points of a point or direction set live.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[repr(u32)]
pub enum Domain {
    /// The unit square `[0,1)^2`.
    Square = 0,
    /// The unit sphere, through [`crate::sphere::square_to_sphere`].
    Sphere = 1,
    /// The upper hemisphere `z >= 0`, through [`crate::sphere::square_to_hemisphere`].
    Hemisphere = 2,
}

impl Domain {
    /// The domain with this code, if any.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            0 => Some(Self::Square),
            1 => Some(Self::Sphere),
            2 => Some(Self::Hemisphere),
            _ => None,
        }
    }

    /// The domain's name as the CLI and reports spell it: `square`, `sphere` or
    /// `hemisphere`.
    ///
    /// ```
    /// # use nuld_core::domain::Domain;
    /// assert_eq!(Domain::Hemisphere.name(), "hemisphere");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Self::Square => "square",
            Self::Sphere => "sphere",
            Self::Hemisphere => "hemisphere",
        }
    }

    /// The unit direction of the square point `p` under the domain's equal-area map:
    /// [`crate::sphere::square_to_hemisphere`] for [`Domain::Hemisphere`],
    /// [`crate::sphere::square_to_sphere`] otherwise ([`Domain::to_direction_real`]
    /// in `f64`). [`Domain::Square`] is not a direction domain; it gets the sphere
    /// map so that the function stays total. `O(1)`, never panics.
    ///
    /// ```
    /// # use nuld_core::domain::Domain; use glam::{DVec2, DVec3};
    /// let p = DVec2::new(1.0, 0.5);
    /// assert!((Domain::Hemisphere.to_direction(p) - DVec3::X).length() < 1e-12);
    /// assert!((Domain::Sphere.to_direction(p) - DVec3::X).length() < 1e-12);
    /// ```
    #[inline]
    pub fn to_direction(self, p: DVec2) -> DVec3 {
        DVec3::from_array(self.to_direction_real(p.to_array()))
    }

    /// [`Domain::to_direction`] in any [`Real`] precision on plain arrays
    /// ([`square_to_hemisphere_real`] or [`square_to_sphere_real`]): what the
    /// runtime's conditional sampler evaluates in `f32`. `O(1)`, never panics.
    ///
    /// ```
    /// # use nuld_core::domain::Domain;
    /// assert_eq!(Domain::Hemisphere.to_direction_real([0.5f32, 0.5]), [0.0, 0.0, 1.0]);
    /// ```
    #[inline]
    pub fn to_direction_real<T: Real>(self, p: [T; 2]) -> [T; 3] {
        match self {
            Self::Hemisphere => square_to_hemisphere_real(p),
            Self::Sphere | Self::Square => square_to_sphere_real(p),
        }
    }

    /// Inverse of [`Domain::to_direction`]: the square point of the unit direction
    /// `d` ([`hemisphere_to_square`], which mirrors `z < 0` to `|z|`, or
    /// [`sphere_to_square`]). `O(1)`, never panics.
    #[inline]
    pub fn to_square(self, d: DVec3) -> DVec2 {
        match self {
            Self::Hemisphere => hemisphere_to_square(d),
            Self::Sphere | Self::Square => sphere_to_square(d),
        }
    }

    /// The domain's area: `4 pi` steradians for the sphere, `2 pi` for the
    /// hemisphere, 1 for the unit square. The uniform point spacing of `n` points is
    /// `sqrt(area / n)`; the equal-area maps scale areas by `area` (square to
    /// directions). `O(1)`, never panics.
    ///
    /// ```
    /// # use nuld_core::domain::Domain;
    /// use core::f64::consts::PI;
    /// assert_eq!(Domain::Sphere.area(), 4.0 * PI);
    /// assert_eq!(Domain::Hemisphere.area(), 2.0 * PI);
    /// ```
    #[inline]
    pub fn area(self) -> f64 {
        match self {
            Self::Square => 1.0,
            Self::Sphere => 4.0 * core::f64::consts::PI,
            Self::Hemisphere => 2.0 * core::f64::consts::PI,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::{square_to_hemisphere, square_to_sphere};

    #[test]
    fn codes_and_names_round_trip() {
        for d in [Domain::Square, Domain::Sphere, Domain::Hemisphere] {
            assert_eq!(Domain::from_code(d as u32), Some(d));
        }
        assert_eq!(Domain::from_code(3), None);
        let names = [Domain::Square, Domain::Sphere, Domain::Hemisphere].map(Domain::name);
        assert_eq!(names, ["square", "sphere", "hemisphere"]);
    }

    #[test]
    fn maps_are_the_domain_maps_and_invert() {
        let p = DVec2::new(0.3, 0.8);
        assert_eq!(Domain::Sphere.to_direction(p), square_to_sphere(p));
        assert_eq!(Domain::Hemisphere.to_direction(p), square_to_hemisphere(p));
        for d in [Domain::Sphere, Domain::Hemisphere] {
            let q = d.to_square(d.to_direction(p));
            assert!((p - q).length() < 1e-12, "{d:?}: {q:?}");
        }
    }
}
