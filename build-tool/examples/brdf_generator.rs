//! Whether another rank-1 lattice generator would rescue the BRDF prior at
//! the smooth grazing conditions where the N = 256 sampler reads above 1:
//! `cargo run --release -p nuld-build-tool --example brdf_generator -- N K
//! CONDITIONS [GENERATORS]` (about 3 s a condition at N = 256, K = 16, on 2
//! cores).
//!
//! For each condition (`roughness,view°,metallic` triples separated by `/`)
//! and each generator `g` (default: every `g < N / 2` coprime to `N`), the mean
//! over `K` shifts of the lattice `(i/N, frac(i g/N))` (the salted instance
//! offsets) of its cap L2 over Owen-Sobol through the condition's exact inverse
//! CDF (`eval brdf-prior`'s judge), through the shipped prior and through the
//! exact inverse CDF itself. Printed: the bake's generator
//! (`train::lattice_generator`) and the six best through the prior, each with
//! its Zaremba index (`train::zaremba_index`) and its score through the exact
//! inverse CDF.
mod conditions;
#[allow(dead_code)]
mod selection;

use nuld_build_tool::lab::eval::brdf_prior::{self, judging, BrdfPriorSettings};
use nuld_build_tool::sphere::brdf_prior::BrdfPrior;
use nuld_build_tool::sphere::{BrdfTarget, TabulatedWarp};
use nuld_build_tool::train::{gcd, lattice_generator, zaremba_index};
use nuld_core::blob::Domain;
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(4..=5).contains(&args.len()) {
        eprintln!("usage: brdf_generator N K CONDITIONS [GENERATORS]");
        std::process::exit(2);
    }
    let n: u32 = args[1].parse().expect("N: a point count");
    let k: u32 = args[2].parse().expect("K: a count of shifts");
    let conds = conditions::parse(&args[3]);
    let generators: Vec<u32> = match args.get(4) {
        Some(s) => (s.split(','))
            .map(|x| x.parse().expect("a generator"))
            .collect(),
        None => (1..n / 2)
            .filter(|&g| gcd(g as u64, n as u64) == 1)
            .collect(),
    };
    let prior = BrdfPrior::shared();
    let warp = prior.warp();
    let settings = BrdfPriorSettings {
        n,
        ..BrdfPriorSettings::default()
    };
    let shipped = lattice_generator(n);
    let candidates: Vec<(u32, Vec<Vec<glam::DVec2>>)> = (generators.iter())
        .map(|&g| (g, selection::candidates(n, g, k)))
        .collect();
    for (index, &c) in conds.iter().enumerate() {
        let judge = brdf_prior::judge(c, &judging(&settings), index as u64).unwrap();
        let target = BrdfTarget::metallic(c[0], c[1], c[2], Domain::Hemisphere).unwrap();
        let exact = TabulatedWarp::new(&target, 1024, 2).unwrap();
        // (g, through the prior, through the exact inverse CDF)
        let mut rows: Vec<(u32, f64, f64)> = (candidates.par_iter())
            .map(|(g, sets)| {
                let p =
                    selection::mean_score_through(sets, &judge, &|u| prior.sample(&warp, c, u).0);
                let e = selection::mean_score_through(sets, &judge, &|u| exact.warp(u));
                (*g, p, e)
            })
            .collect();
        let bake = rows.iter().find(|r| r.0 == shipped).copied();
        rows.sort_by(|a, b| a.1.total_cmp(&b.1));
        let best: Vec<String> = (rows.iter().take(6))
            .map(|&(g, p, e)| {
                let z = zaremba_index(n as u64, g as u64);
                format!("g {g} {p:.3} (index {z}, exact {e:.3})")
            })
            .collect();
        let bake = bake.map_or("not scanned".to_string(), |(_, p, e)| {
            format!("{p:.3} (exact {e:.3})")
        });
        println!(
            "({:.2}, {:4.1}°, {:.2}): the bake's g {shipped} {bake}; best: {}",
            c[0],
            c[1],
            c[2],
            best.join("; ")
        );
    }
}
