//! The point-set methods the figures compare, and how each one produces `n` points
//! for a target: ours (optimized, cached on disk), the uniform baselines (warped to
//! the target the standard way), SOT and GBN (run against the target, or against its
//! projection to the square for directions), and spherical Fibonacci.

use super::cache::Cache;
use super::EvalSettings;
use crate::baselines::{
    gaussian_blue_noise, sliced_optimal_transport, spherical_fibonacci, Baseline, HierarchicalWarp,
    GBN_DEFAULT_ITERATIONS, SOT_DEFAULT_ITERATIONS,
};
use crate::density::{Density2D, TabulatedDensity};
use crate::optimize::directions::{
    optimize_directions, optimize_directions_scheduled, CapSchedule, DirectionConfig,
};
use crate::optimize::{optimize, AreaOption, OptimizeConfig};
use crate::seeding::derive_seed;
use crate::sphere::{square_cell_masses, DirectionDensity};
use anyhow::Result;
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Base seed of the evaluation: realization `r` uses [`realization_seed`]`(r)`.
pub const EVAL_SEED: u64 = 0x5EED_E7A1;

/// The generator seed of realization `r` (the same for every method and every N,
/// so that at equal `r` our set starts from the scramble the Owen-Sobol baseline
/// would use after its own seed folding, and baselines at different N are
/// prefixes of one randomized sequence where the method is a sequence).
pub fn realization_seed(r: u64) -> u64 {
    derive_seed(EVAL_SEED, r)
}

/// A method of the comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Our optimized sets (paper §3): the 2D optimizer
    /// ([`crate::optimize::optimize`]) or the direction optimizer
    /// ([`crate::optimize::directions::optimize_directions`]), both started from
    /// warped Owen-scrambled Sobol points.
    Ours,
    /// A baseline generator of [`crate::baselines`].
    Baseline(Baseline),
    /// Spherical Fibonacci directions (deterministic; one realization).
    SphericalFibonacci,
}

impl Method {
    /// Kebab-case name used in files, CSV and legends (`ours`, the baseline's
    /// name, `spherical-fibonacci`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Ours => "ours",
            Method::Baseline(b) => b.name(),
            Method::SphericalFibonacci => "spherical-fibonacci",
        }
    }

    /// Whether every realization is the same set (only one is computed).
    pub fn is_deterministic(self) -> bool {
        self == Method::SphericalFibonacci
    }

    /// Realizations evaluated per N under `s`: one for a deterministic method,
    /// `s.realizations_ours` for ours, `s.realizations_baseline` otherwise.
    pub fn realizations(self, s: &EvalSettings) -> usize {
        if self.is_deterministic() {
            1
        } else if self == Method::Ours {
            s.realizations_ours
        } else {
            s.realizations_baseline
        }
    }

    /// Whether the points are optimized against the target itself (ours, SOT,
    /// GBN) rather than generated uniformly and warped.
    pub fn targets_density(self) -> bool {
        matches!(
            self,
            Method::Ours | Method::Baseline(Baseline::Sot) | Method::Baseline(Baseline::Gbn)
        )
    }

    /// One line saying how the method makes points for a non-uniform target.
    pub fn description(self, sphere: bool) -> String {
        match (self, sphere) {
            (Method::Ours, false) => {
                "ours: 2D optimizer (default settings but epochs), from inverse-CDF-warped Owen-Sobol".into()
            }
            (Method::Ours, true) => {
                "ours: direction optimizer (default settings but epochs), from Owen-Sobol warped by the target's standard sampler".into()
            }
            (Method::Baseline(b @ (Baseline::Sot | Baseline::Gbn)), false) => format!(
                "{b}: run against the target density ({} iterations)",
                iterations(b)
            ),
            (Method::Baseline(b @ (Baseline::Sot | Baseline::Gbn)), true) => format!(
                "{b}: run in the domain's equal-area square against the target's density projected to it (uniform: the uniform square), then mapped ({} iterations)",
                iterations(b)
            ),
            (Method::Baseline(b), false) => {
                format!("{b}: uniform points warped to the target (inverse CDF; hierarchical for images)")
            }
            (Method::Baseline(b), true) => {
                format!("{b}: uniform points warped by the target's standard sampler (uniform: equal-area map)")
            }
            (Method::SphericalFibonacci, _) => {
                "spherical-fibonacci: deterministic, one realization".into()
            }
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Iterations of SOT / GBN.
fn iterations(b: Baseline) -> usize {
    match b {
        Baseline::Sot => SOT_DEFAULT_ITERATIONS,
        Baseline::Gbn => GBN_DEFAULT_ITERATIONS,
        _ => 0,
    }
}

/// What part of a realization's fingerprint depends on the method (settings that
/// change its points).
pub fn method_fingerprint(method: Method, epochs: usize) -> String {
    match method {
        Method::Ours => format!("ours-epochs={epochs}"),
        Method::Baseline(b @ (Baseline::Sot | Baseline::Gbn)) => {
            format!("{b}-iterations={}", iterations(b))
        }
        m => m.name().to_string(),
    }
}

/// How baselines reach a 2D target.
pub enum SquareWarp {
    /// No warp (the uniform target).
    Identity,
    /// Marginal-then-conditional inverse CDF.
    InverseCdf,
    /// Clarberg et al. 2005 hierarchical warping over the image's pixel grid.
    Hierarchical(Box<HierarchicalWarp>),
}

/// A 2D target as methods see it.
pub struct SquareSampler<'a> {
    /// The target density.
    pub density: &'a dyn Density2D,
    /// The baselines' warp.
    pub warp: SquareWarp,
    /// Epochs of our optimizer.
    pub epochs: usize,
    /// Point cache (our sets are cached by target SPEC and settings).
    pub cache: &'a Cache,
}

/// Our cached sets of a target: the cache group and fingerprint.
fn ours_group(domain: &str, spec: &str) -> String {
    // Paths make long, unreadable names: keep the file name only (the fingerprint
    // holds the full SPEC).
    let short = match spec.split_once(':') {
        Some((kind @ ("image" | "envmap"), path)) => {
            let file = std::path::Path::new(path)
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            format!("{kind}-{file}")
        }
        _ => spec.to_string(),
    };
    format!("ours-{domain}-{short}")
}

impl SquareSampler<'_> {
    /// `n` points of `method` for realization seed `seed`.
    pub fn points(&self, method: Method, n: usize, seed: u64) -> Result<Vec<DVec2>> {
        let uniform = self.density.spec() == "uniform";
        Ok(match method {
            Method::Ours => {
                let spec = self.density.spec();
                let group = ours_group(Domain::Square.name(), &spec);
                let fp = format!("v1;{spec};{}", method_fingerprint(method, self.epochs));
                if let Some(p) = self.cache.get_points(&group, n, seed, &fp) {
                    return Ok(p);
                }
                let cfg = OptimizeConfig {
                    epochs: self.epochs,
                    seed,
                    ..OptimizeConfig::default()
                };
                let p = optimize(self.density, n, &cfg, &mut |_| {});
                self.cache.put_points(&group, seed, &fp, &p)?;
                p
            }
            Method::Baseline(Baseline::Sot) if !uniform => {
                sliced_optimal_transport(n, seed, Some(self.density), SOT_DEFAULT_ITERATIONS)
            }
            Method::Baseline(Baseline::Gbn) if !uniform => {
                gaussian_blue_noise(n, seed, Some(self.density), GBN_DEFAULT_ITERATIONS)
            }
            Method::Baseline(b) => {
                let u = b.generate(n, seed);
                match &self.warp {
                    SquareWarp::Identity => u,
                    SquareWarp::InverseCdf => {
                        u.iter().map(|p| self.density.inverse_cdf(*p)).collect()
                    }
                    SquareWarp::Hierarchical(w) => u.iter().map(|p| w.warp(*p)).collect(),
                }
            }
            Method::SphericalFibonacci => anyhow::bail!("spherical Fibonacci has no 2D form"),
        })
    }
}

/// Side of the grid on which a direction target is projected to its equal-area
/// square for SOT and GBN.
pub const PROJECTION_RESOLUTION: usize = 256;

/// The target's density pulled back to the domain's equal-area square (constant
/// area element, so the square density is proportional to the target's pdf at the
/// mapped point), tabulated at cell centres on a
/// [`PROJECTION_RESOLUTION`]-square grid: what SOT and GBN are run against for
/// non-uniform directions (paper §5: "generated over a projected density").
pub fn projected_density(density: &dyn DirectionDensity) -> Result<TabulatedDensity> {
    let m = PROJECTION_RESOLUTION;
    let values = square_cell_masses(density, m, 1);
    Ok(TabulatedDensity::from_grid(m, m, values)?)
}

/// Our direction optimizer's [`CapSchedule`]s for a target without closed-form cap
/// measures, one per seed, kept while a panel runs: every size of a realization
/// shares its seed's schedule, so the table lookups are paid once per realization
/// instead of once per (realization, N). About 8 bytes x epochs x caps each (41 MB
/// at the full settings).
#[derive(Default)]
pub struct ScheduleMemo(Mutex<HashMap<u64, Arc<CapSchedule>>>);

impl ScheduleMemo {
    /// The schedule of `config` for `density`, built on first use.
    fn get(&self, density: &dyn DirectionDensity, config: &DirectionConfig) -> Arc<CapSchedule> {
        let mut memo = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let s = memo
            .entry(config.seed)
            .or_insert_with(|| Arc::new(CapSchedule::new(density, config)));
        if !s.matches(config) {
            *s = Arc::new(CapSchedule::new(density, config));
        }
        Arc::clone(s)
    }
}

/// A direction target as methods see it.
pub struct DirectionSampler<'a> {
    /// The target density.
    pub density: &'a dyn DirectionDensity,
    /// Its projection to the square (non-uniform targets that SOT / GBN need).
    pub projected: Option<TabulatedDensity>,
    /// Epochs of our direction optimizer (cap measures always
    /// [exact](AreaOption::Exact): closed forms, or the density's quadrature table
    /// through a [`ScheduleMemo`]).
    pub epochs: usize,
    /// Cap schedules of targets without closed-form cap measures.
    pub schedules: ScheduleMemo,
    /// Point cache.
    pub cache: &'a Cache,
}

impl DirectionSampler<'_> {
    /// Whether the target is the uniform one.
    fn uniform(&self) -> bool {
        self.density.spec() == "uniform"
    }

    /// `n` unit directions of `method` for realization seed `seed`.
    pub fn directions(&self, method: Method, n: usize, seed: u64) -> Result<Vec<DVec3>> {
        let domain = self.density.domain();
        let map = |p: &[DVec2]| {
            p.iter()
                .map(|q| domain.to_direction(*q))
                .collect::<Vec<_>>()
        };
        Ok(match method {
            Method::Ours => {
                let spec = self.density.spec();
                let group = ours_group(domain.name(), &spec);
                // v2: `brdf:` names the glTF BRDF, whose cap-measure rule has jittered
                // strata; v1 sets were optimized against the Burley BRDF or the
                // midpoint rule's ringed measures.
                let fp = format!(
                    "v2;{spec};{};area={:?}",
                    method_fingerprint(method, self.epochs),
                    AreaOption::Exact
                );
                let sq = match self.cache.get_points(&group, n, seed, &fp) {
                    Some(p) => p,
                    None => {
                        let cfg = DirectionConfig {
                            epochs: self.epochs,
                            area: AreaOption::Exact,
                            seed,
                            ..DirectionConfig::default()
                        };
                        let p = if self.density.has_closed_form_caps() {
                            optimize_directions(self.density, n, &cfg, &mut |_| {})
                        } else {
                            let schedule = self.schedules.get(self.density, &cfg);
                            optimize_directions_scheduled(
                                self.density,
                                n,
                                &cfg,
                                &schedule,
                                &mut |_| {},
                            )
                        };
                        self.cache.put_points(&group, seed, &fp, &p)?;
                        p
                    }
                };
                map(&sq)
            }
            Method::SphericalFibonacci => {
                anyhow::ensure!(
                    self.uniform() && domain == Domain::Sphere,
                    "spherical Fibonacci is only a uniform-sphere method"
                );
                spherical_fibonacci(n)
            }
            Method::Baseline(b @ (Baseline::Sot | Baseline::Gbn)) => {
                let sq = match (&self.projected, self.uniform()) {
                    (Some(d), false) if b == Baseline::Sot => {
                        sliced_optimal_transport(n, seed, Some(d), SOT_DEFAULT_ITERATIONS)
                    }
                    (Some(d), false) => {
                        gaussian_blue_noise(n, seed, Some(d), GBN_DEFAULT_ITERATIONS)
                    }
                    (None, false) => {
                        anyhow::bail!("{b} needs the projected density of {}", self.density.spec())
                    }
                    (_, true) => b.generate(n, seed),
                };
                map(&sq)
            }
            Method::Baseline(b) => b
                .generate(n, seed)
                .iter()
                .map(|u| self.density.sample(*u))
                .collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::parse_spec;
    use crate::sphere::parse_direction_spec;

    #[test]
    fn methods_make_n_points_in_the_domain_deterministically() {
        let dir = std::env::temp_dir().join(format!("nuld-eval-methods-{}", std::process::id()));
        let cache = Cache::new(&dir);
        let d = parse_spec("quarter-disc").unwrap();
        let s = SquareSampler {
            density: d.as_ref(),
            warp: SquareWarp::InverseCdf,
            epochs: 5,
            cache: &cache,
        };
        for m in [
            Method::Ours,
            Method::Baseline(Baseline::Halton),
            Method::Baseline(Baseline::Sot),
        ] {
            let p = s.points(m, 16, 7).unwrap();
            assert_eq!(p.len(), 16);
            assert_eq!(p, s.points(m, 16, 7).unwrap(), "{m}");
            if m != Method::Baseline(Baseline::Sot) {
                assert!(p.iter().all(|q| d.pdf(*q) > 0.0), "{m}");
            }
        }
        // Ours came from the cache the second time: the file exists.
        assert!(cache
            .points_path("ours-square-quarter-disc", 16, 7)
            .exists());

        let u = parse_direction_spec("cosine", Domain::Hemisphere).unwrap();
        let ds = DirectionSampler {
            density: u.as_ref(),
            projected: Some(projected_density(u.as_ref()).unwrap()),
            epochs: 5,
            schedules: ScheduleMemo::default(),
            cache: &cache,
        };
        for m in [
            Method::Ours,
            Method::Baseline(Baseline::Random),
            Method::Baseline(Baseline::Gbn),
        ] {
            let w = ds.directions(m, 16, 3).unwrap();
            assert_eq!(w.len(), 16);
            assert!(
                w.iter()
                    .all(|v| (v.length() - 1.0).abs() < 1e-9 && v.z >= 0.0),
                "{m}"
            );
        }
        assert!(ds.directions(Method::SphericalFibonacci, 8, 0).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
