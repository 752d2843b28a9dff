//! The baseline BRDF samplers: uniform primary points pushed through the
//! renderer's mixture warp ([`brdf_mixture_real`]: GGX visible normals with
//! probability `p_s`, else cosine), weighted by `f cos / p` with the warp's exact
//! density [`brdf_mixture_pdf`].
//!
//! The lobe probability is the specular share of the albedo of the surface's
//! material, `p_s = A_spec / A` (the split of
//! [`directional_albedo_metallic`], as `BrdfTarget::sample` and the trainer's
//! warp use it for the dielectric), tabulated per material of the scene at 1°
//! steps of `θo` and interpolated linearly: which `p_s` is used only changes how
//! often each lobe is picked; the weight divides by the density of the same
//! `p_s`, so the estimator stays unbiased whatever the interpolation error.
//!
//! For the metal (metallic 1) the diffuse layer `(1 - m)(1 - F) / π` is 0, so
//! `p_s = 1`: pure GGX visible-normal sampling, what a renderer does for a metal
//! (and the weight `f cos / p` is at most `G2 / G1(wo) <= 1`, the Fresnel factor
//! being 1 at base colour 1; mirrored directions only add density). Any cosine
//! share would spend samples where only the lobe's tail is. Between the ends `A_spec / A` blends the two by the
//! albedo, `A(m) = (1 - m) A(0) + m A(1)`.

use super::primary::PrimaryPoints;
use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint, Technique};
use super::scene::Material;
use crate::sphere::brdf_albedo::directional_albedo_metallic;
use glam::DVec3;
use nuld_core::brdf::{alpha, MAX_THETA_O_DEG};
use nuld_core::warp::{brdf_mixture_pdf, brdf_mixture_real};
use rayon::prelude::*;

/// `p_s(θo)` for each material of a scene, on `θo = 0, 1, ..., 89` degrees.
#[derive(Clone, Debug)]
pub struct LobeTable {
    rows: Vec<(Material, Vec<f64>)>,
}

/// The specular share `A_spec / A` of the albedo of `material` at `theta_o_deg`
/// (1 for the metal, whose diffuse layer is 0, without the quadrature).
pub fn material_lobe_probability(material: Material, theta_o_deg: f64) -> f64 {
    if material.metallic >= 1.0 {
        return 1.0;
    }
    let a = directional_albedo_metallic(material.roughness, theta_o_deg, material.metallic);
    a.specular / a.total()
}

impl LobeTable {
    /// The table for `materials` (roughness in `[0.1, 1]`, metallic in
    /// `[0, 1]`); a few ms per material and degree, in parallel.
    pub fn new(materials: &[Material]) -> Self {
        let nodes = MAX_THETA_O_DEG as usize + 1;
        let rows = materials
            .iter()
            .map(|&m| {
                let ps = (0..nodes)
                    .into_par_iter()
                    .map(|t| material_lobe_probability(m, t as f64))
                    .collect();
                (m, ps)
            })
            .collect();
        Self { rows }
    }

    /// `p_s` at the table's material nearest `material` (in roughness plus
    /// metallic) and at `theta_o_deg` (clamped to `[0, 89]`), linear in `θo`.
    pub fn lobe_probability(&self, material: Material, theta_o_deg: f64) -> f64 {
        let distance = |m: &Material| {
            (m.roughness - material.roughness).abs() + (m.metallic - material.metallic).abs()
        };
        let Some((_, ps)) = self
            .rows
            .iter()
            .min_by(|a, b| distance(&a.0).total_cmp(&distance(&b.0)))
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
        let a = alpha(at.material.roughness);
        let p_s = self.lobes.lobe_probability(at.material, at.theta_o_deg());
        let wo = at.wo.to_array();
        out.extend(self.points.points(key).into_iter().map(|u| {
            let l = DVec3::from_array(brdf_mixture_real(wo, a, p_s, u.to_array()));
            let pdf = brdf_mixture_pdf(at.wo, a, p_s, l);
            let f_cos = at.material.cosine_weighted(at.wo, l);
            Sample {
                direction: at.frame.to_world(l),
                weight: if pdf > 0.0 { f_cos / pdf } else { 0.0 },
                pdf,
            }
        }));
    }

    fn pdf(&self, at: &ShadingPoint, l: DVec3) -> Option<f64> {
        let p_s = self.lobes.lobe_probability(at.material, at.theta_o_deg());
        Some(brdf_mixture_pdf(
            at.wo,
            alpha(at.material.roughness),
            p_s,
            at.frame.to_local(l),
        ))
    }
}
