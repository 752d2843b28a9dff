extern crate std;

use super::*;
use crate::test_rng::{assert_chi_square, Rng};
use std::format;

/// Corner sets the tests run over: equal, one corner dark, a diagonal, steep,
/// one corner alone.
const CORNERS: [[f64; 4]; 5] = [
    [1.0, 1.0, 1.0, 1.0],
    [0.0, 2.0, 1.0, 3.0],
    [5.0, 0.1, 0.1, 5.0],
    [0.01, 9.0, 0.02, 0.5],
    [0.0, 0.0, 0.0, 4.0],
];

/// The density, written from its definition (module docs), not from the
/// marginal and conditional the warp uses.
fn direct(p: [f64; 2], w: [f64; 4]) -> f64 {
    let [x, y] = p;
    let b =
        (1.0 - x) * (1.0 - y) * w[0] + x * (1.0 - y) * w[1] + (1.0 - x) * y * w[2] + x * y * w[3];
    4.0 * b / w.iter().sum::<f64>()
}

#[test]
fn the_pdf_is_the_bilinear_density_and_integrates_to_one() {
    for w in CORNERS {
        let m = 256;
        let mut total = 0.0;
        for k in 0..m * m {
            let p = [
                ((k % m) as f64 + 0.5) / m as f64,
                ((k / m) as f64 + 0.5) / m as f64,
            ];
            let pdf = bilinear_pdf(p, w);
            assert!(
                (pdf - direct(p, w)).abs() <= 1e-12 * (1.0 + pdf),
                "{w:?} {p:?}"
            );
            total += pdf;
        }
        // The midpoint rule is exact for a bilinear function.
        let total = total / (m * m) as f64;
        assert!((total - 1.0).abs() < 1e-12, "{w:?}: {total}");
    }
}

/// 10^6 samples on 16 x 16 bins: chi-square against the density integrated
/// over each bin (exactly, by its corners: the density is bilinear); and far
/// from uniform points.
#[test]
fn samples_follow_the_pdf_chi_square() {
    for (t, w) in CORNERS.into_iter().enumerate() {
        let bins = 16;
        let mut r = Rng(11 + t as u64);
        let draw = || {
            let (p, pdf, _) = sample_bilinear([r.next(), r.next()], w);
            assert!((pdf - bilinear_pdf(p, w)).abs() <= 1e-9 * (1.0 + pdf));
            p
        };
        // The mean of a bilinear function over a cell is its corners' mean.
        let mean = |i: usize, j: usize| {
            let at = |a: usize, b: usize| {
                direct(
                    [(i + a) as f64 / bins as f64, (j + b) as f64 / bins as f64],
                    w,
                )
            };
            (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) / 4.0
        };
        assert_chi_square(&format!("{w:?}"), 1_000_000, bins, draw, mean, t > 0);
    }
}

#[test]
fn invert_undoes_sample_and_the_slopes_are_the_derivatives() {
    let mut r = Rng(3);
    for w in CORNERS {
        for _ in 0..2000 {
            let u = [0.02 + 0.96 * r.next(), 0.02 + 0.96 * r.next()];
            let (p, _, slopes) = sample_bilinear(u, w);
            let back = invert_bilinear(p, w);
            assert!(
                (back[0] - u[0]).abs() < 1e-9 && (back[1] - u[1]).abs() < 1e-9,
                "{w:?} {u:?} {back:?}"
            );
            let h = 1e-6;
            let dx = (sample_bilinear([u[0] + h, u[1]], w).0[0]
                - sample_bilinear([u[0] - h, u[1]], w).0[0])
                / (2.0 * h);
            let dy = (sample_bilinear([u[0], u[1] + h], w).0[1]
                - sample_bilinear([u[0], u[1] - h], w).0[1])
                / (2.0 * h);
            let cross = (sample_bilinear([u[0] + h, u[1]], w).0[1]
                - sample_bilinear([u[0] - h, u[1]], w).0[1])
                / (2.0 * h);
            for (k, fd) in [(0, dx), (1, cross), (2, dy)] {
                assert!(
                    (fd - slopes[k]).abs() <= 1e-4 * (1.0 + fd.abs()),
                    "{w:?} {k}: {fd} {slopes:?}"
                );
            }
        }
    }
}

/// Equal corners, no usable corner, hostile values: the identity or a warp of
/// the usable corners, never a NaN or a point outside the square; `f32` follows
/// `f64`.
#[test]
fn degenerate_corners_and_f32() {
    let u = [0.3, 0.8];
    let (p, pdf, _) = sample_bilinear(u, [2.0; 4]);
    assert!((p[0] - 0.3).abs() < 1e-15 && (p[1] - 0.8).abs() < 1e-15 && (pdf - 1.0).abs() < 1e-15);
    for w in [
        [0.0; 4],
        [-1.0, f64::NAN, -3.0, 0.0],
        [f64::INFINITY, 1.0, 1.0, 1.0],
    ] {
        let (p, pdf, s) = sample_bilinear(u, w);
        assert!(
            p.iter().chain(&s).all(|v| v.is_finite()) && pdf.is_finite(),
            "{w:?}"
        );
    }
    // A NaN corner counts as 0.
    let (a, ..) = sample_bilinear(u, [f64::NAN, 1.0, 2.0, 3.0]);
    let (b, ..) = sample_bilinear(u, [0.0, 1.0, 2.0, 3.0]);
    assert_eq!(a, b);
    for bad in [[f64::NAN, 0.5], [-2.0, 7.0]] {
        let (p, pdf, _) = sample_bilinear(bad, CORNERS[1]);
        assert!(p.iter().all(|v| (0.0..=1.0).contains(v)) && pdf.is_finite());
    }
    let mut r = Rng(9);
    for w in CORNERS {
        for _ in 0..1000 {
            let u = [r.next(), r.next()];
            let (p64, pdf64, _) = sample_bilinear(u, w);
            let (p32, pdf32, _) = sample_bilinear(u.map(|v| v as f32), w.map(|v| v as f32));
            assert!((p32[0] as f64 - p64[0]).abs() < 1e-4 && (p32[1] as f64 - p64[1]).abs() < 1e-4);
            assert!((pdf32 as f64 - pdf64).abs() <= 1e-3 * (1.0 + pdf64));
        }
    }
}
