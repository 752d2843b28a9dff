//! The bilinearly filtered luminance of an equirectangular map: the radiance of
//! `bake --envmap`'s target `q(l | n) ∝ L(l) max(0, n.l)` and of `render`'s light.
//!
//! Layout as [`super::EnvmapDensity`]'s (docs/targets.md): column `c` of `W` covers
//! `phi in [2 pi c / W, 2 pi (c+1) / W)` from `+x` toward `+y`, row `r` of `H`
//! covers `theta in [pi r / H, pi (r+1) / H)` from `+z`. In pixel coordinates
//! `x = W phi / (2 pi)`, `y = H theta / pi`, pixel `(c, r)`'s value sits at its
//! centre `(c + 1/2, r + 1/2)`, and `L` is the bilinear interpolation of the four
//! centres around `(x, y)`: periodic in `x`, clamped to the first and last row's
//! centres in `y` (so `L` is constant in `theta` within half a pixel of a pole).
//! That is the filter a renderer's texture lookup applies (pbrt-v4's
//! `ImageInfiniteLight` with bilinear lookups); `L` is continuous, so a sun of a
//! few pixels has soft edges half a pixel wide instead of steps.
//!
//! [`FilteredLuminance::half_pixel_averages`] tabulates `L` exactly for the
//! piecewise-constant machinery ([`super::EnvmapDensity`]: cap measures, the
//! mass-adaptive rule, the inverse CDF): on the grid of half pixels (`2W x 2H`)
//! every cell lies inside one bilinear patch (between four centres) or in a
//! clamped half row, so its solid-angle mean of `L` is `L` at the cell's
//! solid-angle centroid (the mean of a function bilinear in `(x, y)` under the
//! product weight `dx sin theta dtheta`). The tabulation therefore holds every
//! half pixel's exact mass `∫ L dw`, and its density differs from `L / ∫ L` only
//! inside half pixels.

use super::equirect::pixel_coords;
use super::geometry::unit_or_z;
use crate::density::image::LuminanceImage;
use glam::DVec3;
use std::f64::consts::PI;

/// Cells per pixel side of [`FilteredLuminance::half_pixel_averages`]: the finest
/// grid whose cells each lie within one bilinear patch.
pub const SUBDIVISION: usize = 2;

/// The bilinearly filtered luminance `L` of a `W x H` equirectangular map
/// (module docs), negative pixels read as 0 (as [`super::EnvmapDensity`] reads
/// them). Values are not otherwise checked: callers reject non-finite ones first
/// ([`super::EnvmapDensity`]'s constructors do).
#[derive(Clone, Debug, PartialEq)]
pub struct FilteredLuminance {
    width: usize,
    height: usize,
    values: Vec<f64>,
}

impl FilteredLuminance {
    /// The filtered map of `img` (which must hold `width * height >= 1` values),
    /// its negative values set to 0.
    pub fn new(img: &LuminanceImage) -> Self {
        Self {
            width: img.width,
            height: img.height,
            values: img
                .values
                .iter()
                .map(|&v| if v < 0.0 { 0.0 } else { v })
                .collect(),
        }
    }

    /// `L` at pixel coordinates `(x, y)` (`x` any real, periodic; `y` clamped to
    /// the centres of the first and last rows).
    fn at_pixel_coords(&self, x: f64, y: f64) -> f64 {
        let (w, h) = (self.width, self.height);
        let xc = x - 0.5;
        let x0 = xc.floor();
        let tx = xc - x0;
        let c0 = (x0 as i64).rem_euclid(w as i64) as usize;
        let c1 = (c0 + 1) % w;
        let yc = (y - 0.5).clamp(0.0, (h - 1) as f64);
        let r0 = (yc.floor() as usize).min(h - 1);
        let ty = yc - r0 as f64;
        let r1 = (r0 + 1).min(h - 1);
        let v = |c: usize, r: usize| self.values[r * w + c];
        let top = v(c0, r0) + tx * (v(c1, r0) - v(c0, r0));
        let bottom = v(c0, r1) + tx * (v(c1, r1) - v(c0, r1));
        top + ty * (bottom - top)
    }

    /// `L(w)` for a direction `w` (any length > 0; the zero vector reads as `+z`),
    /// luminance units.
    pub fn at(&self, w: DVec3) -> f64 {
        let p = pixel_coords(unit_or_z(w), self.width, self.height);
        self.at_pixel_coords(p.x, p.y)
    }

    /// The `(SUBDIVISION W) x (SUBDIVISION H)` image whose cell `(j, i)` holds the
    /// mean of `L` over the cell's solid angle, exactly (module docs): for `phi`
    /// the cell's middle, for `theta` its centroid under `sin theta`,
    /// `(sin b - b cos b - sin a + a cos a) / (cos a - cos b)` on `[a, b]`.
    pub fn half_pixel_averages(&self) -> LuminanceImage {
        let (w, h) = (self.width * SUBDIVISION, self.height * SUBDIVISION);
        let s = SUBDIVISION as f64;
        let rows: Vec<f64> = (0..h)
            .map(|i| {
                let (a, b) = (PI * i as f64 / h as f64, PI * (i + 1) as f64 / h as f64);
                let centroid =
                    (b.sin() - b * b.cos() - a.sin() + a * a.cos()) / (a.cos() - b.cos());
                centroid / PI * self.height as f64
            })
            .collect();
        let values = rows
            .iter()
            .flat_map(|&y| (0..w).map(move |j| ((j as f64 + 0.5) / s, y)))
            .map(|(x, y)| self.at_pixel_coords(x, y))
            .collect();
        LuminanceImage {
            width: w,
            height: h,
            values,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::geometry::direction_from_angles as direction;
    use std::f64::consts::TAU;

    fn map() -> FilteredLuminance {
        let (w, h) = (8, 4);
        FilteredLuminance::new(&LuminanceImage {
            width: w,
            height: h,
            values: (0..w * h).map(|k| ((k * 7919) % 13) as f64 + 0.5).collect(),
        })
    }

    #[test]
    fn centres_give_pixel_values_and_midpoints_their_means() {
        let m = map();
        let v = |c: usize, r: usize| m.values[r * 8 + c];
        let angle = |c: f64, r: f64| (PI * r / 4.0, TAU * c / 8.0);
        for r in 0..4 {
            for c in 0..8 {
                let (t, p) = angle(c as f64 + 0.5, r as f64 + 0.5);
                assert!((m.at(direction(t, p)) - v(c, r)).abs() < 1e-12, "{c},{r}");
                // Between two centres of a row, across the seam for c = 7.
                let (t, p) = angle(c as f64 + 1.0, r as f64 + 0.5);
                let want = 0.5 * (v(c, r) + v((c + 1) % 8, r));
                assert!((m.at(direction(t, p)) - want).abs() < 1e-12, "{c},{r}");
            }
        }
        // Between four centres: their mean.
        let (t, p) = angle(3.0, 2.0);
        let want = 0.25 * (v(2, 1) + v(3, 1) + v(2, 2) + v(3, 2));
        assert!((m.at(direction(t, p)) - want).abs() < 1e-12);
        // Above the first row's centres, constant in theta.
        let (t, p) = angle(4.5, 0.1);
        assert!((m.at(direction(t, p)) - v(4, 0)).abs() < 1e-12);
    }

    /// Every half pixel's mean against a brute-force midpoint sum of `L` over the
    /// cell's solid angle (`sin theta dtheta dphi`), which knows nothing of the
    /// centroid formula.
    #[test]
    fn half_pixel_averages_are_the_solid_angle_means() {
        let m = map();
        let fine = m.half_pixel_averages();
        assert_eq!((fine.width, fine.height), (16, 8));
        let k = 200;
        for i in 0..8 {
            for j in 0..16 {
                let (mut sum, mut area) = (0.0, 0.0);
                for a in 0..k {
                    let theta = PI * (i as f64 + (a as f64 + 0.5) / k as f64) / 8.0;
                    for b in 0..k {
                        let phi = TAU * (j as f64 + (b as f64 + 0.5) / k as f64) / 16.0;
                        sum += m.at(direction(theta, phi)) * theta.sin();
                        area += theta.sin();
                    }
                }
                let want = sum / area;
                let got = fine.values[i * 16 + j];
                assert!((got - want).abs() < 1e-4 * want, "{j},{i}: {got} vs {want}");
            }
        }
    }
}
