extern crate std;

use super::*;
use crate::test_rng::Rng;
use std::vec;
use std::vec::Vec;

/// Tabulated tables of `nodes` nodes on `nx x ny` vertices: node `k`'s value at
/// vertex `(x, y)` is `value(k, x, y)`.
struct Tables {
    shape: Marginal2DShape,
    data: Vec<f64>,
    marginal: Vec<f64>,
    conditional: Vec<f64>,
}

impl Tables {
    fn new(nx: u32, ny: u32, nodes: u32, value: impl Fn(usize, f64, f64) -> f64) -> Self {
        let shape = Marginal2DShape {
            size: [nx, ny],
            nodes,
        };
        let (nxu, nyu) = (nx as usize, ny as usize);
        let mut data = Vec::new();
        for k in 0..nodes as usize {
            for j in 0..nyu {
                for i in 0..nxu {
                    let (x, y) = (i as f64 / (nxu - 1) as f64, j as f64 / (nyu - 1) as f64);
                    data.push(value(k, x, y));
                }
            }
        }
        let mut marginal = vec![0.0; shape.marginal_len().unwrap()];
        let mut conditional = vec![0.0; shape.data_len().unwrap()];
        tabulate(shape, &mut data, &mut marginal, &mut conditional).unwrap();
        Self {
            shape,
            data,
            marginal,
            conditional,
        }
    }

    fn warp(&self) -> Marginal2D<'_, f64> {
        Marginal2D::new(self.shape, &self.data, &self.marginal, &self.conditional).unwrap()
    }

    /// Node `k`'s normalized density at `(x, y)`, bilinear between its vertices,
    /// computed here from the data alone (not through the warp).
    fn node_density(&self, k: usize, x: f64, y: f64) -> f64 {
        let (nx, ny) = (self.shape.size[0] as usize, self.shape.size[1] as usize);
        let fx = x * (nx - 1) as f64;
        let fy = y * (ny - 1) as f64;
        let i = (fx.floor() as usize).min(nx - 2);
        let j = (fy.floor() as usize).min(ny - 2);
        let (s, t) = (fx - i as f64, fy - j as f64);
        let at = |i: usize, j: usize| self.data[(k * ny + j) * nx + i];
        (1.0 - t) * ((1.0 - s) * at(i, j) + s * at(i + 1, j))
            + t * ((1.0 - s) * at(i, j + 1) + s * at(i + 1, j + 1))
    }
}

/// Four nodes (a 2 x 2 parameter grid) of rather different shapes: a ramp, a
/// bump, a table with an empty band and a near-delta corner.
fn four_nodes() -> Tables {
    Tables::new(9, 7, 4, |k, x, y| match k {
        0 => 0.2 + x + 2.0 * y,
        1 => (-20.0 * ((x - 0.6).powi(2) + (y - 0.3).powi(2))).exp(),
        2 => {
            if (0.3..0.6).contains(&y) {
                0.0
            } else {
                1.0 + x * y
            }
        }
        _ => {
            if x > 0.8 && y > 0.8 {
                50.0
            } else {
                0.01
            }
        }
    })
}

#[test]
fn tabulation_normalizes_and_integrates_exactly() {
    // A constant table on 3 x 3 vertices: density 1, CDFs the coordinates.
    let t = Tables::new(3, 3, 1, |_, _, _| 7.0);
    assert!(t.data.iter().all(|&v| (v - 1.0).abs() < 1e-15));
    assert_eq!(t.marginal, vec![0.0, 0.5, 1.0]);
    assert_eq!(&t.conditional[..3], &[0.0, 0.5, 1.0]);
    // f(x, y) = x on 2 x 2 vertices: mass 1/2, so f = 2x; C_j(1) = 1 on each row.
    let t = Tables::new(2, 2, 1, |_, x, _| x);
    assert_eq!(t.data, vec![0.0, 2.0, 0.0, 2.0]);
    assert_eq!(t.conditional, vec![0.0, 1.0, 0.0, 1.0]);
    assert_eq!(t.marginal, vec![0.0, 1.0]);
}

#[test]
fn blend_weights_at_nodes_and_between_them() {
    // At a node: that node alone.
    let b = Blend::<f64>::multilinear(&[0.5, 1.0], &[3, 2]);
    assert_eq!(b.pairs().collect::<Vec<_>>(), vec![(4, 1.0)]);
    // Between: the multilinear weights, node i0 + 3 i1.
    let b = Blend::<f64>::multilinear(&[0.25, 0.75], &[3, 2]);
    let mut pairs: Vec<_> = b.pairs().collect();
    pairs.sort_by_key(|p| p.0);
    let want = [
        (0, 0.5 * 0.25),
        (1, 0.5 * 0.25),
        (3, 0.5 * 0.75),
        (4, 0.5 * 0.75),
    ];
    assert_eq!(pairs.len(), 4);
    for ((n, w), (m, v)) in pairs.iter().zip(want) {
        assert_eq!(*n, m);
        assert!((w - v).abs() < 1e-15, "{w} vs {v}");
    }
    // Clamped outside [0, 1], NaN as 0, one node per pinned axis, three axes.
    let b = Blend::<f64>::multilinear(&[-3.0, f64::NAN, 9.0], &[4, 5, 2]);
    assert_eq!(b.pairs().collect::<Vec<_>>(), vec![(20, 1.0)]);
    let b = Blend::<f64>::multilinear(&[0.5, 0.5, 0.5], &[2, 2, 2]);
    assert_eq!(b.pairs().count(), 8);
    assert!((b.pairs().map(|p| p.1).sum::<f64>() - 1.0).abs() < 1e-15);
    assert_eq!(Blend::<f64>::multilinear(&[], &[]).pairs().count(), 1);
}

#[test]
fn the_pdf_is_the_blend_of_the_node_densities() {
    let t = four_nodes();
    let w = t.warp();
    let mut r = Rng(3);
    for _ in 0..200 {
        let (a, b) = (r.next(), r.next());
        let blend = Blend::multilinear(&[a, b], &[2, 2]);
        let weights = [(1.0 - a) * (1.0 - b), a * (1.0 - b), (1.0 - a) * b, a * b];
        let (x, y) = (r.next(), r.next());
        let want: f64 = (0..4).map(|k| weights[k] * t.node_density(k, x, y)).sum();
        let got = w.pdf([x, y], &blend);
        assert!(
            (got - want).abs() <= 1e-12 * want.max(1.0),
            "{got} vs {want}"
        );
    }
}

#[test]
fn the_pdf_integrates_to_one_between_nodes() {
    let t = four_nodes();
    let w = t.warp();
    for params in [[0.0, 0.0], [0.3, 0.7], [0.5, 0.5], [1.0, 0.2]] {
        let blend = Blend::multilinear(&params, &[2, 2]);
        // The midpoint rule on sub-cells is exact for a bilinear function.
        let m = 8 * 6 * 4;
        let mut sum = 0.0;
        for j in 0..m {
            for i in 0..m {
                let p = [(i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64];
                sum += w.pdf(p, &blend);
            }
        }
        sum /= (m * m) as f64;
        assert!((sum - 1.0).abs() < 1e-12, "{params:?}: {sum}");
    }
}

#[test]
fn invert_undoes_sample_and_sample_undoes_invert() {
    let t = four_nodes();
    let w = t.warp();
    let mut r = Rng(11);
    let mut worst: f64 = 0.0;
    for _ in 0..20_000 {
        let blend = Blend::multilinear(&[r.next(), r.next()], &[2, 2]);
        let u = [r.next(), r.next()];
        let (p, pdf) = w.sample(u, &blend);
        assert!((0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1]));
        assert!(pdf > 0.0, "a sample where the density is 0: {p:?}");
        let back = w.invert(p, &blend);
        worst = worst
            .max((back[0] - u[0]).abs())
            .max((back[1] - u[1]).abs());
        let (q, _) = w.sample(w.invert(p, &blend), &blend);
        assert!((q[0] - p[0]).abs() < 1e-9 && (q[1] - p[1]).abs() < 1e-9);
    }
    assert!(worst < 1e-9, "worst round trip {worst}");
}

/// `sample_with_slopes` draws `sample`'s point and density, bit for bit, and its
/// slopes are the central differences of `sample` where the differences stay in
/// one table cell (a cell boundary is a kink of the piecewise warp); and `dy/du.x`
/// is 0 there: `y` reads `u.y` alone.
#[test]
fn the_slopes_are_the_derivatives_of_the_warp() {
    let t = four_nodes();
    let w = t.warp();
    let mut r = Rng(23);
    let (h, mut checked) = (1e-6, 0);
    let [nx, ny] = t.shape.size.map(|n| n as usize);
    let cells = |p: [f64; 2]| (cell(p[0], nx).0, cell(p[1], ny).0);
    for _ in 0..5000 {
        let blend = Blend::multilinear(&[r.next(), r.next()], &[2, 2]);
        let u = [0.02 + 0.96 * r.next(), 0.02 + 0.96 * r.next()];
        let (p, pdf, [dx_dux, dx_duy, dy_duy]) = w.sample_with_slopes(u, &blend);
        assert_eq!((p, pdf), w.sample(u, &blend));
        let at = |du: [f64; 2]| w.sample([u[0] + du[0], u[1] + du[1]], &blend).0;
        let ends = [at([h, 0.0]), at([-h, 0.0]), at([0.0, h]), at([0.0, -h])];
        if ends.iter().any(|&q| cells(q) != cells(p)) {
            continue;
        }
        let slope = |a: [f64; 2], b: [f64; 2], k: usize| (a[k] - b[k]) / (2.0 * h);
        let want = [
            slope(ends[0], ends[1], 0),
            slope(ends[2], ends[3], 0),
            slope(ends[2], ends[3], 1),
        ];
        for (got, want) in [dx_dux, dx_duy, dy_duy].into_iter().zip(want) {
            assert!(
                (got - want).abs() <= 1e-5 * want.abs().max(1.0),
                "u {u:?}: {got} vs {want}"
            );
        }
        assert!(slope(ends[0], ends[1], 1).abs() < 1e-9);
        checked += 1;
    }
    assert!(checked > 4000, "only {checked} points inside a cell");
}

/// The warp keeps one copy per blend size (1, 2, 4 and 8 slots, 3 and 5 to 7
/// nodes padded with empty slots): every size samples its own pdf, which is the
/// weighted average of the nodes' densities computed here from the data alone,
/// and a node of weight 0 appended to a blend changes no bit of it.
#[test]
fn blends_of_every_size_sample_their_own_pdf() {
    let t = Tables::new(9, 7, 8, |k, x, y| {
        let c = (k as f64 + 0.5) / 8.0;
        0.05 + (-(6.0 + k as f64) * ((x - c).powi(2) + (y - 1.0 + c).powi(2))).exp()
            + x * y * (k % 3) as f64
    });
    let w = t.warp();
    let mut r = Rng(21);
    for size in 1..=8usize {
        for _ in 0..20 {
            let pairs: Vec<(u32, f64)> = (0..size)
                .map(|k| ((k * 5 % 8) as u32, 0.05 + r.next()))
                .collect();
            let blend = Blend::from_pairs(&pairs);
            let mut padded = pairs.clone();
            padded.push((3, 0.0));
            let padded = Blend::from_pairs(&padded);
            let mass: f64 = pairs.iter().map(|p| p.1).sum();
            for _ in 0..50 {
                let u = [r.next(), r.next()];
                let (p, pdf) = w.sample(u, &blend);
                let want: f64 = pairs
                    .iter()
                    .map(|&(k, wk)| wk * t.node_density(k as usize, p[0], p[1]))
                    .sum::<f64>()
                    / mass;
                assert!(
                    (pdf - want).abs() <= 1e-12 * want.max(1.0),
                    "size {size}: {pdf} vs {want}"
                );
                let back = w.invert(p, &blend);
                assert!(
                    (back[0] - u[0]).abs() < 1e-9 && (back[1] - u[1]).abs() < 1e-9,
                    "size {size}: {u:?} came back as {back:?}"
                );
                if size < 8 {
                    assert_eq!(w.sample(u, &padded), (p, pdf), "size {size}");
                    assert_eq!(w.pdf(p, &padded), w.pdf(p, &blend), "size {size}");
                }
            }
        }
    }
}

/// A chi-square test of 10^6 samples against the pdf on 16 x 16 bins, at a blend
/// of all four nodes: each bin lies inside one table cell, where the density is
/// bilinear and the midpoint rule gives the bin's mass exactly.
#[test]
fn samples_follow_the_pdf_chi_square() {
    let t = Tables::new(9, 9, 4, |k, x, y| match k {
        0 => 0.2 + x + 2.0 * y,
        1 => (-8.0 * ((x - 0.6).powi(2) + (y - 0.3).powi(2))).exp(),
        2 => 1.0 + 3.0 * x * (1.0 - y),
        _ => 0.5 + (6.0 * x).sin().abs() * y,
    });
    let w = t.warp();
    let blend = Blend::multilinear(&[0.35, 0.6], &[2, 2]);
    let bins = 16;
    let samples = 1_000_000;
    let mut counts = vec![0u32; bins * bins];
    let mut r = Rng(5);
    for _ in 0..samples {
        let (p, _) = w.sample([r.next(), r.next()], &blend);
        let i = ((p[0] * bins as f64) as usize).min(bins - 1);
        let j = ((p[1] * bins as f64) as usize).min(bins - 1);
        counts[j * bins + i] += 1;
    }
    let mut chi2 = 0.0;
    for j in 0..bins {
        for i in 0..bins {
            let c = [
                (i as f64 + 0.5) / bins as f64,
                (j as f64 + 0.5) / bins as f64,
            ];
            let expected = samples as f64 * w.pdf(c, &blend) / (bins * bins) as f64;
            let d = counts[j * bins + i] as f64 - expected;
            chi2 += d * d / expected;
        }
    }
    // 255 degrees of freedom: mean 255, standard deviation 22.6; 5 deviations.
    assert!(chi2 < 255.0 + 5.0 * 22.6, "chi-square {chi2}");
    // And it is a real test: the samples are far from a wrong density (node 0's).
    let node0 = Blend::single(0);
    let mut wrong = 0.0;
    for j in 0..bins {
        for i in 0..bins {
            let c = [
                (i as f64 + 0.5) / bins as f64,
                (j as f64 + 0.5) / bins as f64,
            ];
            let expected = samples as f64 * w.pdf(c, &node0) / (bins * bins) as f64;
            let d = counts[j * bins + i] as f64 - expected;
            wrong += d * d / expected;
        }
    }
    assert!(
        wrong > 10.0 * (255.0 + 5.0 * 22.6),
        "wrong density passes: {wrong}"
    );
}

#[test]
fn empty_bands_are_never_sampled() {
    let t = four_nodes();
    let w = t.warp();
    // Node 2 alone has no mass for y in (0.3, 0.6) beyond the vertex rows'
    // interpolation: the rows at y = 1/3 and 1/2 are 0, so (1/3, 1/2) is empty.
    let blend = Blend::single(2);
    let mut r = Rng(17);
    for _ in 0..50_000 {
        let (p, pdf) = w.sample([r.next(), r.next()], &blend);
        assert!(!(p[1] > 1.0 / 3.0 + 1e-12 && p[1] < 0.5 - 1e-12), "{p:?}");
        assert!(pdf > 0.0);
    }
    // The edges of the unit interval of u land inside the square.
    for u in [
        [0.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [1.0, 0.0],
        [f64::NAN, 2.0],
    ] {
        let (p, pdf) = w.sample(u, &blend);
        assert!(
            (0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1]),
            "{u:?}"
        );
        assert!(pdf.is_finite());
    }
}

#[test]
fn f32_tables_sample_what_f64_tables_do() {
    let t = four_nodes();
    let data: Vec<f32> = t.data.iter().map(|&v| v as f32).collect();
    let marginal: Vec<f32> = t.marginal.iter().map(|&v| v as f32).collect();
    let conditional: Vec<f32> = t.conditional.iter().map(|&v| v as f32).collect();
    let w32 = Marginal2D::new(t.shape, &data, &marginal, &conditional).unwrap();
    let w64 = t.warp();
    let mut r = Rng(23);
    for _ in 0..10_000 {
        let (a, b, ux, uy) = (r.next(), r.next(), r.next(), r.next());
        let (p, pdf) = w32.sample(
            [ux as f32, uy as f32],
            &Blend::multilinear(&[a as f32, b as f32], &[2, 2]),
        );
        let (q, qdf) = w64.sample([ux, uy], &Blend::multilinear(&[a, b], &[2, 2]));
        assert!((p[0] as f64 - q[0]).abs() < 2e-4 && (p[1] as f64 - q[1]).abs() < 2e-4);
        assert!(
            (pdf as f64 - qdf).abs() < 1e-3 * qdf.max(1.0),
            "{pdf} vs {qdf}"
        );
    }
}

#[test]
fn bad_tables_are_refused_and_bad_queries_do_not_panic() {
    let t = four_nodes();
    let (d, m, c) = (&t.data[..], &t.marginal[..], &t.conditional[..]);
    let shape = t.shape;
    let bad = |s: Marginal2DShape, d: &[f64], m: &[f64], c: &[f64]| {
        Marginal2D::new(s, d, m, c).unwrap_err()
    };
    assert_eq!(
        bad(
            Marginal2DShape {
                size: [1, 7],
                ..shape
            },
            d,
            m,
            c
        ),
        Marginal2DError::Shape
    );
    assert!(matches!(
        bad(shape, &d[1..], m, c),
        Marginal2DError::Length { slice: 0, .. }
    ));
    let huge = Marginal2DShape {
        size: [u32::MAX, u32::MAX],
        nodes: u32::MAX,
    };
    assert!(matches!(
        bad(huge, d, m, c),
        Marginal2DError::Length { slice: 0, .. }
    ));
    let mut neg = d.to_vec();
    neg[5] = -1.0;
    assert_eq!(
        bad(shape, &neg, m, c),
        Marginal2DError::BadValue { slice: 0, index: 5 }
    );
    let mut nan = c.to_vec();
    nan[3] = f64::NAN;
    assert_eq!(
        bad(shape, d, m, &nan),
        Marginal2DError::BadValue { slice: 2, index: 3 }
    );
    let mut down = m.to_vec();
    down.swap(2, 3);
    assert_eq!(
        bad(shape, d, &down, c),
        Marginal2DError::Decreasing { slice: 1, index: 3 }
    );
    let zero_m = vec![0.0; m.len()];
    assert_eq!(
        bad(shape, d, &zero_m, c),
        Marginal2DError::NoMass { node: 0 }
    );
    let mut zero = vec![0.0; d.len()];
    let (mut mm, mut cc) = (vec![0.0; m.len()], vec![0.0; c.len()]);
    assert_eq!(
        tabulate(shape, &mut zero, &mut mm, &mut cc),
        Err(Marginal2DError::NoMass { node: 0 })
    );
    // A blend naming nodes past the tables reads them as empty.
    let w = t.warp();
    let stray = Blend::from_pairs(&[(99, 1.0)]);
    assert_eq!(w.pdf([0.5, 0.5], &stray), 0.0);
    let (p, pdf) = w.sample([0.3, f64::INFINITY], &stray);
    assert!(p[0].is_finite() && p[1].is_finite() && pdf == 0.0);
    let _ = w.invert([f64::NAN, -4.0], &stray);
    let (p, _) = w.sample([0.3, 0.4], &Blend::from_pairs(&[(0, f64::NAN), (1, 1.0)]));
    assert!(p[0].is_finite() && p[1].is_finite());
}

/// The answer `search` promises, by brute force: the largest `k <= n - 2` with
/// `cdf(k) <= target` (0 if none), then moved off intervals without mass as the
/// contract says.
fn brute_search(cdf: &[f64], target: f64) -> usize {
    let n = cdf.len();
    let mut k = (0..n - 1).rev().find(|&k| cdf[k] <= target).unwrap_or(0);
    while k > 0 && cdf[k + 1] <= cdf[k] {
        k -= 1;
    }
    while k + 2 < n && cdf[k + 1] <= cdf[k] {
        k += 1;
    }
    k
}

#[test]
fn search_finds_the_brute_force_interval_at_every_length() {
    let mut rng = Rng(0x5ea7c4);
    for n in [
        2usize, 3, 16, 17, 18, 33, 96, 255, 256, 257, 258, 300, 1024, 4097,
    ] {
        for trial in 0..40 {
            // Non-decreasing with runs of equal values (intervals without mass).
            let mut v = 0.0;
            let cdf: Vec<f64> = (0..n)
                .map(|k| {
                    if k > 0 && rng.next() < 0.6 - 0.01 * trial as f64 {
                        v += rng.next();
                    }
                    v
                })
                .collect();
            let top = cdf[n - 1];
            let mut targets = vec![0.0, top, -1.0, top + 1.0];
            targets.extend(cdf.iter().copied());
            targets.extend((0..20).map(|_| rng.next() * top));
            for t in targets {
                let k = brute_search(&cdf, t);
                assert_eq!(search(n, t, |k| cdf[k]), (k, cdf[k]), "n {n} target {t}");
            }
        }
    }
}

#[test]
fn search_stays_in_range_on_a_cdf_that_decreases_or_is_nan() {
    let mut rng = Rng(0xbad);
    for n in [2usize, 17, 96, 300, 4097] {
        let cdf: Vec<f64> = (0..n).map(|_| rng.next()).collect();
        for t in [-1.0, 0.0, 0.3, 0.7, 2.0, f64::NAN] {
            assert!(search(n, t, |k| cdf[k]).0 <= n - 2, "n {n} target {t}");
        }
    }
}
