//! Direct lighting from the environment, one estimator per pixel: the camera ray
//! through the pixel centre meets the scene at `x`; the pixel is
//! `(1/n) Σ w_i L(l_i) V(x, l_i)` over the `n` samples of the pixel's set
//! ([`super::sampler`]). A camera ray that meets nothing shows the map itself,
//! `L(direction)`, identical for every sampler.

use super::camera::Camera;
use super::environment::Environment;
use super::frame::Frame;
use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint};
use super::scene::{Ray, Scene, RAY_EPSILON};
use glam::DVec3;
use rayon::prelude::*;

/// A luminance image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `values[y * width + x]`.
    pub values: Vec<f64>,
}

/// The scene, its camera and its light.
#[derive(Clone, Copy)]
pub struct Setup<'a> {
    /// Geometry and materials.
    pub scene: &'a Scene,
    /// The view and the image size.
    pub camera: &'a Camera,
    /// The only light.
    pub env: &'a Environment,
}

/// What a camera ray sees.
pub enum Primary {
    /// Nothing: the map's radiance in this direction.
    Background(f64),
    /// A surface point.
    Surface {
        /// Where the ray hit.
        position: DVec3,
        /// Its frame, view and material.
        at: ShadingPoint,
    },
}

impl Setup<'_> {
    /// What the camera ray of pixel `(x, y)` sees.
    pub fn primary(&self, x: u32, y: u32) -> Primary {
        let ray = self.camera.ray(x, y);
        match self.scene.intersect(&ray) {
            None => Primary::Background(self.env.radiance(ray.direction)),
            Some(hit) => {
                let frame = Frame::new(hit.normal);
                let wo = frame.to_local(-ray.direction);
                // A camera ray meets a surface from its front; rounding may leave
                // the view a hair below the horizon.
                let wo = DVec3::new(wo.x, wo.y, wo.z.max(1e-6)).normalize();
                Primary::Surface {
                    position: hit.position,
                    at: ShadingPoint {
                        frame,
                        wo,
                        material: hit.material,
                    },
                }
            }
        }
    }

    /// `L(l) V(x, l)` for a world direction `l` at `position` with normal `n`: 0
    /// below the surface or when the scene blocks `l`.
    pub fn unoccluded_radiance(&self, position: DVec3, normal: DVec3, l: DVec3) -> f64 {
        if l.dot(normal) <= 0.0 {
            return 0.0;
        }
        let origin = position + normal * (RAY_EPSILON * (1.0 + position.abs().max_element()));
        let shadow = Ray {
            origin,
            direction: l,
        };
        if self.scene.occluded(&shadow) {
            0.0
        } else {
            self.env.radiance(l)
        }
    }

    /// The image of `sampler` at `n` samples per pixel, pixel keys from `seed`.
    /// Rows in parallel; `on_row` is called after each row. Bit for bit the same at
    /// any thread count.
    pub fn render(
        &self,
        sampler: &dyn DirectionSampler,
        n: u32,
        seed: u64,
        on_row: &(dyn Fn() + Sync),
    ) -> Image {
        let values = self.per_pixel(
            || Vec::with_capacity(n as usize),
            |buf: &mut Vec<Sample>, x, y| {
                let key = PixelKey::new(seed, self.camera.pixel_index(x, y));
                self.pixel(sampler, n, x, y, key, buf)
            },
            on_row,
        );
        Image {
            width: self.camera.width(),
            height: self.camera.height(),
            values,
        }
    }

    /// `pixel(state, x, y)` for every pixel of the camera, row-major: rows in
    /// parallel, each with its own `state()` (scratch reused along the row), and
    /// `on_row` after each row. The result does not depend on the thread count.
    pub fn per_pixel<S, T: Send>(
        &self,
        state: impl Fn() -> S + Sync,
        pixel: impl Fn(&mut S, u32, u32) -> T + Sync,
        on_row: &(dyn Fn() + Sync),
    ) -> Vec<T> {
        let (w, h) = (self.camera.width(), self.camera.height());
        let rows: Vec<Vec<T>> = (0..h)
            .into_par_iter()
            .map(|y| {
                let mut s = state();
                let row = (0..w).map(|x| pixel(&mut s, x, y)).collect();
                on_row();
                row
            })
            .collect();
        rows.into_iter().flatten().collect()
    }

    /// One pixel's estimate.
    fn pixel(
        &self,
        sampler: &dyn DirectionSampler,
        n: u32,
        x: u32,
        y: u32,
        key: PixelKey,
        buf: &mut Vec<Sample>,
    ) -> f64 {
        match self.primary(x, y) {
            Primary::Background(l) => l,
            Primary::Surface { position, at } => {
                sampler.samples(&at, key, n, buf);
                let normal = at.frame.normal();
                let sum: f64 = buf
                    .iter()
                    .filter(|s| s.weight > 0.0)
                    .map(|s| s.weight * self.unoccluded_radiance(position, normal, s.direction))
                    .sum();
                sum / n as f64
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::render::blobs::tiny_blob;
    use crate::lab::render::brdf_warp::{LobeTable, MixtureSampler};
    use crate::lab::render::lineup;
    use crate::lab::render::nuld_sampler::{NuldMode, NuldSampler};
    use crate::lab::render::primary::{Generator, PrimaryPoints};
    use crate::lab::render::sampler::Technique;
    use crate::lab::render::scene::{Material, Sphere};
    use crate::sphere::brdf_albedo::directional_albedo_metallic;

    /// One sphere of `material`, no ground, filling most of a 48 x 48 view.
    fn furnace_setup(material: Material) -> (Scene, Camera) {
        let scene = Scene {
            spheres: vec![Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
                material,
            }],
            ground: None,
        };
        let camera = Camera::new(DVec3::new(0.0, -4.0, 0.0), DVec3::ZERO, 32.0, 48, 48);
        (scene, camera)
    }

    /// Per pixel of a furnace view, `c A(roughness, θo, metallic)` of the
    /// surface's material where a surface shows (`A` the independent quadrature
    /// of `sphere::brdf_albedo`), `None` on the background, which must be the
    /// sky's `c`.
    fn furnace_albedo(setup: &Setup<'_>, c: f64) -> Vec<Option<f64>> {
        let (w, h) = (setup.camera.width(), setup.camera.height());
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| match setup.primary(x, y) {
                Primary::Surface { at, .. } => {
                    let t = at.theta_o_deg().min(89.0);
                    let m = at.material;
                    Some(c * directional_albedo_metallic(m.roughness, t, m.metallic).total())
                }
                Primary::Background(l) => {
                    assert!((l - c).abs() < 1e-9 * c);
                    None
                }
            })
            .collect()
    }

    /// The mean of `value / want - 1` over the pixels with a `want`, and its
    /// standard error from the pixels' spread.
    fn relative_error(img: &Image, want: &[Option<f64>]) -> (f64, f64) {
        let ratios: Vec<f64> = img
            .values
            .iter()
            .zip(want)
            .filter_map(|(v, a)| a.map(|a| v / a - 1.0))
            .collect();
        let k = ratios.len() as f64;
        let mean = ratios.iter().sum::<f64>() / k;
        let var = ratios.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (k - 1.0);
        (mean, (var / k).sqrt())
    }

    /// The white furnace: under a constant unit sky an unoccluded point's pixel is
    /// its directional albedo `A(roughness, θo, metallic)` (the independent
    /// quadrature of `sphere::brdf_albedo`), for every sampler of every
    /// technique, MIS included (a wrong heuristic weight or pdf shows here), on
    /// dielectrics, a metal and a half-metal. Mean over the sphere's pixels of
    /// `value / A - 1` within 4 standard errors (from the pixels' own spread,
    /// plus 0.2% for ours' fixed instances, whose weight is the blob's
    /// interpolated albedo table; ours' unbiased mode gets none). Ours for the
    /// environment is left out: its blob is of another map, and its weights
    /// and pdfs are the runtime's, checked in `nuld_sampler`'s tests.
    #[test]
    fn furnace_every_sampler_integrates_to_the_albedo() {
        let env = Environment::constant(1.0).unwrap();
        let blob = tiny_blob(16);
        let mut ours = 0;
        for material in [
            Material::dielectric(0.25),
            Material::dielectric(0.7),
            Material::metal(0.25),
            Material {
                roughness: 0.7,
                metallic: 0.5,
            },
        ] {
            let (scene, camera) = furnace_setup(material);
            let setup = Setup {
                scene: &scene,
                camera: &camera,
                env: &env,
            };
            let lobes = LobeTable::new(&[material]);
            // Environment sampling of a glossy lobe has a heavy-tailed weight
            // `f cos / pdf`: 64 samples per pixel keep the pixels' spread an honest
            // standard error there.
            let (mut w16, mut w64) = Default::default();
            let mut samplers = lineup::samplers(
                &[Technique::Brdf, Technique::Mis],
                Some(blob.as_slice()),
                None,
                16,
                5,
                &lobes,
                &env,
                &mut w16,
            )
            .unwrap();
            samplers.extend(
                lineup::samplers(
                    &[Technique::Envmap],
                    None,
                    None,
                    64,
                    5,
                    &lobes,
                    &env,
                    &mut w64,
                )
                .unwrap(),
            );
            // A at each surface pixel's view angle.
            let albedo = furnace_albedo(&setup, 1.0);
            assert!(albedo.iter().flatten().count() > 800);
            for s in &samplers {
                let n = match s.technique() {
                    Technique::Envmap => 64,
                    _ => 16,
                };
                let img = setup.render(s.as_ref(), n, 9, &|| {});
                let (mean, se) = relative_error(&img, &albedo);
                let slack = match s.name() {
                    "nuld-table" | "nuld-network" => 2e-3,
                    _ => 0.0,
                };
                ours += s.name().starts_with("nuld") as usize;
                assert!(
                    mean.abs() <= 4.0 * se + slack + 1e-12,
                    "{} {} at {material:?}: mean relative error {mean:.3e}, stderr {se:.3e}",
                    s.technique().name(),
                    s.name(),
                );
            }
        }
        // Ours' table, network and unbiased modes at each material.
        assert_eq!(ours, 3 * 4);
    }

    /// The material reaches the shading: a metal sphere's pixels are not a
    /// dielectric's of the same roughness. In the white furnace each renders
    /// (Owen-Sobol through the mixture warp, ours' unbiased mode) to its own
    /// albedo, and the two differ by many standard errors; in the evaluation
    /// scene every pixel of the back row shades a metal.
    #[test]
    fn a_metal_sphere_renders_unlike_a_dielectric() {
        let env = Environment::constant(1.0).unwrap();
        let blob = tiny_blob(16);
        let render = |material: Material, name: &str| {
            let (scene, camera) = furnace_setup(material);
            let setup = Setup {
                scene: &scene,
                camera: &camera,
                env: &env,
            };
            let lobes = LobeTable::new(&[material]);
            let mut weights = Default::default();
            let samplers = lineup::samplers(
                &[Technique::Brdf],
                Some(blob.as_slice()),
                None,
                16,
                5,
                &lobes,
                &env,
                &mut weights,
            )
            .unwrap();
            let s = samplers.iter().find(|s| s.name() == name).unwrap();
            let img = setup.render(s.as_ref(), 16, 9, &|| {});
            (img, furnace_albedo(&setup, 1.0))
        };
        for name in ["owen-sobol", "nuld-unbiased"] {
            let (metal, metal_albedo) = render(Material::metal(0.7), name);
            let (dielectric, dielectric_albedo) = render(Material::dielectric(0.7), name);
            // The same pixels show the sphere; the metal's own albedo fits it, the
            // dielectric's misses it by far (and the other way round).
            let (own, own_se) = relative_error(&metal, &metal_albedo);
            let (other, other_se) = relative_error(&metal, &dielectric_albedo);
            assert!(
                own.abs() <= 4.0 * own_se,
                "{name}: {own:.3e} ± {own_se:.3e}"
            );
            assert!(
                other.abs() > 20.0 * other_se,
                "{name}: {other:.3e} ± {other_se:.3e}"
            );
            let (back, back_se) = relative_error(&dielectric, &metal_albedo);
            assert!(
                back.abs() > 20.0 * back_se,
                "{name}: {back:.3e} ± {back_se:.3e}"
            );
            let differ = metal
                .values
                .iter()
                .zip(&dielectric.values)
                .zip(&metal_albedo)
                .filter(|((a, b), w)| w.is_some() && a != b)
                .count();
            assert!(differ > 800, "{name}: {differ} pixels differ");
        }

        let scene = Scene::spheres_on_ground();
        let camera = Camera::evaluation(64, 48);
        let setup = Setup {
            scene: &scene,
            camera: &camera,
            env: &env,
        };
        let (mut metal, mut dielectric) = (0, 0);
        for y in 0..48 {
            for x in 0..64 {
                let ray = camera.ray(x, y);
                if let (Some(hit), Primary::Surface { at, .. }) =
                    (scene.intersect(&ray), setup.primary(x, y))
                {
                    assert_eq!(at.material, hit.material);
                    let back_row = hit.position.y > 0.0 && hit.position.z > 1e-9;
                    assert_eq!(at.material.metallic, if back_row { 1.0 } else { 0.0 });
                    metal += back_row as usize;
                    dielectric += (!back_row && hit.position.z > 1e-9) as usize;
                }
            }
        }
        // Both rows are in view, neither hidden by the other.
        assert!(metal > 150 && dielectric > 150, "{metal} {dielectric}");
    }

    /// Ours' unbiased mode is unbiased by construction, in multiple importance
    /// sampling too: in a white furnace (a constant sky and a test-sized bake of
    /// it, whose sets follow nothing in particular) its pixels are `c A`, `c` the
    /// sky's radiance and `A` the independent quadrature's albedo, within 4
    /// standard errors, for environment sampling alone and with MIS, with
    /// Owen-Sobol or ours (a test-sized BRDF bake) for the BRDF half.
    #[test]
    fn ours_unbiased_mode_integrates_to_the_albedo_in_a_furnace() {
        use crate::lab::render::blobs::tiny_envmap_blob;
        let dir = std::env::temp_dir().join(format!("nuld-furnace-ours-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let map = dir.join("white.png");
        image::RgbImage::from_pixel(32, 16, image::Rgb([200, 200, 200]))
            .save(&map)
            .unwrap();
        let env = Environment::from_file(&map).unwrap();
        let c = env.radiance(DVec3::new(0.3, -0.2, 0.9).normalize());
        let blob = tiny_envmap_blob(16, &map);
        let brdf_blob = tiny_blob(16);
        let material = Material::dielectric(0.7);
        let (scene, camera) = furnace_setup(material);
        let setup = Setup {
            scene: &scene,
            camera: &camera,
            env: &env,
        };
        let lobes = LobeTable::new(&[material]);
        let mut weights = Default::default();
        let samplers = lineup::samplers(
            &[Technique::Envmap, Technique::Mis],
            Some(brdf_blob.as_slice()),
            Some(blob.as_slice()),
            16,
            5,
            &lobes,
            &env,
            &mut weights,
        )
        .unwrap();
        let mut checked = 0;
        let unbiased = ["nuld-unbiased", "nuld-both-unbiased"];
        for s in samplers.iter().filter(|s| unbiased.contains(&s.name())) {
            let img = setup.render(s.as_ref(), 16, 9, &|| {});
            let albedo = furnace_albedo(&setup, c);
            assert!(albedo.iter().flatten().count() > 800);
            let (mean, se) = relative_error(&img, &albedo);
            assert!(
                mean.abs() <= 4.0 * se,
                "{} {}: mean relative error {mean:.3e}, stderr {se:.3e}",
                s.technique().name(),
                s.name()
            );
            checked += 1;
        }
        assert_eq!(checked, 3);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn images_are_bit_identical_at_any_thread_count() {
        let env = Environment::constant(2.0).unwrap();
        let scene = Scene::spheres_on_ground();
        let camera = Camera::evaluation(16, 12);
        let setup = Setup {
            scene: &scene,
            camera: &camera,
            env: &env,
        };
        let lobes = LobeTable::new(&scene.materials());
        let blob = tiny_blob(4);
        let ours = NuldSampler::new(blob.as_slice(), NuldMode::Network).unwrap();
        let sobol = MixtureSampler::new(PrimaryPoints::new(Generator::Gbn, 4, 1), &lobes);
        let with = |threads: usize, s: &dyn DirectionSampler| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| setup.render(s, 4, 3, &|| {}))
        };
        for s in [&ours as &dyn DirectionSampler, &sobol] {
            let (a, b) = (with(1, s), with(3, s));
            let bits = |i: &Image| i.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a), bits(&b), "{}", s.name());
            assert_ne!(
                bits(&a),
                bits(&setup.render(s, 4, 4, &|| {})),
                "seed must matter"
            );
        }
    }
}
