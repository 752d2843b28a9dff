//! The test scene of the rendering evaluation (paper Fig. 8): spheres of the glTF
//! BRDF at several roughnesses, dielectric and metal, on a ground plane, and ray
//! casting against them.
//!
//! World frame: `+z` up (the environment map's convention), the ground is the plane
//! `z = 0`, every sphere rests on it. Every surface uses the glTF 2.0
//! metallic-roughness BRDF of [`nuld_core::brdf`] (base colour 1) at its own
//! [`Material`]: roughness and metallic.

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

/// A surface's glTF metallic-roughness material, base colour 1: the BRDF
/// `nuld_core::brdf::gltf_metallic` at its roughness and metallic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// glTF roughness in `[0.1, 1]`.
    pub roughness: f64,
    /// glTF metallic in `[0, 1]`: 0 the dielectric, 1 the metal.
    pub metallic: f64,
}

impl Material {
    /// The dielectric (metallic 0) of `roughness`.
    pub const fn dielectric(roughness: f64) -> Self {
        Self {
            roughness,
            metallic: 0.0,
        }
    }

    /// The metal (metallic 1) of `roughness`.
    pub const fn metal(roughness: f64) -> Self {
        Self {
            roughness,
            metallic: 1.0,
        }
    }

    /// `f(wo, l) max(n.l, 0)` for unit local directions (`z` = the normal):
    /// `nuld_core::brdf::gltf_metallic` times the cosine, bit for bit
    /// `nuld_core::brdf::cosine_weighted` for the dielectric.
    pub fn cosine_weighted(&self, wo: DVec3, l: DVec3) -> f64 {
        let f = nuld_core::brdf::gltf_metallic(
            wo.to_array(),
            l.to_array(),
            self.roughness,
            self.metallic,
        );
        f * l.z.max(0.0)
    }
}

/// A sphere of a [`Material`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: DVec3,
    /// Radius, `> 0`.
    pub radius: f64,
    /// Its material.
    pub material: Material,
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
    /// The surface's material.
    pub material: Material,
}

/// The classes of surface that `render` splits its error by: what decides a
/// pixel's error differs between them (under environment sampling alone a
/// smooth metal's rare hits on bright light carry weights in the thousands, the
/// ground's never do).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceClass {
    /// Spheres of metallic 0.5 or less.
    DielectricSpheres,
    /// Spheres of metallic above 0.5.
    MetalSpheres,
    /// The ground plane `z = 0`.
    Ground,
}

impl SurfaceClass {
    /// Every class, in print order (`index` is the place in it).
    pub const ALL: [SurfaceClass; 3] = [
        SurfaceClass::DielectricSpheres,
        SurfaceClass::MetalSpheres,
        SurfaceClass::Ground,
    ];

    /// The class of a surface point at `position` of `material`: the ground where
    /// `z` is within 1e-9 of 0 (every sphere rests above it), else a sphere,
    /// metal for metallic above 0.5.
    pub fn of(position: DVec3, material: &Material) -> Self {
        match (position.z < 1e-9, material.metallic > 0.5) {
            (true, _) => Self::Ground,
            (false, true) => Self::MetalSpheres,
            (false, false) => Self::DielectricSpheres,
        }
    }

    /// Its place in [`Self::ALL`].
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Its name in prose: `dielectric spheres`, `metal spheres`, `ground`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::DielectricSpheres => "dielectric spheres",
            Self::MetalSpheres => "metal spheres",
            Self::Ground => "ground",
        }
    }

    /// Its RMSE's `render.csv` column: `rmse_dielectric`, `rmse_metal`,
    /// `rmse_ground`.
    pub const fn column(self) -> &'static str {
        match self {
            Self::DielectricSpheres => "rmse_dielectric",
            Self::MetalSpheres => "rmse_metal",
            Self::Ground => "rmse_ground",
        }
    }

    /// Its bias's `render.csv` column: `bias_dielectric`, `bias_metal`,
    /// `bias_ground`.
    pub const fn bias_column(self) -> &'static str {
        match self {
            Self::DielectricSpheres => "bias_dielectric",
            Self::MetalSpheres => "bias_metal",
            Self::Ground => "bias_ground",
        }
    }
}

/// Spheres on the ground plane `z = 0` (an infinite plane of material `ground`;
/// `None`: no ground).
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The spheres.
    pub spheres: Vec<Sphere>,
    /// The ground plane's material, `None` for no ground.
    pub ground: Option<Material>,
}

/// Roughnesses of the default scene's spheres, left to right: the condition range
/// of the BRDF sampler, `[0.1, 1]`, from near-mirror to fully rough.
pub const SPHERE_ROUGHNESS: [f64; 5] = [0.1, 0.25, 0.4, 0.7, 1.0];

/// The default scene's ground: a rough dielectric.
pub const GROUND: Material = Material::dielectric(0.8);

/// `y` of the default scene's front row (dielectrics) and back row (metals).
pub const ROWS_Y: [f64; 2] = [-1.3, 1.3];

impl Scene {
    /// The scene of the evaluation: two rows of five unit spheres along `x`,
    /// spaced 2.3 apart, with the roughnesses [`SPHERE_ROUGHNESS`] left to right:
    /// dielectrics in front (`y = -1.3`), metals behind them (`y = 1.3`), on a
    /// dielectric ground of roughness 0.8 ([`GROUND`]).
    pub fn spheres_on_ground() -> Self {
        let row = |y: f64, material: fn(f64) -> Material| {
            SPHERE_ROUGHNESS
                .iter()
                .enumerate()
                .map(move |(k, &roughness)| Sphere {
                    center: DVec3::new(2.3 * (k as f64 - 2.0), y, 1.0),
                    radius: 1.0,
                    material: material(roughness),
                })
        };
        let spheres = row(ROWS_Y[0], Material::dielectric)
            .chain(row(ROWS_Y[1], Material::metal))
            .collect();
        Self {
            spheres,
            ground: Some(GROUND),
        }
    }

    /// Every material in the scene, each once: the spheres' in order, then the
    /// ground's (what a renderer tabulates its per-material lobe probabilities
    /// for).
    pub fn materials(&self) -> Vec<Material> {
        let mut all: Vec<Material> = Vec::new();
        for m in self.spheres.iter().map(|s| s.material).chain(self.ground) {
            if !all.contains(&m) {
                all.push(m);
            }
        }
        all
    }

    /// The closest hit of `ray` with `t > 0`, if any. `O(spheres)`.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<(f64, DVec3, Material)> = None;
        for s in &self.spheres {
            if let Some(t) = sphere_distance(s, ray) {
                if best.is_none_or(|(b, _, _)| t < b) {
                    let n = (ray.origin + t * ray.direction - s.center) / s.radius;
                    best = Some((t, n, s.material));
                }
            }
        }
        if let (Some(material), Some(t)) = (self.ground, plane_distance(ray)) {
            if best.is_none_or(|(b, _, _)| t < b) {
                let n = DVec3::new(0.0, 0.0, if ray.origin.z >= 0.0 { 1.0 } else { -1.0 });
                best = Some((t, n, material));
            }
        }
        best.map(|(t, normal, material)| {
            let normal = if normal.dot(ray.direction) > 0.0 {
                -normal
            } else {
                normal
            };
            Hit {
                t,
                position: ray.origin + t * ray.direction,
                normal: normal.normalize(),
                material,
            }
        })
    }

    /// Whether anything blocks `ray` (a shadow ray towards the environment, which
    /// is infinitely far). `O(spheres)`.
    pub fn occluded(&self, ray: &Ray) -> bool {
        (self.ground.is_some() && plane_distance(ray).is_some())
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
        let [front, back] = ROWS_Y;
        // Straight down onto the middle front sphere's top: t = 10 - 2, the
        // dielectric of the middle roughness.
        let down = |x: f64, y: f64| Ray {
            origin: DVec3::new(x, y, 10.0),
            direction: DVec3::NEG_Z,
        };
        let hit = scene.intersect(&down(0.0, front)).unwrap();
        assert!((hit.t - 8.0).abs() < 1e-12);
        assert!((hit.normal - DVec3::Z).length() < 1e-12);
        assert_eq!(hit.material, Material::dielectric(SPHERE_ROUGHNESS[2]));
        // Behind it, the metal of the same roughness; the rightmost metal is the
        // roughest.
        let hit = scene.intersect(&down(0.0, back)).unwrap();
        assert!((hit.t - 8.0).abs() < 1e-12);
        assert_eq!(hit.material, Material::metal(SPHERE_ROUGHNESS[2]));
        let hit = scene.intersect(&down(4.6, back)).unwrap();
        assert_eq!(hit.material, Material::metal(1.0));
        // Between two spheres, and between the rows, the ground is hit.
        for gap in [down(1.15, front), down(0.0, 0.0)] {
            let hit = scene.intersect(&gap).unwrap();
            assert!((hit.t - 10.0).abs() < 1e-12 && hit.material == GROUND);
        }
        let gap = down(1.15, front);
        let roughness = [0.1, 0.25, 0.4, 0.7, 1.0];
        let want: Vec<Material> = (roughness.map(Material::dielectric).into_iter())
            .chain(roughness.map(Material::metal))
            .chain([GROUND])
            .collect();
        assert_eq!(scene.materials(), want);
        let floating = Scene {
            ground: None,
            ..scene.clone()
        };
        assert!(floating.intersect(&gap).is_none() && !floating.occluded(&gap));
        // Sideways into the leftmost front sphere from far left: its surface at
        // x = -5.6.
        let side = Ray {
            origin: DVec3::new(-20.0, front, 1.0),
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
        // From a sphere's side towards its neighbour: blocked; from a front
        // sphere's back towards the metal behind it: blocked.
        let towards = Ray {
            origin: DVec3::new(-1.0 - RAY_EPSILON, front, 1.0),
            direction: DVec3::NEG_X,
        };
        assert!(scene.occluded(&towards));
        let behind = Ray {
            origin: DVec3::new(0.0, front + 1.0 + RAY_EPSILON, 1.0),
            direction: DVec3::Y,
        };
        assert!(scene.occluded(&behind));
    }

    /// The material's `f cos` is the metallic-roughness BRDF's, the dielectric's
    /// bit for bit as before.
    #[test]
    fn materials_evaluate_the_metallic_brdf() {
        let wo = DVec3::new(0.6, 0.0, 0.8);
        let l = DVec3::new(-0.28, 0.0, 0.96);
        let d = Material::dielectric(0.3).cosine_weighted(wo, l);
        assert_eq!(d, nuld_core::brdf::cosine_weighted(wo, l, 0.3));
        let m = Material::metal(0.3).cosine_weighted(wo, l);
        let want = nuld_core::brdf::gltf_metallic(wo.to_array(), l.to_array(), 0.3, 1.0) * l.z;
        assert_eq!(m, want);
        assert!(m != d && m > 0.0);
        assert_eq!(Material::metal(0.3).cosine_weighted(wo, -l), 0.0);
    }
}
