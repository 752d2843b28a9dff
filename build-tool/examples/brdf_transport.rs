//! Whether the BRDF prior's nodes could be blended as *maps* instead of as
//! densities: `cargo run --release -p nuld-build-tool --example brdf_transport
//! -- [K] [BLOB|-] [N CONDITIONS [SIZE]]` (about 40 s, 2 min with a blob). With
//! `N` and `CONDITIONS` (`roughness,view°,metallic` separated by `/`), it prints
//! part 1 alone, for sets of `N` at those conditions, through a prior of `SIZE`
//! vertices a side (default the shipped 96).
//!
//! The shipped prior blends the (up to 8) nodes' densities and inverts the
//! blend exactly: two binary searches, each step a blended read of every node
//! (`core/src/marginal2d.rs`), most of a table-mode sample's time. A
//! *transport* prior tabulates instead each node's own exact warp `T_k(u)`
//! (its marginal then conditional inverse CDF, read from the shipped tables) on
//! a `G x G` grid of knots of the primary square, bilinear between them, and
//! samples the blend of the maps, `T(u) = Σ w_k T_k(u) / Σ w_k` with the
//! multilinear weights `w_k`. Each `T_k` is triangular (`y` from `u.y` alone,
//! `x` increasing in `u.x`), and so is `T`: a bijection of the square whose
//! density is exactly `1 / (∂x/∂u.x ∂y/∂u.y)`, the pdf of the points it
//! produces, read at the same cell corners. A sample reads 6 values per node,
//! independent of each other: no search. (The pdf of an arbitrary direction,
//! for MIS, needs the inverse: a search over the blended map.)
//!
//! Two things make it work. The metallic axis is a *mixture* of the metallic 0
//! and 1 targets, which no blend of their maps follows, so the maps are
//! tabulated at `L` metallic layers (each layer's node the prior's exact
//! mixture there), blended as the other axes are. And a uniform grid of knots
//! leaves the tails of each node's map (`u` near 0 and 1) too coarse, so the
//! knots crowd towards the edges: `s(v) = v - a sin(2 pi v) / (2 pi)` at
//! `v = j / (G - 1)`, found by a guide table at run time.
//!
//! Printed:
//!
//! 1. over the 16 held-out conditions of `eval brdf-prior` and its judge (4096
//!    caps, Owen-Sobol through each condition's exact inverse CDF), the mean
//!    over `K` (default 64) randomly shifted rank-1 lattices of N = 64 of their
//!    cap L2 over the baseline, through the condition's own exact inverse CDF
//!    (the bound of any prior), the shipped prior (`density blend`) and
//!    transport priors of several `L`, `G` and `a`;
//! 2. the same at 12 nodes of the prior's grid, each node's table alone: the
//!    maps' tabulation error apart from the blend;
//! 3. the transport pdf against central differences of its map;
//! 4. ns per sample (f32, 64 conditions in turn, metallic 0, 0.5 and 1, the
//!    median of 5 turns): the warp alone, the pdf at a given square point
//!    (the maps' after inverting their blend) and the whole prior (blend,
//!    warp, direction, pdf and weight `f cos / pdf`), density blend against
//!    the transport prior `L = 5, G = 97, a = 0.97`;
//! 5. with `BLOB` (a `bake --brdf` blob, any N): its table-mode and
//!    network-mode primary points through both priors on `eval brdf-prior
//!    --sets 32`'s judge, and through the maps at metallic 0 and 1 only with
//!    the density blend between; then ns per sample against the incumbent
//!    (Owen-Sobol through the VNDF/cosine mixture warp, f32) and against the
//!    incumbent with the weight a renderer computes after it (`f cos / pdf`):
//!    the runtime's table-mode sample, its primary point alone, that point
//!    through the transport prior, and the same for network mode on decoded
//!    weights; at metallic 0, 0.5 and 1 in turn, then at 0 and 1 alone.
mod conditions;
#[allow(dead_code)]
mod selection;

use glam::{DVec2, DVec3, Vec2};
use nuld_build_tool::lab::eval::brdf_prior::{self, held_out, judging, BrdfPriorSettings};
use nuld_build_tool::lab::eval::prior_judge::Judge;
use nuld_build_tool::seeding::rng;
use nuld_build_tool::sphere::brdf_prior::{BrdfPrior, PriorSpace, PRIOR_GRID};
use nuld_build_tool::sphere::{BrdfTarget, TabulatedWarp};
use nuld_build_tool::train::lattice_generator;
use nuld_core::blob::Domain;
use nuld_core::brdf::{alpha, gltf_metallic, view_direction, view_direction_real};
use nuld_core::brdf_prior::{query_square, reads_metal_layer, unit_condition};
use nuld_core::marginal2d::{Blend, Marginal2D};
use nuld_core::warp::{brdf_mixture_pdf, brdf_mixture_real};
use nuld_runtime::ConditionalSampler;
use rand::Rng;
use rayon::prelude::*;
use std::hint::black_box;
use std::time::Instant;

/// A transport prior: `layers` metallic layers (0: the shipped prior's own
/// nodes, metallic 0 and 1), `g` knots per axis crowded by `crowd`.
#[derive(Clone, Copy, PartialEq)]
struct Variant {
    layers: u32,
    g: usize,
    crowd: f64,
}

impl Variant {
    fn name(self) -> String {
        let layers = match self.layers {
            0 => "shipped nodes".to_string(),
            l => format!("{l} layers"),
        };
        format!("G {}, {layers}, a {}", self.g, self.crowd)
    }
}

/// The transport prior of `printed 4` and `5`.
const PROPOSAL: Variant = Variant {
    layers: 5,
    g: 97,
    crowd: 0.97,
};

/// Every map node's exact warp on a `g x g` grid of knots.
struct Transport {
    g: usize,
    /// `y` of node `k` at `u.y = knots[j]`: `y[k g + j]`.
    y: Vec<f32>,
    /// `x` of node `k` at `(knots[i], knots[j])`: `x[(k g + j) g + i]`.
    x: Vec<f32>,
    knots: Vec<f32>,
    /// The cell of a `u` in `[q, q + 1) / guide.len()` is `guide[q]` or one
    /// of the next few.
    guide: Vec<u32>,
}

impl Transport {
    /// Node `k`'s map is the shipped warp of the blend `nodes[k]`.
    fn new(warp: &Marginal2D<'_, f32>, nodes: &[Blend<f32>], g: usize, crowd: f64) -> Self {
        let tau = 2.0 * std::f64::consts::PI;
        let knots: Vec<f32> = (0..g)
            .map(|j| {
                let v = j as f64 / (g - 1) as f64;
                (v - crowd * (tau * v).sin() / tau) as f32
            })
            .collect();
        let per_node: Vec<(Vec<f32>, Vec<f32>)> = nodes
            .par_iter()
            .map(|node| {
                let y = (0..g)
                    .map(|j| warp.sample([0.5, knots[j]], node).0[1])
                    .collect();
                let x = (0..g * g)
                    .map(|v| warp.sample([knots[v % g], knots[v / g]], node).0[0])
                    .collect();
                (y, x)
            })
            .collect();
        let (y, x): (Vec<Vec<f32>>, Vec<Vec<f32>>) = per_node.into_iter().unzip();
        let guide = (0..4 * g)
            .map(|q| {
                let u = q as f32 / (4 * g) as f32;
                (knots.partition_point(|&k| k <= u).clamp(1, g - 1) - 1) as u32
            })
            .collect();
        Self {
            g,
            y: y.concat(),
            x: x.concat(),
            knots,
            guide,
        }
    }

    /// The primary point that the blended map takes to the square point `p`
    /// and the density there: what `pdf(direction)` needs for MIS. Two
    /// binary searches over the knots, each step a blended read (of one row
    /// of `y`, then of two rows of `x`), and a linear solve in the cell, whose
    /// ends give the density.
    fn invert(&self, p: [f32; 2], blend: &Blend<f32>) -> ([f32; 2], f32) {
        let (g, k) = (self.g, &self.knots);
        let total: f32 = blend.pairs().map(|(_, w)| w).sum();
        // The last cell `[c, c + 1]` whose start `at(c)` is at most `target`.
        let search = |target: f32, at: &dyn Fn(usize) -> f32| {
            let (mut lo, mut hi) = (0, g - 2);
            while lo < hi {
                let mid = (lo + hi).div_ceil(2);
                if at(mid) <= target {
                    lo = mid;
                } else {
                    hi = mid - 1;
                }
            }
            lo
        };
        let y_at = |j: usize| {
            blend
                .pairs()
                .map(|(n, w)| w * self.y[n as usize * g + j])
                .sum::<f32>()
                / total
        };
        let j = search(p[1], &y_at);
        let (y0, y1) = (y_at(j), y_at(j + 1));
        let ty = ((p[1] - y0) / (y1 - y0)).clamp(0.0, 1.0);
        let x_at = |i: usize| {
            blend
                .pairs()
                .map(|(n, w)| {
                    let at = (n as usize * g + j) * g + i;
                    w * (self.x[at] + (self.x[at + g] - self.x[at]) * ty)
                })
                .sum::<f32>()
                / total
        };
        let i = search(p[0], &x_at);
        let (x0, x1) = (x_at(i), x_at(i + 1));
        let tx = ((p[0] - x0) / (x1 - x0)).clamp(0.0, 1.0);
        let (wx, wy) = (k[i + 1] - k[i], k[j + 1] - k[j]);
        let u = [k[i] + tx * wx, k[j] + ty * wy];
        // The map is linear along `u.x` at this `u.y`, and `y` along `u.y`,
        // within the cell: [`Self::sample`]'s Jacobian from the same reads.
        (u, wx * wy / ((x1 - x0) * (y1 - y0)))
    }

    /// The blended map at `u` and its density in the square.
    #[inline]
    fn sample(&self, u: [f32; 2], blend: &Blend<f32>) -> ([f32; 2], f32) {
        let (g, k) = (self.g, &self.knots);
        // The cell, the position in it and `d position / d u`.
        let cell = |u: f32| {
            let u = u.clamp(0.0, 1.0);
            let q = ((u * self.guide.len() as f32) as usize).min(self.guide.len() - 1);
            let mut i = self.guide[q] as usize;
            while i + 2 < g && k[i + 1] <= u {
                i += 1;
            }
            let width = k[i + 1] - k[i];
            (i, ((u - k[i]) / width).clamp(0.0, 1.0), 1.0 / width)
        };
        let ((i, tx, sx), (j, ty, sy)) = (cell(u[0]), cell(u[1]));
        let [mut y, mut dy, mut x, mut dx, mut total] = [0.0f32; 5];
        for (node, w) in blend.pairs() {
            let n = node as usize;
            let (y0, y1) = (self.y[n * g + j], self.y[n * g + j + 1]);
            y += w * (y0 + (y1 - y0) * ty);
            dy += w * (y1 - y0);
            let at = (n * g + j) * g + i;
            let (a, b) = (self.x[at], self.x[at + 1]);
            let (c, d) = (self.x[at + g], self.x[at + g + 1]);
            let (lo, hi) = (a + (b - a) * tx, c + (d - c) * tx);
            x += w * (lo + (hi - lo) * ty);
            dx += w * ((b - a) + ((d - c) - (b - a)) * ty);
            total += w;
        }
        let jacobian = (dx * sx / total) * (dy * sy / total);
        ([x / total, y / total], 1.0 / jacobian)
    }
}

/// The map nodes of `layers` metallic layers at `0, 1 / (layers - 1), ..., 1`
/// in the shared square (each the prior's exact mixture of its metallic 0 and
/// 1 nodes there), then the metal layer's nodes; `layers` 0: the shipped nodes.
fn map_nodes(prior: &BrdfPrior, layers: u32) -> Vec<Blend<f32>> {
    let [gr, gt, _] = prior.grid;
    let layer = gr * gt;
    if layers == 0 {
        return (0..prior.masses.len() as u32).map(Blend::single).collect();
    }
    let mass = |k: u32| prior.masses[k as usize];
    let mut nodes = Vec::new();
    for l in 0..layers {
        let m = l as f32 / (layers - 1) as f32;
        for k in 0..layer {
            let pairs = [(k, (1.0 - m) * mass(k)), (k + layer, m * mass(k + layer))];
            nodes.push(Blend::from_pairs(&pairs));
        }
    }
    nodes.extend((2 * layer..3 * layer).map(Blend::single));
    nodes
}

/// The multilinear blend at `c` of [`map_nodes`]`(layers)`.
fn map_blend(prior: &BrdfPrior, layers: u32, c: [f32; 3]) -> Blend<f32> {
    let [gr, gt, _] = prior.grid;
    if layers == 0 {
        // The shipped blend without its masses.
        let c = c.map(|x| x as f64);
        let pairs: Vec<(u32, f32)> = prior
            .blend(c)
            .pairs()
            .map(|(k, w)| (k, w / prior.masses[k as usize]))
            .collect();
        return Blend::from_pairs(&pairs);
    }
    let unit = unit_condition(c);
    if reads_metal_layer(prior.grid, c[2]) {
        let metal = layers * gr * gt;
        let b = Blend::multilinear(&unit[..2], &[gr, gt]);
        let pairs: Vec<(u32, f32)> = b.pairs().map(|(k, w)| (k + metal, w)).collect();
        Blend::from_pairs(&pairs)
    } else {
        Blend::multilinear(&unit, &[gr, gt, layers])
    }
}

/// The light direction of the square point `p` at condition `c`.
fn direction(c: [f64; 3], p: [f32; 2]) -> DVec3 {
    let wo = view_direction(c[1]).to_array();
    let p = [p[0] as f64, p[1] as f64];
    query_square(PRIOR_GRID, c)
        .direction(wo, p)
        .map_or(DVec3::Z, |(wi, _)| DVec3::from_array(wi))
}

/// The transport prior's whole sample: direction, solid-angle pdf and weight
/// `f cos / pdf`, as `nuld_core::brdf_prior::BrdfPrior::sample_weighted`.
fn sample_weighted(
    prior: &BrdfPrior,
    map: &Transport,
    c: [f32; 3],
    u: [f32; 2],
) -> ([f32; 3], f32, f32) {
    let wo = view_direction_real(c[1]);
    let (p, pdf) = map.sample(u, &map_blend(prior, PROPOSAL.layers, c));
    match query_square(prior.grid, c).direction(wo, p) {
        Some((wi, jac)) => {
            let pdf = pdf / (2.0 * std::f32::consts::PI * jac);
            (wi, pdf, gltf_metallic(wo, wi, c[0], c[2]) * wi[2] / pdf)
        }
        None => ([0.0, 0.0, 1.0], 0.0, 0.0),
    }
}

/// Mean and worst of column `j` of `rows`.
fn summary(rows: &[Vec<f64>], j: usize) -> (f64, f64) {
    let mean = rows.iter().map(|r| r[j]).sum::<f64>() / rows.len() as f64;
    (mean, rows.iter().map(|r| r[j]).fold(0.0, f64::max))
}

/// The median of 5 turns of `f`, each timed on `samples` calls, in ns a call.
fn turns(samples: usize, fs: &[&dyn Fn(usize) -> f32]) -> Vec<f64> {
    let mut figures = vec![Vec::new(); fs.len()];
    for _ in 0..5 {
        for (f, figure) in fs.iter().zip(&mut figures) {
            let start = Instant::now();
            let mut sum = 0.0f32;
            for s in 0..samples {
                sum += f(black_box(s));
            }
            black_box(sum);
            figure.push(start.elapsed().as_nanos() as f64 / samples as f64);
        }
    }
    figures
        .into_iter()
        .map(|mut v| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let k_count: u32 = args.get(1).map_or(64, |s| s.parse().unwrap());
    let prior = match args.get(5) {
        Some(size) => std::sync::Arc::new(
            BrdfPrior::new(PRIOR_GRID, size.parse().unwrap(), PriorSpace::HalfVector).unwrap(),
        ),
        None => BrdfPrior::shared(),
    };
    let warp = prior.warp();
    let variants = [
        (0, 33, 0.0),
        (0, 97, 0.0),
        (5, 97, 0.0),
        (9, 97, 0.0),
        (5, 97, 0.9),
        (5, 97, 0.97),
        (9, 97, 0.97),
        (5, 129, 0.97),
    ]
    .map(|(layers, g, crowd)| Variant { layers, g, crowd });
    let start = Instant::now();
    let maps: Vec<Transport> = variants
        .iter()
        .map(|v| Transport::new(&warp, &map_nodes(&prior, v.layers), v.g, v.crowd))
        .collect();
    let proposal = &maps[variants.iter().position(|&v| v == PROPOSAL).unwrap()];
    eprintln!("maps: {:.1} s", start.elapsed().as_secs_f64());

    // 1. Held-out conditions.
    let n: u32 = args.get(3).map_or(64, |s| s.parse().unwrap());
    let listed = args.get(4).map(|list| conditions::parse(list));
    let only_listed = listed.is_some();
    let candidates = selection::candidates(n, lattice_generator(n), k_count);
    let settings = BrdfPriorSettings {
        n,
        ..BrdfPriorSettings::default()
    };
    let score_at = |judge: &Judge<BrdfTarget>, to: &dyn Fn(DVec2) -> DVec3| {
        selection::mean_score_through(&candidates, judge, to)
    };
    let f32u = |u: DVec2| [u.x as f32, u.y as f32];
    let rows: Vec<Vec<f64>> = (listed.unwrap_or_else(|| held_out(&settings)))
        .par_iter()
        .enumerate()
        .map(|(index, &c)| {
            let judge = brdf_prior::judge(c, &judging(&settings), index as u64).unwrap();
            let target = BrdfTarget::metallic(c[0], c[1], c[2], Domain::Hemisphere).unwrap();
            let exact = TabulatedWarp::new(&target, 1024, 2).unwrap();
            let mut row = vec![
                score_at(&judge, &|u| exact.warp(u)),
                score_at(&judge, &|u| prior.sample(&warp, c, u).0),
            ];
            for (v, map) in variants.iter().zip(&maps) {
                let b = map_blend(&prior, v.layers, c.map(|x| x as f32));
                row.push(score_at(&judge, &|u| {
                    direction(c, map.sample(f32u(u), &b).0)
                }));
            }
            selection::print_row(c, &row);
            row
        })
        .collect();
    let mut names = vec!["exact inverse CDF".to_string(), "density blend".to_string()];
    names.extend(variants.iter().map(|v| v.name()));
    println!(
        "held-out: {} conditions, N = {n}, K = {k_count}",
        rows.len()
    );
    for (j, name) in names.iter().enumerate() {
        let (mean, worst) = summary(&rows, j);
        println!("{name:>28}: mean {mean:.3}, worst {worst:.3}");
    }
    if only_listed {
        return;
    }

    // 2. At nodes, each node's table alone.
    let node_maps: Vec<(String, Transport)> = [(97, 0.0), (193, 0.0), (97, 0.9), (97, 0.97)]
        .into_iter()
        .map(|(g, crowd)| {
            let name = format!("G {g}, a {crowd}");
            (name, Transport::new(&warp, &map_nodes(&prior, 0), g, crowd))
        })
        .collect();
    let picks = [3u32, 15, 27, 38, 52, 66, 80, 95, 107, 118, 245, 300];
    let node_rows: Vec<Vec<f64>> = picks
        .par_iter()
        .map(|&k| {
            let c = BrdfPrior::node_condition(PRIOR_GRID, k);
            let judge = brdf_prior::judge(c, &judging(&settings), 500 + k as u64).unwrap();
            let single = Blend::single(k);
            let mut row = vec![score_at(&judge, &|u| {
                direction(c, warp.sample(f32u(u), &single).0)
            })];
            for (_, map) in &node_maps {
                row.push(score_at(&judge, &|u| {
                    direction(c, map.sample(f32u(u), &single).0)
                }));
            }
            row
        })
        .collect();
    println!("at {} nodes, each node's table alone:", picks.len());
    let mut names = vec!["density".to_string()];
    names.extend(node_maps.iter().map(|(name, _)| name.clone()));
    for (j, name) in names.iter().enumerate() {
        println!("{name:>28}: mean {:.3}", summary(&node_rows, j).0);
    }

    // 3. The pdf against central differences of the map, inside a cell.
    let mut r = rng(0, 0x7472_616e);
    let mut next = || r.random::<f64>();
    let (mut worst, mut checked) = (0.0f64, 0);
    let knots = &proposal.knots;
    for _ in 0..2000 {
        let m = [0.0, 0.5, 1.0][(next() * 3.0) as usize];
        let c = [0.1 + 0.9 * next(), 85.0 * next(), m].map(|x| x as f32);
        let blend = map_blend(&prior, PROPOSAL.layers, c);
        let u = [next() as f32, next() as f32];
        let h = 2e-4f32;
        let near = |v: f32| knots.iter().any(|&k| (k - v).abs() < 2.0 * h);
        if near(u[0]) || near(u[1]) {
            continue;
        }
        let at = |u: [f32; 2]| proposal.sample(u, &blend).0.map(|x| x as f64);
        let (xp, xm) = (at([u[0] + h, u[1]]), at([u[0] - h, u[1]]));
        let (yp, ym) = (at([u[0], u[1] + h]), at([u[0], u[1] - h]));
        let h2 = (2.0 * h as f64).powi(2);
        let det = ((xp[0] - xm[0]) * (yp[1] - ym[1]) - (xp[1] - xm[1]) * (yp[0] - ym[0])) / h2;
        let pdf = proposal.sample(u, &blend).1 as f64;
        worst = worst.max((pdf * det - 1.0).abs());
        checked += 1;
    }
    println!(
        "{}: pdf against central differences at {checked} points: worst relative error {worst:.1e}",
        PROPOSAL.name()
    );

    // 4. Cost.
    let conds: Vec<[f32; 3]> = (0..64)
        .map(|k| [0.1 + 0.9 * next(), 89.0 * next(), [0.0, 0.5, 1.0][k % 3]].map(|x| x as f32))
        .collect();
    let density_blends: Vec<Blend<f32>> = conds
        .iter()
        .map(|c| prior.blend(c.map(|x| x as f64)))
        .collect();
    let map_blends: Vec<Blend<f32>> = conds
        .iter()
        .map(|&c| map_blend(&prior, PROPOSAL.layers, c))
        .collect();
    let us: Vec<[f32; 2]> = (0..4096).map(|_| [next() as f32, next() as f32]).collect();
    let samples = 2_000_000;
    let u_at = |s: usize| us[s % us.len()];
    let figures = turns(
        samples,
        &[
            &|s| {
                let (p, pdf) = warp.sample(u_at(s), &density_blends[s % 64]);
                p[0] + p[1] + pdf
            },
            &|s| {
                let (p, pdf) = proposal.sample(u_at(s), &map_blends[s % 64]);
                p[0] + p[1] + pdf
            },
        ],
    );
    println!(
        "the warp alone, ns per sample: density blend {:.1}, {} {:.1}",
        figures[0],
        PROPOSAL.name(),
        figures[1]
    );
    let core = prior.core().unwrap();
    let figures = turns(
        samples,
        &[
            &|s| {
                let (d, pdf, w) = core.sample_weighted(conds[s % 64], u_at(s));
                d[0] + pdf + w
            },
            &|s| {
                let (d, pdf, w) = sample_weighted(&prior, proposal, conds[s % 64], u_at(s));
                d[0] + pdf + w
            },
        ],
    );
    println!(
        "the whole prior (sample_weighted), ns per sample: density blend {:.1}, {} {:.1}",
        figures[0],
        PROPOSAL.name(),
        figures[1]
    );
    // The pdf at a given square point (MIS): the density blend reads its
    // cell's corners; the maps invert their blend first.
    let points: Vec<[f32; 2]> = (0..4096)
        .map(|s| proposal.sample(u_at(s), &map_blends[s % 64]).0)
        .collect();
    // The round trip: the point back, and the pdf as the sample gave it.
    let (worst_u, worst_pdf) = (0..4096)
        .map(|s| {
            let (u, pdf) = proposal.invert(points[s], &map_blends[s % 64]);
            let want = proposal.sample(u_at(s), &map_blends[s % 64]).1;
            let du = (u[0] - u_at(s)[0]).abs().max((u[1] - u_at(s)[1]).abs());
            (du, (pdf / want - 1.0).abs())
        })
        .fold((0.0f32, 0.0f32), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    let pdfs = turns(
        samples,
        &[
            &|s| warp.pdf(points[s % 4096], &density_blends[s % 64]),
            &|s| proposal.invert(points[s % 4096], &map_blends[s % 64]).1,
        ],
    );
    println!(
        "the pdf at a square point, ns: density blend {:.1}, {} (inverting the map; \
         |u - invert(sample(u))| at most {worst_u:.1e}, its pdf within {worst_pdf:.1e} \
         of the sample's) {:.1}",
        pdfs[0],
        PROPOSAL.name(),
        pdfs[1]
    );

    // 5. A blob's points.
    let Some(path) = args.get(2).filter(|p| *p != "-") else {
        return;
    };
    let bytes = std::fs::read(path).unwrap();
    let blob = nuld_runtime::Blob::parse(bytes.as_slice()).unwrap();
    let cs = blob.brdf().unwrap().conditional();
    judge_blob(&prior, &warp, proposal, &cs);
    println!("metallic 0, 0.5 and 1 in turn:");
    blob_cost(&prior, proposal, &cs, &conds, samples);
    let ends: Vec<[f32; 3]> = conds
        .iter()
        .enumerate()
        .map(|(k, &[r, t, _])| [r, t, (k % 2) as f32])
        .collect();
    println!("metallic 0 and 1 in turn (where the maps would serve alone):");
    blob_cost(&prior, proposal, &cs, &ends, samples);
}

/// ns per sample, the median of 5 turns of `samples`, at `conds` in turn:
/// the incumbent, without and with its weight, and the blob's table and
/// network modes through the density blend and through `map`.
fn blob_cost(
    prior: &BrdfPrior,
    map: &Transport,
    cs: &ConditionalSampler<'_>,
    conds: &[[f32; 3]],
    samples: usize,
) {
    let n = cs.len();
    let count = conds.len();
    let incumbents: Vec<([f32; 3], f32, f32)> = conds
        .iter()
        .map(|c| {
            let c = c.map(|x| x as f64);
            let t = BrdfTarget::metallic(c[0], c[1], c[2], Domain::Hemisphere).unwrap();
            let wo = view_direction(c[1]).as_vec3().to_array();
            (wo, alpha(c[0]) as f32, t.lobe_probability() as f32)
        })
        .collect();
    let mut buf = vec![0.0f32; cs.decoded_network_len()];
    let decoded = cs.decode_network(&mut buf).unwrap();
    // Instance `s / n` mod 64, index `s mod n`, condition `s` mod their count.
    let at = |s: usize| (conds[s % count], (s as u32 / n) % 64, s as u32 % n);
    // The incumbent's direction: instance `k`'s Owen-Sobol point `i` through
    // the mixture warp.
    let incumbent = |s: usize| {
        let (wo, a, ps) = incumbents[s % count];
        let (_, k, i) = at(s);
        let seed = nuld_core::network::hash_u32(k);
        let u = [
            sobol_burley::sample(i, 0, seed),
            sobol_burley::sample(i, 1, seed),
        ];
        brdf_mixture_real(wo, a, ps, u)
    };
    let figures = turns(
        samples,
        &[
            &|s| incumbent(s)[0],
            &|s| {
                // The weight a renderer computes after the incumbent's
                // sample: the mixture's pdf and the BRDF (in f64, as `bench
                // --only runtime`'s row of it).
                let (wo, a, ps) = incumbents[s % count];
                let c = at(s).0;
                let d = incumbent(s).map(|x| x as f64);
                let wo = wo.map(|x| x as f64);
                let pdf = brdf_mixture_pdf(wo.into(), a as f64, ps as f64, d.into());
                let f = gltf_metallic(wo, d, c[0] as f64, c[2] as f64);
                (d[0] + f * d[2] / pdf) as f32
            },
            &|s| {
                let ([r, t, m], k, i) = at(s);
                let sample = cs.sample_metallic(Vec2::new(r, t), m, k, i);
                sample.direction.x + sample.weight
            },
            &|s| {
                let ([r, t, m], k, i) = at(s);
                cs.square_point_metallic(Vec2::new(r, t), m, k, i).x
            },
            &|s| {
                let (c, k, i) = at(s);
                let p = cs.square_point_metallic(Vec2::new(c[0], c[1]), c[2], k, i);
                let (d, _, w) = sample_weighted(prior, map, c, p.to_array());
                d[0] + w
            },
            &|s| {
                let ([r, t, m], k, i) = at(s);
                let sample = decoded.sample_metallic(Vec2::new(r, t), m, k, i);
                sample.direction.x + sample.weight
            },
            &|s| {
                let (c, k, i) = at(s);
                let p = decoded.square_point_metallic(Vec2::new(c[0], c[1]), c[2], k, i);
                let (d, _, w) = sample_weighted(prior, map, c, p.to_array());
                d[0] + w
            },
        ],
    );
    println!("ns per sample (/ the incumbent, / the incumbent with its weight):");
    let names = [
        "incumbent (f32)",
        "incumbent + weight",
        "runtime table mode",
        "its primary point alone",
        "that point, transport",
        "runtime network (decoded)",
        "its point, transport",
    ];
    for (name, t) in names.iter().zip(&figures) {
        let ratios = (t / figures[0], t / figures[1]);
        println!("{name:>28}: {t:.1} ({:.2}x, {:.2}x)", ratios.0, ratios.1);
    }
}

/// `eval brdf-prior --sets 32`'s judge of the table-mode and network-mode
/// primary points of `cs` through the density blend and through `map`.
fn judge_blob(
    prior: &BrdfPrior,
    warp: &Marginal2D<'_, f32>,
    map: &Transport,
    cs: &ConditionalSampler<'_>,
) {
    let sets = 32;
    // The judge's baseline is Owen-Sobol sets of the blob's own N.
    let settings = BrdfPriorSettings {
        n: cs.len(),
        instances: sets,
        ..BrdfPriorSettings::default()
    };
    let conds = held_out(&settings);
    let rows: Vec<Vec<f64>> = conds
        .par_iter()
        .enumerate()
        .map(|(index, &c)| {
            let judge = brdf_prior::judge(c, &judging(&settings), index as u64).unwrap();
            let (cond, m) = (Vec2::new(c[0] as f32, c[1] as f32), c[2] as f32);
            let blend = map_blend(prior, PROPOSAL.layers, c.map(|x| x as f32));
            let mut row = vec![0.0; 4];
            for k in 0..sets {
                let table: Vec<[f32; 2]> = (0..cs.len())
                    .map(|i| cs.square_point_metallic(cond, m, k, i).to_array())
                    .collect();
                let network: Vec<[f32; 2]> = (0..cs.len())
                    .map(|i| cs.network().square_point_metallic(cond, m, k, i).to_array())
                    .collect();
                for (j, points) in [&table, &network].into_iter().enumerate() {
                    let density: Vec<DVec3> = points
                        .iter()
                        .map(|&u| {
                            prior
                                .sample(warp, c, DVec2::new(u[0] as f64, u[1] as f64))
                                .0
                        })
                        .collect();
                    let moved: Vec<DVec3> = points
                        .iter()
                        .map(|&u| direction(c, map.sample(u, &blend).0))
                        .collect();
                    row[2 * j] += judge.d(&density) / judge.baseline() / sets as f64;
                    row[2 * j + 1] += judge.d(&moved) / judge.baseline() / sets as f64;
                }
            }
            // The maps at metallic 0 and 1 (the metal layer), the density
            // blend between.
            let ends = c[2] <= 0.0 || reads_metal_layer(prior.grid, c[2]);
            let pick = usize::from(ends);
            row.extend([row[pick], row[2 + pick]]);
            selection::print_row(c, &row);
            row
        })
        .collect();
    println!("the blob's points, {sets} sets:");
    let names = [
        "table, density blend",
        "table, transport",
        "network, density blend",
        "network, transport",
        "table, maps at 0 and 1",
        "network, maps at 0 and 1",
    ];
    for (j, name) in names.iter().enumerate() {
        let (mean, worst) = summary(&rows, j);
        // Metallic 0, 0.5, 1 and the held-out conditions' uniform ones.
        let groups: [&dyn Fn(f64) -> bool; 4] =
            [&|m| m == 0.0, &|m| m == 0.5, &|m| m == 1.0, &|m| {
                ![0.0, 0.5, 1.0].contains(&m)
            }];
        let by_metallic: Vec<String> = groups
            .iter()
            .map(|keep| {
                let v: Vec<f64> = rows
                    .iter()
                    .zip(&conds)
                    .filter(|(_, c)| keep(c[2]))
                    .map(|(r, _)| r[j])
                    .collect();
                format!("{:.3}", v.iter().sum::<f64>() / v.len() as f64)
            })
            .collect();
        println!(
            "{name:>28}: mean {mean:.4}, worst {worst:.3}, metallic 0 / 0.5 / 1 / others: {}",
            by_metallic.join(" / ")
        );
    }
}
