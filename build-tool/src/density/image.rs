//! `image:PATH` and tabulated grids: piecewise-constant densities on a pixel grid.
//!
//! Pixel `(col, row)` of a `W x H` grid covers `x in [col/W, (col+1)/W]`,
//! `y in [row/H, (row+1)/H]` (y grows with the row index: the first row of the
//! file is at `y = 0`, no flip). The density on a pixel is proportional to its
//! value (for images: Rec.709 luminance).
//!
//! Everything is precomputed once: an `f64` summed-area table (so `cdf` and
//! `measure` are exact and O(1)), the marginal CDF over columns and the
//! conditional CDF over rows within each column (so `inverse_cdf` is two binary
//! searches, O(log W + log H)).

use super::numeric::{next_down, next_up};
use super::{one_line, CellGrid, Density2D, DensityError};
use glam::{DMat2, DVec2};
use std::io::Read;
use std::path::Path;

/// Rec.709 / sRGB-primaries relative luminance `Y = 0.2126 R + 0.7152 G + 0.0722 B`
/// of linear RGB values (dimensionless, same units as the inputs).
pub fn luminance(r: f64, g: f64, b: f64) -> f64 {
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

/// A decoded single-channel image: `values[row * width + col]` is the Rec.709
/// luminance of pixel `(col, row)`, row 0 being the first row stored in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct LuminanceImage {
    /// Number of columns (pixels along x).
    pub width: usize,
    /// Number of rows (pixels along y).
    pub height: usize,
    /// Row-major luminance values (may contain negative or non-finite values
    /// exactly as decoded; [`TabulatedDensity`] checks them).
    pub values: Vec<f64>,
}

/// What [`LuminanceImage::clamp_negatives`] changed: lossy EXR compression (DWAB,
/// PXR24, B44) routinely leaves a few tiny negative pixels around bright edges.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct NegativePixels {
    /// Pixels whose luminance was negative (now 0).
    pub pixels: usize,
    /// Their summed magnitude relative to the sum of the positive values (0 when
    /// there are none).
    pub share: f64,
}

impl NegativePixels {
    /// One line for stderr and reports, `None` when nothing was clamped.
    pub fn note(&self, what: &str) -> Option<String> {
        (self.pixels > 0).then(|| {
            format!(
                "{what}: {} negative pixel(s) set to 0 (together {:.1e} of the total luminance), \
                 as renderers do for lossy-compressed maps",
                self.pixels, self.share
            )
        })
    }
}

impl LuminanceImage {
    /// Sets negative values to 0, as pbrt and Mitsuba do when they build a
    /// sampling distribution from a map, and says how many there were and how much
    /// they weighed. NaN and infinite values are left as they are (the densities
    /// reject them).
    pub fn clamp_negatives(&mut self) -> NegativePixels {
        let (mut pixels, mut negative, mut positive) = (0, 0.0, 0.0);
        for v in self.values.iter_mut() {
            if *v < 0.0 {
                pixels += 1;
                negative -= *v;
                *v = 0.0;
            } else if v.is_finite() {
                positive += *v;
            }
        }
        let share = if positive > 0.0 {
            negative / positive
        } else {
            0.0
        };
        NegativePixels { pixels, share }
    }
}

/// OpenEXR magic number (first four bytes of every EXR file).
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Decodes PNG, JPEG, Radiance HDR (via `image`) or OpenEXR (via `exr`, detected by
/// its magic number) into Rec.709 luminance.
///
/// Conventions (documented choices):
/// * 8- and 16-bit PNG/JPEG values are used as stored, scaled to `[0,1]`
///   (`v/255`, `v/65535`) **without** sRGB decoding: the density is proportional
///   to the encoded value, which is what "the image" looks like as data;
/// * HDR and EXR values are linear radiance as stored (`f32`);
/// * grayscale images have `R = G = B`, so their luminance is the gray value;
/// * alpha is ignored;
/// * EXR: the first layer with R, G, B channels (missing alpha is fine); failing
///   that, a layer with a single `Y` (or single unnamed) channel.
pub fn load_luminance(path: impl AsRef<Path>) -> Result<LuminanceImage, DensityError> {
    let path = path.as_ref();
    let shown = path.display().to_string();
    if path.is_dir() {
        return Err(DensityError::Io {
            path: shown,
            reason: "is a directory".to_string(),
        });
    }
    if is_exr(path).map_err(|e| io_error(&shown, e))? {
        read_exr(path, &shown)
    } else {
        read_with_image_crate(path, &shown)
    }
}

/// The width and height of the image at `path` from its header alone (EXR, or any
/// format [`load_luminance`] reads through `image`), or `None` where the file
/// cannot be read or is not such an image (its load then says why).
pub fn image_size(path: impl AsRef<Path>) -> Option<(usize, usize)> {
    let path = path.as_ref();
    if is_exr(path).ok()? {
        let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
        let size = meta.headers.first()?.layer_size;
        Some((size.width(), size.height()))
    } else {
        let (w, h) = ::image::image_dimensions(path).ok()?;
        Some((w as usize, h as usize))
    }
}

/// Whether the file at `path` begins with the EXR magic number (else it is left
/// to `image`, which knows the other formats by their contents).
fn is_exr(path: &Path) -> std::io::Result<bool> {
    let mut magic = [0u8; 4];
    let n = std::fs::File::open(path)?.read(&mut magic)?;
    Ok(n == 4 && magic == EXR_MAGIC)
}

fn io_error(shown: &str, e: std::io::Error) -> DensityError {
    if e.kind() == std::io::ErrorKind::NotFound {
        DensityError::MissingFile {
            path: shown.to_string(),
        }
    } else {
        DensityError::Io {
            path: shown.to_string(),
            reason: one_line(e),
        }
    }
}

fn read_with_image_crate(path: &Path, shown: &str) -> Result<LuminanceImage, DensityError> {
    use ::image::DynamicImage;
    let undecodable = |reason: String| DensityError::Undecodable {
        path: shown.to_string(),
        reason,
    };
    let img = ::image::ImageReader::open(path)
        .map_err(|e| io_error(shown, e))?
        .with_guessed_format()
        .map_err(|e| io_error(shown, e))?
        .decode()
        .map_err(|e| undecodable(decode_reason(e)))?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let values: Vec<f64> = match &img {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => img
            .to_rgb32f()
            .pixels()
            .map(|p| luminance(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect(),
        _ => {
            // Integer formats: u8 widens exactly to u16 (v * 257), so v/65535 = v/255.
            img.to_rgb16()
                .pixels()
                .map(|p| {
                    let s = 1.0 / 65535.0;
                    luminance(p[0] as f64 * s, p[1] as f64 * s, p[2] as f64 * s)
                })
                .collect()
        }
    };
    Ok(LuminanceImage {
        width,
        height,
        values,
    })
}

/// The `image` crate's error on one line, except for an unrecognized file, which
/// it words with an oddly quoted extension (`` `."txt"` ``).
fn decode_reason(e: ::image::ImageError) -> String {
    use ::image::error::{ImageFormatHint, UnsupportedErrorKind};
    if let ::image::ImageError::Unsupported(u) = &e {
        if let UnsupportedErrorKind::Format(ImageFormatHint::PathExtension(ext)) = u.kind() {
            return format!(
                "neither its content nor its extension `.{}` is PNG, JPEG, HDR or EXR",
                ext.display()
            );
        }
    }
    one_line(e)
}

fn read_exr(path: &Path, shown: &str) -> Result<LuminanceImage, DensityError> {
    let rgba = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            (
                resolution.width(),
                vec![0.0_f64; resolution.width() * resolution.height()],
            )
        },
        |(w, px): &mut (usize, Vec<f64>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = luminance(r as f64, g as f64, b as f64);
        },
    );
    match rgba {
        Ok(img) => {
            let size = img.layer_data.size;
            Ok(LuminanceImage {
                width: size.width(),
                height: size.height(),
                values: img.layer_data.channel_data.pixels.1,
            })
        }
        Err(rgba_err) => {
            // Fall back to a luminance-only layer.
            let flat = exr::prelude::read_first_flat_layer_from_file(path).map_err(|e| {
                DensityError::Undecodable {
                    path: shown.to_string(),
                    reason: one_line(format!("{rgba_err}; {e}")),
                }
            })?;
            let size = flat.layer_data.size;
            let channels = &flat.layer_data.channel_data.list;
            let chan = channels
                .iter()
                .find(|c| c.name.eq("Y"))
                .or(if channels.len() == 1 {
                    channels.first()
                } else {
                    None
                })
                .ok_or_else(|| DensityError::Undecodable {
                    path: shown.to_string(),
                    reason: one_line(format!("no R,G,B or Y channels ({rgba_err})")),
                })?;
            Ok(LuminanceImage {
                width: size.width(),
                height: size.height(),
                values: chan.sample_data.values_as_f32().map(f64::from).collect(),
            })
        }
    }
}

/// A piecewise-constant density on a `W x H` grid (SPEC `image:PATH`, or built
/// with [`TabulatedDensity::from_grid`]):
/// `q(x, y) = W H m[row][col]` on pixel `(col, row)`, where
/// `m = max(v, 0) / Σ max(v, 0)` are the cell masses (`v` the pixel values).
///
/// * Negative values are clamped to 0 (they can come from out-of-gamut linear
///   HDR/EXR colors); NaN or infinite values are an error
///   ([`DensityError::NonFinitePixel`]); an all-zero grid is
///   [`DensityError::ZeroMass`].
/// * `cdf`/`measure`: bilinear interpolation of the summed-area table inside a
///   pixel, which is exact for a piecewise-constant density; O(1).
/// * `inverse_cdf` (pbrt `PiecewiseConstant2D` style): column `c` from the
///   marginal CDF over columns, then row `r` from the conditional CDF over rows of
///   column `c`, linear inside the pixel; O(log W + log H). Samples always land in
///   a pixel of positive mass, strictly (by an ulp if needed) inside its cell as
///   seen by `pdf`.
/// * Jacobian: exactly `diag(1/(W M_c), M_c/(H m_rc))` inside a pixel (`M_c` the
///   column mass); `x` does not depend on `u.y`, and `y` does not depend on `u.x`
///   within a column (it jumps between columns, where T is discontinuous).
/// * `cells` returns the pixel grid itself.
#[derive(Clone, Debug)]
pub struct TabulatedDensity {
    spec: String,
    width: usize,
    height: usize,
    /// Row-major cell masses, summing to 1.
    mass: Vec<f64>,
    /// Summed-area table, `(height+1) x (width+1)`, row-major: entry `(i, j)` is the
    /// mass of columns `< i` and rows `< j`; entry `(width, height)` is exactly 1.
    sat: Vec<f64>,
    /// Column masses.
    col_mass: Vec<f64>,
    /// Marginal CDF over columns (`width + 1` entries, from 0 to exactly 1).
    col_cdf: Vec<f64>,
    /// Conditional CDFs over rows, column by column (`height + 1` entries each).
    cond_cdf: Vec<f64>,
}

/// `(i, t)` with `cdf[i] <= u < cdf[i+1]` (a cell of positive mass) and `t` the
/// fraction of the way through it; `u >= cdf[n]` picks the last positive cell with
/// `t = 1`.
fn pick(cdf: &[f64], u: f64) -> (usize, f64) {
    let n = cdf.len() - 1;
    let total = cdf[n];
    let u = if u > 0.0 { u } else { 0.0 };
    if u >= total {
        let i = cdf.partition_point(|&v| v < total) - 1;
        return (i, 1.0);
    }
    let k = cdf.partition_point(|&v| v <= u);
    let i = k - 1;
    let t = (u - cdf[i]) / (cdf[k] - cdf[i]);
    (i, t.clamp(0.0, 1.0))
}

/// Index of the cell holding coordinate `x` in `[0,1]` on an `n`-cell axis.
fn cell_index(x: f64, n: usize) -> usize {
    ((x * n as f64) as usize).min(n - 1)
}

/// `(i + t) / n`, moved by ulps if needed so that [`cell_index`] returns `i`.
fn coord_in_cell(i: usize, t: f64, n: usize) -> f64 {
    let mut x = ((i as f64 + t) / n as f64).clamp(0.0, 1.0);
    for _ in 0..32 {
        let c = cell_index(x, n);
        if c == i {
            break;
        }
        x = if c > i { next_down(x) } else { next_up(x) };
    }
    x
}

impl TabulatedDensity {
    /// Builds a tabulated density from `width * height` row-major values
    /// (`values[row * width + col]`, any non-negative scale; negatives clamped to
    /// 0, non-finite values and all-zero grids are errors). Its `spec()` is
    /// `grid:WxH` (informational; not accepted by `parse_spec`).
    pub fn from_grid(width: usize, height: usize, values: Vec<f64>) -> Result<Self, DensityError> {
        Self::build(format!("grid:{width}x{height}"), width, height, values)
    }

    /// Loads `PATH` with [`load_luminance`] and builds the density; `spec()` is
    /// `image:PATH` with the path as given.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, DensityError> {
        let path = path.as_ref();
        let img = load_luminance(path)?;
        Self::build(
            format!("image:{}", path.display()),
            img.width,
            img.height,
            img.values,
        )
    }

    /// Grid width `W` (columns, along x).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Grid height `H` (rows, along y).
    pub fn height(&self) -> usize {
        self.height
    }

    /// Mass of pixel `(col, row)` (the masses sum to 1).
    pub fn cell_mass(&self, col: usize, row: usize) -> f64 {
        self.mass[row * self.width + col]
    }

    fn build(
        spec: String,
        width: usize,
        height: usize,
        mut values: Vec<f64>,
    ) -> Result<Self, DensityError> {
        let n = width
            .checked_mul(height)
            .ok_or_else(|| DensityError::BadGrid {
                reason: format!("{width}x{height} is too large"),
            })?;
        if n == 0 {
            return Err(DensityError::BadGrid {
                reason: format!("{width}x{height} has no pixels"),
            });
        }
        if values.len() != n {
            return Err(DensityError::BadGrid {
                reason: format!("{width}x{height} needs {n} values, got {}", values.len()),
            });
        }
        let mut max = 0.0_f64;
        for (k, v) in values.iter_mut().enumerate() {
            if !v.is_finite() {
                return Err(DensityError::NonFinitePixel {
                    what: spec,
                    col: k % width,
                    row: k / width,
                    value: *v,
                });
            }
            *v = v.max(0.0);
            max = max.max(*v);
        }
        if max <= 0.0 {
            return Err(DensityError::ZeroMass { what: spec });
        }
        // Scale by the maximum first so the sum cannot overflow.
        let total: f64 = values.iter().map(|v| v / max).sum();
        if total.is_nan() || total <= 0.0 || total.is_infinite() {
            return Err(DensityError::NonFiniteMass { what: spec });
        }
        let norm = 1.0 / (max * total);
        let mass: Vec<f64> = values.iter().map(|v| v * norm).collect();

        // Summed-area table.
        let w1 = width + 1;
        let mut sat = vec![0.0; (height + 1) * w1];
        for (row, masses) in mass.chunks_exact(width).enumerate() {
            let mut run = 0.0;
            for (col, m) in masses.iter().enumerate() {
                run += m;
                sat[(row + 1) * w1 + col + 1] = sat[row * w1 + col + 1] + run;
            }
        }
        let s = sat[height * w1 + width];
        sat.iter_mut().for_each(|v| *v /= s);

        // Marginal over columns.
        let mut col_mass = vec![0.0; width];
        for masses in mass.chunks_exact(width) {
            for (cm, m) in col_mass.iter_mut().zip(masses) {
                *cm += m;
            }
        }
        let mut col_cdf = Vec::with_capacity(width + 1);
        col_cdf.push(0.0);
        let mut run = 0.0;
        for &m in &col_mass {
            run += m;
            col_cdf.push(run);
        }
        col_cdf.iter_mut().for_each(|v| *v /= run);

        // Conditionals over rows, per column.
        let h1 = height + 1;
        let mut cond_cdf = vec![0.0; width * h1];
        for (col, c) in cond_cdf.chunks_exact_mut(h1).enumerate() {
            let mut run = 0.0;
            for row in 0..height {
                run += mass[row * width + col];
                c[row + 1] = run;
            }
            if run > 0.0 {
                c.iter_mut().for_each(|v| *v /= run);
            } else {
                // Never selected (zero column mass); uniform for definiteness.
                for (row, v) in c.iter_mut().enumerate() {
                    *v = row as f64 / height as f64;
                }
            }
        }
        Ok(Self {
            spec,
            width,
            height,
            mass,
            sat,
            col_mass,
            col_cdf,
            cond_cdf,
        })
    }

    fn column_cdf(&self, col: usize) -> &[f64] {
        let h1 = self.height + 1;
        &self.cond_cdf[col * h1..(col + 1) * h1]
    }

    /// `(col, row, point)` of the inverse CDF at `u`.
    fn locate(&self, u: DVec2) -> (usize, usize, DVec2) {
        let (col, tx) = pick(&self.col_cdf, u.x);
        let x = coord_in_cell(col, tx, self.width);
        let (row, ty) = pick(self.column_cdf(col), u.y);
        let y = coord_in_cell(row, ty, self.height);
        (col, row, DVec2::new(x, y))
    }
}

impl Density2D for TabulatedDensity {
    fn spec(&self) -> String {
        self.spec.clone()
    }

    fn pdf(&self, p: DVec2) -> f64 {
        if !((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y)) {
            return 0.0;
        }
        let col = cell_index(p.x, self.width);
        let row = cell_index(p.y, self.height);
        self.mass[row * self.width + col] * (self.width * self.height) as f64
    }

    fn cdf(&self, p: DVec2) -> f64 {
        let p = p.clamp(DVec2::ZERO, DVec2::ONE);
        let fx = p.x * self.width as f64;
        let fy = p.y * self.height as f64;
        let i = (fx as usize).min(self.width - 1);
        let j = (fy as usize).min(self.height - 1);
        let (tx, ty) = (fx - i as f64, fy - j as f64);
        let w1 = self.width + 1;
        let s00 = self.sat[j * w1 + i];
        let s10 = self.sat[j * w1 + i + 1];
        let s01 = self.sat[(j + 1) * w1 + i];
        let s11 = self.sat[(j + 1) * w1 + i + 1];
        // Bilinear interpolation of the SAT: exact for a constant density per cell.
        let v = s00 + tx * (s10 - s00) + ty * (s01 - s00) + tx * ty * (s11 - s10 - s01 + s00);
        v.clamp(0.0, 1.0)
    }

    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        if hi.x <= lo.x || hi.y <= lo.y {
            return 0.0;
        }
        let m = self.cdf(hi) - self.cdf(DVec2::new(lo.x, hi.y)) - self.cdf(DVec2::new(hi.x, lo.y))
            + self.cdf(lo);
        m.max(0.0)
    }

    fn inverse_cdf(&self, u: DVec2) -> DVec2 {
        self.locate(u).2
    }

    fn inverse_cdf_jacobian(&self, u: DVec2) -> DMat2 {
        let (col, row, _) = self.locate(u);
        let cm = self.col_mass[col];
        let m = self.mass[row * self.width + col];
        DMat2::from_diagonal(DVec2::new(
            1.0 / (self.width as f64 * cm),
            cm / (self.height as f64 * m),
        ))
    }

    fn cells(&self, _resolution: usize) -> CellGrid {
        CellGrid {
            width: self.width,
            height: self.height,
            mass: self.mass.clone(),
        }
    }
}

#[cfg(test)]
mod tests;
