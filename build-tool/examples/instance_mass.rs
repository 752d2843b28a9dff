//! Where a baked environment sampler's fixed instances put the light, against the
//! target they were trained towards and the prior they are warped through:
//! `cargo run --release -p nuld-build-tool --example instance_mass -- MAP BLOB [K]`.
//!
//! At 64 normals spread over the sphere (`z` from 1 down to -0.6), the light of
//! each normal, `E(n) = ∫ L max(0, n.l)`, is split into three parts: where `L`
//! exceeds `K` times its mean (default 10) above the horizon, the rest above it,
//! and below the horizon or on black pixels, where the target has none. Each part
//! is given, summed over the normals, for
//!
//! * `q`, the target `L cos / E`: a midpoint rule of `L cos` on `2048^2` points of
//!   the sphere's equal-area square;
//! * the prior: `E` times the runtime's pdf (`EnvmapSampler::pdf`) integrated
//!   over the part by the same rule on `1024^2` points;
//! * the union of the 64 table instances and of the 64 network instances: `E`
//!   times the share of their `64 N` points in the part.
//!
//! A renderer that weighs a fixed instance by `q` (`E f / L`) is biased by the
//! union's distance from `q`; one that weighs by the pdf, by its distance from
//! the prior. Results: docs/results/rendering.md#fixed-instance-weight.
use glam::{DVec2, DVec3, Vec3};
use nuld_build_tool::pointset::AlignedBytes;
use nuld_build_tool::sphere::{DirectionDensity, EnvmapDensity};
use nuld_core::blob::Domain;
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Points per axis of the target's rule and of the prior's.
const TARGET_RULE: usize = 2048;
const PRIOR_RULE: usize = 1024;

/// The midpoint rule's directions on `m x m` points of the equal-area square.
fn rule(m: usize) -> Vec<DVec3> {
    (0..m * m)
        .map(|k| {
            let u = DVec2::new(
                ((k % m) as f64 + 0.5) / m as f64,
                ((k / m) as f64 + 0.5) / m as f64,
            );
            square_to_sphere(u)
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(3..=4).contains(&args.len()) {
        eprintln!("usage: instance_mass MAP BLOB [K]");
        std::process::exit(2);
    }
    let map = EnvmapDensity::from_file_filtered(&args[1], Domain::Sphere).unwrap();
    let bytes = AlignedBytes::read(std::path::Path::new(&args[2])).unwrap();
    let env = nuld_runtime::Blob::parse(bytes.as_slice())
        .unwrap()
        .envmap()
        .unwrap();
    let k: f64 = args.get(3).map_or(10.0, |a| a.parse().unwrap());
    let radiance = |d: DVec3| map.pdf(d) * map.integral();
    let bright = k * map.integral() / (4.0 * PI);
    // The part of direction `d` for normal `n`: 0 bright, 1 the rest, 2 unlit.
    let part = |n: DVec3, d: DVec3, l: f64| match (n.dot(d) > 0.0 && l > 0.0, l > bright) {
        (false, _) => 2,
        (true, true) => 0,
        (true, false) => 1,
    };
    let target_rule: Vec<(DVec3, f64)> = rule(TARGET_RULE)
        .into_par_iter()
        .map(|d| (d, radiance(d)))
        .collect();
    let prior_rule: Vec<(DVec3, f64)> = rule(PRIOR_RULE)
        .into_par_iter()
        .map(|d| (d, radiance(d)))
        .collect();
    let normals: Vec<DVec3> = (0..64)
        .map(|i| {
            let z = 1.0 - (i as f64 + 0.5) / 64.0 * 1.6;
            let (r, phi) = ((1.0 - z * z).sqrt(), PI * (3.0 - 5f64.sqrt()) * i as f64);
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    // Per normal: [q, prior, table, network] x 3 parts.
    let rows: Vec<[[f64; 3]; 4]> = normals
        .par_iter()
        .map(|&n| {
            let nf = Vec3::new(n.x as f32, n.y as f32, n.z as f32);
            let mut out = [[0.0; 3]; 4];
            let cell = 4.0 * PI / (TARGET_RULE * TARGET_RULE) as f64;
            for &(d, l) in &target_rule {
                out[0][part(n, d, l)] += l * n.dot(d).max(0.0) * cell;
            }
            let e: f64 = out[0].iter().sum();
            let cell = 4.0 * PI / (PRIOR_RULE * PRIOR_RULE) as f64;
            let mut prior = [0.0; 3];
            for &(d, l) in &prior_rule {
                prior[part(n, d, l)] += env.pdf(nf, d.as_vec3()) as f64 * cell;
            }
            let total: f64 = prior.iter().sum();
            out[1] = prior.map(|p| e * p / total);
            let points = (64 * env.len()) as f64;
            for instance in 0..64 {
                for i in 0..env.len() {
                    for (row, s) in [
                        (2, env.sample(nf, instance, i)),
                        (3, env.network().sample(nf, instance, i)),
                    ] {
                        let d = s.direction.as_dvec3();
                        out[row][part(n, d, radiance(d))] += e / points;
                    }
                }
            }
            out
        })
        .collect();
    let mut sums = [[0.0; 3]; 4];
    for r in &rows {
        for (s, v) in sums.iter_mut().zip(r) {
            for p in 0..3 {
                s[p] += v[p];
            }
        }
    }
    let total: f64 = sums[0].iter().sum();
    println!(
        "{} ({} points a set), 64 normals, light {total:.4} (irradiance summed over the normals)",
        args[2],
        env.len()
    );
    println!("part | target q | prior | union of table instances | union of network instances");
    let labels = [
        format!("L > {k} x mean, above the horizon"),
        "the rest above the horizon".to_string(),
        "below the horizon or unlit".to_string(),
    ];
    for (p, label) in labels.iter().enumerate() {
        let rel = |v: f64| {
            if sums[0][p] > 0.0 {
                format!("{v:.4} ({:+.2} %)", 100.0 * (v / sums[0][p] - 1.0))
            } else {
                format!("{v:.4} ({:.2} % of the light)", 100.0 * v / total)
            }
        };
        println!(
            "{label} | {:.4} | {} | {} | {}",
            sums[0][p],
            rel(sums[1][p]),
            rel(sums[2][p]),
            rel(sums[3][p])
        );
    }
}
