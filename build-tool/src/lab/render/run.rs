//! `build-tool render`: the whole evaluation of paper Fig. 8 into one directory.
//!
//! Writes into `DIR`: `render.csv` ([`super::summary::CSV_HEADER`], one row per
//! technique, sampler, spp and seed; the RMSE over the image and over each
//! surface class), `render-summary.md` (equal-sample-count
//! and equal-time tables, means over the seeds with their standard errors),
//! `reference.png` and the cached `reference-KEY.bin`, `images/T-S-N.png`
//! (technique `T`, sampler `S`, `N` spp, the first seed; tone-mapped with the
//! reference's exposure), `errors/T-S-N.png` (absolute error against the
//! reference, white at twice Owen-Sobol's RMSE of the same technique and spp),
//! `fig8-T.png` per technique (and `-errors` twins: rows = samplers, columns =
//! spp), and the baked blobs `brdf-nN/` and `envmap-nN/` it needed. Every file is
//! written atomically.

use super::blobs::{BrdfBlobs, SamplerBlobs};
use super::brdf_warp::LobeTable;
use super::camera::Camera;
use super::environment::Environment;
use super::integrator::{Image, Primary, Setup};
use super::lineup;
use super::nuld_sampler::FixedWeight;
use super::picture::{error_map, exposure, tone_map, Picture};
use super::reference::Reference;
use super::sampler::Technique;
use super::scene::{Scene, SurfaceClass};
use super::summary::{csv, errors, errors_by_surface, markdown, Row};
use crate::conditional::bake::BakeConfig;
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render_composite, Composite, Tile};
use crate::progress::Progress;
use crate::seeding::content_hash;
use crate::sphere::envmap_tree::PRIOR_GRID;
use crate::train::{TrainConfig, TrainTarget};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Settings of a render.
#[derive(Clone, Debug)]
pub struct RenderConfig {
    /// The environment map (HDR, EXR, PNG).
    pub envmap: PathBuf,
    /// Samples per pixel, each in `1..=65536`.
    pub spp: Vec<u32>,
    /// Image size in pixels.
    pub width: u32,
    /// Image size in pixels.
    pub height: u32,
    /// Samples of each technique per pixel of the reference.
    pub reference_samples: u32,
    /// Given BRDF sampler blobs (one per set size).
    pub brdf_blobs: Vec<PathBuf>,
    /// Given environment sampler blobs of the map (one per set size).
    pub envmap_blobs: Vec<PathBuf>,
    /// How missing BRDF blobs are baked (`train.n` is set per sample count).
    pub bake: BakeConfig,
    /// How missing environment blobs are baked: these settings
    /// [`with_envmap`](BakeConfig::with_envmap) the render's map.
    pub envmap_bake: BakeConfig,
    /// Fixes the reference; the images are rendered at seeds `seed`,
    /// `seed + 1`, ..., `seed + seeds - 1` (pixel keys, pool sets).
    pub seed: u64,
    /// Renders per technique, sampler and spp (at least 1), each at its own seed.
    pub seeds: u32,
    /// What to render (BRDF sampling, environment sampling, MIS); a BRDF blob is
    /// needed only for BRDF sampling, an environment blob for the others.
    pub techniques: Vec<Technique>,
    /// How our environment sampler's fixed instances weigh their samples.
    pub fixed_weight: FixedWeight,
}

impl RenderConfig {
    /// The full evaluation: 320 x 240 pixels, 4/16/64/256 spp at 4 seeds, every
    /// technique, a reference of 4096 + 4096 samples per pixel, missing blobs
    /// baked with the defaults of `bake --brdf` and `bake --envmap`.
    pub fn full(envmap: PathBuf) -> Self {
        Self {
            envmap,
            spp: vec![4, 16, 64, 256],
            width: 320,
            height: 240,
            reference_samples: 4096,
            brdf_blobs: Vec::new(),
            envmap_blobs: Vec::new(),
            bake: BakeConfig::default(),
            envmap_bake: BakeConfig::envmap_sizes(),
            seed: 0,
            seeds: 4,
            techniques: Technique::ALL.to_vec(),
            fixed_weight: FixedWeight::default(),
        }
    }

    /// `--quick`, for tests: 32 x 24 pixels, 4/16 spp, a reference of 256 + 256
    /// samples per pixel, missing blobs baked in a few steps (a tiny network that
    /// is barely trained: it exercises the path, not the quality).
    pub fn quick(envmap: PathBuf) -> Self {
        let bake = BakeConfig {
            train: TrainConfig {
                hidden: vec![8],
                steps: 4,
                pretrain_steps: 4,
                conditions_per_step: 2,
                instances_per_condition: 2,
                pool_conditions: 4,
                pool_caps: 64,
                caps_per_step: 32,
                ..TrainConfig::default()
            },
            instances: 4,
            grid: [3, 3],
            weight_grid: [8, 8],
            quality_grid: 0,
            checkpoint_every: Duration::from_secs(3600),
            ..BakeConfig::default()
        };
        Self {
            spp: vec![4, 16],
            width: 32,
            height: 24,
            reference_samples: 256,
            seeds: 2,
            envmap_bake: bake.clone(),
            bake,
            ..Self::full(envmap)
        }
    }
}

/// What a render measured.
#[derive(Clone, Debug)]
pub struct RenderReport {
    /// One row per technique, sampler and spp (as in `render.csv`).
    pub rows: Vec<Row>,
    /// `render-summary.md`.
    pub summary: String,
    /// Seconds spent on the reference (0 when it came from the cache).
    pub reference_seconds: f64,
    /// Mean standard error of the reference over surface pixels.
    pub reference_stderr: f64,
    /// Seconds for everything.
    pub total_seconds: f64,
}

/// Runs the evaluation into `out` (see the module docs).
pub fn render(config: &RenderConfig, out: &Path) -> Result<RenderReport> {
    let started = Instant::now();
    if config.spp.is_empty() || config.spp.iter().any(|&n| !(1..=65536).contains(&n)) {
        bail!("--spp must list sample counts in 1..=65536, like 4,16,64,256");
    }
    if config.width == 0 || config.height == 0 || config.reference_samples < 2 {
        bail!("the image needs at least 1 x 1 pixels and the reference 2 samples");
    }
    if config.seeds == 0 || config.techniques.is_empty() {
        bail!("--seeds must be at least 1 and --techniques name at least one of brdf, envmap, mis");
    }
    let wants_brdf = config.techniques.contains(&Technique::Brdf);
    let wants_envmap = config.techniques.iter().any(|t| *t != Technique::Brdf);
    let wants_mis = config.techniques.contains(&Technique::Mis);
    let map_bytes = std::fs::read(&config.envmap)
        .with_context(|| format!("cannot read environment map {}", config.envmap.display()))?;
    let env = Environment::from_file(&config.envmap)?;
    let mut blobs = BrdfBlobs::read(&config.brdf_blobs)?;
    let mut envmap_blobs = SamplerBlobs::read_envmap(&config.envmap_blobs, &env)?;
    ensure_dir(out)?;
    ensure_dir(&out.join("images"))?;
    ensure_dir(&out.join("errors"))?;
    if wants_brdf {
        blobs.complete(&config.spp, out, &config.bake)?;
    }
    if wants_envmap {
        let map_target = TrainTarget::envmap_with_bytes(&config.envmap, &map_bytes);
        let envmap_template = config.envmap_bake.clone().with_envmap(map_target);
        envmap_blobs.complete(&config.spp, out, &envmap_template)?;
    }

    let scene = Scene::spheres_on_ground();
    let camera = Camera::evaluation(config.width, config.height);
    let setup = Setup {
        scene: &scene,
        camera: &camera,
        env: &env,
    };
    let lobes = LobeTable::new(&scene.materials());

    // The reference, cached by everything it depends on.
    let key = content_hash(
        format!(
            "reference v3 (product warp {} levels, {PRIOR_GRID} normals) {:016x} {scene:?} {camera:?} {} {}",
            env.product_levels(),
            content_hash(&map_bytes),
            config.reference_samples,
            config.seed
        )
        .as_bytes(),
    );
    let (w, h) = (config.width, config.height);
    let t = Instant::now();
    let (reference, reference_seconds) = match Reference::load(out, key, w, h)? {
        Some(r) => (r, 0.0),
        None => {
            let progress = Progress::stderr("render reference", h as u64, "row");
            let r = Reference::render(
                &setup,
                &lobes,
                config.reference_samples,
                config.seed,
                &|| progress.inc(1),
            );
            progress.finish();
            r.save(out, key)?;
            (r, t.elapsed().as_secs_f64())
        }
    };
    let classes = setup.per_pixel(
        || (),
        |_, x, y| match setup.primary(x, y) {
            Primary::Surface { position, at } => Some(SurfaceClass::of(position, &at.material)),
            Primary::Background(_) => None,
        },
        &|| {},
    );
    let mask: Vec<bool> = classes.iter().map(Option::is_some).collect();
    let surface = mask.iter().filter(|m| **m).count().max(1);
    let reference_stderr = reference
        .stderr
        .iter()
        .zip(&mask)
        .filter(|(_, m)| **m)
        .map(|(s, _)| s)
        .sum::<f64>()
        / surface as f64;
    let exposure = exposure(&reference.image);
    tone_map(&reference.image, exposure).write_png(&out.join("reference.png"))?;

    // MIS pairs ours for both halves where a BRDF blob serves the count: one
    // baked for BRDF sampling, or one given.
    if let Some(w) = mis_without_brdf(wants_mis, &config.spp, |n| blobs.get(n).is_some()) {
        eprintln!("warning: {w}");
    }
    let per_seed: usize = (config.spp.iter())
        .flat_map(|&n| {
            let brdf = blobs.get(n).is_some();
            (config.techniques.iter()).map(move |t| lineup::names(*t, brdf).len())
        })
        .sum();
    let progress = Progress::stderr(
        "render",
        (per_seed * config.seeds as usize) as u64 * h as u64,
        "row",
    );
    // Every seed's row; the first seed's image and tone-mapped picture.
    let mut rows: Vec<Row> = Vec::new();
    let mut shown: Vec<Row> = Vec::new();
    let mut images: Vec<Image> = Vec::new();
    let mut pictures: Vec<Picture> = Vec::new();
    for &n in &config.spp {
        let brdf = match wants_brdf {
            true => Some(
                blobs
                    .get(n)
                    .with_context(|| format!("no BRDF blob with N = {n}"))?,
            ),
            false => blobs.get(n),
        };
        let envmap = match wants_envmap {
            true => Some(
                envmap_blobs
                    .get(n)
                    .with_context(|| format!("no environment blob with N = {n}"))?,
            ),
            false => None,
        };
        for k in 0..config.seeds {
            let seed = config.seed.wrapping_add(k as u64);
            // Network mode's weights, decoded once per blob (as a renderer would).
            let mut weights = Default::default();
            let samplers = lineup::weighted_samplers(
                &config.techniques,
                [brdf.map(|(_, b)| b), envmap.map(|(_, b)| b)],
                config.fixed_weight,
                n,
                seed,
                &lobes,
                &env,
                &mut weights,
            )
            .with_context(|| {
                let paths: Vec<String> = [brdf, envmap]
                    .into_iter()
                    .flatten()
                    .map(|(p, _)| p.display().to_string())
                    .collect();
                format!("blobs {}", paths.join(" and "))
            })?;
            for sampler in &samplers {
                progress.set_context(format!(
                    "{} {} {n} spp, seed {seed}",
                    sampler.technique().name(),
                    sampler.name()
                ));
                let t = Instant::now();
                let image = setup.render(sampler.as_ref(), n, seed, &|| progress.inc(1));
                let seconds = t.elapsed().as_secs_f64();
                let (rmse, bias) = errors(&image, &reference.image, &mask);
                let by_surface = errors_by_surface(&image, &reference.image, &classes);
                let row = Row {
                    technique: sampler.technique().name().to_string(),
                    sampler: sampler.name().to_string(),
                    spp: n,
                    seed,
                    rmse,
                    bias,
                    seconds,
                    rmse_by_surface: by_surface.map(|(rmse, _)| rmse),
                    bias_by_surface: by_surface.map(|(_, bias)| bias),
                };
                if k == 0 {
                    let picture = tone_map(&image, exposure);
                    picture.write_png(&out.join("images").join(file_name(&row)))?;
                    shown.push(row.clone());
                    images.push(image);
                    pictures.push(picture);
                }
                rows.push(row);
            }
        }
    }
    progress.finish();

    // Error maps, white at twice Owen-Sobol's RMSE of the same technique and spp.
    let mut errors_of = Vec::new();
    for (row, image) in shown.iter().zip(&images) {
        let scale = shown
            .iter()
            .find(|r| r.technique == row.technique && r.spp == row.spp && r.sampler == "owen-sobol")
            .map_or(row.rmse, |r| r.rmse);
        let pic = error_map(image, &reference.image, 2.0 * scale.max(f64::MIN_POSITIVE));
        pic.write_png(&out.join("errors").join(file_name(row)))?;
        errors_of.push(pic);
    }
    for &technique in &config.techniques {
        for (suffix, pictures) in [("", &pictures), ("-errors", &errors_of)] {
            let composite = composite(technique, &config.spp, &shown, pictures, suffix);
            render_composite(
                &out.join(format!("fig8-{}{suffix}.png", technique.name())),
                &composite,
            )?;
        }
    }
    write_atomic(&out.join("render.csv"), csv(&rows).as_bytes())?;
    let reference_rms = (reference
        .stderr
        .iter()
        .zip(&mask)
        .filter(|(_, m)| **m)
        .map(|(s, _)| s * s)
        .sum::<f64>()
        / surface as f64)
        .sqrt();
    let summary = format!(
        "{}\n## The reference\n\n{} + {} samples per pixel (BRDF mixture and product warp, balance heuristic): standard error per pixel {:.3e} mean, {:.3e} root mean square (this much of every RMSE above is the reference's own noise, `RMSE² ≈ error² + {:.3e}²`); the standard error of its image mean, which any bias above shares, is at most {:.3e}.\n",
        markdown(&rows),
        config.reference_samples,
        config.reference_samples,
        reference_stderr,
        reference_rms,
        reference_rms,
        reference_rms / (surface as f64).sqrt(),
    );
    write_atomic(&out.join("render-summary.md"), summary.as_bytes())?;
    Ok(RenderReport {
        rows,
        summary,
        reference_seconds,
        reference_stderr,
        total_seconds: started.elapsed().as_secs_f64(),
    })
}

/// `T-S-N.png`.
fn file_name(row: &Row) -> String {
    format!("{}-{}-{}.png", row.technique, row.sampler, row.spp)
}

/// The warning that MIS leaves out ours for both halves at the counts of `spp`
/// where no BRDF blob serves (`has_blob` false); `None` when MIS is not
/// wanted or every count has one.
fn mis_without_brdf(
    wants_mis: bool,
    spp: &[u32],
    has_blob: impl Fn(u32) -> bool,
) -> Option<String> {
    if !wants_mis {
        return None;
    }
    let without: Vec<String> = (spp.iter())
        .filter(|&&n| !has_blob(n))
        .map(|n| n.to_string())
        .collect();
    (!without.is_empty()).then(|| {
        format!(
            "no BRDF blob at {} spp: mis leaves out ours for both halves (nuld-both-*) there; give --brdf-blob or add brdf to --techniques",
            without.join(", ")
        )
    })
}

/// The Fig. 8 grid of one technique: rows = its samplers, columns = `spp`;
/// `pictures[i]` shows `rows[i]`.
fn composite<'a>(
    technique: Technique,
    spp: &[u32],
    rows: &[Row],
    pictures: &'a [Picture],
    suffix: &str,
) -> Composite<'a> {
    // The rows rendered (MIS's of ours for both halves need a BRDF blob).
    let names: Vec<&str> = (lineup::names(technique, true).iter().copied())
        .filter(|name| {
            rows.iter()
                .any(|r| r.technique == technique.name() && r.sampler == *name)
        })
        .collect();
    let cells = names
        .iter()
        .map(|name| {
            spp.iter()
                .map(|&n| {
                    rows.iter()
                        .zip(pictures)
                        .find(|(r, _)| {
                            r.technique == technique.name() && r.sampler == *name && r.spp == n
                        })
                        .map(|(r, p)| Tile {
                            width: p.width,
                            height: p.height,
                            rgb: &p.rgb,
                            caption: format!("RMSE {:.3e}", r.rmse),
                        })
                })
                .collect()
        })
        .collect();
    let what = if suffix.is_empty() {
        "renders"
    } else {
        "absolute error (white = 2x owen-sobol RMSE)"
    };
    Composite {
        title: format!("{} sampling: {what}", technique.name()),
        row_labels: names.iter().map(|s| s.to_string()).collect(),
        column_labels: spp.iter().map(|n| format!("{n} spp")).collect(),
        cells,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::render::summary::CSV_HEADER;
    use crate::sphere::envmap::test_support::grey_map;

    /// `../shared/data/envmaps/courtyard.hdr` when present, else a generated sky
    /// written as PNG into `dir`.
    fn test_map(dir: &Path) -> PathBuf {
        let shared =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/envmaps/courtyard.hdr");
        if shared.is_file() {
            return shared;
        }
        eprintln!("skipped: {} (using a generated sky)", shared.display());
        grey_map(dir, "sky.png", [64, 32], |x, y| {
            if y == 5 && x == 9 {
                255
            } else if y < 16 {
                120 + 4 * y as u8
            } else {
                30
            }
        })
    }

    /// `render --quick` end to end, as CI runs it: every output file, the exact
    /// CSV header and one row per technique, sampler and spp; a second run reuses
    /// the cached reference and the baked blobs and reproduces every number.
    #[test]
    fn quick_render_writes_every_output_and_reproduces_itself() {
        let out = std::env::temp_dir().join(format!("nuld-render-quick-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        std::fs::create_dir_all(&out).unwrap();
        let config = RenderConfig::quick(test_map(&out));
        let first = render(&config, &out).unwrap();
        assert!(first.reference_seconds > 0.0);
        let csv_text = std::fs::read_to_string(out.join("render.csv")).unwrap();
        let mut lines = csv_text.lines();
        assert_eq!(lines.next(), Some(CSV_HEADER));
        assert_eq!(
            CSV_HEADER,
            "technique,sampler,spp,seed,rmse,bias,seconds,rmse_dielectric,rmse_metal,rmse_ground,\
             bias_dielectric,bias_metal,bias_ground"
        );
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        let per_seed: usize = (Technique::ALL.iter())
            .map(|t| lineup::names(*t, true).len())
            .sum();
        assert_eq!(rows.len(), per_seed * 2 * config.seeds as usize);
        for t in Technique::ALL {
            let technique = t.name();
            for name in lineup::names(t, true) {
                for spp in ["4", "16"] {
                    for seed in ["0", "1"] {
                        let row = rows
                            .iter()
                            .find(|r| {
                                r[0] == technique && r[1] == *name && r[2] == spp && r[3] == seed
                            })
                            .unwrap_or_else(|| panic!("no row {technique},{name},{spp},{seed}"));
                        let nums: Vec<f64> = row[4..].iter().map(|v| v.parse().unwrap()).collect();
                        assert!(
                            nums[0] > 0.0
                                && nums[0].is_finite()
                                && nums[1].is_finite()
                                && nums[2] >= 0.0,
                            "{row:?}"
                        );
                        // The scene shows every class; the image's mean square
                        // error is their pixel-weighted mean, so its RMSE lies
                        // between theirs (to the CSV's 7 digits).
                        let by_class = &nums[3..6];
                        let lo = by_class.iter().copied().fold(f64::INFINITY, f64::min);
                        let hi = by_class.iter().copied().fold(0.0, f64::max);
                        assert!(
                            lo > 0.0
                                && hi.is_finite()
                                && nums[0] >= lo * (1.0 - 1e-6)
                                && nums[0] <= hi * (1.0 + 1e-6),
                            "{row:?}"
                        );
                        // Likewise the image's bias, the pixel-weighted mean of
                        // the classes' biases (signed; the CSV's rounding apart).
                        let biases = &nums[6..9];
                        let lo = biases.iter().copied().fold(f64::INFINITY, f64::min);
                        let hi = biases.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                        let slack = 1e-6 * (lo.abs() + hi.abs());
                        assert!(
                            nums[1] >= lo - slack && nums[1] <= hi + slack && lo < hi,
                            "{row:?}"
                        );
                    }
                    for sub in ["images", "errors"] {
                        let f = out.join(sub).join(format!("{technique}-{name}-{spp}.png"));
                        assert!(f.is_file(), "{}", f.display());
                    }
                }
            }
        }
        for f in [
            "render-summary.md",
            "reference.png",
            "fig8-brdf.png",
            "fig8-envmap.png",
            "fig8-mis.png",
            "fig8-brdf-errors.png",
            "fig8-envmap-errors.png",
            "fig8-mis-errors.png",
            "brdf-n4/brdf.nuld",
            "brdf-n16/brdf.nuld",
        ] {
            assert!(out.join(f).is_file(), "{f}");
        }
        let png = image::open(out.join("images/brdf-owen-sobol-4.png")).unwrap();
        assert_eq!((png.width(), png.height()), (32, 24));
        let leftovers: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .filter(|n| n.contains(".tmp-"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");

        let second = render(&config, &out).unwrap();
        assert_eq!(second.reference_seconds, 0.0, "the reference is reused");
        for (a, b) in first.rows.iter().zip(&second.rows) {
            assert_eq!(
                (
                    a.rmse.to_bits(),
                    a.bias.to_bits(),
                    a.rmse_by_surface.map(f64::to_bits),
                    a.bias_by_surface.map(f64::to_bits)
                ),
                (
                    b.rmse.to_bits(),
                    b.bias.to_bits(),
                    b.rmse_by_surface.map(f64::to_bits),
                    b.bias_by_surface.map(f64::to_bits)
                ),
                "{}",
                a.sampler
            );
        }
        std::fs::remove_dir_all(&out).unwrap();
    }

    /// MIS without a BRDF blob at some counts says which, and nothing when
    /// every count has one or MIS is not wanted.
    #[test]
    fn mis_without_a_brdf_blob_is_a_warning_naming_the_counts() {
        let w = mis_without_brdf(true, &[16, 64, 256], |n| n == 64).unwrap();
        assert!(w.starts_with("no BRDF blob at 16, 256 spp: "), "{w}");
        assert!(
            w.contains("nuld-both-*") && w.contains("--brdf-blob"),
            "{w}"
        );
        assert_eq!(mis_without_brdf(true, &[16, 64], |_| true), None);
        assert_eq!(mis_without_brdf(false, &[16, 64], |_| false), None);
    }

    /// A blob `render` bakes is the one `bake --envmap` would: every setting equal.
    #[test]
    fn missing_environment_blobs_are_baked_with_the_bake_commands_defaults() {
        let target = TrainTarget::envmap_with_bytes(Path::new("sky.hdr"), b"sky");
        let config = RenderConfig::full(PathBuf::from("sky.hdr"));
        let render = config.envmap_bake.with_envmap(target.clone());
        let bake = BakeConfig::envmap(target);
        assert_eq!(
            serde_json::to_value(&render).unwrap(),
            serde_json::to_value(&bake).unwrap()
        );
    }

    #[test]
    fn bad_input_is_a_one_line_error_before_anything_is_written() {
        let out = std::env::temp_dir().join(format!("nuld-render-bad-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let missing = RenderConfig::quick(PathBuf::from("/nonexistent/map.hdr"));
        let e = format!("{:#}", render(&missing, &out).unwrap_err());
        assert!(
            e.contains("cannot read environment map /nonexistent/map.hdr") && !e.contains('\n'),
            "{e}"
        );
        for spp in [vec![], vec![0], vec![4, 70_000]] {
            let bad = RenderConfig {
                spp,
                ..RenderConfig::quick(PathBuf::from("x.hdr"))
            };
            assert!(format!("{:#}", render(&bad, &out).unwrap_err()).contains("--spp"));
        }
        assert!(!out.exists(), "nothing written for bad input");
    }
}
