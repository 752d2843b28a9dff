//! `build-tool render`: the rendering evaluation of paper Fig. 8 (library:
//! [`crate::lab::render`]).

use crate::lab::render::nuld_sampler::FixedWeight;
use crate::lab::render::sampler::Technique;
use crate::lab::render::{render, RenderConfig};
use crate::sphere::envmap::shape_warning;
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `build-tool render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Environment map lighting the scene (HDR, EXR or PNG, equirectangular).
    #[arg(long)]
    pub envmap: PathBuf,
    /// Samples per pixel, comma-separated [default: 4,16,64,256; 4,16 with --quick].
    #[arg(long, value_delimiter = ',', value_parser = spp)]
    pub spp: Vec<u32>,
    /// Small and fast (32 x 24 pixels, 4,16 spp, a small reference, tiny bakes): for tests.
    #[arg(long)]
    pub quick: bool,
    /// Image size WIDTHxHEIGHT [default: 320x240; 32x24 with --quick].
    #[arg(long, value_parser = size)]
    pub size: Option<(u32, u32)>,
    /// Reference samples per pixel and technique [default: 4096; 256 with --quick].
    #[arg(long, allow_negative_numbers = true, value_parser = super::count)]
    pub reference_spp: Option<usize>,
    /// A baked BRDF sampler blob; serves the spp equal to its N. Repeat for
    /// several; counts without one are baked into DIR/brdf-nN/ when brdf is
    /// among the techniques (mis uses the blobs at hand for ours on both halves).
    #[arg(long)]
    pub brdf_blob: Vec<PathBuf>,
    /// A baked environment sampler blob of the same map (`bake --envmap`); serves
    /// the spp equal to its N. Repeat for several; counts without one are baked
    /// into DIR/envmap-nN/.
    #[arg(long)]
    pub envmap_blob: Vec<PathBuf>,
    /// Seed; fixes every image bit for bit whatever the thread count. The images
    /// are rendered at SEED, SEED + 1, ... (see --seeds).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Renders per technique, sampler and spp, each at its own seed; the tables
    /// give means and standard errors over them [default: 4; 2 with --quick].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub seeds: Option<u32>,
    /// Techniques, comma-separated: brdf (BRDF sampling), envmap (environment
    /// sampling), mis (both, power heuristic) [default: all three]. Without brdf
    /// no BRDF blob is baked, and mis pairs ours for both halves only at the
    /// counts a --brdf-blob serves.
    #[arg(long, value_delimiter = ',', value_parser = technique)]
    pub techniques: Vec<Technique>,
    /// How our environment sampler's fixed instances weigh a sample `l`: pdf
    /// (f cos / pdf, the prior's pdf, as the unbiased mode), target (E f / L: as
    /// if the set followed L cos / E), normalized (f cos / pdf, the set's weights
    /// divided by its own estimate of the irradiance over the blob's E(n))
    /// [default: pdf].
    #[arg(long, value_parser = fixed_weight)]
    pub fixed_weight: Option<FixedWeight>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

/// `normalized`, `pdf` or `target`.
fn fixed_weight(s: &str) -> Result<FixedWeight, String> {
    FixedWeight::ALL
        .iter()
        .find(|(name, _)| *name == s.trim())
        .map(|(_, w)| *w)
        .ok_or_else(|| format!("{s:?} is not a weight: normalized, pdf or target"))
}

/// A sample count in `1..=65536`.
fn spp(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if (1..=65536).contains(&n) => Ok(n),
        _ => Err(format!("{s:?} is not a sample count in 1..=65536")),
    }
}

/// `brdf`, `envmap` or `mis`.
fn technique(s: &str) -> Result<Technique, String> {
    Technique::from_name(s.trim())
        .ok_or_else(|| format!("{s:?} is not a technique: brdf, envmap or mis"))
}

/// `WIDTHxHEIGHT`, each in `1..=16384`.
fn size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("{s:?} is not WIDTHxHEIGHT with each in 1..=16384");
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    let parse = |v: &str| v.parse::<u32>().ok().filter(|n| (1..=16384).contains(n));
    Ok((parse(w).ok_or_else(bad)?, parse(h).ok_or_else(bad)?))
}

/// Runs `build-tool render`.
pub fn run(a: RenderArgs) -> Result<()> {
    if let Some(w) = shape_warning(&a.envmap) {
        eprintln!("warning: {w}");
    }
    let mut config = if a.quick {
        RenderConfig::quick(a.envmap)
    } else {
        RenderConfig::full(a.envmap)
    };
    if !a.spp.is_empty() {
        config.spp = a.spp;
    }
    if let Some((w, h)) = a.size {
        (config.width, config.height) = (w, h);
    }
    if let Some(m) = a.reference_spp {
        if !(2..=1 << 24).contains(&m) {
            bail!("--reference-spp must be in 2..=16777216, got {m}");
        }
        config.reference_samples = m as u32;
    }
    config.brdf_blobs = a.brdf_blob;
    config.envmap_blobs = a.envmap_blob;
    config.seed = a.seed;
    if let Some(k) = a.seeds {
        config.seeds = k;
    }
    if !a.techniques.is_empty() {
        config.techniques = a.techniques;
    }
    if let Some(w) = a.fixed_weight {
        config.fixed_weight = w;
    }
    let report = render(&config, &a.out)?;
    println!("{}", report.summary);
    println!(
        "wrote {} ({} renders) in {:.1} s (reference {:.1} s, mean standard error {:.3e})",
        a.out.join("render.csv").display(),
        report.rows.len(),
        report.total_seconds,
        report.reference_seconds,
        report.reference_stderr
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_counts_and_sizes_parse_or_say_why_not() {
        assert_eq!(spp("16"), Ok(16));
        assert!(spp("0").unwrap_err().contains("1..=65536"));
        assert!(spp("-4").is_err() && spp("65537").is_err() && spp("x").is_err());
        assert_eq!(size("320x240"), Ok((320, 240)));
        assert!(size("320").is_err() && size("0x5").is_err() && size("5x").is_err());
        assert_eq!(technique("mis"), Ok(Technique::Mis));
        assert!(technique("light")
            .unwrap_err()
            .contains("brdf, envmap or mis"));
        assert_eq!(fixed_weight("pdf"), Ok(FixedWeight::Pdf));
        assert_eq!(fixed_weight(" normalized"), Ok(FixedWeight::Normalized));
        assert_eq!(fixed_weight("target"), Ok(FixedWeight::Target));
        assert!(fixed_weight("q")
            .unwrap_err()
            .contains("normalized, pdf or target"));
    }

    #[test]
    fn a_brdf_blob_given_as_the_environment_sampler_is_refused_by_name() {
        let dir = std::env::temp_dir().join(format!("nuld-render-cli-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let map = dir.join("sky.png");
        image::RgbImage::from_pixel(16, 8, image::Rgb([200, 180, 160]))
            .save(&map)
            .unwrap();
        let blob = dir.join("brdf.nuld");
        std::fs::write(&blob, nuld_runtime::doc_example_conditional_blob().0).unwrap();
        let a = RenderArgs {
            envmap: map,
            spp: vec![],
            quick: true,
            size: None,
            reference_spp: None,
            brdf_blob: vec![],
            envmap_blob: vec![blob],
            seed: 0,
            seeds: None,
            techniques: vec![],
            fixed_weight: None,
            out: dir.join("never-written"),
        };
        let e = run(a).unwrap_err().to_string();
        assert!(
            e.contains("environment blob")
                && e.contains("brdf.nuld")
                && e.contains("not an environment map"),
            "{e}"
        );
        assert!(!dir.join("never-written").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
