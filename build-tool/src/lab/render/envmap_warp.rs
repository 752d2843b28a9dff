//! The baseline environment samplers: uniform primary points through the map's
//! marginal-conditional inverse CDF or through hierarchical warping
//! ([`Environment`]), weighted by `f cos / pdf_env`.

use super::environment::Environment;
use super::primary::{Generator, PrimaryPoints};
use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint, Technique};

/// Which warp of the map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvWarp {
    /// Marginal-conditional inverse CDF.
    InverseCdf,
    /// Hierarchical sample warping.
    Hierarchical,
}

/// A baseline environment sampler.
pub struct EnvmapSampler<'a> {
    points: PrimaryPoints,
    warp: EnvWarp,
    env: &'a Environment,
}

impl<'a> EnvmapSampler<'a> {
    /// `points` through `warp` of `env`.
    pub fn new(points: PrimaryPoints, warp: EnvWarp, env: &'a Environment) -> Self {
        Self { points, warp, env }
    }
}

impl DirectionSampler for EnvmapSampler<'_> {
    fn technique(&self) -> Technique {
        Technique::Envmap
    }

    /// `owen-sobol` and `halton` through the inverse CDF; `owen-sobol-hierarchical`
    /// and `halton-hierarchical` through hierarchical warping (`random` likewise).
    fn name(&self) -> &'static str {
        match (self.warp, self.points.generator()) {
            (EnvWarp::InverseCdf, g) => g.name(),
            (EnvWarp::Hierarchical, Generator::OwenSobol) => "owen-sobol-hierarchical",
            (EnvWarp::Hierarchical, Generator::Halton) => "halton-hierarchical",
            (EnvWarp::Hierarchical, Generator::Random) => "random-hierarchical",
            (EnvWarp::Hierarchical, Generator::Sot) => "sot-hierarchical",
            (EnvWarp::Hierarchical, Generator::Gbn) => "gbn-hierarchical",
        }
    }

    fn samples(&self, at: &ShadingPoint, key: PixelKey, _n: u32, out: &mut Vec<Sample>) {
        out.clear();
        out.extend(self.points.points(key).into_iter().map(|u| {
            let l = match self.warp {
                EnvWarp::InverseCdf => self.env.sample_inverse_cdf(u),
                EnvWarp::Hierarchical => self.env.sample_hierarchical(u),
            };
            let pdf = self.env.pdf(l);
            Sample {
                direction: l,
                weight: if pdf > 0.0 {
                    at.cosine_weighted(l) / pdf
                } else {
                    0.0
                },
            }
        }));
    }
}
