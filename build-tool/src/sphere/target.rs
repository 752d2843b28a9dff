//! The [`DirectionDensity`] trait every direction target implements, the error its
//! constructors return, and the helpers the targets share (rule normalization, SPEC
//! number formatting).
//!
//! Every density is a probability density per unit solid angle, normalized over the
//! sphere (`∫ pdf dω = 1`; zero where the target has no mass). Each one offers:
//!
//! * [`DirectionDensity::sample`]: the *standard warp* a baseline uses to turn a
//!   point of `[0,1)^2` into a direction (equal-area map, Malley's method, GGX
//!   visible normals mixed with a cosine lobe, marginal-conditional inverse CDF),
//!   with its density [`DirectionDensity::sample_pdf`];
//! * [`DirectionDensity::sample_target`]: *exact* samples distributed by the target
//!   (for the BRDF, by rejection; elsewhere the warp itself is exact);
//! * [`DirectionDensity::cap_measure`]: `mu(C(w, t))`, the target measure of a cap,
//!   closed form where one exists (uniform, cosine), otherwise computed from a
//!   precomputed table (see each type for its method, accuracy and cost);
//! * [`DirectionDensity::quadrature`]: a weighted point rule for `mu`, used by the
//!   energy-distance metric ([`super::metrics::cap_l2_nonuniform`]).
//!
//! The SPEC parser that builds them is [`super::spec`].

use crate::density::{fmt_num, DensityError, SpecSyntaxError};
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use rand::{Rng, RngCore};

/// A probability density of directions on the unit sphere.
pub trait DirectionDensity: Send + Sync {
    /// The canonical SPEC string (e.g. `brdf:0.5,30`).
    fn spec(&self) -> String;

    /// [`Domain::Sphere`] or [`Domain::Hemisphere`]: where the point sets live (the
    /// density itself is always defined on the whole sphere).
    fn domain(&self) -> Domain;

    /// Density per unit solid angle at the unit vector `w`, normalized so that
    /// `∫ pdf dω = 1` over the sphere; 0 where the target has no mass.
    fn pdf(&self, w: DVec3) -> f64;

    /// The standard warp of `u` in `[0,1)^2` to a direction that baselines use.
    /// For `uniform`, `cosine` and `envmap` it is distributed exactly by
    /// [`DirectionDensity::pdf`] when `u` is uniform; for `brdf` it is the usual
    /// importance-sampling mixture, *not* exact (see the `brdf:` target, [`super::BrdfTarget`]).
    fn sample(&self, u: DVec2) -> DVec3;

    /// Density per unit solid angle of [`DirectionDensity::sample`]'s directions
    /// when `u` is uniform in `[0,1)^2`: what an importance-sampling estimate over
    /// warped points divides by. The default is [`DirectionDensity::pdf`], right for
    /// every exact warp; `brdf` overrides it with its mixture's density.
    fn sample_pdf(&self, w: DVec3) -> f64 {
        self.pdf(w)
    }

    /// One direction distributed exactly by [`DirectionDensity::pdf`]. The default
    /// warps a uniform `u` with [`DirectionDensity::sample`] (exact for every
    /// density but `brdf`, which overrides it with rejection sampling).
    fn sample_target(&self, rng: &mut dyn RngCore) -> DVec3 {
        let u = DVec2::new(rng.random::<f64>(), rng.random::<f64>());
        self.sample(u)
    }

    /// Whether [`DirectionDensity::cap_measure`] is a cheap closed form. Targets
    /// without one (tabulated: `brdf`, `envmap`) are served from a
    /// [`super::CapMeasureTable`] by optimizers and estimators that need many caps.
    fn has_closed_form_caps(&self) -> bool {
        false
    }

    /// Lines a user should read about how the target was built from its input
    /// (e.g. negative pixels of a map set to 0); empty by default. The CLI prints
    /// each on stderr and records them in reports.
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }

    /// Target measure `mu(C)` of the cap `C = {x : <center, x> >= cos_theta}`;
    /// `center` is normalized here, `cos_theta` is clamped into `[-1, 1]`.
    fn cap_measure(&self, center: DVec3, cos_theta: f64) -> f64;

    /// [`DirectionDensity::cap_measure`] of the caps `C(center, t)` for every `t`
    /// in `cos_thetas` (same order). Tabulated densities override this with a
    /// one-pass computation that may be coarser than `cap_measure` (documented per
    /// type); the default calls `cap_measure` for each.
    fn cap_measure_profile(&self, center: DVec3, cos_thetas: &[f64]) -> Vec<f64> {
        cos_thetas
            .iter()
            .map(|&t| self.cap_measure(center, t))
            .collect()
    }

    /// A quadrature rule for the target measure: about `k` directions with
    /// non-negative weights summing to 1, so that `∫ g dmu ≈ sum_i w_i g(y_i)` for
    /// smooth `g`. The default is the midpoint rule on an `m x m` grid
    /// (`m = round(sqrt k)`) of the domain's equal-area map, weight
    /// `pdf(centre) * cell solid angle`, renormalized; cells of zero weight are left
    /// out.
    fn quadrature(&self, k: usize) -> Vec<(DVec3, f64)> {
        let m = ((k as f64).sqrt().round() as usize).max(1);
        let domain = self.domain();
        let mut rule: Vec<(DVec3, f64)> = (0..m * m)
            .filter_map(|i| {
                let p = DVec2::new(
                    ((i % m) as f64 + 0.5) / m as f64,
                    ((i / m) as f64 + 0.5) / m as f64,
                );
                let d = domain.to_direction(p);
                let w = self.pdf(d);
                (w > 0.0).then_some((d, w))
            })
            .collect();
        normalize_rule(&mut rule);
        rule
    }
}

/// Scales the weights of `rule` to sum to 1 (no-op for an all-zero rule).
pub(crate) fn normalize_rule(rule: &mut [(DVec3, f64)]) {
    let total: f64 = rule.iter().map(|p| p.1).sum();
    if total > 0.0 {
        rule.iter_mut().for_each(|p| p.1 /= total);
    }
}

/// Why a direction density could not be built. `Display` is one line naming the
/// problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DirectionSpecError {
    /// The SPEC does not follow the grammar.
    #[error(transparent)]
    Syntax(#[from] SpecSyntaxError),
    /// A parameter is outside its valid range (NaN and infinities included).
    #[error("direction density `{kind}`: parameter {param} = {value} is outside {range}")]
    OutOfRange {
        /// Density kind.
        kind: &'static str,
        /// Parameter name.
        param: &'static str,
        /// The value.
        value: f64,
        /// The valid range, e.g. `(0, 1]`.
        range: &'static str,
    },
    /// `envmap:` without a path.
    #[error("direction density `envmap` needs a file path (envmap:PATH), got an empty path")]
    EmptyPath,
    /// Direction densities need the sphere or the hemisphere domain.
    #[error("direction density `{spec}` needs the sphere or hemisphere domain, not the square")]
    SquareDomain {
        /// The SPEC.
        spec: String,
    },
    /// The environment map could not be read or decoded.
    #[error(transparent)]
    Image(#[from] DensityError),
    /// A pixel's luminance is NaN or infinite.
    #[error(
        "envmap `{path}`: pixel (col {col}, row {row}) has luminance {value} (must be finite)"
    )]
    BadPixel {
        /// The map's path (or name).
        path: String,
        /// Column.
        col: usize,
        /// Row.
        row: usize,
        /// The value.
        value: f64,
    },
    /// Dimensions are zero or do not match the number of values.
    #[error("envmap `{path}`: bad image: {reason}")]
    BadImage {
        /// The map's path (or name).
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// The target has no mass on the domain.
    #[error("direction density `{what}` has zero mass on the {domain}")]
    ZeroMass {
        /// The SPEC (or name).
        what: String,
        /// `sphere` or `hemisphere`.
        domain: &'static str,
    },
    /// The target's mass is not finite.
    #[error("direction density `{what}` has non-finite total mass")]
    NonFiniteMass {
        /// The SPEC (or name).
        what: String,
    },
}

/// Canonical number formatting for SPEC strings.
pub(crate) fn spec_num(v: f64) -> String {
    fmt_num(v)
}
