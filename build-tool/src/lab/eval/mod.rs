//! The evaluation harness: the paper's §5 figures as CSV, JSON and log-log plots.
//!
//! * Fig. 2: 2D uniform — L2-star and exact star discrepancy vs N.
//! * Fig. 3: uniform sphere — cap L2 (Stolarsky, exact) and a cap star lower bound.
//! * Fig. 5: 2D non-uniform targets — asd, L2-star (exact for the target's cell
//!   tabulation) and exact `D*(mu)`, ours vs warped baselines.
//! * Fig. 6: directions, non-uniform targets — cap L2 (Monte Carlo over caps with
//!   exact cap measures) and the cap star lower bound, ours vs baselines warped by the target's standard sampler.
//! * Fig. 7: integration RMSE over independent realizations
//!   ([`integrands`] lists the integrands and their reference values).
//!
//! [`figures`] defines every figure's panels (targets, methods, metrics),
//! [`runner`] evaluates them with an on-disk [`cache`] of per-realization results
//! (reruns skip finished work and reproduce the output byte for byte) into
//! [`rows`], and [`report`] writes `figN.csv`, `figN.json`, `figN-<target>-<metric>.png` and
//! `figN-summary.md` ([`summary`]: ours against the best other method).
//! Everything is deterministic given the seeds ([`methods::realization_seed`]).
//!
//! [`envmap_prior`] measures an environment map's product warp as a prior, by
//! normal grid and table size (`build-tool eval envmap-prior`).
//!
//! [`conditional`] is the quality report of a conditional BRDF sampler (paper §4)
//! on held-out conditions (`build-tool eval conditional`).

pub mod brdf_prior;
pub mod brdf_sampler;
pub mod cache;
pub mod conditional;
pub mod envmap_prior;
pub mod figures;
pub mod integrands;
pub mod methods;
pub mod prior_judge;
pub mod report;
pub mod rows;
pub mod runner;
pub mod stats;
pub mod summary;

use anyhow::{ensure, Result};
use serde::Serialize;
use std::path::PathBuf;

/// A figure of the paper's §5.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Figure {
    /// 2D uniform discrepancy.
    Fig2,
    /// Uniform sphere discrepancy.
    Fig3,
    /// 2D non-uniform discrepancy.
    Fig5,
    /// Non-uniform direction discrepancy.
    Fig6,
    /// Integration error.
    Fig7,
}

impl Figure {
    /// Every figure, in order.
    pub const ALL: [Figure; 5] = [
        Figure::Fig2,
        Figure::Fig3,
        Figure::Fig5,
        Figure::Fig6,
        Figure::Fig7,
    ];

    /// `fig2`, `fig3`, `fig5`, `fig6` or `fig7` (file-name prefix).
    pub fn name(self) -> &'static str {
        match self {
            Figure::Fig2 => "fig2",
            Figure::Fig3 => "fig3",
            Figure::Fig5 => "fig5",
            Figure::Fig6 => "fig6",
            Figure::Fig7 => "fig7",
        }
    }

    /// The figure number as the paper writes it (`Fig. 2`).
    pub fn label(self) -> &'static str {
        match self {
            Figure::Fig2 => "Fig. 2",
            Figure::Fig3 => "Fig. 3",
            Figure::Fig5 => "Fig. 5",
            Figure::Fig6 => "Fig. 6",
            Figure::Fig7 => "Fig. 7",
        }
    }
}

impl std::fmt::Display for Figure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Everything that controls an evaluation run. Only the fields that change results
/// enter the cache fingerprints; the JSON report lists them all.
#[derive(Clone, Debug, Serialize)]
pub struct EvalSettings {
    /// Output directory (`figN.*` files and `cache/`).
    pub out: PathBuf,
    /// Data directory holding `images/camera.png` and `envmaps/courtyard.hdr`.
    pub data: PathBuf,
    /// Largest N; the sizes are the powers of two `4, 8, ..., max_n`.
    pub max_n: usize,
    /// Whether the reduced `--quick` settings are in use.
    pub quick: bool,
    /// Realizations per (method, N) for baselines (paper: 128).
    pub realizations_baseline: usize,
    /// Realizations per (method, N) for ours (paper: 16).
    pub realizations_ours: usize,
    /// Epochs of our 2D optimizer (paper: 1000).
    pub epochs: usize,
    /// Epochs of our direction optimizer (paper: 5000).
    pub direction_epochs: usize,
    /// Random caps of the cap star discrepancy search (then refined).
    pub cap_star_caps: usize,
    /// Best random caps refined by the cap star search (radius sweeps and hill
    /// climbing; each sweep costs a cap-measure profile).
    pub cap_star_refine: usize,
    /// Hill-climbing rounds per refined cap.
    pub cap_star_rounds: usize,
    /// Random caps of the Monte Carlo estimate of the non-uniform cap L2
    /// discrepancy (per point set; unbiased for `D^2`).
    pub cap_l2_caps: usize,
    /// Per-pixel midpoint grid side of the `brdf-envmap` reference quadrature.
    pub reference_subdivision: usize,
    /// Panels to run, by short name (the CSV `target` column); empty runs every
    /// panel. A filter, not a result-changing setting: a panel's rows are the same
    /// whether it runs alone or with the others.
    pub only_panels: Vec<String>,
}

impl EvalSettings {
    /// The full settings (the paper's): N up to 4096, 128 / 16 realizations, 1000 /
    /// 5000 epochs,
    /// 20000 random caps with 16 refined over 12 rounds (the sphere module's
    /// defaults), 4096 caps for the Monte Carlo cap L2, 8x8 subpixels.
    pub fn full(out: impl Into<PathBuf>, data: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            data: data.into(),
            max_n: 4096,
            quick: false,
            realizations_baseline: 128,
            realizations_ours: 16,
            epochs: 1000,
            direction_epochs: 5000,
            cap_star_caps: 20_000,
            cap_star_refine: 16,
            cap_star_rounds: 12,
            cap_l2_caps: 4096,
            reference_subdivision: 8,
            only_panels: Vec::new(),
        }
    }

    /// The `--quick` settings: N up to 64, 8 / 2 realizations, 200 / 100 epochs, 500 random caps with 4 refined over 6 rounds, 512
    /// caps for the Monte Carlo cap L2, 4x4 subpixels.
    pub fn quick(out: impl Into<PathBuf>, data: impl Into<PathBuf>) -> Self {
        Self {
            max_n: 64,
            quick: true,
            realizations_baseline: 8,
            realizations_ours: 2,
            epochs: 200,
            direction_epochs: 100,
            cap_star_caps: 500,
            cap_star_refine: 4,
            cap_star_rounds: 6,
            cap_l2_caps: 512,
            reference_subdivision: 4,
            ..Self::full(out, data)
        }
    }

    /// The point counts `4, 8, ..., max_n` (powers of two).
    pub fn sizes(&self) -> Vec<usize> {
        std::iter::successors(Some(4usize), |n| Some(n * 2))
            .take_while(|n| *n <= self.max_n)
            .collect()
    }

    /// Checks the settings (`max_n` in `4..=65536`, at least one realization and
    /// one epoch, non-zero metric effort).
    pub fn validate(&self) -> Result<()> {
        ensure!(
            (4..=crate::baselines::OWEN_SOBOL_MAX_POINTS).contains(&self.max_n),
            "--max-n must be in 4..=65536, got {}",
            self.max_n
        );
        ensure!(
            self.realizations_baseline >= 1 && self.realizations_ours >= 1,
            "realization counts must be at least 1"
        );
        ensure!(
            self.epochs >= 1 && self.direction_epochs >= 1,
            "epochs must be at least 1"
        );
        ensure!(
            self.cap_star_caps >= 1 && self.cap_l2_caps >= 1 && self.reference_subdivision >= 1,
            "metric settings must be positive"
        );
        Ok(())
    }
}

/// Evaluates `figure` with `settings` and writes its outputs; returns the report.
pub fn run_figure(figure: Figure, settings: &EvalSettings) -> Result<report::FigureReport> {
    settings.validate()?;
    crate::output::ensure_dir(&settings.out)?;
    let cache = cache::Cache::new(settings.out.join("cache"));
    let (panels, skipped) = figures::panels(figure, settings)?;
    let (panels, skipped) = figures::select(figure, panels, skipped, &settings.only_panels)?;
    for s in &skipped {
        eprintln!("{figure}: skipping {}: {}", s.target, s.reason);
    }
    let mut rows = Vec::new();
    for panel in &panels {
        rows.extend(runner::run_panel(figure, panel, settings, &cache)?);
    }
    let rep = report::FigureReport::new(figure, settings, &panels, skipped, rows);
    rep.write(&settings.out, &panels)?;
    Ok(rep)
}
