//! Target densities of directions (docs/targets.md sphere SPECs): `uniform`, `cosine`,
//! `brdf:ROUGHNESS,THETA_O_DEG` (glTF 2.0; `brdf-burley:` for Burley's BRDF) and
//! `envmap:PATH`, on the sphere or the upper hemisphere.
//!
//! Every density is a probability density per unit solid angle, normalized over the
//! sphere (`∫ pdf dω = 1`; zero where the target has no mass). Each one offers:
//!
//! * [`DirectionDensity::sample`]: the *standard warp* a baseline uses to turn a
//!   point of `[0,1)^2` into a direction (equal-area map, Malley's method, GGX
//!   visible normals mixed with a cosine lobe, marginal-conditional inverse CDF);
//! * [`DirectionDensity::sample_target`]: *exact* samples distributed by the target
//!   (for the BRDF, by rejection; elsewhere the warp itself is exact);
//! * [`DirectionDensity::cap_measure`]: `mu(C(w, t))`, the target measure of a cap,
//!   closed form where one exists (uniform, cosine), otherwise computed from a
//!   precomputed table (see each type for its method, accuracy and cost);
//! * [`DirectionDensity::quadrature`]: a weighted point rule for `mu`, used by the
//!   energy-distance metric ([`super::metrics::cap_l2_nonuniform`]).

use super::brdf_target::BrdfTarget;
use super::envmap::EnvmapDensity;
use super::geometry::{
    cosine_cap_measure, uniform_hemisphere_cap_measure, uniform_sphere_cap_measure,
};
use crate::density::{fmt_num, split_params, DensityError, ParamError};
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use nuld_core::brdf::BrdfModel;
use nuld_core::sphere::{square_to_hemisphere, square_to_sphere};
use rand::{Rng, RngCore};
use std::f64::consts::{FRAC_PI_4, PI};

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
    /// importance-sampling mixture, *not* exact (see [`BrdfTarget::sample`]).
    fn sample(&self, u: DVec2) -> DVec3;

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
        let hemi = self.domain() == Domain::Hemisphere;
        let mut rule: Vec<(DVec3, f64)> = (0..m * m)
            .filter_map(|i| {
                let p = DVec2::new(
                    ((i % m) as f64 + 0.5) / m as f64,
                    ((i / m) as f64 + 0.5) / m as f64,
                );
                let d = if hemi {
                    square_to_hemisphere(p)
                } else {
                    square_to_sphere(p)
                };
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
    /// The SPEC is empty or whitespace.
    #[error(
        "empty direction density spec (expected uniform, cosine, \
         brdf:ROUGHNESS,THETA_O_DEG or envmap:PATH)"
    )]
    EmptySpec,
    /// The kind before `:` is not a direction density.
    #[error(
        "unknown direction density spec kind `{kind}` (expected uniform, cosine, \
         brdf:ROUGHNESS,THETA_O_DEG, brdf-burley:ROUGHNESS,THETA_O_DEG or envmap:PATH)"
    )]
    UnknownKind {
        /// The kind as written.
        kind: String,
    },
    /// Wrong number of comma-separated parameters.
    #[error("direction density `{kind}` takes {expected} parameter(s) ({usage}), got {got}")]
    ParamCount {
        /// Density kind.
        kind: &'static str,
        /// Usage, e.g. `brdf:ROUGHNESS,THETA_O_DEG`.
        usage: &'static str,
        /// Parameters the kind takes.
        expected: usize,
        /// Parameters given.
        got: usize,
    },
    /// A parameter does not parse as a number.
    #[error("direction density `{kind}`: parameter {param} = `{text}` is not a number")]
    NotANumber {
        /// Density kind.
        kind: &'static str,
        /// Parameter name.
        param: &'static str,
        /// The text as written.
        text: String,
    },
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

/// The domain's name in messages.
pub(crate) fn domain_name(d: Domain) -> &'static str {
    if d == Domain::Hemisphere {
        "hemisphere"
    } else {
        "sphere"
    }
}

/// Parses a direction density SPEC (docs/targets.md) for `domain`
/// ([`Domain::Sphere`] or [`Domain::Hemisphere`]):
///
/// * `uniform` — uniform on the domain (on the hemisphere: over `z >= 0`);
/// * `cosine` — `∝ max(z, 0)` (the same on both domains);
/// * `brdf:ROUGHNESS,THETA_O_DEG` — `∝ f(wo, wi) max(n.wi, 0)` of the glTF 2.0 BRDF
///   ([`nuld_core::brdf`]) with `wo = view_direction(THETA_O_DEG)`;
///   ROUGHNESS in `[0.1, 1]`, THETA_O_DEG in `[0, 89]`;
/// * `brdf-burley:ROUGHNESS,THETA_O_DEG` — the same with Burley's 2012 BRDF
///   ([`BrdfModel::Burley`]), same ranges;
/// * `envmap:PATH` — equirectangular luminance map, `+z` up (everything after the
///   first `:` is the path). On the hemisphere domain the map is cut at the horizon.
///
/// The kind is matched exactly; whitespace around it and the numbers is ignored.
/// Building `brdf` costs a few tens of ms (normalizer and tables), `envmap` the
/// decode plus `O(W H)`.
pub fn parse_direction_spec(
    spec: &str,
    domain: Domain,
) -> Result<Box<dyn DirectionDensity>, DirectionSpecError> {
    let spec = spec.trim();
    if spec.is_empty() {
        return Err(DirectionSpecError::EmptySpec);
    }
    if domain == Domain::Square {
        return Err(DirectionSpecError::SquareDomain {
            spec: spec.to_string(),
        });
    }
    let (kind, rest) = match spec.split_once(':') {
        Some((k, r)) => (k.trim(), Some(r)),
        None => (spec, None),
    };
    let hemisphere = domain == Domain::Hemisphere;
    match kind {
        "uniform" => {
            params("uniform", "uniform", &[], rest)?;
            Ok(Box::new(UniformDirections { hemisphere }))
        }
        "cosine" => {
            params("cosine", "cosine", &[], rest)?;
            Ok(Box::new(CosineDirections { hemisphere }))
        }
        "brdf" => {
            let p = params(
                "brdf",
                "brdf:ROUGHNESS,THETA_O_DEG",
                &["ROUGHNESS", "THETA_O_DEG"],
                rest,
            )?;
            Ok(Box::new(BrdfTarget::new(p[0], p[1], domain)?))
        }
        "brdf-burley" => {
            let p = params(
                "brdf-burley",
                "brdf-burley:ROUGHNESS,THETA_O_DEG",
                &["ROUGHNESS", "THETA_O_DEG"],
                rest,
            )?;
            Ok(Box::new(BrdfTarget::with_model(
                BrdfModel::Burley,
                p[0],
                p[1],
                domain,
            )?))
        }
        "envmap" => {
            let path = rest.unwrap_or("");
            if path.trim().is_empty() {
                return Err(DirectionSpecError::EmptyPath);
            }
            Ok(Box::new(EnvmapDensity::from_file(path, domain)?))
        }
        other => Err(DirectionSpecError::UnknownKind {
            kind: other.to_string(),
        }),
    }
}

/// Parses the comma-separated numbers of `kind` (range checks are the caller's).
fn params(
    kind: &'static str,
    usage: &'static str,
    names: &[&'static str],
    text: Option<&str>,
) -> Result<Vec<f64>, DirectionSpecError> {
    split_params(names, text).map_err(|e| match e {
        ParamError::Count { expected, got } => DirectionSpecError::ParamCount {
            kind,
            usage,
            expected,
            got,
        },
        ParamError::NotANumber { param, text } => DirectionSpecError::NotANumber {
            kind,
            param,
            text: text.to_string(),
        },
    })
}

/// Canonical number formatting for SPEC strings.
pub(crate) fn spec_num(v: f64) -> String {
    fmt_num(v)
}

/// `uniform`: `1/(4 pi)` on the sphere, `1/(2 pi)` on `z >= 0` for the hemisphere.
/// Warp: the domain's equal-area map (exact). Cap measure: closed form
/// (`(1 - t)/2`, or the cap–hemisphere intersection area over `2 pi`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UniformDirections {
    /// Whether the target is the upper hemisphere (else the whole sphere).
    pub hemisphere: bool,
}

impl DirectionDensity for UniformDirections {
    fn has_closed_form_caps(&self) -> bool {
        true
    }

    fn spec(&self) -> String {
        "uniform".to_string()
    }

    fn domain(&self) -> Domain {
        if self.hemisphere {
            Domain::Hemisphere
        } else {
            Domain::Sphere
        }
    }

    fn pdf(&self, w: DVec3) -> f64 {
        if !self.hemisphere {
            1.0 / (4.0 * PI)
        } else if w.z >= 0.0 {
            1.0 / (2.0 * PI)
        } else {
            0.0
        }
    }

    fn sample(&self, u: DVec2) -> DVec3 {
        if self.hemisphere {
            square_to_hemisphere(u)
        } else {
            square_to_sphere(u)
        }
    }

    fn cap_measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        if self.hemisphere {
            uniform_hemisphere_cap_measure(center, cos_theta)
        } else {
            uniform_sphere_cap_measure(cos_theta)
        }
    }
}

/// `cosine`: `max(z, 0) / pi` (on both domains). Warp: Malley's method (Shirley–Chiu
/// concentric disk lifted to `z = sqrt(1 - r^2)`; exact). Cap measure: closed form
/// ([`super::geometry::cosine_cap_measure`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CosineDirections {
    /// Whether the point sets live on the hemisphere domain (the density is the same).
    pub hemisphere: bool,
}

impl DirectionDensity for CosineDirections {
    fn has_closed_form_caps(&self) -> bool {
        true
    }

    fn spec(&self) -> String {
        "cosine".to_string()
    }

    fn domain(&self) -> Domain {
        if self.hemisphere {
            Domain::Hemisphere
        } else {
            Domain::Sphere
        }
    }

    fn pdf(&self, w: DVec3) -> f64 {
        w.z.max(0.0) / PI
    }

    fn sample(&self, u: DVec2) -> DVec3 {
        malley(u)
    }

    fn cap_measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        cosine_cap_measure(center, cos_theta)
    }
}

/// Shirley–Chiu concentric map of `[0,1]^2` onto the unit disk (area preserving up to
/// the factor `pi`).
pub(crate) fn concentric_disk(u: DVec2) -> DVec2 {
    let o = 2.0 * u - DVec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return DVec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (o.x / o.y))
    };
    r * DVec2::new(theta.cos(), theta.sin())
}

/// Malley's method: cosine-distributed directions about `+z` (density `z / pi`).
pub(crate) fn malley(u: DVec2) -> DVec3 {
    let d = concentric_disk(u);
    DVec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeding::rng;
    use crate::sphere::geometry::random_direction;

    #[test]
    fn specs_parse_and_errors_are_one_line() {
        for (s, d) in [
            ("uniform", Domain::Sphere),
            (" cosine ", Domain::Hemisphere),
            ("brdf:0.5, 30", Domain::Hemisphere),
            ("brdf-burley:0.5,30", Domain::Hemisphere),
        ] {
            let den = parse_direction_spec(s, d).unwrap();
            assert_eq!(den.domain(), d);
            assert!(!den.spec().contains(' '));
        }
        assert_eq!(
            parse_direction_spec("brdf:0.5,30", Domain::Hemisphere)
                .unwrap()
                .spec(),
            "brdf:0.5,30"
        );
        assert_eq!(
            parse_direction_spec("brdf-burley:0.1,89", Domain::Sphere)
                .unwrap()
                .spec(),
            "brdf-burley:0.1,89"
        );
        let bad = [
            ("", "empty"),
            (
                "gaussian:1,2,3",
                "unknown direction density spec kind `gaussian`",
            ),
            ("uniform:3", "takes 0 parameter"),
            (
                "brdf:0.5",
                "takes 2 parameter(s) (brdf:ROUGHNESS,THETA_O_DEG), got 1",
            ),
            ("brdf:x,30", "ROUGHNESS = `x` is not a number"),
            ("brdf:0.09,30", "ROUGHNESS = 0.09 is outside [0.1, 1]"),
            ("brdf:1.5,30", "ROUGHNESS = 1.5 is outside"),
            ("brdf:nan,30", "ROUGHNESS = NaN is outside"),
            ("brdf:0.5,89.5", "THETA_O_DEG = 89.5 is outside [0, 89]"),
            (
                "brdf-burley:0.05,30",
                "`brdf-burley`: parameter ROUGHNESS = 0.05",
            ),
            (
                "brdf-burley:1",
                "takes 2 parameter(s) (brdf-burley:ROUGHNESS,THETA_O_DEG)",
            ),
            ("brdf:0.5,-1", "THETA_O_DEG = -1 is outside"),
            ("envmap:", "needs a file path"),
            ("envmap:/nonexistent/x.hdr", "not found"),
        ];
        for (s, want) in bad {
            let e = parse_direction_spec(s, Domain::Sphere)
                .err()
                .unwrap()
                .to_string();
            assert!(e.contains(want), "{s}: {e}");
            assert!(!e.contains('\n'));
        }
        let e = parse_direction_spec("uniform", Domain::Square)
            .err()
            .unwrap();
        assert!(e.to_string().contains("not the square"));
        // An undecodable file.
        let dir = std::env::temp_dir().join(format!("nuld-sphere-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("junk.hdr");
        std::fs::write(&f, b"this is not an image").unwrap();
        let e = parse_direction_spec(&format!("envmap:{}", f.display()), Domain::Sphere)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("cannot decode"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    /// `∫ pdf dω` by the midpoint rule on the sphere map.
    fn total_mass(d: &dyn DirectionDensity, m: usize) -> f64 {
        let mut s = 0.0;
        for i in 0..m * m {
            let p = DVec2::new(
                ((i % m) as f64 + 0.5) / m as f64,
                ((i / m) as f64 + 0.5) / m as f64,
            );
            s += d.pdf(square_to_sphere(p));
        }
        s * 4.0 * PI / (m * m) as f64
    }

    #[test]
    fn uniform_and_cosine_are_normalized_and_warps_follow_the_cap_measure() {
        let dens: [Box<dyn DirectionDensity>; 3] = [
            Box::new(UniformDirections { hemisphere: false }),
            Box::new(UniformDirections { hemisphere: true }),
            Box::new(CosineDirections { hemisphere: true }),
        ];
        let mut r = rng(17, 0);
        for d in &dens {
            assert!(
                (total_mass(d.as_ref(), 511) - 1.0).abs() < 1e-4,
                "{}: {}",
                d.spec(),
                total_mass(d.as_ref(), 511)
            );
            // Fraction of warped uniform samples in caps vs closed-form cap measure,
            // within 3 standard errors (binomial).
            let n = 100_000;
            let pts: Vec<DVec3> = (0..n).map(|_| d.sample_target(&mut r)).collect();
            for _ in 0..12 {
                let c = random_direction(&mut r);
                let t = 1.0 - 2.0 * r.random::<f64>();
                let mu = d.cap_measure(c, t);
                let f = pts.iter().filter(|p| c.dot(**p) >= t).count() as f64 / n as f64;
                let se = (mu * (1.0 - mu) / n as f64).sqrt().max(1e-6);
                assert!((f - mu).abs() < 3.5 * se, "{}: {f} vs {mu}", d.spec());
            }
            // The default quadrature sums to 1 and integrates z like the target.
            let q = d.quadrature(4096);
            let sum: f64 = q.iter().map(|p| p.1).sum();
            assert!((sum - 1.0).abs() < 1e-12);
        }
        // E[z] over the cosine target: ∫ z^2 / pi dω = 2/3.
        let q = CosineDirections { hemisphere: true }.quadrature(16384);
        let ez: f64 = q.iter().map(|(d, w)| d.z * w).sum();
        assert!((ez - 2.0 / 3.0).abs() < 1e-4, "{ez}");
    }
}
