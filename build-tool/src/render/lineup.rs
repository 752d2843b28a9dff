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
pub const ENVMAP_SAMPLERS: [&str; 3] = ["owen-sobol", "halton", "owen-sobol-hierarchical"];

/// Every sampler at `n` samples per pixel, BRDF then environment, named as
/// [`BRDF_SAMPLERS`] and [`ENVMAP_SAMPLERS`]: ours from the blob `blob` (whose
/// `N` should be `n`) in both modes; the baselines' points from `seed` (SOT and
/// GBN generate their pools now). An error if `blob` is not a conditional BRDF
/// sampler.
pub fn samplers<'a>(
    blob: &'a [u8],
    n: u32,
    seed: u64,
    lobes: &'a LobeTable,
    env: &'a Environment,
) -> Result<Vec<Box<dyn DirectionSampler + 'a>>, NuldBlobError> {
    let points = |g| PrimaryPoints::new(g, n, seed);
    let brdf = |g| Box::new(MixtureSampler::new(points(g), lobes));
    let envmap = |g, warp| Box::new(EnvmapSampler::new(points(g), warp, env));
    Ok(vec![
        Box::new(NuldSampler::new(blob, NuldMode::Table)?),
        Box::new(NuldSampler::new(blob, NuldMode::Network)?),
        brdf(Generator::OwenSobol),
        brdf(Generator::Random),
        brdf(Generator::Sot),
        brdf(Generator::Gbn),
        envmap(Generator::OwenSobol, EnvWarp::InverseCdf),
        envmap(Generator::Halton, EnvWarp::InverseCdf),
        envmap(Generator::OwenSobol, EnvWarp::Hierarchical),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::blobs::tiny_blob;
    use crate::render::sampler::Technique;

    #[test]
    fn the_lineup_is_named_as_the_tables() {
        let blob = tiny_blob(4);
        let env = Environment::constant(1.0).unwrap();
        let lobes = LobeTable::new(&[0.5]);
        let all = samplers(blob.as_slice(), 4, 0, &lobes, &env).unwrap();
        let names = |t| {
            all.iter()
                .filter(|s| s.technique() == t)
                .map(|s| s.name())
                .collect::<Vec<_>>()
        };
        assert_eq!(names(Technique::Brdf), BRDF_SAMPLERS);
        assert_eq!(names(Technique::Envmap), ENVMAP_SAMPLERS);
        assert!(samplers(&[0u8; 16], 4, 0, &lobes, &env).is_err());
    }
}
