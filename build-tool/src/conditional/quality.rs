//! A quick quality check of a conditional BRDF sampler at held-out conditions,
//! in network mode on the f16 parameters that ship.
//!
//! * **cap L2**: the paper's `D_cap,2` (Eq. 9, `theta` uniform) by Monte Carlo over
//!   shared measured caps ([`MeasuredCaps`]) against the target [`BrdfTarget`],
//!   mean over instances, divided by the same for Owen-Sobol sets warped by the
//!   renderer's mixture warp ([`BrdfTarget::sample`]) over as many seeds;
//! * **diversity**: `D_cap,2` of the union of many instances over the mean of a
//!   single instance's (independent sets: about `1/sqrt(instances)`; identical
//!   sets: 1), and the mean angle from a point of one instance to the nearest point
//!   of the next instance over the mean nearest-neighbour angle within a set
//!   (independent Owen-Sobol sets: about 0.65; identical sets: 0).

use crate::baselines::warped_owen_sobol_directions;
use crate::eval::conditional::diversity;
use crate::network::Params;
use crate::sphere::metrics::{CapRadius, MeasuredCaps};
use crate::sphere::{BrdfTarget, DirectionDensity};
use crate::train::pool::normalized;
use glam::DVec3;
use nuld_core::blob::Domain;
use nuld_core::brdf::{CONDITION_MAX, CONDITION_MIN};
use nuld_core::conditional::PointWarp;
use rayon::prelude::*;
use serde::Serialize;

/// Settings of [`evaluate`].
#[derive(Clone, Debug, Serialize)]
pub struct QualityConfig {
    /// Held-out conditions `(roughness, theta_o in degrees)`.
    pub conditions: Vec<[f64; 2]>,
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
    /// A `k x k` grid of conditions at cell centres of the condition range
    /// (off any point-table grid with an odd node count... and most even ones),
    /// 8 instances, unions of 64, 4096 caps.
    pub fn held_out(k: usize, seed: u64) -> Self {
        // Cell centre `j` of axis `a` of the condition range.
        let at = |j: usize, a: usize| {
            let (lo, hi) = (CONDITION_MIN[a], CONDITION_MAX[a]);
            lo + (j as f64 + 0.5) / k as f64 * (hi - lo)
        };
        let conditions = (0..k * k).map(|j| [at(j % k, 0), at(j / k, 1)]).collect();
        Self {
            conditions,
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
    /// `(roughness, theta_o in degrees)`.
    pub condition: [f64; 2],
    /// Mean `D_cap,2` of single instances.
    pub ours: f64,
    /// Mean `D_cap,2` of warped Owen-Sobol sets.
    pub baseline: f64,
    /// `ours / baseline`.
    pub ratio: f64,
    /// `D_cap,2` of the union of instances over `ours`.
    pub union_ratio: f64,
    /// Nearest-neighbour angle across instances over within a set.
    pub nn_ratio: f64,
}

/// The summary over all held-out conditions.
#[derive(Clone, Debug, Serialize)]
pub struct Quality {
    /// Per condition.
    pub conditions: Vec<ConditionQuality>,
    /// Mean of the ratios.
    pub mean_ratio: f64,
    /// Largest ratio.
    pub worst_ratio: f64,
    /// Mean union ratio.
    pub mean_union_ratio: f64,
    /// Mean nearest-neighbour ratio.
    pub mean_nn_ratio: f64,
}

/// The directions of instance `k` at `cond` (network mode, `params` as given),
/// `p_s` the condition's lobe probability (used by the mixture warp,
/// [`PointWarp::direction`]).
pub fn instance_directions(params: &Params, cond: [f64; 2], p_s: f64, k: u32) -> Vec<DVec3> {
    let unit = normalized(cond);
    let warp = PointWarp::of_shape(&params.shape);
    (0..params.shape.n())
        .map(|i| {
            let s = params.square_point(unit, k, i);
            DVec3::from_array(warp.direction(Domain::Hemisphere, cond, p_s, s))
        })
        .collect()
}

/// Scores `params` rounded to f16 (see the module docs).
pub fn evaluate(params: &Params, config: &QualityConfig) -> Quality {
    let shipped = params.rounded_to_f16();
    let n = params.shape.n() as usize;
    let conditions: Vec<ConditionQuality> = config
        .conditions
        .iter()
        .enumerate()
        .map(|(ci, &cond)| {
            let target = BrdfTarget::new(cond[0], cond[1], Domain::Hemisphere)
                .expect("held-out conditions lie in the range");
            let caps = MeasuredCaps::draw(
                config.caps,
                crate::seeding::derive_seed(config.seed, ci as u64),
                CapRadius::ThetaUniform,
                |w, t| target.cap_measure(w, t),
            );
            let d = |pts: &[DVec3]| caps.l2_squared(pts, CapRadius::ThetaUniform).0.sqrt();
            let sets: Vec<Vec<DVec3>> = (0..config.union_instances.max(config.instances).max(2))
                .into_par_iter()
                .map(|k| instance_directions(&shipped, cond, target.lobe_probability(), k))
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
                            &target,
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
                condition: cond,
                ours,
                baseline,
                ratio: ours / baseline,
                union_ratio: spread.as_ref().map_or(f64::NAN, |s| s.union_ratio),
                nn_ratio: spread.as_ref().map_or(f64::NAN, |s| s.nn_ratio),
            }
        })
        .collect();
    let m = conditions.len().max(1) as f64;
    Quality {
        mean_ratio: conditions.iter().map(|c| c.ratio).sum::<f64>() / m,
        worst_ratio: conditions.iter().map(|c| c.ratio).fold(0.0, f64::max),
        mean_union_ratio: conditions.iter().map(|c| c.union_ratio).sum::<f64>() / m,
        mean_nn_ratio: conditions.iter().map(|c| c.nn_ratio).sum::<f64>() / m,
        conditions,
    }
}
