//! The `build-tool` command line (README.md, "CLI").

pub mod bake;
pub mod bench;
pub mod eval;
pub mod export;
pub mod metrics;
pub mod optimize;
pub mod render;
pub mod sample;
pub mod shader;
pub mod sobol;

use clap::{Parser, Subcommand, ValueEnum};
use nuld_core::blob::Domain;

/// Bakes non-uniform low-discrepancy sample tables (`.nuld` blobs).
#[derive(Parser, Debug)]
#[command(name = "build-tool", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Write plain Owen-scrambled Sobol sets (2D, or mapped to the sphere/hemisphere).
    Sobol(sobol::SobolArgs),
    /// Print a blob's points as CSV: `set,index,x,y` (2D) or `set,index,x,y,z`.
    Export(export::ExportArgs),
    /// Print a conditional blob's samples at one condition (--cond) or normal (--normal) as CSV: `index,x,y,z,weight,pdf`.
    Sample(sample::SampleArgs),
    /// Optimize point sets for a target density: DIR/set.nuld, report.json, set.png.
    Optimize(optimize::OptimizeArgs),
    /// Exact discrepancies of a blob's point sets against a target density.
    Metrics(metrics::MetricsArgs),
    /// Train and distill a conditional sampler (--brdf, or --envmap MAP): DIR/brdf.nuld or DIR/envmap.nuld, report.json, loss.png, sets.png.
    Bake(bake::BakeArgs),
    /// Time the optimizer (fast vs dense gradient per epoch, full default runs); with --only, the baselines, the runtime samplers against the incumbents, the environment prior or training.
    Bench(bench::BenchArgs),
    /// Write the sampling kernel (WGSL sampler + compute entry point) in a shading language.
    Shader(shader::ShaderArgs),
    /// Render the Fig. 8 evaluation (BRDF and envmap sampling vs a reference): DIR/render.csv, PNGs.
    Render(render::RenderArgs),
    /// Evaluate the paper's §5 figures (fig2, fig3, fig5, fig6, fig7, all): CSV, JSON, plots.
    Eval(Box<eval::EvalArgs>),
}

/// `--domain` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DomainArg {
    /// The unit square.
    Square,
    /// The unit sphere.
    Sphere,
    /// The upper hemisphere.
    Hemisphere,
}

impl From<DomainArg> for Domain {
    fn from(d: DomainArg) -> Self {
        match d {
            DomainArg::Square => Domain::Square,
            DomainArg::Sphere => Domain::Sphere,
            DomainArg::Hemisphere => Domain::Hemisphere,
        }
    }
}

/// Parses a count argument (`--n`, `--sets`, `--epochs`, ...): a whole number
/// `>= 0`; the command's own range check (often `>= 1`) comes after. The arguments
/// that use it accept values starting with `-`, so that `--n -5` is reported as a
/// negative count instead of as an unknown argument `-5`.
pub(crate) fn count(s: &str) -> Result<usize, String> {
    s.parse::<usize>().map_err(|e| {
        let negative = s
            .strip_prefix('-')
            .is_some_and(|digits| digits.parse::<u128>().is_ok());
        if negative {
            format!("{s} is negative; a count is a whole number >= 0")
        } else {
            e.to_string()
        }
    })
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Sobol(a) => sobol::run(a),
        Command::Bake(a) => bake::run(a),
        Command::Export(a) => export::run(a),
        Command::Sample(a) => sample::run(a),
        Command::Optimize(a) => optimize::run(a),
        Command::Metrics(a) => metrics::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Eval(a) => eval::run(*a),
        Command::Shader(a) => shader::run(a),
        Command::Render(a) => render::run(a),
    }
}
