//! The environment map that lights the scene, and the map's importance samplers.
//!
//! The map is read by [`crate::density::image::load_luminance`] (HDR, EXR, PNG)
//! and rendered in luminance (Rec.709 `Y`): with base colour 1 every surface is
//! grey, so the luminance of the image is the image of the luminance. The
//! equirectangular convention is [`EnvmapDensity`]'s (`+z` up, `phi` from `+x`
//! towards `+y`, row 0 at `theta = 0`), and the radiance `L(w)` is the map's
//! bilinearly filtered luminance ([`FilteredLuminance`]), as a renderer's
//! filtered texture lookup gives it.
//!
//! Two warps of a uniform point `u` of the square, both onto the density of the
//! filtered map tabulated on half pixels with their exact masses
//! ([`EnvmapDensity::from_luminance_filtered`], the density `bake --envmap` trains
//! on), as pbrt-v4 builds its sampling distribution from the filtered image:
//! * **marginal-conditional inverse CDF** ([`Environment::sample_inverse_cdf`],
//!   [`EnvmapDensity`]'s own sampler): a row by `u.y`, a column within it by `u.x`;
//! * **hierarchical warping** ([`Environment::sample_hierarchical`], Clarberg et
//!   al. 2005, [`HierarchicalWarp`]) over the grid of half-pixel masses.
//!
//! Both place the point inside its half pixel uniformly in `z = cos theta` and
//! `phi` ([`EnvmapDensity::pixel_direction`]), so their density is the same
//! piecewise-constant [`Environment::pdf`]; it is positive wherever `L` is (a half
//! pixel's mass is `∫ L` over it), so `L / pdf` is finite and the estimators are
//! unbiased, and it varies inside a half pixel where `L` does.
//!
//! A third warp samples the product `L(l) max(0, n.l)` at a surface's normal:
//! the map's tree ([`EnvmapTree`], [`Environment::sample_product`]), built from
//! the same density with the same settings as the prior of `bake --envmap`
//! ([`prior_levels`], [`PRIOR_GRID`]), so it is the very warp under ours' learned
//! points; uniform points through it are the baselines that isolate what the
//! learning adds.

use crate::baselines::HierarchicalWarp;
use crate::density::image::{load_luminance, LuminanceImage};
use crate::density::CellGrid;
use crate::sphere::envmap_tree::{prior_levels, EnvmapTree, PRIOR_GRID};
use crate::sphere::{DirectionDensity, EnvmapDensity, FilteredLuminance};
use anyhow::{Context, Result};
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use std::path::Path;

/// An environment map: radiance lookup, density and the three warps.
#[derive(Clone, Debug)]
pub struct Environment {
    radiance: FilteredLuminance,
    density: EnvmapDensity,
    hierarchical: HierarchicalWarp,
    product: EnvmapTree,
}

impl Environment {
    /// Loads the map at `path`; one-line errors for a missing or unreadable file, a
    /// NaN or infinite pixel, or a map without light.
    pub fn from_file(path: &Path) -> Result<Self> {
        let img = load_luminance(path)
            .with_context(|| format!("cannot read environment map {}", path.display()))?;
        Self::from_luminance(&img, &path.display().to_string())
    }

    /// A map that is `value` (> 0) in every direction: the furnace of the tests.
    pub fn constant(value: f64) -> Result<Self> {
        let img = LuminanceImage {
            width: 8,
            height: 4,
            values: vec![value; 32],
        };
        Self::from_luminance(&img, "constant")
    }

    /// The map from decoded luminance (`name` for messages). Negative pixels are
    /// set to 0, as [`EnvmapDensity`] does.
    pub fn from_luminance(img: &LuminanceImage, name: &str) -> Result<Self> {
        let density = EnvmapDensity::from_luminance_filtered(img, Domain::Sphere, name)
            .with_context(|| format!("environment map {name}"))?;
        let radiance = FilteredLuminance::new(img);
        let (w, h) = (density.width(), density.height());
        let mass: Vec<f64> = (0..h)
            .flat_map(|r| (0..w).map(move |c| (c, r)))
            .map(|(c, r)| density.pixel_mass(c, r))
            .collect();
        let hierarchical = HierarchicalWarp::new(&CellGrid {
            width: w,
            height: h,
            mass,
        });
        let product = EnvmapTree::new(&density, prior_levels(&density), PRIOR_GRID)
            .with_context(|| format!("environment map {name}"))?;
        Ok(Self {
            radiance,
            density,
            hierarchical,
            product,
        })
    }

    /// `Φ = ∫ L(w) dw` over the sphere (luminance times steradians; exact, the sum
    /// of the half pixels' masses).
    pub fn power(&self) -> f64 {
        self.density.integral()
    }

    /// Radiance (luminance) arriving from direction `w` (any length > 0): the
    /// map's bilinearly filtered luminance there ([`FilteredLuminance::at`]).
    pub fn radiance(&self, w: DVec3) -> f64 {
        self.radiance.at(w)
    }

    /// The irradiance `E(n) = ∫ L(l) max(0, n.l) dl` at surfaces facing each of
    /// the unit `normals` ([`EnvmapDensity::irradiances`]).
    pub fn irradiances(&self, normals: &[DVec3]) -> Vec<f64> {
        self.density.irradiances(normals)
    }

    /// Density per steradian of both warps at `w`: the mean of `L` over the half
    /// pixel holding `w`, over `Φ`.
    pub fn pdf(&self, w: DVec3) -> f64 {
        self.density.pdf(w)
    }

    /// The direction of `u` in `[0,1)^2` by the marginal-conditional inverse CDF.
    pub fn sample_inverse_cdf(&self, u: DVec2) -> DVec3 {
        self.density.sample(u)
    }

    /// The direction of `u` in `[0,1)^2` by hierarchical warping: the quadtree picks
    /// a half pixel with its mass and a point in it, which is spread uniformly in
    /// `z` and `phi` within the half pixel ([`EnvmapDensity::pixel_direction`]).
    pub fn sample_hierarchical(&self, u: DVec2) -> DVec3 {
        let p = self.hierarchical.warp(u);
        let (w, h) = (self.density.width(), self.density.height());
        let (x, y) = (p.x * w as f64, p.y * h as f64);
        let (c, r) = ((x as usize).min(w - 1), (y as usize).min(h - 1));
        let f = DVec2::new(
            (x - c as f64).clamp(0.0, 1.0),
            (y - r as f64).clamp(0.0, 1.0),
        );
        self.density.pixel_direction(c, r, f)
    }

    /// The direction of `u` in `[0,1)^2` by the product warp at the unit normal
    /// `n` (module docs), and its solid-angle pdf ([`Self::product_pdf`]).
    pub fn sample_product(&self, n: DVec3, u: DVec2) -> (DVec3, f64) {
        EnvmapTree::sample(&self.product.tree(), n, u)
    }

    /// Levels of the product warp's tree.
    pub fn product_levels(&self) -> u32 {
        self.product.levels
    }

    /// The solid-angle density of [`Self::sample_product`] at `n` in the unit
    /// direction `l`: 0 where the normal cannot see `l`.
    pub fn product_pdf(&self, n: DVec3, l: DVec3) -> f64 {
        EnvmapTree::pdf(&self.product.tree(), n, l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeding::rng;
    use crate::sphere::geometry::{direction_from_angles, random_direction};
    use rand::Rng;
    use std::f64::consts::TAU;

    /// A 16 x 8 map with one bright pixel and a gradient, in closed form.
    fn test_map() -> LuminanceImage {
        let (w, h) = (16, 8);
        let values = (0..w * h)
            .map(|k| {
                if k == 3 * w + 5 {
                    500.0
                } else {
                    1.0 + (k % w) as f64
                }
            })
            .collect();
        LuminanceImage {
            width: w,
            height: h,
            values,
        }
    }

    #[test]
    fn radiance_is_the_pixel_value_at_centres_and_power_its_integral() {
        let img = test_map();
        let env = Environment::from_luminance(&img, "test").unwrap();
        // Pixel centres by the map convention, independently of the density code.
        for (c, r) in [(5, 3), (0, 0), (15, 7), (8, 4)] {
            let theta = std::f64::consts::PI * (r as f64 + 0.5) / 8.0;
            let phi = TAU * (c as f64 + 0.5) / 16.0;
            let w = direction_from_angles(theta, phi);
            let want = img.values[r * 16 + c];
            assert!((env.radiance(w) - want).abs() < 1e-9 * want, "{c},{r}");
        }
        // Φ by Monte Carlo over uniform directions: 4π E[L].
        let mut g = rng(1, 2);
        let m = 400_000;
        let sum: f64 = (0..m).map(|_| env.radiance(random_direction(&mut g))).sum();
        let mc = 4.0 * std::f64::consts::PI * sum / m as f64;
        assert!(
            (mc / env.power() - 1.0).abs() < 0.02,
            "{mc} vs {}",
            env.power()
        );
    }

    #[test]
    fn both_warps_follow_the_pdf() {
        // E_pdf[g / pdf] = ∫ g for g = L (x + 2): a wrong density biases it.
        let env = Environment::from_luminance(&test_map(), "test").unwrap();
        let g = |w: DVec3| env.radiance(w) * (w.x + 2.0);
        let mut r = rng(3, 4);
        let m = 200_000;
        let uniform: f64 =
            (0..m).map(|_| g(random_direction(&mut r))).sum::<f64>() * 4.0 * std::f64::consts::PI
                / m as f64;
        for warp in [
            Environment::sample_inverse_cdf,
            Environment::sample_hierarchical,
        ] {
            let est: f64 = (0..m)
                .map(|_| {
                    let w = warp(&env, DVec2::new(r.random(), r.random()));
                    g(w) / env.pdf(w)
                })
                .sum::<f64>()
                / m as f64;
            assert!((est / uniform - 1.0).abs() < 0.02, "{est} vs {uniform}");
        }
    }
}
