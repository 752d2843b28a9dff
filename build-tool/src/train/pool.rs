//! The training conditions and their caps, measured once.
//!
//! A cap's target measure under the glTF BRDF has no closed form: a
//! [`BrdfTarget`] answers it from a `2^18`-point rule whose table takes ~0.1 s to
//! build, far too slow to pay per training step. The trainer therefore draws its
//! conditions from a fixed **pool**: `P` conditions spread over the whole range by
//! a scrambled Sobol sequence (so no two share a roughness or a view angle), each
//! with `C` caps (a scrambled 3D Sobol set, the direction optimizer's caps) whose
//! measures are computed once. A step picks conditions from the pool and a window
//! of `M` of each one's caps. The caps are measured with a `2^14`-point rule
//! ([`BrdfTarget::coarse`], [`POOL_RULE_POINTS`]): the pool is paid once, nothing per step.

use crate::baselines::warped_owen_sobol_directions;
use crate::discrepancy::caps::{cap_loss_and_gradient, Cap, CapArea};
use crate::discrepancy::GradientPath;
use crate::optimize::directions::map_jacobian;
use crate::optimize::directions::{epoch_caps, local_factor};
use crate::seeding::derive_seed;
use crate::sphere::{BrdfTarget, DirectionDensity};
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use nuld_core::brdf::{view_direction, BrdfModel, CONDITION_MAX, CONDITION_MIN};
use nuld_core::conditional::PointWarp;
use nuld_core::network::{instance_offset, shifted_lattice_point, Shape};
use nuld_core::sphere::hemisphere_to_square;
use rayon::prelude::*;

/// Points of the rule that measures a pool condition's caps: `2^14`, 1/16 of a
/// [`BrdfTarget::new`]'s, so that building the pool costs seconds, not minutes.
pub const POOL_RULE_POINTS: usize = 1 << 14;

/// The normalized condition in `[0,1]^2` of `(roughness, theta_o_deg)`: its place
/// between [`CONDITION_MIN`] and [`CONDITION_MAX`].
pub fn normalized(cond: [f64; 2]) -> [f64; 2] {
    core::array::from_fn(|a| (cond[a] - CONDITION_MIN[a]) / (CONDITION_MAX[a] - CONDITION_MIN[a]))
}

/// One training condition: what a step needs to score a set for it.
pub struct PoolCondition {
    /// `(roughness, theta_o in degrees)`.
    pub cond: [f64; 2],
    /// [`normalized`] `cond`, the network's condition input.
    pub unit: [f64; 2],
    /// View direction.
    pub wo: DVec3,
    /// Directional albedo, the normalizer of the target density.
    pub albedo: f64,
    /// The caps.
    pub caps: Vec<Cap>,
    /// Their target measures.
    pub measures: Vec<f64>,
    /// Square points of the renderer's warp ([`BrdfTarget::sample`]) applied to
    /// the shifted lattice of instances `0..PRETRAIN_INSTANCES`, in
    /// `[instance][index]` order: the pretraining targets
    /// ([`super::TrainConfig::pretrain_steps`]).
    pub warp_targets: Vec<DVec2>,
    /// Cap loss of `N` Owen-Sobol points through the renderer's warp on the first
    /// window of caps: the scale against which the trainer ranks conditions.
    pub baseline_loss: f64,
    /// The specular share `p_s = A_spec / A` of the albedo, the mixture warp's lobe
    /// probability.
    pub lobe_probability: f64,
    /// How the network's points become directions ([`PointWarp::of_shape`]).
    pub warp: PointWarp,
}

impl PoolCondition {
    /// Target density `q(x) = f(wo, x) (n.x) / A` at direction `x`.
    pub fn pdf(&self, x: DVec3) -> f64 {
        BrdfModel::Gltf.cosine_weighted(self.wo, x, self.cond[0]) / self.albedo
    }

    /// Local sharpness factor `sqrt(2 pi q(x))`, clamped (direction optimizer's
    /// local units).
    pub fn local_factor(&self, x: DVec3) -> f64 {
        local_factor(Domain::Hemisphere.area(), self.pdf(x))
    }

    /// The direction of the network's point `p` ([`PointWarp::direction`]) and its
    /// derivatives along `p.x` and `p.y`: for the mixture warp by central
    /// differences of step `1e-6`, zeroed where they straddle the lobe boundary (a
    /// jump that no gradient can follow); for the hemisphere map exact.
    pub fn direction(&self, p: DVec2) -> (DVec3, DVec3, DVec3) {
        let warp = |u: DVec2| {
            DVec3::from_array(self.warp.direction(
                Domain::Hemisphere,
                self.cond,
                self.lobe_probability,
                u.to_array(),
            ))
        };
        if self.warp == PointWarp::EqualArea {
            let (jx, jy) = map_jacobian(Domain::Hemisphere, p);
            return (warp(p), jx, jy);
        }
        let [jx, jy] = self
            .warp
            .direction_differences(
                Domain::Hemisphere,
                self.cond,
                self.lobe_probability,
                p.to_array(),
                1e-6,
            )
            .map(|j| {
                let j = DVec3::from_array(j);
                // A smooth warp moves a direction by at most ~1/alpha per unit of p.
                if j.is_finite() && j.length() < 1e3 {
                    j
                } else {
                    DVec3::ZERO
                }
            });
        (warp(p), jx, jy)
    }
}

/// Instances with pretraining targets per pool condition.
pub const PRETRAIN_INSTANCES: u32 = 8;

/// The warp's square points for the shifted lattices of the first
/// [`PRETRAIN_INSTANCES`] instances, so the start is a warped randomly shifted
/// lattice: with a [lattice residual](Shape::lattice_residual) the shifted lattice
/// point itself (a zero residual; the mixture warp follows), otherwise the
/// square point of the renderer's mixture warp ([`BrdfTarget::sample`]) of it.
fn warp_targets(target: &BrdfTarget, shape: &Shape) -> Vec<DVec2> {
    let (shape_n, g) = (shape.n(), shape.lattice_generator());
    let residual = shape.lattice_residual();
    (0..PRETRAIN_INSTANCES)
        .flat_map(|k| {
            let z = instance_offset::<f64>(k);
            (0..shape_n).map(move |i| {
                let u = shifted_lattice_point(i, shape_n, g, z);
                let u = DVec2::new(u[0], u[1]);
                if residual {
                    u
                } else {
                    hemisphere_to_square(target.sample(u))
                }
            })
        })
        .collect()
}

/// The conditions of a training run.
pub struct ConditionPool {
    /// Conditions in pool order.
    pub conditions: Vec<PoolCondition>,
}

impl ConditionPool {
    /// `count` conditions with `caps` caps each, for the sets of a network of
    /// `shape`, from `seed`; built in parallel, identical for any thread count.
    pub fn new(count: usize, caps: usize, window: usize, shape: &Shape, seed: u64) -> Self {
        let scramble = derive_seed(seed, 0x706f_6f6c) as u32;
        let conditions = (0..count)
            .into_par_iter()
            .map(|p| {
                let u = [
                    sobol_burley::sample(p as u32, 0, scramble) as f64,
                    sobol_burley::sample(p as u32, 1, scramble) as f64,
                ];
                let cond: [f64; 2] = core::array::from_fn(|a| {
                    CONDITION_MIN[a] + u[a] * (CONDITION_MAX[a] - CONDITION_MIN[a])
                });
                condition(cond, caps, window, shape, derive_seed(seed, p as u64))
            })
            .collect();
        Self { conditions }
    }

    /// Number of conditions.
    pub fn len(&self) -> usize {
        self.conditions.len()
    }

    /// Whether the pool is empty.
    pub fn is_empty(&self) -> bool {
        self.conditions.is_empty()
    }
}

fn condition(
    cond: [f64; 2],
    caps: usize,
    window: usize,
    shape: &Shape,
    seed: u64,
) -> PoolCondition {
    let n = shape.n() as usize;
    let target = BrdfTarget::coarse(cond[0], cond[1], POOL_RULE_POINTS)
        .expect("pool conditions lie in the condition range");
    let caps = epoch_caps(seed, 0, caps);
    let measures: Vec<f64> = caps
        .iter()
        .map(|c| target.cap_measure(c.center, c.cos_theta))
        .collect();
    let pc = PoolCondition {
        cond,
        unit: normalized(cond),
        wo: view_direction(cond[1]),
        albedo: target.albedo(),
        caps,
        measures,
        warp_targets: warp_targets(&target, shape),
        baseline_loss: 0.0,
        lobe_probability: target.lobe_probability(),
        warp: PointWarp::of_shape(shape),
    };
    let w = window.min(pc.caps.len());
    let pts = warped_owen_sobol_directions(&target, n, seed);
    let local: Vec<f64> = pts.iter().map(|&x| pc.local_factor(x)).collect();
    let mut g = vec![DVec3::ZERO; n];
    let baseline_loss = cap_loss_and_gradient(
        &pts,
        &pc.caps[..w],
        CapArea::Precomputed(&pc.measures[..w]),
        1.0,
        Some(&local),
        GradientPath::Fast,
        &mut g,
    );
    PoolCondition {
        baseline_loss,
        ..pc
    }
}
