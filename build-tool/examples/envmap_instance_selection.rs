//! Whether choosing, per normal of a table, which of a baked environment
//! sampler's trained instances to serve beats serving them all:
//! `cargo run --release -p nuld-build-tool --example envmap_instance_selection -- MAP BLOB [K]`.
//!
//! The candidates are the blob's table-mode instances `0..64` at the query's
//! normal, and (for comparison) the first `K` (default 256) salted shifts of the
//! rank-1 lattice through the prior, as `envmap_selection` draws them. At each of
//! the check's 16 held-out normals, on the check's judge, prints the mean over
//! the trained instances, the best 8 chosen at the held-out normal by other caps,
//! and the best 8 chosen at a node of a `G x G` table half a cell away along
//! both axes of the octahedral square (a nearest-node table's worst case) and a
//! quarter cell away (about its typical distance), by the node's own judge on
//! the sets at the node, each scored at the held-out normal with the chosen
//! instances evaluated there; and the same choices among the lattice shifts and
//! among both kinds together. Results: docs/results/envmap.md#instance-selection.
mod check;
mod selection;

use glam::{DVec2, DVec3, Vec3};
use nuld_build_tool::lab::eval::prior_judge::Judge;
use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;

/// Table sizes whose nodes choose: the bake's grid and three finer ones.
const GRIDS: [usize; 4] = [13, 25, 49, 97];

/// How many chosen candidates a table keeps per node (its instances).
const KEPT: usize = 8;

/// The trained candidates: the blob's table-mode instances `0..TRAINED` (the
/// default bake's 64 stored instances).
const TRAINED: u32 = 64;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(3..=4).contains(&args.len()) {
        eprintln!("usage: envmap_instance_selection MAP BLOB [K]");
        std::process::exit(2);
    }
    let k_count: u32 = args.get(3).map_or(256, |s| s.parse().unwrap());
    let n = 64;
    let (shape, env) = check::load(&args[1], n);
    let tree = env.tree.tree();
    let bytes = AlignedBytes::read(std::path::Path::new(&args[2])).unwrap();
    let sampler = nuld_runtime::Blob::parse(bytes.as_slice())
        .unwrap()
        .envmap()
        .unwrap();
    let n = sampler.len();
    let lattice = selection::candidates(n, shape.lattice_generator(), k_count);
    // Every candidate's directions at the normal of octahedral point `u`: the
    // trained instances first, then the lattice shifts.
    let sets_at = |u: [f64; 2]| -> Vec<Vec<DVec3>> {
        let normal = square_to_sphere(DVec2::from(u));
        let nf = Vec3::new(normal.x as f32, normal.y as f32, normal.z as f32);
        let mut sets: Vec<Vec<DVec3>> = (0..TRAINED)
            .map(|k| {
                (0..n)
                    .map(|i| sampler.sample(nf, k, i).direction.as_dvec3().normalize())
                    .collect()
            })
            .collect();
        sets.extend(lattice.iter().map(|set| {
            set.iter()
                .map(|&p| DVec3::from(tree.sample_square(u, p.to_array()).0))
                .collect()
        }));
        sets
    };
    let judge = |u: [f64; 2], index: u64| -> Option<Judge<[f64; 2]>> {
        Some(check::judge(&check::lit(&env.map, u)?, u, n, index))
    };
    let t = TRAINED as usize;
    // Of the scores `at_u` (held out) and `choice` (the chooser's), the mean of
    // the best KEPT by `choice` among the trained, the lattice and both.
    let choices = |at_u: &[f64], choice: &[f64]| -> [f64; 3] {
        let pick = |range: std::ops::Range<usize>| {
            let order: Vec<usize> = selection::ranking(&choice[range.clone()])
                .into_iter()
                .map(|k| k + range.start)
                .collect();
            selection::mean_of(at_u, &order, KEPT)
        };
        [pick(0..t), pick(t..choice.len()), pick(0..choice.len())]
    };
    let rows: Vec<Vec<f64>> = (0..check::NORMALS)
        .into_par_iter()
        .filter_map(|index| {
            let u = check::held_out(index);
            let held_out = judge(u, index as u64)?;
            let at_u = selection::scores(&sets_at(u), &held_out);
            let mut row = vec![
                at_u[..t].iter().sum::<f64>() / t as f64,
                at_u[..8].iter().sum::<f64>() / 8.0,
                at_u[t..].iter().sum::<f64>() / (at_u.len() - t) as f64,
            ];
            let other = judge(u, 2000 + index as u64)?;
            row.extend(choices(&at_u, &selection::scores(&sets_at(u), &other)));
            for (j, grid) in GRIDS.iter().enumerate() {
                for (e, frac) in [0.5, 0.25].into_iter().enumerate() {
                    let d = frac / (grid - 1) as f64;
                    let node = [u[0] + d, u[1] + d];
                    let node_judge = judge(node, 1000 + (32 * j + 16 * e + index) as u64)?;
                    row.extend(choices(
                        &at_u,
                        &selection::scores(&sets_at(node), &node_judge),
                    ));
                }
            }
            eprintln!("normal {index:2}: {row:.3?}");
            Some(row)
        })
        .collect();
    let cols = rows[0].len();
    let mean: Vec<f64> = (0..cols)
        .map(|c| rows.iter().map(|r| r[c]).sum::<f64>() / rows.len() as f64)
        .collect();
    let worst: Vec<f64> = (0..cols)
        .map(|c| rows.iter().map(|r| r[c]).fold(0.0, f64::max))
        .collect();
    let mut names = vec![
        "trained, all 64".to_string(),
        "trained, 0-7".to_string(),
        "lattice, all".to_string(),
    ];
    for at in std::iter::once("other caps".to_string()).chain(GRIDS.iter().flat_map(|g| {
        [
            format!("{g}x{g} half cell"),
            format!("{g}x{g} quarter cell"),
        ]
    })) {
        for kind in ["trained", "lattice", "both"] {
            names.push(format!("{at}: best {KEPT} {kind}"));
        }
    }
    println!("| choice | mean | worst |\n|---|---:|---:|");
    for ((name, m), w) in names.iter().zip(&mean).zip(&worst) {
        println!("| {name} | {m:.3} | {w:.3} |");
    }
}
