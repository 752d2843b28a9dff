//! `build-tool eval FIG --out DIR`: the paper's §5 figures (see [`crate::eval`]).

use crate::eval::{run_figure, EvalSettings, Figure};
use anyhow::Result;
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::time::Instant;

/// `FIG` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FigArg {
    /// 2D uniform: L2-star and exact D* (ours, random, owen-sobol, sobol-cp,
    /// halton, poisson-disk, sot, gbn).
    Fig2,
    /// Uniform sphere: cap L2 (Stolarsky) and cap D* lower bound.
    Fig3,
    /// 2D non-uniform targets: asd, L2-star, D*(mu).
    Fig5,
    /// Non-uniform directions: cap L2 (energy form), cap D* lower bound.
    Fig6,
    /// Integration RMSE.
    Fig7,
    /// Every figure, in order.
    All,
}

/// Arguments of `build-tool eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// Which figure.
    #[arg(value_enum)]
    pub fig: FigArg,
    /// Output directory: figN.csv, figN.json, figN-<target>-<metric>.png, cache/.
    #[arg(long)]
    pub out: PathBuf,
    /// Largest N (sizes 4, 8, ..., max-n) [default: 4096, --quick: 64].
    #[arg(long)]
    pub max_n: Option<usize>,
    /// Reduced settings for a smoke run: N <= 64, 8 / 2 realizations, 200 / 100
    /// epochs, cheaper metrics.
    #[arg(long)]
    pub quick: bool,
    /// Realizations per N for baselines [default: 128, --quick: 8].
    #[arg(long)]
    pub realizations_baseline: Option<usize>,
    /// Realizations per N for ours [default: 16, --quick: 2].
    #[arg(long)]
    pub realizations_ours: Option<usize>,
    /// Epochs of our 2D optimizer [default: 1000, --quick: 200].
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Epochs of our direction optimizer [default: 5000, --quick: 100].
    #[arg(long)]
    pub direction_epochs: Option<usize>,
    /// Random caps of the cap star discrepancy search [default: 20000, --quick: 500]
    /// (each costs one cap measure: ~0.5 ms for the environment map).
    #[arg(long)]
    pub cap_star_caps: Option<usize>,
    /// Data directory with images/camera.png and envmaps/courtyard.hdr; panels whose
    /// file is missing are skipped with a note.
    #[arg(long, default_value = "../shared/data")]
    pub data: PathBuf,
}

impl EvalArgs {
    /// The settings these arguments ask for.
    pub fn settings(&self) -> EvalSettings {
        let mut s = if self.quick {
            EvalSettings::quick(&self.out, &self.data)
        } else {
            EvalSettings::full(&self.out, &self.data)
        };
        if let Some(v) = self.max_n {
            s.max_n = v;
        }
        if let Some(v) = self.realizations_baseline {
            s.realizations_baseline = v;
        }
        if let Some(v) = self.realizations_ours {
            s.realizations_ours = v;
        }
        if let Some(v) = self.epochs {
            s.epochs = v;
        }
        if let Some(v) = self.direction_epochs {
            s.direction_epochs = v;
        }
        if let Some(v) = self.cap_star_caps {
            s.cap_star_caps = v;
        }
        s
    }
}

/// Runs `build-tool eval`.
pub fn run(a: EvalArgs) -> Result<()> {
    let s = a.settings();
    s.validate()?;
    let figures: Vec<Figure> = match a.fig {
        FigArg::Fig2 => vec![Figure::Fig2],
        FigArg::Fig3 => vec![Figure::Fig3],
        FigArg::Fig5 => vec![Figure::Fig5],
        FigArg::Fig6 => vec![Figure::Fig6],
        FigArg::Fig7 => vec![Figure::Fig7],
        FigArg::All => Figure::ALL.to_vec(),
    };
    for f in figures {
        let started = Instant::now();
        let rep = run_figure(f, &s)?;
        print!("{}", rep.summary_markdown());
        eprintln!(
            "{f}: {} rows, {} panel(s){} in {:.1} s -> {}",
            rep.rows.len(),
            rep.panels.len(),
            if rep.skipped.is_empty() {
                String::new()
            } else {
                format!(" ({} skipped)", rep.skipped.len())
            },
            started.elapsed().as_secs_f64(),
            s.out.display()
        );
    }
    Ok(())
}
