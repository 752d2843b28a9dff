//! What a conditional blob's condition means: its target, a code of the blob format
//! (a leaf module, so that the blob's errors can name a target).

use crate::domain::Domain;

/// What a conditional blob's condition means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum ConditionalTarget {
    /// The glTF 2.0 BRDF (`crate::brdf`): condition `(roughness, theta_o in
    /// degrees)`, view in the xz-plane on the `+x` side, directions on the upper
    /// hemisphere, weight = directional albedo.
    GltfBrdf = 1,
    /// An environment map lit through a cosine, `q(l | n) ∝ L(l) max(0, n.l)` (`L`
    /// the map's luminance): condition = the unit normal `n` as its point of the
    /// equal-area octahedral square ([`crate::sphere::sphere_to_square`]) in
    /// `[0,1]^2`, directions on the whole sphere in the map's (world) frame, weight
    /// = the irradiance `E(n) = ∫ L(l) max(0, n.l) dl`. Table mode interpolates the
    /// four corners' *directions* ([`super::GridCell::nlerp`]): a set's point may sit on
    /// opposite sides of an octahedral fold at neighbouring nodes, where square
    /// coordinates would jump.
    EnvmapNormal = 2,
}

impl ConditionalTarget {
    /// The target with this code, if any.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            1 => Some(Self::GltfBrdf),
            2 => Some(Self::EnvmapNormal),
            _ => None,
        }
    }

    /// Where the target's directions live: the upper hemisphere of the local frame
    /// for the BRDF, the whole sphere for an environment map.
    pub fn domain(self) -> Domain {
        match self {
            Self::GltfBrdf => Domain::Hemisphere,
            Self::EnvmapNormal => Domain::Sphere,
        }
    }
}
