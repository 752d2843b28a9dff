//! Where the environment prior's leaf probabilities leave `L cos`, level by
//! level, for top tables of 3, 4 and 5 levels: `cargo run --release -p
//! nuld-build-tool --example tree_misfit -- MAP` (about a minute a map on 2
//! cores).
//!
//! The tree as the bake builds it, its top table tabulated again for each
//! depth `T` (`envmap_tree::top_table`; the bake writes
//! `TOP_LEVELS`). At 64 normals spread over the sphere (`z` from 1 down to
//! -0.6, as `leaf_shape`), for each level `l` the probability `P(node)` that
//! the descent gives each node of level `l` (the product of its ancestors'
//! shares) against the node's exact share of `L cos`, `ρ = W(node) / (W P(node))`
//! (`W(node) = Σ_leaves max(0, n.m1)` over its leaf records, `W` the sum over
//! all): the misfit `Σ P (ρ - 1)^2` (the variance of `E[L cos / (E pdf) |
//! node]`; 0 where every node's probability is its light's share). Prints the
//! mean over the normals per level, and the top table's size on the bake's
//! grid. Below the top levels a node's weight is the moments' bound, loose
//! where a node straddles the normal's horizon: the misfit grows at the first
//! level below the table. Results: docs/results/envmap.md#top-levels.

use nuld_build_tool::sphere::envmap_tree::{prior_levels, top_table, PRIOR_GRID};
use nuld_build_tool::sphere::geometry::spiral_normal;
use nuld_build_tool::sphere::{EnvmapDensity, EnvmapTree};
use nuld_core::blob::Domain;
use nuld_core::envmap_tree::{
    node_index, EnvmapTree as CoreTree, LEGACY_TOP_LEVELS, MAX_TOP_LEVELS,
};
use nuld_core::quadtree::{ChildWeights, Node};
use nuld_core::sphere::{sphere_to_square, square_to_sphere_real};
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 2 {
        eprintln!("usage: tree_misfit MAP");
        std::process::exit(2);
    }
    let map = EnvmapDensity::from_file_filtered(&args[1], Domain::Sphere).unwrap();
    let levels = prior_levels(&map);
    let built = EnvmapTree::new(&map, levels, PRIOR_GRID).unwrap();
    let nodes = &built.nodes;
    let grid = built.grid;
    println!(
        "{}: {levels} levels, top table on {grid} x {grid} normals",
        args[1]
    );
    for t in LEGACY_TOP_LEVELS..=MAX_TOP_LEVELS {
        let top = top_table(levels, t, nodes, grid);
        let tree = CoreTree::new(levels, nodes, grid, &top, t).unwrap();
        let per_normal: Vec<Vec<f64>> = (0..64)
            .into_par_iter()
            .map(|k| {
                let n = spiral_normal(k, 64);
                misfit_by_level(&tree, levels, sphere_to_square(n).to_array())
            })
            .collect();
        let mean: Vec<String> = (0..levels as usize)
            .map(|l| {
                let m = per_normal.iter().map(|v| v[l]).sum::<f64>() / per_normal.len() as f64;
                format!("{m:.5}")
            })
            .collect();
        println!(
            "T = {t} ({:.1} MB): misfit by level 1..{levels}: {}",
            top.len() as f64 * 4.0 / 1e6,
            mean.join(" ")
        );
    }
}

/// `Σ P (ρ - 1)^2` over each level's nodes (module docs) for the normal at
/// octahedral square point `q`, levels 1 to `levels`.
fn misfit_by_level(tree: &CoreTree<'_>, levels: u32, q: [f64; 2]) -> Vec<f64> {
    let lit = tree.lit_square(q);
    let n = square_to_sphere_real(q);
    let side = 1usize << levels;
    let records = tree.nodes();
    // The exact lit masses, leaves first, then each level from its children.
    let mut exact: Vec<Vec<f64>> = vec![Vec::new(); levels as usize + 1];
    exact[levels as usize] = (0..side * side)
        .map(|k| {
            let m = records[node_index(levels, (k % side) as u32, (k / side) as u32)].moment;
            (n[0] * m[0] as f64 + n[1] * m[1] as f64 + n[2] * m[2] as f64).max(0.0)
        })
        .collect();
    for l in (0..levels as usize).rev() {
        let (s, c) = (1usize << l, 2usize << l);
        let below = &exact[l + 1];
        exact[l] = (0..s * s)
            .map(|k| {
                let (x, y) = (k % s, k / s);
                below[2 * y * c + 2 * x]
                    + below[2 * y * c + 2 * x + 1]
                    + below[(2 * y + 1) * c + 2 * x]
                    + below[(2 * y + 1) * c + 2 * x + 1]
            })
            .collect();
    }
    let total = exact[0][0];
    let mut prob = vec![1.0f64];
    let mut out = Vec::new();
    for l in 0..levels as usize {
        let (s, c) = (1usize << l, 2usize << l);
        let mut next = vec![0.0; c * c];
        for y in 0..s {
            for x in 0..s {
                let w = lit
                    .children(Node::new(l as u32, x as u32, y as u32))
                    .map(|v| v.max(0.0));
                let sum: f64 = w.iter().sum();
                for (k, wk) in w.iter().enumerate() {
                    let (i, j) = (k & 1, k >> 1);
                    next[(2 * y + j) * c + 2 * x + i] = if sum > 0.0 {
                        prob[y * s + x] * wk / sum
                    } else {
                        0.0
                    };
                }
            }
        }
        prob = next;
        let misfit = prob
            .iter()
            .zip(&exact[l + 1])
            .filter(|(p, _)| **p > 0.0)
            .map(|(p, w)| p * (w / total / p - 1.0).powi(2))
            .sum();
        out.push(misfit);
    }
    out
}
