//! `envmap:PATH`: an equirectangular luminance map as a density of directions.
//!
//! Layout (docs/targets.md): `+z` up; column `c` of `W` covers
//! `phi in [2 pi c / W, 2 pi (c+1) / W)` measured from `+x` toward `+y`; row `r` of
//! `H` covers `theta in [pi r / H, pi (r+1) / H)` from `+z`. The density is constant
//! on each pixel and proportional to its luminance; pixel `(c, r)` has solid angle
//! `(2 pi / W)(cos theta_r - cos theta_{r+1})`, so its mass is luminance times solid
//! angle, normalized to 1. On the hemisphere domain the map is cut at the horizon
//! (rows below carry no mass).
//!
//! * **Warp / exact sampler** ([`EnvmapDensity::sample`]): marginal-conditional
//!   inverse CDF, the row by `u.y` (row masses), the column by `u.x` (masses within
//!   the row), then uniform in `z = cos theta` and in `phi` within the pixel, using the
//!   rescaled remainders of `u.y` and `u.x`. Exact for the piecewise-constant density.
//! * **Cap measure** ([`EnvmapDensity::cap_measure`]): exact in `phi`, quadrature in
//!   `z`. For a fixed `z` the cap meets the latitude circle in one arc
//!   `|phi - phi_w| <= acos((t - z cos gamma) / (sqrt(1 - z^2) sin gamma))`, whose
//!   mass within a row is a difference of the row's piecewise-linear cumulative
//!   mass. Latitudes entirely inside the cap are added in closed form; on the band
//!   `cos(gamma + theta) < z < cos(gamma - theta)` where the boundary crosses, each
//!   row's share is integrated over the polar angle `alpha` (`dz = sin alpha dalpha`)
//!   after the substitution `alpha = alpha_a + (alpha_b - alpha_a)(1 - cos psi)/2`
//!   (which removes the square-root behaviour of the arc width at the band ends),
//!   by 4-point Gauss–Legendre on pieces of at most `pi/16` in `psi`; the pieces at
//!   the two band ends are graded geometrically (12 halvings), which resolves rims
//!   passing close to a pole (where the arc width jumps from 0 to ~pi within an
//!   angle comparable to the rim's distance from the pole). What remains is the
//!   error from the kinks where an arc end crosses a pixel column (not resolved;
//!   see the tests for measured errors: against brute-force subdivision up to
//!   ~5e-5 on high-contrast synthetic maps; on `courtyard.hdr` median 4e-8, 90th
//!   percentile 5e-7, max 5e-6 against a 32-pieces-per-row reference, which
//!   [`EnvmapDensity::cap_measure_with`] provides). Cost `O(H)` per cap, about
//!   0.1–0.3 ms for a 1024x512 map.
//! * **Profiles / quadrature** ([`EnvmapDensity::mass_rule`]): points spread in
//!   proportion to the mass, each carrying at most about `1/k` of it (a bright pixel
//!   is cut into many equal-mass cells, dim regions are merged into blocks), so a
//!   sun of a few pixels is resolved as finely as the rest of the light; profiles
//!   use a `2^15`-point rule (coarser than `cap_measure`).

mod box_filter;
mod cap_measure;
mod irradiance;
mod mass_rule;
#[cfg(test)]
pub(crate) mod test_support;
#[cfg(test)]
mod tests;

pub use box_filter::COARSE_CELLS;
pub use irradiance::{lit_subdivision, MIN_LIT_ROWS};

use super::cap_table::profile_of_rule;
use super::equirect::pixel_coords;
use super::filtered_luminance::FilteredLuminance;
use super::geometry::unit_or_z;
use super::target::{DirectionDensity, DirectionSpecError};
use crate::density::image::{load_luminance, LuminanceImage, NegativePixels};
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use std::f64::consts::{PI, TAU};
use std::path::Path;
use std::sync::OnceLock;

/// Points of the rule used for cap-measure profiles.
const PROFILE_POINTS: usize = 1 << 15;

/// Gauss–Legendre nodes and weights on `[0, 1]`, 4 points.
const GL4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// Largest step in the band angle `psi` integrated by one 4-point rule.
const PSI_PIECE: f64 = PI / 16.0;
/// Levels of geometric grading toward a band end (pieces of 1/2, 1/4, ... of the
/// end piece).
const END_GRADING: u32 = 12;
/// A pixel is *bright* when it holds more than this multiple of its row's mean
/// pixel mass ...
const BRIGHT_PIXEL: f64 = 16.0;
/// ... and more than this much of the map's mass. Cap measures integrate the rows
/// holding bright pixels piecewise between the angles where an arc end crosses a
/// bright pixel's edge, adaptively.
const BRIGHT_MASS: f64 = 1e-7;
/// Absolute tolerance (in mass) of one adaptively integrated piece.
const ADAPTIVE_TOL: f64 = 1e-10;
/// Most halvings of one adaptively integrated piece.
const ADAPTIVE_DEPTH: u32 = 24;

/// The `envmap:` target (see the module docs).
#[derive(Clone, Debug)]
pub struct EnvmapDensity {
    name: String,
    width: usize,
    height: usize,
    domain: Domain,
    /// Per row: `z` range `[z_lo, z_hi]` (clipped at the horizon on the hemisphere).
    z_lo: Vec<f64>,
    z_hi: Vec<f64>,
    /// Row-major pixel masses, summing to 1.
    mass: Vec<f64>,
    /// `∫ L dw` over the domain: the masses' sum before normalization.
    integral: f64,
    /// Per row, `W + 1` cumulative masses (`col_cum[r * (W+1) + c]`).
    col_cum: Vec<f64>,
    /// `H + 1` cumulative row masses.
    row_cdf: Vec<f64>,
    /// Per row, the columns of its bright pixels (see [`BRIGHT_PIXEL`]).
    bright_cols: Vec<Vec<usize>>,
    /// Per column, `[cos phi, sin phi]` of its centre; per row, `[z, sqrt(1 - z^2)]`
    /// of its centre: [`Self::pixel_center`] without a sine or cosine per pixel
    /// (the lit maps of a bake light every pixel of hundreds of normals).
    col_trig: Vec<[f64; 2]>,
    row_trig: Vec<[f64; 2]>,
    /// The rule of [`Self::cap_measure_profile`], built on first use: a bake
    /// builds a lit map per normal and never asks most of them for a profile.
    profile_rule: OnceLock<Vec<(DVec3, f64)>>,
    /// The blocks of [`Self::irradiances`], built on first use: only the maps
    /// whose irradiance is asked for (a bake's weight table, a render's light).
    irradiance_blocks: OnceLock<irradiance::IrradianceBlocks>,
    negative: NegativePixels,
}

/// `img` with its negative pixels set to 0, and their count, once it is checked to
/// hold at least one pixel, as many values as pixels, all finite.
fn cleaned(
    mut img: LuminanceImage,
    name: &str,
) -> Result<(LuminanceImage, NegativePixels), DirectionSpecError> {
    let negative = img.clamp_negatives();
    let (w, h) = (img.width, img.height);
    if w == 0 || h == 0 || img.values.len() != w * h {
        return Err(DirectionSpecError::BadImage {
            path: name.to_string(),
            reason: format!("{w}x{h} pixels with {} values", img.values.len()),
        });
    }
    if let Some(k) = img.values.iter().position(|v| !v.is_finite()) {
        return Err(DirectionSpecError::BadPixel {
            path: name.to_string(),
            col: k % w,
            row: k / w,
            value: img.values[k],
        });
    }
    Ok((img, negative))
}

/// What is wrong with the shape of the map at `path` if its pixels are not twice
/// as wide as tall: an equirectangular map spans 360° of longitude across and 180°
/// of latitude down, so a map of any other shape (a square mirror ball, a cube
/// cross, a cropped panorama) is read stretched. `None` for a 2:1 map, or one
/// whose size cannot be read (loading it then says why).
pub fn shape_warning(path: &Path) -> Option<String> {
    let (w, h) = crate::density::image::image_size(path)?;
    (w != 2 * h).then(|| {
        format!(
            "{} is {w} x {h} pixels, not 2:1: it is read as an equirectangular map (longitude across, latitude down) and stretched",
            path.display()
        )
    })
}

/// `[cos phi, sin phi]` at the centre of each of `w` columns.
fn column_centres(w: usize) -> Vec<[f64; 2]> {
    (0..w)
        .map(|c| {
            let phi = TAU * (c as f64 + 0.5) / w as f64;
            [phi.cos(), phi.sin()]
        })
        .collect()
}

/// `[z, sqrt(1 - z^2)]` at the middle of each row's `z` range `(lo, hi)`.
fn row_centres(ranges: impl Iterator<Item = (f64, f64)>) -> Vec<[f64; 2]> {
    ranges
        .map(|(lo, hi)| {
            let z = 0.5 * (lo + hi);
            [z, (1.0 - z * z).max(0.0).sqrt()]
        })
        .collect()
}

/// `z = cos(pi r / H)` written as `sin(pi (H - 2r) / (2H))`, exact 0 at the equator.
fn z_edge(r: usize, h: usize) -> f64 {
    (PI * (h as f64 - 2.0 * r as f64) / (2.0 * h as f64)).sin()
}

impl EnvmapDensity {
    /// Loads `path` (PNG/JPEG/HDR/EXR, Rec.709 luminance) for `domain`.
    pub fn from_file(path: impl AsRef<Path>, domain: Domain) -> Result<Self, DirectionSpecError> {
        let img = load_luminance(path.as_ref())?;
        Self::from_luminance(&img, domain, &path.as_ref().display().to_string())
    }

    /// Builds the density from decoded luminance (`name` is the SPEC's path).
    /// Negative pixels are set to 0 and counted ([`EnvmapDensity::negative_pixels`]);
    /// a NaN or infinite pixel, or a map without positive mass on `domain`, is an
    /// error.
    pub fn from_luminance(
        img: &LuminanceImage,
        domain: Domain,
        name: &str,
    ) -> Result<Self, DirectionSpecError> {
        Self::from_owned_luminance(img.clone(), domain, name)
    }

    /// [`Self::from_luminance`] of an image the caller gives up (no copy is made
    /// to clean it: a bake builds a lit map for every pool normal).
    pub(super) fn from_owned_luminance(
        img: LuminanceImage,
        domain: Domain,
        name: &str,
    ) -> Result<Self, DirectionSpecError> {
        let (img, negative) = cleaned(img, name)?;
        Self::from_cleaned(&img, negative, domain, name)
    }

    /// The density of a map that [`cleaned`] returned (with the count of the
    /// negative pixels it set to 0).
    fn from_cleaned(
        img: &LuminanceImage,
        negative: NegativePixels,
        domain: Domain,
        name: &str,
    ) -> Result<Self, DirectionSpecError> {
        let (w, h) = (img.width, img.height);
        let hemi = domain == Domain::Hemisphere;
        let clip = |z: f64| if hemi { z.max(0.0) } else { z };
        let z_hi: Vec<f64> = (0..h).map(|r| clip(z_edge(r, h))).collect();
        let z_lo: Vec<f64> = (0..h).map(|r| clip(z_edge(r + 1, h))).collect();
        let dphi = TAU / w as f64;
        let mut mass: Vec<f64> = img
            .values
            .iter()
            .enumerate()
            .map(|(k, v)| v * dphi * (z_hi[k / w] - z_lo[k / w]).max(0.0))
            .collect();
        let total: f64 = mass.iter().sum();
        let what = format!("envmap:{name}");
        if !total.is_finite() {
            return Err(DirectionSpecError::NonFiniteMass { what });
        }
        if total <= 0.0 {
            return Err(DirectionSpecError::ZeroMass {
                what,
                domain: domain.name(),
            });
        }
        mass.iter_mut().for_each(|m| *m /= total);
        let mut col_cum = Vec::with_capacity(h * (w + 1));
        let mut row_cdf = Vec::with_capacity(h + 1);
        row_cdf.push(0.0);
        for r in 0..h {
            let mut s = 0.0;
            col_cum.push(0.0);
            for c in 0..w {
                s += mass[r * w + c];
                col_cum.push(s);
            }
            row_cdf.push(row_cdf[r] + s);
        }
        let bright_cols: Vec<Vec<usize>> = mass
            .chunks_exact(w)
            .map(|row| {
                let mean = row.iter().sum::<f64>() / w as f64;
                let floor = (BRIGHT_PIXEL * mean).max(BRIGHT_MASS);
                (0..w).filter(|&c| row[c] > floor).collect()
            })
            .collect();
        let col_trig = column_centres(w);
        let row_trig = row_centres((0..h).map(|r| (z_lo[r], z_hi[r])));
        Ok(Self {
            name: name.to_string(),
            width: w,
            height: h,
            domain,
            z_lo,
            z_hi,
            mass,
            integral: total,
            col_cum,
            row_cdf,
            bright_cols,
            col_trig,
            row_trig,
            profile_rule: OnceLock::new(),
            irradiance_blocks: OnceLock::new(),
            negative,
        })
    }

    /// Loads `path` like [`Self::from_file`], as [`Self::from_luminance_filtered`].
    pub fn from_file_filtered(
        path: impl AsRef<Path>,
        domain: Domain,
    ) -> Result<Self, DirectionSpecError> {
        let img = load_luminance(path.as_ref())?;
        Self::from_luminance_filtered(&img, domain, &path.as_ref().display().to_string())
    }

    /// The density of the map's *bilinearly filtered* luminance (the target of
    /// `bake --envmap` and the light of `render`, [`FilteredLuminance`]),
    /// tabulated on half pixels with every half pixel's exact mass: a
    /// `2W x 2H` piecewise-constant density whose [`Self::width`] and
    /// [`Self::height`] are those of the half-pixel grid. Errors and negative
    /// pixels as [`Self::from_luminance`], counted on the map itself.
    pub fn from_luminance_filtered(
        img: &LuminanceImage,
        domain: Domain,
        name: &str,
    ) -> Result<Self, DirectionSpecError> {
        let (img, negative) = cleaned(img.clone(), name)?;
        let fine = FilteredLuminance::new(&img).half_pixel_averages();
        Self::from_cleaned(&fine, negative, domain, name)
    }

    /// `∫ L(w) dw` over the domain (luminance times steradians, negative pixels as
    /// 0): `Σ L_p Ω_p` over the pixels, `Ω_p = (2 pi / W) (z_hi - z_lo)`, the factor
    /// that normalizes the map into this density.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The luminance of a region of solid angle `omega` (steradians) that holds
    /// `mass` of this density: `mass integral / omega`, 0 for a region of no
    /// solid angle (rows cut off by the hemisphere's horizon).
    fn luminance_of(&self, mass: f64, omega: f64) -> f64 {
        if omega > 0.0 {
            mass * self.integral / omega
        } else {
            0.0
        }
    }

    /// The negative pixels that were set to 0 when the map was loaded.
    pub fn negative_pixels(&self) -> NegativePixels {
        self.negative
    }

    /// Map width (columns, along `phi`).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Map height (rows, along `theta`).
    pub fn height(&self) -> usize {
        self.height
    }

    /// Mass of pixel `(col, row)` (masses sum to 1).
    pub fn pixel_mass(&self, col: usize, row: usize) -> f64 {
        self.mass[row * self.width + col]
    }

    /// `z` range `[lo, hi]` of row `row` on this domain.
    pub fn row_z_range(&self, row: usize) -> (f64, f64) {
        (self.z_lo[row], self.z_hi[row])
    }

    /// The direction at `f` in `[0,1]^2` of pixel `(c, r)`, uniform in `z = cos
    /// theta` and `phi` within the pixel: `phi = 2 pi (c + f.x) / W`, `z` from the
    /// row's top (`f.y = 0`) to its bottom (`f.y = 1`). A uniform `f` gives a
    /// direction uniform in the pixel's solid angle.
    pub fn pixel_direction(&self, c: usize, r: usize, f: DVec2) -> DVec3 {
        let z = self.z_hi[r] - f.y * (self.z_hi[r] - self.z_lo[r]);
        let phi = TAU * (c as f64 + f.x) / self.width as f64;
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }

    /// Direction of the centre of pixel `(c, r)`.
    #[inline]
    fn pixel_center(&self, c: usize, r: usize) -> DVec3 {
        let [z, s] = self.row_trig[r];
        let [cos_phi, sin_phi] = self.col_trig[c];
        DVec3::new(s * cos_phi, s * sin_phi, z)
    }
}

/// Index `i` with `cum[i] <= v < cum[i+1]` among bins of positive mass, and the
/// remainder `(v - cum[i]) / (cum[i+1] - cum[i])` in `[0, 1)`.
fn pick(cum: &[f64], v: f64) -> (usize, f64) {
    let n = cum.len() - 1;
    let mut i = cum[1..].partition_point(|&c| c <= v).min(n - 1);
    while i > 0 && cum[i + 1] <= cum[i] {
        i -= 1;
    }
    while i + 1 < n && cum[i + 1] <= cum[i] {
        i += 1;
    }
    let m = cum[i + 1] - cum[i];
    let rem = if m > 0.0 { (v - cum[i]) / m } else { 0.5 };
    (i, rem.clamp(0.0, 1.0 - f64::EPSILON / 2.0))
}

impl DirectionDensity for EnvmapDensity {
    fn spec(&self) -> String {
        format!("envmap:{}", self.name)
    }

    fn domain(&self) -> Domain {
        self.domain
    }

    fn pdf(&self, w: DVec3) -> f64 {
        let w = unit_or_z(w);
        if self.domain == Domain::Hemisphere && w.z < 0.0 {
            return 0.0;
        }
        let p = pixel_coords(w, self.width, self.height);
        let r = (p.y as usize).min(self.height - 1);
        let c = (p.x as usize).min(self.width - 1);
        let dz = self.z_hi[r] - self.z_lo[r];
        if dz <= 0.0 {
            return 0.0;
        }
        self.mass[r * self.width + c] / (TAU / self.width as f64 * dz)
    }

    /// Marginal-conditional inverse CDF (module docs); exact.
    fn sample(&self, u: DVec2) -> DVec3 {
        let (r, ry) = pick(
            &self.row_cdf,
            u.y.clamp(0.0, 1.0) * self.row_cdf[self.height],
        );
        let base = r * (self.width + 1);
        let row = &self.col_cum[base..base + self.width + 1];
        let (c, rx) = pick(row, u.x.clamp(0.0, 1.0) * row[self.width]);
        self.pixel_direction(c, r, DVec2::new(rx, ry))
    }

    fn notes(&self) -> Vec<String> {
        self.negative.note(&self.spec()).into_iter().collect()
    }

    fn cap_measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        self.cap_measure_with(center, cos_theta, 1)
    }

    fn cap_measure_profile(&self, center: DVec3, cos_thetas: &[f64]) -> Vec<f64> {
        let rule = self
            .profile_rule
            .get_or_init(|| self.quadrature(PROFILE_POINTS));
        profile_of_rule(rule.iter().copied(), center, cos_thetas)
    }

    /// The mass-adaptive rule of [`EnvmapDensity::mass_rule`].
    fn quadrature(&self, k: usize) -> Vec<(DVec3, f64)> {
        self.mass_rule(k)
    }
}

/// A small sky (a bright spot above a gradient, 32 x 16 pixels) written as PNG
/// into `dir`, for tests that need a map file.
#[cfg(test)]
pub(crate) fn tiny_map(dir: &Path) -> std::path::PathBuf {
    test_support::grey_map(dir, "sky.png", [32, 16], |x, y| {
        if (x, y) == (5, 3) {
            255
        } else {
            (40 + 8 * (16 - y)) as u8
        }
    })
}
