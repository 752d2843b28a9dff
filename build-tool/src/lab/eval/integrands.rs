//! The integrands of the paper's Fig. 7 (§5, "Numerical Integration Tests"), each
//! with the target density its samples follow and its exact or reference value.
//!
//! Every estimate is the importance-sampling mean `(1/N) sum_i f(x_i) / p(x_i)`,
//! where `p` is the density the method's points follow: the *target* for ours, SOT
//! and GBN (they are optimized towards it), the *warp's* density for warped
//! baselines. All warps here are exact (so `p = q`) except the BRDF's standard
//! sampler (GGX visible normals mixed with a cosine lobe, [`BrdfTarget::sample`]),
//! whose mixture density [`DirectionDensity::sample_pdf`] is used for it. Terms with
//! `f = 0` count 0 even where `p = 0` (points outside the target's support).
//!
//! 2D (domain `[0,1]^2`, Lebesgue measure):
//! * `quarter-disc`: `f = 1[x^2 + y^2 < 2/pi]`, uniform samples; `I = 1/2`.
//! * `step-gaussian`: `f = 1[x < 1/pi] exp(-x^2 - y^2)`, samples of the Gaussian
//!   factor `q ∝ exp(-x^2 - y^2)` on the square (`gaussian:0,0,1/sqrt 2`);
//!   `I = (sqrt(pi)/2)^2 erf(1/pi) erf(1)`.
//! * `disc-bilinear`: `f = 1[x^2 + y^2 < 2/pi] x y`, samples of the quarter disc;
//!   `I = R^4 / 8 = 1 / (2 pi^2)` (`R^2 = 2/pi`).
//!
//! Directions (solid angle `dω`):
//! * `sphere-abs-z`: `f = |z| / (4 pi)`, uniform samples on the sphere; `I = 1/2`.
//! * `brdf-envmap`: `f = q_brdf(w) L(w)`, samples of the BRDF target
//!   `q_brdf ∝ f_r(wo, w) cos` (`brdf:0.3,45`, hemisphere), `L = 4 pi q_env` the
//!   environment map's radiance scaled to mean 1 over the sphere. Reference by
//!   quadrature ([`envmap_product_reference`]).
//! * `envmap-cosine`: `f = L(w) max(z, 0) / pi`, samples of the environment map
//!   (whole sphere); `I = 4 sum_pixels mass * mean_pixel max(z, 0)`, exact for the
//!   piecewise-constant map ([`envmap_cosine_reference`]).

use crate::density::special::erf;
use crate::density::{parse_spec, Density2D};
use crate::sphere::{BrdfTarget, DirectionDensity, EnvmapDensity, UniformDirections};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// `x^2 + y^2 < 2/pi`: the quarter disc of area 1/2.
fn in_quarter_disc(p: DVec2) -> bool {
    p.x >= 0.0 && p.y >= 0.0 && p.x * p.x + p.y * p.y < 2.0 / PI
}

/// The Gaussian factor's SPEC: `exp(-x^2 - y^2) = exp(-|p|^2 / (2 sigma^2))` with
/// `sigma = 1/sqrt 2`.
pub const STEP_GAUSSIAN_TARGET: &str = "gaussian:0,0,0.7071067811865476";

/// A 2D integrand of Fig. 7 with the density its samples follow.
pub struct SquareIntegrand {
    /// Short name (file names, CSV `target` column).
    pub name: &'static str,
    /// Formula, for titles and the JSON report.
    pub formula: &'static str,
    /// The sampled target density.
    pub density: Box<dyn Density2D>,
    /// The integrand.
    pub f: fn(DVec2) -> f64,
    /// `∫ f` over the square (closed form).
    pub reference: f64,
}

impl SquareIntegrand {
    /// `1[x^2 + y^2 < 2/pi]`, uniform samples, `I = 1/2`.
    pub fn quarter_disc() -> Self {
        Self {
            name: "quarter-disc",
            formula: "f = 1[x^2+y^2 < 2/pi], uniform samples",
            density: parse_spec("uniform").expect("uniform"),
            f: |p| f64::from(u8::from(in_quarter_disc(p))),
            reference: 0.5,
        }
    }

    /// `1[x < 1/pi] exp(-x^2 - y^2)`, Gaussian-factor samples.
    pub fn step_gaussian() -> Self {
        let half_sqrt_pi = PI.sqrt() / 2.0;
        Self {
            name: "step-gaussian",
            formula: "f = 1[x < 1/pi] exp(-x^2-y^2), samples of q ∝ exp(-x^2-y^2)",
            density: parse_spec(STEP_GAUSSIAN_TARGET).expect("valid gaussian spec"),
            f: |p| {
                if p.x < 1.0 / PI {
                    (-p.x * p.x - p.y * p.y).exp()
                } else {
                    0.0
                }
            },
            reference: half_sqrt_pi * half_sqrt_pi * erf(1.0 / PI) * erf(1.0),
        }
    }

    /// `1[x^2 + y^2 < 2/pi] x y`, quarter-disc samples, `I = 1/(2 pi^2)`.
    pub fn disc_bilinear() -> Self {
        Self {
            name: "disc-bilinear",
            formula: "f = 1[x^2+y^2 < 2/pi] x y, samples of the quarter disc",
            density: parse_spec("quarter-disc").expect("quarter-disc"),
            f: |p| if in_quarter_disc(p) { p.x * p.y } else { 0.0 },
            reference: 1.0 / (2.0 * PI * PI),
        }
    }

    /// The three 2D integrands, in the paper's order.
    pub fn all() -> Vec<Self> {
        vec![
            Self::quarter_disc(),
            Self::step_gaussian(),
            Self::disc_bilinear(),
        ]
    }

    /// `(1/N) sum f(x_i) / q(x_i)` (the inverse-CDF warps are exact, so every
    /// method's points follow `q`).
    pub fn estimate(&self, points: &[DVec2]) -> f64 {
        let s: f64 = points
            .iter()
            .map(|&p| {
                let f = (self.f)(p);
                if f == 0.0 {
                    0.0
                } else {
                    f / self.density.pdf(p)
                }
            })
            .sum();
        s / points.len() as f64
    }
}

/// The directional integrands' kinds.
enum SphereKind {
    AbsZ(UniformDirections),
    BrdfEnvmap {
        brdf: Box<BrdfTarget>,
        env: Box<EnvmapDensity>,
    },
    EnvmapCosine(Box<EnvmapDensity>),
}

/// A directional integrand of Fig. 7 with the density its samples follow.
pub struct SphereIntegrand {
    /// Short name (file names, CSV `target` column).
    pub name: &'static str,
    /// Formula, for titles and the JSON report.
    pub formula: &'static str,
    kind: SphereKind,
}

impl SphereIntegrand {
    /// `|z|` on the uniform sphere, `I = 1/2`.
    pub fn abs_z() -> Self {
        Self {
            name: "sphere-abs-z",
            formula: "f = |z| (average over the sphere), uniform samples",
            kind: SphereKind::AbsZ(UniformDirections { hemisphere: false }),
        }
    }

    /// `q_brdf L`, sampled by the BRDF target `brdf` (hemisphere domain); `env` is
    /// the environment map on the sphere.
    pub fn brdf_envmap(brdf: BrdfTarget, env: EnvmapDensity) -> Self {
        Self {
            name: "brdf-envmap",
            formula: "f = q_brdf(w) L(w) (cosine-weighted BRDF x envmap radiance of mean 1), samples of the BRDF target",
            kind: SphereKind::BrdfEnvmap {
                brdf: Box::new(brdf),
                env: Box::new(env),
            },
        }
    }

    /// `L max(z, 0) / pi`, sampled by the environment map `env` (sphere domain).
    pub fn envmap_cosine(env: EnvmapDensity) -> Self {
        Self {
            name: "envmap-cosine",
            formula:
                "f = L(w) max(z,0)/pi (envmap radiance of mean 1 x cosine), samples of the envmap",
            kind: SphereKind::EnvmapCosine(Box::new(env)),
        }
    }

    /// The sampled target density.
    pub fn density(&self) -> &dyn DirectionDensity {
        match &self.kind {
            SphereKind::AbsZ(u) => u,
            SphereKind::BrdfEnvmap { brdf, .. } => brdf.as_ref(),
            SphereKind::EnvmapCosine(e) => e.as_ref(),
        }
    }

    /// The SPECs of the integrand's factors (`sampled` or `sampled x other`).
    pub fn factors(&self) -> String {
        match &self.kind {
            SphereKind::AbsZ(u) => u.spec(),
            SphereKind::BrdfEnvmap { brdf, env } => format!("{} x {}", brdf.spec(), env.spec()),
            SphereKind::EnvmapCosine(e) => format!("{} x cosine", e.spec()),
        }
    }

    /// `f(w) / q(w)` for points that follow the target `q`.
    fn ratio_target(&self, w: DVec3) -> f64 {
        match &self.kind {
            SphereKind::AbsZ(_) => w.z.abs(),
            SphereKind::BrdfEnvmap { env, .. } => 4.0 * PI * env.pdf(w),
            SphereKind::EnvmapCosine(_) => 4.0 * w.z.max(0.0),
        }
    }

    /// `f(w) / p(w)` for points of the target's standard warp with density `p`.
    fn ratio_warp(&self, w: DVec3) -> f64 {
        match &self.kind {
            SphereKind::BrdfEnvmap { brdf, env } => {
                let q = brdf.pdf(w);
                if q == 0.0 {
                    return 0.0;
                }
                q * 4.0 * PI * env.pdf(w) / brdf.sample_pdf(w)
            }
            _ => self.ratio_target(w),
        }
    }

    /// The estimate from `points`; `warped` says whether they come from the target's
    /// standard warp (else they follow the target itself).
    pub fn estimate(&self, points: &[DVec3], warped: bool) -> f64 {
        let s: f64 = points
            .iter()
            .map(|&w| {
                if warped {
                    self.ratio_warp(w)
                } else {
                    self.ratio_target(w)
                }
            })
            .sum();
        s / points.len() as f64
    }

    /// The exact or reference value of the integral; `subdivision` is the per-pixel
    /// midpoint grid of [`envmap_product_reference`] (used by `brdf-envmap` only).
    pub fn reference(&self, subdivision: usize) -> f64 {
        match &self.kind {
            SphereKind::AbsZ(_) => 0.5,
            SphereKind::BrdfEnvmap { brdf, env } => {
                envmap_product_reference(env, brdf.as_ref(), subdivision)
            }
            SphereKind::EnvmapCosine(env) => envmap_cosine_reference(env),
        }
    }

    /// Whether [`SphereIntegrand::reference`] is a quadrature (worth caching)
    /// rather than a closed form.
    pub fn reference_is_quadrature(&self) -> bool {
        matches!(self.kind, SphereKind::BrdfEnvmap { .. })
    }
}

/// `∫ q(w) L(w) dω` with `L = 4 pi q_env` (the map's radiance scaled to mean 1):
/// `L` is constant on each pixel, so the integral is
/// `4 pi sum_pixels mass_pixel * mean_pixel(q)`, with the mean of `q` over the
/// pixel by an `s x s` midpoint rule in `(z, phi)` (the pixel is a rectangle in
/// these equal-area coordinates). Rows in parallel, summed in order
/// (deterministic); `O(W H s^2)` evaluations of `q` over the pixels with mass.
pub fn envmap_product_reference(env: &EnvmapDensity, q: &dyn DirectionDensity, s: usize) -> f64 {
    let (w, h) = (env.width(), env.height());
    let s = s.max(1);
    let rows: Vec<f64> = (0..h)
        .into_par_iter()
        .map(|r| {
            let (zl, zh) = env.row_z_range(r);
            let mut row = 0.0;
            for c in 0..w {
                let m = env.pixel_mass(c, r);
                if m == 0.0 {
                    continue;
                }
                let mut acc = 0.0;
                for j in 0..s {
                    let z = zl + (zh - zl) * (j as f64 + 0.5) / s as f64;
                    let sz = (1.0 - z * z).max(0.0).sqrt();
                    for i in 0..s {
                        let phi = TAU * (c as f64 + (i as f64 + 0.5) / s as f64) / w as f64;
                        acc += q.pdf(DVec3::new(sz * phi.cos(), sz * phi.sin(), z));
                    }
                }
                row += m * acc / (s * s) as f64;
            }
            row
        })
        .collect();
    4.0 * PI * rows.iter().sum::<f64>()
}

/// `∫ L(w) max(z, 0) / pi dω = 4 sum_pixels mass * mean_pixel max(z, 0)`, exact
/// (within a pixel `z` is uniform on its range: the mean of `max(z, 0)` over
/// `[a, b]` is `(a + b)/2` if `a >= 0`, `b^2 / (2 (b - a))` if `a < 0 < b`, else 0).
pub fn envmap_cosine_reference(env: &EnvmapDensity) -> f64 {
    let mut total = 0.0;
    for r in 0..env.height() {
        let (a, b) = env.row_z_range(r);
        let mean = if a >= 0.0 {
            0.5 * (a + b)
        } else if b > 0.0 {
            b * b / (2.0 * (b - a))
        } else {
            0.0
        };
        let mass: f64 = (0..env.width()).map(|c| env.pixel_mass(c, r)).sum();
        total += mass * mean;
    }
    4.0 * total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::image::LuminanceImage;
    use crate::seeding::rng;
    use crate::sphere::CosineDirections;
    use nuld_core::blob::Domain;
    use rand::Rng;

    /// Midpoint rule on an `m x m` grid of the unit square.
    fn grid_integral(f: &dyn Fn(DVec2) -> f64, m: usize) -> f64 {
        let mut s = 0.0;
        for j in 0..m {
            for i in 0..m {
                s += f(DVec2::new(
                    (i as f64 + 0.5) / m as f64,
                    (j as f64 + 0.5) / m as f64,
                ));
            }
        }
        s / (m * m) as f64
    }

    #[test]
    fn square_references_match_closed_forms_and_quadrature() {
        let qd = SquareIntegrand::quarter_disc();
        assert_eq!(qd.reference, 0.5);
        let sg = SquareIntegrand::step_gaussian();
        // (sqrt(pi)/2)^2 erf(1/pi) erf(1), with erf(1/pi) = 0.3475...,
        // erf(1) = 0.8427007929497149.
        let closed = PI / 4.0 * erf(1.0 / PI) * 0.842_700_792_949_714_9;
        assert!((sg.reference - closed).abs() < 1e-12, "{}", sg.reference);
        let db = SquareIntegrand::disc_bilinear();
        let r2 = 2.0 / PI;
        assert!((db.reference - r2 * r2 / 8.0).abs() < 1e-15);
        for it in SquareIntegrand::all() {
            let q = grid_integral(&it.f, 2000);
            assert!(
                (q - it.reference).abs() < 2e-4,
                "{}: {q} vs {}",
                it.name,
                it.reference
            );
        }
        // The Gaussian target is exp(-x^2-y^2) normalized: f/q is constant on x < 1/pi.
        let a = (sg.f)(DVec2::new(0.1, 0.2)) / sg.density.pdf(DVec2::new(0.1, 0.2));
        let b = (sg.f)(DVec2::new(0.3, 0.9)) / sg.density.pdf(DVec2::new(0.3, 0.9));
        assert!((a - b).abs() < 1e-9 * a, "{a} {b}");
    }

    #[test]
    fn estimates_of_exact_samples_are_unbiased() {
        for it in SquareIntegrand::all() {
            let mut g = rng(11, 0);
            let reps: Vec<f64> = (0..200)
                .map(|_| {
                    let pts: Vec<DVec2> = (0..256)
                        .map(|_| it.density.inverse_cdf(DVec2::new(g.random(), g.random())))
                        .collect();
                    it.estimate(&pts)
                })
                .collect();
            let m = super::super::stats::mean(&reps);
            assert!(
                (m.value - it.reference).abs() < 4.0 * m.stderr + 1e-12,
                "{}: {} ± {} vs {}",
                it.name,
                m.value,
                m.stderr,
                it.reference
            );
        }
    }

    /// A small synthetic environment map with structure.
    fn env(domain: Domain) -> EnvmapDensity {
        let (w, h) = (32, 16);
        let values = (0..w * h)
            .map(|k| 0.2 + ((k % w) as f64 * 0.37).sin().abs() + (k / w) as f64 * 0.1)
            .collect();
        EnvmapDensity::from_luminance(
            &LuminanceImage {
                width: w,
                height: h,
                values,
            },
            domain,
            "test",
        )
        .unwrap()
    }

    #[test]
    fn envmap_references_agree_with_closed_forms() {
        let e = env(Domain::Sphere);
        // q uniform on the sphere: ∫ (1/4pi) 4 pi q_env = 1.
        let u = UniformDirections { hemisphere: false };
        assert!((envmap_product_reference(&e, &u, 3) - 1.0).abs() < 1e-12);
        // q = cosine: the midpoint rule is exact for the linear max(z,0) on rows
        // above the equator (a row boundary), so it matches the closed form.
        let c = CosineDirections { hemisphere: false };
        let a = envmap_product_reference(&e, &c, 4);
        let b = envmap_cosine_reference(&e);
        assert!((a - b).abs() < 1e-9, "{a} {b}");
        // A constant map: L = 1, so ∫ max(z,0)/pi = 1.
        let flat = EnvmapDensity::from_luminance(
            &LuminanceImage {
                width: 8,
                height: 6,
                values: vec![1.0; 48],
            },
            Domain::Sphere,
            "flat",
        )
        .unwrap();
        assert!((envmap_cosine_reference(&flat) - 1.0).abs() < 1e-12);
        // The estimator with exact envmap samples is unbiased for envmap-cosine.
        let it = SphereIntegrand::envmap_cosine(e);
        let reference = it.reference(1);
        let mut g = rng(5, 1);
        let reps: Vec<f64> = (0..200)
            .map(|_| {
                let pts: Vec<DVec3> = (0..256)
                    .map(|_| it.density().sample_target(&mut g))
                    .collect();
                it.estimate(&pts, false)
            })
            .collect();
        let m = super::super::stats::mean(&reps);
        assert!(
            (m.value - reference).abs() < 4.0 * m.stderr,
            "{} ± {} vs {reference}",
            m.value,
            m.stderr
        );
    }

    #[test]
    fn brdf_envmap_with_a_constant_map_integrates_the_brdf_target() {
        let brdf = BrdfTarget::new(0.3, 45.0, Domain::Hemisphere).unwrap();
        // With a constant map the brdf-envmap integral is ∫ q_brdf = 1 and the warp
        // estimate of it is unbiased.
        let flat = EnvmapDensity::from_luminance(
            &LuminanceImage {
                width: 64,
                height: 32,
                values: vec![1.0; 2048],
            },
            Domain::Sphere,
            "flat",
        )
        .unwrap();
        let it = SphereIntegrand::brdf_envmap(brdf, flat);
        assert!((it.reference(8) - 1.0).abs() < 2e-3, "{}", it.reference(8));
    }
}
