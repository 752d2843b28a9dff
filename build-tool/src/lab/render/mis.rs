//! Multiple importance sampling of the environment and the BRDF, as pbrt-v4's
//! path integrator combines light and BSDF sampling for direct lighting (Veach
//! 1997, §9.2): per pixel `n` samples `e_j` of an environment sampler with its
//! pdf `p_e` and `n` samples `b_j` of a BRDF sampler with its pdf `p_b`, and
//!
//! `I ≈ (1/n) Σ_j [ w_e(e_j) g(e_j) / p_e(e_j) + w_b(b_j) g(b_j) / p_b(b_j) ]`,
//! `g = f cos L V`,
//!
//! with the power heuristic (β = 2) `w_e = p_e² / (p_e² + p_b²)`,
//! `w_b = p_b² / (p_e² + p_b²)`, each pdf evaluated at the other technique's
//! samples through [`DirectionSampler::pdf`]. `w_e + w_b = 1` wherever either
//! pdf is positive, so the estimate is unbiased when each technique's samples
//! follow its pdf (and as biased as the samplers otherwise).
//!
//! The sampler hands the integrator `2n` samples whose weights already carry
//! `w / p` and `f cos`, so the integrator's `(1/n) Σ w_i L V` is the estimate
//! above. The BRDF half draws from the pixel's second key
//! ([`PixelKey::second`]), independent of the environment half.

use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint, Technique};
use glam::DVec3;
use std::sync::Arc;

thread_local! {
    /// The BRDF samples of the pixel being shaded on this thread.
    static BRDF_SCRATCH: std::cell::RefCell<Vec<Sample>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The power heuristic's weight of a technique of density `p` against the other
/// technique's `q`: `p² / (p² + q²)` (0 when both are 0).
pub fn power_heuristic(p: f64, q: f64) -> f64 {
    let (p2, q2) = (p * p, q * q);
    if p2 + q2 > 0.0 {
        p2 / (p2 + q2)
    } else {
        0.0
    }
}

/// An environment sampler and a BRDF sampler combined (module docs); named as
/// its environment sampler unless [`MisSampler::named`].
pub struct MisSampler<'a> {
    envmap: Arc<dyn DirectionSampler + 'a>,
    brdf: Arc<dyn DirectionSampler + 'a>,
    name: &'static str,
}

impl<'a> MisSampler<'a> {
    /// `envmap` and `brdf` combined; `None` unless both know their pdf (each
    /// [`DirectionSampler::pdf`] answers) and are of those techniques.
    pub fn new(
        envmap: Arc<dyn DirectionSampler + 'a>,
        brdf: Arc<dyn DirectionSampler + 'a>,
        probe: &ShadingPoint,
    ) -> Option<Self> {
        let knows = |s: &dyn DirectionSampler| s.pdf(probe, probe.frame.normal()).is_some();
        (envmap.technique() == Technique::Envmap
            && brdf.technique() == Technique::Brdf
            && knows(envmap.as_ref())
            && knows(brdf.as_ref()))
        .then(|| Self {
            name: envmap.name(),
            envmap,
            brdf,
        })
    }

    /// The combination named `name` (in `render.csv`).
    pub fn named(self, name: &'static str) -> Self {
        Self { name, ..self }
    }
}

impl DirectionSampler for MisSampler<'_> {
    fn technique(&self) -> Technique {
        Technique::Mis
    }

    fn name(&self) -> &'static str {
        self.name
    }

    /// `n` environment samples then `n` BRDF samples, each weight times its
    /// power-heuristic weight.
    fn samples(&self, at: &ShadingPoint, key: PixelKey, n: u32, out: &mut Vec<Sample>) {
        self.envmap.samples(at, key, n, out);
        for s in out.iter_mut().filter(|s| s.weight > 0.0) {
            let other = self.brdf.pdf(at, s.direction).unwrap_or(0.0);
            s.weight *= power_heuristic(s.pdf, other);
        }
        // The BRDF half in a scratch buffer of the thread's, reused from pixel to
        // pixel (no allocation per pixel).
        BRDF_SCRATCH.with_borrow_mut(|brdf| {
            self.brdf.samples(at, key.second(), n, brdf);
            out.extend(brdf.iter().filter(|s| s.weight > 0.0).map(|s| {
                let other = self.envmap.pdf(at, s.direction).unwrap_or(0.0);
                Sample {
                    weight: s.weight * power_heuristic(s.pdf, other),
                    ..*s
                }
            }));
        });
    }

    /// `None`: the combination has no single warp.
    fn pdf(&self, _at: &ShadingPoint, _l: DVec3) -> Option<f64> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_power_heuristic_weights_sum_to_one() {
        for (p, q) in [(1.0, 0.0), (2.0, 3.0), (1e-6, 1e6), (0.0, 4.0)] {
            let (a, b) = (power_heuristic(p, q), power_heuristic(q, p));
            assert!((a + b - 1.0).abs() < 1e-15, "{p} {q}");
        }
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(3.0, 4.0), 9.0 / 25.0);
    }
}
