//! `build-tool bake --brdf`: train the conditional BRDF sampler and write its blob,
//! report and pictures (library: [`crate::conditional::bake`]).

use crate::conditional::bake::{bake, BakeConfig};
use crate::train::TrainConfig;
use anyhow::{ensure, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `build-tool bake`.
#[derive(Args, Debug)]
pub struct BakeArgs {
    /// Bake the glTF 2.0 BRDF sampler (condition: roughness, view angle).
    #[arg(long)]
    pub brdf: bool,
    /// Points per set.
    #[arg(long, default_value_t = 64, allow_negative_numbers = true, value_parser = super::count)]
    pub n: usize,
    /// Instances stored in the point table.
    #[arg(long, default_value_t = 16, allow_negative_numbers = true, value_parser = super::count)]
    pub instances: usize,
    /// Point-table grid nodes: roughness,theta_o (each >= 2).
    #[arg(long, default_value = "10,12")]
    pub grid: String,
    /// Training steps after 300 steps of pretraining on the warp [default: 12000, about 7 min on 2 cores]
    #[arg(long, allow_negative_numbers = true, value_parser = super::count)]
    pub steps: Option<usize>,
    /// Seed; fixes the output bit for bit whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Continue from DIR/checkpoint.bin (same options as the interrupted run).
    #[arg(long)]
    pub resume: bool,
    /// Hidden widths, comma-separated (1 to 3 layers).
    #[arg(long)]
    pub hidden: Option<String>,
    /// SiLU hidden units instead of ReLU.
    #[arg(long)]
    pub silu: bool,
    /// Weight of the union-of-instances term.
    #[arg(long)]
    pub union_weight: Option<f64>,
    /// Initial Adam step.
    #[arg(long)]
    pub lr: Option<f64>,
    /// Held-out conditions per axis of the quality check in the report (0: none).
    #[arg(long, default_value_t = 4, allow_negative_numbers = true, value_parser = super::count)]
    pub quality_grid: usize,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

fn numbers(s: &str, what: &str) -> Result<Vec<u32>> {
    s.split(',')
        .map(|x| {
            x.trim()
                .parse::<u32>()
                .map_err(|_| anyhow::anyhow!("{what}: {x:?} is not a whole number"))
        })
        .collect()
}

/// Runs `build-tool bake`.
pub fn run(a: BakeArgs) -> Result<()> {
    ensure!(a.brdf, "bake needs a target: --brdf");
    ensure!(
        a.n >= 1 && a.n <= 1 << 16,
        "--n must be in 1..=65536, got {}",
        a.n
    );
    ensure!(
        a.instances >= 1 && a.instances <= 1 << 16,
        "--instances must be in 1..=65536, got {}",
        a.instances
    );
    let grid = numbers(&a.grid, "--grid")?;
    ensure!(
        grid.len() == 2 && grid.iter().all(|&g| (2..=256).contains(&g)),
        "--grid must be two node counts in 2..=256, like 10,12"
    );
    let mut train = TrainConfig {
        n: a.n as u32,
        seed: a.seed,
        silu: a.silu,
        ..TrainConfig::default()
    };
    if let Some(s) = a.steps {
        ensure!(s >= 1, "--steps must be at least 1");
        train.steps = s;
    }
    if let Some(h) = &a.hidden {
        train.hidden = numbers(h, "--hidden")?;
    }
    if let Some(w) = a.union_weight {
        ensure!(
            w.is_finite() && w >= 0.0,
            "--union-weight must be finite and >= 0"
        );
        train.union_weight = w;
    }
    if let Some(lr) = a.lr {
        ensure!(lr.is_finite() && lr > 0.0, "--lr must be finite and > 0");
        train.learning_rate = lr;
    }
    let config = BakeConfig {
        train,
        instances: a.instances as u32,
        grid: [grid[0], grid[1]],
        quality_grid: a.quality_grid,
        resume: a.resume,
        ..BakeConfig::default()
    };
    let report = bake(&config, &a.out)?;
    let mut line = format!(
        "wrote {} ({} bytes, {} parameters) in {:.1} s",
        a.out.join("brdf.nuld").display(),
        report.blob_bytes,
        report.parameters,
        report.timings.total_s
    );
    if let Some(q) = &report.quality {
        line += &format!(
            "; held-out cap L2 / warped Owen-Sobol: mean {:.3}, worst {:.3}; union {:.3}, nn {:.3}",
            q.mean_ratio, q.worst_ratio, q.mean_union_ratio, q.mean_nn_ratio
        );
    }
    println!("{line}");
    Ok(())
}
