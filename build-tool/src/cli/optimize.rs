//! `build-tool optimize`: optimize point sets for a target and write the blob, a
//! JSON report with exact metrics against the warped Owen-Sobol baseline, and a
//! picture.

use super::DomainArg;
use crate::density::{parse_spec, Density2D};
use crate::discrepancy::GradientPath;
use crate::metrics::cap_summary::{CapMetricSummary, CapTarget};
use crate::metrics::summary::{MetricSummary, Target};
use crate::optimize::directions::{initial_square_points, optimize_directions, DirectionConfig};
use crate::optimize::{
    initial_parameters, optimize, to_points, AnchorSampling, AreaOption, EpochReport,
    OptimizeConfig, Parameterization,
};
use crate::pointset::PointSets;
use crate::seeding::derive_seed;
use crate::sphere::parse_direction_spec;
use anyhow::{ensure, Context, Result};
use clap::{Args, ValueEnum};
use glam::{DVec2, DVec3};
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
    /// Domain: the unit square, or directions on the sphere or upper hemisphere.
    #[arg(long, value_enum, default_value = "square")]
    pub domain: DomainArg,
    /// Target SPEC (grammar: docs/targets.md). Square: `uniform`, `gaussian:MX,MY,S`,
    /// `bilinear:..`, `quarter-disc`, `step-gaussian`, `image:PATH`; sphere and
    /// hemisphere: `uniform`, `cosine`, `brdf:ROUGHNESS,THETA_O_DEG` (glTF 2.0),
    /// `brdf-burley:ROUGHNESS,THETA_O_DEG`, `envmap:PATH`.
    /// Default: `gaussian:0.5,0.5,0.15` for the square, `uniform` for directions.
    #[arg(long)]
    pub density: Option<String>,
    /// Points per set.
    #[arg(long, default_value_t = 256, allow_negative_numbers = true, value_parser = super::count)]
    pub n: usize,
    /// Independently seeded sets in the blob.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = super::count)]
    pub sets: usize,
    /// Seed; fixes the output bit for bit whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Epochs (gradient steps). Default 1000 (square), 5000 (directions).
    #[arg(long, allow_negative_numbers = true, value_parser = super::count)]
    pub epochs: Option<usize>,
    /// Square: anchors per epoch (M; four boxes each). Default 4096.
    #[arg(long, allow_negative_numbers = true, value_parser = super::count)]
    pub anchors: Option<usize>,
    /// Directions: caps per epoch. Default 1024.
    #[arg(long, allow_negative_numbers = true, value_parser = super::count)]
    pub caps: Option<usize>,
    /// How anchors are drawn each epoch.
    #[arg(long, value_enum, default_value = "owen-sobol")]
    pub anchor_sampling: AnchorArg,
    /// Initial Adam step, in units of the point spacing (see README). Default 0.02.
    #[arg(long, allow_negative_numbers = true)]
    pub lr: Option<f64>,
    /// Sigmoid sharpness at the start, in inverse point spacings. Default 8.
    #[arg(long, allow_negative_numbers = true)]
    pub alpha_start: Option<f64>,
    /// Sigmoid sharpness at the end, in inverse point spacings. Default 128.
    #[arg(long, allow_negative_numbers = true)]
    pub alpha_end: Option<f64>,
    /// How box measures are computed.
    #[arg(long, value_enum, default_value = "exact")]
    pub area: AreaArg,
    /// Shared samples per epoch for `--area mc`.
    #[arg(long, default_value_t = 65536, allow_negative_numbers = true, value_parser = super::count)]
    pub mc_samples: usize,
    /// Parameterization.
    #[arg(long, value_enum, default_value = "inverse-cdf")]
    pub param: ParamArg,
    /// Use the dense O(N M) reference gradient instead of the banded fast path.
    #[arg(long)]
    pub dense: bool,
    /// Warped Owen-Sobol sets averaged for the baseline in the report.
    #[arg(long, default_value_t = 8, allow_negative_numbers = true, value_parser = super::count)]
    pub baseline_sets: usize,
    /// Output directory: set.nuld, report.json, set.png.
    #[arg(long)]
    pub out: PathBuf,
}

impl OptimizeArgs {
    fn area(&self) -> AreaOption {
        match self.area {
            AreaArg::Exact => AreaOption::Exact,
            AreaArg::Mc => AreaOption::MonteCarlo {
                samples: self.mc_samples,
            },
        }
    }

    fn path(&self) -> GradientPath {
        if self.dense {
            GradientPath::Dense
        } else {
            GradientPath::Fast
        }
    }

    /// The target SPEC, with the domain's default.
    pub fn density_spec(&self) -> String {
        self.density.clone().unwrap_or_else(|| {
            if self.domain == DomainArg::Square {
                "gaussian:0.5,0.5,0.15".into()
            } else {
                "uniform".into()
            }
        })
    }

    /// The 2D optimizer settings these arguments ask for.
    pub fn config(&self) -> OptimizeConfig {
        let d = OptimizeConfig::default();
        OptimizeConfig {
            epochs: self.epochs.unwrap_or(d.epochs),
            anchors: self.anchors.unwrap_or(d.anchors),
            anchor_sampling: match self.anchor_sampling {
                AnchorArg::Random => AnchorSampling::Random,
                AnchorArg::OwenSobol => AnchorSampling::OwenSobol,
            },
            learning_rate: self.lr.unwrap_or(d.learning_rate),
            alpha_start: self.alpha_start.unwrap_or(d.alpha_start),
            alpha_end: self.alpha_end.unwrap_or(d.alpha_end),
            area: self.area(),
            parameterization: match self.param {
                ParamArg::InverseCdf => Parameterization::InverseCdf,
                ParamArg::Direct => Parameterization::Direct,
            },
            path: self.path(),
            seed: self.seed,
            ..d
        }
    }

    /// The direction optimizer settings these arguments ask for.
    pub fn direction_config(&self) -> DirectionConfig {
        let d = DirectionConfig::default();
        DirectionConfig {
            epochs: self.epochs.unwrap_or(d.epochs),
            caps: self.caps.unwrap_or(d.caps),
            learning_rate: self.lr.unwrap_or(d.learning_rate),
            alpha_start: self.alpha_start.unwrap_or(d.alpha_start),
            alpha_end: self.alpha_end.unwrap_or(d.alpha_end),
            area: self.area(),
            path: self.path(),
            seed: self.seed,
            ..d
        }
    }

    fn validate(&self) -> Result<()> {
        ensure!(
            (1..=crate::baselines::OWEN_SOBOL_MAX_POINTS).contains(&self.n),
            "--n must be in 1..=65536, got {}",
            self.n
        );
        ensure!(self.sets >= 1, "--sets must be at least 1");
        ensure!(self.epochs != Some(0), "--epochs must be at least 1");
        ensure!(self.anchors != Some(0), "--anchors must be at least 1");
        ensure!(self.caps != Some(0), "--caps must be at least 1");
        for (name, v) in [
            ("--lr", self.lr),
            ("--alpha-start", self.alpha_start),
            ("--alpha-end", self.alpha_end),
        ] {
            if let Some(v) = v {
                ensure!(v.is_finite() && v > 0.0, "{name} must be positive, got {v}");
            }
        }
        ensure!(
            self.area == AreaArg::Exact || self.mc_samples >= 1,
            "--mc-samples must be at least 1"
        );
        Ok(())
    }
}

/// Metrics of a run, as written to report.json. `M` is the metric summary type of
/// the domain: [`MetricSummary`] for the square, [`CapMetricSummary`] for directions.
#[derive(Serialize)]
struct Report<'a, C: Serialize, M: Serialize> {
    density: &'a str,
    domain: &'static str,
    n: usize,
    sets: usize,
    seed: u64,
    settings: &'a C,
    threads: usize,
    wall_time_s: f64,
    optimize_time_s: f64,
    metric_method: String,
    /// Per set: the warped Owen-Sobol start and the optimized result.
    per_set: Vec<SetReport<M>>,
    /// Mean over sets of the optimized metrics.
    optimized_mean: M,
    /// Mean over `baseline_sets` Owen-Sobol sets of the same N warped by the
    /// target's standard sampler (inverse CDF; for directions the equal-area map,
    /// cosine, GGX-VNDF mixture or envmap sampler).
    baseline_warped_owen_sobol_mean: M,
    baseline_sets: usize,
    /// optimized_mean / baseline mean, per metric (below 1 is better).
    ratio_to_baseline: M,
}

#[derive(Serialize)]
struct SetReport<M: Serialize> {
    seed: u64,
    before: M,
    after: M,
    final_loss: f64,
}

/// A SPEC for picture titles: file paths shortened to their file name.
fn short_spec(spec: &str) -> String {
    match spec.split_once(':') {
        Some((kind, path)) if path.contains('/') => {
            let name = std::path::Path::new(path)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| path.to_string());
            format!("{kind}:{name}")
        }
        _ => spec.to_string(),
    }
}

/// A progress bar over all epochs of all sets.
fn progress(total: u64) -> ProgressBar {
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} {prefix} [{bar:30}] {pos}/{len} epochs  {msg}  ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar
}

/// Optimizes one set for a seed, reporting each epoch; returns its square points.
type SetOptimizer<'a> = dyn Fn(u64, &mut dyn FnMut(&EpochReport)) -> Vec<DVec2> + 'a;

/// Runs `optimize_set(seed, on_epoch)` for every set with a shared progress bar;
/// returns the sets, their final losses and the elapsed seconds.
fn run_sets(
    a: &OptimizeArgs,
    epochs: usize,
    optimize_set: &SetOptimizer<'_>,
) -> (Vec<Vec<DVec2>>, Vec<f64>, f64) {
    let started = Instant::now();
    let bar = progress((a.sets * epochs) as u64);
    let mut sets = Vec::with_capacity(a.sets);
    let mut losses = Vec::with_capacity(a.sets);
    for s in 0..a.sets {
        bar.set_prefix(format!("set {}/{}", s + 1, a.sets));
        let mut last = 0.0;
        let points = optimize_set(derive_seed(a.seed, s as u64), &mut |r| {
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
    (sets, losses, started.elapsed().as_secs_f64())
}

/// Writes the three outputs: the picture first, the blob last, each atomically.
fn write_outputs(
    a: &OptimizeArgs,
    ps: &PointSets,
    spec: &str,
    json: &str,
    picture: &dyn Fn(&std::path::Path) -> Result<()>,
) -> Result<()> {
    let blob = ps.to_blob(&Metadata {
        generator: "optimize",
        target: spec,
        seed: a.seed,
    })?;
    picture(&a.out.join("set.png"))?;
    crate::output::write_atomic(&a.out.join("report.json"), json.as_bytes())?;
    crate::output::write_atomic(&a.out.join("set.nuld"), blob.as_slice())
}

/// Runs `build-tool optimize`.
pub fn run(a: OptimizeArgs) -> Result<()> {
    a.validate()?;
    match a.domain {
        DomainArg::Square => run_square(&a),
        DomainArg::Sphere | DomainArg::Hemisphere => run_directions(&a),
    }
}

fn run_square(a: &OptimizeArgs) -> Result<()> {
    let spec_arg = a.density_spec();
    let density = parse_spec(&spec_arg).with_context(|| format!("--density {spec_arg}"))?;
    crate::output::ensure_dir(&a.out)?;
    let config = a.config();
    let started = Instant::now();
    let (sets, losses, optimize_time) = run_sets(a, config.epochs, &|seed, on_epoch| {
        let cfg = OptimizeConfig {
            seed,
            ..config.clone()
        };
        optimize(density.as_ref(), a.n, &cfg, on_epoch)
    });

    let target = Target::new(density.as_ref());
    let per_set: Vec<SetReport<MetricSummary>> = sets
        .iter()
        .zip(&losses)
        .enumerate()
        .map(|(s, (pts, &final_loss))| {
            let seed = derive_seed(a.seed, s as u64);
            SetReport {
                seed,
                before: target.evaluate(&warped_owen_sobol(density.as_ref(), a.n, seed)),
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
    let optimized = MetricSummary::mean(&per_set.iter().map(|r| r.after).collect::<Vec<_>>());
    let base = MetricSummary::mean(&baseline);
    let spec = density.spec();
    let report = Report {
        density: &spec,
        domain: Domain::Square.name(),
        n: a.n,
        sets: a.sets,
        seed: a.seed,
        settings: &config,
        threads: rayon::current_num_threads(),
        wall_time_s: started.elapsed().as_secs_f64(),
        optimize_time_s: optimize_time,
        metric_method: target.method(),
        per_set,
        optimized_mean: optimized,
        baseline_warped_owen_sobol_mean: base,
        baseline_sets: a.baseline_sets,
        ratio_to_baseline: MetricSummary {
            l2_star: optimized.l2_star / base.l2_star,
            asd: optimized.asd / base.asd,
            star: optimized.star / base.star,
        },
    };
    let ps = PointSets {
        domain: Domain::Square,
        sets,
    };
    let title = format!(
        "{} — N = {}, D2asd {:.2e} (warped Owen-Sobol {:.2e})",
        short_spec(&spec),
        a.n,
        optimized.asd,
        base.asd
    );
    write_outputs(
        a,
        &ps,
        &spec,
        &serde_json::to_string_pretty(&report)?,
        &|path| crate::plot::render_point_set(path, &title, &|p| density.pdf(p), &ps.sets[0], 900),
    )?;
    eprintln!(
        "optimized {} set(s) of {} points for {} in {:.1} s: D2asd {:.3e}, L2* {:.3e}, D* {:.3e} \
         (warped Owen-Sobol: {:.3e}, {:.3e}, {:.3e}) -> {}",
        a.sets,
        a.n,
        spec,
        optimize_time,
        optimized.asd,
        optimized.l2_star,
        optimized.star,
        base.asd,
        base.l2_star,
        base.star,
        a.out.display()
    );
    Ok(())
}

fn run_directions(a: &OptimizeArgs) -> Result<()> {
    let domain: Domain = a.domain.into();
    let spec_arg = a.density_spec();
    let density =
        parse_direction_spec(&spec_arg, domain).with_context(|| format!("--density {spec_arg}"))?;
    crate::output::ensure_dir(&a.out)?;
    let config = a.direction_config();
    let started = Instant::now();
    let (sets, losses, optimize_time) = run_sets(a, config.epochs, &|seed, on_epoch| {
        let cfg = DirectionConfig {
            seed,
            ..config.clone()
        };
        optimize_directions(density.as_ref(), a.n, &cfg, on_epoch)
    });
    let dirs_of = |square: &[DVec2]| -> Vec<DVec3> {
        square.iter().map(|&p| domain.to_direction(p)).collect()
    };
    let target = CapTarget::new(density.as_ref());
    let evaluate = |square: &[DVec2]| target.evaluate(&dirs_of(square));
    let per_set: Vec<SetReport<CapMetricSummary>> = sets
        .iter()
        .zip(&losses)
        .enumerate()
        .map(|(s, (pts, &final_loss))| {
            let seed = derive_seed(a.seed, s as u64);
            SetReport {
                seed,
                before: evaluate(&initial_square_points(density.as_ref(), a.n, seed)),
                after: evaluate(pts),
                final_loss,
            }
        })
        .collect();
    let baseline: Vec<CapMetricSummary> = (0..a.baseline_sets)
        .map(|b| {
            let seed = derive_seed(a.seed ^ 0xba5e, b as u64);
            evaluate(&initial_square_points(density.as_ref(), a.n, seed))
        })
        .collect();
    let optimized = CapMetricSummary::mean(&per_set.iter().map(|r| r.after).collect::<Vec<_>>());
    let base = CapMetricSummary::mean(&baseline);
    let spec = density.spec();
    let report = Report {
        density: &spec,
        domain: domain.name(),
        n: a.n,
        sets: a.sets,
        seed: a.seed,
        settings: &config,
        threads: rayon::current_num_threads(),
        wall_time_s: started.elapsed().as_secs_f64(),
        optimize_time_s: optimize_time,
        metric_method: target.method(),
        per_set,
        optimized_mean: optimized,
        baseline_warped_owen_sobol_mean: base,
        baseline_sets: a.baseline_sets,
        ratio_to_baseline: CapMetricSummary {
            cap_l2: optimized.cap_l2 / base.cap_l2,
            cap_l2_theta: optimized.cap_l2_theta / base.cap_l2_theta,
            cap_l2_theta_stderr: f64::NAN,
            cap_star_lower_bound: optimized.cap_star_lower_bound / base.cap_star_lower_bound,
        },
    };
    let ps = PointSets { domain, sets };
    let title = format!(
        "{} ({:?}), N = {}: cap L2 {:.2e} (Owen-Sobol {:.2e})",
        short_spec(&spec),
        domain,
        a.n,
        optimized.cap_l2,
        base.cap_l2
    );
    write_outputs(
        a,
        &ps,
        &spec,
        &serde_json::to_string_pretty(&report)?,
        &|path| {
            crate::plot::render_direction_set(
                path,
                &title,
                &|d| density.pdf(d),
                &|p| domain.to_direction(p),
                &ps.sets[0],
                700,
            )
        },
    )?;
    eprintln!(
        "optimized {} set(s) of {} directions for {} in {:.1} s: cap L2 {:.3e}, theta-uniform {:.3e}, \
         cap D* >= {:.3e} (Owen-Sobol via the standard sampler: {:.3e}, {:.3e}, {:.3e}) -> {}",
        a.sets,
        a.n,
        spec,
        optimize_time,
        optimized.cap_l2,
        optimized.cap_l2_theta,
        optimized.cap_star_lower_bound,
        base.cap_l2,
        base.cap_l2_theta,
        base.cap_star_lower_bound,
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
