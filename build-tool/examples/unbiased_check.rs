//! The unbiased mode of a baked environment sampler, checked on its own map:
//! `cargo run --release -p nuld-build-tool --example unbiased_check -- MAP BLOB`.
//!
//! At two normals, over 4096 pixels (each its own instance and `seed`), the mean
//! of the pixel estimates `(1/N) Σ g(l_i) / pdf_i` of `EnvmapSampler::
//! sample_randomized` (table and network mode, through the runtime) against an
//! independent midpoint quadrature of `∫ g` on 4096^2 points of the sphere, for
//! `g = L cos` and `g = L cos f` (`f` the glTF BRDF at roughness 0.3, the view
//! 40° from the normal); prints the difference in standard errors of the mean.
use glam::{DVec2, DVec3, Vec3};
use nuld_build_tool::pointset::AlignedBytes;
use nuld_build_tool::sphere::{DirectionDensity, EnvmapDensity};
use nuld_core::blob::Domain;
use rayon::prelude::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        eprintln!("usage: unbiased_check MAP BLOB");
        std::process::exit(2);
    }
    let map = EnvmapDensity::from_file_filtered(&args[1], Domain::Sphere).unwrap();
    let bytes = AlignedBytes::read(std::path::Path::new(&args[2])).unwrap();
    let env = nuld_runtime::Blob::parse(bytes.as_slice())
        .unwrap()
        .envmap()
        .unwrap();
    for n in [
        DVec3::new(0.3, -0.4, 0.85).normalize(),
        DVec3::new(-0.6, 0.5, 0.2).normalize(),
    ] {
        let q = nuld_core::sphere::sphere_to_square(n).as_vec2().to_array();
        let normal = DVec3::from_array(nuld_core::sphere::square_to_sphere_real(q).map(f64::from));
        let t = normal.any_orthonormal_vector();
        let b = normal.cross(t);
        let wo_w = (40f64.to_radians().sin() * t + 40f64.to_radians().cos() * normal).normalize();
        let local = |d: DVec3| DVec3::new(d.dot(t), d.dot(b), d.dot(normal));
        let wo = local(wo_w);
        let light = |d: DVec3| map.pdf(d) * map.integral();
        let g1 = |d: DVec3| light(d) * normal.dot(d).max(0.0);
        let g2 = |d: DVec3| {
            if normal.dot(d) <= 0.0 {
                0.0
            } else {
                light(d) * nuld_core::brdf::BrdfModel::Gltf.cosine_weighted(wo, local(d), 0.3)
            }
        };
        let quad = |g: &(dyn Fn(DVec3) -> f64 + Sync)| {
            let m = 4096usize;
            let s: f64 = (0..m * m)
                .into_par_iter()
                .map(|k| {
                    g(nuld_core::sphere::square_to_sphere(DVec2::new(
                        ((k % m) as f64 + 0.5) / m as f64,
                        ((k / m) as f64 + 0.5) / m as f64,
                    )))
                })
                .sum();
            s * 4.0 * std::f64::consts::PI / (m * m) as f64
        };
        let nv = Vec3::new(normal.x as f32, normal.y as f32, normal.z as f32);
        for (name, g) in [
            ("L cos", &g1 as &(dyn Fn(DVec3) -> f64 + Sync)),
            ("L cos f", &g2),
        ] {
            let want = quad(g);
            for mode in ["table", "network"] {
                let est: Vec<f64> = (0..4096u32)
                    .into_par_iter()
                    .map(|seed| {
                        (0..env.len())
                            .map(|i| {
                                let s = if mode == "table" {
                                    env.sample_randomized(
                                        nv,
                                        seed,
                                        i,
                                        seed.wrapping_mul(2654435761),
                                    )
                                } else {
                                    env.network().sample_randomized(
                                        nv,
                                        seed,
                                        i,
                                        seed.wrapping_mul(2654435761),
                                    )
                                };
                                if s.pdf > 0.0 {
                                    g(s.direction.as_dvec3()) / s.pdf as f64
                                } else {
                                    0.0
                                }
                            })
                            .sum::<f64>()
                            / env.len() as f64
                    })
                    .collect();
                let mean = est.iter().sum::<f64>() / est.len() as f64;
                let var =
                    est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (est.len() - 1) as f64;
                let se = (var / est.len() as f64).sqrt();
                println!("normal {normal:.3} {name} {mode}: mean {mean:.6} quadrature {want:.6} diff {:.2} se", (mean - want) / se);
            }
        }
    }
}
