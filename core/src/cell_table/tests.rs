extern crate std;

use super::*;
use crate::test_rng::{assert_chi_square, Rng};
use std::format;
use std::vec;
use std::vec::Vec;

const K: usize = 4;

const LEN: usize = table_len(K);

/// The table of cells given row-major (`c[b K + a]`), as a writer stores it:
/// the column sums, then the cells column by column.
fn pack(c: [f32; K * K]) -> [f32; LEN] {
    let mut t = [0.0; LEN];
    for a in 0..K {
        for b in 0..K {
            t[K + a * K + b] = c[b * K + a];
            t[a] += c[b * K + a];
        }
    }
    t
}

/// Tables the tests run over: flat, one bright cell (a sun in a leaf), a ramp,
/// empty columns and rows, one cell alone; and one whose stored column masses
/// are not its columns' sums (a hostile blob's, still sampled exactly).
fn tables() -> Vec<[f32; LEN]> {
    let mut sun = [0.01f32; K * K];
    sun[2 * K + 1] = 50.0;
    let ramp = core::array::from_fn(|k| (k % K + 2 * (k / K)) as f32);
    let mut holes = [1.0f32; K * K];
    for b in 0..K {
        holes[b * K + 2] = 0.0;
    }
    holes[3] = 0.0;
    let mut alone = [0.0f32; K * K];
    alone[K * K - 1] = 3.0;
    let mut odd = pack(ramp);
    odd[..K].copy_from_slice(&[5.0, 0.5, 2.0, 1.0]);
    vec![
        pack([1.0; K * K]),
        pack(sun),
        pack(ramp),
        pack(holes),
        pack(alone),
        odd,
    ]
}

/// The density written from its definition (module docs), from the column
/// masses and the cells read row-major, not from the warp's sums.
fn direct(p: [f64; 2], t: &[f32]) -> f64 {
    let a = ((p[0] * K as f64) as usize).min(K - 1);
    let b = ((p[1] * K as f64) as usize).min(K - 1);
    let total: f64 = t[..K].iter().map(|&x| x as f64).sum();
    let column: f64 = t[K + a * K..K + (a + 1) * K]
        .iter()
        .map(|&x| x as f64)
        .sum();
    if t[a] == 0.0 {
        return 0.0;
    }
    (K * K) as f64 * (t[a] as f64 / total) * (t[K + a * K + b] as f64 / column)
}

#[test]
fn the_pdf_is_the_tables_density_and_integrates_to_one() {
    for v in tables() {
        let m = 64;
        let mut total = 0.0;
        for k in 0..m * m {
            let p = [
                ((k % m) as f64 + 0.5) / m as f64,
                ((k / m) as f64 + 0.5) / m as f64,
            ];
            let pdf = table_pdf::<f64, K>(p, &v);
            assert!(
                (pdf - direct(p, &v)).abs() <= 1e-12 * (1.0 + pdf),
                "{v:?} {p:?}"
            );
            total += pdf;
        }
        let total = total / (m * m) as f64;
        assert!((total - 1.0).abs() < 1e-12, "{v:?}: {total}");
    }
}

/// 10^6 samples on 16 x 16 bins (four a cell): chi-square against the density
/// integrated over each bin, from [`direct`]; none where it is 0; and far from
/// uniform points.
#[test]
fn samples_follow_the_pdf_chi_square() {
    for (t, v) in tables().into_iter().enumerate() {
        let bins = 16;
        let mut r = Rng(21 + t as u64);
        let draw = || {
            let (p, pdf, _) = sample_table::<f64, K>([r.next(), r.next()], &v);
            assert!((pdf - table_pdf::<f64, K>(p, &v)).abs() <= 1e-12 * (1.0 + pdf));
            p
        };
        // A bin lies inside one cell, where the density is constant.
        let mean = |i: usize, j: usize| {
            direct(
                [
                    (i as f64 + 0.5) / bins as f64,
                    (j as f64 + 0.5) / bins as f64,
                ],
                &v,
            )
        };
        assert_chi_square(&format!("{v:?}"), 1_000_000, bins, draw, mean, t > 0);
    }
}

#[test]
fn invert_undoes_sample_and_the_slopes_are_the_derivatives() {
    let mut r = Rng(5);
    for v in tables() {
        for _ in 0..4000 {
            let u = [r.next(), r.next()];
            let (p, pdf, slopes) = sample_table::<f64, K>(u, &v);
            let back = invert_table::<f64, K>(p, &v);
            assert!(
                (back[0] - u[0]).abs() < 1e-12 && (back[1] - u[1]).abs() < 1e-12,
                "{v:?} {u:?} {back:?}"
            );
            // Inside a cell the map is affine per axis: central differences
            // agree unless the step crosses a cell's edge.
            let h = 1e-7;
            let at = |du: [f64; 2]| sample_table::<f64, K>([u[0] + du[0], u[1] + du[1]], &v).0;
            let dx = (at([h, 0.0])[0] - at([-h, 0.0])[0]) / (2.0 * h);
            let dy = (at([0.0, h])[1] - at([0.0, -h])[1]) / (2.0 * h);
            let same_cell = |q: [f64; 2]| {
                (q[0] * K as f64).floor() == (p[0] * K as f64).floor()
                    && (q[1] * K as f64).floor() == (p[1] * K as f64).floor()
            };
            if [at([h, 0.0]), at([-h, 0.0])].into_iter().all(same_cell) {
                assert!(
                    (dx - slopes[0]).abs() <= 1e-5 * (1.0 + dx.abs()),
                    "{v:?} {u:?}: {dx} {slopes:?}"
                );
                assert_eq!(at([h, 0.0])[1], p[1], "y moves with u.x inside a cell");
            }
            if [at([0.0, h]), at([0.0, -h])].into_iter().all(same_cell) {
                assert!(
                    (dy - slopes[2]).abs() <= 1e-5 * (1.0 + dy.abs()),
                    "{v:?} {u:?}: {dy} {slopes:?}"
                );
            }
            assert_eq!(slopes[1], 0.0);
            // The Jacobian's determinant is the inverse density.
            assert!((slopes[0] * slopes[2] * pdf - 1.0).abs() < 1e-12);
        }
    }
}

/// No usable value, hostile values and points: the identity or a warp of the
/// usable values, never a NaN or a point outside the square; `f32` follows
/// `f64`.
#[test]
fn degenerate_tables_and_f32() {
    let u = [0.3, 0.8];
    for v in [
        [0.0f32; LEN],
        [f32::NAN; LEN],
        [-1.0; LEN],
        [f32::INFINITY; LEN],
    ] {
        let (p, pdf, s) = sample_table::<f64, K>(u, &v);
        assert_eq!((p, pdf, s), (u, 1.0, [1.0, 0.0, 1.0]), "{v:?}");
        assert_eq!(table_pdf::<f64, K>(u, &v), 1.0);
        assert_eq!(invert_table::<f64, K>(u, &v), u);
    }
    // A NaN or negative value counts as 0.
    let mut nan = tables()[2];
    let mut zero = nan;
    nan[5] = f32::NAN;
    zero[5] = 0.0;
    assert_eq!(
        sample_table::<f64, K>(u, &nan),
        sample_table::<f64, K>(u, &zero)
    );
    // A column with mass but no cell of value: uniform along `y` in it, its pdf
    // the column's share alone.
    let mut bare = tables()[2];
    bare[K + K..K + 2 * K].fill(0.0);
    let mut r = Rng(4);
    for _ in 0..200 {
        let u = [r.next(), r.next()];
        let (p, pdf, _) = sample_table::<f64, K>(u, &bare);
        assert_eq!(pdf, table_pdf::<f64, K>(p, &bare));
        if (p[0] * K as f64) as usize == 1 {
            assert_eq!(p[1], u[1]);
            assert!(
                (pdf - K as f64 * bare[1] as f64 / 72.0).abs() < 1e-12,
                "{pdf}"
            );
        }
        assert!((invert_table::<f64, K>(p, &bare)[0] - u[0]).abs() < 1e-12);
    }
    // A short table is no table: the identity.
    let short = &tables()[2][..LEN - 3];
    assert_eq!(sample_table::<f64, K>(u, short), (u, 1.0, [1.0, 0.0, 1.0]));
    assert_eq!(table_pdf::<f64, K>(u, short), 1.0);
    assert_eq!(invert_table::<f64, K>(u, short), u);
    for bad in [[f64::NAN, 0.5], [-2.0, 7.0], [1.0, 1.0], [0.0, 0.0]] {
        for v in tables() {
            let (p, pdf, s) = sample_table::<f64, K>(bad, &v);
            assert!(p.iter().all(|c| (0.0..=1.0).contains(c)) && pdf.is_finite() && pdf > 0.0);
            assert!(s.iter().all(|c| c.is_finite()));
        }
    }
    let mut r = Rng(9);
    for v in tables() {
        let v = &v;
        for _ in 0..1000 {
            let u = [r.next(), r.next()];
            let (p64, pdf64, _) = sample_table::<f64, K>(u, v);
            let (p32, pdf32, _) = sample_table::<f32, K>(u.map(|c| c as f32), v);
            // A point near a cell's edge may round into the neighbour.
            if (p32[0] as f64 - p64[0]).abs() < 1e-4 && (p32[1] as f64 - p64[1]).abs() < 1e-4 {
                let same = table_pdf::<f64, K>(p32.map(|c| c as f64), v);
                assert!((pdf32 as f64 - same).abs() <= 1e-5 * (1.0 + same));
            } else {
                panic!("{v:?} {u:?}: f32 {p32:?} against f64 {p64:?} ({pdf32} {pdf64})");
            }
        }
    }
}
