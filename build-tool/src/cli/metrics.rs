//! `build-tool metrics`: discrepancies of a blob's point or direction sets against a
//! target, by default the one recorded in the blob. The domain is read from the blob.

use crate::metrics::Summary;
use crate::optimize::run::{measure, DirectionProblem, Measured, SquareProblem};
use crate::pointset::{AlignedBytes, PointSets};
use anyhow::{anyhow, Context, Result};
use clap::Args;
use nuld_core::blob::Domain;
use nuld_runtime::Blob;
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `build-tool metrics`.
#[derive(Args, Debug)]
pub struct MetricsArgs {
    /// The blob to evaluate.
    pub file: PathBuf,
    /// Target SPEC the points are meant to follow (2D or direction SPEC, matching
    /// the blob's domain). Default: the target recorded in the blob.
    #[arg(long)]
    pub density: Option<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct MetricsOutput<'a, M: Serialize> {
    file: String,
    density: &'a str,
    /// `recorded in the blob` or `--density`.
    density_source: &'static str,
    domain: String,
    n: usize,
    method: String,
    per_set: Vec<M>,
    mean: M,
}

/// Runs `build-tool metrics`.
pub fn run(a: MetricsArgs) -> Result<()> {
    let bytes = AlignedBytes::read(&a.file)?;
    let file = a.file.display().to_string();
    let blob = Blob::parse(bytes.as_slice()).map_err(|e| anyhow!("{file}: {e}"))?;
    // The metrics of exactly what the blob stores, decoded in f64: the same points
    // `optimize` measured for its report.
    let points = PointSets::from_blob(&blob).with_context(|| file.clone())?;
    let (spec, source) = match &a.density {
        Some(spec) => (spec.clone(), "--density"),
        None => (blob.metadata().target.to_string(), "recorded in the blob"),
    };
    let context = || format!("target {spec} ({source}; --density overrides)");
    match points.domain {
        Domain::Square => {
            let problem = SquareProblem::parse(&spec).with_context(context)?;
            print(
                &a,
                file,
                &spec,
                source,
                &points,
                &measure(&problem, &points),
            )
        }
        domain => {
            let problem = DirectionProblem::parse(&spec, domain).with_context(context)?;
            print(
                &a,
                file,
                &spec,
                source,
                &points,
                &measure(&problem, &points),
            )
        }
    }
}

/// Prints the metrics as JSON or as a table headed by the target used.
fn print<M: Summary>(
    a: &MetricsArgs,
    file: String,
    spec: &str,
    source: &'static str,
    points: &PointSets,
    measured: &Measured<M>,
) -> Result<()> {
    let out = MetricsOutput {
        file,
        density: spec,
        density_source: source,
        domain: points.domain.name().into(),
        n: points.len(),
        method: measured.method.clone(),
        per_set: measured.per_set.clone(),
        mean: measured.mean,
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("target: {spec} ({source})");
    println!(
        "{} ({} set(s) x {} points, {})",
        out.file,
        out.per_set.len(),
        out.n,
        out.domain
    );
    print!("{:>5}", "set");
    M::LABELS.iter().for_each(|n| print!(" {n:>12}"));
    println!();
    let row = |label: String, m: &M| {
        print!("{label:>5}");
        m.values().iter().for_each(|v| print!(" {v:>12.5e}"));
        println!();
    };
    for (s, m) in out.per_set.iter().enumerate() {
        row(s.to_string(), m);
    }
    row("mean".into(), &out.mean);
    println!("({})", out.method);
    Ok(())
}
