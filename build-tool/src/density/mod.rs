//! Target densities on the unit square (SPEC grammar: docs/targets.md).
//!
//! Every density is normalized to integrate to 1 over `[0,1]^2` and exposes its
//! pointwise value, its CDF (the measure of origin-anchored boxes), the measure of
//! any axis-aligned box, its marginal-then-conditional inverse CDF, and a
//! piecewise-constant tabulation used by the exact metrics.

use glam::{DMat2, DVec2};

pub mod bilinear;
pub mod gaussian;
pub mod image;
pub(crate) mod numeric;
pub mod quarter_disc;
pub mod spec_syntax;
pub mod special;
pub mod uniform;

#[cfg(test)]
mod check;

pub use bilinear::Bilinear;
pub use gaussian::{StepGaussian, TruncatedGaussian};
pub use image::TabulatedDensity;
pub use quarter_disc::QuarterDisc;
pub use spec_syntax::{SpecFamily, SpecSyntaxError};
pub use uniform::Uniform;

pub(crate) use spec_syntax::split_params;

/// Why a density could not be built (from a SPEC string, parameters, a file or a
/// grid). `Display` is a single line naming the problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DensityError {
    /// The SPEC does not follow the grammar.
    #[error(transparent)]
    Syntax(#[from] SpecSyntaxError),
    /// A parameter is NaN or infinite.
    #[error("density `{kind}`: parameter {param} = {value} is not finite")]
    NonFinite {
        /// Density kind.
        kind: &'static str,
        /// Parameter name.
        param: &'static str,
        /// The value.
        value: f64,
    },
    /// A parameter that must be `>= 0` is negative.
    #[error("density `{kind}`: parameter {param} = {value} is negative (must be >= 0)")]
    Negative {
        /// Density kind.
        kind: &'static str,
        /// Parameter name.
        param: &'static str,
        /// The value.
        value: f64,
    },
    /// A parameter that must be `> 0` is zero or negative.
    #[error("density `{kind}`: parameter {param} = {value} must be > 0")]
    NonPositive {
        /// Density kind.
        kind: &'static str,
        /// Parameter name.
        param: &'static str,
        /// The value.
        value: f64,
    },
    /// `image:` with nothing after the colon.
    #[error("density `image` needs a file path (image:PATH), got an empty path")]
    EmptyPath,
    /// The image file does not exist.
    #[error("image file `{path}` not found")]
    MissingFile {
        /// The path as given.
        path: String,
    },
    /// The image file exists but could not be read.
    #[error("cannot read image file `{path}`: {reason}")]
    Io {
        /// The path as given.
        path: String,
        /// The I/O error, on one line.
        reason: String,
    },
    /// The file could not be decoded as PNG, JPEG, Radiance HDR or OpenEXR.
    #[error("cannot decode image `{path}`: {reason}")]
    Undecodable {
        /// The path as given.
        path: String,
        /// The decoder's error, on one line.
        reason: String,
    },
    /// A pixel / grid value is NaN or infinite.
    #[error(
        "tabulated density `{what}`: value at pixel (col {col}, row {row}) is not finite ({value})"
    )]
    NonFinitePixel {
        /// The density's name (path or `grid:WxH`).
        what: String,
        /// Column (x index).
        col: usize,
        /// Row (y index).
        row: usize,
        /// The value.
        value: f64,
    },
    /// Grid dimensions are zero or do not match the number of values.
    #[error("tabulated density: bad grid: {reason}")]
    BadGrid {
        /// What is wrong.
        reason: String,
    },
    /// The density integrates to zero over the square (all values 0, underflow).
    #[error("density `{what}` has zero total mass")]
    ZeroMass {
        /// The density's SPEC (or name).
        what: String,
    },
    /// The density's total mass overflows / is not finite.
    #[error("density `{what}` has non-finite total mass")]
    NonFiniteMass {
        /// The density's SPEC (or name).
        what: String,
    },
}

/// Formats a parameter for a canonical SPEC: the shortest string that parses back
/// to the same `f64`, in plain notation for `1e-5 <= |v| < 1e16` (and 0), in
/// exponent notation otherwise (`1e-7`, `2.5e20`).
pub(crate) fn fmt_num(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) || !a.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Collapses a message onto one line (decoder errors may contain newlines).
pub(crate) fn one_line(s: impl std::fmt::Display) -> String {
    s.to_string()
        .split(['\n', '\r'])
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Parses the comma-separated numeric parameters of `kind` (all must be finite).
fn parse_params(
    kind: &'static str,
    usage: &'static str,
    names: &[&'static str],
    text: Option<&str>,
) -> Result<Vec<f64>, DensityError> {
    let values = split_params(SpecFamily::Square, kind, usage, names, text)?;
    for (&value, &param) in values.iter().zip(names) {
        if !value.is_finite() {
            return Err(DensityError::NonFinite { kind, param, value });
        }
    }
    Ok(values)
}

/// Parses a square-domain density SPEC (docs/targets.md):
///
/// * `uniform`
/// * `gaussian:MX,MY,SIGMA` — isotropic Gaussian, truncated to the square
///   (MX, MY finite, any value; SIGMA > 0)
/// * `bilinear:V00,V10,V01,V11` — corner values at (0,0),(1,0),(0,1),(1,1), all
///   finite, >= 0, not all 0
/// * `quarter-disc` — uniform on `x^2 + y^2 < 2/pi`
/// * `step-gaussian` — `∝ 1[x < 1/pi] exp(-x^2 - y^2)`
/// * `image:PATH` — Rec.709 luminance of a PNG/JPEG/HDR/EXR file (everything after
///   the first `:` is the path, so it may contain `:` and `,`)
///
/// The kind is matched exactly (lower case); whitespace around the kind and the
/// numbers is ignored. Every failure is a [`DensityError`] naming the problem.
pub fn parse_spec(spec: &str) -> Result<Box<dyn Density2D>, DensityError> {
    let spec = spec.trim();
    if spec.is_empty() {
        return Err(SpecSyntaxError::Empty {
            family: SpecFamily::Square,
        }
        .into());
    }
    let (kind, rest) = match spec.split_once(':') {
        Some((k, r)) => (k.trim(), Some(r)),
        None => (spec, None),
    };
    match kind {
        "uniform" => {
            parse_params("uniform", "uniform", &[], rest)?;
            Ok(Box::new(Uniform))
        }
        "gaussian" => {
            let p = parse_params(
                "gaussian",
                "gaussian:MX,MY,SIGMA",
                &["MX", "MY", "SIGMA"],
                rest,
            )?;
            Ok(Box::new(TruncatedGaussian::new(p[0], p[1], p[2])?))
        }
        "bilinear" => {
            let p = parse_params(
                "bilinear",
                "bilinear:V00,V10,V01,V11",
                &["V00", "V10", "V01", "V11"],
                rest,
            )?;
            Ok(Box::new(Bilinear::new([p[0], p[1], p[2], p[3]])?))
        }
        "quarter-disc" => {
            parse_params("quarter-disc", "quarter-disc", &[], rest)?;
            Ok(Box::new(QuarterDisc))
        }
        "step-gaussian" => {
            parse_params("step-gaussian", "step-gaussian", &[], rest)?;
            Ok(Box::new(StepGaussian::new()))
        }
        "image" => {
            let path = rest.unwrap_or("");
            if path.trim().is_empty() {
                return Err(DensityError::EmptyPath);
            }
            Ok(Box::new(TabulatedDensity::from_file(path)?))
        }
        other => Err(SpecSyntaxError::UnknownKind {
            family: SpecFamily::Square,
            kind: other.to_string(),
        }
        .into()),
    }
}

/// A cell-wise tabulation of a measure on `[0,1]^2`: `width x height` cells, cell
/// `(col, row)` covering `x in [col/width, (col+1)/width]`, `y in [row/height,
/// (row+1)/height]`; `mass[row * width + col]` is the measure of that cell. Masses
/// are non-negative and sum to 1.
#[derive(Clone, Debug, PartialEq)]
pub struct CellGrid {
    /// Number of columns (cells along x).
    pub width: usize,
    /// Number of rows (cells along y).
    pub height: usize,
    /// Row-major cell masses, summing to 1.
    pub mass: Vec<f64>,
}

/// A probability density on `[0,1]^2`.
pub trait Density2D: Send + Sync {
    /// The canonical SPEC string of this density (e.g. `gaussian:0.5,0.5,0.15`).
    fn spec(&self) -> String;

    /// Density `q(p)`, normalized so that `∫ q = 1` over `[0,1]^2`.
    fn pdf(&self, p: DVec2) -> f64;

    /// CDF `mu([0,p.x] x [0,p.y])`, for `p` in `[0,1]^2` (clamped outside).
    fn cdf(&self, p: DVec2) -> f64;

    /// Measure of the box `[lo, hi]` (inclusion–exclusion over [`Density2D::cdf`],
    /// clamped at 0 against rounding).
    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        let m = self.cdf(hi) - self.cdf(DVec2::new(lo.x, hi.y)) - self.cdf(DVec2::new(hi.x, lo.y))
            + self.cdf(lo);
        m.max(0.0)
    }

    /// Marginal-then-conditional inverse CDF `T(u)`: `x = F_X^-1(u.x)`, then
    /// `y = F_{Y|X=x}^-1(u.y)`. Maps uniform points on `[0,1]^2` to points
    /// distributed by `q`; never returns a point in a zero-density region.
    fn inverse_cdf(&self, u: DVec2) -> DVec2;

    /// Jacobian `dT/du` of [`Density2D::inverse_cdf`] (columns: d/du.x, d/du.y).
    /// Defaults to central differences.
    fn inverse_cdf_jacobian(&self, u: DVec2) -> DMat2 {
        let h = 1e-6;
        let dx = |d: DVec2| {
            let a = (u + d).clamp(DVec2::ZERO, DVec2::ONE);
            let b = (u - d).clamp(DVec2::ZERO, DVec2::ONE);
            (self.inverse_cdf(a) - self.inverse_cdf(b)) / (a - b).length().max(1e-300)
        };
        DMat2::from_cols(dx(DVec2::new(h, 0.0)), dx(DVec2::new(0.0, h)))
    }

    /// A piecewise-constant tabulation of the measure with exact cell masses.
    /// Tabulated (image) densities return their own grid and ignore `resolution`;
    /// others use a `resolution x resolution` grid of [`Density2D::measure`]s.
    fn cells(&self, resolution: usize) -> CellGrid {
        let n = resolution.max(1);
        let mut mass = Vec::with_capacity(n * n);
        for row in 0..n {
            for col in 0..n {
                let lo = DVec2::new(col as f64, row as f64) / n as f64;
                let hi = DVec2::new((col + 1) as f64, (row + 1) as f64) / n as f64;
                mass.push(self.measure(lo, hi));
            }
        }
        let total: f64 = mass.iter().sum();
        mass.iter_mut().for_each(|m| *m /= total);
        CellGrid {
            width: n,
            height: n,
            mass,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_valid_specs() {
        let cases = [
            ("uniform", "uniform"),
            ("  uniform  ", "uniform"),
            ("uniform:", "uniform"),
            ("gaussian:0.5,0.5,0.15", "gaussian:0.5,0.5,0.15"),
            ("gaussian: 0.25 , 0.75 ,1e-1", "gaussian:0.25,0.75,0.1"),
            ("gaussian:-2,3,0.5", "gaussian:-2,3,0.5"),
            ("gaussian:0.5,0.5,1e300", "gaussian:0.5,0.5,1e300"),
            ("gaussian:0.5,0.5,0.000001", "gaussian:0.5,0.5,1e-6"),
            ("bilinear:1,2,3,4", "bilinear:1,2,3,4"),
            ("bilinear:0,0,0,0.5", "bilinear:0,0,0,0.5"),
            ("quarter-disc", "quarter-disc"),
            ("step-gaussian", "step-gaussian"),
        ];
        for (text, canonical) in cases {
            let d = parse_spec(text).unwrap_or_else(|e| panic!("{text}: {e}"));
            assert_eq!(d.spec(), canonical);
            // The canonical form parses to the same density.
            let again = parse_spec(&d.spec()).unwrap();
            let p = DVec2::new(0.3, 0.2);
            assert_eq!(again.pdf(p), d.pdf(p));
            assert!((d.cdf(DVec2::ONE) - 1.0).abs() < 1e-12);
        }
        // image: through a temporary PNG (paths may contain ':' and ',').
        let dir = std::env::temp_dir().join(format!("nuld-spec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a:b,c.png");
        ::image::GrayImage::from_raw(2, 2, vec![0, 10, 20, 30])
            .unwrap()
            .save_with_format(&path, ::image::ImageFormat::Png)
            .unwrap();
        let spec = format!("image:{}", path.display());
        let d = parse_spec(&spec).unwrap();
        assert_eq!(d.spec(), spec);
        assert_eq!(d.pdf(DVec2::new(0.25, 0.25)), 0.0);
        assert!((d.pdf(DVec2::new(0.75, 0.75)) - 4.0 * 30.0 / 60.0).abs() < 1e-12);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn parse_bad_specs() {
        let dir = std::env::temp_dir().join(format!("nuld-spec-bad-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let junk = dir.join("junk.jpg");
        std::fs::write(&junk, "not a jpeg").unwrap();
        let junk_spec = format!("image:{}", junk.display());
        let cases: Vec<(&str, &str)> = vec![
            ("", "empty density spec"),
            ("   ", "empty density spec"),
            ("foo", "unknown density spec kind `foo`"),
            (
                "Gaussian:0.5,0.5,0.1",
                "unknown density spec kind `Gaussian`",
            ),
            (
                "gaussian",
                "takes 3 parameter(s) (gaussian:MX,MY,SIGMA), got 0",
            ),
            (
                "gaussian:0.5,0.5",
                "takes 3 parameter(s) (gaussian:MX,MY,SIGMA), got 2",
            ),
            ("gaussian:0.5,0.5,0.1,4", "got 4"),
            ("gaussian:a,0.5,0.1", "parameter MX = `a` is not a number"),
            ("gaussian:0.5,,0.1", "parameter MY = `` is not a number"),
            ("gaussian:nan,0.5,0.1", "parameter MX = NaN is not finite"),
            ("gaussian:0.5,inf,0.1", "parameter MY = inf is not finite"),
            ("gaussian:0.5,0.5,0", "parameter SIGMA = 0 must be > 0"),
            ("gaussian:0.5,0.5,-1", "parameter SIGMA = -1 must be > 0"),
            ("gaussian:0.5,0.5,1.7e308", "zero total mass"),
            ("bilinear:1,2,3", "takes 4 parameter(s)"),
            ("bilinear:1,-2,3,4", "parameter V10 = -2 is negative"),
            ("bilinear:0,0,0,0", "zero total mass"),
            ("bilinear:1,2,3,x", "parameter V11 = `x` is not a number"),
            ("uniform:1", "density `uniform` takes 0 parameter(s)"),
            (
                "quarter-disc:2",
                "density `quarter-disc` takes 0 parameter(s)",
            ),
            (
                "step-gaussian:1,2",
                "density `step-gaussian` takes 0 parameter(s)",
            ),
            ("image:", "needs a file path"),
            ("image:  ", "needs a file path"),
            (
                "image:/no/such/file.png",
                "image file `/no/such/file.png` not found",
            ),
            (&junk_spec, "cannot decode image"),
        ];
        for (text, needle) in cases {
            let err = match parse_spec(text) {
                Ok(d) => panic!("`{text}` parsed as {}", d.spec()),
                Err(e) => e.to_string(),
            };
            assert!(err.contains(needle), "`{text}`: `{err}` lacks `{needle}`");
            assert!(!err.contains('\n'), "`{text}`: multi-line error `{err}`");
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
