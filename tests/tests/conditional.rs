//! The runtime's conditional sampler against the tool's side of the same blob: the
//! network mode against the tool's `f64` evaluation of the same f16 weights, the
//! table mode and the weights against an interpolation written out here from the
//! formulas of core/FORMAT.md.

use glam::{DVec2, DVec3, Vec2};
use nuld_build_tool::conditional::blob::ConditionalParts;
use nuld_build_tool::sphere::brdf_prior::BrdfPrior;
use nuld_core::blob::Domain;
use nuld_core::brdf::{gltf_metallic, view_direction_real};
use nuld_core::conditional::{brdf_mixture_direction, PointWarp};
use nuld_core::envmap_tree::FINE_SIDE;
use nuld_core::network::{input_features, Activation, Network};
use nuld_core::quantize::f16_decode;
use nuld_core::real::Real;
use nuld_core::sphere::square_to_hemisphere_real;
use nuld_runtime::{Blob, ConditionalSampler};
use nuld_tests::{
    as_envmap, conditional_parts, fixture_tree, shape, with_metal_points, with_metallic_axis, META,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The shapes of the runtime benchmark: n 64, hidden [32, 32], ReLU and SiLU,
/// with the equal-area map and (ReLU) with the BRDF mixture warp and the
/// tabulated BRDF prior, without instance slots and (the default bake's) with
/// 64, and 7 slots (instances wrap at another count than the table's 16); the
/// tabulated prior's also with the default bake's metallic axis
/// ([`METALLIC_NODES`]); and an environment sampler on its tree
/// ([`as_envmap`]); the environment sampler last.
fn fixtures() -> Vec<ConditionalParts> {
    [
        (Activation::Relu, PointWarp::EqualArea, 0, 1),
        (Activation::Silu, PointWarp::EqualArea, 7, 2),
        (Activation::Relu, PointWarp::BrdfMixture, 0, 3),
        (Activation::Relu, PointWarp::BrdfMixture, 64, 4),
        (Activation::Relu, PointWarp::BrdfTable, 64, 6),
        (Activation::Relu, PointWarp::BrdfTable, 64, 7),
        (Activation::Silu, PointWarp::EnvmapTree, 64, 5),
    ]
    .into_iter()
    .map(|(act, warp, slots, seed)| {
        let parts = conditional_parts(shape(64, &[32, 32], act, warp, slots), 16, [10, 9], seed);
        match warp {
            PointWarp::EnvmapTree => as_envmap(parts),
            // The shared prior has the metal layer: the metal points serve it.
            PointWarp::BrdfTable if seed == 7 => {
                let parts = with_metal_points(parts, seed + 100);
                with_metallic_axis(parts, &METALLIC_NODES, seed + 200)
            }
            PointWarp::BrdfTable => with_metal_points(parts, seed + 100),
            _ => parts,
        }
    })
    .collect()
}

/// The metallic axis of the fixture that has one (the default bake's).
const METALLIC_NODES: [f32; 3] = [0.0, 0.5, 0.95];

/// A metallic drawn over `[0, 1]` and a tenth beyond on each side, with the
/// occasional node, end or NaN.
fn metallic(rng: &mut Pcg64Mcg) -> f32 {
    match rng.random_range(0..10) {
        0 => METALLIC_NODES[rng.random_range(0..3)],
        1 => [0.0, 1.0, f32::NAN][rng.random_range(0..3)],
        _ => rng.random_range(-0.1f32..1.1),
    }
}

/// The metallic-axis cell of `m` as core/FORMAT.md writes it: `m` clamped into
/// `[nodes[0], nodes[L - 1]]` (NaN as `nodes[0]`), `j0` the last layer below
/// `L - 1` whose node is `<= m`, `t = (m - nodes[j0]) / (nodes[j0 + 1] -
/// nodes[j0])`.
fn metallic_cell(nodes: &[f32], m: f32) -> (usize, f32) {
    let m = if m.is_nan() {
        nodes[0]
    } else {
        m.clamp(nodes[0], nodes[nodes.len() - 1])
    };
    let j0 = (0..nodes.len() - 1)
        .rev()
        .find(|&j| nodes[j] <= m)
        .unwrap_or(0);
    (
        j0,
        ((m - nodes[j0]) / (nodes[j0 + 1] - nodes[j0])).clamp(0.0, 1.0),
    )
}

/// The blob's condition range `(cond_min[a], cond_max[a])` of axis `a` in `T`.
fn range<T: Real>(parts: &ConditionalParts, a: usize) -> (T, T) {
    let info = &parts.info;
    (
        T::of(info.cond_min[a].into()),
        T::of(info.cond_max[a].into()),
    )
}

/// The clamped condition in blob units, `lo + u (hi - lo)` of the normalized one,
/// in `T`.
fn clamped<T: Real>(parts: &ConditionalParts, u: [T; 2]) -> [T; 2] {
    std::array::from_fn(|a| {
        let (lo, hi) = range::<T>(parts, a);
        lo + u[a] * (hi - lo)
    })
}

/// The normalized condition in `T`, as documented: clamp into the range (NaN to
/// the lower end), then `(c - lo) / (hi - lo)`.
fn normalize<T: Real>(parts: &ConditionalParts, c: Vec2) -> [T; 2] {
    let c = c.to_array();
    std::array::from_fn(|a| {
        let (lo, hi) = range::<T>(parts, a);
        let x = if c[a].is_nan() {
            lo
        } else {
            T::of(c[a].into()).max(lo).min(hi)
        };
        (x - lo) / (hi - lo)
    })
}

/// A condition drawn over the blob's range and a tenth of it beyond on each side
/// (to exercise the clamp), with the occasional NaN.
fn condition(rng: &mut Pcg64Mcg, parts: &ConditionalParts) -> Vec2 {
    let mut c = Vec2::from(std::array::from_fn(|a| {
        let (lo, hi) = range::<f64>(parts, a);
        let margin = 0.1 * (hi - lo);
        rng.random_range(lo - margin..hi + margin) as f32
    }));
    if rng.random_bool(0.02) {
        c.x = f32::NAN;
    }
    c
}

fn with_sampler(parts: &ConditionalParts, f: impl FnOnce(ConditionalSampler<'_>)) {
    let bytes = parts.to_blob(&META).unwrap();
    let blob = Blob::parse(bytes.as_slice()).unwrap();
    assert_eq!(blob.metadata(), META);
    f(blob.conditional().unwrap());
}

/// Network mode equals the tool's `f64` forward pass over the same f16 weights
/// (decoded by `half`), to 1e-5 in the square and on the hemisphere (5e-4 through
/// the mixture warp, whose GGX lobe magnifies square differences up to ~1/alpha = 100). Measured on
/// these fixtures over 20k samples each: max |square difference| 1.9e-7 (ReLU),
/// 3.0e-7 (SiLU), 4.2e-6 (ReLU, mixture warp: the logit residual adds magnitude);
/// max |direction difference| 6.9e-7, 7.5e-7 and 9.7e-5.
#[test]
fn network_mode_equals_the_tools_f64_evaluation_of_the_f16_weights() {
    for parts in fixtures() {
        let metal_shape = parts.info.shape().unwrap();
        let axis = !parts.metallic_nodes.is_empty();
        // The shared network reads the metallic where the blob has an axis.
        let shape = metal_shape.with_metallic_input(axis);
        let decoded =
            |params: &[u16]| -> Vec<f64> { params.iter().map(|&h| f16_decode(h) as f64).collect() };
        let weights = decoded(&parts.params);
        let tool = Network {
            shape,
            params: &weights[..],
        };
        let metal_weights = parts.metal.as_ref().map(|m| decoded(&m.params));
        let metal_tool = metal_weights.as_ref().map(|w| Network {
            shape: metal_shape,
            params: &w[..],
        });
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        let (mut worst_square, mut worst_direction) = (0.0f64, 0.0f64);
        let fixture = fixture_tree();
        let tree = fixture.tree();
        let brdf_prior = BrdfPrior::shared();
        let prior64 = brdf_prior.core_f64().unwrap();
        // Samples whose f32 and f64 descents take the two sides of one of the
        // tree's splits (a jump, not a rounding): counted, held to a small share.
        let (mut split_sides, mut count) = (0u32, 0u32);
        with_sampler(&parts, |cs| {
            for _ in 0..20_000 {
                let c = condition(&mut rng, &parts);
                let k: u32 = rng.random();
                let i = rng.random_range(0..200);
                let u = normalize::<f64>(&parts, c);
                let input = input_features::<f64>(&shape, u, 0.0, k, i);
                let row = shape.embedding_row(k, i);
                let p = DVec2::from(tool.forward(row, input).square_point());
                let got = cs.network().square_point(c, k, i).as_dvec2();
                worst_square = worst_square.max((got - p).abs().max_element());
                if axis {
                    // Below metallic 1 the shared network at the query's metallic.
                    let m = metallic(&mut rng);
                    if m.is_nan() || m < 1.0 {
                        let input = input_features::<f64>(&shape, u, m as f64, k, i);
                        let pm = DVec2::from(tool.forward(row, input).square_point());
                        let got = cs.network().square_point_metallic(c, m, k, i).as_dvec2();
                        worst_square = worst_square.max((got - pm).abs().max_element());
                    }
                }
                if let Some(metal) = &metal_tool {
                    // At metallic 1 the metal layer's network (which reads no
                    // metallic), at 0.99 the shared one.
                    let input = input_features::<f64>(&metal_shape, u, 0.0, k, i);
                    let pm = DVec2::from(metal.forward(row, input).square_point());
                    let got = cs.network().square_point_metallic(c, 1.0, k, i).as_dvec2();
                    worst_square = worst_square.max((got - pm).abs().max_element());
                    let below = cs.network().square_point_metallic(c, 0.99, k, i).as_dvec2();
                    let input = input_features::<f64>(&shape, u, 0.99, k, i);
                    let p99 = DVec2::from(tool.forward(row, input).square_point());
                    worst_square = worst_square.max((below - p99).abs().max_element());
                    if !axis {
                        assert_eq!(below, cs.network().square_point(c, k, i).as_dvec2());
                    }
                }
                let d = match parts.info.point_warp().unwrap() {
                    PointWarp::EqualArea => Domain::Hemisphere.to_direction(p),
                    PointWarp::BrdfMixture => {
                        // The mixture warp jumps between its lobes at p.x = p_s:
                        // there f32 and f64 may pick different lobes.
                        let p_s = cs.lobe_probability(c) as f64;
                        if (p.x - p_s).abs() < 1e-4 {
                            continue;
                        }
                        let cond = clamped(&parts, u);
                        DVec3::from_array(brdf_mixture_direction(cond, p_s, p.to_array()))
                    }
                    PointWarp::EnvmapTree => {
                        let q = clamped(&parts, u);
                        DVec3::from_array(tree.sample_square(q, p.to_array()).0)
                    }
                    PointWarp::BrdfTable => {
                        let q = clamped(&parts, u);
                        DVec3::from_array(prior64.sample([q[0], q[1], 0.0], p.to_array()).0)
                    }
                };
                let s = cs.network().sample(c, k, i);
                let gap = (s.direction.as_dvec3() - d).length();
                count += 1;
                let searched = matches!(
                    parts.info.point_warp(),
                    Some(PointWarp::EnvmapTree | PointWarp::BrdfTable)
                );
                if searched && gap > 1e-2 {
                    split_sides += 1;
                    continue;
                }
                worst_direction = worst_direction.max(gap);
            }
        });
        eprintln!(
            "{:?}: network mode vs f64 tool: square {worst_square:.2e}, direction {worst_direction:.2e}",
            shape.activation()
        );
        assert!(worst_square < 1e-5, "{worst_square}");
        // The mixture warp's GGX lobe magnifies square differences by up to
        // ~1/alpha = 100 at roughness 0.1; the tree's warp and the tabulated
        // BRDF prior by the inverse square root of their pdf, up to a few
        // hundred where the target is dim.
        let bound = match parts.info.point_warp().unwrap() {
            PointWarp::EqualArea => 1e-5,
            PointWarp::BrdfMixture => 5e-4,
            PointWarp::EnvmapTree | PointWarp::BrdfTable => 2e-3,
        };
        assert!(worst_direction < bound, "{worst_direction}");
        eprintln!("  split sides taken apart: {split_sides} of {count}");
        assert!(split_sides * 200 <= count, "{split_sides} of {count}");
    }
}

/// The reference interpolation of core/FORMAT.md, written out in plain `f32`:
/// `s = u (g - 1)`, `j0 = min(floor(s), g - 2)`, `t = s - j0` per axis; corner values
/// `v00, v10, v01, v11`; `a = v00 + (v10 - v00) t0`, `b = v01 + (v11 - v01) t0`,
/// `a + (b - a) t1`.
fn bilinear(u: [f32; 2], nodes: [u32; 2], value: impl Fn(usize) -> f32) -> f32 {
    let cell: [(usize, f32); 2] = std::array::from_fn(|a| {
        let s = u[a] * (nodes[a] - 1) as f32;
        let j0 = (s.floor() as u32).min(nodes[a] - 2);
        (j0 as usize, s - j0 as f32)
    });
    let at = |dx: usize, dy: usize| value((cell[1].0 + dy) * nodes[0] as usize + cell[0].0 + dx);
    let (t0, t1) = (cell[0].1, cell[1].1);
    let a = at(0, 0) + (at(1, 0) - at(0, 0)) * t0;
    let b = at(0, 1) + (at(1, 1) - at(0, 1)) * t0;
    a + (b - a) * t1
}

/// Table lookups equal the reference interpolation of the stored codes bit for
/// bit, in the square and (through the `f32` hemisphere map) as directions.
#[test]
fn table_mode_equals_the_reference_interpolation_bit_for_bit() {
    let fixture = fixture_tree();
    let tree = fixture.tree();
    let brdf_prior = BrdfPrior::shared();
    let prior = brdf_prior.core().unwrap();
    for parts in fixtures() {
        let info = parts.info;
        let mut rng = Pcg64Mcg::seed_from_u64(8);
        with_sampler(&parts, |cs| {
            for _ in 0..50_000 {
                let c = condition(&mut rng, &parts);
                let k: u32 = rng.random();
                let i: u32 = rng.random();
                let (ks, is) = (k % info.instances, i % info.n);
                let u = normalize::<f32>(&parts, c);
                let layer_len = (info.grid[0] * info.grid[1]) as usize;
                let coord_in = |table: &[u32], layer: usize, axis: u32| {
                    bilinear(u, info.grid, |node| {
                        let node = layer * layer_len + node;
                        let at = (node * info.instances as usize + ks as usize) * info.n as usize
                            + is as usize;
                        let code = (table[at] >> (16 * axis)) & 0xffff;
                        (code as f32 + 0.5) / 65536.0
                    })
                };
                let coord = |table: &[u32], axis: u32| coord_in(table, 0, axis);
                // The shared table's point at metallic `m`: with an axis the
                // two layers around it blended as `a + (b - a) t`.
                let point_at = |m: f32| {
                    if parts.metallic_nodes.is_empty() {
                        return [coord(&parts.table, 0), coord(&parts.table, 1)];
                    }
                    let (j0, t) = metallic_cell(&parts.metallic_nodes, m);
                    std::array::from_fn(|a| {
                        let (lo, hi) = (
                            coord_in(&parts.table, j0, a as u32),
                            coord_in(&parts.table, j0 + 1, a as u32),
                        );
                        lo + (hi - lo) * t
                    })
                };
                let p = point_at(0.0);
                assert_eq!(cs.square_point(c, k, i).to_array(), p, "{c} {k} {i}");
                if !parts.metallic_nodes.is_empty() {
                    let m = metallic(&mut rng);
                    if m.is_nan() || m < 1.0 {
                        let got = cs.square_point_metallic(c, m, k, i).to_array();
                        assert_eq!(got, point_at(m), "{c} {m} {k} {i}");
                    }
                }
                let d = match info.point_warp().unwrap() {
                    PointWarp::EqualArea => square_to_hemisphere_real(p),
                    PointWarp::BrdfMixture => {
                        let nodes = info.weight_table_len() as usize;
                        let p_s = bilinear(u, info.weight_grid, |node| parts.weights[nodes + node]);
                        brdf_mixture_direction(clamped(&parts, u), p_s, p)
                    }
                    PointWarp::EnvmapTree => {
                        let (d, pdf) = tree.sample_square(clamped(&parts, u), p);
                        assert_eq!(cs.sample(c, k, i).pdf, pdf);
                        d
                    }
                    PointWarp::BrdfTable => {
                        let m = 0.25;
                        let q = clamped(&parts, u);
                        let (d, pdf) = prior.sample([q[0], q[1], m], point_at(m));
                        let s = cs.sample_metallic(c, m, k, i);
                        assert_eq!(s.direction.to_array(), d);
                        assert_eq!(s.pdf, pdf);
                        // The weight is f cos / pdf of the direction, in f32.
                        let f = gltf_metallic(view_direction_real(q[1]), d, q[0], m);
                        let w = if pdf > 0.0 { f * d[2] / pdf } else { 0.0 };
                        assert_eq!(s.weight, w);
                        if let Some(metal) = &parts.metal {
                            // Metallic 1 reads the metal layer's own table.
                            let pm = [coord(&metal.table, 0), coord(&metal.table, 1)];
                            assert_eq!(cs.square_point_metallic(c, 1.0, k, i).to_array(), pm);
                            let (d1, pdf1) = prior.sample([q[0], q[1], 1.0], pm);
                            let s1 = cs.sample_metallic(c, 1.0, k, i);
                            assert_eq!((s1.direction.to_array(), s1.pdf), (d1, pdf1));
                        }
                        prior.sample([q[0], q[1], 0.0], p).0
                    }
                };
                assert_eq!(cs.sample(c, k, i).direction.to_array(), d);
            }
        });
    }
}

/// Weights equal the reference bilinear interpolation of the weight table bit for
/// bit, and an `f64` bilinear interpolation to `f32` rounding.
#[test]
fn weights_equal_the_reference_bilinear_interpolation() {
    for parts in fixtures() {
        let info = parts.info;
        let mut rng = Pcg64Mcg::seed_from_u64(9);
        with_sampler(&parts, |cs| {
            for _ in 0..50_000 {
                let c = condition(&mut rng, &parts);
                let want = bilinear(normalize::<f32>(&parts, c), info.weight_grid, |node| {
                    parts.weights[node]
                });
                let got = cs.weight(c);
                assert_eq!(got, want, "{c}");
                // The tabulated prior's samples weigh by f cos / pdf instead
                // (the test above).
                if info.point_warp() != Some(PointWarp::BrdfTable) {
                    assert_eq!(cs.sample(c, 3, 5).weight, want);
                    assert_eq!(cs.network().sample(c, 3, 5).weight, want);
                }
                // The same interpolation in f64, from the f64 normalized condition.
                let u = normalize::<f64>(&parts, c);
                let g = info.weight_grid;
                let (s0, s1) = (u[0] * (g[0] - 1) as f64, u[1] * (g[1] - 1) as f64);
                let (j0, j1) = (
                    (s0.floor() as usize).min(g[0] as usize - 2),
                    (s1.floor() as usize).min(g[1] as usize - 2),
                );
                let (t0, t1) = (s0 - j0 as f64, s1 - j1 as f64);
                let w =
                    |x: usize, y: usize| parts.weights[(j1 + y) * g[0] as usize + j0 + x] as f64;
                let exact = (1.0 - t1) * ((1.0 - t0) * w(0, 0) + t0 * w(1, 0))
                    + t1 * ((1.0 - t0) * w(0, 1) + t0 * w(1, 1));
                assert!(
                    (got as f64 - exact).abs() < 1e-6 * exact,
                    "{c}: {got} {exact}"
                );
            }
        });
    }
}

/// Table mode's environment samples through the tree whose pdf they carry: the
/// prior's f32 descent on the interpolated point (the test above), and here that
/// the pdf the runtime returns is the `f64` tree's at the direction to `f32`
/// rounding, but for directions on a leaf's or a detail cell's edge, and `pdf`
/// of the sample's direction is the sample's pdf to that rounding.
#[test]
fn environment_pdfs_are_the_trees_f64_pdfs() {
    let parts = fixtures().pop().unwrap();
    assert_eq!(parts.info.point_warp(), Some(PointWarp::EnvmapTree));
    let fixture = fixture_tree();
    let tree = fixture.tree();
    let mut rng = Pcg64Mcg::seed_from_u64(10);
    let (mut worst, mut edges) = (0.0f64, 0);
    with_sampler(&parts, |cs| {
        for _ in 0..20_000 {
            let c = condition(&mut rng, &parts);
            let s = cs.sample(c, rng.random(), rng.random());
            let q = clamped(&parts, normalize::<f64>(&parts, c));
            let want = tree.pdf_square(q, s.direction.as_dvec3().to_array());
            let rel = (s.pdf as f64 - want).abs() / want;
            // A direction within rounding of a detail cell's edge (the finest,
            // the fine tables', which nest the others) may be read in the
            // neighbouring cell, as one on a leaf's edge in the neighbouring leaf.
            let sq = nuld_core::sphere::sphere_to_square(s.direction.as_dvec3());
            let cells = ((1usize << tree.levels()) * FINE_SIDE) as f64;
            let on_cell_edge = [sq.x, sq.y]
                .iter()
                .any(|c| ((c * cells).round() - c * cells).abs() < 1e-4);
            if rel > 1e-2 || on_cell_edge {
                edges += 1;
                continue;
            }
            worst = worst.max(rel);
            // The pdf of the sample's own direction: the same leaf, and inside
            // a shaped leaf the direction's square point to its rounding.
            let back = cs.pdf(c, s.direction);
            assert!((back - s.pdf).abs() <= 1e-4 * s.pdf, "{back} {}", s.pdf);
        }
    });
    eprintln!("environment pdf vs f64 tree: relative {worst:.2e}, {edges} of 20000 on an edge");
    assert!(worst < 1e-4, "{worst}");
    assert!(edges <= 100, "{edges}");
}

/// `BrdfSampler::sample` in the xz-plane on the `+x` side is `sample` at
/// `theta_o`: the sets are made for that view.
#[test]
fn brdf_view_in_the_xz_plane_is_the_stored_condition() {
    let parts = &fixtures()[0];
    let bytes = parts.to_blob(&META).unwrap();
    let brdf = Blob::parse(bytes.as_slice()).unwrap().brdf().unwrap();
    with_sampler(parts, |cs| {
        for deg in [0.0f64, 30.0, 45.0, 60.0, 75.0, 85.0] {
            let t = deg.to_radians();
            let wo = DVec3::new(t.sin(), 0.0, t.cos()).as_vec3();
            for i in 0..cs.len() {
                let got = brdf.sample(wo, 0.4, 0.0, 2, i);
                let want = cs.sample(Vec2::new(0.4, deg as f32), 2, i);
                assert!(
                    (got.direction - want.direction).length() < 1e-4,
                    "{deg} {i}"
                );
            }
        }
    });
}

/// The unbiased mode against the reference albedo tables (which hold more than
/// this test reads).
#[allow(dead_code)]
mod unbiased {
    use super::*;
    include!("../../core/tests/data/gltf_albedo_reference.rs");
    include!("../../core/tests/data/gltf_metal_albedo_reference.rs");

    /// The BRDF sampler on the tabulated prior, unbiased mode: over 4096 random
    /// shifts (`sample_randomized` seeds) of a fixture's sets, whatever its random
    /// table and network hold, the mean weight `f cos / pdf` is the albedo of the
    /// independent reference table, `(1 - m) A_0 + m A_1`, within 3 standard errors
    /// at metallic 0, 0.5 and 1, in table and network mode, through the typed view
    /// (a view off the xz-plane); and `pdf` answers each sample's pdf.
    #[test]
    fn the_unbiased_modes_mean_weight_is_the_reference_albedo() {
        let parts = fixtures()
            .into_iter()
            .find(|p| p.info.point_warp() == Some(PointWarp::BrdfTable))
            .unwrap();
        let bytes = parts.to_blob(&META).unwrap();
        let brdf = Blob::parse(bytes.as_slice()).unwrap().brdf().unwrap();
        for (ri, ti) in [(3, 2), (1, 4)] {
            let (r, t) = (REFERENCE_ROUGHNESSES[ri], REFERENCE_THETAS[ti]);
            let phi = 2.0f64;
            let tr = t.to_radians();
            let wo = DVec3::new(tr.sin() * phi.cos(), tr.sin() * phi.sin(), tr.cos()).as_vec3();
            for m in [0.0, 0.5, 1.0] {
                let want =
                    (1.0 - m) * REFERENCE_ALBEDO[ri][ti] + m * REFERENCE_METAL_ALBEDO[ri][ti];
                for network in [false, true] {
                    let (mut sum, mut sum2, count) = (0.0f64, 0.0f64, 4096u32);
                    for seed in 0..count {
                        // One set per seed: the mean of its N weights.
                        let mut set = 0.0;
                        for i in 0..brdf.len() {
                            let s = match network {
                                false => brdf.sample_randomized(wo, r as f32, m as f32, 7, i, seed),
                                true => brdf
                                    .network()
                                    .sample_randomized(wo, r as f32, m as f32, 7, i, seed),
                            };
                            if i < 2 && s.pdf > 0.0 {
                                let back = brdf.pdf(wo, r as f32, m as f32, s.direction);
                                assert!((back / s.pdf - 1.0).abs() < 2e-3, "{back} {}", s.pdf);
                            }
                            set += s.weight as f64 / brdf.len() as f64;
                        }
                        sum += set;
                        sum2 += set * set;
                    }
                    let mean = sum / count as f64;
                    let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
                    eprintln!("r {r} θo {t} m {m} network {network}: {mean:.5} vs {want:.5} (se {se:.1e})");
                    assert!(
                        (mean - want).abs() < 3.0 * se + 1e-5,
                        "{mean} vs {want} (se {se})"
                    );
                }
            }
        }
    }
}
