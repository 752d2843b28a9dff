//! Luminance images as pictures: tone-mapped renders and false-colour error maps,
//! as 8-bit sRGB PNG written atomically.

use super::integrator::Image;
use crate::plot::write_rgb_png;
use anyhow::Result;
use std::path::Path;

/// An 8-bit RGB picture, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Picture {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `3 (y width + x)` is the red byte of pixel `(x, y)`.
    pub rgb: Vec<u8>,
}

/// The exposure that puts the median pixel of `reference` at 0.18 (photographic
/// middle grey) before [`tone_map`]: one exposure for every picture of a run, so
/// pictures compare.
pub fn exposure(reference: &Image) -> f64 {
    let mut v: Vec<f64> = reference
        .values
        .iter()
        .copied()
        .filter(|v| *v > 0.0)
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    let mid = v.len() / 2;
    let (_, median, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    0.18 / *median
}

/// sRGB encoding of a linear value in `[0, 1]` (IEC 61966-2-1).
fn srgb(v: f64) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

/// Reinhard's global operator `x / (1 + x)` on `exposure` times the luminance,
/// then sRGB, grey.
pub fn tone_map(image: &Image, exposure: f64) -> Picture {
    let rgb = image
        .values
        .iter()
        .flat_map(|&v| {
            let x = (v * exposure).max(0.0);
            let g = srgb(x / (1.0 + x));
            [g, g, g]
        })
        .collect();
    Picture {
        width: image.width,
        height: image.height,
        rgb,
    }
}

/// The false colour of `t` in `[0, 1]` (clamped): black, red, yellow, white (a
/// heat ramp; 0 is black so that a correct pixel vanishes).
pub fn heat(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 1.0 } else { t.clamp(0.0, 1.0) };
    let c = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    [c(3.0 * t), c(3.0 * t - 1.0), c(3.0 * t - 2.0)]
}

/// The absolute error `|image - reference|` per pixel as [`heat`] of
/// `error / scale` (`scale > 0`: the error shown white).
pub fn error_map(image: &Image, reference: &Image, scale: f64) -> Picture {
    let rgb = image
        .values
        .iter()
        .zip(&reference.values)
        .flat_map(|(a, b)| heat((a - b).abs() / scale))
        .collect();
    Picture {
        width: image.width,
        height: image.height,
        rgb,
    }
}

impl Picture {
    /// Writes the picture as PNG to `path`, atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        write_rgb_png(path, (self.width, self.height), self.rgb.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_map_and_heat_hit_their_anchor_points() {
        // sRGB of 0.5 is 0.7354 (the standard's formula), i.e. byte 188.
        let img = Image {
            width: 2,
            height: 1,
            values: vec![1.0, 0.0],
        };
        let p = tone_map(&img, 1.0);
        assert_eq!(p.rgb, vec![188, 188, 188, 0, 0, 0]);
        assert_eq!(heat(0.0), [0, 0, 0]);
        assert_eq!(heat(1.0), [255, 255, 255]);
        assert_eq!(heat(1.0 / 3.0), [255, 0, 0]);
        assert_eq!(heat(f64::NAN), [255, 255, 255]);
        // Median of (1, 2, 3) is 2 -> 0.09.
        let r = Image {
            width: 3,
            height: 1,
            values: vec![3.0, 1.0, 2.0],
        };
        assert!((exposure(&r) - 0.09).abs() < 1e-15);
    }
}
