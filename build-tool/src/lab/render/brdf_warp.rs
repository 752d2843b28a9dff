//! The baseline BRDF samplers: uniform primary points pushed through the
//! renderer's mixture warp ([`brdf_mixture_real`]: GGX visible normals with
//! probability `p_s`, else cosine), weighted by `f cos / p` with the warp's exact
//! density [`brdf_mixture_pdf`].
//!
//! The lobe probability is the specular share of the albedo,
//! `p_s = A_spec / A` ([`lobe_probability`], as `BrdfTarget::sample` and the
//! trainer's warp use it), tabulated per roughness of the scene at 1° steps of
//! `θo` and interpolated linearly: which `p_s` is used only changes how often each
//! lobe is picked; the weight divides by the density of the same `p_s`, so the
//! estimator stays unbiased whatever the interpolation error.

use super::primary::PrimaryPoints;
use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint, Technique};
use crate::sphere::brdf_albedo::lobe_probability;
use glam::DVec3;
use nuld_core::brdf::{alpha, BrdfModel, MAX_THETA_O_DEG};
use nuld_core::warp::{brdf_mixture_pdf, brdf_mixture_real};
use rayon::prelude::*;

/// `p_s(θo)` for each roughness of a scene, on `θo = 0, 1, ..., 89` degrees.
#[derive(Clone, Debug)]
pub struct LobeTable {
    rows: Vec<(f64, Vec<f64>)>,
}

impl LobeTable {
    /// The table for `roughnesses` (each in `[0.1, 1]`); a few ms per roughness and
    /// degree, in parallel.
    pub fn new(roughnesses: &[f64]) -> Self {
        let nodes = MAX_THETA_O_DEG as usize + 1;
        let rows = roughnesses
            .iter()
            .map(|&r| {
                let ps = (0..nodes)
                    .into_par_iter()
                    .map(|t| lobe_probability(BrdfModel::Gltf, r, t as f64))
                    .collect();
                (r, ps)
            })
            .collect();
        Self { rows }
    }

    /// `p_s` at the table's roughness nearest `roughness` and at `theta_o_deg`
    /// (clamped to `[0, 89]`), linear in `θo`.
    pub fn lobe_probability(&self, roughness: f64, theta_o_deg: f64) -> f64 {
        let Some((_, ps)) = self
            .rows
            .iter()
            .min_by(|a, b| (a.0 - roughness).abs().total_cmp(&(b.0 - roughness).abs()))
        else {
            return 0.5;
        };
        let t = theta_o_deg.clamp(0.0, (ps.len() - 1) as f64);
        let i = (t as usize).min(ps.len() - 2);
        let f = t - i as f64;
        ps[i] + f * (ps[i + 1] - ps[i])
    }
}

/// A baseline BRDF sampler: `points` through the mixture warp.
pub struct MixtureSampler<'a> {
    points: PrimaryPoints,
    lobes: &'a LobeTable,
}

impl<'a> MixtureSampler<'a> {
    /// The sampler of `points` with the lobe probabilities of `lobes`.
    pub fn new(points: PrimaryPoints, lobes: &'a LobeTable) -> Self {
        Self { points, lobes }
    }
}

impl DirectionSampler for MixtureSampler<'_> {
    fn technique(&self) -> Technique {
        Technique::Brdf
    }

    fn name(&self) -> &'static str {
        self.points.generator().name()
    }

    fn samples(&self, at: &ShadingPoint, key: PixelKey, _n: u32, out: &mut Vec<Sample>) {
        out.clear();
        let a = alpha(at.roughness);
        let p_s = self.lobes.lobe_probability(at.roughness, at.theta_o_deg());
        let wo = at.wo.to_array();
        out.extend(self.points.points(key).into_iter().map(|u| {
            let l = DVec3::from_array(brdf_mixture_real(wo, a, p_s, u.to_array()));
            let pdf = brdf_mixture_pdf(at.wo, a, p_s, l);
            let f_cos = nuld_core::brdf::cosine_weighted(at.wo, l, at.roughness);
            Sample {
                direction: at.frame.to_world(l),
                weight: if pdf > 0.0 { f_cos / pdf } else { 0.0 },
                pdf,
            }
        }));
    }

    fn pdf(&self, at: &ShadingPoint, l: DVec3) -> Option<f64> {
        let p_s = self.lobes.lobe_probability(at.roughness, at.theta_o_deg());
        Some(brdf_mixture_pdf(
            at.wo,
            alpha(at.roughness),
            p_s,
            at.frame.to_local(l),
        ))
    }
}
