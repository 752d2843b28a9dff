//! The samplers the evaluation compares, in the order of its tables and figures.

use super::brdf_warp::{LobeTable, MixtureSampler};
use super::environment::Environment;
use super::envmap_warp::{EnvWarp, EnvmapSampler};
use super::frame::Frame;
use super::mis::MisSampler;
use super::nuld_sampler::{FixedWeight, NuldBlobError, NuldMode, NuldSampler};
use super::primary::{Generator, PrimaryPoints};
use super::sampler::{DirectionSampler, ShadingPoint, Technique};
use super::scene::Material;
use glam::DVec3;
use std::sync::Arc;

/// A sampler of the lineup, shared between the techniques that use it (an
/// environment sampler serves its own rows and the MIS ones).
pub type Shared<'a> = Arc<dyn DirectionSampler + 'a>;

/// The BRDF sampler names in table order: ours (fixed instances in both modes,
/// and the unbiased mode), then the generators through the mixture warp.
pub const BRDF_SAMPLERS: [&str; 7] = [
    "nuld-table",
    "nuld-network",
    "nuld-unbiased",
    "owen-sobol",
    "random",
    "sot",
    "gbn",
];

/// The environment sampler names in table order: ours (fixed instances in both
/// modes, and the unbiased mode), the generators through ours' prior (the
/// product warp), and the luminance-only warps renderers ship.
pub const ENVMAP_SAMPLERS: [&str; 11] = [
    "nuld-table",
    "nuld-network",
    "nuld-unbiased",
    "owen-sobol-product",
    "halton-product",
    "random-product",
    "sot-product",
    "gbn-product",
    "owen-sobol",
    "halton",
    "owen-sobol-hierarchical",
];

/// The sampler names of multiple importance sampling ([`super::mis`]): ours
/// for both halves (our environment sampler with our BRDF sampler, each in
/// table mode, network mode, the unbiased mode), then each environment sampler
/// of [`ENVMAP_SAMPLERS`] with Owen-Sobol through the BRDF mixture warp.
pub const MIS_SAMPLERS: [&str; MIS_OURS_BOTH + ENVMAP_SAMPLERS.len()] = {
    let both = ["nuld-both-table", "nuld-both-network", "nuld-both-unbiased"];
    let mut all = [""; MIS_OURS_BOTH + ENVMAP_SAMPLERS.len()];
    let mut i = 0;
    while i < all.len() {
        all[i] = match i < MIS_OURS_BOTH {
            true => both[i],
            false => ENVMAP_SAMPLERS[i - MIS_OURS_BOTH],
        };
        i += 1;
    }
    all
};

/// How many of [`MIS_SAMPLERS`] pair ours for both halves (and need a BRDF
/// blob as well as the environment blob).
const MIS_OURS_BOTH: usize = 3;

/// The names of `technique`'s samplers in table order, with both blobs at hand
/// or, when `brdf_blob` is false, without the BRDF blob (MIS then leaves out
/// the rows of ours for both halves).
pub fn names(technique: Technique, brdf_blob: bool) -> &'static [&'static str] {
    match technique {
        Technique::Brdf => &BRDF_SAMPLERS,
        Technique::Envmap => &ENVMAP_SAMPLERS,
        Technique::Mis if brdf_blob => &MIS_SAMPLERS,
        Technique::Mis => &MIS_SAMPLERS[MIS_OURS_BOTH..],
    }
}

/// The samplers of `techniques` at `n` samples per pixel, in the order of
/// [`Technique::ALL`] and named as [`names`]: ours from the blobs `blob` (BRDF;
/// without it ours is left out of the BRDF samplers and MIS has ours for the
/// environment half only) and `envmap_blob` (the environment sampler of `env`;
/// without it ours is left out of the environment and MIS samplers), whose `N`
/// should be `n`; the
/// baselines' points from `seed` (SOT and GBN generate their pools now, once for
/// all techniques). Our network mode reads its weights decoded into
/// `network_weights` (BRDF, environment; [`NuldSampler::decoded`]). An error if
/// a blob is not the sampler it should be.
#[allow(clippy::too_many_arguments)]
pub fn samplers<'a>(
    techniques: &[Technique],
    blob: Option<&'a [u8]>,
    envmap_blob: Option<&'a [u8]>,
    n: u32,
    seed: u64,
    lobes: &'a LobeTable,
    env: &'a Environment,
    network_weights: &'a mut [Vec<f32>; 2],
) -> Result<Vec<Shared<'a>>, NuldBlobError> {
    let blobs = [blob, envmap_blob];
    let w = FixedWeight::default();
    weighted_samplers(techniques, blobs, w, n, seed, lobes, env, network_weights)
}

/// [`samplers`] of the blobs `[brdf, envmap]` with our environment sampler's
/// fixed instances weighted by `fixed_weight`.
#[allow(clippy::too_many_arguments)]
pub fn weighted_samplers<'a>(
    techniques: &[Technique],
    [blob, envmap_blob]: [Option<&'a [u8]>; 2],
    fixed_weight: FixedWeight,
    n: u32,
    seed: u64,
    lobes: &'a LobeTable,
    env: &'a Environment,
    network_weights: &'a mut [Vec<f32>; 2],
) -> Result<Vec<Shared<'a>>, NuldBlobError> {
    let [brdf_weights, envmap_weights] = network_weights;
    let generators = [
        Generator::OwenSobol,
        Generator::Halton,
        Generator::Random,
        Generator::Sot,
        Generator::Gbn,
    ];
    let wanted = |g: Generator| {
        let brdf = techniques.contains(&Technique::Brdf) && g != Generator::Halton;
        brdf || techniques.iter().any(|t| *t != Technique::Brdf)
    };
    let pools: Vec<(Generator, PrimaryPoints)> = generators
        .into_iter()
        .filter(|g| wanted(*g))
        .map(|g| (g, PrimaryPoints::new(g, n, seed)))
        .collect();
    let points = |g: Generator| {
        pools
            .iter()
            .find(|(h, _)| *h == g)
            .map(|(_, p)| p.clone())
            .unwrap_or_else(|| PrimaryPoints::new(g, n, seed))
    };
    let brdf = |g| Arc::new(MixtureSampler::new(points(g), lobes)) as Shared<'a>;
    let envmap = |g, warp| Arc::new(EnvmapSampler::new(points(g), warp, env)) as Shared<'a>;

    let mut envmaps: Vec<Shared<'a>> = Vec::new();
    if let Some(e) = envmap_blob {
        let w = fixed_weight;
        envmaps.push(Arc::new(
            NuldSampler::envmap(e, NuldMode::Table, env)?.with_fixed_weight(w),
        ));
        let network = NuldSampler::envmap(e, NuldMode::Network, env)?.with_fixed_weight(w);
        envmaps.push(Arc::new(network.decoded(envmap_weights)));
        envmaps.push(Arc::new(
            NuldSampler::envmap(e, NuldMode::Table, env)?.unbiased(),
        ));
    }
    let wants_envmaps = techniques
        .iter()
        .any(|t| matches!(t, Technique::Envmap | Technique::Mis));
    if wants_envmaps {
        for g in generators {
            envmaps.push(envmap(g, EnvWarp::Product));
        }
        envmaps.push(envmap(Generator::OwenSobol, EnvWarp::InverseCdf));
        envmaps.push(envmap(Generator::Halton, EnvWarp::InverseCdf));
        envmaps.push(envmap(Generator::OwenSobol, EnvWarp::Hierarchical));
    }

    // Ours for the BRDF, shared by BRDF sampling and MIS: table, network,
    // unbiased mode.
    let mut ours_brdf: Vec<Shared<'a>> = Vec::new();
    if let Some(b) = blob.filter(|_| techniques.iter().any(|t| *t != Technique::Envmap)) {
        ours_brdf.push(Arc::new(NuldSampler::new(b, NuldMode::Table)?));
        let network = NuldSampler::new(b, NuldMode::Network)?;
        ours_brdf.push(Arc::new(network.decoded(brdf_weights)));
        ours_brdf.push(Arc::new(NuldSampler::new(b, NuldMode::Table)?.unbiased()));
    }

    let mut all: Vec<Shared<'a>> = Vec::new();
    for technique in Technique::ALL {
        if !techniques.contains(&technique) {
            continue;
        }
        match technique {
            Technique::Brdf => {
                all.extend(ours_brdf.iter().cloned());
                for g in [
                    Generator::OwenSobol,
                    Generator::Random,
                    Generator::Sot,
                    Generator::Gbn,
                ] {
                    all.push(brdf(g));
                }
            }
            Technique::Envmap => all.extend(envmaps.iter().cloned()),
            Technique::Mis => {
                let probe = ShadingPoint {
                    frame: Frame::new(DVec3::Z),
                    wo: DVec3::Z,
                    material: Material::dielectric(0.5),
                };
                // Ours for both halves, mode by mode, when both blobs are here.
                let ours_envmap = envmaps
                    .iter()
                    .take(envmap_blob.map_or(0, |_| MIS_OURS_BOTH));
                let both = ours_envmap.zip(&ours_brdf).zip(MIS_SAMPLERS);
                for ((e, b), name) in both {
                    let mis = MisSampler::new(e.clone(), b.clone(), &probe);
                    all.extend(mis.map(|m| Arc::new(m.named(name)) as Shared<'a>));
                }
                for s in &envmaps {
                    let mis = MisSampler::new(s.clone(), brdf(Generator::OwenSobol), &probe);
                    all.extend(mis.map(|m| Arc::new(m) as Shared<'a>));
                }
            }
        }
    }
    Ok(all)
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::render::blobs::{tiny_blob, tiny_envmap_blob};
    use crate::sphere::envmap::tiny_map;

    #[test]
    fn the_lineup_is_named_as_the_tables() {
        let blob = tiny_blob(4);
        let dir = std::env::temp_dir().join(format!("nuld-lineup-{}", std::process::id()));
        let map = tiny_map(&dir);
        let env = Environment::from_file(&map).unwrap();
        let env_blob = tiny_envmap_blob(4, &map);
        let lobes = LobeTable::new(&[Material::dielectric(0.5), Material::metal(0.5)]);
        let mut weights = Default::default();
        let all = samplers(
            &Technique::ALL,
            Some(blob.as_slice()),
            Some(env_blob.as_slice()),
            4,
            0,
            &lobes,
            &env,
            &mut weights,
        )
        .unwrap();
        for t in Technique::ALL {
            let got: Vec<&str> = all
                .iter()
                .filter(|s| s.technique() == t)
                .map(|s| s.name())
                .collect();
            assert_eq!(got, names(t, true), "{}", t.name());
        }
        let fails = |blob: &[u8], envmap_blob: Option<&[u8]>| {
            samplers(
                &Technique::ALL,
                Some(blob),
                envmap_blob,
                4,
                0,
                &lobes,
                &env,
                &mut Default::default(),
            )
            .is_err()
        };
        assert!(fails(&[0u8; 16], Some(env_blob.as_slice())));
        // The two blobs swapped: each is the wrong target.
        assert!(fails(env_blob.as_slice(), Some(blob.as_slice())));
        assert!(fails(blob.as_slice(), Some(blob.as_slice())));
        let mut spare = Default::default();
        let all_techniques = &Technique::ALL;
        let without = samplers(
            all_techniques,
            Some(blob.as_slice()),
            None,
            4,
            0,
            &lobes,
            &env,
            &mut spare,
        )
        .unwrap();
        // Ours' three environment samplers, alone and in MIS, and ours for
        // both halves of MIS.
        assert_eq!(without.len(), all.len() - 9);
        let mut spare = Default::default();
        let mis = samplers(
            &[Technique::Mis],
            None,
            Some(env_blob.as_slice()),
            4,
            0,
            &lobes,
            &env,
            &mut spare,
        )
        .unwrap();
        // Without the BRDF blob, MIS has ours for the environment half only.
        assert!(mis.iter().all(|s| s.technique() == Technique::Mis));
        let got: Vec<&str> = mis.iter().map(|s| s.name()).collect();
        assert_eq!(got, names(Technique::Mis, false));
        assert_eq!(got.len(), MIS_SAMPLERS.len() - MIS_OURS_BOTH);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
