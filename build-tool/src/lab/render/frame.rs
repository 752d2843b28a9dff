//! The local shading frame of a surface point: `z` = the normal, as every BRDF
//! function of [`nuld_core::brdf`] and every sampler expects.

use crate::sphere::geometry::tangent_frame;
use glam::DVec3;

/// An orthonormal basis `(t, b, n)` around a unit normal `n`: `(t, b)` from
/// [`tangent_frame`] (Duff et al. 2017, "Building an Orthonormal Basis, Revisited":
/// branchless, continuous except at `n.z = -1`'s sign switch).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    t: DVec3,
    b: DVec3,
    n: DVec3,
}

impl Frame {
    /// The frame around the unit normal `n`.
    pub fn new(n: DVec3) -> Self {
        let (t, b) = tangent_frame(n);
        Self { t, b, n }
    }

    /// The normal.
    pub fn normal(&self) -> DVec3 {
        self.n
    }

    /// World vector `w` in local coordinates (`z` along the normal).
    pub fn to_local(&self, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(self.t), w.dot(self.b), w.dot(self.n))
    }

    /// Local vector `v` in world coordinates.
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        v.x * self.t + v.y * self.b + v.z * self.n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_invert() {
        for n in [
            DVec3::Z,
            DVec3::NEG_Z,
            DVec3::X,
            DVec3::new(0.3, -0.5, 0.8).normalize(),
            DVec3::new(-0.1, 0.2, -0.97).normalize(),
        ] {
            let f = Frame::new(n);
            for (u, v) in [(f.t, f.b), (f.t, f.n), (f.b, f.n)] {
                assert!(u.dot(v).abs() < 1e-12);
            }
            for v in [f.t, f.b, f.n] {
                assert!((v.length() - 1.0).abs() < 1e-12);
            }
            // Right-handed, so that local azimuths turn the same way as world ones.
            assert!((f.t.cross(f.b) - n).length() < 1e-12);
            let w = DVec3::new(0.2, 0.7, -0.4);
            assert!((f.to_world(f.to_local(w)) - w).length() < 1e-12);
            assert!((f.to_local(n) - DVec3::Z).length() < 1e-12);
        }
    }
}
