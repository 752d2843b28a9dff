extern crate std;

use super::*;
use crate::sphere::square_to_sphere;
use crate::test_rng::Rng;
use glam::{DVec2, DVec3};
use std::vec;
use std::vec::Vec;

/// A light with a broad sky, a small bright sun low in the sky and a dark ground:
/// what the tree must resolve.
fn light(d: DVec3) -> f64 {
    let sun = DVec3::new(0.8, 0.3, 0.2).normalize();
    let sky = if d.z > 0.0 { 0.5 + d.z } else { 0.02 };
    sky + 400.0 * (-(1.0 - d.dot(sun)) * 2000.0).exp()
}

/// Leaf moments of `light` by `k x k` midpoints per leaf (each leaf has the same
/// solid angle, `4 pi / 4^L`).
fn leaves(levels: u32, k: usize) -> Vec<[f64; 4]> {
    let side = 1usize << levels;
    let area = 4.0 * core::f64::consts::PI / (side * side * k * k) as f64;
    (0..side * side)
        .map(|leaf| {
            let (x, y) = (leaf % side, leaf / side);
            let mut m = [0.0; 4];
            for b in 0..k {
                for a in 0..k {
                    let d = square_to_sphere(DVec2::new(
                        (x as f64 + (a as f64 + 0.5) / k as f64) / side as f64,
                        (y as f64 + (b as f64 + 0.5) / k as f64) / side as f64,
                    ));
                    let v = light(d) * area;
                    m[0] += v;
                    m[1] += v * d.x;
                    m[2] += v * d.y;
                    m[3] += v * d.z;
                }
            }
            m
        })
        .collect()
}

fn tree_nodes(levels: u32) -> Vec<NodeRecord> {
    let mut nodes = vec![NodeRecord::zeroed(); node_count(levels)];
    build(levels, &leaves(levels, 4), &mut nodes).unwrap();
    nodes
}

const GRID: u32 = 9;

fn top_table(levels: u32, nodes: &[NodeRecord]) -> Vec<f32> {
    top_table_of(levels, nodes, TOP_LEVELS)
}

/// The top table of `top_levels` levels on the `GRID x GRID` normals.
fn top_table_of(levels: u32, nodes: &[NodeRecord], top_levels: u32) -> Vec<f32> {
    let per = node_count(top_levels);
    let mut top = vec![0.0; top_len(GRID, top_levels)];
    for (r, row) in top.chunks_mut(per).enumerate() {
        let j = [r as u32 % GRID, r as u32 / GRID];
        top_row(levels, top_levels, nodes, top_normal(GRID, j), row);
    }
    top
}

fn normals() -> [[f64; 3]; 4] {
    [
        [0.0, 0.0, 1.0],
        [0.6, -0.3, 0.1],
        [-0.2, 0.9, -0.5],
        [0.0, 0.0, -1.0],
    ]
}

#[test]
fn morton_layout_puts_a_nodes_children_side_by_side() {
    assert_eq!(node_count(1), 4);
    assert_eq!(node_count(3), 4 + 16 + 64);
    for l in 1..6u32 {
        let s = 1u32 << l;
        let mut seen = vec![false; node_count(6)];
        for y in 0..s {
            for x in 0..s {
                let i = node_index(l, x, y);
                assert!(i >= node_count(l - 1) && i < node_count(l));
                assert!(!seen[i]);
                seen[i] = true;
                if l < 5 {
                    let c = node_index(l + 1, 2 * x, 2 * y);
                    assert_eq!(c % 4, 0, "children start a group of four");
                    assert_eq!(node_index(l + 1, 2 * x + 1, 2 * y), c + 1);
                    assert_eq!(node_index(l + 1, 2 * x, 2 * y + 1), c + 2);
                    assert_eq!(node_index(l + 1, 2 * x + 1, 2 * y + 1), c + 3);
                }
            }
        }
    }
}

/// Every node's weight is at least the brute-force `Σ mass max(0, n.l)` over its
/// own light (the leaves' midpoints) and at least `max(0, n.m1)`, and for small
/// nodes well above the horizon (`n.l > 0.3` on the node) within a few percent of
/// it.
#[test]
fn a_nodes_weight_bounds_its_lit_mass_from_above_and_is_tight_above_the_horizon() {
    let levels = 6;
    let k = 4;
    let side = 1usize << levels;
    let area = 4.0 * core::f64::consts::PI / (side * side * k * k) as f64;
    let nodes = tree_nodes(levels);
    for n in normals().map(|n| DVec3::from_array(n).normalize()) {
        for l in [2u32, 4, 6] {
            let s = 1usize << l;
            let block = side / s;
            for node in (0..s * s).step_by(3) {
                let (x, y) = (node % s, node / s);
                let (mut lit, mut low, mut above) = (0.0, false, false);
                for py in y * block * k..(y + 1) * block * k {
                    for px in x * block * k..(x + 1) * block * k {
                        let d = square_to_sphere(DVec2::new(
                            (px as f64 + 0.5) / (side * k) as f64,
                            (py as f64 + 0.5) / (side * k) as f64,
                        ));
                        lit += light(d) * area * n.dot(d).max(0.0);
                        low |= n.dot(d) <= 0.3;
                        above |= n.dot(d) > 0.0;
                    }
                }
                let r = nodes[node_index(l, x as u32, y as u32)];
                let w: f64 = r.weight(n.to_array());
                let m1 = DVec3::from_array(r.moment.map(|v| v as f64));
                assert!(
                    w >= lit * (1.0 - 1e-5) - 1e-12,
                    "level {l} {n}: {w} < {lit}"
                );
                assert!(w >= n.dot(m1).max(0.0) * (1.0 - 1e-6));
                if above {
                    assert!(w > 0.0);
                }
                if l == 6 && !low {
                    assert!(w <= lit * 1.05, "level {l} {n}: {w} vs {lit}");
                }
            }
        }
    }
}

/// At a grid normal the top levels' weights are the exact lit masses of their
/// leaves (a brute-force sum over the leaf records), within f32 rounding; between
/// grid normals they are positive wherever the query's normal sees the node.
#[test]
fn top_weights_are_exact_at_grid_normals_and_positive_where_lit() {
    // Today's depth, and the depth of the trees written before it, which still load.
    for top_levels in [TOP_LEVELS, LEGACY_TOP_LEVELS] {
        top_weights_exact(top_levels);
    }
}

fn top_weights_exact(top_levels: u32) {
    let levels = 5;
    let nodes = tree_nodes(levels);
    let top = top_table_of(levels, &nodes, top_levels);
    let tree = EnvmapTree::new(levels, &nodes, GRID, &top, top_levels).unwrap();
    assert_eq!(tree.top_levels(), top_levels);
    let side = 1u32 << levels;
    let lit_mass = |n: DVec3, l: u32, x: u32, y: u32| {
        let b = side >> l;
        let mut w = 0.0;
        for ly in y * b..(y + 1) * b {
            for lx in x * b..(x + 1) * b {
                let m = nodes[node_index(levels, lx, ly)].moment.map(|v| v as f64);
                w += n.dot(DVec3::from_array(m)).max(0.0);
            }
        }
        w
    };
    for j in [[0, 0], [3, 5], [8, 8], [4, 4]] {
        let n = top_normal(GRID, j);
        let lit = tree.lit(n);
        for l in 0..top_levels {
            let s = 1u32 << l;
            for node in 0..s * s {
                let (x, y) = (node % s, node / s);
                let w = lit.children(Node::new(l, x, y));
                for k in 0..4u32 {
                    let exact = lit_mass(
                        DVec3::from_array(n),
                        l + 1,
                        2 * x + (k & 1),
                        2 * y + (k >> 1),
                    );
                    let floor = TOP_FLOOR
                        * nodes[node_index(l + 1, 2 * x + (k & 1), 2 * y + (k >> 1))]
                            .weight::<f64>(n);
                    assert!((w[k as usize] - exact.max(floor)).abs() <= 1e-6 * exact.max(1e-9));
                }
            }
        }
    }
    let mut r = Rng(8);
    for _ in 0..300 {
        let n = DVec3::new(r.next() - 0.5, r.next() - 0.5, r.next() - 0.5).normalize();
        let lit = tree.lit(n.to_array());
        for k in 0..4u32 {
            let w = lit.children(Node::ROOT)[k as usize];
            if lit_mass(n, 1, k & 1, k >> 1) > 0.0 {
                assert!(w > 0.0);
            }
        }
    }
}

#[test]
fn the_pdf_integrates_to_one_over_the_sphere() {
    let levels = 6;
    let nodes = tree_nodes(levels);
    let top = top_table(levels, &nodes);
    let tree = EnvmapTree::new(levels, &nodes, GRID, &top, TOP_LEVELS).unwrap();
    let m = 256;
    for n in normals() {
        let mut sum = 0.0;
        for k in 0..m * m {
            let d = square_to_sphere(DVec2::new(
                ((k % m) as f64 + 0.5) / m as f64,
                ((k / m) as f64 + 0.5) / m as f64,
            ));
            sum += tree.pdf(n, d.to_array()) * 4.0 * core::f64::consts::PI / (m * m) as f64;
        }
        assert!((sum - 1.0).abs() < 1e-9, "{n:?}: {sum}");
    }
}

/// 10^6 samples of `tree` at `n` (seed `seed`) on `bins x bins` bins of the
/// square: every 50th sample away from its leaf's edge (64 leaves per axis) has
/// `pdf(n, d)` within `tol` relatively of its own pdf and `invert` undoes it to
/// 1e-6; the counts pass a chi-square against `10^6 x 4 pi / bins² x
/// bin_pdf(i, j)`, `bin_pdf` the pdf's mean over bin `(i, j)` (bins expecting
/// fewer than 5 samples pooled).
fn check_samples(
    tree: &EnvmapTree<'_>,
    n: [f64; 3],
    seed: u64,
    tol: f64,
    bins: usize,
    bin_pdf: impl Fn(usize, usize) -> f64,
) {
    let samples = 1_000_000;
    let mut counts = vec![0u32; bins * bins];
    let mut r = Rng(seed);
    let mut worst: f64 = 0.0;
    for s in 0..samples {
        let u = [r.next(), r.next()];
        let (d, pdf) = tree.sample(n, u);
        let p = crate::sphere::sphere_to_square(DVec3::from_array(d));
        let i = ((p.x * bins as f64) as usize).min(bins - 1);
        let j = ((p.y * bins as f64) as usize).min(bins - 1);
        counts[j * bins + i] += 1;
        if s % 50 == 0 {
            let inside = |c: f64| ((c * 64.0).fract() - 0.5).abs() < 0.499;
            if inside(p.x) && inside(p.y) {
                let back = tree.pdf(n, d);
                assert!((back - pdf).abs() <= tol * pdf, "{back} {pdf}");
                let back = tree.invert(n, d);
                worst = worst
                    .max((back[0] - u[0]).abs())
                    .max((back[1] - u[1]).abs());
            }
        }
    }
    assert!(worst < 1e-6, "{worst}");
    // Bins expecting fewer than 5 samples are pooled into one, where the
    // statistic's variance (`2 + 1 / expected` a bin) would swamp it.
    let (mut chi2, mut dof, mut pooled) = (0.0, 0, (0.0, 0.0));
    for j in 0..bins {
        for i in 0..bins {
            let expected =
                samples as f64 * bin_pdf(i, j) * 4.0 * core::f64::consts::PI / (bins * bins) as f64;
            let got = counts[j * bins + i] as f64;
            if expected >= 5.0 {
                chi2 += (got - expected).powi(2) / expected;
                dof += 1;
            } else if expected > 0.0 {
                pooled = (pooled.0 + got, pooled.1 + expected);
            } else {
                assert_eq!(got, 0.0);
            }
        }
    }
    if pooled.1 > 0.0 {
        chi2 += (pooled.0 - pooled.1).powi(2) / pooled.1;
        dof += 1;
    }
    let sd = (2.0 * dof as f64).sqrt();
    assert!(chi2 < dof as f64 + 5.0 * sd, "chi-square {chi2} over {dof}");
}

/// 10^6 samples on 64 x 64 bins of the square (each a union of leaves, where the
/// pdf is constant): chi-square against the pdf; the returned pdf is the pdf at
/// the sample; `invert` undoes `sample`.
#[test]
fn samples_follow_the_pdf_and_invert_undoes_sample() {
    let levels = 6;
    let nodes = tree_nodes(levels);
    let top = top_table(levels, &nodes);
    let tree = EnvmapTree::new(levels, &nodes, GRID, &top, TOP_LEVELS).unwrap();
    let n = [0.6, -0.3, 0.1];
    let bins = 64;
    check_samples(&tree, n, 5, 1e-9, bins, |i, j| {
        let c = square_to_sphere(DVec2::new(
            (i as f64 + 0.5) / bins as f64,
            (j as f64 + 0.5) / bins as f64,
        ));
        tree.pdf(n, c.to_array())
    });
}

/// Samples of [`irradiance_estimate`].
const ESTIMATE_SAMPLES: usize = 200_000;

/// The mean of `L cos / pdf` over [`ESTIMATE_SAMPLES`] of `tree`'s samples at
/// `n` (seed `seed`), and its standard error.
fn irradiance_estimate(tree: &EnvmapTree<'_>, n: [f64; 3], seed: u64) -> (f64, f64) {
    let nv = DVec3::from_array(n).normalize();
    let mut r = Rng(seed);
    let (mut sum, mut sq) = (0.0, 0.0);
    for _ in 0..ESTIMATE_SAMPLES {
        let (d, pdf) = tree.sample(n, [r.next(), r.next()]);
        let d = DVec3::from_array(d);
        let v = if pdf > 0.0 {
            light(d) * nv.dot(d).max(0.0) / pdf
        } else {
            0.0
        };
        sum += v;
        sq += v * v;
    }
    let count = ESTIMATE_SAMPLES as f64;
    let mean = sum / count;
    (mean, ((sq / count - mean * mean) / count).sqrt())
}

/// `(1/M) Σ L cos / pdf` over the tree's samples is the irradiance by an
/// independent quadrature (a fine midpoint rule on the square, `L` the light
/// itself, not the tree's leaves), for normals facing the sun, the sky and the
/// ground; with uniform leaves, and with the leaves shaped and detailed.
#[test]
fn the_estimate_with_the_pdf_is_the_irradiance() {
    let levels = 7;
    let nodes = tree_nodes(levels);
    let top = top_table(levels, &nodes);
    let flat = EnvmapTree::new(levels, &nodes, GRID, &top, TOP_LEVELS).unwrap();
    let corners = corner_values(levels);
    let (index, tables, fine) = detail_values(levels);
    let detailed = flat
        .with_corners(&corners)
        .and_then(|t| t.with_detail(&index, &tables))
        .and_then(|t| t.with_fine_detail(&fine))
        .unwrap();
    let m = 1024;
    for (t, n) in normals().into_iter().enumerate() {
        let nv = DVec3::from_array(n).normalize();
        let mut exact = 0.0;
        for k in 0..m * m {
            let d = square_to_sphere(DVec2::new(
                ((k % m) as f64 + 0.5) / m as f64,
                ((k / m) as f64 + 0.5) / m as f64,
            ));
            exact += light(d) * nv.dot(d).max(0.0) * 4.0 * core::f64::consts::PI / (m * m) as f64;
        }
        // Uniform leaves, and leaves shaped and detailed: each pdf is exact.
        let (d_mean, d_se) = irradiance_estimate(&detailed, n, 60 + t as u64);
        assert!(
            (d_mean - exact).abs() < 4.0 * d_se + 1e-4 * exact,
            "detailed {n:?}: {d_mean} vs {exact} (se {d_se})"
        );
        let (mean, se) = irradiance_estimate(&flat, n, 40 + t as u64);
        assert!(
            (mean - exact).abs() < 4.0 * se + 1e-4 * exact,
            "{n:?}: {mean} vs {exact} (se {se})"
        );
        // The cosine product puts samples where the light meets the cosine: the
        // relative error of one sample stays near that of a perfect importance
        // sampler's for these smooth parts, far below the map's alone.
        assert!(
            se * (ESTIMATE_SAMPLES as f64).sqrt() < 3.0 * exact,
            "{n:?}: {se}"
        );
    }
}

#[test]
fn f32_agrees_with_f64() {
    let levels = 6;
    let nodes = tree_nodes(levels);
    let top = top_table(levels, &nodes);
    let tree = EnvmapTree::new(levels, &nodes, GRID, &top, TOP_LEVELS).unwrap();
    let mut r = Rng(3);
    let mut agreeing = 0;
    for _ in 0..2000 {
        let u = [r.next(), r.next()];
        let n = [r.next() - 0.5, r.next() - 0.5, r.next() - 0.5];
        let (d64, p64) = tree.sample(n, u);
        let (d32, p32) = tree.sample(n.map(|v| v as f32), u.map(|v| v as f32));
        let err = (0..3)
            .map(|c| (d64[c] - d32[c] as f64).abs())
            .fold(0.0, f64::max);
        // A sample on a split's edge may fall on either side in f32.
        if err < 1e-3 {
            assert!(((p32 as f64) - p64).abs() <= 1e-3 * p64, "{p32} vs {p64}");
            agreeing += 1;
        }
    }
    // The sides of a split differ for a few samples only: the check is not empty.
    assert!(agreeing > 1900, "{agreeing}");
}

#[test]
fn bad_trees_are_refused_and_hostile_queries_do_not_panic() {
    let nodes = tree_nodes(4);
    let top = top_table(4, &nodes);
    let new = |l, n: &[NodeRecord]| EnvmapTree::new(l, n, GRID, &top, TOP_LEVELS).map(|_| ());
    assert_eq!(new(2, &nodes), Err(QuadtreeError::Levels(2)));
    assert_eq!(new(13, &nodes), Err(QuadtreeError::Levels(13)));
    // A tree shallower than its top table.
    assert_eq!(new(3, &nodes), Err(QuadtreeError::Levels(3)));
    for t in [0, 2, 6, u32::MAX] {
        assert_eq!(
            EnvmapTree::new(4, &nodes, GRID, &top, t).map(|_| ()),
            Err(QuadtreeError::TopLevels(t))
        );
    }
    // A table of another depth than the one named.
    assert!(matches!(
        EnvmapTree::new(4, &nodes, GRID, &top, LEGACY_TOP_LEVELS),
        Err(QuadtreeError::Length { expected, got }) if expected == 84 * 81 && got == 340 * 81
    ));
    assert!(matches!(
        EnvmapTree::new(4, &nodes, GRID + 1, &top, TOP_LEVELS),
        Err(QuadtreeError::Length { .. })
    ));
    assert!(EnvmapTree::new(4, &nodes, 1, &top[..340], TOP_LEVELS).is_err());
    let mut bad_top = top.clone();
    bad_top[5] = -1.0;
    assert_eq!(
        EnvmapTree::new(4, &nodes, GRID, &bad_top, TOP_LEVELS).map(|_| ()),
        Err(QuadtreeError::BadTopWeight(5))
    );
    let mut bad = nodes.clone();
    bad[7].spread = -1.0;
    assert_eq!(new(4, &bad), Err(QuadtreeError::BadMass(7)));
    bad[7].spread = 1.0;
    bad[9].moment[1] = f32::NAN;
    assert_eq!(new(4, &bad), Err(QuadtreeError::BadMass(9)));
    let dark = vec![NodeRecord::zeroed(); node_count(4)];
    assert_eq!(new(4, &dark), Err(QuadtreeError::NoMass));
    let mut leaves_short = leaves(3, 1);
    let nodes = tree_nodes(4);
    leaves_short.pop();
    let mut out = vec![NodeRecord::zeroed(); node_count(3)];
    assert!(build(3, &leaves_short, &mut out).is_err());

    // Parents that are not their children's sums, zero normals, NaN and huge
    // inputs: finite or zero answers, no panic.
    let mut odd = nodes.clone();
    for r in odd.iter_mut().step_by(5) {
        r.moment = [1e30, -1e30, 0.0];
    }
    let tree = EnvmapTree::new(4, &odd, GRID, &top, TOP_LEVELS).unwrap();
    for n in [
        [0.0f32; 3],
        [f32::NAN, 0.0, 1.0],
        [f32::INFINITY, 1.0, 0.0],
        [1e30, 0.0, 0.0],
    ] {
        for u in [[0.0f32, 0.0], [1.0, 1.0], [f32::NAN, 0.5], [-3.0, 7.0]] {
            let (d, pdf) = tree.sample(n, u);
            assert!(d.iter().all(|c| c.is_finite()) && pdf >= 0.0 && pdf.is_finite());
            assert!(tree.pdf(n, d) >= 0.0);
            let back = tree.invert(n, d);
            assert!(back.iter().all(|c| (0.0..=1.0).contains(c)));
        }
        assert!(tree.pdf(n, [f32::NAN; 3]) >= 0.0);
    }
}

/// The warp's derivatives are its Jacobian within a piece (central differences
/// of step 1e-7 whose two ends share the leaf), uniform leaves and shaped, and
/// its determinant is the inverse of the square's pdf.
#[test]
fn slopes_are_the_warps_derivatives_and_invert_the_pdf() {
    let levels = 6;
    let nodes = tree_nodes(levels);
    let top = top_table(levels, &nodes);
    let flat = EnvmapTree::new(levels, &nodes, GRID, &top, TOP_LEVELS).unwrap();
    let corners = corner_values(levels);
    let shaped = flat.with_corners(&corners).unwrap();
    let q = crate::sphere::sphere_to_square(DVec3::new(0.2, 0.5, 0.7).normalize()).to_array();
    for (name, tree) in [("uniform", flat), ("shaped", shaped)] {
        let mut r = Rng(12);
        let (h, mut compared, mut crossed) = (1e-7, 0, 0);
        for _ in 0..5000 {
            let u = [r.next() * 0.98 + 0.01, r.next() * 0.98 + 0.01];
            let (p, pdf, [dx_dux, dy_dux, dy_duy]) = tree.sample_square_with_slopes(q, u);
            assert!(
                (pdf * dx_dux * dy_duy - 1.0).abs() < 1e-9,
                "{name}: {pdf} {dx_dux} {dy_duy}"
            );
            let leaf = |x: [f64; 2]| x.map(|c| (c * 64.0).floor());
            // Column a of the Jacobian: (dx/du_a, dy/du_a).
            for (a, expected) in [(0, [dx_dux, dy_dux]), (1, [0.0, dy_duy])] {
                let mut lo = u;
                let mut hi = u;
                lo[a] -= h;
                hi[a] += h;
                let (pl, _, _) = tree.sample_square_with_slopes(q, lo);
                let (ph, _, _) = tree.sample_square_with_slopes(q, hi);
                if leaf(pl) != leaf(p) || leaf(ph) != leaf(p) {
                    continue;
                }
                let scale = dx_dux.max(dy_duy);
                for k in 0..2 {
                    let d = (ph[k] - pl[k]) / (2.0 * h);
                    assert!(
                        (d - expected[k]).abs() <= 1e-5 * scale,
                        "{name} u{a} p{k}: {d} vs {}",
                        expected[k]
                    );
                }
                crossed += usize::from(a == 0 && dy_dux.abs() > 1e-3 * scale);
                compared += 1;
            }
        }
        assert!(compared > 9000, "{name}: {compared}");
        // A shaped leaf's conditional moves with x; a uniform one's does not.
        match name {
            "uniform" => assert_eq!(crossed, 0),
            _ => assert!(crossed > 500, "{crossed}"),
        }
    }
}

/// The light at the leaves' corners, `(2^L + 1)^2` values: the leaf shape.
fn corner_values(levels: u32) -> Vec<f32> {
    let side = (1usize << levels) + 1;
    (0..side * side)
        .map(|k| {
            let p = DVec2::new(
                (k % side) as f64 / (side - 1) as f64,
                (k / side) as f64 / (side - 1) as f64,
            );
            light(square_to_sphere(p)) as f32
        })
        .collect()
}

/// With a bilinear shape inside the leaves: the pdf still integrates to 1 (a
/// midpoint rule of 4 x 4 points a leaf is exact for it), a sample's pdf is
/// the pdf at its direction, `invert` undoes `sample`, 10^6 samples pass a
/// chi-square on the leaves' quarters, and `L cos / pdf` estimates the
/// irradiance of the uniform-leaf tree with less spread. Wrong corners are refused.
#[test]
fn a_leaf_shape_keeps_the_pdf_exact() {
    let levels = 6;
    let nodes = tree_nodes(levels);
    let top = top_table(levels, &nodes);
    let corners = corner_values(levels);
    let flat = EnvmapTree::new(levels, &nodes, GRID, &top, TOP_LEVELS).unwrap();
    let tree = flat.with_corners(&corners).unwrap();
    let n = [0.6, -0.3, 0.1];
    let m = 256;
    let cell = |k: usize, m: usize| {
        square_to_sphere(DVec2::new(
            ((k % m) as f64 + 0.5) / m as f64,
            ((k / m) as f64 + 0.5) / m as f64,
        ))
    };
    let sum: f64 = (0..m * m)
        .map(|k| tree.pdf(n, cell(k, m).to_array()) * 4.0 * core::f64::consts::PI / (m * m) as f64)
        .sum();
    assert!((sum - 1.0).abs() < 1e-9, "{sum}");

    let bins = 128;
    check_samples(&tree, n, 6, 1e-8, bins, |i, j| {
        // A bin is a quarter of a leaf: the mean of 2 x 2 midpoints is exact
        // for the bilinear shape in the square.
        let mut pdf = 0.0;
        for (a, b) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
            let c = square_to_sphere(DVec2::new(
                (i as f64 + a) / bins as f64,
                (j as f64 + b) / bins as f64,
            ));
            pdf += tree.pdf(n, c.to_array()) / 4.0;
        }
        pdf
    });

    // The same estimate of the irradiance, with less spread.
    let (a, sa) = irradiance_estimate(&flat, n, 77);
    let (b, sb) = irradiance_estimate(&tree, n, 77);
    assert!((a - b).abs() < 4.0 * (sa * sa + sb * sb).sqrt(), "{a} {b}");
    assert!(sb < 0.8 * sa, "shaped {sb} against uniform {sa}");

    let short = &corners[1..];
    assert!(flat.with_corners(short).is_err());
    let mut bad = corners.clone();
    bad[17] = f32::NAN;
    let shaped = flat.with_corners(&bad).unwrap();
    assert_eq!(shaped.check_values(), Err(QuadtreeError::BadCorner(17)));
    // Bad values never make it panic.
    let (d, pdf) = shaped.sample(n, [0.3, 0.7]);
    assert!(d.iter().all(|c| c.is_finite()) && pdf.is_finite());
}

/// Detail for a tree of `levels` levels: the light's mass over each detail cell
/// (a midpoint of it), column sums first, in the leaves on a checkerboard
/// (16 x 16 cells) and in every leaf whose centre the sun lights (fine, 64 x 64
/// cells); the index, the tables and the fine tables.
fn detail_values(levels: u32) -> (Vec<u32>, Vec<f32>, Vec<f32>) {
    let side = 1usize << levels;
    let mut index = vec![0u32; detail_index_len(levels)];
    let (mut tables, mut fine) = (Vec::new(), Vec::new());
    let at = |x: f64, y: f64| light(square_to_sphere(DVec2::new(x, y) / side as f64));
    for (leaf, entry) in index.iter_mut().enumerate() {
        let (x, y) = ((leaf % side) as f64, (leaf / side) as f64);
        let sun = at(x + 0.5, y + 0.5) >= 5.0;
        if (leaf % side + leaf / side) % 2 == 1 && !sun {
            continue;
        }
        let (n, out, bit, len) = if sun {
            (FINE_SIDE, &mut fine, FINE_BIT, FINE_LEN)
        } else {
            (DETAIL_SIDE, &mut tables, 0, DETAIL_LEN)
        };
        *entry = bit | ((out.len() / len) as u32 + 1);
        // Column-major: cell `(a, b)` at `a n + b`.
        let cells: Vec<f32> = (0..n * n)
            .map(|c| {
                let (a, b) = ((c / n) as f64, (c % n) as f64);
                at(x + (a + 0.5) / n as f64, y + (b + 0.5) / n as f64) as f32
            })
            .collect();
        out.extend(cells.chunks(n).map(|c| c.iter().sum::<f32>()));
        out.extend(cells);
    }
    (index, tables, fine)
}

/// With detailed leaves beside shaped ones: the pdf integrates to 1 (a midpoint
/// rule of 16 x 16 points a leaf is exact for both shapes), a sample's pdf is the
/// pdf at its direction, `invert` undoes `sample`, 10^6 samples pass a
/// chi-square on 2 x 2 bins a leaf, the slopes are the warp's derivatives, and
/// `L cos / pdf` estimates the same irradiance with less spread than the
/// corners alone give. Wrong detail is refused; hostile detail never panics.
#[test]
fn detailed_leaves_keep_the_pdf_exact() {
    let levels = 6;
    let nodes = tree_nodes(levels);
    let top = top_table(levels, &nodes);
    let corners = corner_values(levels);
    let (index, tables, fine) = detail_values(levels);
    assert!(!fine.is_empty() && index.iter().any(|&e| e != 0 && e & FINE_BIT == 0));
    let shaped = EnvmapTree::new(levels, &nodes, GRID, &top, TOP_LEVELS)
        .unwrap()
        .with_corners(&corners)
        .unwrap();
    let tree = shaped
        .with_detail(&index, &tables)
        .and_then(|t| t.with_fine_detail(&fine))
        .unwrap();
    tree.check_values().unwrap();
    let n = [0.6, -0.3, 0.1];
    // A midpoint per fine cell: exact for both tables and the bilinear shape.
    let m = 64 * FINE_SIDE;
    let sum: f64 = (0..m * m)
        .map(|k| {
            let c = square_to_sphere(DVec2::new(
                ((k % m) as f64 + 0.5) / m as f64,
                ((k / m) as f64 + 0.5) / m as f64,
            ));
            tree.pdf(n, c.to_array()) * 4.0 * core::f64::consts::PI / (m * m) as f64
        })
        .sum();
    assert!((sum - 1.0).abs() < 1e-9, "{sum}");

    let bins = 128;
    check_samples(&tree, n, 8, 1e-8, bins, |i, j| {
        // A bin is 32 x 32 fine cells (8 x 8 detail cells): the mean of their
        // midpoints is exact for the tables and for the bilinear shape.
        let k = FINE_SIDE / 2;
        let mut pdf = 0.0;
        for b in 0..k {
            for a in 0..k {
                let c = square_to_sphere(DVec2::new(
                    (i as f64 + (a as f64 + 0.5) / k as f64) / bins as f64,
                    (j as f64 + (b as f64 + 0.5) / k as f64) / bins as f64,
                ));
                pdf += tree.pdf(n, c.to_array()) / (k * k) as f64;
            }
        }
        pdf
    });

    // Inside a detail cell the warp is affine per axis: the slopes are its
    // derivatives, and their product the inverse density.
    let q = crate::sphere::sphere_to_square(DVec3::from_array(n).normalize()).to_array();
    let mut r = Rng(31);
    let (h, mut compared, mut fine_compared) = (1e-8, 0, 0);
    for _ in 0..5000 {
        let u = [r.next() * 0.98 + 0.01, r.next() * 0.98 + 0.01];
        let (p, pdf, [dx, cross, dy]) = tree.sample_square_with_slopes(q, u);
        assert!((pdf * dx * dy - 1.0).abs() < 1e-9, "{pdf} {dx} {dy}");
        // The fine cells nest in the detail cells.
        let cell = |x: [f64; 2]| x.map(|c| (c * (64 * FINE_SIDE) as f64).floor());
        let at = |du: [f64; 2]| {
            tree.sample_square_with_slopes(q, [u[0] + du[0], u[1] + du[1]])
                .0
        };
        let (xl, xh, yl, yh) = (at([-h, 0.0]), at([h, 0.0]), at([0.0, -h]), at([0.0, h]));
        let entry = index[(p[1] * 64.0) as usize * 64 + (p[0] * 64.0) as usize];
        if entry != 0 && [xl, xh, yl, yh].iter().all(|&e| cell(e) == cell(p)) {
            fine_compared += usize::from(entry & FINE_BIT != 0);
            assert_eq!(cross, 0.0);
            let scale = dx.max(dy);
            assert!(((xh[0] - xl[0]) / (2.0 * h) - dx).abs() <= 1e-5 * scale);
            assert!(((yh[1] - yl[1]) / (2.0 * h) - dy).abs() <= 1e-5 * scale);
            compared += 1;
        }
    }
    assert!(
        compared > 1000 && fine_compared > 100,
        "{compared} {fine_compared}"
    );

    // The same estimate of the irradiance, with less spread.
    let (a, sa) = irradiance_estimate(&shaped, n, 78);
    let (b, sb) = irradiance_estimate(&tree, n, 78);
    assert!((a - b).abs() < 4.0 * (sa * sa + sb * sb).sqrt(), "{a} {b}");
    assert!(sb < 0.8 * sa, "detailed {sb} against shaped {sa}");

    // Wrong lengths and values are refused.
    assert!(shaped.with_detail(&index[1..], &tables).is_err());
    assert!(shaped.with_detail(&index, &tables[1..]).is_err());
    assert!(shaped.with_detail(&[], &tables).is_err());
    assert!(tree.with_fine_detail(&fine[1..]).is_err());
    fn with<'a>(
        shaped: EnvmapTree<'a>,
        index: &'a [u32],
        tables: &'a [f32],
        fine: &'a [f32],
    ) -> EnvmapTree<'a> {
        shaped
            .with_detail(index, tables)
            .and_then(|t| t.with_fine_detail(fine))
            .unwrap()
    }
    let (count, fine_count) = ((tables.len() / DETAIL_LEN) as u32, fine.len() / FINE_LEN);
    let mut past = [index.clone(), index.clone(), index.clone()];
    past[0][9] = count + 1;
    past[1][9] = FINE_BIT | (fine_count as u32 + 1);
    past[2][9] = FINE_BIT;
    let hostile: Vec<EnvmapTree<'_>> = past
        .iter()
        .map(|i| with(shaped, i, &tables, &fine))
        .collect();
    for t in &hostile {
        assert_eq!(t.check_values(), Err(QuadtreeError::BadDetailIndex(9)));
    }
    let mut bad = tables.clone();
    bad[40] = f32::INFINITY;
    let bad_tree = with(shaped, &index, &bad, &fine);
    assert_eq!(bad_tree.check_values(), Err(QuadtreeError::BadDetail(40)));
    let mut bad_fine = fine.clone();
    bad_fine[77] = -1.0;
    let bad_fine_tree = with(shaped, &index, &tables, &bad_fine);
    assert_eq!(
        bad_fine_tree.check_values(),
        Err(QuadtreeError::BadFineDetail(77))
    );
    // Bad values never make it panic, and the pdf stays finite.
    for t in hostile.into_iter().chain([bad_tree, bad_fine_tree]) {
        let mut r = Rng(4);
        for _ in 0..2000 {
            let (d, pdf) = t.sample(n, [r.next(), r.next()]);
            assert!(d.iter().all(|c| c.is_finite()) && pdf.is_finite());
            assert!(t.pdf(n, d).is_finite());
        }
    }
}
