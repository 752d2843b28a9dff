//! The environment light's sampling as a shipping renderer does it: the incumbent
//! that `bench --only envmap-prior` times the environment sampler against.
//!
//! [`EnvmapLight`] is Mitsuba 3's `envmap` emitter's warp: the map's luminance
//! times `sin θ` on the `(W + 1) x H` vertices of its pixel grid (the first column
//! repeated at the end, so the interpolant wraps in `φ`), sampled by the exact
//! bilinear marginal-conditional warp ([`nuld_core::marginal2d`], one node) in
//! `f32`, the point `(x, y)` of the square read as `φ = 2π x`, `θ = π y`
//! (`+z` up, row 0 at the zenith: the inverse of
//! [`pixel_coords`]` (ω, 1, 1)`, the layout every map here is read in). Its
//! solid-angle pdf is the square's over the area element:
//!
//! ```text
//! p(ω) = p(x, y) / (2 π² sin θ)
//! ```
//!
//! It ignores the normal's cosine, as renderers' environment lights do; what it
//! costs per sample (two binary searches over 2 MB tables at 1024 x 512 pixels,
//! a few transcendental calls) is what a renderer pays for a direction and its
//! pdf.

use crate::density::image::LuminanceImage;
use crate::sphere::equirect::pixel_coords;
use anyhow::{anyhow, ensure, Result};
use core::f32::consts::PI;
use glam::DVec3;
use nuld_core::marginal2d::{tabulate, Blend, Marginal2D, Marginal2DShape};

/// A map's luminance warp, tabulated once ([`EnvmapLight::new`]); sample it
/// through [`EnvmapLight::sampler`].
#[derive(Clone, Debug)]
pub struct EnvmapLight {
    shape: Marginal2DShape,
    data: Vec<f32>,
    marginal: Vec<f32>,
    conditional: Vec<f32>,
}

impl EnvmapLight {
    /// Tabulates `img`'s luminance times `sin θ_j`, `θ_j = π j / (H - 1)` on
    /// vertex row `j` (module docs); negative or non-finite pixels count as 0.
    /// Errors on a map under 2 pixels tall or without light off its first and
    /// last rows.
    pub fn new(img: &LuminanceImage) -> Result<Self> {
        let (w, h) = (img.width, img.height);
        ensure!(
            w >= 1 && h >= 2 && img.values.len() == w * h,
            "a {w} x {h} map cannot be tabulated (at least 1 x 2 pixels)"
        );
        let (nx, ny) = (w + 1, h);
        let shape = Marginal2DShape {
            size: [nx as u32, ny as u32],
            nodes: 1,
        };
        let mut data = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            let sin_theta = (PI * j as f32 / (ny - 1) as f32).sin().max(0.0);
            let row = &img.values[j * w..(j + 1) * w];
            data.extend((0..nx).map(|i| {
                let v = row[i % w] as f32;
                if v.is_finite() && v > 0.0 {
                    v * sin_theta
                } else {
                    0.0
                }
            }));
        }
        // The first and last vertex rows sit at the poles, where `sin θ` is 0:
        // light there alone (any map 2 pixels tall) leaves nothing to sample.
        ensure!(
            data.iter().any(|&v| v > 0.0),
            "the map's luminance warp has no light to sample: it weighs each pixel row by \
             sin θ, which is 0 on the first and last rows, and the map has no light on the \
             others"
        );
        let mut marginal = vec![0.0; ny];
        let mut conditional = vec![0.0; nx * ny];
        tabulate(shape, &mut data, &mut marginal, &mut conditional)
            .map_err(|e| anyhow!("the map's luminance warp: {e}"))?;
        Ok(Self {
            shape,
            data,
            marginal,
            conditional,
        })
    }

    /// The warp over these tables, as a renderer holds it between samples.
    pub fn sampler(&self) -> EnvmapLightSampler<'_> {
        let warp = Marginal2D::view(self.shape, &self.data, &self.marginal, &self.conditional)
            .expect("the tables were written by tabulate for this shape");
        EnvmapLightSampler { warp }
    }
}

/// [`EnvmapLight`]'s warp, borrowed: a direction and its pdf per sample.
#[derive(Clone, Copy, Debug)]
pub struct EnvmapLightSampler<'a> {
    warp: Marginal2D<'a, f32>,
}

impl EnvmapLightSampler<'_> {
    /// The direction at primary sample `u` in `[0,1]^2` and its solid-angle pdf
    /// (module docs; 0 at the poles, where `sin θ` is). `O(log W + log H)`.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> ([f32; 3], f32) {
        let ([x, y], p) = self.warp.sample(u, &Blend::single(0));
        let (sin_phi, cos_phi) = (2.0 * PI * x).sin_cos();
        let (sin_theta, cos_theta) = (PI * y).sin_cos();
        let d = [sin_theta * cos_phi, sin_theta * sin_phi, cos_theta];
        (d, solid_angle_pdf(p, sin_theta))
    }

    /// The solid-angle density of [`Self::sample`]'s directions at the unit
    /// vector `d`. `O(1)`.
    pub fn pdf(&self, d: [f32; 3]) -> f32 {
        let [x, y] = square_point(d);
        let p = self.warp.pdf([x, y], &Blend::single(0));
        solid_angle_pdf(p, (PI * y).sin())
    }
}

/// The point of the square whose direction is the unit vector `d`: `(φ / 2π,
/// θ / π)`, [`pixel_coords`] of a one-pixel map.
fn square_point(d: [f32; 3]) -> [f32; 2] {
    let p = pixel_coords(DVec3::from_array(d.map(f64::from)), 1, 1);
    [p.x as f32, p.y as f32]
}

/// The square's density `p` over the area element `2 π² sin θ`; 0 where `sin θ`
/// is 0.
#[inline]
fn solid_angle_pdf(p: f32, sin_theta: f32) -> f32 {
    if sin_theta > 0.0 {
        p / (2.0 * PI * PI * sin_theta)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A smooth sky brighter towards the zenith with a bright patch near the
    /// horizon: light everywhere, so every direction has a positive pdf.
    fn sky(w: usize, h: usize) -> LuminanceImage {
        let mut values = Vec::with_capacity(w * h);
        for r in 0..h {
            for c in 0..w {
                let sun = (c / 4 == 5 && r * 8 / h == 3) as u8 as f64;
                values.push(0.2 + (h - r) as f64 / h as f64 + 200.0 * sun);
            }
        }
        LuminanceImage {
            width: w,
            height: h,
            values,
        }
    }

    /// The mean of `g(ω) / p(ω)` over the light's samples estimates `∫ g dω`:
    /// for `g = 1` the sphere's area `4π`, for `g = z²` its second moment
    /// `4π / 3` (closed forms), each within 4 standard errors.
    #[test]
    fn its_pdf_is_the_density_of_its_directions() {
        let light = EnvmapLight::new(&sky(64, 32)).unwrap();
        let s = light.sampler();
        let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(7);
        let n = 200_000;
        let (mut sums, mut squares) = ([0.0f64; 2], [0.0f64; 2]);
        for _ in 0..n {
            let (d, p) = s.sample([r.random::<f32>(), r.random::<f32>()]);
            assert!(p > 0.0, "a sampled direction has pdf {p}");
            // The pdf the sample carries is the light's density there.
            let q = s.pdf(d);
            assert!((q - p).abs() <= 2e-3 * p, "{d:?}: {p} against {q}");
            for (k, g) in [1.0, (d[2] as f64).powi(2)].into_iter().enumerate() {
                let x = g / p as f64;
                sums[k] += x;
                squares[k] += x * x;
            }
        }
        let four_pi = 4.0 * std::f64::consts::PI;
        for (k, want) in [four_pi, four_pi / 3.0].into_iter().enumerate() {
            let mean = sums[k] / n as f64;
            let se = ((squares[k] / n as f64 - mean * mean) / n as f64).sqrt();
            assert!(
                (mean - want).abs() < 4.0 * se,
                "moment {k}: {mean} ± {se}, want {want}"
            );
        }
    }

    /// The bright patch, 1/64 of the map's columns and 1/8 of its rows carrying
    /// most of the light, gets most of the samples.
    #[test]
    fn it_samples_the_bright_pixels() {
        let light = EnvmapLight::new(&sky(64, 32)).unwrap();
        let s = light.sampler();
        let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let n = 20_000;
        let in_patch = (0..n)
            .filter(|_| {
                let (d, _) = s.sample([r.random::<f32>(), r.random::<f32>()]);
                let [x, y] = square_point(d);
                // Columns 20..24 and rows 12..16 of 64 x 32, with the
                // interpolant's half-pixel spread.
                (19.0 / 64.0..25.0 / 64.0).contains(&x) && (11.0 / 31.0..16.0 / 31.0).contains(&y)
            })
            .count();
        assert!(in_patch > n / 2, "{in_patch} of {n} in the patch");
    }

    #[test]
    fn a_map_without_light_is_refused() {
        let dark = LuminanceImage {
            width: 4,
            height: 2,
            values: vec![0.0; 8],
        };
        let e = EnvmapLight::new(&dark).unwrap_err().to_string();
        assert!(e.contains("no light to sample"), "{e}");
    }

    /// Light on the pole rows alone is weighed by `sin θ = 0`: refused with
    /// the reason, where one lit pixel on the row between them is enough.
    #[test]
    fn light_on_the_pole_rows_alone_is_refused() {
        let map = |values: Vec<f64>| LuminanceImage {
            width: 2,
            height: 3,
            values,
        };
        let e = EnvmapLight::new(&map(vec![5.0, 5.0, 0.0, 0.0, 5.0, 5.0]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("first and last rows"), "{e}");
        let light = EnvmapLight::new(&map(vec![5.0, 5.0, 0.0, 1.0, 5.0, 5.0])).unwrap();
        let (d, p) = light.sampler().sample([0.3, 0.6]);
        assert!(p > 0.0 && d[2].abs() < 0.9, "{d:?} {p}");
    }
}
