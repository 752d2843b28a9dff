//! `build-tool metrics`: discrepancies of a blob's point or direction sets against a
//! target. The domain is read from the blob.

use crate::density::parse_spec;
use crate::metrics::cap_summary::{CapMetricSummary, CapTarget};
use crate::metrics::summary::{MetricSummary, Target};
use crate::pointset::AlignedBytes;
use crate::sphere::parse_direction_spec;
use anyhow::{anyhow, Context, Result};
use clap::Args;
use glam::{DVec2, DVec3};
use nuld_runtime::{Blob, BlobKind, Domain};
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `build-tool metrics`.
#[derive(Args, Debug)]
pub struct MetricsArgs {
    /// The blob to evaluate.
    pub file: PathBuf,
    /// Target SPEC the points are meant to follow (2D or direction SPEC, matching
    /// the blob's domain).
    #[arg(long, default_value = "uniform")]
    pub density: String,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct MetricsOutput<'a, M: Serialize> {
    file: String,
    density: &'a str,
    domain: String,
    n: usize,
    method: String,
    per_set: Vec<M>,
    mean: M,
}

/// Runs `build-tool metrics`.
pub fn run(a: MetricsArgs) -> Result<()> {
    let bytes = AlignedBytes::read(&a.file)?;
    let blob = Blob::parse(bytes.as_slice()).map_err(|e| anyhow!("{}: {e}", a.file.display()))?;
    let file = a.file.display().to_string();
    match blob.kind() {
        BlobKind::PointSet2D => {
            let density =
                parse_spec(&a.density).with_context(|| format!("--density {}", a.density))?;
            let pts = blob.point_set_2d().map_err(|e| anyhow!("{file}: {e}"))?;
            // The metrics of exactly what a renderer reads: the decoded points.
            let target = Target::new(density.as_ref());
            let per_set: Vec<MetricSummary> = (0..pts.set_count())
                .map(|s| {
                    let set: Vec<DVec2> =
                        (0..pts.len()).map(|i| pts.point(s, i).as_dvec2()).collect();
                    target.evaluate(&set)
                })
                .collect();
            let out = MetricsOutput {
                file,
                density: &a.density,
                domain: Domain::Square.name().into(),
                n: pts.len(),
                method: target.method(),
                mean: MetricSummary::mean(&per_set),
                per_set,
            };
            if a.json {
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                print_table(&out, &["D2asd", "L2-star", "D*"], |m| {
                    vec![m.asd, m.l2_star, m.star]
                });
            }
        }
        BlobKind::DirectionSet => {
            let dirs = blob.direction_set().map_err(|e| anyhow!("{file}: {e}"))?;
            let density = parse_direction_spec(&a.density, dirs.domain())
                .with_context(|| format!("--density {}", a.density))?;
            let target = CapTarget::new(density.as_ref());
            let per_set: Vec<CapMetricSummary> = (0..dirs.set_count())
                .map(|s| {
                    let set: Vec<DVec3> = (0..dirs.len())
                        .map(|i| dirs.direction(s, i).as_dvec3().normalize())
                        .collect();
                    target.evaluate(&set)
                })
                .collect();
            let out = MetricsOutput {
                file,
                density: &a.density,
                domain: dirs.domain().name().into(),
                n: dirs.len(),
                method: target.method(),
                mean: CapMetricSummary::mean(&per_set),
                per_set,
            };
            if a.json {
                println!("{}", serde_json::to_string_pretty(&out)?);
            } else {
                print_table(&out, &["cap L2", "theta-unif", "cap D* >="], |m| {
                    vec![m.cap_l2, m.cap_l2_theta, m.cap_star_lower_bound]
                });
            }
        }
    }
    Ok(())
}

fn print_table<M: Serialize>(
    out: &MetricsOutput<'_, M>,
    names: &[&str],
    values: impl Fn(&M) -> Vec<f64>,
) {
    println!(
        "{} ({} set(s) x {} points, {}) against {}",
        out.file,
        out.per_set.len(),
        out.n,
        out.domain,
        out.density
    );
    print!("{:>5}", "set");
    names.iter().for_each(|n| print!(" {n:>12}"));
    println!();
    let row = |label: String, m: &M| {
        print!("{label:>5}");
        values(m).iter().for_each(|v| print!(" {v:>12.5e}"));
        println!();
    };
    for (s, m) in out.per_set.iter().enumerate() {
        row(s.to_string(), m);
    }
    row("mean".into(), &out.mean);
    println!("({})", out.method);
}
