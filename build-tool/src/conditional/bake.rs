//! `bake --brdf` and `bake --envmap`: train a conditional sampler, distill it into
//! a blob, and report on it (paper §4).
//!
//! Writes into the output directory `brdf.nuld` or `envmap.nuld` (the blob,
//! [`BakeConfig::blob_name`]), `report.json`
//! (settings, timings, the loss curve and [`quality`](super::quality) at
//! held-out conditions), `loss.png` (the loss curve; none without training,
//! `--steps 0`, whose networks are the prior's lattice), `sets.png` (instance 0 at a
//! few conditions over the target, in the equal-area square; for a map, at a few
//! normals over the sphere's square), and while training
//! `checkpoint.bin` (every [`BakeConfig::checkpoint_every`], and at the end), from
//! which `resume` continues bit for bit; a BRDF bake trains a second network for
//! the prior's metal layer after the first ([`BakeConfig::metal_train`],
//! `checkpoint-metal.bin`). Every file is written atomically.

use super::distill::distill;
use super::quality::{evaluate, instance_directions, Quality, QualityConfig};
use crate::network::Params;
use crate::plot::{render_loglog, render_square_panels, Series, SquarePanel};
use crate::progress::Progress;
use crate::sphere::{BrdfTarget, DirectionDensity, EnvmapDensity};
use crate::train::target::{EnvmapTarget, LoadedTarget};
use crate::train::{envmap_steps, BrdfLayer, Checkpoint, TrainConfig, TrainTarget, Trainer};
use anyhow::{bail, Context, Result};
use glam::{DVec2, DVec3};
use nuld_core::blob::{Domain, Metadata};
use nuld_core::conditional::{ConditionalTarget, PointWarp};
use nuld_core::sphere::sphere_to_square;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Settings of a bake.
#[derive(Clone, Debug, Serialize)]
pub struct BakeConfig {
    /// The training run.
    pub train: TrainConfig,
    /// Instances stored in the point table `S` (default 64). A renderer gives each
    /// pixel an instance modulo `S`, so pixels sharing an instance share its error:
    /// with 16, table-mode renders showed a mean signed error of up to 40% of the
    /// mean pixel (4 spp) that 64 instances remove. Blob size grows linearly in `S`.
    pub instances: u32,
    /// Point-table grid nodes `(roughness, theta_o)`.
    pub grid: [u32; 2],
    /// Weight-table grid nodes.
    pub weight_grid: [u32; 2],
    /// Held-out conditions per axis of the quality check (0 skips it).
    pub quality_grid: usize,
    /// Time between checkpoints.
    pub checkpoint_every: Duration,
    /// Continue from the directory's checkpoints.
    pub resume: bool,
}

impl Default for BakeConfig {
    fn default() -> Self {
        Self {
            train: TrainConfig::default(),
            instances: 64,
            grid: [10, 12],
            weight_grid: [32, 32],
            quality_grid: 4,
            checkpoint_every: Duration::from_secs(120),
            resume: false,
        }
    }
}

/// Seconds spent per phase.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timings {
    /// Building the condition pool (cap measures); without training, reading
    /// the target.
    pub pool_s: f64,
    /// Training.
    pub train_s: f64,
    /// Distilling the tables.
    pub distill_s: f64,
    /// The quality check.
    pub quality_s: f64,
    /// Everything.
    pub total_s: f64,
}

/// `report.json`.
#[derive(Clone, Debug, Serialize)]
pub struct BakeReport {
    /// The settings.
    pub config: BakeConfig,
    /// Network parameters.
    pub parameters: usize,
    /// Multiply-adds per network sample.
    pub multiply_adds: usize,
    /// Blob size in bytes.
    pub blob_bytes: usize,
    /// Phase timings (this run; a resumed run times only what it did).
    pub timings: Timings,
    /// The loss of every step, averaged over blocks of `loss_block` steps.
    pub loss_curve: Vec<f64>,
    /// Steps per entry of `loss_curve`.
    pub loss_block: usize,
    /// Held-out quality of what the blob ships (network mode, f16 parameters,
    /// against Owen-Sobol through the mixture warp for the BRDF, through the lit
    /// map's inverse CDF for a map).
    pub quality: Option<Quality>,
    /// The trained networks' held-out quality where it was worse than the
    /// unbiased mode's and the blob ships the untrained lattice instead
    /// (`quality` is then the lattice's); absent where the trained sets ship.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trained_quality: Option<Quality>,
}

/// Point-table grid of an environment sampler: 13 x 13 normals on the octahedral
/// square (about 15 degrees apart).
pub const ENVMAP_GRID: [u32; 2] = [13, 13];

/// Weight-table grid of an environment sampler: the irradiance has a kink where a
/// sun crosses the normal's horizon, so it is tabulated finer than the points.
pub const ENVMAP_WEIGHT_GRID: [u32; 2] = [64, 64];

impl BakeConfig {
    /// The defaults of an environment sampler of `target`:
    /// [`Self::envmap_sizes`] through [`Self::with_envmap`].
    pub fn envmap(target: TrainTarget) -> Self {
        Self::envmap_sizes().with_envmap(target)
    }

    /// An environment sampler's sizes before its map is known: [`ENVMAP_GRID`],
    /// [`ENVMAP_WEIGHT_GRID`], the steps of [`envmap_steps`] at the default N
    /// ([`crate::train::ENVMAP_STEPS`]), [`ENVMAP_POOL_CONDITIONS`],
    /// otherwise [`BakeConfig::default`] (what `render` bakes for each map it
    /// is given, through [`Self::with_envmap`]).
    pub fn envmap_sizes() -> Self {
        Self {
            grid: ENVMAP_GRID,
            weight_grid: ENVMAP_WEIGHT_GRID,
            train: TrainConfig {
                steps: envmap_steps(TrainConfig::default().n),
                pool_conditions: ENVMAP_POOL_CONDITIONS,
                ..TrainConfig::default()
            },
            ..Self::default()
        }
    }

    /// These settings at `n` points per set ([`TrainConfig::with_points`]: a
    /// BRDF sampler on the recipe moves to the recipe's steps and union weight
    /// at `n`).
    pub fn with_points(self, n: u32) -> Self {
        Self {
            train: self.train.with_points(n),
            ..self
        }
    }

    /// These settings for an environment sampler of `target`: the network refines
    /// the primary space of the map's tree (the exact prior), with
    /// [`ENVMAP_INSTANCE_SLOTS`] instance slots, the union weight
    /// [`ENVMAP_UNION_WEIGHT`] and the end sharpness [`ENVMAP_ALPHA_END`].
    pub fn with_envmap(self, target: TrainTarget) -> Self {
        Self {
            train: TrainConfig {
                target,
                prior: true,
                instance_slots: ENVMAP_INSTANCE_SLOTS,
                union_weight: ENVMAP_UNION_WEIGHT,
                alpha_end: ENVMAP_ALPHA_END,
                ..self.train
            },
            ..self
        }
    }

    /// The blob's file name: `brdf.nuld` or `envmap.nuld` ([`TrainTarget::name`]).
    pub fn blob_name(&self) -> String {
        format!("{}.nuld", self.train.target.name())
    }

    /// The training run of a BRDF sampler's second network, the metal layer's:
    /// [`Self::train`] on metals ([`BrdfLayer::Metal`]); `None` for an
    /// environment map.
    pub fn metal_train(&self) -> Option<TrainConfig> {
        (self.train.target == TrainTarget::GltfBrdf).then(|| TrainConfig {
            layer: BrdfLayer::Metal,
            ..self.train.clone()
        })
    }
}

/// Instance slots of an environment sampler's network, as the BRDF sampler's: on
/// the tree's primary space, courtyard N = 64 (3000 steps) scored 0.724 of the
/// baseline with 64 slots and union weight 0.5, 0.755 with none and weight 4
/// (docs/results/envmap.md).
pub const ENVMAP_INSTANCE_SLOTS: u32 = 64;

/// Weight of the union term for an environment sampler. With the prior's finer
/// leaves, weight 1.5 against 0.5 (the BRDF sampler's): courtyard N = 64 checked
/// at 0.728 (worst 0.895, union 0.156) against 0.734 (0.936, 0.186), lowsun's
/// union 0.286 against 0.299, studio N = 256's 0.268; courtyard rendered with MIS
/// at an RMSE of 2.188e-2 against 2.299e-2 at 64 spp and a fixed-instance bias of
/// -2.14e-3 against -2.49e-3 at 256 spp (docs/results/envmap.md#floor).
pub const ENVMAP_UNION_WEIGHT: f64 = 1.5;

/// The cap loss's end sharpness for an environment sampler, in inverse point
/// spacings: 32 (the BRDF sampler's) gained 0.003 to 0.011 of the baseline on
/// the shared maps at N = 64 and nothing on a map of small lamps, whose worst
/// normal lost 0.014, and took longer (docs/results/envmap.md#alpha-end).
pub const ENVMAP_ALPHA_END: f64 = 64.0;

/// Training conditions in an environment sampler's pool: the normals' pool
/// holds the map's caps per normal, and its bake time is a goal (`bake
/// --envmap` N = 64 within 90 s); the BRDF sampler's larger default
/// ([`TrainConfig::default`]) was measured on the BRDF sampler only.
pub const ENVMAP_POOL_CONDITIONS: usize = 256;

/// The checkpoint's path in `dir`.
pub fn checkpoint_path(dir: &Path) -> PathBuf {
    dir.join("checkpoint.bin")
}

/// The metal layer's network's checkpoint in `dir` ([`BakeConfig::metal_train`]).
pub fn metal_checkpoint_path(dir: &Path) -> PathBuf {
    dir.join("checkpoint-metal.bin")
}

/// The checkpoint at `path` to resume a run of `config` from, if `resume`
/// (`required`: an error if there is none); an error if it was written with
/// other settings.
fn resume_from(
    path: &Path,
    config: &TrainConfig,
    resume: bool,
    required: bool,
) -> Result<Option<Checkpoint>> {
    if !resume || (!required && !path.is_file()) {
        return Ok(None);
    }
    let c = Checkpoint::load(path)?;
    if &c.config != config {
        bail!(
            "{} was written with other training settings; rerun with the same options or without --resume",
            path.display()
        );
    }
    Ok(Some(c))
}

/// Trains `trainer` to its last step, saving its checkpoint at `path` every
/// `every` and at the end; two bars named `label`, so that `--steps K` shows
/// K training steps: the pretraining on the warp, then the cap-loss steps.
fn train(trainer: &mut Trainer, path: &Path, every: Duration, label: &str) -> Result<()> {
    let pretrain = trainer.config.pretrain_steps;
    let mut last_save = Instant::now();
    for (phase, first, end) in [
        ("pretrain", 0, pretrain),
        ("train", pretrain, trainer.total_steps()),
    ] {
        if trainer.state.step >= end {
            continue;
        }
        let progress = Progress::stderr(&format!("{phase}{label}"), (end - first) as u64, "step");
        progress.inc((trainer.state.step.max(first) - first) as u64);
        while trainer.state.step < end {
            let r = trainer.step();
            progress.inc(1);
            progress.set_message(if phase == "pretrain" {
                format!("distance to the warp {:.3e}", r.loss)
            } else {
                format!("loss {:.3e}, sets/baseline {:.3}", r.loss, r.set_ratio)
            });
            if last_save.elapsed() >= every {
                trainer.state.save(path)?;
                last_save = Instant::now();
            }
        }
        progress.finish();
    }
    trainer.state.save(path)
}

/// Runs a bake into `out` (see the module docs); progress on stderr.
pub fn bake(config: &BakeConfig, out: &Path) -> Result<BakeReport> {
    let started = Instant::now();
    if config.train.shape().is_none() {
        bail!(
            "network shape out of range: 1 to 3 hidden layers of 1 to {} units, and \
             max(instance slots, 1) x n x the first width below 2^32",
            nuld_core::network::MAX_WIDTH
        );
    }
    // Before the pool (seconds to minutes): an unusable --out fails at once, and
    // the directory goes again if the run fails before writing into it.
    let out_dir = crate::output::NewDir::create(out)?;
    let mut timings = Timings::default();
    let nets = if config.train.steps == 0 {
        untrained(config, &mut timings)?
    } else {
        trained(config, out, &mut timings)?
    };
    // A training run's checkpoints stay for `--resume` whatever follows; a bake
    // that trained nothing leaves no directory if it fails before its blob.
    let out_dir = if nets.trained {
        out_dir.keep();
        None
    } else {
        Some(out_dir)
    };

    let t = Instant::now();
    let target = &nets.target;
    let shipped = ship(
        nets.params,
        nets.metal,
        target,
        config.quality_grid,
        nets.trained,
    )?;
    timings.quality_s = t.elapsed().as_secs_f64();
    let (params, metal_params) = (&shipped.params, shipped.metal.as_ref());

    let t = Instant::now();
    let parts = distill(
        params,
        metal_params,
        target,
        config.instances,
        config.grid,
        config.weight_grid,
        &config.train.table_metallic_nodes(),
    );
    let blob = parts.to_blob(&Metadata {
        generator: "bake",
        target: config.train.target.name(),
        seed: config.train.seed,
    })?;
    timings.distill_s = t.elapsed().as_secs_f64();

    let losses = &nets.losses;
    let loss_block = losses.len().div_ceil(200).max(1);
    let loss_curve: Vec<f64> = losses
        .chunks(loss_block)
        .map(|c| c.iter().sum::<f64>() / c.len() as f64)
        .collect();
    let series = Series {
        label: "training loss".into(),
        points: loss_curve
            .iter()
            .enumerate()
            .map(|(j, &l)| (((j + 1) * loss_block) as f64, l))
            .collect(),
    };
    let loss_png = out.join("loss.png");
    if losses.is_empty() {
        // No training, no curve: an earlier bake's in this directory would
        // describe another blob.
        if loss_png.is_file() {
            std::fs::remove_file(&loss_png)
                .with_context(|| format!("cannot remove {}", loss_png.display()))?;
        }
    } else {
        render_loglog(
            &loss_png,
            &format!("bake --{}: training loss", config.train.target.name()),
            "step",
            "loss",
            &[series],
            (800, 500),
        )?;
    }
    match target {
        LoadedTarget::GltfBrdf(_) => render_sets(&out.join("sets.png"), params)?,
        LoadedTarget::Envmap(env) => render_envmap_sets(&out.join("sets.png"), params, env)?,
    }
    crate::output::write_atomic(&out.join(config.blob_name()), blob.as_slice())?;
    if let Some(dir) = out_dir {
        dir.keep();
    }
    timings.total_s = started.elapsed().as_secs_f64();
    let report = BakeReport {
        config: config.clone(),
        parameters: params.shape.param_len(),
        multiply_adds: params.shape.multiply_adds(),
        blob_bytes: blob.as_slice().len(),
        timings,
        loss_curve,
        loss_block,
        quality: shipped.quality,
        trained_quality: shipped.trained_quality,
    };
    let json = serde_json::to_vec_pretty(&report).context("cannot encode report")?;
    crate::output::write_atomic(&out.join("report.json"), &json)?;
    Ok(report)
}

/// The networks a bake distills, and what it read to make them.
struct Networks {
    /// The target, as the pool (or an untrained bake) loaded it.
    target: LoadedTarget,
    /// The first network (a BRDF sampler's below metallic 1).
    params: Params,
    /// A BRDF sampler's metal-layer network.
    metal: Option<Params>,
    /// The loss of every training step (none without training).
    losses: Vec<f64>,
    /// Whether they were trained; else they are the prior's lattice, which a
    /// bake has nothing to compare with.
    trained: bool,
}

/// Trains a bake's networks (from `out`'s checkpoints with `resume`), saving
/// checkpoints into `out` as it goes.
fn trained(config: &BakeConfig, out: &Path, timings: &mut Timings) -> Result<Networks> {
    let ckpt_path = checkpoint_path(out);
    let metal_path = metal_checkpoint_path(out);
    let resume = resume_from(&ckpt_path, &config.train, config.resume, true)?;
    let metal_config = config.metal_train();
    let metal_resume = match &metal_config {
        Some(c) => resume_from(&metal_path, c, config.resume, false)?,
        None => None,
    };
    let t = Instant::now();
    let mut trainer = Trainer::new(config.train.clone(), resume)?;
    let mut metal_trainer = metal_config
        .map(|c| Trainer::new(c, metal_resume))
        .transpose()?;
    timings.pool_s = t.elapsed().as_secs_f64();
    print_notes(&trainer.pool.target);

    let t = Instant::now();
    let every = config.checkpoint_every;
    train(&mut trainer, &ckpt_path, every, "")?;
    if let Some(metal) = &mut metal_trainer {
        train(metal, &metal_path, every, " metal")?;
    }
    timings.train_s = t.elapsed().as_secs_f64();
    Ok(Networks {
        params: trainer.params(),
        metal: metal_trainer.as_ref().map(Trainer::params),
        losses: std::mem::take(&mut trainer.state.losses),
        target: trainer.pool.target,
        trained: true,
    })
}

/// A bake of no training steps (`--steps 0`): networks whose residual is 0
/// ([`Params::without_residual`]), so that table and network mode serve the
/// prior's shifted lattice at each instance's offset, the sets the bake ships
/// where training did not help ([`ship`]); no pool is built. An error for a
/// network that refines no prior (`--instance-slots 0` keeps a residual, the
/// earlier mixture networks do not).
fn untrained(config: &BakeConfig, timings: &mut Timings) -> Result<Networks> {
    let t = Instant::now();
    let target = config.train.target.load()?;
    let lattice = |c: &TrainConfig| -> Result<Params> {
        let shape = c.shape().context("network shape out of range")?;
        Params::init(shape, c.seed).without_residual().context(
            "--steps 0 ships the prior's lattice: it needs a network on the prior's primary space",
        )
    };
    let params = lattice(&config.train)?;
    let metal = config.metal_train().map(|c| lattice(&c)).transpose()?;
    timings.pool_s = t.elapsed().as_secs_f64();
    print_notes(&target);
    Ok(Networks {
        target,
        params,
        metal,
        losses: Vec::new(),
        trained: false,
    })
}

/// Prints what reading a map changed, as `optimize` does: e.g. the negative
/// pixels of a lossy EXR, set to 0.
fn print_notes(target: &LoadedTarget) {
    if let LoadedTarget::Envmap(env) = target {
        for note in env.map.notes() {
            eprintln!("note: {note}");
        }
    }
}

/// What a bake ships: the trained networks, or their untrained lattice
/// ([`Params::without_residual`]) where the trained sets check worse than it.
struct Shipped {
    params: Params,
    metal: Option<Params>,
    /// The held-out check of what ships.
    quality: Option<Quality>,
    /// The trained networks' check, where the lattice ships instead.
    trained_quality: Option<Quality>,
}

/// The networks a bake ships, and their held-out check on a `grid x grid` grid
/// of conditions (none at 0). Where the trained sets check worse than the
/// unbiased mode, the prior's shifted lattice with a random shift per instance
/// ([`Quality::training_helps`]), training has hurt this target (a map whose
/// sun holds most of its light: docs/results/envmap.md#clear-skies): the
/// learned residual is dropped, so that table and network mode serve the
/// untrained lattice at each instance's offset, which is checked again.
/// Networks that were not `trained` are that lattice already: checked once.
fn ship(
    params: Params,
    metal: Option<Params>,
    target: &LoadedTarget,
    grid: usize,
    trained: bool,
) -> Result<Shipped> {
    if grid == 0 {
        return Ok(Shipped {
            params,
            metal,
            quality: None,
            trained_quality: None,
        });
    }
    let held_out = QualityConfig::held_out(target, grid, 0x9a11);
    let checked = evaluate(&params, metal.as_ref(), target, &held_out)?;
    if !trained {
        return Ok(Shipped {
            params,
            metal,
            quality: Some(checked),
            trained_quality: None,
        });
    }
    let trained = checked;
    // The metal network's lattice too, where there is one (`None`: no copy).
    let lattice = match &metal {
        None => Some(None),
        Some(m) => m.without_residual().map(Some),
    };
    match (trained.training_helps(), params.without_residual(), lattice) {
        (false, Some(params), Some(metal)) => {
            let quality = evaluate(&params, metal.as_ref(), target, &held_out)?;
            Ok(Shipped {
                params,
                metal,
                quality: Some(quality),
                trained_quality: Some(trained),
            })
        }
        _ => Ok(Shipped {
            params,
            metal,
            quality: Some(trained),
            trained_quality: None,
        }),
    }
}

/// Instance 0 at four conditions, each over its target in the equal-area square.
fn render_sets(path: &Path, params: &Params) -> Result<()> {
    let shipped = params.rounded_to_f16();
    let conds = [[0.15, 20.0], [0.15, 75.0], [0.5, 45.0], [0.9, 80.0]];
    // Only the density and the lobe probability are read: no cap-measure table
    // worth building.
    let targets = conds
        .iter()
        .map(|c| BrdfTarget::coarse(c[0], c[1], 0.0, 1 << 10))
        .collect::<Result<Vec<_>, _>>()?;
    let densities: Vec<Box<dyn Fn(DVec2) -> f64 + '_>> = targets
        .iter()
        .map(|t| {
            Box::new(move |p| t.pdf(Domain::Hemisphere.to_direction(p)))
                as Box<dyn Fn(DVec2) -> f64>
        })
        .collect();
    let panels: Vec<SquarePanel<'_>> = conds
        .iter()
        .zip(&densities)
        .zip(&targets)
        .map(|((c, d), t)| SquarePanel {
            caption: format!("roughness {}, theta_o {} deg", c[0], c[1]),
            density: d.as_ref(),
            points: instance_directions(&shipped, *c, t.lobe_probability(), 0)
                .into_iter()
                .map(|x| Domain::Hemisphere.to_square(x))
                .collect(),
        })
        .collect();
    render_square_panels(path, &panels, 450)
}

/// Instance 0 at four normals, each over its target `L max(0, n.l)` in the
/// sphere's equal-area square.
fn render_envmap_sets(path: &Path, params: &Params, env: &EnvmapTarget) -> Result<()> {
    // The pool's copy: a 450-pixel panel does not see its blocks, and lighting
    // an 8192 x 4096 map whole four times took 29 s.
    let map = env.coarse_map();
    let shipped = params.rounded_to_f16();
    let warp = PointWarp::of(ConditionalTarget::EnvmapNormal, &params.shape);
    let tree = env.tree.tree();
    let normals = [
        ("+z (up)", DVec3::Z),
        ("+x", DVec3::X),
        ("tilted (1, -1, 1)", DVec3::new(1.0, -1.0, 1.0).normalize()),
        ("-z (down)", DVec3::NEG_Z),
    ];
    let lit: Vec<EnvmapDensity> = normals
        .iter()
        .map(|(_, n)| map.cosine_weighted(*n).map(|(lit, _)| lit))
        .collect::<Result<_, _>>()?;
    let densities: Vec<Box<dyn Fn(DVec2) -> f64 + '_>> = lit
        .iter()
        .map(|t| {
            Box::new(move |p| t.pdf(Domain::Sphere.to_direction(p))) as Box<dyn Fn(DVec2) -> f64>
        })
        .collect();
    let panels: Vec<SquarePanel<'_>> = normals
        .iter()
        .zip(&densities)
        .map(|((name, n), d)| {
            let u = sphere_to_square(*n).to_array();
            SquarePanel {
                caption: format!("normal {name}"),
                density: d.as_ref(),
                points: (0..shipped.shape.n())
                    .map(|i| {
                        let p = shipped.square_point(u, 0.0, 0, i);
                        let d = warp.direction(Domain::Sphere, u, 0.0, Some(&tree), p);
                        sphere_to_square(DVec3::from_array(d))
                    })
                    .collect(),
            }
        })
        .collect();
    render_square_panels(path, &panels, 450)
}

#[cfg(test)]
mod tests;
