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
//!
//! An environment sampler's pool ([`TrainTarget::Envmap`]) holds normals instead,
//! spread uniformly over the sphere (the condition is the normal's equal-area
//! octahedral square point), each with the caps of `q(l | n) ∝ L(l) max(0, n.l)`
//! measured on the mass-adaptive rule of
//! [`crate::sphere::EnvmapDensity::cosine_weighted`].

use super::target::{EnvmapTarget, LoadedTarget, TrainTarget};
use super::BrdfLayer;
use crate::baselines::{seeded_owen_sobol, warped_owen_sobol_directions};
use crate::descent::local_factor;
use crate::discrepancy::caps::epoch_caps;
use crate::discrepancy::caps::{cap_loss_and_gradient, Cap, CapArea};
use crate::discrepancy::GradientPath;
use crate::progress::Progress;
use crate::seeding::derive_seed;
use crate::sphere::brdf_prior::BrdfPrior;
use crate::sphere::geometry::map_jacobian;
use crate::sphere::{BrdfTarget, CapMeasureTable, DirectionDensity, EnvmapTree, TabulatedWarp};
use anyhow::Result;
use glam::{DVec2, DVec3};
use nuld_core::blob::Domain;
use nuld_core::brdf::{gltf_metallic, view_direction, view_direction_real};
use nuld_core::brdf_prior::query_square;
use nuld_core::conditional::{ConditionalTarget, PointWarp};
use nuld_core::network::{shifted_lattice_point, Shape};
use nuld_core::sphere::{hemisphere_to_square, sphere_to_square, square_to_sphere};
use rayon::prelude::*;
use std::sync::Arc;

/// Points of the rule that measures a pool condition's caps: `2^14`, 1/16 of a
/// [`BrdfTarget::new`]'s, so that building the pool costs seconds, not minutes.
pub const POOL_RULE_POINTS: usize = 1 << 14;

/// Most batches of `count` candidates [`ConditionPool::new`] draws to find
/// `count` conditions that teach something. Every lit direction of a map lights
/// the half of the sphere's normals about it, so the first batch holds about
/// half its count or more and two or three suffice; a map lit nowhere is refused
/// before ([`crate::sphere::EnvmapDensity`]).
const MAX_POOL_BATCHES: usize = 8;

/// Cells per side of the tabulated inverse CDF (2 x 2 midpoints per cell) that
/// warps a BRDF pool condition's baseline. The tournament draws conditions by
/// their loss over this baseline; over the renderer's VNDF/cosine mixture instead,
/// grazing views, where the mixture is far worse than the exact inverse CDF,
/// looked easy and were rarely drawn (README.md: 0.852 against 0.845 of the exact
/// baseline at N = 64). 256 cells keep the pool's cost at seconds.
pub const POOL_BASELINE_TABULATION: usize = 256;

/// What a condition's target density is made of.
pub enum ConditionDensity {
    /// The glTF metallic-roughness BRDF at a view.
    Brdf {
        /// View direction.
        wo: DVec3,
        /// The metallic in `[0, 1]`.
        metallic: f64,
        /// Directional albedo, the normalizer of the target density.
        albedo: f64,
        /// The tabulated prior ([`PointWarp::BrdfTable`]).
        prior: Arc<BrdfPrior>,
    },
    /// An environment map through the cosine about a normal.
    Envmap {
        /// The unit normal.
        normal: DVec3,
        /// The map and its tree, shared by the pool.
        env: Arc<EnvmapTarget>,
        /// `1 / ∫ pdf_map(l) max(0, n.l) dl`, the normalizer.
        scale: f64,
    },
}

/// One training condition: what a step needs to score a set for it.
pub struct PoolCondition {
    /// The condition in blob units: `(roughness, theta_o in degrees)` for the
    /// BRDF, the normal's octahedral square point for a map.
    pub cond: [f64; 2],
    /// [`LoadedTarget::normalized`] `cond`, the network's condition input.
    pub unit: [f64; 2],
    /// The BRDF's metallic (0 for a map): the network's metallic input where
    /// it reads one ([`nuld_core::network::Shape::metallic_input`]).
    pub metallic: f64,
    /// The target density's ingredients.
    pub density: ConditionDensity,
    /// Where the directions live.
    pub domain: Domain,
    /// The caps.
    pub caps: Vec<Cap>,
    /// Their target measures.
    pub measures: Vec<f64>,
    /// Square points of the renderer's warp ([`BrdfTarget::sample`]) applied to
    /// the shifted lattice of instances `0..PRETRAIN_INSTANCES`, in
    /// `[instance][index]` order: the pretraining targets
    /// ([`super::TrainConfig::pretrain_steps`]).
    pub warp_targets: Vec<DVec2>,
    /// Cap loss of `N` Owen-Sobol points on the first window of caps, through the
    /// target's exact tabulated inverse CDF ([`POOL_BASELINE_TABULATION`]) for
    /// the BRDF, through the map's inverse CDF for a normal: the scale against
    /// which the trainer ranks conditions.
    pub baseline_loss: f64,
    /// The specular share `p_s = A_spec / A` of the albedo, the mixture warp's lobe
    /// probability (0 for a map).
    pub lobe_probability: f64,
    /// How the network's points become directions ([`PointWarp::of`]).
    pub warp: PointWarp,
}

impl PoolCondition {
    /// Whether training on this condition can improve the sampler: not for a
    /// normal that no light reaches. The estimate there is 0 whatever the set
    /// (its weight `E(n)` is 0, and every `L cos` it reads too), while the
    /// prior still puts every point in the map's light (below that normal's
    /// horizon), so the set could never follow the stand-in target of the
    /// cosine lobe: such conditions' losses stayed near 1 a cap, the
    /// tournament drew them most, and their gradients wrecked the lit normals'
    /// sets (`scripts/synthetic-maps.py`'s map lit by one pixel checked at 5.50
    /// of the baseline with them, 3.45 without).
    pub fn teaches(&self) -> bool {
        match &self.density {
            ConditionDensity::Envmap { scale, .. } => *scale > 0.0,
            ConditionDensity::Brdf { .. } => true,
        }
    }

    /// Target density at direction `x`: `q(x) = f(wo, x) (n.x) / A` for the BRDF,
    /// `pdf_map(x) max(0, n.x) scale` for a map.
    pub fn pdf(&self, x: DVec3) -> f64 {
        match &self.density {
            ConditionDensity::Brdf {
                wo,
                metallic,
                albedo,
                ..
            } => {
                gltf_metallic(wo.to_array(), x.to_array(), self.cond[0], *metallic) * x.z.max(0.0)
                    / albedo
            }
            ConditionDensity::Envmap { normal, env, scale } => {
                env.coarse_map().pdf(x) * normal.dot(x).max(0.0) * scale
            }
        }
    }

    /// Local sharpness factor `sqrt(area q(x))`, clamped (direction optimizer's
    /// local units).
    pub fn local_factor(&self, x: DVec3) -> f64 {
        local_factor(self.domain.area(), self.pdf(x))
    }

    /// The direction of the network's point `p` ([`PointWarp::direction`]) and its
    /// derivatives along `p.x` and `p.y`: for the mixture warp by central
    /// differences of step `1e-6`, zeroed where they straddle the lobe boundary (a
    /// jump that no gradient can follow); for the environment tree the descent's
    /// Jacobian (its slopes, and inside a shaped leaf the conditional's shift
    /// with `x`) through the sphere map, exact within the piece of the tree the
    /// point falls in; for the equal-area maps exact.
    pub fn direction(&self, p: DVec2) -> (DVec3, DVec3, DVec3) {
        if let (
            PointWarp::BrdfTable,
            ConditionDensity::Brdf {
                metallic, prior, ..
            },
        ) = (self.warp, &self.density)
        {
            return brdf_table_direction(prior, [self.cond[0], self.cond[1], *metallic], p);
        }
        let tree = match &self.density {
            ConditionDensity::Envmap { env, .. } => Some(env.tree.tree()),
            ConditionDensity::Brdf { .. } => None,
        };
        if let (PointWarp::EnvmapTree, Some(tree)) = (self.warp, &tree) {
            // Within a piece the tree's warp has a closed-form Jacobian (zero
            // across nothing, unlike differences, and one descent instead of five).
            return EnvmapTree::sample_with_jacobian(tree, self.cond, p);
        }
        let tree = tree.as_ref();
        let warp = |u: DVec2| {
            DVec3::from_array(self.warp.direction(
                self.domain,
                self.cond,
                self.lobe_probability,
                tree,
                u.to_array(),
            ))
        };
        if self.warp == PointWarp::EqualArea {
            let (jx, jy) = map_jacobian(self.domain, p);
            return (warp(p), jx, jy);
        }
        let [jx, jy] = self
            .warp
            .direction_differences(
                self.domain,
                self.cond,
                self.lobe_probability,
                tree,
                p.to_array(),
                1e-6,
            )
            .map(|j| followable(DVec3::from_array(j)));
        (warp(p), jx, jy)
    }
}

/// The direction of the BRDF prior's primary point `p` at `[roughness, θo,
/// metallic]` (`f64` warp over the prior's tables, [`BrdfPrior::core_f64`]) and
/// its derivatives along `p.x` and `p.y`: the table's exact slopes
/// ([`nuld_core::brdf_prior::BrdfPrior::square_with_slopes`], one warp) through
/// the half-vector map's central differences of step `1e-6` in the square (no
/// table read), a column zeroed where they straddle the edge of the prior's
/// support (a jump to `+z`, which no gradient can follow).
pub fn brdf_table_direction(prior: &BrdfPrior, cond: [f64; 3], p: DVec2) -> (DVec3, DVec3, DVec3) {
    let core = prior
        .core_f64()
        .expect("the BRDF sampler's prior is half-vector");
    let (q, pdf, [dx_dux, dx_duy, dy_duy]) = core.square_with_slopes(cond, p.to_array());
    let (wo, square) = (
        view_direction_real(cond[1]),
        query_square(core.grid(), cond),
    );
    let at = |q: DVec2| {
        square
            .direction(wo, q.to_array())
            .map(|(wi, _)| DVec3::from_array(wi))
    };
    let q = DVec2::from(q);
    let Some(d) = at(q).filter(|_| pdf > 0.0) else {
        return (DVec3::Z, DVec3::ZERO, DVec3::ZERO);
    };
    let h = 1e-6;
    // The map's derivative along `e`, on a step kept inside the square.
    let diff = |e: DVec2| {
        let (hi, lo) = (
            (q + h * e).clamp(DVec2::ZERO, DVec2::ONE),
            (q - h * e).clamp(DVec2::ZERO, DVec2::ONE),
        );
        match (at(hi), at(lo)) {
            (Some(a), Some(b)) => (a - b) / (hi - lo).dot(e),
            _ => DVec3::ZERO,
        }
    };
    let (d_dx, d_dy) = (diff(DVec2::X), diff(DVec2::Y));
    (
        d,
        followable(d_dx * dx_dux),
        followable(d_dx * dx_duy + d_dy * dy_duy),
    )
}

/// A direction's derivative `j` along a primary coordinate, or 0 where no
/// gradient should follow it: a smooth warp moves a direction by at most about
/// `1 / alpha` per unit of the square, so a finite difference that is not
/// finite or exceeds `1e3` straddles a jump.
fn followable(j: DVec3) -> DVec3 {
    if j.is_finite() && j.length() < 1e3 {
        j
    } else {
        DVec3::ZERO
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
            let z = shape.instance_offset::<f64>(k);
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
    /// The target's data, as read once for the pool (distillation reuses it).
    pub target: LoadedTarget,
}

impl ConditionPool {
    /// `count` conditions of `target` (a BRDF's metallic drawn for `layer` and
    /// the metallic nodes `nodes`, [`BrdfLayer::pool_metallic`]) with `caps` caps each, for the sets of a
    /// network of `shape`, from `seed`; built in parallel, identical for any thread
    /// count. An error if a map cannot be read, or if an environment sampler's
    /// network has the BRDF mixture's lattice residual.
    pub fn new(
        target: &TrainTarget,
        (layer, nodes): (BrdfLayer, &[f64]),
        count: usize,
        caps: usize,
        window: usize,
        shape: &Shape,
        seed: u64,
    ) -> Result<Self> {
        let loaded = target.load()?;
        let scramble = derive_seed(seed, 0x706f_6f6c) as u32;
        let candidate = |p: usize| -> Result<PoolCondition> {
            let u = [
                sobol_burley::sample(p as u32, 0, scramble) as f64,
                sobol_burley::sample(p as u32, 1, scramble) as f64,
            ];
            let seed = derive_seed(seed, p as u64);
            let cond = loaded.condition(u);
            match &loaded {
                LoadedTarget::GltfBrdf(prior) => {
                    let v = sobol_burley::sample(p as u32, 2, scramble) as f64;
                    let m = layer.pool_metallic(nodes, v);
                    let cond = [cond[0], cond[1], m];
                    condition(prior, cond, caps, window, shape, seed)
                }
                LoadedTarget::Envmap(env) => envmap_condition(env, cond, caps, window, shape, seed),
            }
        };
        // Candidates in the sequence's order, a batch of `count` at a time, keeping
        // the first `count` that teach something ([`PoolCondition::teaches`]).
        let mut conditions = Vec::with_capacity(count);
        for batch in 0..MAX_POOL_BATCHES {
            let first = batch * count;
            // Named as `bake` names the training it feeds ("train metal").
            let mut phase = match (&loaded, layer) {
                (LoadedTarget::GltfBrdf(_), BrdfLayer::Metal) => "pool metal".to_string(),
                _ => "pool".to_string(),
            };
            if batch > 0 {
                phase += &format!(", batch {} (normals that light reaches)", batch + 1);
            }
            let progress = Progress::stderr(&phase, count as u64, "condition");
            let found = (first..first + count)
                .into_par_iter()
                .map(|p| {
                    let c = candidate(p);
                    progress.inc(1);
                    c
                })
                .collect::<Result<Vec<_>>>()?;
            progress.finish();
            conditions.extend(found.into_iter().filter(PoolCondition::teaches));
            if conditions.len() >= count {
                break;
            }
        }
        conditions.truncate(count);
        Ok(Self {
            conditions,
            target: loaded,
        })
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

/// The pool condition `[roughness, θo, metallic]` of the BRDF.
fn condition(
    prior: &Arc<BrdfPrior>,
    cond3: [f64; 3],
    caps: usize,
    window: usize,
    shape: &Shape,
    seed: u64,
) -> Result<PoolCondition> {
    let n = shape.n() as usize;
    let cond = [cond3[0], cond3[1]];
    let target = BrdfTarget::coarse(cond[0], cond[1], cond3[2], POOL_RULE_POINTS)
        .expect("pool conditions lie in the condition range");
    let exact = TabulatedWarp::new(&target, POOL_BASELINE_TABULATION, 2)?;
    let baseline = exact.warp_all(&seeded_owen_sobol(n, seed));
    let pc = PoolCondition {
        cond,
        unit: LoadedTarget::GltfBrdf(Arc::clone(prior)).normalized(cond),
        metallic: cond3[2],
        density: ConditionDensity::Brdf {
            wo: view_direction(cond[1]),
            metallic: cond3[2],
            albedo: target.albedo(),
            prior: Arc::clone(prior),
        },
        domain: Domain::Hemisphere,
        caps: Vec::new(),
        measures: Vec::new(),
        warp_targets: warp_targets(&target, shape),
        baseline_loss: 0.0,
        lobe_probability: target.lobe_probability(),
        warp: PointWarp::of(ConditionalTarget::GltfBrdf, shape),
    };
    Ok(pc.measured(
        caps,
        seed,
        |c, t| target.cap_measure(c, t),
        &baseline,
        window,
    ))
}

impl PoolCondition {
    /// The condition with its caps (epoch 0 of `seed`, [`epoch_caps`]), their
    /// target measures by `measure(centre, cos_theta)`, and the loss of the
    /// `baseline` set on the first `window` of them: what every target's condition
    /// computes alike once its density is set.
    fn measured(
        mut self,
        caps: usize,
        seed: u64,
        measure: impl Fn(DVec3, f64) -> f64,
        baseline: &[DVec3],
        window: usize,
    ) -> Self {
        self.caps = epoch_caps(seed, 0, caps);
        self.measures = self
            .caps
            .iter()
            .map(|c| measure(c.center, c.cos_theta))
            .collect();
        self.baseline_loss = self.window_loss(baseline, window);
        self
    }

    /// Cap loss of `pts` on the first window of `window` caps at sharpness 1:
    /// the baseline's score ([`PoolCondition::baseline_loss`]).
    fn window_loss(&self, pts: &[DVec3], window: usize) -> f64 {
        let w = window.min(self.caps.len());
        let local: Vec<f64> = pts.iter().map(|&x| self.local_factor(x)).collect();
        let mut g = vec![DVec3::ZERO; pts.len()];
        cap_loss_and_gradient(
            pts,
            &self.caps[..w],
            CapArea::Precomputed(&self.measures[..w]),
            1.0,
            Some(&local),
            GradientPath::Fast,
            &mut g,
        )
    }
}

/// The pool condition of the normal whose octahedral square point is `u`: caps
/// measured on the mass-adaptive rule of the map lit through the cosine about the
/// normal; the baseline from that density's inverse CDF (what the renderer's map
/// sampler would do for this normal alone); pretraining targets the shifted
/// lattice itself for a network on the tree's primary space (a zero residual),
/// else that inverse CDF applied to the lattice.
fn envmap_condition(
    env: &Arc<EnvmapTarget>,
    u: [f64; 2],
    caps: usize,
    window: usize,
    shape: &Shape,
    seed: u64,
) -> Result<PoolCondition> {
    let n = shape.n() as usize;
    let map = env.coarse_map();
    let normal = square_to_sphere(DVec2::from(u));
    // A normal that no light reaches trains on the cosine lobe (its weight is 0).
    let (lit, irradiance) = map.cosine_weighted(normal)?;
    let residual = shape.lattice_residual();
    let table = CapMeasureTable::new(&lit.mass_rule(POOL_RULE_POINTS));
    let share = irradiance / map.integral();
    let warp_targets = (0..PRETRAIN_INSTANCES)
        .flat_map(|k| {
            let z = shape.instance_offset::<f64>(k);
            let g = shape.lattice_generator();
            let lit = &lit;
            (0..shape.n()).map(move |i| {
                let p = DVec2::from(shifted_lattice_point(i, shape.n(), g, z));
                if residual {
                    p
                } else {
                    sphere_to_square(lit.sample(p))
                }
            })
        })
        .collect();
    let pc = PoolCondition {
        cond: u,
        unit: u,
        metallic: 0.0,
        density: ConditionDensity::Envmap {
            normal,
            env: Arc::clone(env),
            scale: if share > 0.0 { 1.0 / share } else { 0.0 },
        },
        domain: Domain::Sphere,
        caps: Vec::new(),
        measures: Vec::new(),
        warp_targets,
        baseline_loss: 0.0,
        lobe_probability: 0.0,
        warp: PointWarp::of(ConditionalTarget::EnvmapNormal, shape),
    };
    Ok(pc.measured(
        caps,
        seed,
        |c, t| table.measure(c, t),
        &warped_owen_sobol_directions(&lit, n, seed),
        window,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::envmap::test_support::grey_map;
    use nuld_core::network::Activation;

    /// The BRDF prior's direction derivatives are the central differences of
    /// its whole warp (`sample`, five table searches) wherever those stay in one
    /// table cell (a cell boundary is a kink) and alive, at dielectric,
    /// intermediate and metal conditions on and between the nodes.
    #[test]
    fn brdf_direction_derivatives_are_the_warps() {
        use crate::sphere::brdf_prior::PRIOR_SIZE;
        use rand::Rng;
        let prior = BrdfPrior::shared();
        let core = prior.core_f64().unwrap();
        let mut r = crate::seeding::rng(5, 0);
        let (h, mut checked) = (1e-7, 0);
        for _ in 0..3000 {
            let cond = [
                r.random_range(0.1..1.0),
                r.random_range(0.0..85.0),
                [0.0, 0.3, 1.0][r.random_range(0..3)],
            ];
            let u = DVec2::new(r.random_range(0.01..0.99), r.random_range(0.01..0.99));
            let (d, jx, jy) = brdf_table_direction(&prior, cond, u);
            let (want, pdf) = core.sample(cond, u.to_array());
            if pdf <= 0.0 {
                assert_eq!((d, jx, jy), (DVec3::Z, DVec3::ZERO, DVec3::ZERO));
                continue;
            }
            assert!(d.distance(DVec3::from_array(want)) < 1e-12);
            // The table cell of a primary point's square point.
            let cell = |v: DVec2| {
                let q = DVec2::from(core.square_with_slopes(cond, v.to_array()).0);
                (q * f64::from(PRIOR_SIZE - 1)).floor()
            };
            let ends = [
                u + h * DVec2::X,
                u - h * DVec2::X,
                u + h * DVec2::Y,
                u - h * DVec2::Y,
            ];
            let alive = ends.iter().all(|e| core.sample(cond, e.to_array()).1 > 0.0);
            if !alive || ends.iter().any(|&e| cell(e) != cell(u)) {
                continue;
            }
            let at = |v: DVec2| DVec3::from_array(core.sample(cond, v.to_array()).0);
            for (got, want) in [
                (jx, (at(ends[0]) - at(ends[1])) / (2.0 * h)),
                (jy, (at(ends[2]) - at(ends[3])) / (2.0 * h)),
            ] {
                assert!(
                    got.distance(want) <= 1e-4 * want.length().max(1.0),
                    "{cond:?} {u}: {got} vs {want}"
                );
            }
            checked += 1;
        }
        assert!(checked > 2000, "only {checked} points checked");
    }

    /// A BRDF condition's baseline is Owen-Sobol through the exact tabulated
    /// inverse CDF: the same points' loss, recomputed here, and at a sharp grazing
    /// lobe lower than through the renderer's mixture, which `eval conditional`
    /// measures at 1.3 to 2.8 times the exact warp's cap L2 there.
    #[test]
    fn brdf_baselines_are_the_exact_inverse_cdf() {
        let shape = Shape::new(64, &[4], Activation::Relu, 5).unwrap();
        for cond in [[0.13, 85.0], [0.25, 80.0], [0.5, 30.0]] {
            let prior = BrdfPrior::shared();
            let pc = condition(&prior, [cond[0], cond[1], 0.0], 512, 256, &shape, 3).unwrap();
            let target = BrdfTarget::coarse(cond[0], cond[1], 0.0, POOL_RULE_POINTS).unwrap();
            let exact = TabulatedWarp::new(&target, POOL_BASELINE_TABULATION, 2).unwrap();
            let u = seeded_owen_sobol(64, 3);
            let want = pc.window_loss(&exact.warp_all(&u), 256);
            assert_eq!(pc.baseline_loss.to_bits(), want.to_bits(), "{cond:?}");
            if cond[1] > 75.0 {
                let mixture = pc.window_loss(&warped_owen_sobol_directions(&target, 64, 3), 256);
                assert!(
                    pc.baseline_loss < mixture,
                    "{cond:?}: {} vs {mixture}",
                    pc.baseline_loss
                );
            }
        }
    }

    /// A pool of `count` conditions of the map at `path` (8 points, 64 caps a
    /// condition, windows of 32, seed 5).
    fn envmap_pool(path: &std::path::Path, count: usize) -> ConditionPool {
        let shape = Shape::new(8, &[4], Activation::Relu, 3).unwrap();
        let target = TrainTarget::envmap(path).unwrap();
        ConditionPool::new(&target, (BrdfLayer::Shared, &[]), count, 64, 32, &shape, 5).unwrap()
    }

    /// The map of an environment pool.
    fn envmap_target(pool: &ConditionPool) -> &EnvmapTarget {
        match &pool.target {
            LoadedTarget::Envmap(env) => env,
            _ => panic!("an envmap target"),
        }
    }

    /// A map lit by one pixel leaves half the sphere's normals in the dark: the
    /// pool skips them and still holds its count of distinct normals, each lit
    /// (its irradiance, by the map's own sum over pixels, positive).
    #[test]
    fn an_envmap_pool_holds_only_normals_that_light_reaches() {
        let dir = std::env::temp_dir().join(format!("nuld-pool-dark-{}", std::process::id()));
        let path = grey_map(&dir, "one-pixel.png", [32, 16], |x, y| {
            if (x, y) == (5, 3) {
                255
            } else {
                0
            }
        });
        let count = 24;
        let pool = envmap_pool(&path, count);
        let env = envmap_target(&pool);
        let normals: Vec<DVec3> = pool
            .conditions
            .iter()
            .map(|pc| match pc.density {
                ConditionDensity::Envmap { normal, .. } => normal,
                _ => panic!("an envmap condition"),
            })
            .collect();
        assert_eq!(normals.len(), count);
        for (k, n) in normals.iter().enumerate() {
            assert!(env.map.irradiance(*n) > 0.0, "{n}");
            assert!(pool.conditions[k].teaches());
            assert!(
                normals[..k].iter().all(|m| m.distance(*n) > 1e-9),
                "{n} twice"
            );
        }
        // The map does leave normals in the dark: the filter had work to do.
        let dark = (0..64)
            .map(|j| {
                square_to_sphere(DVec2::new(
                    (j % 8) as f64 / 8.0 + 0.06,
                    (j / 8) as f64 / 8.0 + 0.06,
                ))
            })
            .filter(|&n| env.map.irradiance(n) == 0.0)
            .count();
        assert!(dark > 16, "{dark} of 64 normals dark");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An environment pool condition measures its caps on the lit map: its
    /// measures agree with the exact cap measure of the lit map
    /// ([`crate::sphere::EnvmapDensity::cap_measure`], a quadrature independent of the rule); a
    /// cap a little wider than the hemisphere about the normal holds all the mass,
    /// one a little narrower than the opposite hemisphere none (the tiny map's
    /// pixels are 11 degrees tall, and a pixel lit at its centre reaches below the
    /// horizon); the lit map integrates to the irradiance; and the density
    /// integrates to 1 (midpoint rule on the sphere's equal-area square).
    #[test]
    fn envmap_conditions_hold_the_lit_map() {
        let dir = std::env::temp_dir().join(format!("nuld-pool-envmap-{}", std::process::id()));
        let map = crate::sphere::envmap::tiny_map(&dir);
        let pool = envmap_pool(&map, 3);
        let density = &envmap_target(&pool).map;
        for pc in &pool.conditions {
            let ConditionDensity::Envmap { normal, .. } = pc.density else {
                panic!("an envmap condition")
            };
            assert_eq!(pc.domain, Domain::Sphere);
            let (lit, irradiance) = density.cosine_weighted(normal).unwrap();
            assert!((irradiance / density.irradiance(normal) - 1.0).abs() < 1e-12);
            let worst = pc
                .caps
                .iter()
                .zip(&pc.measures)
                .map(|(c, m)| (m - lit.cap_measure(c.center, c.cos_theta)).abs())
                .fold(0.0, f64::max);
            assert!(worst < 5e-3, "{worst}");
            let table = CapMeasureTable::new(&lit.mass_rule(POOL_RULE_POINTS));
            assert!((table.measure(normal, -0.2) - 1.0).abs() < 1e-9);
            assert!(table.measure(-normal, 0.2) < 1e-9);
            assert!(table.measure(normal, 0.0) > 0.95);
            let k = 256;
            let integral: f64 = (0..k * k)
                .map(|j| {
                    let p = DVec2::new(
                        ((j % k) as f64 + 0.5) / k as f64,
                        ((j / k) as f64 + 0.5) / k as f64,
                    );
                    pc.pdf(square_to_sphere(p))
                })
                .sum::<f64>()
                * Domain::Sphere.area()
                / (k * k) as f64;
            assert!((integral - 1.0).abs() < 0.02, "{integral}");
            assert!(pc.baseline_loss > 0.0 && pc.baseline_loss.is_finite());
            assert_eq!(pc.warp_targets.len(), (PRETRAIN_INSTANCES * 8) as usize);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
