extern crate std;

use super::*;
use crate::test_rng::Rng;
use std::vec;
use std::vec::Vec;

/// A pyramid of `levels` levels over leaves `mass(x, y)` at leaf centres.
fn pyramid(levels: u32, mass: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    let side = 1usize << levels;
    let leaves: Vec<f64> = (0..side * side)
        .map(|k| {
            let (x, y) = ((k % side) as f64 + 0.5, (k / side) as f64 + 0.5);
            mass(x / side as f64, y / side as f64)
        })
        .collect();
    let mut p = vec![0.0; pyramid_len(levels)];
    build_pyramid(levels, &leaves, &mut p).unwrap();
    p
}

/// A factor that is 0 on the nodes left of `x = 0.3` at every level below 1 and
/// grows to the right: a query-time product like a cosine's bound.
fn factor(l: u32, x: u32, _y: u32) -> f64 {
    if l < 2 {
        return 1.0;
    }
    let right_edge = (x + 1) as f64 / (1u64 << l) as f64;
    if right_edge <= 0.3 {
        0.0
    } else {
        right_edge
    }
}

/// The weight of a child: its mass times [`factor`].
fn weigh(l: u32, x: u32, y: u32, mass: f64) -> f64 {
    mass * factor(l, x, y)
}

fn sharp(x: f64, y: f64) -> f64 {
    0.05 + (-60.0 * ((x - 0.7).powi(2) + (y - 0.4).powi(2))).exp() + if y > 0.9 { 3.0 } else { 0.0 }
}

#[test]
fn pyramid_levels_hold_sums_of_their_children() {
    let p = pyramid(3, |x, y| x + 2.0 * y);
    assert_eq!(level_offset(0), 0);
    assert_eq!(level_offset(1), 1);
    assert_eq!(level_offset(2), 5);
    assert_eq!(pyramid_len(3), 85);
    // 64 leaves at centres (i + 0.5) / 8: the sum of x + 2y is 64 * 1.5.
    assert!((p[0] - 96.0).abs() < 1e-12);
    let level1: f64 = p[1..5].iter().sum();
    assert!((level1 - p[0]).abs() < 1e-12);
}

#[test]
fn the_pdf_integrates_to_one_and_vanishes_where_the_product_does() {
    let levels = 6;
    let p = pyramid(levels, sharp);
    let w = QuadtreeWarp::new(levels, &p).unwrap();
    let side = 1usize << levels;
    let mut sum = 0.0;
    for k in 0..side * side {
        let c = [
            ((k % side) as f64 + 0.5) / side as f64,
            ((k / side) as f64 + 0.5) / side as f64,
        ];
        let pdf = w.pdf(c, weigh);
        if c[0] < 0.25 {
            assert_eq!(pdf, 0.0, "{c:?}");
        }
        sum += pdf / (side * side) as f64;
    }
    assert!((sum - 1.0).abs() < 1e-12, "{sum}");
}

#[test]
fn invert_undoes_sample() {
    let levels = 7;
    let p = pyramid(levels, sharp);
    let w = QuadtreeWarp::new(levels, &p).unwrap();
    let mut r = Rng(9);
    let mut worst: f64 = 0.0;
    for _ in 0..20_000 {
        let u = [r.next(), r.next()];
        let (x, pdf) = w.sample(u, weigh);
        // Leaves whose right edge passes 0.3 (the factor's zero region ends there).
        assert!(pdf > 0.0 && x[0] >= 38.0 / 128.0 - 1e-12, "{x:?} {pdf}");
        assert!((w.pdf(x, weigh) - pdf).abs() <= 1e-9 * pdf);
        let back = w.invert(x, weigh);
        worst = worst
            .max((back[0] - u[0]).abs())
            .max((back[1] - u[1]).abs());
    }
    assert!(worst < 1e-9, "{worst}");
}

/// 10^6 samples on 32 x 32 bins (each a union of leaves, where the density is
/// constant): chi-square against the pdf, and far from the mass alone (the
/// factor ignored).
#[test]
fn samples_follow_the_pdf_chi_square() {
    let levels = 6;
    let p = pyramid(levels, sharp);
    let w = QuadtreeWarp::new(levels, &p).unwrap();
    let bins = 32;
    let samples = 1_000_000;
    let mut counts = vec![0u32; bins * bins];
    let mut r = Rng(4);
    for _ in 0..samples {
        let (x, _) = w.sample([r.next(), r.next()], weigh);
        let i = ((x[0] * bins as f64) as usize).min(bins - 1);
        let j = ((x[1] * bins as f64) as usize).min(bins - 1);
        counts[j * bins + i] += 1;
    }
    let chi2 = |f: &dyn Fn([f64; 2]) -> f64| {
        let (mut chi2, mut dof) = (0.0, 0);
        for j in 0..bins {
            for i in 0..bins {
                // A bin is 2 x 2 leaves: the mean pdf of their centres.
                let leaf = |a: usize, b: usize| {
                    f([
                        (2 * i + a) as f64 / 64.0 + 1.0 / 128.0,
                        (2 * j + b) as f64 / 64.0 + 1.0 / 128.0,
                    ])
                };
                let pdf = (leaf(0, 0) + leaf(1, 0) + leaf(0, 1) + leaf(1, 1)) / 4.0;
                let expected = samples as f64 * pdf / (bins * bins) as f64;
                let c = counts[j * bins + i] as f64;
                if expected > 0.0 {
                    chi2 += (c - expected).powi(2) / expected;
                    dof += 1;
                } else {
                    assert_eq!(c, 0.0, "samples where the pdf is 0");
                }
            }
        }
        (chi2, dof)
    };
    let (good, dof) = chi2(&|x| w.pdf(x, weigh));
    let sd = (2.0 * dof as f64).sqrt();
    assert!(
        good < dof as f64 + 5.0 * sd,
        "chi-square {good} over {dof} bins"
    );
    let (bad, _) = chi2(&|x| w.pdf(x, |_, _, _, m| m));
    assert!(
        bad > 10.0 * (dof as f64 + 5.0 * sd),
        "the mass alone passes: {bad}"
    );
}

/// `g / pdf` estimates `∫ g` for `g = mass density x the factor's true function`
/// (here `x`, which the per-node factor bounds from above to the right of 0.3).
#[test]
fn the_estimate_is_unbiased_for_a_function_the_factor_bounds() {
    let levels = 6;
    let p = pyramid(levels, sharp);
    let w = QuadtreeWarp::new(levels, &p).unwrap();
    let side = 64.0;
    // The density the pyramid describes: leaf mass over the total, per unit area.
    let density = |x: [f64; 2]| {
        let (i, j) = ((x[0] * side) as usize, (x[1] * side) as usize);
        p[level_offset(levels) + j.min(63) * 64 + i.min(63)] / p[0] * side * side
    };
    let g = |x: [f64; 2]| density(x) * if x[0] > 0.3 { x[0] } else { 0.0 };
    // The integral by a fine midpoint rule (the density is constant per leaf).
    let m = 1024;
    let mut exact = 0.0;
    for k in 0..m * m {
        let x = [
            ((k % m) as f64 + 0.5) / m as f64,
            ((k / m) as f64 + 0.5) / m as f64,
        ];
        exact += g(x) / (m * m) as f64;
    }
    let mut r = Rng(77);
    let n = 400_000;
    let (mut sum, mut sq) = (0.0, 0.0);
    for _ in 0..n {
        let (x, pdf) = w.sample([r.next(), r.next()], weigh);
        let v = g(x) / pdf;
        sum += v;
        sq += v * v;
    }
    let mean = sum / n as f64;
    let se = ((sq / n as f64 - mean * mean) / n as f64).sqrt();
    assert!(
        (mean - exact).abs() < 4.0 * se,
        "{mean} vs {exact} (se {se})"
    );
}

#[test]
fn bad_pyramids_are_refused_and_queries_do_not_panic() {
    let p = pyramid(2, |x, _| x);
    assert!(matches!(
        QuadtreeWarp::new(3, &p),
        Err(QuadtreeError::Length { .. })
    ));
    assert_eq!(
        QuadtreeWarp::<f64>::new(99, &p).unwrap_err(),
        QuadtreeError::Levels(99)
    );
    let mut bad = p.clone();
    bad[7] = f64::NAN;
    assert_eq!(
        QuadtreeWarp::new(2, &bad).unwrap_err(),
        QuadtreeError::BadMass(7)
    );
    let zero = vec![0.0; p.len()];
    assert_eq!(
        QuadtreeWarp::new(2, &zero).unwrap_err(),
        QuadtreeError::NoMass
    );
    // Weights that are NaN (or 0) everywhere: the masses decide.
    let w = QuadtreeWarp::new(2, &p).unwrap();
    for u in [[0.5, 0.5], [0.0, 1.0], [f64::NAN, 7.0]] {
        let (x, pdf) = w.sample(u, |_, _, _, _| f64::NAN);
        assert!(x[0].is_finite() && pdf.is_finite() && pdf > 0.0, "{u:?}");
        let back = w.invert(x, |_, _, _, _| 0.0);
        assert!(back[0].is_finite() && back[1].is_finite());
    }
    // The f32 instantiation samples.
    let p32: Vec<f32> = p.iter().map(|&v| v as f32).collect();
    let w32 = QuadtreeWarp::new(2, &p32).unwrap();
    let (x, pdf) = w32.sample([0.3, 0.6], |_, _, _, m: f32| m);
    assert!(x[0] > 0.0 && pdf > 0.0);
}

/// A node's Morton code against the bits interleaved one at a time, kept by
/// [`Node::child`] down a path as [`Node::new`] computes it, and an ancestor's
/// taken from its leaf's code as computed afresh.
#[test]
fn morton_codes_kept_along_a_path_match_the_interleaved_bits() {
    let brute = |x: u32, y: u32| {
        (0..32).fold(0u64, |z, b| {
            z | (((x >> b) & 1) as u64) << (2 * b) | (((y >> b) & 1) as u64) << (2 * b + 1)
        })
    };
    let mut r = Rng(3);
    for _ in 0..2000 {
        let (x, y) = ((r.next() * 4.0e9) as u32, (r.next() * 4.0e9) as u32);
        assert_eq!(morton(x, y), brute(x, y), "({x}, {y})");
    }
    assert_eq!(morton(u32::MAX, u32::MAX), u64::MAX);
    for _ in 0..200 {
        let levels = 1 + (r.next() * MAX_LEVELS as f64) as u32 % MAX_LEVELS;
        let mut node = Node::ROOT;
        let mut path = Vec::new();
        for _ in 0..levels {
            node = node.child((r.next() * 4.0) as u32 % 4);
            assert_eq!(node, Node::new(node.level, node.x, node.y));
            path.push(node);
        }
        for &a in &path {
            let up = Node::ancestor(levels, [node.x, node.y], node.z, a.level);
            assert_eq!(up, a);
        }
    }
}
