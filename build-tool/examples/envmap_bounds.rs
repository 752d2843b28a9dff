//! How low one normal's set can go on a map, on the judge of `bake --envmap`'s
//! held-out check, and whether sets fitted at the table's nodes still serve
//! between them: `cargo run --release -p nuld-build-tool --example
//! envmap_bounds -- MAP [N] [STEPS] [STEP] [GRID]`.
//!
//! At the check's 16 held-out normals (the cell centres of a 4 x 4 grid on the
//! octahedral square), with the check's own 4096 caps and exact cap measures
//! and its baseline (the mean cap L2 of 8 Owen-Sobol sets through each normal's
//! exact inverse CDF), prints six ratios to that baseline:
//!
//! * `lattice`: instance 0's shifted rank-1 lattice through the prior (the tree
//!   at that normal), what a network with a zero residual gives;
//! * `primary`: that lattice fitted to this one normal in the tree's primary
//!   space, as training moves points (cap loss with per-point sharpness in local
//!   units, gradients through the tree's exact slopes, 256 of 2048 caps measured on
//!   the lit map's mass rule per step, the trainer's schedule: sharpness 8 to 64
//!   inverse spacings, the step's cosine decay to 3 %), by Adam on the points
//!   themselves, `STEPS` steps (default 3000) of size `STEP / sqrt(N)` in the
//!   square (default 0.02);
//! * `blend`: the lattice fitted so at each of the four nodes around the normal
//!   of a `GRID x GRID` table (default 13, the bake's), those four primary sets
//!   blended bilinearly (table mode's arithmetic, in `f64`) and warped at the
//!   normal itself;
//! * `joint`: one set fitted to those four nodes at once (the sum of their
//!   losses), warped at the normal: what a family of sets that changes
//!   smoothly across the cell could keep;
//! * `joint directions`: the same in the sphere's equal-area square (the
//!   lattice through the tree at the normal, fitted to the four nodes'
//!   targets as directions, read at the normal as they are): the family in
//!   the space where the lights stay put as the normal moves;
//! * `direct`: the direction optimizer of `optimize --domain sphere` (its
//!   defaults, seed 0) on the lit map, no prior at all.
//!
//! What a conditional sampler trained in the prior's primary space could reach
//! at one normal, and in a table fitted node by node, against what the bake's
//! network reaches across all normals (docs/results/envmap.md, "bounds").
mod check;
mod fit;
mod primary;

use fit::{fit, warp, Fit, Site};
use glam::{DVec2, DVec3};
use nuld_build_tool::optimize::directions::{optimize_directions, DirectionConfig};
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=6).contains(&args.len()) {
        eprintln!("usage: envmap_bounds MAP [N] [STEPS] [STEP] [GRID]");
        std::process::exit(2);
    }
    let arg = |k: usize, default: f64| args.get(k).map_or(default, |s| s.parse().unwrap());
    let how = Fit::from_args(&args);
    let grid = arg(5, 13.0) as usize;
    let n = how.n;
    let (shape, env) = check::load(&args[1], n as u32);
    let tree = env.tree.tree();
    let lattice = fit::lattice(&shape, n);
    let rows: Vec<[f64; 6]> = (0..check::NORMALS)
        .into_par_iter()
        .filter_map(|index| {
            let u = check::held_out(index);
            let normal = square_to_sphere(DVec2::from(u));
            let lit = check::lit(&env.map, u)?;
            let judge = check::judge(&lit, u, n as u32, index as u64);
            let d = |x: &[DVec3]| judge.d(x) / judge.baseline();
            let directions = |p: &[DVec2]| {
                p.iter()
                    .map(|&q| warp(Some(&tree), u, q).0)
                    .collect::<Vec<_>>()
            };
            let start = d(&directions(&lattice));
            let primary = fit(
                Some(&tree),
                &[Site::new(&env.map, u, index as u32)],
                &lattice,
                &how,
            );
            let primary = d(&directions(&primary));

            // The four table nodes around `u` and their bilinear weights.
            let cell = u.map(|x| {
                let s = x * (grid - 1) as f64;
                let j = (s.floor() as usize).min(grid - 2);
                (j, s - j as f64)
            });
            let corners = [(0, 0), (1, 0), (0, 1), (1, 1)];
            let nodes: Vec<Site> = corners
                .iter()
                .map(|&(dx, dy)| {
                    let node = [
                        (cell[0].0 + dx) as f64 / (grid - 1) as f64,
                        (cell[1].0 + dy) as f64 / (grid - 1) as f64,
                    ];
                    Site::new(&env.map, node, 1000 + (index * 4 + 2 * dy + dx) as u32)
                })
                .collect();
            let mut blend = vec![DVec2::ZERO; n];
            for (&(dx, dy), site) in corners.iter().zip(&nodes) {
                let w = if dx == 0 { 1.0 - cell[0].1 } else { cell[0].1 }
                    * if dy == 0 { 1.0 - cell[1].1 } else { cell[1].1 };
                let fitted = fit(Some(&tree), std::slice::from_ref(site), &lattice, &how);
                for (b, q) in blend.iter_mut().zip(fitted) {
                    *b += w * q;
                }
            }
            let blend = d(&directions(&blend));
            let joint = d(&directions(&fit(Some(&tree), &nodes, &lattice, &how)));
            // The same in directions: the lattice through the tree at the normal,
            // fitted to the four nodes on the sphere's square.
            let from: Vec<DVec2> = directions(&lattice)
                .iter()
                .map(|&x| nuld_core::sphere::sphere_to_square(x))
                .collect();
            let joint_directions = fit(None, &nodes, &from, &how);
            let joint_directions: Vec<DVec3> = joint_directions
                .iter()
                .map(|&q| square_to_sphere(q))
                .collect();
            let joint_directions = d(&joint_directions);

            let direct = optimize_directions(&lit, n, &DirectionConfig::default(), &mut |_| {});
            let direct: Vec<DVec3> = direct.iter().map(|&q| square_to_sphere(q)).collect();
            let direct = d(&direct);
            println!(
                "normal {index:2} {normal:.3}: lattice {start:.3}  primary {primary:.3}  \
                 blend {blend:.3}  joint {joint:.3}  joint directions {joint_directions:.3}  \
                 direct {direct:.3}"
            );
            Some([start, primary, blend, joint, joint_directions, direct])
        })
        .collect();
    let k = rows.len() as f64;
    for (j, name) in [
        "lattice",
        "primary",
        "blend",
        "joint",
        "joint directions",
        "direct",
    ]
    .iter()
    .enumerate()
    {
        let mean = rows.iter().map(|r| r[j]).sum::<f64>() / k;
        let worst = rows.iter().map(|r| r[j]).fold(0.0, f64::max);
        println!("{name}: mean {mean:.3}, worst {worst:.3}");
    }
}
