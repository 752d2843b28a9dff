//! `build-tool eval FIG --out DIR`: the paper's §5 figures (see [`crate::lab::eval`]).

use crate::lab::eval::conditional::{blob_sets, evaluate, ConditionalSettings, MixtureOwenSobol};
use crate::lab::eval::{run_figure, EvalSettings, Figure};
use crate::pointset::AlignedBytes;
use anyhow::Result;
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::time::Instant;

/// `FIG` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FigArg {
    /// 2D uniform: L2-star and exact D* (ours, random, owen-sobol, sobol-cp,
    /// halton, poisson-disk, sot, gbn).
    Fig2,
    /// Uniform sphere: cap L2 (Stolarsky) and cap D* lower bound.
    Fig3,
    /// 2D non-uniform targets: asd, L2-star, D*(mu).
    Fig5,
    /// Non-uniform directions: cap L2 (energy form), cap D* lower bound.
    Fig6,
    /// Integration RMSE.
    Fig7,
    /// Every figure, in order (not `conditional`, which needs a blob).
    All,
    /// Quality report of a conditional BRDF sampler (`--blob FILE`, or
    /// `--calibrate`) on held-out (roughness, θo) crossed with --metallic: cap L2
    /// and largest local discrepancy vs Owen-Sobol + exact inverse CDF, + VNDF/cosine
    /// mixture, and per-condition optimization, overall and per metallic; instance
    /// diversity. Writes conditional.json, .csv, PNGs.
    Conditional,
    /// An environment map's product warps as priors (`--envmap MAP`): cap L2 at
    /// held-out normals of Owen-Sobol and of a shifted lattice through them, over
    /// Owen-Sobol through each normal's exact inverse CDF: tables by --grids and
    /// --sizes, the hierarchical warp by --levels; their state. Writes
    /// envmap-prior.json and envmap-prior.md.
    EnvmapPrior,
    /// The tabulated glTF metallic-roughness BRDF warp as a prior: cap L2 at
    /// held-out (roughness, θo, metallic) of Owen-Sobol and of a shifted lattice
    /// through it, over Owen-Sobol through each condition's exact inverse CDF, by
    /// --brdf-grids, --sizes and --spaces, beside the VNDF/cosine mixture; their
    /// state. Writes brdf-prior.json and brdf-prior.md.
    BrdfPrior,
}

/// Arguments of `build-tool eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// Which figure.
    #[arg(value_enum)]
    pub fig: FigArg,
    /// Output directory: figN.csv, figN.json, figN-TARGET-METRIC.png, cache/
    /// (conditional: conditional.json, conditional.csv, conditional-*.png).
    #[arg(long)]
    pub out: PathBuf,
    /// Largest N (sizes 4, 8, ..., max-n) [default: 4096, --quick: 64].
    #[arg(long)]
    pub max_n: Option<usize>,
    /// Reduced settings for a smoke run: N <= 64, 8 / 2 realizations, 200 / 100
    /// epochs, cheaper metrics.
    #[arg(long)]
    pub quick: bool,
    /// Realizations per N for baselines [default: 128, --quick: 8].
    #[arg(long)]
    pub realizations_baseline: Option<usize>,
    /// Realizations per N for ours [default: 16, --quick: 2].
    #[arg(long)]
    pub realizations_ours: Option<usize>,
    /// Epochs of our 2D optimizer [default: 1000, --quick: 200].
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Epochs of our direction optimizer [default: 5000, --quick: 100].
    #[arg(long)]
    pub direction_epochs: Option<usize>,
    /// Random caps of the cap star discrepancy search [default: 20000, --quick: 500]
    /// (each costs one cap measure: ~0.5 ms for the environment map).
    #[arg(long)]
    pub cap_star_caps: Option<usize>,
    /// Data directory with images/camera.png and envmaps/courtyard.hdr; panels whose
    /// file is missing are skipped with a note.
    #[arg(long, default_value = "../shared/data")]
    pub data: PathBuf,
    /// Run only this panel (repeatable; the CSV `target` column, e.g. `brdf` of
    /// fig6, `brdf-envmap` of fig7); the figure's files then hold only these.
    #[arg(long = "panel", value_name = "NAME")]
    pub panels: Vec<String>,
    /// conditional: the `.nuld` conditional blob whose table and network modes are
    /// judged. brdf-prior: also judge this baked BRDF sampler (`bake --brdf`) at
    /// the prior's conditions: table, network and unbiased mode, per metallic,
    /// the union of 64 instances, and the variance of f cos / pdf at metals
    /// against the VNDF/cosine mixture (the judge takes the blob's N).
    #[arg(long)]
    pub blob: Option<PathBuf>,
    /// conditional: judge independent Owen-Sobol sets warped by the VNDF/cosine
    /// mixture in place of a blob (a check of the report itself: ratio to the
    /// mixture about 1, union ratio about 1/sqrt(K), nearest-neighbour ratio about
    /// 0.65).
    #[arg(long, conflicts_with = "blob")]
    pub calibrate: bool,
    /// conditional: instances whose union and pairs measure diversity
    /// [default: 64, --quick: 16].
    #[arg(long, value_parser = super::count)]
    pub n_instances: Option<usize>,
    /// conditional: metallic values, each in [0, 1], crossed with the 25 held-out
    /// (roughness, θo) (--quick: 3 of them), each summarized on its own; direct
    /// optimization runs at 5 of them (--quick: 1) for metallic 0 and for 1 where
    /// listed. On 2 shared cores each value costs about 65 s, and 0 and 1 another
    /// 85 s each for direct optimization: the default about 6 min.
    #[arg(long, value_delimiter = ',', default_value = "0,0.5,1", value_parser = metallic_value)]
    pub metallic: Vec<f64>,
    /// conditional: points per set of the --calibrate sampler; envmap-prior:
    /// points per set.
    #[arg(long, default_value_t = 64, value_parser = super::count)]
    pub n: usize,
    /// envmap-prior: the environment map (PNG, JPEG, HDR or EXR; equirectangular).
    #[arg(long)]
    pub envmap: Option<PathBuf>,
    /// envmap-prior: normal grids, nodes per axis (each >= 2): the tables'
    /// normals, and the normals of the tree's exact top-level weights.
    #[arg(long, value_delimiter = ',', default_value = "9,13,17")]
    pub grids: Vec<u32>,
    /// envmap-prior, brdf-prior: table sizes, vertices per axis (each >= 2).
    #[arg(long, value_delimiter = ',', default_value = "32,64,128")]
    pub sizes: Vec<u32>,
    /// brdf-prior: condition grids RxTxM: roughness and θo nodes (2 to 64 each),
    /// and M = 2 (metallic 0 and 1) or 3 (and the metal layer, the metal again in
    /// its own square, read at metallic 1: the blob's).
    #[arg(long, value_delimiter = ',', default_value = "10x12x3", value_parser = condition_grid)]
    pub brdf_grids: Vec<[u32; 3]>,
    /// brdf-prior: table spaces, `direction` (the light direction's equal-area
    /// square), `half-vector` (the blob's prior: the half vector's, its slopes
    /// divided by roughness near the pole and roughness^(1/4) beyond 0.25, the
    /// radial square, the metal layer's on the star disc), `half-vector:P` (slopes
    /// divided by roughness^(P/100), the metal layer the blob's) and
    /// `radial:A_B_C_Q:A_B_C_Q` (shared square, metal layer: slopes stretched by
    /// roughness^(A/100) near the pole and roughness^(B/100) beyond the table
    /// slope C/100, the in-plane slope further by max(cos θo, 0.05)^(Q/100)), and
    /// for the metal layer on a disc whose rim is the horizon (the shared square
    /// the blob's): `horizon:C_Q_P` (the mirror direction moved to the disc's
    /// centre, zoom (C/100) alpha / cos^(P/100) θo) and `star:C_E_Q`, `starl:C_E_Q`
    /// (the disc drawn from the mirror direction in slopes or Lambert radii,
    /// zoom (C/100) roughness^(E/100); Q an anisotropy as radial's).
    #[arg(long, value_delimiter = ',', default_value = "direction,half-vector", value_parser = prior_space)]
    pub spaces: Vec<crate::sphere::brdf_prior::PriorSpace>,
    /// brdf-prior: held-out conditions judged (roughness 0.1 + 0.9 u^2, θo
    /// uniform in 0° to 85°, metallic 0, 0.5, 1 and uniform in turn; 16 cost
    /// about 10 s; more include smooth metals).
    #[arg(long, default_value_t = 16, value_parser = super::count)]
    pub conditions: usize,
    /// brdf-prior: sets averaged per condition and method (Owen-Sobol
    /// scrambles, lattice shifts, a blob's instances 0 to K-1; 1 to 64, and
    /// at most the instances a blob stores). More
    /// sets shrink the judge's own noise, which is largest at smooth grazing
    /// conditions, where one set's discrepancy varies most.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub sets: u32,
    /// envmap-prior: depths of the hierarchical product warp (`2^L` leaves per
    /// axis; each 3 to 12).
    #[arg(long, value_delimiter = ',', default_value = "8,9,10")]
    pub levels: Vec<u32>,
}

impl EvalArgs {
    /// The settings these arguments ask for.
    pub fn settings(&self) -> EvalSettings {
        let mut s = if self.quick {
            EvalSettings::quick(&self.out, &self.data)
        } else {
            EvalSettings::full(&self.out, &self.data)
        };
        if let Some(v) = self.max_n {
            s.max_n = v;
        }
        if let Some(v) = self.realizations_baseline {
            s.realizations_baseline = v;
        }
        if let Some(v) = self.realizations_ours {
            s.realizations_ours = v;
        }
        if let Some(v) = self.epochs {
            s.epochs = v;
        }
        if let Some(v) = self.direction_epochs {
            s.direction_epochs = v;
        }
        if let Some(v) = self.cap_star_caps {
            s.cap_star_caps = v;
        }
        s.only_panels.clone_from(&self.panels);
        s
    }
}

/// Runs `build-tool eval`.
pub fn run(a: EvalArgs) -> Result<()> {
    let figures: Vec<Figure> = match a.fig {
        FigArg::Fig2 => vec![Figure::Fig2],
        FigArg::Fig3 => vec![Figure::Fig3],
        FigArg::Fig5 => vec![Figure::Fig5],
        FigArg::Fig6 => vec![Figure::Fig6],
        FigArg::Fig7 => vec![Figure::Fig7],
        FigArg::All => Figure::ALL.to_vec(),
        FigArg::Conditional => return run_conditional(&a),
        FigArg::EnvmapPrior => return run_envmap_prior(&a),
        FigArg::BrdfPrior => return run_brdf_prior(&a),
    };
    let s = a.settings();
    s.validate()?;
    for f in figures {
        let started = Instant::now();
        let rep = run_figure(f, &s)?;
        print!("{}", rep.summary_markdown());
        eprintln!(
            "{f}: {} rows, {} panel(s){} in {:.1} s -> {}",
            rep.rows.len(),
            rep.panels.len(),
            if rep.skipped.is_empty() {
                String::new()
            } else {
                format!(" ({} skipped)", rep.skipped.len())
            },
            started.elapsed().as_secs_f64(),
            s.out.display()
        );
    }
    Ok(())
}

/// `build-tool eval conditional`: parses, evaluates, writes, prints the summary.
fn run_conditional(a: &EvalArgs) -> Result<()> {
    let mut s = if a.quick {
        ConditionalSettings::quick(&a.metallic)
    } else {
        ConditionalSettings::full(&a.metallic)
    };
    if let Some(k) = a.n_instances {
        s.union_instances = k;
    }
    if let Some(v) = a.cap_star_caps {
        s.cap_star_caps = v;
    }
    if let Some(v) = a.direction_epochs {
        s.direct_epochs = v;
    }
    anyhow::ensure!(
        a.blob.is_some() || a.calibrate,
        "eval conditional needs --blob FILE (or --calibrate)"
    );
    let started = Instant::now();
    let bytes;
    let calibration;
    let owned;
    let samplers: Vec<&dyn crate::lab::eval::conditional::ConditionalSets> = match &a.blob {
        Some(path) => {
            bytes = AlignedBytes::read(path)?;
            owned = blob_sets(bytes.as_slice())?;
            owned.iter().map(|b| b.as_ref()).collect()
        }
        None => {
            calibration = MixtureOwenSobol::new(a.n, s.seed ^ 0xCA11);
            vec![&calibration]
        }
    };
    let rep = evaluate(&samplers, &s)?;
    let files = rep.write(&a.out)?;
    print!("{}", rep.summary_markdown());
    eprintln!(
        "conditional: {} conditions, {} file(s) in {:.1} s -> {}",
        rep.conditions.len(),
        files.len(),
        started.elapsed().as_secs_f64(),
        a.out.display()
    );
    Ok(())
}

/// A metallic value: a number in `[0, 1]`.
fn metallic_value(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|m| (0.0..=1.0).contains(m))
        .ok_or_else(|| format!("{s:?} is not a metallic value: a number in [0, 1]"))
}

/// `RxTxM`: R and T in `2..=64`, M 2 or 3.
fn condition_grid(s: &str) -> Result<[u32; 3], String> {
    let bad = || {
        format!(
            "{s:?} is not a grid RxTxM: R and T in 2..=64, M 2 (metallic 0 and 1) or 3 (and the metal layer)"
        )
    };
    let v: Vec<u32> = s
        .split('x')
        .map(|p| p.trim().parse::<u32>().ok())
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    let grid: [u32; 3] = v.try_into().map_err(|_| bad())?;
    // A blob's grid (the metallic axis 2 or 3), at most 64 nodes per axis here.
    let blob_grid = nuld_core::brdf_prior::BrdfPriorInfo { grid, size: 2 }
        .nodes()
        .is_some();
    (blob_grid && grid[..2].iter().all(|&n| n <= 64))
        .then_some(grid)
        .ok_or_else(bad)
}

/// `direction`, `half-vector`, `half-vector:P`, `radial:A_B_C_Q:A_B_C_Q`,
/// `horizon:C_Q_P`, `star:C_E_Q` or `starl:C_E_Q`.
fn prior_space(s: &str) -> Result<crate::sphere::brdf_prior::PriorSpace, String> {
    crate::sphere::brdf_prior::PriorSpace::parse(s).ok_or_else(|| {
        format!(
            "{s:?} is not a table space: direction, half-vector, half-vector:P (P in 0..=400), \
             radial:A_B_C_Q:A_B_C_Q (each in 0..=400, C > 0), horizon:C_Q_P, star:C_E_Q or \
             starl:C_E_Q (C in 1..=10000, the others in 0..=400)"
        )
    })
}

/// `build-tool eval brdf-prior`: measures, writes, prints.
fn run_brdf_prior(a: &EvalArgs) -> Result<()> {
    use crate::lab::eval::brdf_prior::{evaluate, judging, markdown, BrdfPriorSettings};
    use crate::lab::eval::brdf_sampler;
    anyhow::ensure!(
        a.sizes.iter().all(|&v| v >= 2),
        "--sizes needs values of at least 2"
    );
    anyhow::ensure!(a.conditions >= 1, "--conditions needs at least 1");
    let blob = match &a.blob {
        Some(path) => Some(crate::pointset::AlignedBytes::read(path)?),
        None => None,
    };
    // A blob's judge takes its N, and its sets are the blob's stored instances
    // (table mode repeats them beyond `S`, which would count a set twice).
    let n = match &blob {
        Some(bytes) => {
            let info = *nuld_runtime::Blob::parse(bytes.as_slice())
                .and_then(|b| b.brdf())
                .map_err(|e| anyhow::anyhow!("{}: {e}", a.blob.as_ref().unwrap().display()))?
                .conditional()
                .info();
            anyhow::ensure!(
                a.sets <= info.instances,
                "--sets {} exceeds the {} instances the blob stores",
                a.sets,
                info.instances
            );
            info.n
        }
        None => u32::try_from(a.n).map_err(|_| anyhow::anyhow!("--n {} is too large", a.n))?,
    };
    let s = BrdfPriorSettings {
        grids: a.brdf_grids.clone(),
        sizes: a.sizes.clone(),
        spaces: a.spaces.clone(),
        n,
        conditions: a.conditions,
        instances: a.sets,
        ..BrdfPriorSettings::default()
    };
    crate::output::ensure_dir(&a.out)?;
    let started = Instant::now();
    let blob_steps = if blob.is_some() { 5 } else { 0 };
    let total = (s.conditions + s.spaces.len() * s.grids.len() * s.sizes.len() + blob_steps) as u64;
    let progress = crate::progress::Progress::stderr("brdf-prior", total, "step");
    let tell = |what: &str| {
        progress.set_message(what.to_string());
        progress.inc(1);
    };
    let (rows, judges) = evaluate(&s, &tell)?;
    let sampler = match &blob {
        Some(bytes) => Some(brdf_sampler::evaluate(
            bytes.as_slice(),
            &judges,
            &judging(&s),
            &tell,
        )?),
        None => None,
    };
    progress.finish();
    let mut table = markdown(&rows);
    if let Some(r) = &sampler {
        table += &brdf_sampler::markdown(r);
    }
    let json = serde_json::json!({ "settings": s, "rows": rows, "blob": sampler });
    write_prior_report(&a.out, "brdf-prior", &json, &table, rows.len(), started)
}

/// Writes `DIR/STEM.json` and `DIR/STEM.md` (the table, also printed) of a
/// prior's evaluation, and says how many configurations took how long.
fn write_prior_report(
    out: &std::path::Path,
    stem: &str,
    json: &serde_json::Value,
    table: &str,
    configurations: usize,
    started: Instant,
) -> Result<()> {
    let text = serde_json::to_string_pretty(json)?;
    crate::output::write_atomic(&out.join(format!("{stem}.json")), text.as_bytes())?;
    crate::output::write_atomic(&out.join(format!("{stem}.md")), table.as_bytes())?;
    print!("{table}");
    eprintln!(
        "{stem}: {configurations} configurations in {:.1} s -> {}",
        started.elapsed().as_secs_f64(),
        out.display()
    );
    Ok(())
}

/// `build-tool eval envmap-prior`: reads the map, measures, writes, prints.
fn run_envmap_prior(a: &EvalArgs) -> Result<()> {
    use crate::lab::eval::envmap_prior::{evaluate, markdown, PriorSettings};
    let path = a
        .envmap
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("eval envmap-prior needs --envmap MAP"))?;
    anyhow::ensure!(
        a.grids.iter().chain(&a.sizes).all(|&v| v >= 2),
        "--grids and --sizes need values of at least 2"
    );
    anyhow::ensure!(
        a.levels.iter().all(|&l| (3..=12).contains(&l)),
        "--levels needs values from 3 to 12"
    );
    let s = PriorSettings {
        grids: a.grids.clone(),
        sizes: a.sizes.clone(),
        levels: a.levels.clone(),
        n: u32::try_from(a.n).map_err(|_| anyhow::anyhow!("--n {} is too large", a.n))?,
        ..PriorSettings::default()
    };
    let map =
        crate::sphere::EnvmapDensity::from_file_filtered(path, nuld_core::blob::Domain::Sphere)?;
    crate::output::ensure_dir(&a.out)?;
    let started = Instant::now();
    let total = (s.normals + s.grids.len() * (s.sizes.len() + s.levels.len())) as u64;
    let progress = crate::progress::Progress::stderr("envmap-prior", total, "step");
    let rows = evaluate(&map, &s, &|what| {
        progress.set_message(what.to_string());
        progress.inc(1);
    })?;
    progress.finish();
    let json = serde_json::json!({
        "map": path.display().to_string(),
        "settings": s,
        "rows": rows,
    });
    write_prior_report(
        &a.out,
        "envmap-prior",
        &json,
        &markdown(&rows),
        rows.len(),
        started,
    )
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    /// `build-tool eval FIG --out x EXTRA...` parsed, or clap's message.
    fn eval_args(fig: &str, extra: &[&str]) -> Result<super::EvalArgs, String> {
        let args = ["build-tool", "eval", fig, "--out", "x"];
        match crate::cli::Cli::try_parse_from(args.iter().chain(extra)) {
            Ok(crate::cli::Cli {
                command: crate::cli::Command::Eval(a),
            }) => Ok(*a),
            Ok(_) => unreachable!("eval parses to Eval"),
            Err(e) => Err(e.to_string()),
        }
    }

    /// `--metallic` defaults to the report's `DEFAULT_METALLIC` and says why a
    /// value is refused.
    #[test]
    fn metallic_list_defaults_to_the_report_and_refuses_values_off_zero_one() {
        let parse = |extra: &[&str]| eval_args("conditional", extra).map(|a| a.metallic);
        use crate::lab::eval::conditional::DEFAULT_METALLIC;
        assert_eq!(parse(&[]).unwrap(), DEFAULT_METALLIC);
        assert_eq!(parse(&["--metallic", "1,0.25"]).unwrap(), [1.0, 0.25]);
        for bad in ["1.5", "-0.1", "NaN", "metal"] {
            let e = parse(&["--metallic", &format!("0,{bad}")]).unwrap_err();
            assert!(
                e.contains("is not a metallic value: a number in [0, 1]"),
                "{e}"
            );
        }
    }

    /// `--brdf-grids` defaults to the blob's prior grid (with the metal layer)
    /// and refuses a metallic axis other than 2 or 3 nodes, and short axes.
    #[test]
    fn brdf_grids_default_to_the_blobs_and_take_two_or_three_metallic_nodes() {
        let parse = |extra: &[&str]| eval_args("brdf-prior", extra).map(|a| a.brdf_grids);
        use crate::sphere::brdf_prior::PRIOR_GRID;
        assert_eq!(parse(&[]).unwrap(), [PRIOR_GRID]);
        assert_eq!(
            parse(&["--brdf-grids", "10x12x2,4x5x3"]).unwrap(),
            [[10, 12, 2], [4, 5, 3]]
        );
        for bad in ["10x12x4", "10x12x1", "1x12x2", "10x12", "10x65x2", "axbxc"] {
            let e = parse(&["--brdf-grids", bad]).unwrap_err();
            assert!(e.contains("is not a grid RxTxM"), "{bad}: {e}");
        }
    }

    /// `--conditions` (brdf-prior) defaults to the judge's 16, and a run with 0
    /// is refused before any work.
    #[test]
    fn brdf_prior_conditions_default_to_sixteen_and_refuse_zero() {
        let parse = |extra: &[&str]| eval_args("brdf-prior", extra).map(|a| a.conditions);
        let judge = crate::lab::eval::brdf_prior::BrdfPriorSettings::default();
        assert_eq!(parse(&[]).unwrap(), judge.conditions);
        assert_eq!(parse(&["--conditions", "48"]).unwrap(), 48);
        let out = std::env::temp_dir().join(format!("nuld-cond0-{}", std::process::id()));
        let args = [
            "build-tool",
            "eval",
            "brdf-prior",
            "--conditions",
            "0",
            "--out",
        ];
        let cli = crate::cli::Cli::try_parse_from(
            args.iter()
                .map(|a| a.to_string())
                .chain([out.display().to_string()]),
        )
        .unwrap();
        let e = crate::cli::run(cli).unwrap_err().to_string();
        assert!(e.contains("--conditions needs at least 1"), "{e}");
        assert!(!out.exists());
    }

    #[test]
    fn brdf_prior_sets_default_to_the_judges_and_stay_within_the_table() {
        let parse = |extra: &[&str]| eval_args("brdf-prior", extra).map(|a| a.sets);
        let judge = crate::lab::eval::brdf_prior::BrdfPriorSettings::default();
        assert_eq!(parse(&[]).unwrap(), judge.instances);
        assert_eq!(parse(&["--sets", "32"]).unwrap(), 32);
        assert!(parse(&["--sets", "0"]).is_err());
        assert!(parse(&["--sets", "65"]).is_err());
    }
}
