//! `build-tool sample`: the samples of a conditional blob at one condition as CSV,
//! read through the runtime so that the CSV shows exactly what a renderer gets.

use crate::pointset::AlignedBytes;
use anyhow::{anyhow, bail, Result};
use clap::{Args, ValueEnum};
use nuld_core::brdf::{clamp_metallic, MAX_METALLIC, MIN_METALLIC};
use nuld_core::conditional::ConditionalTarget;
use nuld_runtime::glam::{Vec2, Vec3};
use nuld_runtime::{Blob, BlobError, ConditionalSampler, EnvmapSampler};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `build-tool sample`.
#[derive(Args, Debug)]
pub struct SampleArgs {
    /// The conditional blob.
    pub file: PathBuf,
    /// The condition in the blob's units, `ROUGHNESS,THETA_O_DEG[,METALLIC]` for
    /// BRDF samplers (view in the xz-plane, +x side; metallic 0 to 1, default 0,
    /// the dielectric); values outside the blob's range clamp.
    #[arg(long, value_parser = parse_condition, allow_hyphen_values = true,
        required_unless_present = "normal", conflicts_with = "normal")]
    pub cond: Option<Condition>,
    /// For environment samplers: the surface normal `X,Y,Z` (world frame, +z up; any
    /// length), placed on the condition grid by its octahedral square point.
    #[arg(long, value_parser = parse_normal, allow_hyphen_values = true)]
    pub normal: Option<Normal>,
    /// The instance (table mode wraps it modulo the stored instances).
    #[arg(long, default_value_t = 0)]
    pub instance: u32,
    /// Table lookups or the network evaluated per sample.
    #[arg(long, value_enum, default_value = "table")]
    pub mode: SampleMode,
    /// The unbiased mode: the set's primary points shifted on the torus by a
    /// random vector drawn from SEED (a renderer passes each pixel's random
    /// number), so that every sample is distributed exactly as its pdf.
    #[arg(long, value_name = "SEED")]
    pub randomize: Option<u32>,
}

/// A parsed `--cond`: two finite numbers and a third (the metallic) that
/// defaults to 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Condition(pub [f32; 3]);

/// A parsed `--normal`: three finite numbers, not all zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normal(pub [f32; 3]);

/// Where `sample` reads the blob: a condition in its units, or a normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum At {
    /// `--cond`.
    Condition(Condition),
    /// `--normal` ([`nuld_runtime::EnvmapSampler::sample`]).
    Normal(Normal),
}

/// `--mode` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SampleMode {
    /// Interpolated point table (the runtime's table-mode views).
    Table,
    /// The f16 network (the runtime's network-mode views).
    Network,
}

fn parse_condition(s: &str) -> Result<Condition, String> {
    let bad =
        || format!("{s:?} is not ROUGHNESS,THETA_O_DEG[,METALLIC] (two or three finite numbers)");
    let v: Vec<f32> = s
        .split(',')
        .map(|v| v.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    match v[..] {
        [x, y] => Ok(Condition([x, y, 0.0])),
        [x, y, m] => Ok(Condition([x, y, m])),
        _ => Err(bad()),
    }
}

fn parse_normal(s: &str) -> Result<Normal, String> {
    let bad = || format!("{s:?} is not X,Y,Z (three finite numbers, not all zero)");
    let v: Vec<f32> = s
        .split(',')
        .map(|v| v.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    match v[..] {
        [x, y, z] if x != 0.0 || y != 0.0 || z != 0.0 => Ok(Normal([x, y, z])),
        _ => Err(bad()),
    }
}

/// Writes the CSV `index,x,y,z,weight,pdf` of every index `0..n` of instance
/// `instance` at `at` to `out`, in the unbiased mode when `randomize` gives a
/// seed: values as the runtime returns them (f32, shortest round-trip decimal;
/// `pdf` per steradian, 0 for a sampler without an exact prior). Fails for a blob
/// that is not a conditional sampler, or a normal given to a sampler whose
/// condition is not one.
pub fn write_csv(
    bytes: &[u8],
    at: At,
    instance: u32,
    (mode, randomize): (SampleMode, Option<u32>),
    out: &mut impl Write,
) -> Result<()> {
    let blob = Blob::parse(bytes).map_err(|e| anyhow!("{e}"))?;
    // The runtime's view for the place asked for; a normal needs an environment
    // sampler, refused before anything is written.
    let view = match at {
        At::Normal(n) => {
            let env = blob.envmap().map_err(|e| match e {
                BlobError::WrongTarget { .. } => anyhow!(
                    "--normal needs an environment sampler; this blob's condition is --cond ROUGHNESS,THETA_O_DEG"
                ),
                e => anyhow!("{e}"),
            })?;
            View::Normal(env, Vec3::from(n.0))
        }
        At::Condition(c) => {
            let cs = blob.conditional().map_err(|e| anyhow!("{e}"))?;
            View::Condition(cs, Vec2::new(c.0[0], c.0[1]), c.0[2])
        }
    };
    let len = match view {
        View::Normal(env, _) => env.len(),
        View::Condition(cs, ..) => cs.len(),
    };
    writeln!(out, "index,x,y,z,weight,pdf")?;
    for i in 0..len {
        let k = instance;
        let s = match (view, mode, randomize) {
            (View::Normal(env, n), SampleMode::Table, None) => env.sample(n, k, i),
            (View::Normal(env, n), SampleMode::Table, Some(r)) => env.sample_randomized(n, k, i, r),
            (View::Normal(env, n), SampleMode::Network, None) => env.network().sample(n, k, i),
            (View::Normal(env, n), SampleMode::Network, Some(r)) => {
                env.network().sample_randomized(n, k, i, r)
            }
            (View::Condition(cs, c, m), SampleMode::Table, None) => cs.sample_metallic(c, m, k, i),
            (View::Condition(cs, c, m), SampleMode::Table, Some(r)) => {
                cs.sample_randomized_metallic(c, m, k, i, r)
            }
            (View::Condition(cs, c, m), SampleMode::Network, None) => {
                cs.network().sample_metallic(c, m, k, i)
            }
            (View::Condition(cs, c, m), SampleMode::Network, Some(r)) => {
                cs.network().sample_randomized_metallic(c, m, k, i, r)
            }
        };
        let d = s.direction;
        writeln!(out, "{i},{},{},{},{},{}", d.x, d.y, d.z, s.weight, s.pdf)?;
    }
    Ok(())
}

/// The runtime view `sample` reads and where: an environment sampler at a normal,
/// or any conditional sampler at a condition in the blob's units.
#[derive(Clone, Copy)]
enum View<'a> {
    Normal(EnvmapSampler<'a>, Vec3),
    Condition(ConditionalSampler<'a>, Vec2, f32),
}

/// The one-line warning for a `--cond` outside the blob's condition range, which
/// the runtime clamps (`None` inside the range or for another blob).
pub fn clamp_warning(bytes: &[u8], at: At) -> Option<String> {
    let At::Condition(Condition(c)) = at else {
        return None;
    };
    let cs = Blob::parse(bytes).ok()?.conditional().ok()?;
    let info = cs.info();
    let inside = (0..2).all(|a| (info.cond_min[a]..=info.cond_max[a]).contains(&c[a]));
    let clamped = info.denormalize(info.normalize([c[0], c[1]]));
    // A BRDF sampler also clamps the metallic (an environment sampler ignores it).
    let brdf = info.target == ConditionalTarget::GltfBrdf as u32;
    let metallic = clamp_metallic(c[2]);
    if inside && (!brdf || metallic == c[2]) {
        return None;
    }
    let (range, given, at) = if brdf {
        (
            format!(" x metallic [{MIN_METALLIC}, {MAX_METALLIC}]"),
            format!(",{}", c[2]),
            format!(",{metallic}"),
        )
    } else {
        Default::default()
    };
    Some(format!(
        "warning: --cond {},{}{given} is outside the blob's range [{}, {}] x [{}, {}]{range}; sampling at the clamped {},{}{at}",
        c[0], c[1], info.cond_min[0], info.cond_max[0], info.cond_min[1], info.cond_max[1],
        clamped[0], clamped[1]
    ))
}

/// Runs `build-tool sample`. A reader that stops early closes the pipe; the
/// resulting `BrokenPipe` ends the command normally, with exit code 0.
pub fn run(a: SampleArgs) -> Result<()> {
    let bytes = AlignedBytes::read(&a.file)?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let at = match (a.cond, a.normal) {
        (Some(c), _) => At::Condition(c),
        (None, Some(n)) => At::Normal(n),
        (None, None) => {
            bail!("sample needs --cond ROUGHNESS,THETA_O_DEG[,METALLIC] or --normal X,Y,Z")
        }
    };
    if let Some(warning) = clamp_warning(bytes.as_slice(), at) {
        eprintln!("{warning}");
    }
    let how = (a.mode, a.randomize);
    let written =
        write_csv(bytes.as_slice(), at, a.instance, how, &mut out).and_then(|()| Ok(out.flush()?));
    match written {
        Err(e) if super::export::is_broken_pipe(&e) => Ok(()),
        other => other.map_err(|e| anyhow!("{}: {e}", a.file.display())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_parse_or_say_why_not() {
        assert_eq!(parse_normal("0, -1.5,2"), Ok(Normal([0.0, -1.5, 2.0])));
        for bad in ["0,0,0", "1,2", "1,2,3,4", "1,x,2", "nan,0,1"] {
            assert!(parse_normal(bad).unwrap_err().contains("X,Y,Z"), "{bad}");
        }
    }

    /// `--normal` rows are the runtime's `EnvmapSampler`; a BRDF blob refuses a
    /// normal with a one-line error.
    #[test]
    fn a_normal_reads_an_environment_blob_and_is_refused_by_a_brdf_blob() {
        let dir = std::env::temp_dir().join(format!("nuld-sample-cli-{}", std::process::id()));
        let map = crate::sphere::envmap::tiny_map(&dir);
        let blob = crate::lab::render::blobs::tiny_envmap_blob(4, &map);
        let at = At::Normal(Normal([0.2, 0.9, -0.3]));
        let env = Blob::parse(blob.as_slice()).unwrap().envmap().unwrap();
        let n = Vec3::new(0.2, 0.9, -0.3);
        for randomize in [None, Some(99)] {
            let mut out = Vec::new();
            write_csv(
                blob.as_slice(),
                at,
                3,
                (SampleMode::Network, randomize),
                &mut out,
            )
            .unwrap();
            let text = String::from_utf8(out).unwrap();
            let rows: Vec<&str> = text.lines().collect();
            assert_eq!(rows[0], "index,x,y,z,weight,pdf");
            for i in 0..4u32 {
                let s = match randomize {
                    None => env.network().sample(n, 3, i),
                    Some(r) => env.network().sample_randomized(n, 3, i, r),
                };
                assert!(s.pdf > 0.0);
                let d = s.direction;
                let want = format!("{i},{},{},{},{},{}", d.x, d.y, d.z, s.weight, s.pdf);
                assert_eq!(rows[1 + i as usize], want);
            }
        }
        let brdf = nuld_runtime::doc_example_conditional_blob();
        let e = write_csv(&brdf.0, at, 0, (SampleMode::Table, None), &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("--normal needs an environment sampler"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
