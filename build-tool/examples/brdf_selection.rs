//! Whether choosing, per node of a table of BRDF conditions, which untrained
//! shifted lattices to warp through the BRDF sampler's prior beats the bake's
//! trained sets: `cargo run --release -p nuld-build-tool --example brdf_selection
//! -- [BLOB] [N] [K]`.
//!
//! The BRDF twin of `envmap_selection`. The candidates are the rank-1 lattice of
//! `N` (default 64) points shifted by the first `K` (default 256) offsets of the
//! salted instance hash, each warped through the shipped prior
//! (`BrdfPrior::shared`, the half-vector tables) at a condition. The judge is
//! `eval brdf-prior`'s (16 held-out conditions, seed 0; 4096 measured caps, over
//! 8 Owen-Sobol sets through the condition's exact inverse CDF). Prints, per
//! held-out condition and as mean and worst:
//!
//! * `mean`: the mean over all `K` candidates (a random instance's lattice);
//! * `oracle 1 / 8 / 64`: the best one and the mean of the best 8 and 64 by
//!   the held-out judge itself (a bound no table reaches);
//! * `R x T: 1 / 8 / 64`: the same chosen at a node of an `R x T` table of
//!   (roughness, θo) on the prior's unit coordinates (the bake's 10 x 12 and two
//!   finer ones) by that node's own judge (other caps, other baseline), then
//!   scored at the held-out condition. The node lies half a cell away along both
//!   axes (a nearest-node table's worst case), at the nearest of metallic 0,
//!   0.5 and 1;
//! * with `BLOB` (a `bake --brdf` blob of the same `N`): its table mode on the
//!   same judge, instances 0 to 7 and 0 to 63.
mod selection;

use glam::{DVec3, Vec2};
use nuld_build_tool::lab::eval::brdf_prior::{self, held_out, judging, BrdfPriorSettings};
use nuld_build_tool::lab::eval::prior_judge::Judge;
use nuld_build_tool::sphere::brdf_prior::BrdfPrior;
use nuld_build_tool::sphere::BrdfTarget;
use nuld_build_tool::train::lattice_generator;
use nuld_core::brdf::{MAX_ROUGHNESS, MIN_ROUGHNESS};
use nuld_core::brdf_prior::{theta_o_of_unit, unit_condition};
use rayon::prelude::*;

/// `(roughness, θo)` nodes of the tables whose nodes choose.
const GRIDS: [[usize; 2]; 3] = [[10, 12], [19, 23], [37, 45]];

/// How many chosen candidates each column keeps.
const KEPT: [usize; 3] = [1, 8, 64];

/// The held-out scores `at_c` of the best 1, 8 and 64 candidates by `choice`.
fn push_choice(row: &mut Vec<f64>, at_c: &[f64], choice: &[f64]) {
    let order = selection::ranking(choice);
    for kept in KEPT {
        let kept = kept.min(order.len());
        row.push(selection::mean_of(at_c, &order, kept));
    }
}

/// `eval brdf-prior`'s judge of condition `c`, caps drawn from `index`.
fn judge(c: [f64; 3], index: u64) -> Judge<BrdfTarget> {
    brdf_prior::judge(c, &judging(&BrdfPriorSettings::default()), index).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let blob = args
        .get(1)
        .filter(|s| !s.is_empty())
        .map(|p| std::fs::read(p).unwrap());
    let arg = |k: usize, default: usize| args.get(k).map_or(default, |s| s.parse().unwrap());
    let (n, k_count) = (arg(2, 64) as u32, arg(3, 256) as u32);
    let prior = BrdfPrior::shared();
    let warp = prior.warp();
    let g = lattice_generator(n);
    let candidates = selection::candidates(n, g, k_count);
    let sets_at = |c: [f64; 3]| -> Vec<Vec<DVec3>> {
        candidates
            .iter()
            .map(|set| set.iter().map(|&p| prior.sample(&warp, c, p).0).collect())
            .collect()
    };
    let parsed = blob.as_ref().map(|b| {
        nuld_runtime::Blob::parse(b.as_slice())
            .unwrap()
            .brdf()
            .unwrap()
            .conditional()
    });
    let conditions = held_out(&BrdfPriorSettings::default());
    let rows: Vec<Vec<f64>> = conditions
        .par_iter()
        .enumerate()
        .map(|(index, &c)| {
            let held = judge(c, index as u64);
            let at_c = selection::scores(&sets_at(c), &held);
            let mut row = vec![at_c.iter().sum::<f64>() / at_c.len() as f64];
            push_choice(&mut row, &at_c, &at_c);
            let unit = unit_condition(c);
            for (j, [gr, gt]) in GRIDS.iter().enumerate() {
                // Half a cell away along both axes, back inside the square.
                let step = |x: f64, cells: usize| {
                    let half = 0.5 / (cells - 1) as f64;
                    if x + half <= 1.0 {
                        x + half
                    } else {
                        x - half
                    }
                };
                let metallic = [0.0, 0.5, 1.0]
                    .into_iter()
                    .min_by(|a: &f64, b: &f64| (a - c[2]).abs().total_cmp(&(b - c[2]).abs()))
                    .unwrap();
                let node = [
                    MIN_ROUGHNESS + step(unit[0], *gr) * (MAX_ROUGHNESS - MIN_ROUGHNESS),
                    theta_o_of_unit(step(unit[1], *gt)),
                    metallic,
                ];
                let node_judge = judge(node, 1000 + (16 * j + index) as u64);
                push_choice(
                    &mut row,
                    &at_c,
                    &selection::scores(&sets_at(node), &node_judge),
                );
            }
            if let Some(cs) = &parsed {
                let cond = Vec2::new(c[0] as f32, c[1] as f32);
                let table: Vec<f64> = (0..64)
                    .map(|k| {
                        let dirs: Vec<DVec3> = (0..cs.len())
                            .map(|i| {
                                cs.sample_metallic(cond, c[2] as f32, k, i)
                                    .direction
                                    .as_dvec3()
                            })
                            .collect();
                        held.d(&dirs) / held.baseline()
                    })
                    .collect();
                row.push(table[..8].iter().sum::<f64>() / 8.0);
                row.push(table.iter().sum::<f64>() / 64.0);
            }
            selection::print_row(c, &row);
            row
        })
        .collect();
    let mut names = vec!["mean".to_string()];
    names.extend(KEPT.map(|k| format!("oracle {k}")));
    for [gr, gt] in GRIDS {
        names.extend(KEPT.map(|k| format!("{gr} x {gt}: {k}")));
    }
    if parsed.is_some() {
        names.push("blob table 0-7".into());
        names.push("blob table 0-63".into());
    }
    println!("{} conditions, N = {n}, K = {k_count}", rows.len());
    for (j, name) in names.iter().enumerate() {
        let mean = rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
        let worst = rows.iter().map(|r| r[j]).fold(0.0, f64::max);
        println!("{name:>16}: mean {mean:.3}, worst {worst:.3}");
    }
}
