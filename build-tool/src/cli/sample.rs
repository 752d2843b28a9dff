//! `build-tool sample`: the samples of a conditional blob at one condition as CSV,
//! read through the runtime so that the CSV shows exactly what a renderer gets.

use crate::pointset::AlignedBytes;
use anyhow::{anyhow, Result};
use clap::{Args, ValueEnum};
use nuld_runtime::glam::Vec2;
use nuld_runtime::Blob;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `build-tool sample`.
#[derive(Args, Debug)]
pub struct SampleArgs {
    /// The conditional blob.
    pub file: PathBuf,
    /// The condition in the blob's units, `ROUGHNESS,THETA_O_DEG` for BRDF samplers
    /// (view in the xz-plane, +x side); values outside the blob's range clamp.
    #[arg(long, value_parser = parse_condition, allow_hyphen_values = true)]
    pub cond: Condition,
    /// The instance (table mode wraps it modulo the stored instances).
    #[arg(long, default_value_t = 0)]
    pub instance: u32,
    /// Table lookups or the network evaluated per sample.
    #[arg(long, value_enum, default_value = "table")]
    pub mode: SampleMode,
}

/// A parsed `--cond`: two finite numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Condition(pub [f32; 2]);

/// `--mode` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SampleMode {
    /// Interpolated point table (`ConditionalSampler::sample`).
    Table,
    /// The f16 network (`ConditionalSampler::sample_network`).
    Network,
}

fn parse_condition(s: &str) -> Result<Condition, String> {
    let bad = || format!("{s:?} is not ROUGHNESS,THETA_O_DEG (two finite numbers)");
    let (a, b) = s.split_once(',').ok_or_else(bad)?;
    let num = |v: &str| v.trim().parse::<f32>().ok().filter(|x| x.is_finite());
    match (num(a), num(b)) {
        (Some(x), Some(y)) => Ok(Condition([x, y])),
        _ => Err(bad()),
    }
}

/// Writes the CSV `index,x,y,z,weight` of every index `0..n` of instance `instance`
/// at condition `cond` to `out`: values as the runtime returns them (f32, shortest
/// round-trip decimal). Fails for a blob that is not a conditional sampler.
pub fn write_csv(
    bytes: &[u8],
    cond: Condition,
    instance: u32,
    mode: SampleMode,
    out: &mut impl Write,
) -> Result<()> {
    let blob = Blob::parse(bytes).map_err(|e| anyhow!("{e}"))?;
    let cs = blob.conditional().map_err(|e| anyhow!("{e}"))?;
    let c = Vec2::from(cond.0);
    writeln!(out, "index,x,y,z,weight")?;
    for i in 0..cs.len() {
        let s = match mode {
            SampleMode::Table => cs.sample(c, instance, i),
            SampleMode::Network => cs.sample_network(c, instance, i),
        };
        let d = s.direction;
        writeln!(out, "{i},{},{},{},{}", d.x, d.y, d.z, s.weight)?;
    }
    Ok(())
}

/// Runs `build-tool sample`. A reader that stops early closes the pipe; the
/// resulting `BrokenPipe` ends the command normally, with exit code 0.
pub fn run(a: SampleArgs) -> Result<()> {
    let bytes = AlignedBytes::read(&a.file)?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let written = write_csv(bytes.as_slice(), a.cond, a.instance, a.mode, &mut out)
        .and_then(|()| Ok(out.flush()?));
    match written {
        Err(e) if super::export::is_broken_pipe(&e) => Ok(()),
        other => other.map_err(|e| anyhow!("{}: {e}", a.file.display())),
    }
}
