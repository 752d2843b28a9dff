//! What the shape inside the environment prior's leaves gives: `cargo run
//! --release -p nuld-build-tool --example leaf_shape -- MAP [LEVELS]` (about
//! 10 s a map).
//!
//! The prior's tree (the one the bake builds, or one of `LEVELS` levels) draws a
//! point inside its leaf by the bilinear warp of the leaf's four corner values
//! (`nuld_core::bilinear`; the map's `L` at the corners, floored), and inside
//! the sharp leaves (around lamps and the sun) by the piecewise-constant warp of
//! the leaf's light on 16 x 16 cells (`nuld_core::cell_table`, the detail; 64 x
//! 64 in the few leaves that hold the most light, a sun's). At
//! 64 normals spread over the sphere (`z` from 1 down to -0.6), 200 000 random
//! primary samples each, prints the number of detailed leaves and the state's
//! size, then the relative variance of `L cos / (E pdf)` (the single-sample
//! irradiance estimate over `E`, of mean one) for the tree with the corners
//! alone (no detail), for the tree as baked, and for the map's own luminance
//! warp (`pdf ∝ L`, the exact inverse CDF of the filtered map's half pixels:
//! what renderers ship, blind to the cosine). What is left for the tree is the
//! leaves' probabilities' distance from `L cos`, and the shapes' from `L`; for
//! the luminance warp, the cosine and the samples below the normal's horizon.
//! A last line gives the tree whose leaves would follow their light exactly
//! inside them (`pdf = P(leaf) L / M(leaf)`, the estimate `cos M(leaf) / (E
//! P(leaf))` with the cosine read at the shaped sample, which is in the leaf):
//! the bound of pixel-exact leaves.
//! Results: docs/results/rendering.md#fixed-instance-weight, docs/results/envmap.md#clear-skies.
use glam::{DVec2, DVec3};
use nuld_build_tool::sphere::envmap_tree::{prior_levels, PRIOR_GRID};
use nuld_build_tool::sphere::geometry::spiral_normal;
use nuld_build_tool::sphere::{DirectionDensity, EnvmapDensity, EnvmapTree};
use nuld_core::blob::Domain;
use nuld_core::envmap_tree::node_index;
use nuld_core::quadtree::descend;
use nuld_core::sphere::square_to_sphere;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=3).contains(&args.len()) {
        eprintln!("usage: leaf_shape MAP [LEVELS]");
        std::process::exit(2);
    }
    let path = &args[1];
    let map = EnvmapDensity::from_file_filtered(path, Domain::Sphere).unwrap();
    let levels = args.get(2).map_or(prior_levels(&map), |s| {
        s.parse().expect("LEVELS: an integer")
    });
    let tree = EnvmapTree::new(&map, levels, PRIOR_GRID).unwrap();
    println!(
        "{} detailed leaves ({} of them fine) of {} ({:.1} MB of state)",
        tree.detail.len() / nuld_core::envmap_tree::DETAIL_LEN
            + tree.fine.len() / nuld_core::envmap_tree::FINE_LEN,
        tree.fine.len() / nuld_core::envmap_tree::FINE_LEN,
        1usize << (2 * levels),
        tree.state_bytes() as f64 / 1e6
    );
    let shaped = tree.tree();
    // No detail: the corners' bilinear shape in every leaf, bit for bit.
    let corners_only = shaped.with_detail(&[], &[]).unwrap();
    let l = |d: DVec3| map.pdf(d) * map.integral();
    let rows: Vec<[f64; 8]> = (0..64)
        .into_par_iter()
        .map(|k| {
            let n = spiral_normal(k as usize, 64);
            let e = map.irradiance(n);
            let q = nuld_core::sphere::sphere_to_square(n).to_array();
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(k);
            let m = 200_000;
            let mut acc = [0.0; 8];
            let lit = shaped.lit_square(q);
            for _ in 0..m {
                let u = [rng.random::<f64>(), rng.random::<f64>()];
                for (j, t) in [(0, &corners_only), (2, &shaped)] {
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
                // The luminance warp's `L cos / (E pdf)` is `cos ∫L / E`.
                let d = map.sample(DVec2::from(u));
                let ratio = n.dot(d).max(0.0) * map.integral() / e;
                acc[4] += ratio;
                acc[5] += ratio * ratio;
                // Leaves that followed their light exactly inside them (what
                // pixel-exact leaves would reach): `pdf = P(leaf) L / M(leaf)`, so
                // `L cos / (E pdf) = cos M(leaf) / (E P(leaf))`, the cosine read at a
                // point of the leaf (it hardly varies across one).
                let leaf = descend(&lit, u);
                let record = shaped.nodes()[node_index(levels, leaf.leaf[0], leaf.leaf[1])];
                let (p, _, _) = shaped.sample_square_with_slopes(q, u);
                let d = square_to_sphere(DVec2::from(p));
                let mass = record.mass() as f64 * map.integral();
                let ratio = n.dot(d).max(0.0) * mass / (e * leaf.share);
                acc[6] += ratio;
                acc[7] += ratio * ratio;
            }
            acc.map(|a| a / m as f64)
        })
        .collect();
    let mean = |j: usize| rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
    // Estimate `j`'s variance at one normal: its second moment less its mean squared.
    let var_at = |r: &[f64; 8], j: usize| r[j + 1] - r[j] * r[j];
    let var = |j: usize| rows.iter().map(|r| var_at(r, j)).sum::<f64>() / rows.len() as f64;
    // The normals where the luminance warp's (4) estimate is the less variable.
    let luminance_lower = |j: usize| rows.iter().filter(|r| var_at(r, 4) < var_at(r, j)).count();
    println!(
        "{path}, {levels} levels: corners only: mean {:.4}, variance of L cos/(E pdf) {:.4}; as baked (detail in sharp leaves): mean {:.4}, variance {:.4}; the luminance warp: mean {:.4}, variance {:.4}",
        mean(0),
        var(0),
        mean(2),
        var(2),
        mean(4),
        var(4)
    );
    // The mean hides where each wins: the luminance warp wastes the samples below
    // a normal's horizon, the tree none, but inside a light it follows `L` exactly.
    let lower = luminance_lower(2);
    let median = |j: usize| {
        let mut v: Vec<f64> = rows.iter().map(|r| var_at(r, j)).collect();
        v.sort_by(f64::total_cmp);
        let h = v.len() / 2;
        (v[h - 1] + v[h]) / 2.0
    };
    println!(
        "median variance: shaped {:.4}, luminance {:.4}; the luminance warp's is the lower at {lower} of 64 normals",
        median(2),
        median(4)
    );
    let exact_lower = luminance_lower(6);
    println!(
        "leaves exact inside: mean {:.4}, variance {:.4}, median {:.4}; the luminance warp's is the lower at {exact_lower} of 64 normals",
        mean(6),
        var(6),
        median(6)
    );
}
