//! How far the environment sampler's prior, the map's tree, is from the target
//! it stands in for: `cargo run --release -p nuld-build-tool --example
//! envmap_prior_floor -- MAP [LEVELS]`.
//!
//! At each of the bake check's 16 held-out normals and on its judge (4096 caps
//! with exact measures, over 8 Owen-Sobol sets of 64 points through the exact
//! inverse CDF of the lit map `L cos`), prints the cap L2 of `2^16` Owen-Sobol
//! points through the tree (`tree`) and through the exact inverse CDF (`exact`,
//! what so many points leave: about 0.006): the first is the distance of the
//! tree's own distribution from `L cos`, a floor under every set warped through
//! the tree, and under the union of many. Then, over the 16 normals, the mean
//! and worst ratio of 64-point Owen-Sobol sets and randomly shifted rank-1
//! lattices through the tree and through the exact inverse CDF
//! (`prior_judge::score`). `LEVELS` is the tree's depth (default: the bake's,
//! `prior_levels`); the tree is built as the bake builds it.
//! Results: docs/results/envmap.md#floor.
mod check;

use glam::{DVec2, DVec3};
use nuld_build_tool::baselines::seeded_owen_sobol;
use nuld_build_tool::lab::eval::prior_judge::{score, JudgeSettings};
use nuld_build_tool::sphere::envmap_tree::{prior_levels, PRIOR_GRID};
use nuld_build_tool::sphere::{DirectionDensity, EnvmapTree};
use rayon::prelude::*;

/// Points of the sets whose cap L2 measures a distribution.
const DENSE: usize = 1 << 16;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=3).contains(&args.len()) {
        eprintln!("usage: envmap_prior_floor MAP [LEVELS]");
        std::process::exit(2);
    }
    let (_, env) = check::load(&args[1], 64);
    let levels = args
        .get(2)
        .map_or(prior_levels(&env.map), |s| s.parse().unwrap());
    let clock = std::time::Instant::now();
    let built = EnvmapTree::new(&env.map, levels, PRIOR_GRID).unwrap();
    eprintln!(
        "tree of {levels} levels built in {:.2} s",
        clock.elapsed().as_secs_f64()
    );
    let tree = built.tree();
    let (judges, lits): (Vec<_>, Vec<_>) = (0..check::NORMALS)
        .into_par_iter()
        .filter_map(|index| {
            let u = check::held_out(index);
            let lit = check::lit(&env.map, u)?;
            Some((check::judge(&lit, u, 64, index as u64), lit))
        })
        .unzip();
    let dense = seeded_owen_sobol(DENSE, 77);
    let through_tree = |u: [f64; 2], p: DVec2| DVec3::from(tree.sample_square(u, p.to_array()).0);
    let mut floors = Vec::new();
    for (judge, lit) in judges.iter().zip(&lits) {
        let u = judge.condition;
        let t: Vec<DVec3> = dense.iter().map(|&p| through_tree(u, p)).collect();
        let e: Vec<DVec3> = dense.iter().map(|&p| lit.sample(p)).collect();
        let floor = judge.d(&t) / judge.baseline();
        println!(
            "normal at square point {u:?}: tree {floor:.3}, exact {:.3}",
            judge.d(&e) / judge.baseline()
        );
        floors.push(floor);
    }
    println!(
        "floor of the tree: mean {:.3}, worst {:.3}",
        floors.iter().sum::<f64>() / floors.len() as f64,
        floors.iter().copied().fold(0.0, f64::max)
    );
    let s = JudgeSettings {
        n: 64,
        instances: 8,
        caps: 4096,
        seed: check::CHECK_SEED,
    };
    let (os, lattice) = score(&judges, &s, &|u: &[f64; 2], p| through_tree(*u, p));
    println!("through the tree: owen-sobol {os:.3?}, lattice {lattice:.3?} (mean, worst)");
    let (os, lattice) = score(&judges, &s, &|u: &[f64; 2], p| {
        let k = judges.iter().position(|j| j.condition == *u).unwrap();
        lits[k].sample(p)
    });
    println!("through the exact inverse CDF: owen-sobol {os:.3?}, lattice {lattice:.3?}");
}
