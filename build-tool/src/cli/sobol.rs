//! `build-tool sobol`: Owen-scrambled Sobol sets written as a blob.

use crate::baselines::{owen_sobol, OWEN_SOBOL_MAX_POINTS};
use crate::pointset::PointSets;
use crate::seeding::derive_seed;
use anyhow::{ensure, Result};
use clap::Args;
use nuld_core::blob::Metadata;
use std::path::PathBuf;

/// Arguments of `build-tool sobol`.
#[derive(Args, Debug)]
pub struct SobolArgs {
    /// Where the points live; sphere/hemisphere sets are stored in the equal-area square.
    #[arg(long, value_enum, default_value = "square")]
    pub domain: super::DomainArg,
    /// Points per set.
    #[arg(long, default_value_t = 256, allow_negative_numbers = true, value_parser = super::count)]
    pub n: usize,
    /// Number of independently scrambled sets.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = super::count)]
    pub sets: usize,
    /// Seed of the scrambles.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output blob path.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `build-tool sobol`.
pub fn run(a: SobolArgs) -> Result<()> {
    ensure!(
        (1..=OWEN_SOBOL_MAX_POINTS).contains(&a.n),
        "--n must be in 1..={OWEN_SOBOL_MAX_POINTS}, got {}",
        a.n
    );
    ensure!(a.sets >= 1, "--sets must be at least 1");
    let sets = (0..a.sets)
        .map(|s| owen_sobol(a.n, derive_seed(a.seed, s as u64) as u32))
        .collect();
    let ps = PointSets {
        domain: a.domain.into(),
        sets,
    };
    let meta = Metadata {
        generator: "owen-sobol",
        target: "uniform",
        seed: a.seed,
    };
    ps.write_blob(&a.out, &meta)?;
    eprintln!(
        "wrote {} ({} set(s) x {} points, {:?})",
        a.out.display(),
        a.sets,
        a.n,
        ps.domain
    );
    Ok(())
}
