//! One optimization run, whatever the domain: optimize every set, then measure the
//! stored sets, their starting sets and the baseline sets for the [`RunReport`].
//! A [`Problem`] says what differs between the square and the direction domains.

use super::directions::{initial_square_points, optimize_directions, DirectionConfig};
use super::report::{RunInfo, RunReport, SetReport};
use super::{optimize, OptimizeConfig};
use crate::baselines::warped_owen_sobol;
use crate::density::{parse_spec, Density2D};
use crate::descent::EpochReport;
use crate::metrics::cap_summary::{CapMetricSummary, CapTarget};
use crate::metrics::summary::{MetricSummary, Target};
use crate::metrics::Summary;
use crate::pointset::PointSets;
use crate::progress::Progress;
use crate::seeding::derive_seed;
use crate::sphere::{parse_direction_spec, DirectionDensity};
use anyhow::Result;
use glam::DVec2;
use nuld_core::blob::Domain;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// Stream of [`derive_seed`] for the baseline sets, apart from the optimized sets'.
const BASELINE_STREAM: u64 = 0xba5e;

/// Measures one set of square points.
type Evaluate<'a, M> = Box<dyn Fn(&[DVec2]) -> M + Sync + 'a>;

/// The metrics of square points (directions in their equal-area square) against a
/// prepared target.
pub struct Metrics<'a, M> {
    /// How the metrics are computed, for reports.
    pub method: String,
    evaluate: Evaluate<'a, M>,
}

impl<M> Metrics<'_, M> {
    /// The metrics of one set.
    pub fn evaluate(&self, points: &[DVec2]) -> M {
        (self.evaluate)(points)
    }
}

/// What an optimization run needs to know about its domain and target.
pub trait Problem: Sync {
    /// The optimizer's settings.
    type Config: Clone + Serialize + Sync;
    /// The metrics reported for one set.
    type Summary: Summary;

    /// Where the points live.
    fn domain(&self) -> Domain;
    /// The canonical target SPEC.
    fn spec(&self) -> String;
    /// Epochs per set under `config`.
    fn epochs(config: &Self::Config) -> usize;
    /// Optimizes `n` points with seed `seed` (replacing `config`'s), calling
    /// `on_epoch` after every epoch; returns square points.
    fn optimize(
        &self,
        n: usize,
        config: &Self::Config,
        seed: u64,
        on_epoch: &mut dyn FnMut(&EpochReport),
    ) -> Vec<DVec2>;
    /// The optimizer's start for `seed`, which is also the baseline: Owen-Sobol
    /// warped by the target's standard sampler, as square points.
    fn baseline(&self, n: usize, seed: u64) -> Vec<DVec2>;
    /// The target prepared for measuring sets (tabulated once).
    fn metrics(&self) -> Metrics<'_, Self::Summary>;
    /// Notes on how the target was built from its input (e.g. negative pixels of a
    /// map set to 0); none by default.
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }
    /// Draws `points` over the target's density into a PNG at `path`.
    fn render(&self, path: &Path, title: &str, points: &[DVec2]) -> Result<()>;
}

/// A 2D target.
pub struct SquareProblem {
    /// The target.
    pub density: Box<dyn Density2D>,
}

impl SquareProblem {
    /// The target of a 2D SPEC (see [`parse_spec`]).
    pub fn parse(spec: &str) -> Result<Self> {
        Ok(Self {
            density: parse_spec(spec)?,
        })
    }
}

impl Problem for SquareProblem {
    type Config = OptimizeConfig;
    type Summary = MetricSummary;

    fn domain(&self) -> Domain {
        Domain::Square
    }

    fn spec(&self) -> String {
        self.density.spec()
    }

    fn epochs(config: &OptimizeConfig) -> usize {
        config.epochs
    }

    fn optimize(
        &self,
        n: usize,
        config: &OptimizeConfig,
        seed: u64,
        on_epoch: &mut dyn FnMut(&EpochReport),
    ) -> Vec<DVec2> {
        let config = OptimizeConfig {
            seed,
            ..config.clone()
        };
        optimize(self.density.as_ref(), n, &config, on_epoch)
    }

    fn baseline(&self, n: usize, seed: u64) -> Vec<DVec2> {
        warped_owen_sobol(self.density.as_ref(), n, seed)
    }

    fn metrics(&self) -> Metrics<'_, MetricSummary> {
        let target = Target::new(self.density.as_ref());
        Metrics {
            method: target.method(),
            evaluate: Box::new(move |points| target.evaluate(points)),
        }
    }

    fn render(&self, path: &Path, title: &str, points: &[DVec2]) -> Result<()> {
        crate::plot::render_point_set(path, title, &|p| self.density.pdf(p), points, 900)
    }
}

/// A target on the sphere or the upper hemisphere.
pub struct DirectionProblem {
    /// The target.
    pub density: Box<dyn DirectionDensity>,
}

impl DirectionProblem {
    /// The target of a direction SPEC on `domain` (see [`parse_direction_spec`]).
    pub fn parse(spec: &str, domain: Domain) -> Result<Self> {
        Ok(Self {
            density: parse_direction_spec(spec, domain)?,
        })
    }
}

impl Problem for DirectionProblem {
    type Config = DirectionConfig;
    type Summary = CapMetricSummary;

    fn notes(&self) -> Vec<String> {
        self.density.notes()
    }

    fn domain(&self) -> Domain {
        self.density.domain()
    }

    fn spec(&self) -> String {
        self.density.spec()
    }

    fn epochs(config: &DirectionConfig) -> usize {
        config.epochs
    }

    fn optimize(
        &self,
        n: usize,
        config: &DirectionConfig,
        seed: u64,
        on_epoch: &mut dyn FnMut(&EpochReport),
    ) -> Vec<DVec2> {
        let config = DirectionConfig {
            seed,
            ..config.clone()
        };
        optimize_directions(self.density.as_ref(), n, &config, on_epoch)
    }

    fn baseline(&self, n: usize, seed: u64) -> Vec<DVec2> {
        initial_square_points(self.density.as_ref(), n, seed)
    }

    fn metrics(&self) -> Metrics<'_, CapMetricSummary> {
        let target = CapTarget::new(self.density.as_ref());
        let domain = self.domain();
        Metrics {
            method: target.method(),
            evaluate: Box::new(move |points| {
                let dirs: Vec<_> = points.iter().map(|&p| domain.to_direction(p)).collect();
                target.evaluate(&dirs)
            }),
        }
    }

    fn render(&self, path: &Path, title: &str, points: &[DVec2]) -> Result<()> {
        let domain = self.domain();
        crate::plot::render_direction_set(
            path,
            title,
            &|d| self.density.pdf(d),
            &|p| domain.to_direction(p),
            points,
            700,
        )
    }
}

/// The size and seeds of a run.
#[derive(Clone, Copy, Debug)]
pub struct RunSettings {
    /// Points per set.
    pub n: usize,
    /// Sets to optimize; set `s` uses seed `derive_seed(seed, s)`.
    pub sets: usize,
    /// Run seed.
    pub seed: u64,
    /// Baseline sets for the report; set `b` uses `derive_seed(seed ^ 0xba5e, b)`.
    pub baseline_sets: usize,
}

/// What a run produced: the optimized sets and their report.
pub struct Run<C, M> {
    /// The optimized sets (full precision; the blob quantizes them).
    pub points: PointSets,
    /// The report.
    pub report: RunReport<C, M>,
}

/// Optimizes `settings.sets` sets for `problem` under `config`, then measures each
/// optimized set as stored (quantized, [`PointSets::quantized`]), its starting set
/// and `settings.baseline_sets` baseline sets, in parallel; progress of both phases
/// on stderr ([`Progress`]). Deterministic: the seeds fix the result whatever the
/// thread count (only the timings vary).
pub fn run<P: Problem>(
    problem: &P,
    settings: &RunSettings,
    config: &P::Config,
) -> Run<P::Config, P::Summary> {
    let started = Instant::now();
    let &RunSettings {
        n,
        sets,
        seed,
        baseline_sets,
    } = settings;
    let notes = problem.notes();
    for note in &notes {
        eprintln!("note: {note}");
    }
    let epochs = P::epochs(config);
    let progress = Progress::stderr("optimize", (sets * epochs) as u64, "epoch");
    let mut optimized = Vec::with_capacity(sets);
    let mut losses = Vec::with_capacity(sets);
    for s in 0..sets {
        progress.set_context(format!("set {}/{sets}", s + 1));
        let mut last = 0.0;
        optimized.push(
            problem.optimize(n, config, derive_seed(seed, s as u64), &mut |r| {
                last = r.loss;
                if r.epoch % 10 == 0 {
                    progress.set_message(format!("loss {:.3e}", r.loss));
                }
                progress.inc(1);
            }),
        );
        losses.push(last);
    }
    progress.finish();
    let optimize_time_s = started.elapsed().as_secs_f64();
    let points = PointSets {
        domain: problem.domain(),
        sets: optimized,
    };

    let measuring = Instant::now();
    let stored = points.quantized();
    let progress = Progress::stderr("report", (2 * sets + baseline_sets) as u64, "set");
    progress.set_context("preparing the target");
    let metrics = problem.metrics();
    progress.set_context("");
    // Every set to measure: the optimized sets as stored, their starts, the baselines.
    let start = |s: usize| problem.baseline(n, derive_seed(seed, s as u64));
    let base = |b: usize| problem.baseline(n, derive_seed(seed ^ BASELINE_STREAM, b as u64));
    let measured: Vec<P::Summary> = (0..2 * sets + baseline_sets)
        .into_par_iter()
        .map(|k| {
            let m = if k < sets {
                metrics.evaluate(&stored.sets[k])
            } else if k < 2 * sets {
                metrics.evaluate(&start(k - sets))
            } else {
                metrics.evaluate(&base(k - 2 * sets))
            };
            progress.inc(1);
            m
        })
        .collect();
    progress.finish();
    let per_set = (0..sets)
        .map(|s| SetReport {
            seed: derive_seed(seed, s as u64),
            before: measured[sets + s],
            after: measured[s],
            final_loss: losses[s],
        })
        .collect();
    let info = RunInfo {
        density: problem.spec(),
        domain: problem.domain().name(),
        n,
        seed,
        settings: config.clone(),
        optimize_time_s,
        report_time_s: measuring.elapsed().as_secs_f64(),
        metric_method: metrics.method.clone(),
        notes,
    };
    Run {
        report: RunReport::new(info, per_set, &measured[2 * sets..]),
        points,
    }
}

/// The metrics of every set of a blob's `points` against `problem`'s target.
#[derive(Clone, Debug, Serialize)]
pub struct Measured<M> {
    /// How they were computed.
    pub method: String,
    /// Per set.
    pub per_set: Vec<M>,
    /// Their mean.
    pub mean: M,
}

/// Measures every set of `points` (square points; directions in their equal-area
/// square) against `problem`'s target, in parallel, with progress on stderr.
pub fn measure<P: Problem>(problem: &P, points: &PointSets) -> Measured<P::Summary> {
    let progress = Progress::stderr("metrics", points.set_count() as u64, "set");
    let metrics = problem.metrics();
    let per_set: Vec<P::Summary> = points
        .sets
        .par_iter()
        .map(|set| {
            let m = metrics.evaluate(set);
            progress.inc(1);
            m
        })
        .collect();
    progress.finish();
    Measured {
        method: metrics.method.clone(),
        mean: P::Summary::mean(&per_set),
        per_set,
    }
}
