//! What a map delivers to a surface: its irradiance `E(n)` at a normal and the
//! map lit through the cosine about `n`, `q(l | n) ∝ L(l) max(0, n.l)` (the
//! target of `bake --envmap`).

use super::{column_centres, row_centres, z_edge, EnvmapDensity};
use crate::density::image::LuminanceImage;
use crate::sphere::DirectionSpecError;
use glam::DVec3;
use nuld_core::blob::Domain;
use rayon::prelude::*;
use std::borrow::Cow;
use std::f64::consts::TAU;

impl EnvmapDensity {
    /// `∫ L(l) max(0, n.l) dl` for the unit normal `n`: the irradiance at a
    /// surface facing `n` (luminance units), `Σ L_p Ω_p max(0, n.c_p)` over the
    /// pixels with `c_p` the pixel's centre. `O(W H)` the first time (the blocks
    /// of [`Self::irradiances`]), then a block per `16 x 16` cells and the cells
    /// along the horizon.
    pub fn irradiance(&self, n: DVec3) -> f64 {
        self.irradiances(&[n])[0]
    }

    /// [`Self::irradiance`] at each of `normals`, in parallel (each normal's sum
    /// in a fixed order, so the values do not depend on the thread count).
    ///
    /// Each sum runs over blocks of 16 x 16 cells (built on first use): a block
    /// whose lit cell centres all lie above the normal's horizon adds
    /// `n . Σ mass c_p` (the same sum, `max` never clipping, in another order of
    /// operations), one below it nothing, and only the blocks the horizon
    /// crosses add their cells one by one. On a 2048 x 1024 cell map that is
    /// about a twentieth of the cells (a bake's 64 x 64 irradiance table read
    /// every cell of the map 4096 times). Equal to the pixel-order sum to
    /// rounding: the blocks kept whole have every cell about `1e-3` or more
    /// above the horizon (in `n . c_p`), so no term is small against the
    /// rounding of the others. `O(blocks + horizon cells)` a normal.
    ///
    /// A map of fewer than [`MIN_LIT_ROWS`] rows sums the lit map's own
    /// sub-cells instead ([`Self::cosine_weighted`]), in the order the lit map
    /// sums them: its integral to the last bit.
    pub fn irradiances(&self, normals: &[DVec3]) -> Vec<f64> {
        if lit_subdivision(self.height) > 1 {
            return normals
                .par_iter()
                .map(|&n| {
                    let lit = self.lit_cells(n);
                    lit.values
                        .iter()
                        .enumerate()
                        .map(|(j, v)| v * lit.dphi() * lit.dz(j / lit.width))
                        .sum()
                })
                .collect();
        }
        let blocks = self
            .irradiance_blocks
            .get_or_init(|| IrradianceBlocks::new(self));
        normals
            .par_iter()
            .map(|&n| self.integral * blocks.lit_sum(self, n))
            .collect()
    }

    /// The density `q(l | n) ∝ L(l) max(0, n.l)` of the map lit through a cosine
    /// about the unit normal `n`, on the sphere: every pixel's luminance times
    /// `max(0, n.c)` at the centre `c` of each of its `k x k` equal-angle sub-cells
    /// (piecewise constant like the map; `k` = [`lit_subdivision`], 1 for maps of
    /// [`MIN_LIT_ROWS`] rows or more), and the irradiance `E(n)` it integrates to
    /// (the lit map's [`integral`](Self::integral); at `k = 1`
    /// [`Self::irradiance`]'s sum). If no light reaches `n` (the map is black
    /// above its horizon), the plain cosine lobe about `n` and `E(n) = 0`: any set
    /// serves there, since the estimator's weight is 0.
    pub fn cosine_weighted(&self, n: DVec3) -> Result<(Self, f64), DirectionSpecError> {
        let LitCells {
            mut values,
            width,
            height,
        } = self.lit_cells(n);
        let dark = !values.iter().any(|&v| v > 0.0);
        if dark {
            let centres = self.centres(lit_subdivision(self.height));
            for (r, row) in values.chunks_exact_mut(width).enumerate() {
                for (c, v) in row.iter_mut().enumerate() {
                    *v = n.dot(centres.at(c, r)).max(0.0);
                }
            }
        }
        let img = LuminanceImage {
            width,
            height,
            values,
        };
        let lit = Self::from_owned_luminance(img, Domain::Sphere, &self.name)?;
        let irradiance = if dark { 0.0 } else { lit.integral };
        Ok((lit, irradiance))
    }

    /// The lit map's values before normalization: each (sub-)cell's luminance
    /// times `max(0, n.c)` at its centre ([`Self::cosine_weighted`]).
    fn lit_cells(&self, n: DVec3) -> LitCells {
        let (w, h) = (self.width, self.height);
        let k = lit_subdivision(h);
        let centres = self.centres(k);
        let dphi = TAU / w as f64;
        // Row by row into one allocation: a bake builds this for every pool
        // normal, on the filtered map's four cells a pixel.
        let (lw, lh) = (w * k, h * k);
        let mut values = vec![0.0f64; lw * lh];
        for (r, row) in values.chunks_exact_mut(lw).enumerate() {
            let cell_row = r / k;
            let omega = dphi * (self.z_hi[cell_row] - self.z_lo[cell_row]);
            for (c, v) in row.iter_mut().enumerate() {
                let lum = self.luminance_of(self.mass[cell_row * w + c / k], omega);
                *v = lum * n.dot(centres.at(c, r)).max(0.0);
            }
        }
        LitCells {
            values,
            width: lw,
            height: lh,
        }
    }

    /// The centres of the lit map's cells: this map's own at `k = 1`, else those
    /// of the `k`-times finer equal-angle grid.
    fn centres(&self, k: usize) -> Centres<'_> {
        if k == 1 {
            return Centres {
                rows: Cow::Borrowed(&self.row_trig),
                cols: Cow::Borrowed(&self.col_trig),
            };
        }
        let (lw, lh) = (self.width * k, self.height * k);
        Centres {
            rows: Cow::Owned(row_centres(
                (0..lh).map(|r| (z_edge(r + 1, lh), z_edge(r, lh))),
            )),
            cols: Cow::Owned(column_centres(lw)),
        }
    }
}

/// [`EnvmapDensity::lit_cells`]: a lit map's values, row-major, on its cells.
struct LitCells {
    values: Vec<f64>,
    width: usize,
    height: usize,
}

impl LitCells {
    /// Each cell's width in `phi`.
    fn dphi(&self) -> f64 {
        TAU / self.width as f64
    }

    /// The `z` extent of row `r` (on the sphere, as the lit map measures it).
    fn dz(&self, r: usize) -> f64 {
        (z_edge(r, self.height) - z_edge(r + 1, self.height)).max(0.0)
    }
}

/// `[z, sqrt(1 - z^2)]` per row and `[cos phi, sin phi]` per column of a grid's
/// cell centres.
struct Centres<'a> {
    rows: Cow<'a, [[f64; 2]]>,
    cols: Cow<'a, [[f64; 2]]>,
}

impl Centres<'_> {
    /// The direction of cell `(c, r)`'s centre.
    fn at(&self, c: usize, r: usize) -> DVec3 {
        let [z, s] = self.rows[r];
        let [cos_phi, sin_phi] = self.cols[c];
        DVec3::new(s * cos_phi, s * sin_phi, z)
    }
}

/// Rows of cells that a lit map ([`EnvmapDensity::cosine_weighted`]) has at
/// least: the cosine is read once per cell, and on a map of a few pixels (a 1 x 1
/// map's four cells span 90° each) that reading is far from `max(0, n.l)`,
/// which the bake's check and training would then take as the target. At 256
/// rows a cell spans 0.7°, as a 256 x 128 map's half pixels do.
pub const MIN_LIT_ROWS: usize = 256;

/// The `k` of [`EnvmapDensity::cosine_weighted`]: each cell of a map of `h` rows
/// cut into `k x k` for the cosine, `ceil(MIN_LIT_ROWS / h)` (1 from
/// [`MIN_LIT_ROWS`] rows on, so those maps' lit maps are what they were).
pub fn lit_subdivision(h: usize) -> usize {
    MIN_LIT_ROWS.div_ceil(h.max(1))
}

/// Cells per side of an [`IrradianceBlocks`] block: 16 x 16 cells of a
/// 2048 x 1024 map are 8192 blocks, of which a horizon crosses a few hundred.
const IRRADIANCE_BLOCK: usize = 16;

/// How far above a normal's horizon (in `n . l`) every lit cell centre of a block
/// must lie for the block to add its first moment in one dot product: `n . Σ m c`
/// then sums terms of at least this size, whose rounding stays within about
/// `1e-13` of the block's share.
const HORIZON_MARGIN: f64 = 1e-3;

/// A map's cells in square blocks, each with what [`EnvmapDensity::irradiances`]
/// needs to take it whole: the first moment of its light and a cone about its
/// cell centres.
#[derive(Clone, Debug)]
pub(super) struct IrradianceBlocks {
    blocks: Vec<Block>,
}

/// One block of [`IrradianceBlocks`].
#[derive(Clone, Debug)]
struct Block {
    /// First cell row and column; the block ends at the map's edge or
    /// [`IRRADIANCE_BLOCK`] cells on.
    row: usize,
    col: usize,
    /// `Σ mass c_p` over the block's lit cells.
    moment: DVec3,
    /// The unit axis of the cone (the mean of the lit cell centres).
    axis: DVec3,
    /// `sin r` for the cone's half-angle `r` (the largest angle from the axis to
    /// a lit cell centre); 2 where `r` reaches 90°, so that no normal sees the
    /// block whole.
    sin_radius: f64,
}

impl IrradianceBlocks {
    /// The blocks of `map` that hold light, in row-major block order.
    fn new(map: &EnvmapDensity) -> Self {
        let (w, h, b) = (map.width, map.height, IRRADIANCE_BLOCK);
        let corners: Vec<(usize, usize)> = (0..h.div_ceil(b))
            .flat_map(|by| (0..w.div_ceil(b)).map(move |bx| (by * b, bx * b)))
            .collect();
        let blocks = corners
            .par_iter()
            .filter_map(|&(row, col)| {
                let mut moment = DVec3::ZERO;
                let mut sum = DVec3::ZERO;
                let mut lit = 0usize;
                for (c, r) in lit_cells(map, row, col) {
                    let d = map.pixel_center(c, r);
                    moment += map.mass[r * w + c] * d;
                    sum += d;
                    lit += 1;
                }
                if lit == 0 {
                    return None;
                }
                // A block of a tiny map can span half the sphere, its centres'
                // sum near 0: any axis then, and a radius past 90° below.
                let axis = sum.try_normalize().unwrap_or(DVec3::Z);
                let min_cos = lit_cells(map, row, col)
                    .map(|(c, r)| axis.dot(map.pixel_center(c, r)))
                    .fold(1.0f64, f64::min);
                let sin_radius = match min_cos > 0.0 {
                    true => (1.0 - min_cos * min_cos).max(0.0).sqrt(),
                    false => 2.0,
                };
                Some(Block {
                    row,
                    col,
                    moment,
                    axis,
                    sin_radius,
                })
            })
            .collect();
        Self { blocks }
    }

    /// `Σ mass max(0, n . c_p)` over `map`'s lit cells (the masses normalized to
    /// 1), block by block in order: with `a` the angle from `n` to a block's axis
    /// and `r` its radius, `cos a > sin r + margin` puts every cell centre more
    /// than the margin above the horizon (`a + r < 90°` by at least that), and
    /// `cos a < -(sin r + margin)` every one below it.
    fn lit_sum(&self, map: &EnvmapDensity, n: DVec3) -> f64 {
        let mut sum = -0.0;
        for block in &self.blocks {
            let cos_a = n.dot(block.axis);
            let bound = block.sin_radius + HORIZON_MARGIN;
            if cos_a > bound {
                sum += n.dot(block.moment);
            } else if cos_a >= -bound {
                for (c, r) in lit_cells(map, block.row, block.col) {
                    let m = map.mass[r * map.width + c];
                    sum += m * n.dot(map.pixel_center(c, r)).max(0.0);
                }
            }
        }
        sum
    }
}

/// The lit cells `(column, row)` of the block whose first cell is `(col, row)`,
/// row by row: what a block's moment, its cone and a horizon's cell-by-cell sum
/// all run over, in this order.
fn lit_cells(
    map: &EnvmapDensity,
    row: usize,
    col: usize,
) -> impl Iterator<Item = (usize, usize)> + '_ {
    let (w, b) = (map.width, IRRADIANCE_BLOCK);
    (row..(row + b).min(map.height))
        .flat_map(move |r| (col..(col + b).min(w)).map(move |c| (c, r)))
        .filter(move |&(c, r)| map.mass[r * w + c] > 0.0)
}
