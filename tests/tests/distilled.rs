//! A blob distilled from a (briefly) trained network, read by the runtime: table
//! mode against network mode, and the weights against the directional albedo of an
//! independent quadrature.

use glam::Vec2;
use nuld_build_tool::pointset::AlignedBytes;
use nuld_build_tool::sphere::brdf_albedo::{directional_albedo, directional_albedo_metallic};
use nuld_core::brdf::BrdfModel;
use nuld_core::quantize::UNORM16_MAX_ERROR;
use nuld_runtime::{Blob, ConditionalSampler};
use nuld_tests::{distilled_parts, META};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::sync::OnceLock;

const GRID: [u32; 2] = [5, 6];
const WEIGHT_GRID: [u32; 2] = [10, 9];
const INSTANCES: u32 = 3;

/// The runtime's view of the distilled blob of a small network trained for a few
/// steps (enough to leave the initialization); trained once, shared by the tests.
fn distilled() -> ConditionalSampler<'static> {
    static BLOB: OnceLock<AlignedBytes> = OnceLock::new();
    let bytes = BLOB.get_or_init(|| {
        distilled_parts(INSTANCES, GRID, WEIGHT_GRID)
            .to_blob(&META)
            .unwrap()
    });
    Blob::parse(bytes.as_slice())
        .unwrap()
        .conditional()
        .unwrap()
}

/// A node's condition (`f64`, blob units) as the `f32` condition a caller passes.
fn node(c: [f64; 2]) -> Vec2 {
    Vec2::new(c[0] as f32, c[1] as f32)
}

/// Table mode equals network mode at the grid nodes up to the table's u16 code
/// (half a cell, 2^-17) and the f64/f32 difference of the two evaluations (the
/// runtime's network is f32, the table was filled in f64; 1e-5 by the conformance
/// test of tests/conditional.rs). Off the nodes, bilinear interpolation adds an
/// error that grows with the network's curvature in the condition: the test
/// measures it at the cell and edge midpoints, and requires every one of 20k random
/// conditions to stay within twice the largest midpoint error plus the node bound.
#[test]
fn table_mode_follows_network_mode_within_a_measured_bound() {
    for metallic in [0.0, 1.0] {
        table_follows_network_at(metallic);
    }
}

/// [`table_mode_follows_network_mode_within_a_measured_bound`] at `metallic`: at 1
/// the metal layer's own table and network, which are not the shared ones.
fn table_follows_network_at(metallic: f32) {
    let cs = distilled();
    let n = cs.len();
    assert!(cs.has_metal_points());
    let gap = |c: Vec2, k: u32, i: u32| {
        (cs.square_point_metallic(c, metallic, k, i)
            - cs.network().square_point_metallic(c, metallic, k, i))
        .abs()
        .max_element()
    };
    if metallic >= 1.0 {
        let c = Vec2::new(0.5, 40.0);
        let apart = (0..n)
            .map(|i| (cs.square_point_metallic(c, 1.0, 0, i) - cs.square_point(c, 0, i)).length())
            .fold(0.0f32, f32::max);
        assert!(
            apart > 1e-3,
            "the metal points are the shared ones: {apart}"
        );
    }
    let node_bound = UNORM16_MAX_ERROR as f32 + 1e-5;
    let mut at_nodes = 0.0f32;
    let mut at_midpoints = 0.0f32;
    for j1 in 0..GRID[1] {
        for j0 in 0..GRID[0] {
            let at = |j| node(cs.info().grid_condition(j));
            let here = at([j0, j1]);
            let steps = [
                (at([(j0 + 1).min(GRID[0] - 1), j1]) - here) / 2.0,
                (at([j0, (j1 + 1).min(GRID[1] - 1)]) - here) / 2.0,
            ];
            for k in 0..INSTANCES {
                for i in 0..n {
                    at_nodes = at_nodes.max(gap(here, k, i));
                    for mid in [here + steps[0], here + steps[1], here + steps[0] + steps[1]] {
                        at_midpoints = at_midpoints.max(gap(mid, k, i));
                    }
                }
            }
        }
    }
    assert!(
        at_nodes <= node_bound,
        "at the nodes: {at_nodes} > {node_bound}"
    );
    let bound = 2.0 * at_midpoints + node_bound;
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let mut worst = 0.0f32;
    for _ in 0..20_000 {
        let c = Vec2::new(rng.random_range(0.1..1.0), rng.random_range(0.0..89.0));
        worst = worst.max(gap(
            c,
            rng.random_range(0..INSTANCES),
            rng.random_range(0..n),
        ));
    }
    println!(
        "table vs network (square units), metallic {metallic}: nodes {at_nodes:.2e}, \
         midpoints {at_midpoints:.2e}, 20k random conditions {worst:.2e} (bound {bound:.2e})"
    );
    assert!(worst <= bound, "{worst} > {bound}");
}

/// The weights at the weight-grid nodes equal the glTF directional albedo of the
/// Gauss-Legendre quadrature (itself checked against published reference values)
/// within 1e-4, and the albedo at metallic 0, 1 and 0.5 the dielectric's, the
/// metal's and their mean.
#[test]
fn weights_equal_the_albedo_at_the_weight_grid_nodes() {
    let cs = distilled();
    for j1 in 0..WEIGHT_GRID[1] {
        for j0 in 0..WEIGHT_GRID[0] {
            let c = node(cs.info().weight_grid_condition([j0, j1]));
            let want = directional_albedo(BrdfModel::Gltf, c.x as f64, c.y as f64).total();
            let metal = directional_albedo_metallic(c.x as f64, c.y as f64, 1.0).total();
            let half = 0.5 * (want + metal);
            for (got, want) in [
                (cs.weight(c), want),
                (cs.albedo(c, 0.0), want),
                (cs.albedo(c, 1.0), metal),
                (cs.albedo(c, 0.5), half),
            ] {
                assert!(
                    (got as f64 - want).abs() < 1e-4,
                    "({}, {}): {got} vs {want}",
                    c.x,
                    c.y
                );
            }
        }
    }
}
