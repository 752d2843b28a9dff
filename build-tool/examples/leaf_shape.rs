//! What the shape inside the environment prior's leaves gives: `cargo run
//! --release -p nuld-build-tool --example leaf_shape -- MAP` (about 10 s a map).
//!
//! The prior's tree (the one the bake builds) draws a point inside its leaf by
//! the bilinear warp of the leaf's four corner values (`nuld_core::bilinear`;
//! the map's `L` at the corners, floored), where uniform leaves would leave
//! the point where the descent put it. At 64 normals spread over the sphere
//! (`z` from 1 down to -0.6), 200 000 random primary samples each, prints the
//! relative variance of `L cos / (E pdf)` (the single-sample irradiance
//! estimate over `E`, of mean one) for the tree with uniform leaves and for the
//! tree as baked. What is left is the leaves' probabilities' distance from
//! `L cos`, and the bilinear shape's from `L`.
//! Results: docs/results/rendering.md#fixed-instance-weight.
use glam::{DVec2, DVec3};
use nuld_build_tool::sphere::envmap_tree::{prior_levels, PRIOR_GRID};
use nuld_build_tool::sphere::{DirectionDensity, EnvmapDensity, EnvmapTree};
use nuld_core::blob::Domain;
use nuld_core::sphere::square_to_sphere;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: leaf_shape MAP");
        std::process::exit(2);
    };
    let map = EnvmapDensity::from_file_filtered(&path, Domain::Sphere).unwrap();
    let levels = prior_levels(&map);
    let tree = EnvmapTree::new(&map, levels, PRIOR_GRID).unwrap();
    let shaped = tree.tree();
    // No corners: the uniform leaves, bit for bit.
    let uniform = shaped.with_corners(&[]).unwrap();
    let l = |d: DVec3| map.pdf(d) * map.integral();
    let rows: Vec<[f64; 4]> = (0..64)
        .into_par_iter()
        .map(|k| {
            let z = 1.0 - (k as f64 + 0.5) / 64.0 * 1.6;
            let r = (1.0 - z * z).sqrt();
            let ph = 2.399963 * k as f64;
            let n = DVec3::new(r * ph.cos(), r * ph.sin(), z);
            let e = map.irradiance(n);
            let q = nuld_core::sphere::sphere_to_square(n).to_array();
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(k);
            let m = 200_000;
            let mut acc = [0.0; 4];
            for _ in 0..m {
                let u = [rng.random::<f64>(), rng.random::<f64>()];
                for (j, t) in [(0, &uniform), (2, &shaped)] {
                    // `L cos / (E pdf)` at the sample, pdf per unit square area.
                    let (p, pdf_sq, _) = t.sample_square_with_slopes(q, u);
                    let d = square_to_sphere(DVec2::from(p));
                    let ratio = if pdf_sq > 0.0 {
                        l(d) * n.dot(d).max(0.0) * 4.0 * std::f64::consts::PI / (e * pdf_sq)
                    } else {
                        0.0
                    };
                    acc[j] += ratio;
                    acc[j + 1] += ratio * ratio;
                }
            }
            acc.map(|a| a / m as f64)
        })
        .collect();
    let mean = |j: usize| rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
    let var =
        |j: usize| rows.iter().map(|r| r[j + 1] - r[j] * r[j]).sum::<f64>() / rows.len() as f64;
    println!(
        "{path}: uniform leaves: mean {:.4}, variance of L cos/(E pdf) {:.4}; shaped (as baked): mean {:.4}, variance {:.4}",
        mean(0),
        var(0),
        mean(2),
        var(2)
    );
}
