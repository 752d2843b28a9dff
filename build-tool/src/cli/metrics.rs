//! `build-tool metrics`: exact discrepancies of a blob's point sets against a target.

use super::DomainArg;
use crate::density::parse_spec;
use crate::metrics::summary::{MetricSummary, Target};
use crate::pointset::AlignedBytes;
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use glam::DVec2;
use nuld_runtime::Blob;
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `build-tool metrics`.
#[derive(Args, Debug)]
pub struct MetricsArgs {
    /// The blob to evaluate.
    pub file: PathBuf,
    /// Target density SPEC the points are meant to follow.
    #[arg(long, default_value = "uniform")]
    pub density: String,
    /// Domain; only `square` in this version.
    #[arg(long, value_enum, default_value = "square")]
    pub domain: DomainArg,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct MetricsOutput<'a> {
    file: String,
    density: &'a str,
    n: usize,
    method: String,
    per_set: Vec<MetricSummary>,
    mean: MetricSummary,
}

/// Runs `build-tool metrics`.
pub fn run(a: MetricsArgs) -> Result<()> {
    if a.domain != DomainArg::Square {
        bail!(
            "--domain {:?} is not supported yet: only square-domain metrics in this version",
            a.domain
        );
    }
    let density = parse_spec(&a.density).with_context(|| format!("--density {}", a.density))?;
    let bytes = AlignedBytes::read(&a.file)?;
    let blob = Blob::parse(bytes.as_slice()).map_err(|e| anyhow!("{}: {e}", a.file.display()))?;
    let pts = blob
        .point_set_2d()
        .map_err(|e| anyhow!("{}: {e}", a.file.display()))?;
    // The metrics of exactly what a renderer reads: the decoded (quantized) points.
    let sets: Vec<Vec<DVec2>> = (0..pts.set_count())
        .map(|s| (0..pts.len()).map(|i| pts.point(s, i).as_dvec2()).collect())
        .collect();
    let target = Target::new(density.as_ref());
    let per_set: Vec<MetricSummary> = sets.iter().map(|s| target.evaluate(s)).collect();
    let out = MetricsOutput {
        file: a.file.display().to_string(),
        density: &a.density,
        n: pts.len(),
        method: target.method(),
        mean: MetricSummary::mean(&per_set),
        per_set,
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!(
            "{} ({} set(s) x {} points) against {}",
            out.file,
            pts.set_count(),
            out.n,
            a.density
        );
        println!(
            "{:>5} {:>12} {:>12} {:>12}",
            "set", "D2asd", "L2-star", "D*"
        );
        for (s, m) in out.per_set.iter().enumerate() {
            println!(
                "{s:>5} {:>12.5e} {:>12.5e} {:>12.5e}",
                m.asd, m.l2_star, m.star
            );
        }
        println!(
            "{:>5} {:>12.5e} {:>12.5e} {:>12.5e}",
            "mean", out.mean.asd, out.mean.l2_star, out.mean.star
        );
        println!("({})", out.method);
    }
    Ok(())
}
