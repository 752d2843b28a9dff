//! What a shape inside the environment prior's leaves would give: `cargo run
//! --release -p nuld-build-tool --example leaf_shape -- MAP` (about 10 s a map).
//!
//! The prior (the tree the bake builds) is uniform inside each leaf, while the
//! map's light is not. At 64 normals spread over the sphere (`z` from 1 down to
//! -0.6), 200 000 random primary samples each, prints the relative variance of
//! `L cos / (E pdf)` (the single-sample irradiance estimate over `E`, of mean
//! one) for the prior as it is, and for the prior with a bilinear shape inside
//! each leaf: the leaf's probability unchanged, the point inside it drawn by
//! the bilinear warp of the map's `L` at the leaf's four corners (pbrt-v4's
//! `SampleBilinear`), the pdf times that warp's density. What is left is the
//! leaves' probabilities' distance from `L cos`, and the bilinear shape's from `L`.
//! Results: docs/results/rendering.md#fixed-instance-weight.
use glam::{DVec2, DVec3};
use nuld_build_tool::sphere::envmap_tree::{prior_levels, PRIOR_GRID};
use nuld_build_tool::sphere::{DirectionDensity, EnvmapDensity, EnvmapTree};
use nuld_core::blob::Domain;
use nuld_core::sphere::square_to_sphere;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

/// pbrt-v4's `SampleLinear`: the inverse CDF of the density on `[0, 1]`
/// proportional to `a + (b - a) x`.
fn sample_linear(u: f64, a: f64, b: f64) -> f64 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + (a * a + u * (b * b - a * a)).max(0.0).sqrt());
    x.min(1.0 - 1e-12)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let map = EnvmapDensity::from_file_filtered(&args[1], Domain::Sphere).unwrap();
    let levels = prior_levels(&map);
    let tree = EnvmapTree::new(&map, levels, PRIOR_GRID).unwrap();
    let core = tree.tree();
    let side = (1u64 << levels) as f64;
    let l = |d: DVec3| map.pdf(d) * map.integral();
    // `L` at the leaves' corners, `(2^L + 1)^2` values, read once: a sample
    // reads four.
    let row = (1usize << levels) + 1;
    let corners: Vec<f64> = (0..row * row)
        .into_par_iter()
        .map(|k| {
            let (x, y) = ((k % row) as f64, (k / row) as f64);
            l(square_to_sphere(DVec2::new(x / side, y / side)))
        })
        .collect();
    let corner = |x: f64, y: f64| corners[y as usize * row + x as usize];
    let rows: Vec<[f64; 4]> = (0..64)
        .into_par_iter()
        .map(|k| {
            let z = 1.0 - (k as f64 + 0.5) / 64.0 * 1.6;
            let r = (1.0 - z * z).sqrt();
            let ph = 2.399963 * k as f64;
            let n = DVec3::new(r * ph.cos(), r * ph.sin(), z);
            let e = map.irradiance(n);
            let q = nuld_core::sphere::sphere_to_square(n);
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(k);
            let m = 200_000;
            let mut acc = [0.0; 4];
            // `L cos / (E pdf)` at square point `p` of square density `pdf_sq`.
            let ratio_at = |p: DVec2, pdf_sq: f64| {
                let d = square_to_sphere(p);
                if pdf_sq > 0.0 {
                    l(d) * n.dot(d).max(0.0) * 4.0 * std::f64::consts::PI / (e * pdf_sq)
                } else {
                    0.0
                }
            };
            for _ in 0..m {
                let u = [rng.random::<f64>(), rng.random::<f64>()];
                let (p, pdf_sq, _) = core.sample_square_with_slopes(q.to_array(), u);
                let ratio = ratio_at(DVec2::from(p), pdf_sq);
                acc[0] += ratio;
                acc[1] += ratio * ratio;
                // Bilinear inside the leaf.
                let (lx, ly) = (
                    (p[0] * side).floor().min(side - 1.0),
                    (p[1] * side).floor().min(side - 1.0),
                );
                let (ux, uy) = (p[0] * side - lx, p[1] * side - ly);
                let w = [
                    corner(lx, ly),
                    corner(lx + 1.0, ly),
                    corner(lx, ly + 1.0),
                    corner(lx + 1.0, ly + 1.0),
                ];
                let mean = w.iter().sum::<f64>() / 4.0;
                let (x, y, local) = if mean > 0.0 {
                    let x = sample_linear(ux, w[0] + w[2], w[1] + w[3]);
                    let y = sample_linear(uy, w[0] + (w[1] - w[0]) * x, w[2] + (w[3] - w[2]) * x);
                    let b = (1.0 - x) * (1.0 - y) * w[0]
                        + x * (1.0 - y) * w[1]
                        + (1.0 - x) * y * w[2]
                        + x * y * w[3];
                    (x, y, b / mean)
                } else {
                    (ux, uy, 1.0)
                };
                let p2 = DVec2::new((lx + x) / side, (ly + y) / side);
                let ratio2 = ratio_at(p2, pdf_sq * local);
                acc[2] += ratio2;
                acc[3] += ratio2 * ratio2;
            }
            acc.map(|a| a / m as f64)
        })
        .collect();
    let mean = |j: usize| rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
    let var =
        |j: usize| rows.iter().map(|r| r[j + 1] - r[j] * r[j]).sum::<f64>() / rows.len() as f64;
    println!("{}: uniform in leaves: mean {:.4}, variance of L cos/(E pdf) {:.4}; bilinear: mean {:.4}, variance {:.4}", args[1], mean(0), var(0), mean(2), var(2));
}
