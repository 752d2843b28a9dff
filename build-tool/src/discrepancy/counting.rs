//! Exact box counts for many boxes at once: 2D dominance counting by a sweep over x
//! with a Fenwick tree over y ranks, O((N + M) log N) for N points and M queries
//! (the dense alternative is O(N M)).

use glam::DVec2;

/// Counts of points around one query point `u`, from which the counts of all four
/// quadrant boxes follow (see [`QuadrantCounts::quadrants`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct QuadrantCounts {
    /// `#{i : x_i < u.x and y_i < u.y}`.
    pub lower_left: u32,
    /// `#{i : x_i < u.x}`.
    pub left: u32,
    /// `#{i : y_i < u.y}`.
    pub below: u32,
}

impl QuadrantCounts {
    /// Counts of the four quadrant boxes around `u` out of `n` points, in the order
    /// of [`crate::discrepancy::QUADRANTS`]: lower-left, lower-right, upper-left,
    /// upper-right.
    #[inline]
    pub fn quadrants(&self, n: u32) -> [u32; 4] {
        let ll = self.lower_left;
        [
            ll,
            self.below - ll,
            self.left - ll,
            n + ll - self.left - self.below,
        ]
    }
}

/// A Fenwick (binary indexed) tree of counts.
struct Fenwick(Vec<u32>);

impl Fenwick {
    fn new(n: usize) -> Self {
        Self(vec![0; n + 1])
    }
    fn add(&mut self, index: usize) {
        let mut i = index + 1;
        while i < self.0.len() {
            self.0[i] += 1;
            i += i & i.wrapping_neg();
        }
    }
    /// Sum of counts at indices `< end`.
    fn prefix(&self, end: usize) -> u32 {
        let mut i = end;
        let mut s = 0;
        while i > 0 {
            s += self.0[i];
            i &= i - 1;
        }
        s
    }
}

/// [`QuadrantCounts`] of `points` around every query, in query order. Comparisons are
/// strict (`<`); ties have probability zero for continuous queries.
pub fn quadrant_counts(points: &[DVec2], queries: &[DVec2]) -> Vec<QuadrantCounts> {
    let mut ys: Vec<f64> = points.iter().map(|p| p.y).collect();
    ys.sort_unstable_by(f64::total_cmp);
    let mut by_x: Vec<(f64, usize)> = points
        .iter()
        .map(|p| (p.x, ys.partition_point(|&y| y < p.y)))
        .collect();
    by_x.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let mut order: Vec<u32> = (0..queries.len() as u32).collect();
    order.sort_unstable_by(|&a, &b| queries[a as usize].x.total_cmp(&queries[b as usize].x));

    let mut tree = Fenwick::new(points.len());
    let mut inserted = 0;
    let mut out = vec![QuadrantCounts::default(); queries.len()];
    for q in order {
        let u = queries[q as usize];
        while inserted < by_x.len() && by_x[inserted].0 < u.x {
            tree.add(by_x[inserted].1);
            inserted += 1;
        }
        let below = ys.partition_point(|&y| y < u.y);
        out[q as usize] = QuadrantCounts {
            lower_left: tree.prefix(below),
            left: inserted as u32,
            below: below as u32,
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn matches_brute_force_counts() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(5);
        for (n, m) in [(0, 3), (1, 5), (17, 40), (300, 200)] {
            let pts: Vec<DVec2> = (0..n)
                .map(|_| DVec2::new(rng.random(), rng.random()))
                .collect();
            let qs: Vec<DVec2> = (0..m)
                .map(|_| DVec2::new(rng.random(), rng.random()))
                .collect();
            let got = quadrant_counts(&pts, &qs);
            for (u, c) in qs.iter().zip(&got) {
                let count = |f: &dyn Fn(&DVec2) -> bool| pts.iter().filter(|p| f(p)).count() as u32;
                let want = [
                    count(&|p| p.x < u.x && p.y < u.y),
                    count(&|p| p.x >= u.x && p.y < u.y),
                    count(&|p| p.x < u.x && p.y >= u.y),
                    count(&|p| p.x >= u.x && p.y >= u.y),
                ];
                assert_eq!(c.quadrants(n as u32), want);
            }
        }
    }
}
