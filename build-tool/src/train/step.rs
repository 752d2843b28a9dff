//! One training step ([`super::Trainer::step`]): the batch of pool conditions
//! and instances drawn from the step's seed ([`BatchLoss`]), each condition's
//! sets through the network and the prior, their cap loss and its gradient
//! ([`condition_step`], or the warp-fitting loss while pretraining,
//! [`pretrain_step`]), summed in batch order, and the buffers every step
//! reuses ([`StepScratch`]).

use super::{pool, ConditionPool, PoolCondition, TrainConfig, TOURNAMENT};
use crate::descent::{EpochLoss, PARAMETER_CHUNK};
use crate::discrepancy::caps::{cap_loss_and_gradient, Cap, CapArea};
use crate::discrepancy::GradientPath;
use crate::network::{backward, output_gradient, Interleaved};
use crate::seeding::rng;
use glam::{DVec2, DVec3};
use nuld_core::network::{InterleavedParams, Network, Shape, Trace, OUTPUTS};
use rand::Rng;
use rayon::prelude::*;

/// The loss of step `step`: its batch of conditions drawn from the step's seed,
/// the warp-fitting loss while pretraining, then the cap loss of the sets and
/// their union; updates the pool's running losses that the tournament reads.
pub(super) struct BatchLoss<'a> {
    pub(super) cfg: &'a TrainConfig,
    pub(super) pool: &'a ConditionPool,
    pub(super) running: &'a mut Vec<f64>,
    pub(super) scratch: &'a mut StepScratch,
    pub(super) step: usize,
    /// Mean set loss over the conditions' baselines, once computed.
    pub(super) set_ratio: f64,
}

impl EpochLoss<f64> for BatchLoss<'_> {
    fn loss_and_gradient(
        &mut self,
        _epoch: usize,
        alpha: f64,
        values: &[f64],
        grad: &mut [f64],
    ) -> f64 {
        let cfg = self.cfg;
        let t = self.step;
        let pretraining = t < cfg.pretrain_steps;
        let mut r = rng(cfg.seed, 1 + t as u64);
        let p = self.pool.len();
        let running = &*self.running;
        let score = |j: usize| running[j] / self.pool.conditions[j].baseline_loss;
        let mut batch = Vec::with_capacity(cfg.conditions_per_step);
        for b in 0..cfg.conditions_per_step {
            let mut pick = r.random_range(0..p);
            if b >= cfg.conditions_per_step / 2 {
                for _ in 1..TOURNAMENT {
                    let other = r.random_range(0..p);
                    if score(other) > score(pick) {
                        pick = other;
                    }
                }
            }
            let instances = draw_instances(&mut r, cfg.instances_per_condition, cfg.instance_slots);
            let start = r.random_range(0..cfg.pool_caps);
            batch.push((pick, instances, start));
        }
        let StepScratch { forward, slots } = &mut *self.scratch;
        forward.refresh(values);
        let net = &StepNetwork {
            values,
            forward: forward.network(),
        };
        let results: Vec<(f64, f64)> = batch
            .par_iter()
            .zip(slots.par_iter_mut())
            .map(|((pick, instances, start), slot)| {
                let pc = &self.pool.conditions[*pick];
                slot.grad.fill(0.0);
                if pretraining {
                    return pretrain_step(cfg, net, pc, instances, &mut slot.grad);
                }
                condition_step(cfg, net, pc, instances, *start, alpha, slot)
            })
            .collect();
        // Each parameter sums its conditions' gradients in batch order, whichever
        // thread takes its chunk: the same bits.
        grad.par_chunks_mut(PARAMETER_CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                let start = c * PARAMETER_CHUNK;
                for slot in slots.iter() {
                    for (a, b) in chunk.iter_mut().zip(&slot.grad[start..]) {
                        *a += b;
                    }
                }
            });
        let (mut loss, mut ratio) = (0.0, 0.0);
        let inv_b = 1.0 / batch.len() as f64;
        for ((pick, _, _), (set_loss, union_loss)) in batch.iter().zip(&results) {
            loss += (set_loss + cfg.union_weight * union_loss) * inv_b;
            ratio += set_loss / self.pool.conditions[*pick].baseline_loss * inv_b;
            if pretraining {
                continue;
            }
            let run = &mut self.running[*pick];
            *run = if run.is_finite() {
                0.8 * *run + 0.2 * set_loss
            } else {
                *set_loss
            };
        }
        self.set_ratio = ratio;
        loss
    }
}

/// `count` instances for one condition of a batch: distinct slots when the network
/// has `slots >= count` of them (a repeated slot is the same set, which the union
/// term could not tell apart), else random `u32`s.
pub(super) fn draw_instances(r: &mut impl Rng, count: usize, slots: u32) -> Vec<u32> {
    if (slots as usize) < count {
        return (0..count).map(|_| r.random()).collect();
    }
    // A partial Fisher-Yates shuffle of 0..slots.
    let mut all: Vec<u32> = (0..slots).collect();
    for j in 0..count {
        let pick = r.random_range(j..all.len());
        all.swap(j, pick);
    }
    all.truncate(count);
    all
}

/// A pretraining step for one condition: the squared distance of the network's
/// square points to the warp's ([`PoolCondition::warp_targets`]) for the
/// pretraining instance `instances[j] mod PRETRAIN_INSTANCES`; returns
/// `(mean squared distance, 0)` and adds the gradient into `grad`.
fn pretrain_step(
    cfg: &TrainConfig,
    net: &StepNetwork<'_>,
    pc: &PoolCondition,
    instances: &[u32],
    grad: &mut [f64],
) -> (f64, f64) {
    let n = cfg.n as usize;
    let w = 1.0 / (cfg.conditions_per_step * instances.len() * n) as f64;
    let mut loss = 0.0;
    for &r in instances {
        let k = r % pool::PRETRAIN_INSTANCES;
        for i in 0..cfg.n {
            let mut t = Trace::default();
            net.forward
                .trace_point_into(pc.unit, pc.metallic, k, i, &mut t);
            let s = t.square_point();
            let d = DVec2::new(s[0], s[1]) - pc.warp_targets[k as usize * n + i as usize];
            loss += d.length_squared() / (instances.len() * n) as f64;
            let d_out = output_gradient(&t, 2.0 * w * d);
            net.backward(&t, k, i, d_out, grad);
        }
    }
    (loss, 0.0)
}

/// The parameters of a step: as the optimizer holds them (row-major, what the
/// backward pass reads) and interleaved for the forward pass ([`Interleaved`]),
/// the same network.
struct StepNetwork<'a> {
    values: &'a [f64],
    forward: Network<InterleavedParams<'a, f64>>,
}

impl StepNetwork<'_> {
    /// [`backward`] of point `i` of instance `k` from its trace `t`, into `grad`.
    fn backward(&self, t: &Trace<f64>, k: u32, i: u32, d_out: [f64; OUTPUTS], grad: &mut [f64]) {
        let shape = &self.forward.shape;
        backward(
            shape,
            self.values,
            t,
            shape.embedding_row(k, i),
            d_out,
            grad,
        );
    }
}

/// Buffers that every training step reuses, so that a step allocates no
/// large arrays: an interleaved copy of the parameters and, per condition of a batch, its
/// forward passes and gradients. A step's memory was allocated afresh
/// before (about 24 MB a step at N = 64, from the network's traces and a
/// dense gradient per condition) and a quarter of training went to the
/// kernel's page faults and the allocator. No state: the results are the
/// same bits.
pub(super) struct StepScratch {
    /// The parameters of the step, interleaved for the forward pass.
    forward: Interleaved,
    /// One per condition of a batch, in batch order.
    slots: Vec<ConditionScratch>,
}

impl StepScratch {
    pub(super) fn new(cfg: &TrainConfig, shape: Shape) -> Self {
        let len = shape.param_len();
        Self {
            forward: Interleaved::new(shape, &vec![0.0; len]),
            slots: (0..cfg.conditions_per_step)
                .map(|_| ConditionScratch {
                    grad: vec![0.0; len],
                    ..ConditionScratch::default()
                })
                .collect(),
        }
    }
}

/// One condition's buffers in a step ([`condition_step`]).
#[derive(Default)]
struct ConditionScratch {
    traces: Vec<Trace<f64>>,
    jacobians: Vec<(DVec3, DVec3)>,
    dirs: Vec<DVec3>,
    local: Vec<f64>,
    grad3: Vec<DVec3>,
    g: Vec<DVec3>,
    caps: Vec<Cap>,
    mu: Vec<f64>,
    /// `dL/dparams` of the condition, already scaled by the batch's weights
    /// (cleared by the step before each condition adds into it).
    grad: Vec<f64>,
}

/// The sets of one condition in a batch: `(mean set loss, union loss)`, and
/// `dL/dparams` added into `scratch.grad`, already scaled by the batch's
/// weights.
fn condition_step(
    cfg: &TrainConfig,
    net: &StepNetwork<'_>,
    pc: &PoolCondition,
    instances: &[u32],
    start: usize,
    alpha: f64,
    scratch: &mut ConditionScratch,
) -> (f64, f64) {
    let n = cfg.n as usize;
    let s = instances.len();
    let b = cfg.conditions_per_step as f64;
    let m = cfg.caps_per_step.min(pc.caps.len());
    let ConditionScratch {
        traces,
        jacobians,
        dirs,
        local,
        grad3,
        g,
        caps,
        mu,
        grad,
    } = scratch;
    let idx = |j: usize| (start + j) % pc.caps.len();
    caps.clear();
    caps.extend((0..m).map(|j| pc.caps[idx(j)]));
    mu.clear();
    mu.extend((0..m).map(|j| pc.measures[idx(j)]));
    // Traces are written in place: a step's 3 kB per point, cleared and
    // moved, was a tenth of training.
    traces.resize(s * n, Trace::default());
    jacobians.clear();
    dirs.clear();
    let points = instances
        .iter()
        .flat_map(|&k| (0..cfg.n).map(move |i| (k, i)));
    for ((k, i), t) in points.zip(traces.iter_mut()) {
        net.forward.trace_point_into(pc.unit, pc.metallic, k, i, t);
        let sq = t.square_point();
        let (d, jx, jy) = pc.direction(DVec2::new(sq[0], sq[1]));
        jacobians.push((jx, jy));
        dirs.push(d);
    }
    local.clear();
    local.extend(dirs.iter().map(|&x| pc.local_factor(x)));
    let spacing = |points: usize| (pc.domain.area() / points as f64).sqrt();
    grad3.clear();
    grad3.resize(s * n, DVec3::ZERO);
    g.clear();
    g.resize(s * n, DVec3::ZERO);
    let mut set_loss = 0.0;
    for j in 0..s {
        let range = j * n..(j + 1) * n;
        set_loss += cap_loss_and_gradient(
            &dirs[range.clone()],
            caps,
            CapArea::Precomputed(mu),
            alpha / spacing(n),
            Some(&local[range.clone()]),
            GradientPath::Fast,
            &mut g[range.clone()],
        );
        let w = 1.0 / (b * s as f64);
        for (a, &x) in grad3[range.clone()].iter_mut().zip(&g[range]) {
            *a += w * x;
        }
    }
    set_loss /= s as f64;
    let mut union_loss = 0.0;
    if cfg.union_weight > 0.0 {
        union_loss = cap_loss_and_gradient(
            dirs,
            caps,
            CapArea::Precomputed(mu),
            alpha / spacing(s * n),
            Some(local),
            GradientPath::Fast,
            g,
        );
        let w = cfg.union_weight / b;
        for (a, &x) in grad3.iter_mut().zip(g.iter()) {
            *a += w * x;
        }
    }
    for (j, ((t, &(jx, jy)), &g3)) in traces
        .iter()
        .zip(jacobians.iter())
        .zip(grad3.iter())
        .enumerate()
    {
        let d_out = output_gradient(t, DVec2::new(jx.dot(g3), jy.dot(g3)));
        net.backward(t, instances[j / n], (j % n) as u32, d_out, grad);
    }
    (set_loss, union_loss)
}
