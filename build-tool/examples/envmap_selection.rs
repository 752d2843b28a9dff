//! Whether choosing, per normal of a table, which untrained shifted lattice to
//! warp through the environment prior beats the bake's network:
//! `cargo run --release -p nuld-build-tool --example envmap_selection -- MAP [N] [K] [PRIOR]`.
//!
//! The candidates are the bake's rank-1 lattice (its shape's generator) shifted
//! by the first `K` (default 256) offsets of its instance hash
//! (`OffsetHash::Salted`, not wrapped at the shape's 64 instance slots), each a set of
//! `N` (default 64) points through the prior (the map's tree at the normal): what
//! the unbiased mode draws, with no learned part. `PRIOR` is `tree` (default,
//! the sampler's) or `table` (`sphere::EnvmapPrior`, the marginal-conditional
//! warp of `L cos` tabulated on 33 x 33 normals and 64 x 64 vertices, blended
//! between the four normals around the query). At each of the check's 16
//! held-out normals (the cell centres of a 4 x 4 grid on the octahedral square)
//! and on the check's judge (4096 caps with exact measures, over 8 Owen-Sobol
//! sets through the normal's exact inverse CDF), prints:
//!
//! * `mean`: the mean over all `K` candidates (a random instance's lattice);
//! * `oracle 1`, `oracle 8`: the best one, and the mean of the best 8, chosen by
//!   the held-out judge itself (a bound no table reaches);
//! * `other caps 1`, `other caps 8`: the same, chosen at the held-out normal
//!   itself by a judge of other caps (what the judges' own noise leaves);
//! * `G: 1`, `G: 8`: the best one and the best 8 chosen at a node of a `G x G`
//!   table of normals (G = 13, the bake's, 25, 49 and 97) by that node's own judge
//!   (other caps, other baseline), then scored at the held-out normal. The node
//!   is half a cell away along both axes of the octahedral square, the farthest a
//!   nearest-node lookup reads from, so these are a table's worst case;
//! * `49 fast: 1`, `49 fast: 8`: the same on 49 x 49 with a cheaper judge at the
//!   node (1024 caps measured on the lit map's mass rule of `2^14` points, as the
//!   bake's training pool measures them);
//! * `49 cell: 1`, `49 cell: 8`: chosen by that cheaper judge over the node's
//!   cell: the sum, over the node and four normals a quarter cell from it along
//!   the square's axes, of each normal's scores over their mean.
//!
//! On stderr, for candidate 0 and each grid, how far the normal moves from the
//! held-out normal to the node and how far the set's points move with it
//! (median, 90th percentile, most): whether the prior's warp is continuous in the
//! normal for a fixed primary point; and the seconds a node's choice took (its
//! judge, then the `K` candidates scored), one thread of two.
//!
//! A table of such choices holds one small integer per node and instance; a
//! sample reads it, shifts the lattice and warps (no blend of points, no
//! network). Results: docs/results/envmap.md#selection.
mod check;
mod selection;

use glam::{DVec2, DVec3};
use nuld_build_tool::lab::eval::prior_judge::Judge;
use nuld_build_tool::sphere::metrics::{CapRadius, MeasuredCaps};
use nuld_build_tool::sphere::{CapMeasureTable, EnvmapPrior};
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;

/// Table sizes whose nodes choose: the bake's grid and three finer ones.
const GRIDS: [usize; 4] = [13, 25, 49, 97];

/// The grid whose nodes also choose by a cheaper judge: [`FAST_CAPS`] caps
/// measured on the lit map's mass rule of `2^14` points, as the bake's pool
/// measures its caps.
const FAST_GRID: usize = 49;

/// Caps of the cheaper judge.
const FAST_CAPS: usize = 1024;

/// How many chosen candidates a table keeps per node (its instances).
const KEPT: usize = 8;

/// A choice's two columns: the held-out scores `at_u` of the best candidate by
/// `choice` (lower is better), and their mean over its best [`KEPT`].
fn push_choice(row: &mut Vec<f64>, at_u: &[f64], choice: &[f64]) {
    let order = selection::ranking(choice);
    row.push(at_u[order[0]]);
    row.push(selection::mean_of(at_u, &order, KEPT));
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=5).contains(&args.len()) {
        eprintln!("usage: envmap_selection MAP [N] [K] [tree|table]");
        std::process::exit(2);
    }
    let arg = |k: usize, default: usize| args.get(k).map_or(default, |s| s.parse().unwrap());
    let (n, k_count) = (arg(2, 64) as u32, arg(3, 256) as u32);
    let (shape, env) = check::load(&args[1], n);
    let tree = env.tree.tree();
    let table = match args.get(4).map_or("tree", |s| s.as_str()) {
        "tree" => None,
        "table" => Some(EnvmapPrior::new(&env.map, 33, 64).unwrap()),
        other => panic!("PRIOR is tree or table, not {other}"),
    };
    let table_warp = table.as_ref().map(|t| t.warp());
    // The prior's direction of primary point `p` at the normal of octahedral point `u`.
    let warp = |u: [f64; 2], p: DVec2| -> DVec3 {
        match (&table, &table_warp) {
            (Some(t), Some(w)) => t.sample(w, square_to_sphere(DVec2::from(u)), p).0,
            _ => DVec3::from(tree.sample_square(u, p.to_array()).0),
        }
    };
    let g = shape.lattice_generator();
    let candidates = selection::candidates(n, g, k_count);
    // Every candidate's directions at the normal of octahedral point `u`.
    let sets_at = |u: [f64; 2]| -> Vec<Vec<DVec3>> {
        candidates
            .iter()
            .map(|set| set.iter().map(|&p| warp(u, p)).collect())
            .collect()
    };
    // The squared cap L2 of every candidate at `u` on caps measured by the lit
    // map's mass rule (as the bake's pool measures), for ranking only: no baseline.
    let fast_scores = |u: [f64; 2], sets: &[Vec<DVec3>], seed: u64| -> Option<Vec<f64>> {
        let table = CapMeasureTable::new(&check::lit(&env.map, u)?.mass_rule(1 << 14));
        let caps = MeasuredCaps::draw(FAST_CAPS, seed, CapRadius::ThetaUniform, |w, t| {
            table.measure(w, t)
        });
        Some(
            sets.iter()
                .map(|dirs| caps.l2_squared(dirs, CapRadius::ThetaUniform).0)
                .collect(),
        )
    };
    // The check's judge at octahedral point `u`, caps drawn from `index`.
    let judge = |u: [f64; 2], index: u64| -> Option<Judge<[f64; 2]>> {
        Some(check::judge(&check::lit(&env.map, u)?, u, n, index))
    };
    let rows: Vec<Vec<f64>> = (0..check::NORMALS)
        .into_par_iter()
        .filter_map(|index| {
            let u = check::held_out(index);
            let held_out = judge(u, index as u64)?;
            let sets = sets_at(u);
            let at_u = selection::scores(&sets, &held_out);
            let mut row = vec![at_u.iter().sum::<f64>() / at_u.len() as f64];
            push_choice(&mut row, &at_u, &at_u);
            // The same normal judged on other caps: what the judge's own noise
            // leaves of a choice.
            let other = judge(u, 2000 + index as u64)?;
            push_choice(&mut row, &at_u, &selection::scores(&sets, &other));
            for (j, grid) in GRIDS.iter().enumerate() {
                let half = 0.5 / (grid - 1) as f64;
                let node = [u[0] + half, u[1] + half];
                let clock = std::time::Instant::now();
                let node_sets = sets_at(node);
                let warped = clock.elapsed().as_secs_f64();
                // How far candidate 0's points move from the normal to the node
                // (radians): the warp's own change across the half cell.
                let mut sorted: Vec<f64> = sets[0]
                    .iter()
                    .zip(&node_sets[0])
                    .map(|(a, b)| a.angle_between(*b))
                    .collect();
                sorted.sort_by(f64::total_cmp);
                eprintln!(
                    "normal {index:2} grid {grid}: normal moves {:.2} deg; points move median {:.3} deg, 90% {:.3}, max {:.3}",
                    square_to_sphere(DVec2::from(u)).angle_between(square_to_sphere(DVec2::from(node))).to_degrees(),
                    sorted[sorted.len() / 2].to_degrees(),
                    sorted[sorted.len() * 9 / 10].to_degrees(),
                    sorted[sorted.len() - 1].to_degrees()
                );
                let clock = std::time::Instant::now();
                let node_judge = judge(node, 1000 + (16 * j + index) as u64)?;
                let judged = clock.elapsed().as_secs_f64();
                push_choice(&mut row, &at_u, &selection::scores(&node_sets, &node_judge));
                eprintln!(
                    "normal {index:2} grid {grid}: a node's choice took {:.3} s (judge {judged:.3} s)",
                    warped + clock.elapsed().as_secs_f64()
                );
                if *grid == FAST_GRID {
                    let clock = std::time::Instant::now();
                    let fast = fast_scores(node, &node_sets, 3000 + index as u64)?;
                    eprintln!(
                        "normal {index:2} grid {grid}: a node's fast choice took {:.3} s",
                        warped + clock.elapsed().as_secs_f64()
                    );
                    push_choice(&mut row, &at_u, &fast);
                    // Over the node's own cell: the node and four normals a
                    // quarter cell from it, each point's scores over their mean.
                    let quarter = 0.5 * half;
                    let mut total = vec![0.0; candidates.len()];
                    for (e, [dx, dy]) in [[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]
                        .into_iter()
                        .enumerate()
                    {
                        let at = [node[0] + dx * quarter, node[1] + dy * quarter];
                        let sc = fast_scores(at, &sets_at(at), 4000 + 8 * index as u64 + e as u64)?;
                        let mean = sc.iter().sum::<f64>() / sc.len() as f64;
                        for (t, v) in total.iter_mut().zip(&sc) {
                            *t += v / mean;
                        }
                    }
                    push_choice(&mut row, &at_u, &total);
                }
            }
            let cells: Vec<String> = row.iter().map(|x| format!("{x:.3}")).collect();
            println!("normal {index:2}: {}", cells.join(" "));
            Some(row)
        })
        .collect();
    let mut names = vec![
        "mean".to_string(),
        "oracle 1".to_string(),
        format!("oracle {KEPT}"),
        "other caps 1".to_string(),
        format!("other caps {KEPT}"),
    ];
    for grid in GRIDS {
        names.push(format!("{grid}: 1"));
        names.push(format!("{grid}: {KEPT}"));
        if grid == FAST_GRID {
            names.push(format!("{grid} fast: 1"));
            names.push(format!("{grid} fast: {KEPT}"));
            names.push(format!("{grid} cell: 1"));
            names.push(format!("{grid} cell: {KEPT}"));
        }
    }
    println!("{} normals, N = {n}, K = {k_count}", rows.len());
    for (j, name) in names.iter().enumerate() {
        let mean = rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
        let worst = rows.iter().map(|r| r[j]).fold(0.0, f64::max);
        println!("{name:>10}: mean {mean:.3}, worst {worst:.3}");
    }
}
