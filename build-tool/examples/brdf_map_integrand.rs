//! How the BRDF sampler's fixed sets integrate a real map through a lobe, beside
//! what the cap judge says of them: `cargo run --release -p nuld-build-tool
//! --example brdf_map_integrand -- BLOB MAP [INSTANCES] [CAPS] [OPTIMIZED|-]
//! [CONDITIONS]` (16 sets and 512 caps a scale by default; seconds).
//!
//! At the render scene's materials (`lab::render::scene`: the ground, dielectric
//! 0.8, at three views; spheres' roughnesses, dielectric and metal), or at
//! `CONDITIONS` (`roughness,view°,metallic` separated by `/`), every method's
//! `INSTANCES` sets of the blob's `N` directions, scored four ways, each over
//! Owen-Sobol through the exact inverse CDF of the condition's `q = f cos / A`:
//!
//! * **cap L2** (paper Eq. 9, centre uniform) over caps whose radius is uniform in
//!   `[0, R]`, `R` = 180° (the judge's measure), 45°, 15° and 5°
//!   ([`MeasuredCaps::draw_up_to`]); and over caps centred on the normal
//!   (**zonal**, radii evenly spread over 0° to 90°, [`MeasuredCaps::zonal`]);
//! * **map RMSE**: the error of `(1/N) sum_i L(R_j l_i)` against `2^16` Owen-Sobol
//!   points through the same exact warp, over the sets and 32 turns `R_j` of the
//!   map about the normal `z` (a ground pixel's estimate of its reflected light
//!   over `A`, as a fixed instance weighs it, with the map's own `+z` up);
//! * **beyond 60°**: points per set more than 60° from the normal, mean ± sd over
//!   the sets, against `N` times the target's mass there (a studio's lamps and
//!   a courtyard's bright walls sit in that band);
//! * **profile** (table mode and Owen-Sobol, every `N/16`-th point): where a
//!   set's points lie along the normal, the sorted target mass between the
//!   horizon and each point, mean over the sets, against the even `(k + 1/2) / N`;
//!   with `OPTIMIZED`, a `set.nuld` of directly optimized sets of the ground at
//!   50° (`build-tool optimize --domain hemisphere --density brdf:0.8,50 --n N
//!   --sets 16 --out DIR`), theirs at that condition too.
//!
//! Methods: the blob's table and network modes; its unbiased mode (instance `k`
//! with seed `k`); the render's baselines, Owen-Sobol, SOT and GBN as `render`
//! draws them per pixel (`lab::render::primary`: a scramble, or a pooled set
//! shifted toroidally), through the renderer's VNDF/cosine mixture as in the
//! render, and through the exact inverse CDF (Owen-Sobol's is the reference).
use glam::{DMat3, DVec2, DVec3};
use nuld_build_tool::baselines::seeded_owen_sobol;
use nuld_build_tool::lab::render::environment::Environment;
use nuld_build_tool::lab::render::primary::{Generator, PrimaryPoints};
use nuld_build_tool::lab::render::sampler::PixelKey;
use nuld_build_tool::sphere::metrics::{CapRadius, MeasuredCaps};
use nuld_build_tool::sphere::{BrdfTarget, DirectionDensity, TabulatedWarp};
use nuld_core::blob::Domain;
use rayon::prelude::*;
use std::f64::consts::TAU;

mod conditions;

/// `cos 60°`: the band of [`rim_counts`].
const RIM_COS: f64 = 0.5;

/// Radii `R` of the cap L2 columns, degrees.
const RADII_DEG: [f64; 4] = [180.0, 45.0, 15.0, 5.0];

/// Turns of the map about the normal.
const TURNS: usize = 32;

/// Root mean square cap L2 of the sets over `caps` (their squares averaged).
fn cap_l2(sets: &[Vec<DVec3>], caps: &MeasuredCaps) -> f64 {
    let squared = |set: &Vec<DVec3>| caps.l2_squared(set, CapRadius::ThetaUniform).0;
    (sets.iter().map(squared).sum::<f64>() / sets.len() as f64).sqrt()
}

/// Points beyond 60° from the normal: mean and standard deviation over the sets.
fn rim_counts(sets: &[Vec<DVec3>]) -> (f64, f64) {
    let counts: Vec<f64> = sets
        .iter()
        .map(|p| p.iter().filter(|l| l.z < RIM_COS).count() as f64)
        .collect();
    let m = counts.len() as f64;
    let mean = counts.iter().sum::<f64>() / m;
    let var = counts.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / m;
    (mean, var.sqrt())
}

/// `F(z)`: the target's mass at `cos θ < z` (from the horizon in), read off
/// `zs`, the sorted `cos θ` of a fine exact set.
fn mass_below(zs: &[f64], z: f64) -> f64 {
    zs.partition_point(|&v| v < z) as f64 / zs.len() as f64
}

/// The sets' profile along the normal: the `k`-th smallest [`mass_below`] of a
/// set's points, mean over the sets. An even profile is `(k + 1/2) / N`.
fn profile(sets: &[Vec<DVec3>], zs: &[f64]) -> Vec<f64> {
    let n = sets[0].len();
    let mut mean = vec![0.0; n];
    for set in sets {
        let mut f: Vec<f64> = set.iter().map(|l| mass_below(zs, l.z)).collect();
        f.sort_by(f64::total_cmp);
        for (m, v) in mean.iter_mut().zip(f) {
            *m += v / sets.len() as f64;
        }
    }
    mean
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(3..=7).contains(&args.len()) {
        eprintln!(
            "usage: brdf_map_integrand BLOB MAP [INSTANCES] [CAPS] [OPTIMIZED|-] [CONDITIONS]"
        );
        std::process::exit(2);
    }
    let map = Environment::from_file(std::path::Path::new(&args[2])).unwrap();
    let instances: u32 = args.get(3).map_or(16, |s| s.parse().unwrap());
    let count: usize = args.get(4).map_or(512, |s| s.parse().unwrap());
    let optimized_bytes = (args.get(5))
        .filter(|p| *p != "-")
        .map(|p| std::fs::read(p).unwrap());
    let optimized: Option<Vec<Vec<DVec3>>> = optimized_bytes.as_ref().map(|b| {
        let sets = nuld_runtime::Blob::parse(b)
            .unwrap()
            .direction_set()
            .unwrap();
        (0..sets.set_count())
            .map(|s| {
                (0..sets.len())
                    .map(|i| sets.direction(s, i).as_dvec3())
                    .collect()
            })
            .collect()
    });
    let bytes = std::fs::read(&args[1]).unwrap();
    let blob = nuld_runtime::Blob::parse(&bytes).unwrap();
    let cs = blob.brdf().unwrap().conditional();
    let n = cs.len() as usize;
    let conditions: Vec<[f64; 3]> = match args.get(6) {
        Some(list) => conditions::parse(list),
        None => vec![
            [0.8, 20.0, 0.0],
            [0.8, 50.0, 0.0],
            [0.8, 75.0, 0.0],
            [0.4, 45.0, 0.0],
            [0.1, 45.0, 0.0],
            [0.4, 45.0, 1.0],
            [0.1, 70.0, 1.0],
        ],
    };
    let generators: Vec<PrimaryPoints> = [Generator::OwenSobol, Generator::Sot, Generator::Gbn]
        .into_iter()
        .map(|g| PrimaryPoints::new(g, n as u32, 1))
        .collect();
    let turns: Vec<DMat3> = (0..TURNS)
        .map(|j| DMat3::from_rotation_z(TAU * (j as f64 + 0.5) / TURNS as f64))
        .collect();
    let mean_radiance = |dirs: &[DVec3], turn: &DMat3| {
        dirs.iter().map(|&l| map.radiance(*turn * l)).sum::<f64>() / dirs.len() as f64
    };
    println!(
        "N = {n}, {instances} sets a method, {count} caps a radius; {}; each over Owen-Sobol through the exact inverse CDF",
        args[2]
    );
    for [r, t, m] in conditions {
        let target = BrdfTarget::metallic(r, t, m, Domain::Hemisphere).unwrap();
        let exact = TabulatedWarp::new(&target, 1024, 2).unwrap();
        let c = nuld_runtime::glam::Vec2::new(r as f32, t as f32);
        let runtime = |f: &dyn Fn(u32, u32) -> nuld_runtime::Sample| -> Vec<Vec<DVec3>> {
            (0..instances)
                .map(|k| {
                    (0..n as u32)
                        .map(|i| f(k, i).direction.as_dvec3())
                        .collect()
                })
                .collect()
        };
        let by_exact = |u: &[DVec2]| exact.warp_all(u);
        let by_mixture = |u: &[DVec2]| u.iter().map(|&p| target.sample(p)).collect();
        // The render's own sets of a generator (per pixel key: Owen-Sobol's scramble,
        // a pooled SOT or GBN set shifted toroidally), through a warp.
        let pixels = |g: &PrimaryPoints, warp: &dyn Fn(&[DVec2]) -> Vec<DVec3>| {
            (0..instances as u64)
                .map(|k| warp(&g.points(PixelKey::new(1, k))))
                .collect::<Vec<_>>()
        };
        let mut methods: Vec<(String, Vec<Vec<DVec3>>)> = vec![
            ("owen-sobol".into(), pixels(&generators[0], &by_exact)),
            (
                "table".into(),
                runtime(&|k, i| cs.sample_metallic(c, m as f32, k, i)),
            ),
            (
                "network".into(),
                runtime(&|k, i| cs.network().sample_metallic(c, m as f32, k, i)),
            ),
            (
                "unbiased".into(),
                runtime(&|k, i| cs.sample_randomized_metallic(c, m as f32, k, i, k)),
            ),
        ];
        for g in &generators {
            let name = g.generator().name();
            methods.push((format!("{name}-mixture"), pixels(g, &by_mixture)));
        }
        for g in &generators[1..] {
            methods.push((g.generator().name().to_string(), pixels(g, &by_exact)));
        }

        let measure = |w: DVec3, t: f64| target.cap_measure(w, t);
        let l2: Vec<Vec<f64>> = RADII_DEG
            .iter()
            .enumerate()
            .map(|(s, &rd)| MeasuredCaps::draw_up_to(count, 7 + s as u64, rd.to_radians(), measure))
            .chain(std::iter::once(MeasuredCaps::zonal(
                DVec3::Z,
                count,
                std::f64::consts::FRAC_PI_2,
                measure,
            )))
            .map(|caps| {
                methods
                    .iter()
                    .map(|(_, sets)| cap_l2(sets, &caps))
                    .collect()
            })
            .collect();
        let fine = exact.warp_all(&seeded_owen_sobol(1 << 16, 99));
        let reference: Vec<f64> = turns.par_iter().map(|j| mean_radiance(&fine, j)).collect();
        let rmse: Vec<f64> = methods
            .iter()
            .map(|(_, sets)| {
                let squared: f64 = sets
                    .par_iter()
                    .map(|p| {
                        turns
                            .iter()
                            .zip(&reference)
                            .map(|(j, e)| (mean_radiance(p, j) - e).powi(2))
                            .sum::<f64>()
                    })
                    .sum();
                (squared / (sets.len() * TURNS) as f64).sqrt()
            })
            .collect();
        let mut zs: Vec<f64> = fine.iter().map(|l| l.z).collect();
        zs.sort_by(f64::total_cmp);
        let rim_target = n as f64 * mass_below(&zs, RIM_COS);

        println!("\n({r}, {t}°, metallic {m}): beyond 60° the target holds {rim_target:.2} points");
        let even: Vec<f64> = (0..n).map(|k| (k as f64 + 0.5) / n as f64).collect();
        let mut profiles = vec![
            ("even", even),
            ("table", profile(&methods[1].1, &zs)),
            ("owen-sobol", profile(&methods[0].1, &zs)),
        ];
        if let Some(sets) = optimized.as_ref().filter(|_| [r, t, m] == [0.8, 50.0, 0.0]) {
            profiles.push(("optimized", profile(sets, &zs)));
        }
        for (name, profile) in profiles {
            let stride = n.div_ceil(16);
            let cells: Vec<String> = profile
                .iter()
                .step_by(stride)
                .map(|f| format!("{f:.3}"))
                .collect();
            println!("  profile, {name:<10} {}", cells.join(" "));
        }
        let mut radii: Vec<String> = RADII_DEG.iter().map(|r| format!("L2 {r}°")).collect();
        radii.push("zonal".into());
        println!(
            "  {:<12} {}  map RMSE  beyond 60°",
            "method",
            radii.join("  ")
        );
        for (k, (name, sets)) in methods.iter().enumerate() {
            let cells: Vec<String> = l2
                .iter()
                .map(|row| format!("{:>7.3}", row[k] / row[0]))
                .collect();
            let (mean, sd) = rim_counts(sets);
            println!(
                "  {name:<12} {}  {:>8.3}  {mean:.2} ± {sd:.2}",
                cells.join("  "),
                rmse[k] / rmse[0]
            );
        }
    }
}
