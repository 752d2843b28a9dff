//! Point–point kernel means shared by the L2 discrepancies (the `(1/N^2) sum_i sum_k`
//! terms of docs/metrics.md), exact in `O(N log N)` by sorting and Fenwick-tree dominance
//! sums, with dense `O(N^2)` references.

use glam::DVec2;
use rayon::prelude::*;

use super::sum::Neumaier;

/// Rows of the outer sum handled by one task in the dense references. Fixed (not tied
/// to the thread count) so that the summation order, hence the result, is identical
/// whatever the number of threads.
const DENSE_CHUNK: usize = 64;

/// Warnock (origin-anchored L2-star) point–point term
/// `(1/N^2) sum_i sum_k prod_j (1 - max(x_ij, x_kj))`, exact in `O(N log N)`.
///
/// Points are sorted by `x`; for the pair `i` before `k` the `x` factor is
/// `1 - x_k`, and the `y` factors of the earlier points are split at `y_k` by a
/// Fenwick tree over the ranks of `y` (counts and sums of `1 - y`). Ties in either
/// coordinate are handled exactly. Deterministic (sequential). Returns 0 for no points.
pub fn l2_star_pair_term(points: &[DVec2]) -> f64 {
    let n = points.len();
    if n == 0 {
        return 0.0;
    }
    let order = sort_by_x(points);
    let (rank, ranks) = y_ranks(points);
    let mut diag = Neumaier::default();
    for p in points {
        diag.add((1.0 - p.x) * (1.0 - p.y));
    }
    // Fields: count, sum of (1 - y).
    let mut fen = Fenwick::<2>::new(ranks);
    let mut all = [0.0f64; 2];
    let mut off = Neumaier::default();
    for &k in &order {
        let p = points[k];
        let r = rank[k];
        let le = fen.prefix(r + 1);
        let gt_sum = all[1] - le[1];
        off.add((1.0 - p.x) * (le[0] * (1.0 - p.y) + gt_sum));
        let v = [1.0, 1.0 - p.y];
        fen.add(r, v);
        all[0] += v[0];
        all[1] += v[1];
    }
    (diag.total() + 2.0 * off.total()) / (n as f64 * n as f64)
}

/// Dense `O(N^2)` reference for [`l2_star_pair_term`]: the same quantity
/// `(1/N^2) sum_i sum_k prod_j (1 - max(x_ij, x_kj))`, parallel over `i` in fixed
/// chunks with fixed-order summation (deterministic whatever the thread count).
pub fn l2_star_pair_term_dense(points: &[DVec2]) -> f64 {
    dense_pair_mean(points, |a, b| (1.0 - a.x.max(b.x)) * (1.0 - a.y.max(b.y)))
}

/// Average-squared-discrepancy point–point term
/// `(1/N^2) sum_i sum_k prod_j (1 - |x_ij - x_kj|)/2`, exact in `O(N log N)`.
///
/// Expands `(1-|dx|)(1-|dy|) = 1 - |dx| - |dy| + |dx||dy|`: the one-dimensional sums
/// come from sorted coordinates, `sum |dx||dy|` from a sweep in `x` with a Fenwick tree
/// over the ranks of `y` holding counts and sums of `x`, `y`, `xy`. Ties are handled
/// exactly. Deterministic (sequential). Returns 0 for no points.
pub fn asd_pair_term(points: &[DVec2]) -> f64 {
    let n = points.len();
    if n == 0 {
        return 0.0;
    }
    let order = sort_by_x(points);
    let (rank, ranks) = y_ranks(points);

    let xs: Vec<f64> = order.iter().map(|&i| points[i].x).collect();
    let mut ys: Vec<f64> = points.iter().map(|p| p.y).collect();
    ys.sort_by(f64::total_cmp);
    let sum_abs_dx = sorted_abs_diff_sum(&xs);
    let sum_abs_dy = sorted_abs_diff_sum(&ys);

    // Fields: count, sum x, sum y, sum xy.
    let mut fen = Fenwick::<4>::new(ranks);
    let mut all = [0.0f64; 4];
    let mut prod = Neumaier::default();
    for &k in &order {
        let p = points[k];
        let r = rank[k];
        let le = fen.prefix(r + 1);
        let gt = [
            all[0] - le[0],
            all[1] - le[1],
            all[2] - le[2],
            all[3] - le[3],
        ];
        // sum over the earlier points of (x - x_i)(y - y_i).
        let f = |s: [f64; 4]| p.x * p.y * s[0] - p.x * s[2] - p.y * s[1] + s[3];
        prod.add(f(le));
        prod.add(-f(gt));
        let v = [1.0, p.x, p.y, p.x * p.y];
        fen.add(r, v);
        for (a, b) in all.iter_mut().zip(v) {
            *a += b;
        }
    }
    let nf = n as f64;
    let pairs = nf * (nf - 1.0) / 2.0;
    let mut off = Neumaier::default();
    off.add(pairs);
    off.add(-sum_abs_dx);
    off.add(-sum_abs_dy);
    off.add(prod.total());
    (nf + 2.0 * off.total()) / (4.0 * nf * nf)
}

/// Dense `O(N^2)` reference for [`asd_pair_term`]: the same quantity
/// `(1/N^2) sum_i sum_k prod_j (1 - |x_ij - x_kj|)/2`, parallel over `i` in fixed
/// chunks with fixed-order summation (deterministic whatever the thread count).
pub fn asd_pair_term_dense(points: &[DVec2]) -> f64 {
    dense_pair_mean(points, |a, b| {
        0.25 * (1.0 - (a.x - b.x).abs()) * (1.0 - (a.y - b.y).abs())
    })
}

/// `(1/N^2) sum_i sum_k kernel(x_i, x_k)`, deterministic parallel double sum.
fn dense_pair_mean(points: &[DVec2], kernel: impl Fn(DVec2, DVec2) -> f64 + Sync) -> f64 {
    let n = points.len();
    if n == 0 {
        return 0.0;
    }
    let partial: Vec<f64> = points
        .par_chunks(DENSE_CHUNK)
        .map(|chunk| {
            let mut s = Neumaier::default();
            for &a in chunk {
                for &b in points {
                    s.add(kernel(a, b));
                }
            }
            s.total()
        })
        .collect();
    let mut s = Neumaier::default();
    for v in partial {
        s.add(v);
    }
    s.total() / (n as f64 * n as f64)
}

/// `sum_{i<k} (v_k - v_i)` for ascending `v`.
fn sorted_abs_diff_sum(v: &[f64]) -> f64 {
    let mut prefix = 0.0;
    let mut s = Neumaier::default();
    for (k, &x) in v.iter().enumerate() {
        s.add(k as f64 * x - prefix);
        prefix += x;
    }
    s.total()
}

/// Indices sorted by ascending `x` (stable, total order).
fn sort_by_x(points: &[DVec2]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a].x.total_cmp(&points[b].x));
    order
}

/// Dense ranks of the `y` coordinates (equal values share a rank) and the number
/// of distinct values.
fn y_ranks(points: &[DVec2]) -> (Vec<usize>, usize) {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a].y.total_cmp(&points[b].y));
    let mut rank = vec![0usize; points.len()];
    let mut r = 0usize;
    for (j, &i) in order.iter().enumerate() {
        if j > 0 && points[i].y != points[order[j - 1]].y {
            r += 1;
        }
        rank[i] = r;
    }
    (rank, if points.is_empty() { 0 } else { r + 1 })
}

/// A Fenwick (binary indexed) tree of `K` summed fields.
struct Fenwick<const K: usize> {
    tree: Vec<[f64; K]>,
}

impl<const K: usize> Fenwick<K> {
    fn new(n: usize) -> Self {
        Self {
            tree: vec![[0.0; K]; n + 1],
        }
    }

    /// Adds `v` at position `i` (0-based).
    fn add(&mut self, i: usize, v: [f64; K]) {
        let mut j = i + 1;
        while j < self.tree.len() {
            for (t, x) in self.tree[j].iter_mut().zip(v) {
                *t += x;
            }
            j += j & j.wrapping_neg();
        }
    }

    /// Sum over positions `0..i`.
    fn prefix(&self, i: usize) -> [f64; K] {
        let mut acc = [0.0; K];
        let mut j = i;
        while j > 0 {
            for (a, t) in acc.iter_mut().zip(self.tree[j]) {
                *a += t;
            }
            j &= j - 1;
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::test_util::{random_points, SplitMix64};

    #[test]
    fn fast_pair_terms_match_dense() {
        let mut rng = SplitMix64::new(7);
        for &n in &[1usize, 2, 3, 10, 57, 300] {
            let pts = random_points(&mut rng, n);
            let (a, b) = (l2_star_pair_term(&pts), l2_star_pair_term_dense(&pts));
            assert!((a - b).abs() <= 1e-14, "n={n}: {a} vs {b}");
            let (a, b) = (asd_pair_term(&pts), asd_pair_term_dense(&pts));
            assert!((a - b).abs() <= 1e-14, "n={n}: {a} vs {b}");
        }
    }

    #[test]
    fn fast_pair_terms_handle_ties() {
        // Coordinates on a coarse lattice: many equal x, equal y and duplicate points.
        let mut rng = SplitMix64::new(11);
        for &n in &[2usize, 9, 40, 200] {
            let pts: Vec<DVec2> = (0..n)
                .map(|_| {
                    DVec2::new(
                        (rng.next_f64() * 5.0).floor() / 4.0,
                        (rng.next_f64() * 4.0).floor() / 3.0,
                    )
                })
                .collect();
            let (a, b) = (l2_star_pair_term(&pts), l2_star_pair_term_dense(&pts));
            assert!((a - b).abs() <= 1e-14, "n={n}: {a} vs {b}");
            let (a, b) = (asd_pair_term(&pts), asd_pair_term_dense(&pts));
            assert!((a - b).abs() <= 1e-14, "n={n}: {a} vs {b}");
        }
    }

    #[test]
    fn dense_is_deterministic() {
        let mut rng = SplitMix64::new(3);
        let pts = random_points(&mut rng, 1000);
        let a = asd_pair_term_dense(&pts);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let b = pool.install(|| asd_pair_term_dense(&pts));
        assert_eq!(a.to_bits(), b.to_bits());
    }
}
