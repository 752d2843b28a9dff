//! `build-tool bench`: parses the arguments, takes the measurements of
//! [`crate::lab::bench`] and prints them as tables.

use crate::baselines::Baseline;
use crate::conditional::bake::BakeConfig;
use crate::discrepancy::GradientPath;
use crate::lab::bench::rounds::ROUNDS;
use crate::lab::bench::{baselines, envmap_prior, optimizer, runtime, training};
use crate::optimize::directions::DirectionConfig;
use crate::optimize::{AreaOption, OptimizeConfig};
use anyhow::Result;
use clap::Args;

/// Arguments of `build-tool bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Point counts to time per epoch.
    #[arg(long, value_delimiter = ',', default_value = "256,1024,2048,4096")]
    pub sizes: Vec<usize>,
    /// Closed-form target for the per-epoch timings and the first full run.
    #[arg(long, default_value = "gaussian:0.5,0.5,0.15")]
    pub density: String,
    /// Tabulated target for the second full run (skipped if it does not load).
    #[arg(long, default_value = "image:../shared/data/images/camera.png")]
    pub image_density: String,
    /// Epochs timed per size on the fast path (the full alpha ramp is compressed
    /// into them, so the band widths match a real run's average).
    #[arg(long, default_value_t = 100)]
    pub fast_epochs: usize,
    /// Epochs timed per size on the dense path.
    #[arg(long, default_value_t = 3)]
    pub dense_epochs: usize,
    /// Point count of the full default runs (0 skips them).
    #[arg(long, default_value_t = 2048)]
    pub full_n: usize,
    /// Direction target (sphere domain) for the direction timings.
    #[arg(long, default_value = "uniform")]
    pub direction_density: String,
    /// Environment map of the `envmap-prior` timings.
    #[arg(long, default_value = "../shared/data/envmaps/courtyard.hdr")]
    pub envmap: std::path::PathBuf,
    /// Which parts to run.
    #[arg(long, value_enum, default_value = "all")]
    pub only: BenchPart,
}

/// `--only` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchPart {
    /// 2D and directions.
    All,
    /// Only the 2D optimizer.
    Square,
    /// Only the direction optimizer.
    Directions,
    /// Only the baseline generators (milliseconds per set; not part of `all`).
    Baselines,
    /// Only the runtime's conditional samplers against the incumbent warps
    /// (nanoseconds per sample, one thread; not part of `all`): the BRDF
    /// sampler's table, then the environment sampler's (`envmap-prior`) when
    /// `--envmap` is there.
    Runtime,
    /// Only the environment sampler's prior, the exact product warp of a map's
    /// light and a normal's cosine, against Owen-Sobol through the map's
    /// luminance warp in f32 with its pdf, as Mitsuba 3's environment light
    /// samples it (nanoseconds per sample, one thread; not part of `all`).
    EnvmapPrior,
    /// Only the conditional sampler's training: milliseconds per step at N = 64,
    /// 256 and 2048, all threads, and the default bake's training time that
    /// implies (not part of `all`).
    Training,
}

fn run_directions(a: &BenchArgs) -> Result<()> {
    let d = DirectionConfig::default();
    println!(
        "direction optimizer per-epoch cost, {} on the sphere ({} caps, alpha {}..{} inverse spacings)",
        a.direction_density, d.caps, d.alpha_start, d.alpha_end
    );
    println!(
        "{:>6} {:>14} {:>14} {:>8}",
        "N", "fast ms/epoch", "dense ms/epoch", "ratio"
    );
    for &n in &a.sizes {
        let fast = optimizer::direction_seconds_per_epoch(
            &a.direction_density,
            n,
            5 * a.fast_epochs,
            GradientPath::Fast,
        )?;
        let dense = optimizer::direction_seconds_per_epoch(
            &a.direction_density,
            n,
            a.dense_epochs,
            GradientPath::Dense,
        )?;
        println!(
            "{n:>6} {:>14.2} {:>14.2} {:>7.1}x",
            fast * 1e3,
            dense * 1e3,
            dense / fast
        );
    }
    if a.full_n > 0 {
        let s = optimizer::direction_full_run(&a.direction_density, a.full_n)?;
        println!(
            "full default run ({} epochs), N = {}: {s:.1} s   (paper, RTX 5090 laptop: 75 s)",
            d.epochs, a.full_n
        );
    }
    Ok(())
}

/// Runs `build-tool bench`.
pub fn run(a: BenchArgs) -> Result<()> {
    match a.only {
        BenchPart::All => {
            run_square(&a)?;
            run_directions(&a)
        }
        BenchPart::Square => run_square(&a),
        BenchPart::Directions => run_directions(&a),
        BenchPart::Baselines => run_baselines(&a),
        BenchPart::Runtime => {
            run_runtime()?;
            // The environment sampler's table, too, when its map is there.
            if a.envmap.exists() {
                println!();
                run_envmap_prior(&a)?;
            } else {
                println!(
                    "environment sampler skipped: {} not found (--envmap MAP)",
                    a.envmap.display()
                );
            }
            Ok(())
        }
        BenchPart::Training => run_training(),
        BenchPart::EnvmapPrior => run_envmap_prior(&a),
    }
}

/// Sizes of the training timings and the cap-loss steps timed at each (a step
/// costs about linearly in N).
const TRAINING_SIZES: [(u32, usize); 3] = [(64, 20), (256, 6), (2048, 2)];

/// Milliseconds per training step of the conditional BRDF sampler, all threads,
/// and the default bake's training time at that rate: the steps of each network
/// it trains at that N (below metallic 1, and the metal), pretraining included.
fn run_training() -> Result<()> {
    let d = crate::train::TrainConfig::default();
    let bake_steps = |n: u32| {
        let bake = BakeConfig::default().with_points(n);
        std::iter::once(bake.train.clone())
            .chain(bake.metal_train())
            .map(|t| t.pretrain_steps + t.steps)
            .sum::<usize>()
    };
    println!(
        "conditional sampler training, {} rayon threads, hidden {:?}, {} conditions x {} instances per step",
        rayon::current_num_threads(),
        d.hidden,
        d.conditions_per_step,
        d.instances_per_condition
    );
    println!(
        "{:>6} {:>10} {:>8} {:>12} {:>30}",
        "N", "setup s", "steps", "ms/step", "default bake's training, min"
    );
    for t in training::measure(&TRAINING_SIZES) {
        println!(
            "{:>6} {:>10.1} {:>8} {:>12.1} {:>30.1}",
            t.n,
            t.setup_s,
            t.timed_steps,
            t.ms_per_step,
            t.run_seconds(bake_steps(t.n)) / 60.0
        );
    }
    Ok(())
}

/// Samples timed per method over its rounds (a tenth of it in network mode):
/// half a million a round.
const RUNTIME_SAMPLES: u32 = 500_000 * ROUNDS;

/// Nanoseconds per sample of the conditional sampler's modes and of the incumbent,
/// one thread, with each method's ratio to the incumbent (direction only).
fn run_runtime() -> Result<()> {
    let t = runtime::measure(RUNTIME_SAMPLES)?;
    println!("runtime ns per sample, one thread, n = 64 (median of {ROUNDS} interleaved rounds)");
    println!("{:<68} {:>10} {:>12}", "method", "ns/sample", "/ incumbent");
    let base = t.rows.first().map_or(f64::NAN, |r| r.1);
    for (name, ns) in &t.rows {
        println!("{name:<68} {ns:>10.1} {:>11.2}x", ns / base);
    }
    Ok(())
}

/// Nanoseconds per sample of the environment sampler's prior against the
/// incumbent, one thread.
fn run_envmap_prior(a: &BenchArgs) -> Result<()> {
    let img = crate::density::image::load_luminance(&a.envmap)?;
    let map = crate::sphere::EnvmapDensity::from_luminance_filtered(
        &img,
        nuld_core::blob::Domain::Sphere,
        &a.envmap.display().to_string(),
    )?;
    let light = crate::baselines::EnvmapLight::new(&img)?;
    let rows = envmap_prior::measure(&map, &light, RUNTIME_SAMPLES)?;
    println!(
        "environment prior ns per sample, one thread, {}, n = 64 (median of {ROUNDS} interleaved rounds)",
        a.envmap.display()
    );
    println!("{:<72} {:>10} {:>12}", "method", "ns/sample", "/ incumbent");
    let base = rows.first().map_or(f64::NAN, |r| r.1);
    for (name, ns) in &rows {
        println!("{name:<72} {ns:>10.1} {:>11.2}x", ns / base);
    }
    Ok(())
}

/// Sets timed per (baseline, size); the fastest is reported (the least disturbed
/// by other work on the machine).
const BASELINE_REPEATS: u64 = 3;

/// Milliseconds per uniform set of every baseline generator (the fastest of
/// [`BASELINE_REPEATS`] seeds per size; SOT and GBN at their default iteration
/// counts): what the evaluation harness pays per realization before any metric.
fn run_baselines(a: &BenchArgs) -> Result<()> {
    println!(
        "baseline generators, ms per uniform 2D set, {} rayon threads",
        rayon::current_num_threads()
    );
    print!("{:<14}", "method");
    for n in &a.sizes {
        print!(" {:>10}", format!("N={n}"));
    }
    println!();
    for b in Baseline::ALL {
        print!("{:<14}", b.name());
        for &n in &a.sizes {
            let best = baselines::best_ms_per_set(b, n, BASELINE_REPEATS)?;
            print!(" {best:>10.2}");
        }
        println!();
    }
    Ok(())
}

fn run_square(a: &BenchArgs) -> Result<()> {
    let d = OptimizeConfig::default();
    println!(
        "optimizer per-epoch cost, {} ({} anchors x 4 boxes, alpha {}..{} sqrt(N)), {} rayon threads",
        a.density,
        d.anchors,
        d.alpha_start,
        d.alpha_end,
        rayon::current_num_threads()
    );
    println!(
        "{:>6} {:>14} {:>14} {:>8}",
        "N", "fast ms/epoch", "dense ms/epoch", "ratio"
    );
    for &n in &a.sizes {
        let fast =
            optimizer::square_seconds_per_epoch(&a.density, n, a.fast_epochs, GradientPath::Fast)?;
        let dense = optimizer::square_seconds_per_epoch(
            &a.density,
            n,
            a.dense_epochs,
            GradientPath::Dense,
        )?;
        println!(
            "{n:>6} {:>14.2} {:>14.2} {:>7.1}x",
            fast * 1e3,
            dense * 1e3,
            dense / fast
        );
    }
    if a.full_n > 0 {
        println!("full default runs ({} epochs), N = {}:", d.epochs, a.full_n);
        let s = optimizer::square_full_run(&a.density, a.full_n, AreaOption::Exact)?;
        println!("  {:<50} {s:>7.1} s   (paper, RTX A5000: 150 s)", a.density);
        let mc = AreaOption::MonteCarlo { samples: 65536 };
        for (area, label) in [
            (AreaOption::Exact, "exact areas"),
            (mc, "MC areas, K = 65536"),
        ] {
            let name = format!("{} ({label})", a.image_density);
            match optimizer::square_full_run(&a.image_density, a.full_n, area) {
                Ok(s) => println!("  {name:<50} {s:>7.1} s   (paper, RTX A5000: 630 s, MC areas)"),
                Err(e) => println!("  {name:<50} skipped: {e:#}"),
            }
        }
    }
    Ok(())
}
