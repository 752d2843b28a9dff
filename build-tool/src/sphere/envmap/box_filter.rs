//! A coarser copy of a map's density: each block of `k x k` cells merged into one
//! cell holding exactly the block's mass.
//!
//! A bake lights the map through the cosine of every pool normal and sums it for
//! every node of the irradiance table, `O(cells)` per normal. A 4096 x 2048 map is
//! 33.5 M half-pixel cells ([`EnvmapDensity::from_luminance_filtered`]), sixteen
//! times a 1024 x 512 map's: its pool took 182 s and its irradiance table 50 s
//! where the shared maps take 12 s and 3 s. Those phases read the map through
//! sums over caps and over the sphere, which a block's mass serves as well as
//! its cells' do, so they read the copy this module makes, as does the bake's
//! quality check, while the prior's tree keeps every cell
//! (docs/results/envmap.md#large-maps, #coarse-check).

use super::EnvmapDensity;
use crate::density::image::LuminanceImage;
use std::f64::consts::TAU;

/// Cells of the density of a 1024 x 512 map (its 2048 x 1024 half pixels): the
/// size the shared maps have and the bake's times were set at. A bake lights a
/// larger map's [`EnvmapDensity::coarse_factor`] copy of at most this many cells.
pub const COARSE_CELLS: usize = 2048 * 1024;

impl EnvmapDensity {
    /// This density with every `k x k` block of cells (`k` rows by `k` columns,
    /// from the top left) merged into one cell of the blocks' grid: a block's mass
    /// is the sum of its cells' masses and its luminance their mean weighted by
    /// solid angle, so the integral, the mass of every block and of every union of
    /// blocks are this density's (to rounding). The rows of the coarse grid stay
    /// equal steps of `theta` (a block's `z` edges are its outer cells'), its
    /// columns equal steps of `phi`. `None` unless `k >= 2` divides both the width
    /// and the height. `O(cells)`.
    pub fn box_filtered(&self, k: usize) -> Option<Self> {
        let (w, h) = (self.width, self.height);
        if k < 2 || !w.is_multiple_of(k) || !h.is_multiple_of(k) {
            return None;
        }
        let (cw, ch) = (w / k, h / k);
        let dphi = TAU / cw as f64;
        let mut values = vec![0.0f64; cw * ch];
        for (rc, row) in values.chunks_exact_mut(cw).enumerate() {
            for r in rc * k..(rc + 1) * k {
                let cells = &self.mass[r * w..(r + 1) * w];
                for (v, block) in row.iter_mut().zip(cells.chunks_exact(k)) {
                    *v += block.iter().sum::<f64>();
                }
            }
            // The block's solid angle: the sum of its cells' (their z edges nest).
            let omega = dphi * (self.z_hi[rc * k] - self.z_lo[(rc + 1) * k - 1]).max(0.0);
            for v in row.iter_mut() {
                *v = self.luminance_of(*v, omega);
            }
        }
        let img = LuminanceImage {
            width: cw,
            height: ch,
            values,
        };
        let (img, _) = super::cleaned(img, &self.name).ok()?;
        Self::from_cleaned(&img, self.negative, self.domain, &self.name).ok()
    }

    /// The block size `k` of the [`Self::box_filtered`] copy that a bake lights
    /// for this density: 1 (the density itself) where it has at most
    /// `max_cells` cells, else the smallest `k` that brings it to at most
    /// `max_cells` and divides both sides, or 1 if no `k` up to four times that
    /// size does (a map of an odd size is then lit whole, as before).
    pub fn coarse_factor(&self, max_cells: usize) -> usize {
        let (cells, max_cells) = (self.width * self.height, max_cells.max(1));
        if cells <= max_cells {
            return 1;
        }
        let mut least = 2;
        while cells.div_ceil(least * least) > max_cells {
            least += 1;
        }
        (least..=4 * least)
            .find(|&k| self.width.is_multiple_of(k) && self.height.is_multiple_of(k))
            .unwrap_or(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use nuld_core::blob::Domain;

    /// A density of `w x h` cells with a smooth sky, a few bright cells and a
    /// dark band.
    fn map(w: usize, h: usize) -> EnvmapDensity {
        let values = (0..w * h)
            .map(|k| {
                let (c, r) = (k % w, k / w);
                let sun = if (c, r) == (w / 3, h / 4) || (c, r) == (w / 3 + 1, h / 4) {
                    500.0
                } else {
                    0.0
                };
                let dark = r > h / 2 && r < h / 2 + h / 8;
                if dark {
                    0.0
                } else {
                    1.0 + (c as f64 * 0.37).sin().abs() + sun
                }
            })
            .collect();
        let img = LuminanceImage {
            width: w,
            height: h,
            values,
        };
        EnvmapDensity::from_luminance(&img, Domain::Sphere, "box").unwrap()
    }

    /// Every block's mass is the sum of its cells' masses (an independent sum
    /// over the fine cells), the integral is kept, and so is the irradiance of
    /// a normal to within what moving each cell's cosine to its block's centre
    /// can change (blocks of 4 x 4 cells, 5.6 degrees across).
    #[test]
    fn a_block_keeps_the_mass_of_its_cells() {
        let (w, h, k) = (256, 128, 4);
        let fine = map(w, h);
        let coarse = fine.box_filtered(k).unwrap();
        assert_eq!((coarse.width(), coarse.height()), (w / k, h / k));
        assert!((coarse.integral() / fine.integral() - 1.0).abs() < 1e-12);
        for rc in 0..h / k {
            for cc in 0..w / k {
                let want: f64 = (0..k * k)
                    .map(|j| fine.pixel_mass(cc * k + j % k, rc * k + j / k))
                    .sum();
                let got = coarse.pixel_mass(cc, rc);
                assert!(
                    (got - want).abs() < 1e-14,
                    "block ({cc}, {rc}): {got} vs {want}"
                );
            }
            let (lo, hi) = coarse.row_z_range(rc);
            assert!((hi - fine.row_z_range(rc * k).1).abs() < 1e-15);
            assert!((lo - fine.row_z_range(rc * k + k - 1).0).abs() < 1e-15);
        }
        for n in [DVec3::Z, DVec3::new(0.3, -0.5, 0.2).normalize(), -DVec3::X] {
            let (e, ec) = (fine.irradiance(n), coarse.irradiance(n));
            assert!((ec / e - 1.0).abs() < 0.01, "{n}: {ec} vs {e}");
        }
        // The copy is a different density: far from uniform, as the map is.
        assert!(coarse.pixel_mass(w / 3 / k, h / 4 / k) > 10.0 * coarse.pixel_mass(0, 1));
    }

    /// The factor is 1 up to the limit, then the smallest divisor of both sides
    /// that reaches it; a size with no such divisor is lit whole; a factor that
    /// does not divide is refused.
    #[test]
    fn the_factor_is_the_smallest_dividing_block_that_fits() {
        let m = map(64, 32);
        assert_eq!(m.coarse_factor(64 * 32), 1);
        assert_eq!(m.coarse_factor(16 * 8), 4);
        assert_eq!(m.coarse_factor(16 * 8 + 1), 4);
        // 2 x 2 blocks leave 512 cells, over 500: the next divisor is 4.
        assert_eq!(m.coarse_factor(500), 4);
        let odd = map(2 * 23, 23);
        assert_eq!(odd.coarse_factor(100), 1);
        assert!(odd.box_filtered(2).is_none());
        assert!(m.box_filtered(1).is_none());
        assert!(m.box_filtered(3).is_none());
        assert!(odd.box_filtered(23).is_some());
    }
}
