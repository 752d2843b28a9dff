//! The `build-tool` command line (DESIGN.md §3).

pub mod export;
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

/// Runs a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Sobol(a) => sobol::run(a),
        Command::Export(a) => export::run(a),
    }
}
