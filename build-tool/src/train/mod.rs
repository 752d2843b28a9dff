//! Training the conditional sampler's network (paper §4) on the direction
//! optimizer's cap loss.
//!
//! A step draws `B` conditions from the [`ConditionPool`] (half uniformly, half by
//! tournament toward the conditions whose running loss is worst relative to
//! Owen-Sobol points through the target's exact inverse CDF,
//! [`PoolCondition::baseline_loss`]) and `S` instances of each (distinct slots of
//! a network with [instance slots](Shape::with_instance_slots), else random u32s),
//! evaluates the network for every index of every set, and minimizes
//!
//! ```text
//! L = (1 / (B S)) sum_{b,s} loss(X_bs) + lambda (1 / B) sum_b loss(X_b1 u ... u X_bS)
//! ```
//!
//! with `loss` the spherical-cap estimator of [`crate::discrepancy::caps`] (exact
//! counts, sigmoid surrogate gradients, per-point sharpness in local units) on a
//! window of the condition's caps. The union term asks the `S` instances of a
//! condition to be different sets that together follow the target, as
//! independently scrambled sets do; without it a network learns to ignore the
//! instance. Gradients flow back through the hemisphere map, the sigmoid and the
//! network ([`crate::network::backward()`]); Adam with cosine decay; the sigmoid
//! sharpness ramps linearly in units of each loss's point spacing.
//!
//! Deterministic: every random draw of step `t` comes from `(seed, t)`, conditions
//! are processed in parallel but summed in batch order, so a seed fixes the result
//! bit for bit at any thread count, and a run resumed from a [`Checkpoint`]
//! continues exactly as the uninterrupted run.

pub mod checkpoint;
pub mod pool;
mod step;
pub mod target;

pub use checkpoint::Checkpoint;
pub use pool::{ConditionPool, PoolCondition};
pub use target::TrainTarget;

use step::{BatchLoss, StepScratch};

use crate::descent::{Adam, Descent, Schedule};
use crate::network::Params;
use nuld_core::network::{Activation, Shape};
use serde::{Deserialize, Serialize};

/// Settings of a training run. Defaults chosen by measurement (README.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfig {
    /// What the sampler samples (the glTF BRDF unless given).
    #[serde(default)]
    pub target: TrainTarget,
    /// Points per set `N`.
    pub n: u32,
    /// Hidden widths.
    pub hidden: Vec<u32>,
    /// `true` for SiLU hidden units, `false` for ReLU.
    pub silu: bool,
    /// `true`: the network emits a residual on the logit of the shifted lattice
    /// point in the primary sample space of the target's prior, the renderer's
    /// mixture warp for the BRDF
    /// ([`nuld_core::conditional::PointWarp::BrdfMixture`]), the map's tree for
    /// an environment ([`nuld_core::conditional::PointWarp::EnvmapTree`]);
    /// `false`: a point of the equal-area square.
    #[serde(alias = "mixture_prior")]
    pub prior: bool,
    /// Gradient steps on the cap loss.
    pub steps: usize,
    /// Steps before those that fit the network to the renderer's warp of its
    /// shifted-lattice input (squared distance in the square), a starting
    /// point near the baseline instead of a random map.
    pub pretrain_steps: usize,
    /// Conditions per step `B`.
    pub conditions_per_step: usize,
    /// Instances per condition and step `S`.
    pub instances_per_condition: usize,
    /// Weight `lambda` of the union term.
    pub union_weight: f64,
    /// Conditions in the pool (the BRDF sampler's default 1024: on the
    /// 16-condition judge at N = 64, 0.821 and 0.817 of the baseline at seeds 0
    /// and 1 against 0.823 and 0.823 with 256; docs/results/brdf-sampler.md).
    pub pool_conditions: usize,
    /// Caps measured per pool condition.
    pub pool_caps: usize,
    /// Caps per condition and step `M` (a window of the pool's caps).
    pub caps_per_step: usize,
    /// Adam step at the start.
    pub learning_rate: f64,
    /// Step at the end relative to the start (cosine decay).
    pub final_learning_rate_ratio: f64,
    /// Sigmoid sharpness at the start, in inverse point spacings.
    pub alpha_start: f64,
    /// Sigmoid sharpness at the end, in inverse point spacings. The BRDF
    /// sampler's default 32: on the 16-condition judge 0.805, 0.806 and 0.845 of
    /// the baseline at N = 16, 64 and 256 against 0.809, 0.810 and 0.854 at 64,
    /// and lower render error at 64 and 256 spp on both shared maps
    /// (docs/results/brdf-sampler.md#sharpness-32); an environment sampler's is
    /// [`crate::conditional::bake::ENVMAP_ALPHA_END`].
    pub alpha_end: f64,
    /// Instance slots `M` of the network ([`Shape::with_instance_slots`]; 0: an
    /// offset per instance and no per-instance embedding).
    #[serde(default)]
    pub instance_slots: u32,
    /// Which metallic values a BRDF sampler's network serves, and so which of
    /// the prior's squares it refines (ignored for an environment map).
    #[serde(default)]
    pub layer: BrdfLayer,
    /// The metallic nodes of a BRDF sampler's shared network
    /// ([`nuld_core::conditional::metallic_axis`]): with 2 or more, the network
    /// reads the metallic as an input, the pool's metallic is one of the nodes
    /// ([`BrdfLayer::pool_metallic`]), and the blob's point table holds a layer
    /// per node; empty (what older configurations read as), none of this.
    /// Ignored by the metal layer and an environment map.
    #[serde(default)]
    pub metallic_nodes: Vec<f64>,
    /// Fixes the initialization, the pool and every draw.
    pub seed: u64,
}

impl Default for TrainConfig {
    /// The BRDF sampler at N = 64, its steps and union weight [`brdf_recipe`]'s.
    fn default() -> Self {
        let (steps, union_weight) = brdf_recipe(64);
        Self {
            target: TrainTarget::GltfBrdf,
            n: 64,
            hidden: vec![32, 32],
            silu: false,
            prior: true,
            steps,
            pretrain_steps: 300,
            conditions_per_step: 8,
            instances_per_condition: 8,
            union_weight,
            pool_conditions: 1024,
            pool_caps: 2048,
            caps_per_step: 256,
            learning_rate: 6e-3,
            final_learning_rate_ratio: 0.03,
            alpha_start: 8.0,
            alpha_end: 32.0,
            instance_slots: 64,
            layer: BrdfLayer::Shared,
            metallic_nodes: METALLIC_NODES.to_vec(),
            seed: 0,
        }
    }
}

/// Which of the BRDF prior's squares a network's points serve
/// ([`nuld_core::brdf_prior`]): a query below metallic 1 warps through the
/// shared square (the blend of the metallic 0 and 1 layers), one at metallic 1
/// through the metal layer's own square, whose primary space is another, so
/// each gets a network of its own (`bake --brdf` trains both). Measured with
/// `eval conditional` at N = 64 (docs/results/brdf-sampler.md): a network
/// trained on metals alone scored 0.805 of the exact warp's Owen-Sobol at
/// metallic 1 (worst 1.071), the one network for both 0.881 (worst 1.480).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum BrdfLayer {
    /// Metallic below 1: the pool's metallic is one of the metallic nodes
    /// ([`TrainConfig::metallic_nodes`]), a share `1 / L` of the pool each;
    /// without nodes `clamp(1.25 v - 0.25, 0, 1)` for `v` uniform in `[0, 1)`,
    /// a fifth of the pool the pure dielectric (what renderers see most), the
    /// rest uniform below 1.
    #[default]
    Shared,
    /// Metallic 1 (a glTF metal), through the prior's metal layer.
    Metal,
}

impl BrdfLayer {
    /// A pool condition's metallic from a uniform `v` in `[0, 1)` (see the
    /// variants); with metallic `nodes` (2 or more) the shared layer's is node
    /// `floor(v L)`, each node a share `1 / L` of the pool.
    pub fn pool_metallic(self, nodes: &[f64], v: f64) -> f64 {
        match self {
            Self::Shared if nodes.len() >= 2 => {
                let j = ((v * nodes.len() as f64) as usize).min(nodes.len() - 1);
                nodes[j]
            }
            Self::Shared => (1.25 * v - 0.25).clamp(0.0, 1.0),
            Self::Metal => 1.0,
        }
    }
}

/// The default metallic nodes of a BRDF sampler's shared network
/// ([`TrainConfig::metallic_nodes`]). The network that reads the metallic
/// and trains on these three values scored 0.809 of the exact warp's
/// Owen-Sobol on the 16-condition judge at N = 64 in network mode (32 sets;
/// worst 0.867), against 0.817 (worst 0.923) for the network that does not
/// read it; one that reads it but trains on a continuum of metallics scored
/// 0.819 (docs/results/brdf-sampler.md).
pub const METALLIC_NODES: [f64; 3] = [0.0, 0.5, 0.95];

/// Training steps of each of a BRDF sampler's networks at 64 to 127 points per
/// set ([`brdf_recipe`]).
pub const BRDF_STEPS_AT_64: usize = 20_000;

/// Training steps of each of a BRDF sampler's networks at other sizes
/// ([`brdf_recipe`]).
pub const BRDF_STEPS: usize = 12_000;

/// Weight of the union term of a BRDF sampler below 64 points per set
/// ([`brdf_recipe`]).
pub const BRDF_UNION_WEIGHT_BELOW_64: f64 = 0.5;

/// A BRDF sampler's training steps and union weight at `n` points per set,
/// chosen by measurement (docs/results/brdf-sampler.md#per-n-recipe):
///
/// * below 64 points, [`BRDF_STEPS`] steps and the union term at
///   [`BRDF_UNION_WEIGHT_BELOW_64`]: without it the union of N = 16's instances
///   reads 0.339 of one set (the goal: at most 0.3) and studio's 16 spp loses by
///   38 % instead of 18 %;
/// * from 64 points on no union term: the union stays within the goal without it
///   (0.25 at N = 64, 0.27 at 256), and the sets, the renders and the bake gain
///   (N = 256: 1481 s instead of 1673 of its 30 minutes);
/// * at 64 to 127 points [`BRDF_STEPS_AT_64`] steps, which the bake's time
///   without the union term and with the training's flat caps affords (367 s
///   here, what 16 000 steps took before them; the judge 0.798 against
///   0.800); from 128 on [`BRDF_STEPS`] (N = 256's 30 minutes).
pub fn brdf_recipe(n: u32) -> (usize, f64) {
    match n {
        0..=63 => (BRDF_STEPS, BRDF_UNION_WEIGHT_BELOW_64),
        64..=127 => (BRDF_STEPS_AT_64, 0.0),
        _ => (BRDF_STEPS, 0.0),
    }
}

/// Training steps of an environment sampler below [`ENVMAP_UNTRAINED_FROM`]
/// points per set: on the tree's primary space 3000 steps scored as 12 000 did
/// (courtyard N = 64: 0.755 and 0.759 of the baseline), in a quarter of the
/// time.
pub const ENVMAP_STEPS: usize = 3000;

/// Points per set from which an environment sampler trains nothing by default
/// ([`envmap_steps`]).
pub const ENVMAP_UNTRAINED_FROM: u32 = 256;

/// An environment sampler's training steps at `n` points per set, chosen by
/// measurement (docs/results/envmap.md#untrained): [`ENVMAP_STEPS`] below
/// [`ENVMAP_UNTRAINED_FROM`], else 0. At N = 256 the trained sets checked
/// worse than the prior's shifted lattice on both shared maps (courtyard 0.767
/// against 0.707, studio 0.941 against 0.858; nor did a smaller step or a pool
/// four times as large make them better), so the bake shipped the lattice
/// after minutes of training: with no steps it ships the same sets without
/// them.
pub fn envmap_steps(n: u32) -> usize {
    if n >= ENVMAP_UNTRAINED_FROM {
        0
    } else {
        ENVMAP_STEPS
    }
}

impl TrainConfig {
    /// These settings at `n` points per set; a sampler on its recipe (a BRDF
    /// sampler's steps and union weight those of [`brdf_recipe`] at its own `n`,
    /// an environment sampler's steps those of [`envmap_steps`]) moves to the
    /// recipe's at `n`, any other keeps its own (a caller's explicit ones).
    pub fn with_points(self, n: u32) -> Self {
        let brdf = self.target == TrainTarget::GltfBrdf;
        let on_recipe = match brdf {
            true => (self.steps, self.union_weight) == brdf_recipe(self.n),
            false => self.steps == envmap_steps(self.n),
        };
        let (steps, union_weight) = match (on_recipe, brdf) {
            (true, true) => brdf_recipe(n),
            (true, false) => (envmap_steps(n), self.union_weight),
            (false, _) => (self.steps, self.union_weight),
        };
        Self {
            n,
            steps,
            union_weight,
            ..self
        }
    }

    /// Whether the network reads the metallic ([`Self::metallic_nodes`]): the
    /// shared layer of a BRDF sampler with 2 or more nodes.
    pub fn reads_metallic(&self) -> bool {
        self.target == TrainTarget::GltfBrdf
            && self.layer == BrdfLayer::Shared
            && self.metallic_nodes.len() >= 2
    }

    /// The metallic nodes the blob's point table is laid out on, rounded to
    /// `f32` as the blob stores them: [`Self::metallic_nodes`] where the network
    /// reads the metallic ([`Self::reads_metallic`]), else none.
    pub fn table_metallic_nodes(&self) -> Vec<f32> {
        match self.reads_metallic() {
            true => self.metallic_nodes.iter().map(|&m| m as f32).collect(),
            false => Vec::new(),
        }
    }

    /// The network architecture, or `None` if a count is out of range.
    pub fn shape(&self) -> Option<Shape> {
        let act = if self.silu {
            Activation::Silu
        } else {
            Activation::Relu
        };
        Shape::new(self.n, &self.hidden, act, lattice_generator(self.n))
            .map(|s| s.with_lattice_residual(self.prior))
            .map(|s| s.with_metallic_input(self.reads_metallic()))
            .and_then(|s| s.with_instance_slots(self.instance_slots))
    }
}

/// The rank-1 lattice generator `g` for `n` points: the `g` in `1..n` coprime to
/// `n` whose lattice `(i/n, frac(i g / n))` has the largest Zaremba index
/// ([`zaremba_index`]), ties to the largest minimum distance on the torus
/// ([`shortest_lattice_vector`]), then to the smallest `g`. `O(n^2)`.
///
/// Why the Zaremba index and not the distance alone: both priors' warps (the
/// environment map's tree, the BRDF's marginal-conditional table) stretch the
/// primary square along its axes, by other factors in every piece, and the
/// index bounds how close two points come under any such stretch: scaled by
/// `n`, the dual lattice is the lattice itself turned a quarter turn (`b ≡ g a`
/// iff `(-b) + g a ≡ 0`), so any two points differ by `(dx, dy)` with
/// `max(1/n, |dx|) max(1/n, |dy|) >= ρ / n²` (on the torus), whatever the
/// stretch of each axis. Where the two criteria disagree
/// (`n` = 16, 128, 256, 512), the index's lattice through the environment prior
/// scores 6–8 % lower cap L2 on held-out normals (`docs/results/envmap.md#generator`).
pub fn lattice_generator(n: u32) -> u32 {
    let mut best = (1u32, 0u64, -1.0);
    for g in 1..n.max(2) {
        if gcd(g as u64, n as u64) != 1 {
            continue;
        }
        let index = zaremba_index(n as u64, g as u64);
        let shortest = shortest_lattice_vector(n as u64, g as u64);
        if (index, shortest) > (best.1, best.2) {
            best = (g, index, shortest);
        }
    }
    best.0
}

/// The Zaremba index of the rank-1 lattice `(i/n, frac(i g / n))`: the least
/// `max(1, |h1|) max(1, |h2|)` over the nonzero integer vectors `(h1, h2)` of its
/// dual lattice, `h1 + g h2 ≡ 0 (mod n)`; `n` for `n` below 2 (no dual vector
/// but multiples of `n`). `O(n)`: for each `h2` in `0..=n/2` only the `h1` of
/// least magnitude counts.
pub fn zaremba_index(n: u64, g: u64) -> u64 {
    let n = n.max(1);
    // h2 = 0: h1 a nonzero multiple of n.
    let mut best = n;
    for h2 in 1..=n / 2 {
        let r = (n - (g as u128 * h2 as u128 % n as u128) as u64) % n;
        let h1 = r.min(n - r);
        best = best.min(h2 * h1.max(1));
    }
    best
}

/// The squared length of the shortest nonzero vector on the torus of the rank-1
/// lattice `(i/n, frac(i g / n))`, `i < n`: its points' minimum squared distance.
/// `O(n)`.
pub fn shortest_lattice_vector(n: u64, g: u64) -> f64 {
    let wrap = |x: f64| x.min(1.0 - x);
    (1..n)
        .map(|i| {
            let x = wrap(i as f64 / n as f64);
            let y = wrap((i as u128 * g as u128 % n as u128) as f64 / n as f64);
            x * x + y * y
        })
        .fold(f64::INFINITY, f64::min)
}

/// The greatest common divisor of `a` and `b` (Euclid).
pub fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// What one step reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Index of the step just taken.
    pub step: usize,
    /// The loss `L` of the batch.
    pub loss: f64,
    /// Mean cap loss of single sets, relative to the conditions' baselines.
    pub set_ratio: f64,
    /// Sigmoid sharpness in inverse point spacings.
    pub alpha: f64,
    /// Adam step.
    pub learning_rate: f64,
}

/// A trainer: configuration, pool and the state that checkpoints hold.
pub struct Trainer {
    /// The settings.
    pub config: TrainConfig,
    /// The conditions.
    pub pool: ConditionPool,
    /// Parameters, Adam state, step, running losses.
    pub state: Checkpoint,
    /// The network's architecture (`config.shape()`, whose lattice-generator
    /// search is built once here).
    shape: Shape,
    /// Buffers that every step reuses ([`StepScratch`]).
    scratch: StepScratch,
}

/// How many random pool members a tournament compares.
const TOURNAMENT: usize = 4;

impl Trainer {
    /// A fresh trainer (parameters from the seed) or one resuming `resume`; an
    /// error if the target's data cannot be read ([`ConditionPool::new`]) or
    /// `resume` was written for another configuration.
    ///
    /// # Panics
    /// If the configuration's shape is invalid.
    pub fn new(config: TrainConfig, resume: Option<Checkpoint>) -> anyhow::Result<Self> {
        let shape = config.shape().expect("valid network shape");
        let pool = ConditionPool::new(
            &config.target,
            (config.layer, &config.metallic_nodes),
            config.pool_conditions,
            config.pool_caps,
            config.caps_per_step,
            &shape,
            config.seed,
        )?;
        let state = match resume {
            Some(c) => {
                anyhow::ensure!(
                    c.config == config,
                    "the checkpoint was written with other training settings"
                );
                c
            }
            None => {
                let params = Params::init(shape, config.seed);
                Checkpoint::fresh(config.clone(), params.values, pool.len())
            }
        };
        let scratch = StepScratch::new(&config, shape);
        Ok(Self {
            config,
            pool,
            state,
            shape,
            scratch,
        })
    }

    /// The current parameters.
    pub fn params(&self) -> Params {
        Params {
            shape: self.shape,
            values: self.state.params.clone(),
        }
    }

    /// Whether every step has been taken.
    pub fn done(&self) -> bool {
        self.state.step >= self.total_steps()
    }

    /// Pretraining and cap-loss steps together.
    pub fn total_steps(&self) -> usize {
        self.config.pretrain_steps + self.config.steps
    }

    /// Takes one step: a batch of pool conditions (half of them by a tournament
    /// toward the worst relative to their baselines) and one [`Descent::epoch`]
    /// on its loss.
    pub fn step(&mut self) -> StepReport {
        let cfg = &self.config;
        let t = self.state.step;
        let schedule = Schedule {
            epochs: cfg.steps,
            alpha: (cfg.alpha_start, cfg.alpha_end),
            final_learning_rate_ratio: cfg.final_learning_rate_ratio,
        };
        let adam = Adam::<f64>::from_state(
            std::mem::take(&mut self.state.adam_m),
            std::mem::take(&mut self.state.adam_v),
            self.state.adam_t,
        );
        // The sharpness is in inverse point spacings already (the loss divides by
        // the spacing of its sets and their union): spacing 1.
        let mut descent = Descent::new(adam, schedule, cfg.learning_rate, 1.0);
        let mut batch = BatchLoss {
            cfg,
            pool: &self.pool,
            running: &mut self.state.running,
            scratch: &mut self.scratch,
            step: t,
            set_ratio: 0.0,
        };
        let report = descent.epoch(
            t.saturating_sub(cfg.pretrain_steps),
            &mut self.state.params,
            &mut batch,
        );
        let set_ratio = batch.set_ratio;
        (self.state.adam_m, self.state.adam_v, self.state.adam_t) = descent.adam.into_state();
        self.state.losses.push(report.loss);
        self.state.step += 1;
        StepReport {
            step: t,
            loss: report.loss,
            set_ratio,
            alpha: report.alpha,
            learning_rate: report.learning_rate,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::step::draw_instances;
    use super::*;
    use crate::seeding::rng;

    /// The recipes at the three sizes a renderer bakes, and who follows them: a
    /// configuration on its recipe moves with `n`, an explicit one keeps its
    /// steps and union weight; an environment sampler trains below 256 points
    /// and not from there on, whatever its union weight.
    #[test]
    fn the_recipes_follow_the_points_per_set() {
        let d = TrainConfig::default();
        assert_eq!((d.n, d.steps, d.union_weight), (64, 20_000, 0.0));
        let at = |c: &TrainConfig, n| {
            let c = c.clone().with_points(n);
            (c.n, c.steps, c.union_weight)
        };
        assert_eq!(at(&d, 16), (16, 12_000, 0.5));
        assert_eq!(at(&d, 256), (256, 12_000, 0.0));
        assert_eq!(at(&d.clone().with_points(16), 64), (64, 20_000, 0.0));
        let explicit = TrainConfig {
            steps: 4,
            ..d.clone()
        };
        assert_eq!(at(&explicit, 16), (16, 4, 0.0));
        let env = TrainConfig {
            target: TrainTarget::Envmap {
                path: "map.hdr".into(),
                content_hash: 1,
            },
            union_weight: 1.5,
            steps: 3000,
            ..d
        };
        assert_eq!(at(&env, 16), (16, 3000, 1.5));
        assert_eq!(at(&env, 255), (255, 3000, 1.5));
        assert_eq!(at(&env, 256), (256, 0, 1.5));
        assert_eq!(at(&env, 1024), (1024, 0, 1.5));
        assert_eq!(at(&env.clone().with_points(256), 64), (64, 3000, 1.5));
        let explicit_env = TrainConfig {
            steps: 500,
            ..env.clone()
        };
        assert_eq!(at(&explicit_env, 256), (256, 500, 1.5));
        let untrained_env = TrainConfig { steps: 0, ..env };
        assert_eq!(at(&untrained_env, 16), (16, 0, 1.5));
    }

    fn tiny() -> TrainConfig {
        TrainConfig {
            n: 8,
            hidden: vec![6, 5],
            steps: 6,
            pretrain_steps: 2,
            conditions_per_step: 4,
            instances_per_condition: 3,
            pool_conditions: 5,
            pool_caps: 64,
            caps_per_step: 32,
            seed: 7,
            ..TrainConfig::default()
        }
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn train_with_threads(threads: usize, config: &TrainConfig) -> Checkpoint {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut t = Trainer::new(config.clone(), None).unwrap();
            while !t.done() {
                t.step();
            }
            t.state
        })
    }

    #[test]
    fn a_seed_fixes_the_run_bit_for_bit_at_any_thread_count() {
        let cfg = tiny();
        let a = train_with_threads(1, &cfg);
        let b = train_with_threads(3, &cfg);
        assert_eq!(bits(&a.params), bits(&b.params));
        assert_eq!(bits(&a.losses), bits(&b.losses));
        assert_eq!(a.losses.len(), 8);
        // Training moved the parameters, and another seed trains differently.
        let init = Params::init(cfg.shape().unwrap(), cfg.seed);
        assert_ne!(bits(&a.params), bits(&init.values));
        let c = train_with_threads(2, &TrainConfig { seed: 8, ..cfg });
        assert_ne!(bits(&a.params), bits(&c.params));
    }

    #[test]
    fn a_resumed_run_continues_bit_identically() {
        let cfg = tiny();
        let mut straight = Trainer::new(cfg.clone(), None).unwrap();
        while !straight.done() {
            straight.step();
        }
        let mut first = Trainer::new(cfg.clone(), None).unwrap();
        for _ in 0..4 {
            first.step();
        }
        let dir = std::env::temp_dir().join(format!("nuld-train-resume-{}", std::process::id()));
        crate::output::ensure_dir(&dir).unwrap();
        let path = dir.join("checkpoint.bin");
        first.state.save(&path).unwrap();
        drop(first);
        let saved = Checkpoint::load(&path).unwrap();
        // A checkpoint resumes only the configuration that wrote it.
        let other = TrainConfig {
            seed: cfg.seed + 1,
            ..cfg.clone()
        };
        let refused = Trainer::new(other, Some(saved.clone())).err().unwrap();
        assert!(
            refused.to_string().contains("other training settings"),
            "{refused}"
        );
        let mut resumed = Trainer::new(cfg, Some(saved)).unwrap();
        assert_eq!(resumed.state.step, 4);
        while !resumed.done() {
            resumed.step();
        }
        assert_eq!(resumed.state, straight.state);
        assert_eq!(bits(&resumed.state.params), bits(&straight.state.params));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn pretraining_fits_the_warp_and_the_cap_loss_falls() {
        let cfg = TrainConfig {
            n: 16,
            hidden: vec![16, 16],
            steps: 60,
            pretrain_steps: 60,
            conditions_per_step: 4,
            instances_per_condition: 4,
            pool_conditions: 8,
            pool_caps: 256,
            caps_per_step: 128,
            learning_rate: 1e-2,
            // The equal-area output, whose start is far from the warp; with the
            // mixture prior the start is the warp already.
            prior: false,
            ..TrainConfig::default()
        };
        let mut t = Trainer::new(cfg, None).unwrap();
        let mut losses = Vec::new();
        while !t.done() {
            losses.push(t.step().loss);
        }
        let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len() as f64;
        // Squared square distance to the warp's points.
        assert!(
            mean(&losses[50..60]) < 0.5 * mean(&losses[..10]),
            "{losses:?}"
        );
        // Cap loss.
        assert!(mean(&losses[110..]) < mean(&losses[60..70]), "{losses:?}");
    }

    #[test]
    fn the_shared_network_reads_the_metallic_and_trains_on_the_nodes() {
        let nodes = [0.0, 0.5, 0.95];
        let config = TrainConfig::default();
        assert_eq!(config.metallic_nodes, nodes);
        assert!(config.reads_metallic() && config.shape().unwrap().metallic_input());
        assert_eq!(config.table_metallic_nodes(), [0.0f32, 0.5, 0.95]);
        // The metal layer, an axis of one node, an environment map: no axis.
        let metal = TrainConfig {
            layer: BrdfLayer::Metal,
            ..config.clone()
        };
        let one = TrainConfig {
            metallic_nodes: vec![0.5],
            ..config.clone()
        };
        let map = TrainConfig {
            target: TrainTarget::envmap_with_bytes(std::path::Path::new("x.hdr"), b"map"),
            ..config.clone()
        };
        for c in [&metal, &one, &map] {
            assert!(!c.reads_metallic() && !c.shape().unwrap().metallic_input());
            assert!(c.table_metallic_nodes().is_empty());
        }
        // A third of the unit interval per node, in order; the metal layer 1.
        let draw = |v: f64| BrdfLayer::Shared.pool_metallic(&nodes, v);
        let counts = (0..3000).fold([0; 3], |mut c, j| {
            let m = draw((j as f64 + 0.5) / 3000.0);
            c[nodes.iter().position(|&x| x == m).unwrap()] += 1;
            c
        });
        assert_eq!(counts, [1000; 3]);
        assert_eq!(draw(0.0), 0.0);
        assert_eq!(draw(0.999_999), 0.95);
        assert_eq!(BrdfLayer::Metal.pool_metallic(&nodes, 0.2), 1.0);
        // Without nodes: a fifth pure dielectric, the rest uniform below 1.
        assert_eq!(BrdfLayer::Shared.pool_metallic(&[], 0.1), 0.0);
        assert!((BrdfLayer::Shared.pool_metallic(&[], 0.6) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_batch_draws_distinct_slots_when_there_are_enough() {
        let mut r = rng(3, 1);
        for _ in 0..200 {
            let mut k = draw_instances(&mut r, 8, 10);
            k.sort_unstable();
            k.dedup();
            assert_eq!(k.len(), 8, "{k:?}");
            assert!(k.iter().all(|&s| s < 10));
        }
        // Fewer slots than instances (or none): any u32.
        let k = draw_instances(&mut r, 8, 0);
        assert!(k.iter().any(|&s| s >= 1 << 16), "{k:?}");
    }

    #[test]
    fn lattice_generator_maximizes_the_zaremba_index_then_the_shortest_vector() {
        // Fibonacci lattices are the best rank-1 lattices of Fibonacci sizes by
        // both criteria.
        assert_eq!(lattice_generator(8), 3);
        let g = lattice_generator(89);
        assert!(g == 34 || g == 55, "{g}");
        assert_eq!(lattice_generator(1), 1);
        // n = 64: 19 and 27 tie on both (index 19, distance sqrt(29)/64);
        // the smaller wins.
        assert_eq!(lattice_generator(64), 19);
        // n = 16: g = 3 has the longest shortest vector, (1, 3)/16, but the
        // dual vector (-3, 1) gives it index 3; g = 7's least is (2, 2): 4.
        assert_eq!((zaremba_index(16, 3), zaremba_index(16, 7)), (3, 4));
        assert_eq!(lattice_generator(16), 7);
        // n = 256: 75 (and its transpose 99, 75 * 99 = 1 mod 256) has index 75
        // (the dual vector (-75, 1)); the longest shortest vector's 71 has 36,
        // from (2, 18): 2 + 71 * 18 = 1280 = 5 * 256.
        assert_eq!((zaremba_index(256, 75), zaremba_index(256, 71)), (75, 36));
        assert_eq!(lattice_generator(256), 75);
        // The index against a brute force over the dual lattice's vectors in
        // [-n, n]^2, for every generator of small sizes.
        for n in 2..40u64 {
            for g in (1..n).filter(|&g| gcd(g, n) == 1) {
                let mut brute = u64::MAX;
                for h1 in -(n as i64)..=n as i64 {
                    for h2 in -(n as i64)..=n as i64 {
                        if (h1, h2) != (0, 0) && (h1 + g as i64 * h2).rem_euclid(n as i64) == 0 {
                            let r = h1.unsigned_abs().max(1) * h2.unsigned_abs().max(1);
                            brute = brute.min(r);
                        }
                    }
                }
                assert_eq!(zaremba_index(n, g), brute, "n {n} g {g}");
            }
        }
        // n = 8, g = 3: point 2 is (2/8, 6/8), (1/4, 1/4) from the origin on
        // the torus, the shortest of the seven; by hand.
        assert_eq!(shortest_lattice_vector(8, 3), 0.125);
        // n = 4, g = 1: the diagonal's first point, (1/4)^2 + (1/4)^2.
        assert_eq!(shortest_lattice_vector(4, 1), 0.125);
        assert!((shortest_lattice_vector(5, 2) - 0.2).abs() < 1e-15);
        assert_eq!(
            (gcd(12, 18), gcd(7, 0), gcd(0, 7), gcd(9, 28)),
            (6, 7, 7, 1)
        );
    }
}
