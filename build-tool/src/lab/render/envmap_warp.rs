//! The baseline environment samplers: uniform primary points through the map's
//! marginal-conditional inverse CDF or through hierarchical warping of its
//! luminance, as renderers ship them, or through the product warp of `L cos` at
//! the normal that ours uses as its prior ([`Environment`]); weighted by
//! `f cos / pdf_env` with the warp's own pdf.

use super::environment::Environment;
use super::primary::{Generator, PrimaryPoints};
use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint, Technique};
use glam::DVec3;

/// Which warp of the map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvWarp {
    /// Marginal-conditional inverse CDF.
    InverseCdf,
    /// Hierarchical sample warping.
    Hierarchical,
    /// The product warp of `L max(0, n.l)` at the normal (ours' prior).
    Product,
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
    /// through hierarchical warping, `owen-sobol-product` through the product warp
    /// (the other generators likewise).
    fn name(&self) -> &'static str {
        match (self.warp, self.points.generator()) {
            (EnvWarp::InverseCdf, g) => g.name(),
            (EnvWarp::Hierarchical, Generator::OwenSobol) => "owen-sobol-hierarchical",
            (EnvWarp::Hierarchical, Generator::Halton) => "halton-hierarchical",
            (EnvWarp::Hierarchical, Generator::Random) => "random-hierarchical",
            (EnvWarp::Hierarchical, Generator::Sot) => "sot-hierarchical",
            (EnvWarp::Hierarchical, Generator::Gbn) => "gbn-hierarchical",
            (EnvWarp::Product, Generator::OwenSobol) => "owen-sobol-product",
            (EnvWarp::Product, Generator::Halton) => "halton-product",
            (EnvWarp::Product, Generator::Random) => "random-product",
            (EnvWarp::Product, Generator::Sot) => "sot-product",
            (EnvWarp::Product, Generator::Gbn) => "gbn-product",
        }
    }

    fn samples(&self, at: &ShadingPoint, key: PixelKey, _n: u32, out: &mut Vec<Sample>) {
        out.clear();
        let normal = at.frame.normal();
        out.extend(self.points.points(key).into_iter().map(|u| {
            let (l, pdf) = match self.warp {
                EnvWarp::InverseCdf => {
                    let l = self.env.sample_inverse_cdf(u);
                    (l, self.env.pdf(l))
                }
                EnvWarp::Hierarchical => {
                    let l = self.env.sample_hierarchical(u);
                    (l, self.env.pdf(l))
                }
                EnvWarp::Product => self.env.sample_product(normal, u),
            };
            Sample {
                direction: l,
                weight: if pdf > 0.0 {
                    at.cosine_weighted(l) / pdf
                } else {
                    0.0
                },
                pdf,
            }
        }));
    }

    fn pdf(&self, at: &ShadingPoint, l: DVec3) -> Option<f64> {
        Some(match self.warp {
            EnvWarp::InverseCdf | EnvWarp::Hierarchical => self.env.pdf(l),
            EnvWarp::Product => self.env.product_pdf(at.frame.normal(), l),
        })
    }
}
