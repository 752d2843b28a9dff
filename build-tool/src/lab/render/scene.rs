//! The test scene of the rendering evaluation (paper Fig. 8): spheres of the glTF
//! BRDF at several roughnesses on a ground plane, and ray casting against them.
//!
//! World frame: `+z` up (the environment map's convention), the ground is the plane
//! `z = 0`, every sphere rests on it. Every surface uses the glTF 2.0 BRDF of
//! [`nuld_core::brdf`] (metallic 0, base colour 1) at its own roughness.

use glam::DVec3;

/// Offset of shadow-ray origins along the geometric normal, in scene units (the
/// scene is about 10 units across): keeps a shadow ray from hitting its own
/// surface through rounding.
pub const RAY_EPSILON: f64 = 1e-6;

/// A ray `origin + t direction`, `t > 0`; `direction` is a unit vector.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: DVec3,
    /// Unit direction.
    pub direction: DVec3,
}

/// A sphere of the glTF BRDF at `roughness`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: DVec3,
    /// Radius, `> 0`.
    pub radius: f64,
    /// glTF roughness in `[0.1, 1]`.
    pub roughness: f64,
}

/// The closest intersection of a ray with the scene.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f64,
    /// The point hit.
    pub position: DVec3,
    /// Unit geometric normal, facing the side the ray came from.
    pub normal: DVec3,
    /// The surface's glTF roughness.
    pub roughness: f64,
}

/// Spheres on the ground plane `z = 0` (an infinite plane of roughness
/// `ground_roughness`; `None`: no ground).
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The spheres.
    pub spheres: Vec<Sphere>,
    /// The ground plane's glTF roughness, `None` for no ground.
    pub ground_roughness: Option<f64>,
}

/// Roughnesses of the default scene's spheres, left to right: the condition range
/// of the BRDF sampler, `[0.1, 1]`, from near-mirror to fully rough.
pub const SPHERE_ROUGHNESS: [f64; 5] = [0.1, 0.25, 0.4, 0.7, 1.0];

impl Scene {
    /// The scene of the evaluation: five unit spheres in a row along `x`, spaced
    /// 2.3 apart, with the roughnesses [`SPHERE_ROUGHNESS`], on a ground of
    /// roughness 0.8.
    pub fn spheres_on_ground() -> Self {
        let spheres = SPHERE_ROUGHNESS
            .iter()
            .enumerate()
            .map(|(k, &roughness)| Sphere {
                center: DVec3::new(2.3 * (k as f64 - 2.0), 0.0, 1.0),
                radius: 1.0,
                roughness,
            })
            .collect();
        Self {
            spheres,
            ground_roughness: Some(0.8),
        }
    }

    /// Every roughness in the scene: the spheres', then the ground's (what a
    /// renderer tabulates its per-material lobe probabilities for).
    pub fn roughnesses(&self) -> Vec<f64> {
        let spheres = self.spheres.iter().map(|s| s.roughness);
        spheres.chain(self.ground_roughness).collect()
    }

    /// The closest hit of `ray` with `t > 0`, if any. `O(spheres)`.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<(f64, DVec3, f64)> = None;
        for s in &self.spheres {
            if let Some(t) = sphere_distance(s, ray) {
                if best.is_none_or(|(b, _, _)| t < b) {
                    let n = (ray.origin + t * ray.direction - s.center) / s.radius;
                    best = Some((t, n, s.roughness));
                }
            }
        }
        if let (Some(roughness), Some(t)) = (self.ground_roughness, plane_distance(ray)) {
            if best.is_none_or(|(b, _, _)| t < b) {
                let n = DVec3::new(0.0, 0.0, if ray.origin.z >= 0.0 { 1.0 } else { -1.0 });
                best = Some((t, n, roughness));
            }
        }
        best.map(|(t, normal, roughness)| {
            let normal = if normal.dot(ray.direction) > 0.0 {
                -normal
            } else {
                normal
            };
            Hit {
                t,
                position: ray.origin + t * ray.direction,
                normal: normal.normalize(),
                roughness,
            }
        })
    }

    /// Whether anything blocks `ray` (a shadow ray towards the environment, which
    /// is infinitely far). `O(spheres)`.
    pub fn occluded(&self, ray: &Ray) -> bool {
        (self.ground_roughness.is_some() && plane_distance(ray).is_some())
            || self
                .spheres
                .iter()
                .any(|s| sphere_distance(s, ray).is_some())
    }
}

/// Smallest `t > 0` with `|o + t d - c| = r`, if any (`d` unit).
fn sphere_distance(s: &Sphere, ray: &Ray) -> Option<f64> {
    let oc = ray.origin - s.center;
    let b = oc.dot(ray.direction);
    let c = oc.length_squared() - s.radius * s.radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    // The far root computed without cancellation, the near one from the product
    // of the roots (`c`).
    let far = -b + if b <= 0.0 { root } else { -root };
    let (t0, t1) = if far != 0.0 {
        let other = c / far;
        (far.min(other), far.max(other))
    } else {
        (far, far)
    };
    [t0, t1].into_iter().find(|&t| t > 0.0)
}

/// `t > 0` where the ray meets `z = 0`, if any.
fn plane_distance(ray: &Ray) -> Option<f64> {
    let t = -ray.origin.z / ray.direction.z;
    (t > 0.0 && t.is_finite()).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_hit_the_nearest_surface_with_outward_normals() {
        let scene = Scene::spheres_on_ground();
        // Straight down onto the middle sphere's top: t = 10 - 2.
        let down = Ray {
            origin: DVec3::new(0.0, 0.0, 10.0),
            direction: DVec3::NEG_Z,
        };
        let hit = scene.intersect(&down).unwrap();
        assert!((hit.t - 8.0).abs() < 1e-12);
        assert!((hit.normal - DVec3::Z).length() < 1e-12);
        assert_eq!(hit.roughness, SPHERE_ROUGHNESS[2]);
        // Between two spheres the ground is hit.
        let gap = Ray {
            origin: DVec3::new(1.15, 0.0, 10.0),
            direction: DVec3::NEG_Z,
        };
        let hit = scene.intersect(&gap).unwrap();
        assert!((hit.t - 10.0).abs() < 1e-12 && hit.roughness == 0.8);
        assert_eq!(scene.roughnesses(), [0.1, 0.25, 0.4, 0.7, 1.0, 0.8]);
        let floating = Scene {
            ground_roughness: None,
            ..scene.clone()
        };
        assert!(floating.intersect(&gap).is_none() && !floating.occluded(&gap));
        // Sideways into the leftmost sphere from far left: its surface at x = -5.6.
        let side = Ray {
            origin: DVec3::new(-20.0, 0.0, 1.0),
            direction: DVec3::X,
        };
        let hit = scene.intersect(&side).unwrap();
        assert!((hit.position.x + 5.6).abs() < 1e-12, "{}", hit.position);
        assert!((hit.normal + DVec3::X).length() < 1e-12);
        // Upwards from above everything escapes; downwards is blocked.
        let up = Ray {
            origin: DVec3::new(0.0, 5.0, 3.0),
            direction: DVec3::Z,
        };
        assert!(scene.intersect(&up).is_none() && !scene.occluded(&up));
        assert!(scene.occluded(&Ray {
            origin: DVec3::new(0.0, 5.0, 3.0),
            direction: DVec3::NEG_Z
        }));
        // From a sphere's side towards its neighbour: blocked.
        let towards = Ray {
            origin: DVec3::new(-1.0 - RAY_EPSILON, 0.0, 1.0),
            direction: DVec3::NEG_X,
        };
        assert!(scene.occluded(&towards));
    }
}
