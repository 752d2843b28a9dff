//! The reference image: direct lighting at many samples per pixel, combining BRDF
//! sampling (the mixture warp of random points at the material's lobe
//! probability) and environment sampling (the
//! product warp of `L cos` at the normal, [`super::environment`], of random
//! points) by multiple importance sampling with the balance heuristic (Veach
//! 1997, §9.2.2). The product warp puts the environment's samples where the
//! cosine lets light in, none below the surface.
//!
//! With `m` samples from each technique, `b_j ~ p_b`, `e_j ~ p_e`, and
//! `g(l) = f cos L V`, the pixel is `(1/m) Σ_j Y_j`,
//! `Y_j = g(b_j) / (p_b + p_e)(b_j) + g(e_j) / (p_b + p_e)(e_j)`, an unbiased
//! estimate whose standard error `sd(Y) / sqrt(m)` is kept per pixel. Random
//! numbers come from a PRNG stream per pixel ([`crate::seeding::rng`]), so the
//! image is fixed by its seed at any thread count.
//!
//! The image is cached in the output directory as `reference-KEY.bin`, `KEY` a
//! hash of everything it depends on (map file bytes, scene, camera, `m`, seed);
//! the file is written atomically and reused when present.

use super::brdf_warp::LobeTable;
use super::integrator::{Image, Primary, Setup};
use crate::output::write_atomic;
use crate::seeding::rng;
use anyhow::{bail, Context, Result};
use glam::DVec3;
use nuld_core::brdf::alpha;
use nuld_core::warp::{brdf_mixture_pdf, brdf_mixture_real};
use rand::Rng;
use std::path::{Path, PathBuf};

/// A reference image and the standard error of each pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// The estimate.
    pub image: Image,
    /// Standard error per pixel (0 for background pixels, which are exact).
    pub stderr: Vec<f64>,
}

/// First bytes of a cached reference file.
const MAGIC: &[u8; 8] = b"NULDREF1";

/// Stream offset of the reference's per-pixel PRNGs (apart from the samplers').
const REFERENCE_STREAM: u64 = 0x7e7e_0000_0000;

impl Reference {
    /// Renders the reference with `m` samples of each technique per pixel
    /// (`2 m` rays per pixel). `on_row` is called after each row.
    pub fn render(
        setup: &Setup<'_>,
        lobes: &LobeTable,
        m: u32,
        seed: u64,
        on_row: &(dyn Fn() + Sync),
    ) -> Reference {
        let all = setup.per_pixel(|| (), |_, x, y| pixel(setup, lobes, m, seed, x, y), on_row);
        Reference {
            image: Image {
                width: setup.camera.width(),
                height: setup.camera.height(),
                values: all.iter().map(|p| p.0).collect(),
            },
            stderr: all.iter().map(|p| p.1).collect(),
        }
    }

    /// The cached reference in `dir` for `key` ([`Self::cache_path`]), or `None`.
    /// A file that does not match is an error (delete it to recompute).
    pub fn load(dir: &Path, key: u64, width: u32, height: u32) -> Result<Option<Reference>> {
        let path = Self::cache_path(dir, key);
        if !path.is_file() {
            return Ok(None);
        }
        let bytes =
            std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?;
        let n = (width * height) as usize;
        let word =
            |k: usize| u64::from_le_bytes(bytes[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]));
        // The length is checked first: it guarantees the header words exist.
        if bytes.len() != 24 + 16 * n
            || &bytes[..8] != MAGIC
            || word(1) != key
            || word(2) != ((width as u64) << 32 | height as u64)
        {
            bail!(
                "{} is not a reference of this render; delete it to recompute",
                path.display()
            );
        }
        let floats: Vec<f64> = (0..2 * n).map(|k| f64::from_bits(word(3 + k))).collect();
        Ok(Some(Reference {
            image: Image {
                width,
                height,
                values: floats[..n].to_vec(),
            },
            stderr: floats[n..].to_vec(),
        }))
    }

    /// Writes the reference to [`Self::cache_path`] atomically.
    pub fn save(&self, dir: &Path, key: u64) -> Result<()> {
        let mut bytes = MAGIC.to_vec();
        bytes.extend(key.to_le_bytes());
        bytes.extend(((self.image.width as u64) << 32 | self.image.height as u64).to_le_bytes());
        for v in self.image.values.iter().chain(&self.stderr) {
            bytes.extend(v.to_bits().to_le_bytes());
        }
        write_atomic(&Self::cache_path(dir, key), &bytes)
    }

    /// `dir/reference-KEY.bin`, `KEY` in 16 hex digits.
    pub fn cache_path(dir: &Path, key: u64) -> PathBuf {
        dir.join(format!("reference-{key:016x}.bin"))
    }
}

/// The pixel's MIS estimate and its standard error.
fn pixel(setup: &Setup<'_>, lobes: &LobeTable, m: u32, seed: u64, x: u32, y: u32) -> (f64, f64) {
    let (position, at) = match setup.primary(x, y) {
        Primary::Background(l) => return (l, 0.0),
        Primary::Surface { position, at } => (position, at),
    };
    let mut g = rng(seed, REFERENCE_STREAM + setup.camera.pixel_index(x, y));
    let a = alpha(at.material.roughness);
    let p_s = lobes.lobe_probability(at.material, at.theta_o_deg());
    let normal = at.frame.normal();
    // g(l) / (p_b + p_e)(l) for a world direction l.
    let term = |l: DVec3| {
        let local = at.frame.to_local(l);
        let f_cos = at.material.cosine_weighted(at.wo, local);
        if f_cos <= 0.0 {
            return 0.0;
        }
        let p = brdf_mixture_pdf(at.wo, a, p_s, local) + setup.env.product_pdf(normal, l);
        if p <= 0.0 {
            return 0.0;
        }
        f_cos * setup.unoccluded_radiance(position, normal, l) / p
    };
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..m {
        let ub = [g.random::<f64>(), g.random::<f64>()];
        let b = at.frame.to_world(DVec3::from_array(brdf_mixture_real(
            at.wo.to_array(),
            a,
            p_s,
            ub,
        )));
        let (e, _) = setup
            .env
            .sample_product(normal, glam::DVec2::new(g.random(), g.random()));
        let y = term(b) + term(e);
        sum += y;
        sum2 += y * y;
    }
    let mf = m as f64;
    let mean = sum / mf;
    let var = ((sum2 / mf - mean * mean) * mf / (mf - 1.0).max(1.0)).max(0.0);
    (mean, (var / mf).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::image::LuminanceImage;
    use crate::lab::render::camera::Camera;
    use crate::lab::render::environment::Environment;
    use crate::lab::render::scene::{Material, Scene, Sphere};
    use crate::sphere::brdf_albedo::directional_albedo_metallic;

    /// A sky: a smooth gradient and a sun of 2 x 1 pixels holding most of the light.
    fn sun_map() -> Environment {
        let (w, h) = (64, 32);
        let values = (0..w * h)
            .map(|k| {
                let (c, r) = (k % w, k / w);
                if r == 6 && (c == 10 || c == 11) {
                    20_000.0
                } else if r < h / 2 {
                    1.0 + r as f64 / 4.0
                } else {
                    0.2
                }
            })
            .collect();
        Environment::from_luminance(
            &LuminanceImage {
                width: w,
                height: h,
                values,
            },
            "sun",
        )
        .unwrap()
    }

    /// `(mean z, mean z^2)` of `z = (a - b) / sqrt(sa^2 + sb^2)` over pixels with
    /// a positive error.
    fn z_stats(a: &[f64], sa: &[f64], b: &[f64], sb: &[f64]) -> (f64, f64, usize) {
        let z: Vec<f64> = (0..a.len())
            .filter(|&i| sa[i] + sb[i] > 0.0)
            .map(|i| (a[i] - b[i]) / (sa[i] * sa[i] + sb[i] * sb[i]).sqrt())
            .collect();
        let k = z.len() as f64;
        (
            z.iter().sum::<f64>() / k,
            z.iter().map(|v| v * v).sum::<f64>() / k,
            z.len(),
        )
    }

    /// Two seeds agree within their stated standard errors (`z^2` averages to 1
    /// if the errors are right; a wrong MIS weight or pdf makes the estimates
    /// disagree or the errors wrong), and in a white furnace the reference is the
    /// albedo of the independent quadrature.
    #[test]
    fn the_reference_converges_to_one_answer_within_its_stated_error() {
        let env = sun_map();
        let scene = Scene::spheres_on_ground();
        let camera = Camera::evaluation(24, 18);
        let setup = Setup {
            scene: &scene,
            camera: &camera,
            env: &env,
        };
        let lobes = LobeTable::new(&scene.materials());
        let a = Reference::render(&setup, &lobes, 256, 1, &|| {});
        let b = Reference::render(&setup, &lobes, 256, 2, &|| {});
        let (mean, mean_sq, k) = z_stats(&a.image.values, &a.stderr, &b.image.values, &b.stderr);
        assert!(k > 200, "{k}");
        assert!(
            mean.abs() < 4.0 / (k as f64).sqrt() && (0.6..1.5).contains(&mean_sq),
            "z: mean {mean}, mean square {mean_sq}"
        );

        // The white furnace, for the dielectric and the metal.
        let white = Environment::constant(1.0).unwrap();
        for material in [Material::dielectric(0.4), Material::metal(0.4)] {
            let ball = Scene {
                spheres: vec![Sphere {
                    center: glam::DVec3::ZERO,
                    radius: 1.0,
                    material,
                }],
                ground: None,
            };
            let cam = Camera::new(
                glam::DVec3::new(0.0, -4.0, 0.0),
                glam::DVec3::ZERO,
                32.0,
                16,
                16,
            );
            let setup = Setup {
                scene: &ball,
                camera: &cam,
                env: &white,
            };
            let r = Reference::render(&setup, &LobeTable::new(&[material]), 256, 3, &|| {});
            let mut exact = Vec::new();
            for y in 0..16 {
                for x in 0..16 {
                    exact.push(match setup.primary(x, y) {
                        Primary::Surface { at, .. } => directional_albedo_metallic(
                            material.roughness,
                            at.theta_o_deg().min(89.0),
                            material.metallic,
                        )
                        .total(),
                        Primary::Background(l) => l,
                    });
                }
            }
            let zero = vec![0.0; exact.len()];
            let (mean, mean_sq, k) = z_stats(&r.image.values, &r.stderr, &exact, &zero);
            assert!(
                k > 100 && mean.abs() < 4.0 / (k as f64).sqrt() && mean_sq < 1.6,
                "furnace z at {material:?}: mean {mean}, mean square {mean_sq}"
            );
        }
    }

    #[test]
    fn the_cache_round_trips_and_refuses_other_renders() {
        let dir = std::env::temp_dir().join(format!("nuld-reference-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let r = Reference {
            image: Image {
                width: 2,
                height: 1,
                values: vec![0.5, -0.0],
            },
            stderr: vec![1e-3, 0.0],
        };
        r.save(&dir, 7).unwrap();
        assert_eq!(Reference::load(&dir, 7, 2, 1).unwrap(), Some(r));
        assert_eq!(Reference::load(&dir, 8, 2, 1).unwrap(), None);
        std::fs::rename(
            Reference::cache_path(&dir, 7),
            Reference::cache_path(&dir, 8),
        )
        .unwrap();
        assert!(Reference::load(&dir, 8, 2, 1).is_err());
        assert!(Reference::load(&dir, 8, 1, 2).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
