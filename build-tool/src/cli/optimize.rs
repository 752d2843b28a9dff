//! `build-tool optimize`: optimize point sets for a target and write the blob, a
//! JSON report with exact metrics against the warped Owen-Sobol baseline, and a
//! picture.

use super::DomainArg;
use crate::discrepancy::GradientPath;
use crate::metrics::Summary;
use crate::optimize::directions::DirectionConfig;
use crate::optimize::run::{
    run as run_problem, DirectionProblem, Problem, RunSettings, SquareProblem,
};
use crate::optimize::{AnchorSampling, AreaOption, OptimizeConfig, Parameterization};
use anyhow::{ensure, Context, Result};
use clap::{Args, ValueEnum};
use nuld_core::blob::Metadata;
use std::path::PathBuf;

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
    /// hemisphere: `uniform`, `cosine`, `brdf:ROUGHNESS,THETA_O_DEG`, `envmap:PATH`.
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

/// Runs `build-tool optimize`.
pub fn run(a: OptimizeArgs) -> Result<()> {
    a.validate()?;
    let spec = a.density_spec();
    let context = || format!("--density {spec}");
    match a.domain {
        DomainArg::Square => {
            let problem = SquareProblem::parse(&spec).with_context(context)?;
            optimize_and_write(&a, &problem, &a.config())
        }
        DomainArg::Sphere | DomainArg::Hemisphere => {
            let problem = DirectionProblem::parse(&spec, a.domain.into()).with_context(context)?;
            optimize_and_write(&a, &problem, &a.direction_config())
        }
    }
}

/// Optimizes, then writes the three outputs (the picture first, the blob last, each
/// atomically) and prints one summary line.
fn optimize_and_write<P: Problem>(a: &OptimizeArgs, problem: &P, config: &P::Config) -> Result<()> {
    crate::output::ensure_dir(&a.out)?;
    let settings = RunSettings {
        n: a.n,
        sets: a.sets,
        seed: a.seed,
        baseline_sets: a.baseline_sets,
    };
    let run = run_problem(problem, &settings, config);
    let report = &run.report;
    let blob = run.points.to_blob(&Metadata {
        generator: "optimize",
        target: &report.density,
        seed: a.seed,
    })?;
    let (ours, base) = (
        report.optimized_mean.values(),
        report.baseline_warped_owen_sobol_mean.values(),
    );
    let label = P::Summary::LABELS[0];
    let title = format!(
        "{} ({}), N = {}: {label} {:.2e} (warped Owen-Sobol {:.2e})",
        short_spec(&report.density),
        report.domain,
        a.n,
        ours[0],
        base[0]
    );
    problem.render(&a.out.join("set.png"), &title, &run.points.sets[0])?;
    let json = serde_json::to_string_pretty(report)?;
    crate::output::write_atomic(&a.out.join("report.json"), json.as_bytes())?;
    crate::output::write_atomic(&a.out.join("set.nuld"), blob.as_slice())?;
    let list = |v: &[f64]| {
        P::Summary::LABELS
            .iter()
            .zip(v)
            .map(|(l, x)| format!("{l} {x:.3e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    eprintln!(
        "optimized {} set(s) of {} {} points for {} in {:.1} s (report {:.1} s): {} \
         (warped Owen-Sobol: {}) -> {}",
        a.sets,
        a.n,
        report.domain,
        report.density,
        report.optimize_time_s,
        report.report_time_s,
        list(&ours),
        list(&base),
        a.out.display()
    );
    Ok(())
}
