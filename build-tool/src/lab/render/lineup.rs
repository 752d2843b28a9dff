//! The samplers the evaluation compares, in the order of its tables and figures.

use super::brdf_warp::{LobeTable, MixtureSampler};
use super::environment::Environment;
use super::envmap_warp::{EnvWarp, EnvmapSampler};
use super::nuld_sampler::{NuldBlobError, NuldMode, NuldSampler};
use super::primary::{Generator, PrimaryPoints};
use super::sampler::DirectionSampler;

/// The BRDF sampler names in table order.
pub const BRDF_SAMPLERS: [&str; 6] = [
    "nuld-table",
    "nuld-network",
    "owen-sobol",
    "random",
    "sot",
    "gbn",
];
/// The environment sampler names in table order.
pub const ENVMAP_SAMPLERS: [&str; 5] = [
    "nuld-table",
    "nuld-network",
    "owen-sobol",
    "halton",
    "owen-sobol-hierarchical",
];

/// Every sampler at `n` samples per pixel, BRDF then environment, named as
/// [`BRDF_SAMPLERS`] and [`ENVMAP_SAMPLERS`]: ours from the blobs `blob` (BRDF)
/// and `envmap_blob` (the environment sampler of `env`; without it ours is left
/// out of the environment samplers), whose `N` should be `n`, in both modes; the
/// baselines' points from `seed` (SOT and GBN generate their pools now). Our
/// network mode reads its weights decoded into `network_weights` (BRDF,
/// environment; [`NuldSampler::decoded`]). An error if a blob is not the sampler
/// it should be.
pub fn samplers<'a>(
    blob: &'a [u8],
    envmap_blob: Option<&'a [u8]>,
    n: u32,
    seed: u64,
    lobes: &'a LobeTable,
    env: &'a Environment,
    network_weights: &'a mut [Vec<f32>; 2],
) -> Result<Vec<Box<dyn DirectionSampler + 'a>>, NuldBlobError> {
    let [brdf_weights, envmap_weights] = network_weights;
    let points = |g| PrimaryPoints::new(g, n, seed);
    let brdf = |g| Box::new(MixtureSampler::new(points(g), lobes));
    let envmap = |g, warp| Box::new(EnvmapSampler::new(points(g), warp, env));
    let mut all: Vec<Box<dyn DirectionSampler + 'a>> = vec![
        Box::new(NuldSampler::new(blob, NuldMode::Table)?),
        Box::new(NuldSampler::new(blob, NuldMode::Network)?.decoded(brdf_weights)),
        brdf(Generator::OwenSobol),
        brdf(Generator::Random),
        brdf(Generator::Sot),
        brdf(Generator::Gbn),
    ];
    if let Some(e) = envmap_blob {
        all.push(Box::new(NuldSampler::envmap(e, NuldMode::Table, env)?));
        let network = NuldSampler::envmap(e, NuldMode::Network, env)?;
        all.push(Box::new(network.decoded(envmap_weights)));
    }
    all.push(envmap(Generator::OwenSobol, EnvWarp::InverseCdf));
    all.push(envmap(Generator::Halton, EnvWarp::InverseCdf));
    all.push(envmap(Generator::OwenSobol, EnvWarp::Hierarchical));
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::render::blobs::{tiny_blob, tiny_envmap_blob};
    use crate::lab::render::sampler::Technique;
    use crate::sphere::envmap::tiny_map;

    #[test]
    fn the_lineup_is_named_as_the_tables() {
        let blob = tiny_blob(4);
        let dir = std::env::temp_dir().join(format!("nuld-lineup-{}", std::process::id()));
        let map = tiny_map(&dir);
        let env = Environment::from_file(&map).unwrap();
        let env_blob = tiny_envmap_blob(4, &map);
        let lobes = LobeTable::new(&[0.5]);
        let mut weights = Default::default();
        let all = samplers(
            blob.as_slice(),
            Some(env_blob.as_slice()),
            4,
            0,
            &lobes,
            &env,
            &mut weights,
        )
        .unwrap();
        let names = |t| {
            all.iter()
                .filter(|s| s.technique() == t)
                .map(|s| s.name())
                .collect::<Vec<_>>()
        };
        assert_eq!(names(Technique::Brdf), BRDF_SAMPLERS);
        assert_eq!(names(Technique::Envmap), ENVMAP_SAMPLERS);
        let fails = |blob: &[u8], envmap_blob: Option<&[u8]>| {
            samplers(
                blob,
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
        let without = samplers(blob.as_slice(), None, 4, 0, &lobes, &env, &mut spare).unwrap();
        assert_eq!(without.len(), all.len() - 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
