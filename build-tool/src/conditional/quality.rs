//! A quick quality check of a conditional sampler at held-out conditions, in
//! network mode on the f16 parameters that ship.
//!
//! * **cap L2**: the paper's `D_cap,2` (Eq. 9, `theta` uniform) by Monte Carlo over
//!   shared measured caps ([`MeasuredCaps`]) against the condition's target, mean
//!   over instances, divided by the same for Owen-Sobol sets through the standard
//!   warp over as many seeds: for a BRDF sampler the target is the [`BrdfTarget`]
//!   and the warp the renderer's mixture ([`BrdfTarget::sample`]); for an
//!   environment sampler the target is the map lit through the cosine about the
//!   normal ([`crate::sphere::EnvmapDensity::cosine_weighted`], caps measured by its exact
//!   quadrature) and the warp that lit map's inverse CDF, which is what a renderer
//!   sampling the map for this one normal could do at best; a map of more than
//!   2048 x 1024 cells is lit through the training pool's box-filtered copy
//!   ([`EnvmapTarget::coarse_map`]), as the pool lights it;
//! * **diversity**: `D_cap,2` of the union of many instances over the mean of a
//!   single instance's (independent sets: about `1/sqrt(instances)`; identical
//!   sets: 1), and the mean angle from a point of one instance to the nearest point
//!   of the next instance over the mean nearest-neighbour angle within a set
//!   (independent Owen-Sobol sets: about 0.65; identical sets: 0).

use crate::baselines::warped_owen_sobol_directions;
use crate::network::Params;
use crate::progress::Progress;
use crate::sphere::brdf_prior::BrdfPrior;
use crate::sphere::metrics::diversity;
use crate::sphere::metrics::{CapRadius, MeasuredCaps};
use crate::sphere::{BrdfTarget, DirectionDensity};
use crate::train::pool::brdf_table_direction;
use crate::train::target::{EnvmapTarget, LoadedTarget};
use anyhow::Result;
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use nuld_core::brdf_prior::reads_metal_layer;
use nuld_core::conditional::{randomized_point, ConditionalTarget, PointWarp};
use nuld_core::envmap_tree::EnvmapTree as CoreTree;
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::Arc;

/// Settings of [`evaluate`].
#[derive(Clone, Debug, Serialize)]
pub struct QualityConfig {
    /// Held-out conditions in blob units: `(roughness, theta_o in degrees)` for a
    /// BRDF sampler, the normal's octahedral square point for an environment one.
    pub conditions: Vec<[f64; 2]>,
    /// A BRDF sampler's metallic at each condition (0 where missing; environment
    /// samplers ignore it).
    #[serde(default)]
    pub metallic: Vec<f64>,
    /// Instances (and baseline seeds) averaged per condition.
    pub instances: u32,
    /// Instances in the union of the diversity figure.
    pub union_instances: u32,
    /// Measured caps per condition.
    pub caps: usize,
    /// Seed of the caps and the baseline scrambles.
    pub seed: u64,
}

impl QualityConfig {
    /// A `k x k` grid of conditions at cell centres of `target`'s condition range
    /// (off any point-table grid with an odd node count... and most even ones):
    /// `(roughness, theta_o)` for the BRDF, the octahedral square `[0,1]^2` of the
    /// normal for a map; a BRDF's metallic cycles through 0, 1 and 0.5; 8
    /// instances, unions of 64, 4096 caps.
    pub fn held_out(target: &LoadedTarget, k: usize, seed: u64) -> Self {
        // Cell centre `j` of an axis of the unit square.
        let centre = |j: usize| (j as f64 + 0.5) / k as f64;
        let conditions = (0..k * k)
            .map(|j| target.condition([centre(j % k), centre(j / k)]))
            .collect();
        let metallic = match target {
            LoadedTarget::GltfBrdf(_) => (0..k * k).map(|j| [0.0, 1.0, 0.5][j % 3]).collect(),
            LoadedTarget::Envmap(_) => Vec::new(),
        };
        Self {
            conditions,
            metallic,
            instances: 8,
            union_instances: 64,
            caps: 4096,
            seed,
        }
    }
}

/// The figures of one held-out condition.
#[derive(Clone, Debug, Serialize)]
pub struct ConditionQuality {
    /// In blob units (see [`QualityConfig::conditions`]).
    pub condition: [f64; 2],
    /// A BRDF sampler's metallic.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub metallic: Option<f64>,
    /// An environment sampler's normal (world frame, `+z` up).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// Mean `D_cap,2` of single instances.
    pub ours: f64,
    /// Mean `D_cap,2` of warped Owen-Sobol sets.
    pub baseline: f64,
    /// `ours / baseline`.
    pub ratio: f64,
    /// The unbiased mode's sets (instance `k`'s randomly shifted lattice,
    /// `nuld_core::conditional::randomized_point` with seed `k`) over the
    /// baseline: mean over the instances.
    pub randomized_ratio: f64,
    /// `D_cap,2` of the union of instances over `ours`.
    pub union_ratio: f64,
    /// Nearest-neighbour angle across instances over within a set.
    pub nn_ratio: f64,
}

/// The summary over all held-out conditions.
#[derive(Clone, Debug, Serialize)]
pub struct Quality {
    /// Per condition (an environment sampler's normals that no light reaches are
    /// left out: their target is undefined and their weight 0).
    pub conditions: Vec<ConditionQuality>,
    /// Mean of the ratios.
    pub mean_ratio: f64,
    /// Mean of the unbiased mode's ratios.
    pub mean_randomized_ratio: f64,
    /// Largest ratio.
    pub worst_ratio: f64,
    /// Mean union ratio.
    pub mean_union_ratio: f64,
    /// Mean nearest-neighbour ratio.
    pub mean_nn_ratio: f64,
}

impl Quality {
    /// Whether the trained sets check at least as well as the unbiased mode, the
    /// prior's shifted lattice that no training touched: where they do not, the
    /// learned part did not help this target (`bake` then ships the lattice).
    pub fn training_helps(&self) -> bool {
        self.mean_ratio <= self.mean_randomized_ratio
    }
}

/// The directions of instance `k` of a BRDF sampler at `cond` and metallic 0
/// (network mode, `params` as given, through the shared prior), `p_s` the
/// condition's lobe probability (read by the mixture warp only,
/// [`PointWarp::direction`]).
pub fn instance_directions(params: &Params, cond: [f64; 2], p_s: f64, k: u32) -> Vec<DVec3> {
    let unit = LoadedTarget::gltf_brdf().normalized(cond);
    let warp = PointWarp::of(ConditionalTarget::GltfBrdf, &params.shape);
    let prior = BrdfPrior::shared();
    directions_at(
        params,
        unit,
        cond,
        (Domain::Hemisphere, warp, None, Some((&prior, 0.0))),
        p_s,
        (k, false),
    )
}

/// How a sampler's points become directions: the domain, the warp, an
/// environment sampler's tree, a BRDF sampler's prior and metallic.
type How<'a> = (
    Domain,
    PointWarp,
    Option<&'a CoreTree<'a>>,
    Option<(&'a BrdfPrior, f64)>,
);

/// Instance `k`'s directions at the condition `cond` (blob units; `unit` its
/// normalized form, the network's input) on `domain` through `warp` (and its
/// environment tree); in the unbiased mode (`randomized`) the runtime's
/// points instead, `randomized_point(n, g, k, i, k)` (seed `k`).
fn directions_at(
    params: &Params,
    unit: [f64; 2],
    cond: [f64; 2],
    (domain, warp, tree, brdf): How<'_>,
    p_s: f64,
    (k, randomized): (u32, bool),
) -> Vec<DVec3> {
    let (n, g) = (params.shape.n(), params.shape.lattice_generator());
    let metallic = brdf.map_or(0.0, |(_, m)| m);
    (0..n)
        .map(|i| {
            let s = match randomized {
                true => randomized_point(n, g, k, i, k).map(f64::from),
                false => params.square_point(unit, metallic, k, i),
            };
            match (warp, brdf) {
                (PointWarp::BrdfTable, Some((prior, m))) => {
                    brdf_table_direction(prior, [cond[0], cond[1], m], DVec2::from(s)).0
                }
                _ => DVec3::from_array(warp.direction(domain, cond, p_s, tree, s)),
            }
        })
        .collect()
}

/// One held-out condition's target and where a point of ours goes.
struct HeldOut {
    /// The target (caps, baseline warp).
    density: Box<dyn DirectionDensity>,
    /// The condition normalized to `[0,1]^2` (the network's input).
    unit: [f64; 2],
    /// The condition in blob units.
    cond: [f64; 2],
    /// An environment sampler's normal.
    normal: Option<DVec3>,
    /// Where the sets live.
    domain: Domain,
    /// The BRDF mixture's `p_s` (0 for a map: its warp does not read it).
    lobe_probability: f64,
    /// The target's kind.
    kind: ConditionalTarget,
    /// An environment sampler's map and tree.
    env: Option<Arc<EnvmapTarget>>,
    /// A BRDF sampler's prior and metallic.
    brdf: Option<(Arc<BrdfPrior>, f64)>,
}

impl HeldOut {
    /// `cond` of `target`, or `None` for a normal that no light reaches.
    fn new(target: &LoadedTarget, cond: [f64; 2], metallic: f64) -> Result<Option<Self>> {
        let unit = target.normalized(cond);
        Ok(match target {
            LoadedTarget::GltfBrdf(prior) => {
                let t = BrdfTarget::metallic(cond[0], cond[1], metallic, Domain::Hemisphere)?;
                Some(Self {
                    unit,
                    cond,
                    normal: None,
                    domain: Domain::Hemisphere,
                    lobe_probability: t.lobe_probability(),
                    density: Box::new(t),
                    kind: ConditionalTarget::GltfBrdf,
                    env: None,
                    brdf: Some((Arc::clone(prior), metallic)),
                })
            }
            LoadedTarget::Envmap(env) => {
                let normal = square_to_sphere(DVec2::from(cond));
                // Lit on the pool's copy: the map itself up to 2048 x 1024 cells,
                // above that blocks of cells that keep their mass (0.18° at
                // 4096 x 2048; the figures move by under 0.01,
                // docs/results/envmap.md#coarse-check). Lighting every cell of an
                // 8192 x 4096 map took the check three and a half minutes.
                let (lit, irradiance) = env.coarse_map().cosine_weighted(normal)?;
                (irradiance > 0.0).then(|| Self {
                    unit,
                    cond,
                    normal: Some(normal),
                    domain: Domain::Sphere,
                    lobe_probability: 0.0,
                    density: Box::new(lit) as Box<dyn DirectionDensity>,
                    kind: ConditionalTarget::EnvmapNormal,
                    env: Some(Arc::clone(env)),
                    brdf: None,
                })
            }
        })
    }

    /// The figures of `shipped` (the f16-rounded parameters) here; `index` numbers
    /// the condition in its config (the caps' seed).
    fn score(&self, shipped: &Params, config: &QualityConfig, index: usize) -> ConditionQuality {
        let n = shipped.shape.n() as usize;
        let density = self.density.as_ref();
        let caps = MeasuredCaps::draw(
            config.caps,
            crate::seeding::derive_seed(config.seed, index as u64),
            CapRadius::ThetaUniform,
            |w, t| density.cap_measure(w, t),
        );
        let d = |pts: &[DVec3]| caps.l2_squared(pts, CapRadius::ThetaUniform).0.sqrt();
        let tree = self.env.as_ref().map(|e| e.tree.tree());
        let warp = PointWarp::of(self.kind, &shipped.shape);
        let sets: Vec<Vec<DVec3>> = (0..config.union_instances.max(config.instances).max(2))
            .into_par_iter()
            .map(|k| {
                let (unit, cond, p_s) = (self.unit, self.cond, self.lobe_probability);
                let brdf = self.brdf.as_ref().map(|(p, m)| (p.as_ref(), *m));
                let how = (self.domain, warp, tree.as_ref(), brdf);
                directions_at(shipped, unit, cond, how, p_s, (k, false))
            })
            .collect();
        let randomized: Vec<f64> = (0..config.instances)
            .into_par_iter()
            .map(|k| {
                let (unit, cond, p_s) = (self.unit, self.cond, self.lobe_probability);
                let brdf = self.brdf.as_ref().map(|(p, m)| (p.as_ref(), *m));
                let how = (self.domain, warp, tree.as_ref(), brdf);
                d(&directions_at(shipped, unit, cond, how, p_s, (k, true)))
            })
            .collect();
        let mean = |v: Vec<f64>| v.iter().sum::<f64>() / v.len() as f64;
        let ours = mean(
            sets[..config.instances as usize]
                .par_iter()
                .map(|s| d(s))
                .collect(),
        );
        let baseline = mean(
            (0..config.instances as u64)
                .into_par_iter()
                .map(|s| {
                    d(&warped_owen_sobol_directions(
                        density,
                        n,
                        config.seed ^ (s + 1),
                    ))
                })
                .collect(),
        );
        // Nearest neighbours within a set need two points (`bake --n 1` has one).
        let spread =
            (n >= 2).then(|| diversity(&sets[..config.union_instances.max(2) as usize], &caps));
        ConditionQuality {
            condition: self.cond,
            metallic: self.brdf.as_ref().map(|b| b.1),
            normal: self.normal.map(|n| n.to_array()),
            ours,
            baseline,
            ratio: ours / baseline,
            randomized_ratio: mean(randomized) / baseline,
            union_ratio: spread.as_ref().map_or(f64::NAN, |s| s.union_ratio),
            nn_ratio: spread.as_ref().map_or(f64::NAN, |s| s.nn_ratio),
        }
    }
}

/// Scores `params` rounded to f16 on `target` (see the module docs), and at a
/// BRDF's metallic 1 the metal layer's network `metal` where given (what the
/// runtime reads there, [`crate::train::BrdfLayer`]). An error if a held-out
/// BRDF condition lies outside the range or a lit map cannot be built.
pub fn evaluate(
    params: &Params,
    metal: Option<&Params>,
    target: &LoadedTarget,
    config: &QualityConfig,
) -> Result<Quality> {
    let shared = params.rounded_to_f16();
    let metal = metal.map(Params::rounded_to_f16);
    let mut conditions = Vec::new();
    // Seconds per condition for a map (exact cap measures of the lit map).
    let progress = Progress::stderr("quality", config.conditions.len() as u64, "condition");
    for (index, &cond) in config.conditions.iter().enumerate() {
        let metallic = config.metallic.get(index).copied().unwrap_or(0.0);
        if let Some(held) = HeldOut::new(target, cond, metallic)? {
            let shipped = match (&metal, target) {
                (Some(metal), LoadedTarget::GltfBrdf(prior))
                    if reads_metal_layer(prior.grid, metallic) =>
                {
                    metal
                }
                _ => &shared,
            };
            conditions.push(held.score(shipped, config, index));
        }
        progress.inc(1);
    }
    progress.finish();
    let m = conditions.len().max(1) as f64;
    Ok(Quality {
        mean_ratio: conditions.iter().map(|c| c.ratio).sum::<f64>() / m,
        mean_randomized_ratio: conditions.iter().map(|c| c.randomized_ratio).sum::<f64>() / m,
        worst_ratio: conditions.iter().map(|c| c.ratio).fold(0.0, f64::max),
        mean_union_ratio: conditions.iter().map(|c| c.union_ratio).sum::<f64>() / m,
        mean_nn_ratio: conditions.iter().map(|c| c.nn_ratio).sum::<f64>() / m,
        conditions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::envmap::test_support::grey_map;
    use crate::train::TrainTarget;
    use nuld_core::network::{Activation, Shape};

    /// On a map lit only above the horizon (the row just above it is dark too,
    /// since the filtered light reaches half a pixel beyond the lit rows): the
    /// held-out normals are the cell centres of the octahedral square, each judged
    /// names its normal, and the normal `-z` (the square's corner), which faces
    /// only the dark lower half (E = 0), is left out; a network that ignores the
    /// instance makes identical instances (union ratio 1, no nearest-neighbour
    /// distance across), and one that lines its points up on one arc is far worse
    /// than Owen-Sobol through the lit map.
    #[test]
    fn an_envmap_check_judges_lit_normals_against_the_lit_maps_inverse_cdf() {
        let dir = std::env::temp_dir().join(format!("nuld-quality-envmap-{}", std::process::id()));
        let path = grey_map(
            &dir,
            "upper.png",
            [32, 16],
            |_, y| if y < 7 { 200 } else { 0 },
        );
        let target = TrainTarget::envmap(&path).unwrap().load().unwrap();
        let mut config = QualityConfig::held_out(&target, 4, 3);
        assert_eq!(config.conditions.len(), 16);
        assert_eq!(config.conditions[5], [0.375, 0.375]);
        let held_out = config.conditions.clone();
        config.conditions.push([0.0, 0.0]);
        config.caps = 512;
        config.union_instances = 8;
        // Point i at the square point (sigmoid(i / 4), 1/2) whatever the instance:
        // a per-index bias i / 16 on one hidden unit, read by the first output.
        let shape = Shape::new(16, &[4], Activation::Relu, 5).unwrap();
        let mut values = vec![0.0; shape.param_len()];
        for i in 0..16 {
            values[shape.embedding_offset(i)] = i as f64 / 16.0;
        }
        values[shape.layers().last().unwrap().weights] = 4.0;
        let same = Params { shape, values };
        let q = evaluate(&same, None, &target, &config).unwrap();
        let judged: Vec<[f64; 2]> = q.conditions.iter().map(|c| c.condition).collect();
        assert_eq!(judged, held_out);
        for c in &q.conditions {
            let n = DVec3::from_array(c.normal.unwrap());
            assert!((n - square_to_sphere(DVec2::from(c.condition))).length() < 1e-12);
            assert!(c.ratio > 2.0, "{c:?}");
            assert!((c.union_ratio - 1.0).abs() < 1e-12, "{c:?}");
            assert_eq!(c.nn_ratio, 0.0, "{c:?}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A map over the coarse copy's limit is judged, like the pool lights it,
    /// through the copy: a held-out normal's target is the copy lit through the
    /// normal's cosine (its cap measures bit for bit), not the map's every cell,
    /// whose sharp light measures otherwise; within the limit the map itself.
    #[test]
    fn a_large_maps_check_lights_the_coarse_copy() {
        let dir = std::env::temp_dir().join(format!("nuld-quality-coarse-{}", std::process::id()));
        let path = grey_map(&dir, "spots.png", [64, 32], |x, y| {
            if (x * 7 + y * 3) % 11 == 0 {
                255
            } else {
                3
            }
        });
        let loaded = TrainTarget::envmap(&path).unwrap().load().unwrap();
        let LoadedTarget::Envmap(env) = &loaded else {
            panic!("an envmap target");
        };
        let cells = env.map.width() * env.map.height();
        let (map, tree) = (env.map.clone(), env.tree.clone());
        let cond = [0.375, 0.625];
        let normal = square_to_sphere(DVec2::from(cond));
        let caps: Vec<(DVec3, f64)> = (0..32)
            .map(|k| {
                let t = 0.1 + 0.09 * k as f64;
                (
                    DVec3::new(t.cos(), t.sin(), 0.3 - 0.02 * k as f64).normalize(),
                    (0.2 * t).cos(),
                )
            })
            .collect();
        let measures = |d: &dyn DirectionDensity| -> Vec<u64> {
            caps.iter()
                .map(|&(c, t)| d.cap_measure(c, t).to_bits())
                .collect()
        };
        for (limit, coarse) in [(cells, false), (cells / 4, true)] {
            let env = EnvmapTarget::with_coarse_cells(map.clone(), tree.clone(), limit);
            let judged = env.coarse_map().cosine_weighted(normal).unwrap().0;
            let whole = env.map.cosine_weighted(normal).unwrap().0;
            let target = LoadedTarget::Envmap(Arc::new(env));
            let held = HeldOut::new(&target, cond, 0.0).unwrap().unwrap();
            let got = measures(held.density.as_ref());
            assert_eq!(got, measures(&judged), "limit {limit}");
            assert_eq!(got != measures(&whole), coarse, "limit {limit}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
