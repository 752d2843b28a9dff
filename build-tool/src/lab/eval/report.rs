//! The outputs of a figure: `figN.csv`, `figN.json`, `figN-summary.md` and one
//! log-log PNG per (target, metric), all written atomically.

use super::cache::sanitize;
use super::figures::{MetricDef, Panel, Skipped};
use super::methods::EVAL_SEED;
use super::rows::{Row, CSV_COLUMNS};
use super::{EvalSettings, Figure};
use crate::plot::{render_loglog, Series};
use anyhow::Result;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Size of the plots.
pub const PLOT_SIZE: (u32, u32) = (1000, 700);

/// A method as the JSON report lists it.
#[derive(Clone, Debug, Serialize)]
pub struct MethodReport {
    /// Name.
    pub name: String,
    /// How it makes points for this panel.
    pub description: String,
    /// Realizations per N.
    pub realizations: usize,
}

/// A panel as the JSON report lists it.
#[derive(Clone, Debug, Serialize)]
pub struct PanelReport {
    /// Short name (CSV `target`).
    pub target: String,
    /// Title.
    pub title: String,
    /// Target density SPEC.
    pub spec: String,
    /// Conventions and remarks.
    pub notes: Vec<String>,
    /// Reported metrics.
    pub metrics: Vec<MetricDef>,
    /// Methods.
    pub methods: Vec<MethodReport>,
    /// The plot files, one per metric.
    pub plots: Vec<String>,
}

/// Settings as the JSON report lists them (what determines the numbers).
#[derive(Clone, Debug, Serialize)]
pub struct SettingsReport {
    /// Point counts.
    pub sizes: Vec<usize>,
    /// `--quick` in use.
    pub quick: bool,
    /// Baseline realizations per N.
    pub realizations_baseline: usize,
    /// Our realizations per N.
    pub realizations_ours: usize,
    /// Epochs of the 2D optimizer.
    pub epochs_2d: usize,
    /// Epochs of the direction optimizer.
    pub epochs_directions: usize,
    /// Random caps of the cap star search.
    pub cap_star_random_caps: usize,
    /// Caps refined by the cap star search.
    pub cap_star_refine: usize,
    /// Hill-climbing rounds per refined cap.
    pub cap_star_rounds: usize,
    /// Random caps of the Monte Carlo non-uniform cap L2.
    pub cap_l2_caps: usize,
    /// Subpixel grid side of the `brdf-envmap` reference.
    pub reference_subdivision: usize,
    /// Data directory.
    pub data: String,
    /// How seeds are derived.
    pub seeds: String,
}

/// Everything `figN.json` holds.
#[derive(Clone, Debug, Serialize)]
pub struct FigureReport {
    /// `fig2` ... `fig7`.
    pub figure: String,
    /// What the figure shows.
    pub title: String,
    /// Settings.
    pub settings: SettingsReport,
    /// Panels.
    pub panels: Vec<PanelReport>,
    /// Panels left out (missing data).
    pub skipped: Vec<Skipped>,
    /// The CSV's columns.
    pub columns: Vec<String>,
    /// The CSV's rows.
    pub rows: Vec<Row>,
}

/// One-line description of a figure.
pub fn figure_title(f: Figure) -> &'static str {
    match f {
        Figure::Fig2 => "2D uniform: L2-star and star discrepancy vs N",
        Figure::Fig3 => "uniform sphere: cap L2 and cap star discrepancy vs N",
        Figure::Fig5 => {
            "2D non-uniform targets: L2 (asd, L2-star) and star discrepancy D*(mu) vs N"
        }
        Figure::Fig6 => "non-uniform directions: cap L2 and cap star discrepancy vs N",
        Figure::Fig7 => "integration RMSE over independent realizations vs N",
    }
}

/// File name of a panel's plot for one metric: `figN-<target>-<metric>.png`.
pub fn plot_name(f: Figure, target: &str, metric: &str) -> String {
    format!("{}-{}-{}.png", f.name(), sanitize(target), sanitize(metric))
}

impl FigureReport {
    /// Assembles the report of a figure run.
    pub fn new(
        figure: Figure,
        s: &EvalSettings,
        panels: &[Panel],
        skipped: Vec<Skipped>,
        rows: Vec<Row>,
    ) -> Self {
        let panels = panels
            .iter()
            .map(|p| {
                let sphere = matches!(
                    p.kind,
                    super::figures::PanelKind::SphereDiscrepancy { .. }
                        | super::figures::PanelKind::SphereIntegral(_)
                );
                PanelReport {
                    target: p.target.clone(),
                    title: p.title.clone(),
                    spec: p.spec.clone(),
                    notes: p.notes.clone(),
                    metrics: p.metrics.clone(),
                    methods: p
                        .methods
                        .iter()
                        .map(|m| MethodReport {
                            name: m.name().into(),
                            description: m.description(sphere),
                            realizations: m.realizations(s),
                        })
                        .collect(),
                    plots: p
                        .metrics
                        .iter()
                        .map(|m| plot_name(figure, &p.target, m.key))
                        .collect(),
                }
            })
            .collect();
        Self {
            figure: figure.name().into(),
            title: format!("{}: {}", figure.label(), figure_title(figure)),
            settings: SettingsReport {
                sizes: s.sizes(),
                quick: s.quick,
                realizations_baseline: s.realizations_baseline,
                realizations_ours: s.realizations_ours,
                epochs_2d: s.epochs,
                epochs_directions: s.direction_epochs,
                cap_star_random_caps: s.cap_star_caps,
                cap_star_refine: s.cap_star_refine,
                cap_star_rounds: s.cap_star_rounds,
                cap_l2_caps: s.cap_l2_caps,
                reference_subdivision: s.reference_subdivision,
                data: s.data.display().to_string(),
                seeds: format!(
                    "realization r uses seed derive_seed({EVAL_SEED:#x}, r) for every method and N (cache files are named by r)"
                ),
            },
            panels,
            skipped,
            columns: CSV_COLUMNS.iter().map(|c| c.to_string()).collect(),
            rows,
        }
    }

    /// The CSV text: a header line, then one line per row (numbers in Rust's
    /// shortest round-trip exponent form).
    pub fn csv(&self) -> String {
        let mut out = CSV_COLUMNS.join(",");
        out.push('\n');
        for r in &self.rows {
            let _ = writeln!(
                out,
                "{},{},{},{},{:e},{:e},{}",
                r.target, r.metric, r.method, r.n, r.mean, r.stderr, r.realizations
            );
        }
        out
    }

    /// The [`summary`](super::summary) of the rows as a Markdown table.
    pub fn summary_markdown(&self) -> String {
        super::summary::markdown(&self.figure, &super::summary::summarize(&self.rows))
    }

    /// Writes `figN.csv`, `figN.json`, `figN-summary.md` and the plots into `dir`;
    /// returns the paths.
    pub fn write(&self, dir: &Path, panels: &[Panel]) -> Result<Vec<PathBuf>> {
        let mut written = Vec::new();
        let csv = dir.join(format!("{}.csv", self.figure));
        crate::output::write_atomic(&csv, self.csv().as_bytes())?;
        written.push(csv);
        let json = dir.join(format!("{}.json", self.figure));
        let mut text = serde_json::to_string_pretty(self)?;
        text.push('\n');
        crate::output::write_atomic(&json, text.as_bytes())?;
        written.push(json);
        let summary = dir.join(format!("{}-summary.md", self.figure));
        crate::output::write_atomic(&summary, self.summary_markdown().as_bytes())?;
        written.push(summary);
        let figure = Figure::ALL
            .into_iter()
            .find(|f| f.name() == self.figure)
            .unwrap_or(Figure::Fig2);
        for p in panels {
            for metric in &p.metrics {
                let series: Vec<Series> = p
                    .methods
                    .iter()
                    .map(|m| Series {
                        label: m.name().into(),
                        points: self
                            .rows
                            .iter()
                            .filter(|r| {
                                r.target == p.target
                                    && r.metric == metric.key
                                    && r.method == m.name()
                            })
                            .map(|r| (r.n as f64, r.mean))
                            .collect(),
                    })
                    .collect();
                let path = dir.join(plot_name(figure, &p.target, metric.key));
                let title = format!("{} — {}: {}", figure.label(), p.title, metric.label);
                render_loglog(&path, &title, "N", metric.label, &series, PLOT_SIZE)?;
                written.push(path);
            }
        }
        Ok(written)
    }
}
