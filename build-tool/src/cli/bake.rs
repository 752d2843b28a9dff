//! `build-tool bake --brdf` / `bake --envmap MAP`: train a conditional sampler and
//! write its blob, report and pictures (library: [`crate::conditional::bake`]).

use crate::conditional::bake::{bake, BakeConfig, ENVMAP_ALPHA_END, ENVMAP_POOL_CONDITIONS};
use crate::sphere::envmap::shape_warning;
use crate::train::{TrainConfig, TrainTarget};
use anyhow::{ensure, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `build-tool bake`. Defaults are [`BakeConfig::default`]'s and
/// [`TrainConfig::default`]'s, read from there.
#[derive(Args, Debug)]
pub struct BakeArgs {
    /// Bake the glTF 2.0 BRDF sampler (condition: roughness, view angle; the
    /// metallic at run time): two networks, one for metallic below 1 and one for
    /// metals, each trained on its part of the prior.
    #[arg(long, conflicts_with = "envmap")]
    pub brdf: bool,
    /// Bake the environment-map sampler of this map (HDR, EXR; equirectangular, +z
    /// up): q(l | n) proportional to L(l) max(0, n.l), L the map's bilinearly
    /// filtered luminance, condition: the surface normal, weight: the irradiance
    /// E(n). Writes DIR/envmap.nuld.
    #[arg(long, value_name = "MAP")]
    pub envmap: Option<PathBuf>,
    /// Points per set.
    #[arg(long, default_value_t = TrainConfig::default().n as usize, allow_negative_numbers = true, value_parser = super::count)]
    pub n: usize,
    /// Instances stored in the point table (pixels sharing an instance share its error; the blob grows linearly).
    #[arg(long, default_value_t = BakeConfig::default().instances as usize, allow_negative_numbers = true, value_parser = super::count)]
    pub instances: usize,
    /// Point-table grid nodes per axis (each >= 2): roughness,theta_o for --brdf
    /// [default: 10,12]; the normal's octahedral square u,v for --envmap [default: 13,13].
    #[arg(long, value_delimiter = ',')]
    pub grid: Option<Vec<u32>>,
    /// Training steps after the 300 steps of pretraining on the warp; 0 trains
    /// nothing: the blob serves the prior's shifted lattice at each instance's
    /// offset, as a bake does where training did not help [default for --brdf,
    /// each of its two networks (metallic below 1, and the metal): 20000 at --n
    /// 64 to 127, else 12000; for --envmap 3000 below --n 256, 0 from 256 on,
    /// where training did not beat the lattice on any map measured].
    #[arg(long, allow_negative_numbers = true, value_parser = super::count)]
    pub steps: Option<usize>,
    /// Seed; fixes the output bit for bit whatever the thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Continue from DIR/checkpoint.bin (same options as the interrupted run).
    #[arg(long)]
    pub resume: bool,
    /// Hidden widths, comma-separated (1 to 3 layers).
    #[arg(long, value_delimiter = ',', default_values_t = TrainConfig::default().hidden,
        hide_default_value = true,
        help = with_list_default("Hidden widths, comma-separated (1 to 3 layers)", &TrainConfig::default().hidden))]
    pub hidden: Vec<u32>,
    /// SiLU hidden units instead of ReLU.
    #[arg(long)]
    pub silu: bool,
    /// --brdf: the metallic values the first network (metallic below 1) trains
    /// on, comma-separated, 2 to 8 increasing values in [0, 1]; the network reads
    /// the metallic as an input and the point table holds a layer per value,
    /// blended linearly between them. `none`: a network that does not read the
    /// metallic, trained on metallics spread over [0, 1) [default: 0,0.5,0.95].
    #[arg(long, value_name = "LIST", value_parser = metallic_nodes)]
    pub metallic_nodes: Option<MetallicNodes>,
    /// Instance slots M of the network: instance k is slot k mod M, a set with its own
    /// offset and learned per-point biases (0: every instance its own offset, no
    /// per-instance biases). Keep --instances <= M: table instances beyond M repeat
    /// sets [default: 64].
    #[arg(long, allow_negative_numbers = true, value_parser = super::count)]
    pub instance_slots: Option<usize>,
    /// Weight of the union-of-instances term [default for --brdf: 0.5 below --n
    /// 64, else 0 (from 64 points the union of instances stays apart without
    /// it); 1.5 for --envmap].
    #[arg(long)]
    pub union_weight: Option<f64>,
    /// Training conditions in the pool (`None`: the target's default,
    /// [`TrainConfig::default`]'s for a BRDF, [`ENVMAP_POOL_CONDITIONS`] for a map).
    #[arg(long, allow_negative_numbers = true, value_parser = super::count,
        help = pool_help())]
    pub pool_conditions: Option<usize>,
    /// Initial Adam step.
    #[arg(long, default_value_t = TrainConfig::default().learning_rate)]
    pub lr: f64,
    /// The cap loss's end sharpness (`None`: the target's default); its help,
    /// with both defaults, is `alpha_end_help`'s.
    #[arg(long, value_name = "A1", help = alpha_end_help())]
    pub alpha_end: Option<f64>,
    /// Held-out conditions per axis of the quality check in the report (0: none).
    #[arg(long, default_value_t = BakeConfig::default().quality_grid, allow_negative_numbers = true, value_parser = super::count)]
    pub quality_grid: usize,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

/// `--pool-conditions`' help with its two defaults, the BRDF sampler's and the
/// environment sampler's.
fn pool_help() -> String {
    format!(
        "Training conditions in the pool, each with its caps measured once before training \
         (more: a longer pool phase, a finer cover of the condition range) [default: {}; {} with --envmap]",
        TrainConfig::default().pool_conditions,
        ENVMAP_POOL_CONDITIONS
    )
}

/// `--alpha-end`'s help with its two defaults, the BRDF sampler's and the
/// environment sampler's.
fn alpha_end_help() -> String {
    format!(
        "Sharpness of the cap loss's sigmoid at the end of training, in inverse point spacings \
         (it ramps up from {}; smaller: a softer, wider gradient) [default: {} for --brdf, {} for --envmap]",
        TrainConfig::default().alpha_start,
        TrainConfig::default().alpha_end,
        ENVMAP_ALPHA_END
    )
}

/// `help` followed by `[default: a,b,...]`: clap shows a list's default joined by
/// spaces, which a comma-separated option does not parse.
fn with_list_default(help: &str, default: &[u32]) -> String {
    let values: Vec<String> = default.iter().map(u32::to_string).collect();
    format!("{help} [default: {}]", values.join(","))
}

/// Runs `build-tool bake`.
pub fn run(a: BakeArgs) -> Result<()> {
    ensure!(
        a.brdf || a.envmap.is_some(),
        "bake needs a target: --brdf or --envmap MAP"
    );
    ensure!(
        a.n >= 1 && a.n <= 1 << 16,
        "--n must be in 1..=65536, got {}",
        a.n
    );
    // A BRDF sampler's steps and union weight depend on N (`brdf_recipe`).
    let defaults = match &a.envmap {
        Some(map) => BakeConfig::envmap(TrainTarget::envmap(map)?),
        None => BakeConfig::default(),
    }
    .with_points(a.n as u32);
    let grid = a.grid.unwrap_or(defaults.grid.to_vec());
    ensure!(
        a.instances >= 1 && a.instances <= 1 << 16,
        "--instances must be in 1..=65536, got {}",
        a.instances
    );
    ensure!(
        grid.len() == 2 && grid.iter().all(|&g| (2..=256).contains(&g)),
        "--grid must be two node counts in 2..=256, like 10,12"
    );
    let steps = a.steps.unwrap_or(defaults.train.steps);
    ensure!(
        !(a.resume && steps == 0),
        "--resume continues a training run; with no training steps there is none to continue"
    );
    let instance_slots = a
        .instance_slots
        .unwrap_or(defaults.train.instance_slots as usize);
    ensure!(
        instance_slots <= 1 << 16,
        "--instance-slots must be in 0..=65536, got {instance_slots}"
    );
    let union_weight = a.union_weight.unwrap_or(defaults.train.union_weight);
    ensure!(
        union_weight.is_finite() && union_weight >= 0.0,
        "--union-weight must be finite and >= 0"
    );
    ensure!(
        a.lr.is_finite() && a.lr > 0.0,
        "--lr must be finite and > 0"
    );
    let alpha_end = a.alpha_end.unwrap_or(defaults.train.alpha_end);
    ensure!(
        alpha_end.is_finite() && alpha_end > 0.0,
        "--alpha-end must be finite and > 0"
    );
    let pool_conditions = a.pool_conditions.unwrap_or(defaults.train.pool_conditions);
    ensure!(
        (1..=1 << 16).contains(&pool_conditions),
        "--pool-conditions must be in 1..=65536, got {pool_conditions}"
    );
    let train = TrainConfig {
        n: a.n as u32,
        pool_conditions,
        hidden: a.hidden,
        silu: a.silu,
        metallic_nodes: a
            .metallic_nodes
            .map_or(defaults.train.metallic_nodes.clone(), |m| m.0),
        instance_slots: instance_slots as u32,
        steps,
        union_weight,
        learning_rate: a.lr,
        alpha_end,
        seed: a.seed,
        ..defaults.train.clone()
    };
    let config = BakeConfig {
        train,
        instances: a.instances as u32,
        grid: [grid[0], grid[1]],
        quality_grid: a.quality_grid,
        resume: a.resume,
        ..defaults
    };
    if let Some(w) = a.envmap.as_deref().and_then(shape_warning) {
        eprintln!("warning: {w}");
    }
    let report = bake(&config, &a.out)?;
    let mut line = format!(
        "wrote {} ({} bytes, {} parameters) in {:.1} s",
        a.out.join(config.blob_name()).display(),
        report.blob_bytes,
        report.parameters,
        report.timings.total_s
    );
    if let Some(q) = &report.quality {
        line += &format!(
            "; held-out cap L2 / warped Owen-Sobol: mean {:.3}, worst {:.3}, unbiased mode {:.3}; union {:.3}, nn {:.3}",
            q.mean_ratio, q.worst_ratio, q.mean_randomized_ratio, q.mean_union_ratio, q.mean_nn_ratio
        );
    }
    println!("{line}");
    if steps == 0 {
        let default = match a.steps {
            Some(_) => "",
            None => ", the default for --envmap from --n 256",
        };
        eprintln!(
            "note: no training steps{default}: the blob ships the prior's shifted lattice at each instance's offset (--steps K trains K steps)"
        );
    }
    if let (Some(trained), Some(q)) = (&report.trained_quality, &report.quality) {
        eprintln!(
            "note: on this target the trained sets checked worse than the prior's untrained lattice ({:.3} against {:.3}, the unbiased mode): the blob ships the lattice at each instance's offset, which checks at {:.3}",
            trained.mean_ratio, trained.mean_randomized_ratio, q.mean_ratio
        );
    }
    Ok(())
}

/// The values of `--metallic-nodes` (empty for `none`).
#[derive(Clone, Debug)]
pub struct MetallicNodes(Vec<f64>);

/// Parses `--metallic-nodes`: `none`, or 2 to 8 comma-separated increasing
/// values in `[0, 1]` (as the blob's metallic axis requires).
fn metallic_nodes(s: &str) -> Result<MetallicNodes, String> {
    if s.trim() == "none" {
        return Ok(MetallicNodes(Vec::new()));
    }
    let nodes = s
        .split(',')
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .map_err(|_| format!("{v:?} is not a number"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let f32s: Vec<f32> = nodes.iter().map(|&m| m as f32).collect();
    nuld_core::conditional::check_metallic_nodes(&f32s).map_err(|_| {
        format!(
            "expected `none` or 2 to {} increasing values in [0, 1], got {s:?}",
            nuld_core::conditional::MAX_METALLIC_NODES
        )
    })?;
    Ok(MetallicNodes(nodes))
}
