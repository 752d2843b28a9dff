//! Evaluates a panel: every (method, N, realization), through the result cache,
//! baselines' realizations in parallel and ours sequentially (the optimizers are
//! parallel themselves), then aggregated into [`Row`]s.

use super::cache::{Cache, CacheKey, Values};
use super::figures::{Aggregation, Panel, PanelKind};
use super::methods::{
    method_fingerprint, projected_density, realization_seed, DirectionSampler, Method,
    SquareSampler, SquareWarp,
};
use super::rows::Row;
use super::{stats, EvalSettings, Figure};
use crate::baselines::HierarchicalWarp;
use crate::metrics::summary::{Target, TABULATION_RESOLUTION};
use crate::progress::Progress;
use crate::seeding::derive_seed;
use crate::sphere::{
    cap_l2_mc_squared, cap_l2_uniform, cap_star_estimate_with, CapRadius, CapStarOptions,
    DirectionDensity,
};
use anyhow::{anyhow, Result};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Computes one realization's values for a method, N and generator seed.
type Evaluator<'a> = Box<dyn Fn(Method, usize, u64) -> Result<Values> + Sync + 'a>;

/// Stream for the seed of the cap star search of a realization.
const CAP_STAR_STREAM: u64 = 0xCA95_7A12;
/// Stream for the caps of the Monte Carlo cap L2 of a realization.
const CAP_L2_STREAM: u64 = 0xCA91_2B2E;

/// The cap metrics of `points` against `density` (see the figure notes): the cap
/// L2 discrepancy (Stolarsky's closed form for the uniform sphere, else the Monte
/// Carlo estimate over `s.cap_l2_caps` caps in the same cos-uniform convention) and
/// the cap star lower bound.
fn cap_values(
    points: &[glam::DVec3],
    density: &dyn DirectionDensity,
    uniform: bool,
    s: &EvalSettings,
    seed: u64,
) -> Values {
    let l2 = if uniform {
        cap_l2_uniform(points)
    } else {
        let (d2, _) = cap_l2_mc_squared(
            points,
            |w, t| density.cap_measure(w, t),
            s.cap_l2_caps,
            derive_seed(seed, CAP_L2_STREAM),
            CapRadius::CosUniform,
        );
        d2.max(0.0).sqrt()
    };
    let options = CapStarOptions {
        random_caps: s.cap_star_caps,
        refine: s.cap_star_refine,
        rounds: s.cap_star_rounds,
        ..CapStarOptions::default()
    };
    let star = cap_star_estimate_with(
        points,
        density,
        &options,
        derive_seed(seed, CAP_STAR_STREAM),
    );
    [
        ("cap_l2".to_string(), l2),
        ("cap_star".to_string(), star.lower_bound),
    ]
    .into_iter()
    .collect()
}

/// The evaluator of `panel` and the panel part of the cache fingerprint.
fn evaluator<'a>(
    panel: &'a Panel,
    s: &'a EvalSettings,
    cache: &'a Cache,
) -> Result<(Evaluator<'a>, String)> {
    Ok(match &panel.kind {
        PanelKind::SquareDiscrepancy {
            density,
            hierarchical,
        } => {
            let uniform = density.spec() == "uniform";
            let warp = if uniform {
                SquareWarp::Identity
            } else if *hierarchical {
                SquareWarp::Hierarchical(Box::new(HierarchicalWarp::new(
                    &density.cells(TABULATION_RESOLUTION),
                )))
            } else {
                SquareWarp::InverseCdf
            };
            let fp = format!(
                "sq-v1;{};tab={TABULATION_RESOLUTION};hierarchical={hierarchical}",
                panel.spec
            );
            let target = Target::new(density.as_ref());
            let sampler = SquareSampler {
                density: density.as_ref(),
                warp,
                epochs: s.epochs,
                cache,
            };
            let f = move |m: Method, n: usize, seed: u64| -> Result<Values> {
                let pts = sampler.points(m, n, seed)?;
                let v = target.evaluate(&pts);
                Ok([
                    ("l2_star".to_string(), v.l2_star),
                    ("asd".to_string(), v.asd),
                    ("star".to_string(), v.star),
                ]
                .into_iter()
                .collect())
            };
            (Box::new(f), fp)
        }
        PanelKind::SphereDiscrepancy { density } => {
            // Stolarsky's closed form holds for the uniform measure on the sphere.
            let uniform =
                density.spec() == "uniform" && density.domain() == nuld_core::blob::Domain::Sphere;
            let star = format!(
                "{}/{}/{}",
                s.cap_star_caps, s.cap_star_refine, s.cap_star_rounds
            );
            // v3: `brdf:` specs name the glTF BRDF (v2) and measure caps with a
            // jittered rule (v3); v1 entries of brdf panels were computed when they
            // named the Burley BRDF, v2 ones with the midpoint rule's ringed
            // measures near the horizon, and must not be hits.
            let fp = if uniform {
                format!("sph-v3;{};star={}", panel.spec, star)
            } else {
                format!("sph-v3;{};star={};l2mc={}", panel.spec, star, s.cap_l2_caps)
            };
            let sampler = DirectionSampler {
                density: density.as_ref(),
                projected: None,
                epochs: s.direction_epochs,
                schedules: Default::default(),
                cache,
            };
            let f = move |m: Method, n: usize, seed: u64| -> Result<Values> {
                let pts = sampler.directions(m, n, seed)?;
                Ok(cap_values(&pts, sampler.density, uniform, s, seed))
            };
            (Box::new(f), fp)
        }
        PanelKind::SquareIntegral(it) => {
            let uniform = it.density.spec() == "uniform";
            let sampler = SquareSampler {
                density: it.density.as_ref(),
                warp: if uniform {
                    SquareWarp::Identity
                } else {
                    SquareWarp::InverseCdf
                },
                epochs: s.epochs,
                cache,
            };
            let f = move |m: Method, n: usize, seed: u64| -> Result<Values> {
                let pts = sampler.points(m, n, seed)?;
                Ok([("estimate".to_string(), it.estimate(&pts))]
                    .into_iter()
                    .collect())
            };
            (Box::new(f), format!("int2-v1;{};{}", it.name, panel.spec))
        }
        PanelKind::SphereIntegral(it) => {
            let density = it.density();
            let projected = (density.spec() != "uniform")
                .then(|| projected_density(density))
                .transpose()?;
            let sampler = DirectionSampler {
                density,
                projected,
                epochs: s.direction_epochs,
                schedules: Default::default(),
                cache,
            };
            let f = move |m: Method, n: usize, seed: u64| -> Result<Values> {
                let pts = sampler.directions(m, n, seed)?;
                let e = it.estimate(&pts, !m.targets_density());
                Ok([("estimate".to_string(), e)].into_iter().collect())
            };
            (
                Box::new(f),
                format!(
                    // v3 as `sph-v3`: the glTF BRDF and its jittered rule.
                    "int3-v3;{};{};proj={}",
                    it.name,
                    it.factors(),
                    super::methods::PROJECTION_RESOLUTION
                ),
            )
        }
    })
}

/// Evaluates `panel` for every method and size, through `cache`, and returns its
/// rows ordered by metric, then method (panel order), then N.
pub fn run_panel(
    figure: Figure,
    panel: &Panel,
    s: &EvalSettings,
    cache: &Cache,
) -> Result<Vec<Row>> {
    let started = Instant::now();
    let sizes = s.sizes();
    let (eval, panel_fp) = evaluator(panel, s, cache)?;
    let total: usize = panel
        .methods
        .iter()
        .map(|m| m.realizations(s) * sizes.len())
        .sum();
    let progress = Progress::stderr(
        &format!("{figure} {}", panel.target),
        total as u64,
        "realization",
    );
    let hits = AtomicUsize::new(0);
    let sphere = matches!(
        panel.kind,
        PanelKind::SphereDiscrepancy { .. } | PanelKind::SphereIntegral(_)
    );
    let epochs = if sphere { s.direction_epochs } else { s.epochs };
    let mut rows = Vec::new();
    for (mi, &method) in panel.methods.iter().enumerate() {
        let fp = format!("{panel_fp};{}", method_fingerprint(method, epochs));
        for &n in &sizes {
            progress.set_context(format!("{method} N={n}"));
            let one = |r: usize| -> Result<Values> {
                let key = CacheKey {
                    figure: figure.name().into(),
                    method: method.name().into(),
                    target: panel.target.clone(),
                    n,
                    seed: r as u64,
                };
                let v = match cache.get(&key, &fp) {
                    Some(v) => {
                        hits.fetch_add(1, Ordering::Relaxed);
                        v
                    }
                    None => {
                        let v = eval(method, n, realization_seed(r as u64))?;
                        cache.put(&key, &fp, &v)?;
                        v
                    }
                };
                progress.inc(1);
                Ok(v)
            };
            let count = method.realizations(s);
            let values: Vec<Values> = if method == Method::Ours {
                (0..count).map(one).collect::<Result<_>>()?
            } else {
                (0..count).into_par_iter().map(one).collect::<Result<_>>()?
            };
            for (k, metric) in panel.metrics.iter().enumerate() {
                let xs = values
                    .iter()
                    .map(|v| {
                        v.get(metric.source).copied().ok_or_else(|| {
                            anyhow!("no value `{}` for {method} at N={n}", metric.source)
                        })
                    })
                    .collect::<Result<Vec<f64>>>()?;
                let agg = match metric.aggregation {
                    Aggregation::Mean => stats::mean(&xs),
                    Aggregation::Rmse { reference } => stats::rmse(&xs, reference),
                };
                rows.push((
                    (k, mi, n),
                    Row {
                        target: panel.target.clone(),
                        metric: metric.key.to_string(),
                        method: method.name().to_string(),
                        n,
                        mean: agg.value,
                        stderr: agg.stderr,
                        realizations: agg.realizations,
                    },
                ));
            }
        }
    }
    progress.finish_with(&format!(
        "{total} realizations ({} from the cache) in {:.1} s",
        hits.load(Ordering::Relaxed),
        started.elapsed().as_secs_f64()
    ));
    rows.sort_by_key(|(k, _)| *k);
    Ok(rows.into_iter().map(|(_, r)| r).collect())
}
