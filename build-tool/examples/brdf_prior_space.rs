//! Condition by condition, how much of a shifted lattice's low discrepancy
//! survives the BRDF prior in each table space: `cargo run --release -p
//! nuld-build-tool --example brdf_prior_space -- SPACES N K CONDITIONS [SIZE
//! [GRID]]`,
//! e.g. `-- half-vector,radial:100_25_50_0:100_100_50_100 256 8 held:48`.
//!
//! * `SPACES`: table spaces as `eval brdf-prior --spaces` takes them, separated by
//!   `,`; each builds the prior on `GRID` (`RxTxM`, default the blob's 10x12x3)
//!   with `SIZE` vertices a side (default the blob's 96), about 10 s a space;
//! * `N`: points per set; `K`: lattice shifts averaged per condition;
//! * `CONDITIONS`: `roughness,view°,metallic` triples separated by `/`, or
//!   `held:C`, the first `C` held-out conditions of `eval brdf-prior
//!   --conditions C`.
//!
//! Printed: a row per condition, the mean over the `K` shifts of the lattice's cap
//! L2 over Owen-Sobol through the condition's exact inverse CDF (`eval
//! brdf-prior`'s judge), through that exact inverse CDF itself (the bound of any
//! prior) and through each space's prior; then each column's mean and worst, and
//! the worst of the conditions at metallic below 1 and at 1 apart (the metal
//! layer is a square of its own).
mod conditions;
#[allow(dead_code)]
mod selection;

use nuld_build_tool::lab::eval::brdf_prior::{self, held_out, judging, BrdfPriorSettings};
use nuld_build_tool::lab::eval::prior_judge::Judge;
use nuld_build_tool::sphere::brdf_prior::{BrdfPrior, PriorSpace, PRIOR_GRID, PRIOR_SIZE};
use nuld_build_tool::sphere::{BrdfTarget, TabulatedWarp};
use nuld_build_tool::train::lattice_generator;
use nuld_core::blob::Domain;
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 5 {
        eprintln!("usage: brdf_prior_space SPACES N K CONDITIONS [SIZE [GRID]]");
        std::process::exit(2);
    }
    let spaces: Vec<PriorSpace> = (args[1].split(','))
        .map(|s| {
            PriorSpace::parse(s).unwrap_or_else(|| {
                eprintln!("{s:?} is not a table space (see eval brdf-prior --help)");
                std::process::exit(2);
            })
        })
        .collect();
    let number = |i: usize, what: &str| -> u32 {
        args[i].parse().unwrap_or_else(|_| {
            eprintln!("{what} {:?} is not a count", args[i]);
            std::process::exit(2);
        })
    };
    let (n, k) = (number(2, "N"), number(3, "K"));
    let size = args.get(5).map_or(PRIOR_SIZE, |_| number(5, "SIZE"));
    let grid: [u32; 3] = match args.get(6) {
        None => PRIOR_GRID,
        Some(g) => (g.split('x').map(|x| x.parse().ok()))
            .collect::<Option<Vec<u32>>>()
            .and_then(|v| v.try_into().ok())
            .unwrap_or_else(|| {
                eprintln!("GRID {g:?}: expected RxTxM, e.g. 10x12x3");
                std::process::exit(2);
            }),
    };
    let settings = BrdfPriorSettings {
        n,
        conditions: args[4]
            .strip_prefix("held:")
            .map_or(16, |c| c.parse().unwrap_or(16)),
        ..BrdfPriorSettings::default()
    };
    let list = match args[4].starts_with("held:") {
        true => held_out(&settings),
        false => conditions::parse(&args[4]),
    };
    let priors: Vec<BrdfPrior> = (spaces.iter())
        .map(|&space| {
            BrdfPrior::new(grid, size, space).unwrap_or_else(|e| {
                eprintln!("{}: {e}", space.name());
                std::process::exit(2);
            })
        })
        .collect();
    let warps: Vec<_> = priors.iter().map(|p| p.warp()).collect();
    let sets = selection::candidates(n, lattice_generator(n), k);
    let score = |judge: &Judge<BrdfTarget>, to: &dyn Fn(glam::DVec2) -> glam::DVec3| {
        selection::mean_score_through(&sets, judge, to)
    };
    let rows: Vec<([f64; 3], Vec<f64>)> = (list.par_iter().enumerate())
        .map(|(index, &c)| {
            let judge = brdf_prior::judge(c, &judging(&settings), index as u64).unwrap();
            let target = BrdfTarget::metallic(c[0], c[1], c[2], Domain::Hemisphere).unwrap();
            let exact = TabulatedWarp::new(&target, 1024, 2).unwrap();
            let mut row = vec![score(&judge, &|u| exact.warp(u))];
            for (prior, warp) in priors.iter().zip(&warps) {
                row.push(score(&judge, &|u| prior.sample(warp, c, u).0));
            }
            (c, row)
        })
        .collect();
    let names: Vec<String> = std::iter::once("exact inverse CDF".to_string())
        .chain(spaces.iter().map(|s| s.name()))
        .collect();
    println!("columns: {}", names.join(" | "));
    for (c, row) in &rows {
        selection::print_row(*c, row);
    }
    println!(
        "{} conditions, N = {n}, {k} shifts, tables {size} a side on {grid:?} nodes:",
        rows.len()
    );
    for (j, name) in names.iter().enumerate() {
        let column = |metal: Option<bool>| {
            let v: Vec<f64> = (rows.iter())
                .filter(|(c, _)| metal.is_none_or(|m| (c[2] >= 1.0) == m))
                .map(|(_, r)| r[j])
                .collect();
            let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
            (mean, v.iter().copied().fold(0.0, f64::max))
        };
        let (mean, worst) = column(None);
        let (_, below) = column(Some(false));
        let (_, metal) = column(Some(true));
        println!(
            "{name:>40}: mean {mean:.3}, worst {worst:.3} (metallic below 1: {below:.3}, metals: {metal:.3})"
        );
    }
}
