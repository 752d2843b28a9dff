//! A shifted lattice through the BRDF prior at eleven metals (metallic 1), the
//! smooth ones among them: the shipped prior (10 x 12 x 3 nodes, the metal
//! layer in its own square), the same without the metal layer (10 x 12 x 2),
//! and without it for two other stretches of the shared half-vector square
//! (`roughness^p`, p = 1, 2; 0.25 is shipped): cap L2 over Owen-Sobol through
//! each metal's exact inverse CDF, N = 64, 8 sets (the judge of `eval
//! brdf-prior`). `cargo run --release -p nuld-build-tool --example
//! prior_at_smooth_metals` (about a minute on 2 cores);
//! docs/results/brdf-prior.md.
use nuld_build_tool::lab::eval::prior_judge::{score, Judge, JudgeSettings};
use nuld_build_tool::sphere::brdf_prior::{BrdfPrior, PriorSpace};
use nuld_build_tool::sphere::{BrdfTarget, TabulatedWarp};
use nuld_core::blob::Domain;
fn main() -> anyhow::Result<()> {
    let conds = [
        [0.13, 4.0, 1.0],
        [0.13, 45.0, 1.0],
        [0.13, 85.0, 1.0],
        [0.25, 85.0, 1.0],
        [0.44, 63.0, 1.0],
        [0.85, 26.0, 1.0],
        [0.17, 30.0, 1.0],
        [0.33, 70.0, 1.0],
        [0.62, 80.0, 1.0],
        [0.21, 12.0, 1.0],
        [0.97, 75.0, 1.0],
    ];
    let s = JudgeSettings {
        n: 64,
        instances: 8,
        caps: 4096,
        seed: 0,
    };
    let mut judges = Vec::new();
    for (i, c) in conds.iter().enumerate() {
        let t = BrdfTarget::metallic(c[0], c[1], c[2], Domain::Hemisphere)?;
        let exact = TabulatedWarp::new(&t, 1024, 2)?;
        judges.push(Judge::new(*c, &t, &|u| exact.warp(u), &s, i as u64));
    }
    for (p, g_m) in [(25u32, 3u32), (25, 2), (100, 2), (200, 2)] {
        let space = match p {
            25 => PriorSpace::HalfVector,
            p => PriorSpace::HalfVectorPower { stretch_percent: p },
        };
        let prior = BrdfPrior::new([10, 12, g_m], 96, space)?;
        let warp = prior.warp();
        for (j, c) in conds.iter().enumerate() {
            let through = |c: &[f64; 3], u| prior.sample(&warp, *c, u).0;
            let (_, lat) = score(&judges[j..j + 1], &s, &through);
            println!("p {p} G_m {g_m} cond {c:?}: lattice {:.3}", lat.0);
        }
    }
    Ok(())
}
