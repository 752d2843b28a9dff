//! How evenly a warp's low-discrepancy points fill the part of primary space
//! that maps to a light: `cargo run --release -p nuld-build-tool --example
//! primary_strata -- MAP [SHARE]` (about a minute a map on 2 cores).
//!
//! At four normals (the zenith, the ground's normal, and three tilted), the
//! irradiance estimate `(1/N) Σ L cos / pdf` over `R = 1024` randomizations,
//! for `N` = 16, 64 and 256, through the environment prior's tree (the bake's,
//! `L cos` at the normal) and through the map's luminance warp (`pdf ∝ L`,
//! what renderers ship), each fed by a randomly shifted rank-1 lattice (the
//! unbiased mode's points, the bake's generator) and by Owen-scrambled Sobol.
//! Prints the relative RMSE over `E`, then the same for the light alone (the
//! pixels brighter than `SHARE`, default 50, times the map's mean; a sun's or a
//! lamp's), and the count of the points that land there: its RMSE about its
//! expectation `N P(light)`, in points. With the points' values nearly constant
//! over a light, the light's part of the error is that count's error: how
//! evenly the points fill the light's part of primary space, whose shape the
//! warp decides (a few bands through the luminance warp's rows and columns;
//! pieces cut at every level of the tree's descent).
//! Results: docs/results/envmap.md#primary-strata.
use glam::{DVec2, DVec3};
use nuld_build_tool::baselines::owen_sobol;
use nuld_build_tool::sphere::envmap_tree::{prior_levels, PRIOR_GRID};
use nuld_build_tool::sphere::{DirectionDensity, EnvmapDensity, EnvmapTree};
use nuld_build_tool::train::lattice_generator;
use nuld_core::blob::Domain;
use nuld_core::network::{hash_u32, lattice_point};
use nuld_core::sphere::{sphere_to_square, square_to_sphere};
use rayon::prelude::*;

/// Randomizations per figure.
const R: u32 = 1024;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=3).contains(&args.len()) {
        eprintln!("usage: primary_strata MAP [SHARE]");
        std::process::exit(2);
    }
    let map = EnvmapDensity::from_file_filtered(&args[1], Domain::Sphere).unwrap();
    let share: f64 = args
        .get(2)
        .map_or(50.0, |s| s.parse().expect("SHARE: a number"));
    let levels = prior_levels(&map);
    let tree = EnvmapTree::new(&map, levels, PRIOR_GRID).unwrap();
    let shaped = tree.tree();
    let mean_l = map.integral() / (4.0 * std::f64::consts::PI);
    let l = |d: DVec3| map.pdf(d) * map.integral();
    let in_light = |d: DVec3| l(d) > share * mean_l;
    println!("{}: the light is L > {share} x the mean", args[1]);
    println!("normal, N, sampler: relative RMSE of E (all; the light's part); light count RMSE about its expectation (points)");
    for n in [
        DVec3::Z,
        DVec3::new(0.3, -0.4, 0.85).normalize(),
        DVec3::new(-0.6, 0.5, 0.2).normalize(),
        DVec3::new(0.7, 0.1, -0.3).normalize(),
    ] {
        let q = sphere_to_square(n).to_array();
        // The exact values by a midpoint quadrature of the equal-area square.
        let m = 2048usize;
        let (e, e_light) = (0..m * m)
            .into_par_iter()
            .map(|k| {
                let d = square_to_sphere(DVec2::new(
                    ((k % m) as f64 + 0.5) / m as f64,
                    ((k / m) as f64 + 0.5) / m as f64,
                ));
                let g = l(d) * n.dot(d).max(0.0);
                (g, if in_light(d) { g } else { 0.0 })
            })
            .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        let area = 4.0 * std::f64::consts::PI / (m * m) as f64;
        let (e, e_light) = (e * area, e_light * area);
        for count in [16u32, 64, 256] {
            let g = lattice_generator(count);
            for (warp, gen) in [
                ("tree", "lattice"),
                ("tree", "owen-sobol"),
                ("luminance", "lattice"),
                ("luminance", "owen-sobol"),
            ] {
                // Per randomization: the estimate of E, of the light's part, and
                // the light's count (its expectation `N P(light)` is its mean).
                let runs: Vec<[f64; 3]> = (0..R)
                    .into_par_iter()
                    .map(|r| {
                        let seed = hash_u32(r ^ 0x9e37_79b9);
                        let shift = [hash_u32(seed) as f64, hash_u32(seed ^ 0x5bd1_e995) as f64]
                            .map(|h| h / 4_294_967_296.0);
                        let points: Vec<[f64; 2]> = if gen == "lattice" {
                            (0..count)
                                .map(|i| {
                                    let p = lattice_point::<f64>(i, count, g);
                                    [0, 1].map(|a| (p[a] + shift[a]).fract())
                                })
                                .collect()
                        } else {
                            owen_sobol(count as usize, seed)
                                .iter()
                                .map(|p| p.to_array())
                                .collect()
                        };
                        let mut acc = [0.0; 3];
                        for u in points {
                            let (d, pdf) = if warp == "tree" {
                                let (p, pdf_sq, _) = shaped.sample_square_with_slopes(q, u);
                                (
                                    square_to_sphere(DVec2::from(p)),
                                    pdf_sq / (4.0 * std::f64::consts::PI),
                                )
                            } else {
                                let d = map.sample(DVec2::from(u));
                                (d, map.pdf(d))
                            };
                            let v = if pdf > 0.0 {
                                l(d) * n.dot(d).max(0.0) / pdf
                            } else {
                                0.0
                            };
                            acc[0] += v;
                            if in_light(d) {
                                acc[1] += v;
                                acc[2] += 1.0;
                            }
                        }
                        [acc[0] / count as f64, acc[1] / count as f64, acc[2]]
                    })
                    .collect();
                // Every sampler here is unbiased, so its RMSE is its deviation
                // about its own mean (the quadrature cuts a small light's edge
                // too coarsely to be the reference for these figures).
                let mean = |k: usize| runs.iter().map(|x| x[k]).sum::<f64>() / R as f64;
                let sd = |k: usize| {
                    let m = mean(k);
                    (runs.iter().map(|x| (x[k] - m).powi(2)).sum::<f64>() / (R - 1) as f64).sqrt()
                };
                println!(
                    "({:+.2},{:+.2},{:+.2}), {count:3}, {gen:>10} through {warp:>9}: {:.4} ({:.4}); light count {:.2} about {:.2}; mean over the quadrature {:.4} (the light's part {:.3})",
                    n.x,
                    n.y,
                    n.z,
                    sd(0) / e,
                    sd(1) / e,
                    sd(2),
                    mean(2),
                    mean(0) / e,
                    mean(1) / e_light.max(f64::MIN_POSITIVE)
                );
            }
        }
    }
}
