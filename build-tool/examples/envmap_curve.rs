//! Whether the environment prior's tree, descended along a space-filling curve
//! by one primary coordinate instead of by columns and rows, takes a shifted
//! lattice closer to the goal: `cargo run --release -p nuld-build-tool --example
//! envmap_curve -- MAP [N] [K]`.
//!
//! Today's descent (`quadtree::descend`) picks a column by `u.x` and a row in it
//! by `u.y` at every level: a node's count of a set's points is right to within
//! the lattice's box discrepancy, which grows with depth. A descent that orders
//! each node's four children along the Hilbert curve (or in Morton order) and
//! picks one by `u.x` alone, rescaling `u.x` into it, gives every node of every
//! level `floor` or `ceil` of its share of a rank-1 lattice's points, since a
//! node's subtree is one interval of `u.x` and the lattice's `u.x` are evenly
//! spaced; `u.y` and the rest of `u.x` place the point inside its leaf. Each child
//! is still chosen with probability `w_k / Σ w`, so the density and the pdf are
//! the tree's, exactly: only the map from the primary square changes.
//!
//! At the check's 16 held-out normals and judge (4096 caps, over 8 Owen-Sobol
//! sets through each normal's exact inverse CDF), the mean over `K` (default 32)
//! shifts of the bake's rank-1 lattice of `N` (default 64) points, through:
//! the tree (today), the Hilbert descent, the Morton descent. With `SCAN=1` in
//! the environment it instead scores, through the tree, the lattice of every
//! odd generator `g < N / 2` (the bake takes the one of the largest Zaremba
//! index, ties to the longest shortest vector, `train::lattice_generator`);
//! with `SETS=net-xor`, `net-shift` or `owen-sobol` as well, it scores `K` sets
//! of another kind through the tree instead, each as uniform per point as a
//! shifted lattice (what the unbiased mode needs): the Hammersley net `(i / N,
//! radical inverse of i)` (a `(0, m, 2)`-net for `N = 2^m`) under a random
//! digital shift (both coordinates' bits XOR a random word) or a random
//! toroidal shift, or Owen-scrambled Sobol.
mod check;
mod selection;

use glam::{DVec2, DVec3};
use nuld_core::quadtree::{self, ChildWeights, Node};
use rayon::prelude::*;

/// The canonical Hilbert order of a node's four children, `(i, j)`.
const HILBERT: [(u32, u32); 4] = [(0, 0), (0, 1), (1, 1), (1, 0)];
/// The transform (swap, flip) each canonical child's sub-curve adds.
const HILBERT_SUB: [(bool, bool); 4] =
    [(true, false), (false, false), (false, false), (true, true)];

/// Descends `tree` by `u.x` alone, children in Hilbert order (`hilbert`) or
/// Morton order, and returns the square point in the uniform leaf.
fn curve_descent(tree: &impl ChildWeights<f64>, u: [f64; 2], hilbert: bool) -> [f64; 2] {
    let levels = tree.levels();
    let mut t = u[0].clamp(0.0, 1.0);
    let mut node = Node::ROOT;
    let (mut swap, mut flip) = (false, false);
    for _ in 0..levels {
        let w = quadtree::usable(tree.children(node));
        // Children in curve order: their index `i + 2 j` and their transform.
        let order: [(u32, (bool, bool)); 4] = core::array::from_fn(|k| {
            if hilbert {
                let (mut i, mut j) = HILBERT[k];
                if swap {
                    (i, j) = (j, i);
                }
                if flip {
                    (i, j) = (1 - i, 1 - j);
                }
                let (s, f) = HILBERT_SUB[k];
                (i + 2 * j, (swap ^ s, flip ^ f))
            } else {
                (k as u32, (false, false))
            }
        });
        let total: f64 = w.iter().sum();
        let mut acc = 0.0;
        let mut chosen = None;
        for (k, &(c, tr)) in order.iter().enumerate() {
            let share = w[c as usize] / total;
            let last = (k + 1..4).all(|m| w[order[m].0 as usize] <= 0.0);
            if share > 0.0 && (t < acc + share || last) {
                t = ((t - acc) / share).clamp(0.0, 1.0);
                chosen = Some((c, tr));
                break;
            }
            acc += share;
        }
        let (c, tr) = chosen.expect("a child with weight");
        (swap, flip) = tr;
        node = node.child(c);
    }
    quadtree::leaf_point(levels, [node.x, node.y], [t, u[1].clamp(0.0, 1.0)])
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=4).contains(&args.len()) {
        eprintln!("usage: envmap_curve MAP [N] [K]");
        std::process::exit(2);
    }
    let arg = |k: usize, default: usize| args.get(k).map_or(default, |s| s.parse().unwrap());
    let (n, k_count) = (arg(2, 64) as u32, arg(3, 32) as u32);
    let (shape, env) = check::load(&args[1], n);
    let tree = env.tree.tree();
    if std::env::var("SCAN").is_ok() {
        println!("the bake's generator: g = {}", shape.lattice_generator());
        scan_generators(&env, n, k_count);
        return;
    }
    let candidates = selection::candidates(n, shape.lattice_generator(), k_count);
    let names = ["tree", "hilbert", "morton"];
    let rows: Vec<(usize, Vec<f64>)> = (0..check::NORMALS)
        .into_par_iter()
        .filter_map(|index| {
            let u = check::held_out(index);
            let lit = check::lit(&env.map, u)?;
            let judge = check::judge(&lit, u, n, index as u64);
            let lit_tree = tree.lit_square(u);
            // The shaped leaf: the primary point today's descent maps to the
            // uniform leaf's point, through today's warp (which shapes it).
            let shaped = |p: [f64; 2]| -> DVec3 {
                let v = quadtree::invert(&lit_tree, p);
                DVec3::from(tree.sample_square(u, v).0)
            };
            let row = (0..3)
                .map(|m| {
                    let to = |p: DVec2| -> DVec3 {
                        match m {
                            0 => DVec3::from(tree.sample_square(u, p.to_array()).0),
                            _ => shaped(curve_descent(&lit_tree, p.to_array(), m == 1)),
                        }
                    };
                    selection::mean_score_through(&candidates, &judge, &to)
                })
                .collect();
            Some((index, row))
        })
        .collect();
    for (index, row) in &rows {
        let cells: Vec<String> = row.iter().map(|x| format!("{x:.3}")).collect();
        println!("normal {index:2}: {}", cells.join(" "));
    }
    for (m, name) in names.iter().enumerate() {
        let v: Vec<f64> = rows.iter().map(|(_, r)| r[m]).collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let worst = v.iter().cloned().fold(0.0, f64::max);
        println!("{name}: mean {mean:.3} (worst {worst:.3})");
    }
}

/// The mean (worst) over the held-out normals of `K` shifts of the rank-1
/// lattice of every odd generator `g < N / 2` through the tree.
fn scan_generators(env: &nuld_build_tool::train::target::EnvmapTarget, n: u32, k_count: u32) {
    let tree = env.tree.tree();
    // `ALT=1`: 25 other normals, the cell centres of a 5 x 5 grid on the
    // octahedral square (none of them the check's), to choose on.
    let alt = std::env::var("ALT").is_ok();
    let count = if alt { 25 } else { check::NORMALS };
    let only: Option<Vec<u32>> = std::env::var("GENERATORS")
        .ok()
        .map(|s| s.split(',').map(|g| g.parse().unwrap()).collect());
    let judges: Vec<_> = (0..count)
        .into_par_iter()
        .filter_map(|index| {
            let u = if alt {
                [
                    ((index % 5) as f64 + 0.5) / 5.0,
                    ((index / 5) as f64 + 0.5) / 5.0,
                ]
            } else {
                check::held_out(index)
            };
            let lit = check::lit(&env.map, u)?;
            let caps = if alt { 3000 + index } else { index };
            Some((u, check::judge(&lit, u, n, caps as u64)))
        })
        .collect();
    let score = |name: &str, candidates: &[Vec<DVec2>]| {
        let v: Vec<f64> = judges
            .par_iter()
            .map(|(u, judge)| {
                let to = |p: DVec2| DVec3::from(tree.sample_square(*u, p.to_array()).0);
                selection::mean_score_through(candidates, judge, &to)
            })
            .collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let worst = v.iter().cloned().fold(0.0, f64::max);
        println!("{name}: mean {mean:.3} (worst {worst:.3})");
    };
    if let Ok(kind) = std::env::var("SETS") {
        score(&kind, &other_sets(&kind, n, k_count));
        return;
    }
    let all: Vec<u32> = (1..n / 2).step_by(2).collect();
    for &g in only.as_ref().unwrap_or(&all) {
        score(&format!("g {g:3}"), &selection::candidates(n, g, k_count));
    }
}

/// `count` sets of `n` points of `kind` (`net-xor`, `net-shift`, `owen-sobol`;
/// the module docs), set `k` randomized by hashes of `k`.
fn other_sets(kind: &str, n: u32, count: u32) -> Vec<Vec<DVec2>> {
    const WORD: f64 = 4294967296.0;
    (0..count)
        .map(|k| {
            let h = |s: u32| nuld_core::network::hash_u32(k.wrapping_mul(7919).wrapping_add(s));
            let (xor, shift) = ([h(1), h(2)], [h(3) as f64 / WORD, h(4) as f64 / WORD]);
            (0..n)
                .map(|i| {
                    // The net's coordinates as 32-bit words: `i / n` and the
                    // radical inverse of `i` in base 2.
                    let bits = [
                        ((i as u64) << 32).div_euclid(n as u64) as u32,
                        i.reverse_bits(),
                    ];
                    let [x, y] = match kind {
                        "net-xor" => [0, 1].map(|a| ((bits[a] ^ xor[a]) as f64 + 0.5) / WORD),
                        "net-shift" => [0, 1].map(|a| (bits[a] as f64 / WORD + shift[a]).fract()),
                        "owen-sobol" => [0, 1].map(|a| sobol_burley::sample(i, a, h(5)) as f64),
                        _ => panic!("SETS: net-xor, net-shift or owen-sobol, not {kind}"),
                    };
                    DVec2::new(x, y)
                })
                .collect()
        })
        .collect()
}
