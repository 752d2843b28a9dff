//! `build-tool optimize`: optimize point sets for a target and write the blob, a
//! JSON report with exact metrics against the warped Owen-Sobol baseline, and a
//! picture.

use super::DomainArg;
use crate::density::{parse_spec, Density2D};
use crate::discrepancy::GradientPath;
use crate::metrics::summary::{MetricSummary, Target};
use crate::optimize::{
    initial_parameters, optimize, to_points, AnchorSampling, AreaOption, OptimizeConfig,
    Parameterization,
};
use crate::pointset::PointSets;
use crate::seeding::derive_seed;
use anyhow::{bail, ensure, Context, Result};
use clap::{Args, ValueEnum};
use glam::DVec2;
use indicatif::{ProgressBar, ProgressStyle};
use nuld_core::blob::{Domain, Metadata};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// `--area` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AreaArg {
    /// Exact box measures (closed form, or summed-area tables for images).
    Exact,
    /// The paper's Monte-Carlo estimate (Eq. 11) with `--mc-samples` shared samples.
    Mc,
}

/// `--anchor-sampling` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AnchorArg {
    /// Independent uniform anchors (the paper's estimator).
    Random,
    /// A freshly scrambled Owen-Sobol set per epoch (lower variance).
    OwenSobol,
}

/// `--param` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ParamArg {
    /// Optimize through the inverse CDF (paper §3.4).
    InverseCdf,
    /// Optimize the points directly.
    Direct,
}

/// Arguments of `build-tool optimize`.
#[derive(Args, Debug)]
pub struct OptimizeArgs {
    /// Domain; only `square` in this version.
    #[arg(long, value_enum, default_value = "square")]
    pub domain: DomainArg,
    /// Target density SPEC (DESIGN.md §3), e.g. `gaussian:0.5,0.5,0.15`, `image:PATH`.
    #[arg(long, default_value = "gaussian:0.5,0.5,0.15")]
    pub density: String,
    /// Points per set.
    #[arg(long, default_value_t = 256)]
    pub n: usize,
    /// Independently seeded sets in the blob.
    #[arg(long, default_value_t = 1)]
    pub sets: usize,
    /// Seed; fixes the output bit for bit whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Epochs (gradient steps).
    #[arg(long, default_value_t = OptimizeConfig::default().epochs)]
    pub epochs: usize,
    /// Anchors per epoch (M; four boxes each).
    #[arg(long, default_value_t = OptimizeConfig::default().anchors)]
    pub anchors: usize,
    /// How anchors are drawn each epoch.
    #[arg(long, value_enum, default_value = "owen-sobol")]
    pub anchor_sampling: AnchorArg,
    /// Initial Adam step, in units of the point spacing 1/sqrt(N).
    #[arg(long, default_value_t = OptimizeConfig::default().learning_rate)]
    pub lr: f64,
    /// Sigmoid sharpness at the start, in units of sqrt(N).
    #[arg(long, default_value_t = OptimizeConfig::default().alpha_start)]
    pub alpha_start: f64,
    /// Sigmoid sharpness at the end, in units of sqrt(N).
    #[arg(long, default_value_t = OptimizeConfig::default().alpha_end)]
    pub alpha_end: f64,
    /// How box measures are computed.
    #[arg(long, value_enum, default_value = "exact")]
    pub area: AreaArg,
    /// Shared samples per epoch for `--area mc`.
    #[arg(long, default_value_t = 65536)]
    pub mc_samples: usize,
    /// Parameterization.
    #[arg(long, value_enum, default_value = "inverse-cdf")]
    pub param: ParamArg,
    /// Use the dense O(N M) reference gradient instead of the banded fast path.
    #[arg(long)]
    pub dense: bool,
    /// Warped Owen-Sobol sets averaged for the baseline in the report.
    #[arg(long, default_value_t = 8)]
    pub baseline_sets: usize,
    /// Output directory: set.nuld, report.json, set.png.
    #[arg(long)]
    pub out: PathBuf,
}

impl OptimizeArgs {
    /// The optimizer settings these arguments ask for.
    pub fn config(&self) -> OptimizeConfig {
        OptimizeConfig {
            epochs: self.epochs,
            anchors: self.anchors,
            anchor_sampling: match self.anchor_sampling {
                AnchorArg::Random => AnchorSampling::Random,
                AnchorArg::OwenSobol => AnchorSampling::OwenSobol,
            },
            learning_rate: self.lr,
            alpha_start: self.alpha_start,
            alpha_end: self.alpha_end,
            area: match self.area {
                AreaArg::Exact => AreaOption::Exact,
                AreaArg::Mc => AreaOption::MonteCarlo {
                    samples: self.mc_samples,
                },
            },
            parameterization: match self.param {
                ParamArg::InverseCdf => Parameterization::InverseCdf,
                ParamArg::Direct => Parameterization::Direct,
            },
            path: if self.dense {
                GradientPath::Dense
            } else {
                GradientPath::Fast
            },
            seed: self.seed,
            ..OptimizeConfig::default()
        }
    }

    fn validate(&self) -> Result<()> {
        if self.domain != DomainArg::Square {
            bail!("--domain {:?} is not supported yet: only the square domain can be optimized in this version", self.domain);
        }
        ensure!(
            (1..=crate::baselines::OWEN_SOBOL_MAX_POINTS).contains(&self.n),
            "--n must be in 1..=65536, got {}",
            self.n
        );
        ensure!(self.sets >= 1, "--sets must be at least 1");
        ensure!(self.epochs >= 1, "--epochs must be at least 1");
        ensure!(self.anchors >= 1, "--anchors must be at least 1");
        ensure!(
            self.lr.is_finite() && self.lr > 0.0,
            "--lr must be positive"
        );
        ensure!(
            self.alpha_start.is_finite()
                && self.alpha_end.is_finite()
                && self.alpha_start > 0.0
                && self.alpha_end > 0.0,
            "--alpha-start and --alpha-end must be positive"
        );
        ensure!(
            self.area == AreaArg::Exact || self.mc_samples >= 1,
            "--mc-samples must be at least 1"
        );
        Ok(())
    }
}

/// Metrics of a run, as written to report.json.
#[derive(Serialize)]
struct Report<'a> {
    density: &'a str,
    domain: &'static str,
    n: usize,
    sets: usize,
    seed: u64,
    settings: &'a OptimizeConfig,
    threads: usize,
    wall_time_s: f64,
    optimize_time_s: f64,
    metric_method: String,
    /// Per set: the warped Owen-Sobol start and the optimized result.
    per_set: Vec<SetReport>,
    /// Mean over sets of the optimized metrics.
    optimized_mean: MetricSummary,
    /// Mean over `baseline_sets` inverse-CDF-warped Owen-Sobol sets of the same N.
    baseline_warped_owen_sobol_mean: MetricSummary,
    baseline_sets: usize,
    /// optimized_mean / baseline mean, per metric (below 1 is better).
    ratio_to_baseline: MetricSummary,
}

#[derive(Serialize)]
struct SetReport {
    seed: u64,
    before: MetricSummary,
    after: MetricSummary,
    final_loss: f64,
}

/// Runs `build-tool optimize`.
pub fn run(a: super::optimize::OptimizeArgs) -> Result<()> {
    a.validate()?;
    let density = parse_spec(&a.density).with_context(|| format!("--density {}", a.density))?;
    crate::output::ensure_dir(&a.out)?;
    let config = a.config();
    let started = Instant::now();

    let bar = ProgressBar::new((a.sets * a.epochs) as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} {prefix} [{bar:30}] {pos}/{len} epochs  {msg}  ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    let mut sets = Vec::with_capacity(a.sets);
    let mut losses = Vec::with_capacity(a.sets);
    for s in 0..a.sets {
        bar.set_prefix(format!("set {}/{}", s + 1, a.sets));
        let cfg = OptimizeConfig {
            seed: derive_seed(a.seed, s as u64),
            ..config.clone()
        };
        let mut last = 0.0;
        let points = optimize(density.as_ref(), a.n, &cfg, &mut |r| {
            last = r.loss;
            bar.inc(1);
            if r.epoch % 10 == 0 {
                bar.set_message(format!("loss {:.3e}", r.loss));
            }
        });
        sets.push(points);
        losses.push(last);
    }
    bar.finish_and_clear();
    let optimize_time = started.elapsed().as_secs_f64();

    let target = Target::new(density.as_ref());
    let per_set: Vec<SetReport> = sets
        .iter()
        .zip(&losses)
        .enumerate()
        .map(|(s, (pts, &final_loss))| {
            let seed = derive_seed(a.seed, s as u64);
            let start = warped_owen_sobol(density.as_ref(), a.n, seed);
            SetReport {
                seed,
                before: target.evaluate(&start),
                after: target.evaluate(pts),
                final_loss,
            }
        })
        .collect();
    let baseline: Vec<MetricSummary> = (0..a.baseline_sets)
        .map(|b| {
            let seed = derive_seed(a.seed ^ 0xba5e, b as u64);
            target.evaluate(&warped_owen_sobol(density.as_ref(), a.n, seed))
        })
        .collect();
    let optimized_mean = MetricSummary::mean(&per_set.iter().map(|r| r.after).collect::<Vec<_>>());
    let baseline_mean = MetricSummary::mean(&baseline);
    let ratio = MetricSummary {
        l2_star: optimized_mean.l2_star / baseline_mean.l2_star,
        asd: optimized_mean.asd / baseline_mean.asd,
        star: optimized_mean.star / baseline_mean.star,
    };

    let spec = density.spec();
    let ps = PointSets {
        domain: Domain::Square,
        sets,
    };
    let blob = ps.to_blob(&Metadata {
        generator: "optimize",
        target: &spec,
        seed: a.seed,
    })?;
    let report = Report {
        density: &spec,
        domain: "square",
        n: a.n,
        sets: a.sets,
        seed: a.seed,
        settings: &config,
        threads: rayon::current_num_threads(),
        wall_time_s: started.elapsed().as_secs_f64(),
        optimize_time_s: optimize_time,
        metric_method: target.method(),
        per_set,
        optimized_mean,
        baseline_warped_owen_sobol_mean: baseline_mean,
        baseline_sets: a.baseline_sets,
        ratio_to_baseline: ratio,
    };
    let json = serde_json::to_string_pretty(&report)?;
    let title = format!(
        "{} — N = {}, D2asd {:.2e} (warped Sobol {:.2e})",
        spec, a.n, optimized_mean.asd, baseline_mean.asd
    );
    let png_path = a.out.join("set.png");
    crate::plot::render_point_set(&png_path, &title, &|p| density.pdf(p), &ps.sets[0], 900)?;
    crate::output::write_atomic(&a.out.join("report.json"), json.as_bytes())?;
    crate::output::write_atomic(&a.out.join("set.nuld"), blob.as_slice())?;
    eprintln!(
        "optimized {} set(s) of {} points for {} in {:.1} s: D2asd {:.3e}, L2* {:.3e}, D* {:.3e} \
         (warped Owen-Sobol: {:.3e}, {:.3e}, {:.3e}) -> {}",
        a.sets,
        a.n,
        spec,
        optimize_time,
        optimized_mean.asd,
        optimized_mean.l2_star,
        optimized_mean.star,
        baseline_mean.asd,
        baseline_mean.l2_star,
        baseline_mean.star,
        a.out.display()
    );
    Ok(())
}

/// The standard baseline: Owen-Sobol points of scramble `seed` warped by the
/// target's inverse CDF (exactly the optimizer's starting set for that seed).
pub fn warped_owen_sobol(density: &dyn Density2D, n: usize, seed: u64) -> Vec<DVec2> {
    to_points(
        density,
        &initial_parameters(n, seed),
        Parameterization::InverseCdf,
    )
}
