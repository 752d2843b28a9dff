//! A quadrature rule of a map whose points carry equal shares of its mass
//! ([`EnvmapDensity::mass_rule`]): the profiles and cap tables of concentrated
//! maps, where a sun of a few pixels holds much of the light.

use super::EnvmapDensity;
use crate::sphere::geometry::unit_or_z;
use crate::sphere::target::normalize_rule;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// A rectangle of pixels `[c0, c1) x [r0, r1)`.
#[derive(Clone, Copy, Debug)]
struct PixelBlock {
    c0: usize,
    c1: usize,
    r0: usize,
    r1: usize,
}

impl EnvmapDensity {
    /// A weighted rule of about `k` to `3k` directions whose points are spread in
    /// proportion to the *mass*, not the solid angle, with exact pixel masses:
    ///
    /// * a pixel block (starting from the whole map) is split in two across its
    ///   longer side on the sphere while its mass exceeds `1/k`; a block whose mass
    ///   is at most `1/k` becomes one point, at the mass-weighted mean of its pixel
    ///   centres, carrying the block's mass;
    /// * a single pixel of mass `m > 1/k` is cut into about `ceil(m k)` cells of
    ///   equal solid angle (uniform in `z` and `phi`, nearly square on the
    ///   sphere), each a point at its centre carrying `m / cells`.
    ///
    /// Every point therefore carries at most about `1/k` of the mass wherever the
    /// map is bright, however small the bright region: a sun of a few pixels that
    /// holds half the light is resolved by `k/2` points. A rule of equal-solid-angle
    /// blocks (what a plain midpoint grid does) would put such a sun into one point
    /// carrying half the mass; an optimizer matching cap measures of that rule piles
    /// its points onto that one direction, and an energy-form metric built on it
    /// misjudges sets that spread inside the sun.
    pub fn mass_rule(&self, k: usize) -> Vec<(DVec3, f64)> {
        let (w, h) = (self.width, self.height);
        // Summed-area table of pixel masses, (W+1) x (H+1), for O(1) block masses.
        let mut sat = vec![0.0; (w + 1) * (h + 1)];
        for r in 0..h {
            for c in 0..w {
                sat[(r + 1) * (w + 1) + c + 1] =
                    self.mass[r * w + c] + sat[r * (w + 1) + c + 1] + sat[(r + 1) * (w + 1) + c]
                        - sat[r * (w + 1) + c];
            }
        }
        let block_mass = |b: &PixelBlock| -> f64 {
            let at = |c: usize, r: usize| sat[r * (w + 1) + c];
            (at(b.c1, b.r1) - at(b.c0, b.r1) - at(b.c1, b.r0) + at(b.c0, b.r0)).max(0.0)
        };
        let per_point = 1.0 / k.max(1) as f64;
        let mut rule = Vec::new();
        let mut stack = vec![PixelBlock {
            c0: 0,
            c1: w,
            r0: 0,
            r1: h,
        }];
        while let Some(b) = stack.pop() {
            let m = block_mass(&b);
            if m <= 0.0 {
                continue;
            }
            let single = b.c1 - b.c0 == 1 && b.r1 - b.r0 == 1;
            if single {
                self.push_pixel_cells(b.c0, b.r0, (m / per_point).ceil() as usize, &mut rule);
            } else if m <= per_point {
                let mut d = DVec3::ZERO;
                let mut sum = 0.0;
                for r in b.r0..b.r1 {
                    for c in b.c0..b.c1 {
                        let pm = self.mass[r * w + c];
                        if pm > 0.0 {
                            sum += pm;
                            d += pm * self.pixel_center(c, r);
                        }
                    }
                }
                if sum > 0.0 {
                    rule.push((unit_or_z(d), sum));
                }
            } else {
                // Split across the longer side as seen on the sphere (the width of
                // a column shrinks with sin theta toward the poles).
                let theta_mid = PI * (b.r0 + b.r1) as f64 / (2.0 * h as f64);
                let width = (b.c1 - b.c0) as f64 * TAU / w as f64 * theta_mid.sin();
                let height = (b.r1 - b.r0) as f64 * PI / h as f64;
                let split_cols = b.r1 - b.r0 == 1 || (b.c1 - b.c0 > 1 && width >= height);
                if split_cols {
                    let mid = (b.c0 + b.c1) / 2;
                    stack.push(PixelBlock { c1: mid, ..b });
                    stack.push(PixelBlock { c0: mid, ..b });
                } else {
                    let mid = (b.r0 + b.r1) / 2;
                    stack.push(PixelBlock { r1: mid, ..b });
                    stack.push(PixelBlock { r0: mid, ..b });
                }
            }
        }
        normalize_rule(&mut rule);
        rule
    }

    /// Appends about `cells` points of equal mass for pixel `(c, r)`: a grid
    /// uniform in `z` and `phi` (so every cell has the same solid angle, hence the
    /// same mass), with as many rows as keep the cells near square on the sphere.
    fn push_pixel_cells(&self, c: usize, r: usize, cells: usize, rule: &mut Vec<(DVec3, f64)>) {
        let m = self.mass[r * self.width + c];
        let (zl, zh) = (self.z_lo[r], self.z_hi[r]);
        if m <= 0.0 || zh <= zl {
            return;
        }
        let cells = cells.max(1);
        let theta_extent = zl.clamp(-1.0, 1.0).acos() - zh.clamp(-1.0, 1.0).acos();
        let z_mid = 0.5 * (zl + zh);
        let width = TAU / self.width as f64 * (1.0 - z_mid * z_mid).max(0.0).sqrt();
        let rows = ((cells as f64 * theta_extent / width.max(1e-300))
            .sqrt()
            .round() as usize)
            .clamp(1, cells);
        let cols = cells.div_ceil(rows);
        let share = m / (rows * cols) as f64;
        for i in 0..rows {
            let z = zh - (i as f64 + 0.5) / rows as f64 * (zh - zl);
            let s = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..cols {
                let phi = TAU * (c as f64 + (j as f64 + 0.5) / cols as f64) / self.width as f64;
                rule.push((DVec3::new(s * phi.cos(), s * phi.sin(), z), share));
            }
        }
    }
}
