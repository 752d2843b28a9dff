//! Whether the environment prior could be lit at the table's nearest node
//! instead of at the caller's normal: `cargo run --release -p nuld-build-tool
//! --example envmap_nearest_node -- MAP [N] [STEPS] [STEP]` (about 30 s a map
//! on 2 cores).
//!
//! Lit at the exact normal, the tree's shares move with the normal and a point
//! near a share's boundary jumps to another light, which is what keeps a set
//! fitted at one normal from serving a degree away (docs/results/envmap.md,
//! "selection"). Lit at the nearest node of a `G x G` grid on the octahedral
//! square, the prior is constant across a node's cell, nothing jumps, and the
//! returned pdf would still be exact; but the set is then drawn for the node's
//! `L cos`, not the normal's. At the check's 16 held-out normals, with its judge
//! (4096 caps, over 8 Owen-Sobol sets through each normal's exact inverse CDF),
//! the example prints, for the node a quarter and half a cell away along both
//! axes of grids of 13 and 49 nodes:
//!
//! * `lattice@node`: instance 0's shifted lattice through the tree lit at the
//!   node, judged at the normal;
//! * `fit@node via node`: that lattice fitted at the node as `envmap_bounds`
//!   fits (`STEPS` Adam steps, default 3000, of `STEP / sqrt(N)`, default 0.02),
//!   through the tree lit at the node;
//! * `fit@node via u`: the same fitted points through the tree lit at the normal
//!   (today's design, table mode read at the nearest node);
//!
//! beside `lattice@u` and `fit@u` (the lattice, and the lattice fitted at the
//! normal itself, through the tree at the normal).
mod check;
mod fit;
mod primary;

use fit::{fit, warp, Fit, Site};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=5).contains(&args.len()) {
        eprintln!("usage: envmap_nearest_node MAP [N] [STEPS] [STEP]");
        std::process::exit(2);
    }
    let how = Fit::from_args(&args);
    let n = how.n;
    let (shape, env) = check::load(&args[1], n as u32);
    let tree = env.tree.tree();
    let lattice = fit::lattice(&shape, n);
    // (nodes per axis, the node's offset from the normal in cells along both axes)
    let cases = [(13usize, 0.25f64), (13, 0.5), (49, 0.25), (49, 0.5)];
    let rows: Vec<Vec<f64>> = (0..check::NORMALS)
        .into_par_iter()
        .filter_map(|index| {
            let u = check::held_out(index);
            let lit = check::lit(&env.map, u)?;
            let judge = check::judge(&lit, u, n as u32, index as u64);
            let d = |x: &[DVec3]| judge.d(x) / judge.baseline();
            let directions = |at: [f64; 2], p: &[DVec2]| {
                p.iter()
                    .map(|&q| warp(Some(&tree), at, q).0)
                    .collect::<Vec<_>>()
            };
            let mut row = vec![d(&directions(u, &lattice))];
            let fitted = fit(
                Some(&tree),
                &[Site::new(&env.map, u, index as u32)],
                &lattice,
                &how,
            );
            row.push(d(&directions(u, &fitted)));
            for &(grid, off) in &cases {
                let node = u.map(|x| x + off / (grid - 1) as f64);
                row.push(d(&directions(node, &lattice)));
                let f = fit(
                    Some(&tree),
                    &[Site::new(&env.map, node, 500 + index as u32)],
                    &lattice,
                    &how,
                );
                row.push(d(&directions(node, &f)));
                // The node's fit through the tree lit at the normal (its points jump).
                row.push(d(&directions(u, &f)));
            }
            let cells: Vec<String> = row.iter().map(|x| format!("{x:.3}")).collect();
            println!("normal {index:2}: {}", cells.join(" "));
            Some(row)
        })
        .collect();
    let k = rows.len() as f64;
    let mut names = vec!["lattice@u".to_string(), "fit@u".to_string()];
    for (grid, off) in cases {
        names.push(format!("G{grid} off{off}: lattice@node"));
        names.push(format!("G{grid} off{off}: fit@node via node"));
        names.push(format!("G{grid} off{off}: fit@node via u"));
    }
    for (j, name) in names.iter().enumerate() {
        let mean = rows.iter().map(|r| r[j]).sum::<f64>() / k;
        let worst = rows.iter().map(|r| r[j]).fold(0.0, f64::max);
        println!("{name}: mean {mean:.3}, worst {worst:.3}");
    }
}
