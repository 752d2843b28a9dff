//! Non-uniform L2 discrepancies for a piecewise-constant measure given as a
//! [`CellGrid`]: the all-corner average squared discrepancy (kernel form) and the
//! origin-anchored L2-star (docs/metrics.md). Both are exact and cost
//! `O(W H + N log N)`: the measure–measure term by separable operators on the grid,
//! the point–measure term in `O(1)` per point from summed-area tables, the
//! point–point term by [`super::pairs`].

use glam::DVec2;

use super::l2::non_empty;
use super::pairs::{asd_pair_term, l2_star_pair_term};
use super::sum::{sum, Neumaier};
use crate::density::CellGrid;

/// Squared non-uniform average squared discrepancy of `points` for the piecewise-constant
/// measure `mu` of `grid`, kernel form with `K(x,y) = prod_j (1 - |x_j - y_j|)/2`:
///
/// `(D2asd_mu)^2 = ∫∫K dmu dmu - (2/N) sum_i ∫K(x_i,y) dmu(y)
///                 + (1/N^2) sum_i sum_k K(x_i,x_k)`
///
/// `= E_{u,c}[(#{x_i in B(u,c)}/N - mu(B(u,c)))^2]` over `u ~ U[0,1]^2` and the four
/// corners `c` of the square. Exact (closed-form per-axis cell integrals); cost
/// `O(W H + N log N)` for a `W x H` grid, deterministic. Clamped at 0 against rounding.
/// Panics if `points` is empty or `grid.mass.len() != width * height`.
pub fn asd_cells_squared(points: &[DVec2], grid: &CellGrid) -> f64 {
    let n = non_empty(points);
    check_grid(grid);
    let self_term = asd_measure_term(grid);
    let sat = Sat::new(grid);
    let cross = sum(points
        .iter()
        .map(|p| sat.separable(&asd_axis(p.x, grid.width), &asd_axis(p.y, grid.height))));
    (self_term - 2.0 * cross / n + asd_pair_term(points)).max(0.0)
}

/// Non-uniform average squared discrepancy `D2asd_mu` for the measure of `grid`: the
/// square root of [`asd_cells_squared`]. `O(W H + N log N)`. Panics as that does.
pub fn asd_cells(points: &[DVec2], grid: &CellGrid) -> f64 {
    asd_cells_squared(points, grid).sqrt()
}

/// Squared non-uniform (origin-anchored) L2-star discrepancy of `points` for the
/// piecewise-constant measure `mu` of `grid`, with `F(a) = mu([0,a_x] x [0,a_y])`:
///
/// `(D2*_mu)^2 = ∫_{[0,1]^2} (#{x_i <= a}/N - F(a))^2 da
///             = ∫F^2 da - (2/N) sum_i ∫_{a >= x_i} F(a) da
///               + (1/N^2) sum_i sum_k prod_j (1 - max(x_ij, x_kj))`.
///
/// `F` is bilinear on each cell, so `∫F^2` is exact per cell; the middle term is
/// `∫ prod_j (1 - max(x_ij, y_j)) dmu(y)`, exact from summed-area tables. Cost
/// `O(W H + N log N)`, deterministic. Equals [`super::l2_star_uniform_squared`] for a
/// uniform grid. Clamped at 0 against rounding. Panics if `points` is empty or
/// `grid.mass.len() != width * height`.
pub fn l2_star_cells_squared(points: &[DVec2], grid: &CellGrid) -> f64 {
    let n = non_empty(points);
    check_grid(grid);
    let sat = Sat::new(grid);
    let self_term = sat.cdf_squared_integral(grid);
    let cross = sum(points
        .iter()
        .map(|p| sat.separable(&star_axis(p.x, grid.width), &star_axis(p.y, grid.height))));
    (self_term - 2.0 * cross / n + l2_star_pair_term(points)).max(0.0)
}

/// Non-uniform L2-star discrepancy `D2*_mu` for the measure of `grid`: the square root
/// of [`l2_star_cells_squared`]. `O(W H + N log N)`. Panics as that does.
pub fn l2_star_cells(points: &[DVec2], grid: &CellGrid) -> f64 {
    l2_star_cells_squared(points, grid).sqrt()
}

fn check_grid(grid: &CellGrid) {
    assert!(
        grid.width > 0 && grid.height > 0 && grid.mass.len() == grid.width * grid.height,
        "CellGrid {}x{} has {} masses",
        grid.width,
        grid.height,
        grid.mass.len()
    );
}

/// `∫∫K dmu dmu` for the asd kernel. Per axis, the average of `(1 - |s - t|)/2` over
/// `s` in cell `i`, `t` in cell `j` (width `h`) is `(1 - |m_i - m_j|)/2` for `i != j`
/// (disjoint cells: the mean distance is the distance of the centres `m`) and
/// `(1 - h/3)/2` for `i = j`; this is docs/metrics.md's `((b-a)(d-c) - H)/2` divided by the
/// cell areas, without its cancellation. The double sum over cell pairs is then
/// `sum M ∘ (T_y M T_x)` with Toeplitz `T`, each applied in linear time.
fn asd_measure_term(grid: &CellGrid) -> f64 {
    let (w, h) = (grid.width, grid.height);
    let mut tmp = grid.mass.clone();
    let mut buf_in = vec![0.0; w.max(h)];
    let mut buf_out = vec![0.0; w.max(h)];
    for row in tmp.chunks_exact_mut(w) {
        buf_in[..w].copy_from_slice(row);
        apply_asd_toeplitz(&buf_in[..w], &mut buf_out[..w]);
        row.copy_from_slice(&buf_out[..w]);
    }
    for col in 0..w {
        for r in 0..h {
            buf_in[r] = tmp[r * w + col];
        }
        apply_asd_toeplitz(&buf_in[..h], &mut buf_out[..h]);
        for r in 0..h {
            tmp[r * w + col] = buf_out[r];
        }
    }
    sum(grid.mass.iter().zip(&tmp).map(|(m, q)| m * q))
}

/// `out[i] = sum_j v_j (1 - |m_i - m_j|)/2 - (h/6) v_i` with `m_i = (i + 1/2) h`,
/// `h = 1/len`, in `O(len)` by prefix sums of `v` and `v m`.
fn apply_asd_toeplitz(v: &[f64], out: &mut [f64]) {
    let n = v.len();
    let h = 1.0 / n as f64;
    let centre = |i: usize| (i as f64 + 0.5) * h;
    // Left sums (j < i) into out, as sum_j<i v_j (m_i - m_j).
    let (mut l0, mut l1) = (Neumaier::default(), Neumaier::default());
    for i in 0..n {
        out[i] = centre(i) * l0.total() - l1.total();
        l0.add(v[i]);
        l1.add(v[i] * centre(i));
    }
    let total = l0.total();
    let (mut r0, mut r1) = (Neumaier::default(), Neumaier::default());
    for i in (0..n).rev() {
        let dist = out[i] + (r1.total() - centre(i) * r0.total());
        out[i] = 0.5 * total - 0.5 * dist - h / 6.0 * v[i];
        r0.add(v[i]);
        r1.add(v[i] * centre(i));
    }
}

/// One axis of a separable point–cell kernel for a point coordinate lying in cell
/// `cell`: the cell-averaged kernel is `lo.0 + lo.1 * m_c` on cells left of it,
/// `hi.0 + hi.1 * m_c` right of it (`m_c` the cell centre) and `own` on its own cell.
struct AxisForm {
    cell: usize,
    lo: (f64, f64),
    own: f64,
    hi: (f64, f64),
}

/// The cell containing `x` among `n` cells of width `1/n`, with `[a, b]` its bounds;
/// guarantees `a <= x <= b` for `x` in `[0,1]`.
fn locate(x: f64, n: usize) -> (usize, f64, f64) {
    let nf = n as f64;
    let mut c = ((x * nf).floor().max(0.0) as usize).min(n - 1);
    while c > 0 && x < c as f64 / nf {
        c -= 1;
    }
    while c + 1 < n && x > (c + 1) as f64 / nf {
        c += 1;
    }
    (c, c as f64 / nf, (c + 1) as f64 / nf)
}

/// Axis form of `t -> (1 - |x - t|)/2` averaged over cells (docs/metrics.md per-axis
/// closed form divided by the width `h`): `(1 - |x - m_c|)/2` off the own cell,
/// `1/2 - ((x-a)^2 + (b-x)^2)/(4h)` on it.
fn asd_axis(x: f64, n: usize) -> AxisForm {
    let (cell, a, b) = locate(x, n);
    AxisForm {
        cell,
        lo: (0.5 * (1.0 - x), 0.5),
        own: 0.5 - ((x - a) * (x - a) + (b - x) * (b - x)) * n as f64 / 4.0,
        hi: (0.5 * (1.0 + x), -0.5),
    }
}

/// Axis form of `t -> 1 - max(x, t)` averaged over cells: `1 - x` left of the own cell,
/// `1 - m_c` right of it, `((x-a)(1-x) + (b-x)(1-(b+x)/2))/h` on it.
fn star_axis(x: f64, n: usize) -> AxisForm {
    let (cell, a, b) = locate(x, n);
    AxisForm {
        cell,
        lo: (1.0 - x, 0.0),
        own: ((x - a) * (1.0 - x) + (b - x) * (1.0 - 0.5 * (b + x))) * n as f64,
        hi: (1.0, -1.0),
    }
}

/// Summed-area tables of `M`, `M m_c`, `M m_r`, `M m_c m_r` (cell centres
/// `m_c = (c+1/2)/W`, `m_r = (r+1/2)/H`), built with compensated sums:
/// `data[r * (W+1) + c]` sums the cells with row `< r` and column `< c`.
struct Sat {
    w: usize,
    h: usize,
    data: Vec<[f64; 4]>,
}

impl Sat {
    fn new(grid: &CellGrid) -> Self {
        let (w, h) = (grid.width, grid.height);
        let stride = w + 1;
        let mut data = vec![[0.0; 4]; stride * (h + 1)];
        let mut col_acc = vec![[Neumaier::default(); 4]; w];
        for r in 0..h {
            let mr = (r as f64 + 0.5) / h as f64;
            let mut row_acc = [Neumaier::default(); 4];
            for c in 0..w {
                let mc = (c as f64 + 0.5) / w as f64;
                let m = grid.mass[r * w + c];
                let v = [m, m * mc, m * mr, m * mc * mr];
                for f in 0..4 {
                    row_acc[f].add(v[f]);
                    col_acc[c][f].add(row_acc[f].total());
                    data[(r + 1) * stride + c + 1][f] = col_acc[c][f].total();
                }
            }
        }
        Self { w, h, data }
    }

    /// Sums over columns `c0..c1` and rows `r0..r1`.
    fn rect(&self, c0: usize, c1: usize, r0: usize, r1: usize) -> [f64; 4] {
        if c0 >= c1 || r0 >= r1 {
            return [0.0; 4];
        }
        let s = self.w + 1;
        let (a, b, c, d) = (
            self.data[r1 * s + c1],
            self.data[r0 * s + c1],
            self.data[r1 * s + c0],
            self.data[r0 * s + c0],
        );
        std::array::from_fn(|f| (a[f] - b[f]) - (c[f] - d[f]))
    }

    /// `sum_{r,c} M[r,c] gx_c gy_r` for separable axis forms: nine blocks (left / own /
    /// right columns times below / own / above rows), each a rectangle query.
    fn separable(&self, x: &AxisForm, y: &AxisForm) -> f64 {
        let xb = [
            (0, x.cell, x.lo),
            (x.cell, x.cell + 1, (x.own, 0.0)),
            (x.cell + 1, self.w, x.hi),
        ];
        let yb = [
            (0, y.cell, y.lo),
            (y.cell, y.cell + 1, (y.own, 0.0)),
            (y.cell + 1, self.h, y.hi),
        ];
        let mut acc = Neumaier::default();
        for &(r0, r1, (ay, by)) in &yb {
            for &(c0, c1, (ax, bx)) in &xb {
                let s = self.rect(c0, c1, r0, r1);
                acc.add(ax * ay * s[0] + bx * ay * s[1] + ax * by * s[2] + bx * by * s[3]);
            }
        }
        acc.total()
    }

    /// `∫_{[0,1]^2} F^2` with `F` the CDF: `F` is the bilinear interpolant of the grid
    /// node values `SAT[r][c]` on each cell, and for bilinear `f` with corner values
    /// `f_ij`, `∫_cell f^2 = area * sum f_ij f_kl m_ik m_jl` with the 1D mass matrix
    /// `m = [[1/3, 1/6], [1/6, 1/3]]`.
    fn cdf_squared_integral(&self, grid: &CellGrid) -> f64 {
        let (w, h) = (grid.width, grid.height);
        let s = w + 1;
        let f = |r: usize, c: usize| self.data[r * s + c][0];
        let mut acc = Neumaier::default();
        for r in 0..h {
            let mut row = Neumaier::default();
            for c in 0..w {
                let (f00, f10, f01, f11) = (f(r, c), f(r, c + 1), f(r + 1, c), f(r + 1, c + 1));
                row.add(
                    (f00 * f00 + f10 * f10 + f01 * f01 + f11 * f11) / 9.0
                        + (f00 * f10 + f01 * f11 + f00 * f01 + f10 * f11) / 9.0
                        + (f00 * f11 + f10 * f01) / 18.0,
                );
            }
            acc.add(row.total());
        }
        acc.total() / (w as f64 * h as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::test_util::{
        corner_boxes, integrate_pieces, random_grid, random_points, uniform_grid, SplitMix64,
    };
    use crate::metrics::{asd_uniform_squared, l2_star_uniform_squared};

    /// Exact measure of the box `[lo, hi]` by clipping every cell (independent of the
    /// summed-area tables).
    fn measure(grid: &CellGrid, lo: DVec2, hi: DVec2) -> f64 {
        let (w, h) = (grid.width as f64, grid.height as f64);
        let mut m = 0.0;
        for r in 0..grid.height {
            for c in 0..grid.width {
                let ox = ((c + 1) as f64 / w).min(hi.x) - (c as f64 / w).max(lo.x);
                let oy = ((r + 1) as f64 / h).min(hi.y) - (r as f64 / h).max(lo.y);
                if ox > 0.0 && oy > 0.0 {
                    m += grid.mass[r * grid.width + c] * ox * oy * w * h;
                }
            }
        }
        m
    }

    fn breaks(n: usize) -> Vec<f64> {
        (1..n).map(|i| i as f64 / n as f64).collect()
    }

    fn rel_close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-300)
    }

    #[test]
    fn uniform_grid_matches_uniform_formulas() {
        let mut rng = SplitMix64::new(1);
        for &(w, h) in &[(1usize, 1usize), (3, 5), (8, 8), (17, 4)] {
            let grid = uniform_grid(w, h);
            for &n in &[1usize, 5, 64] {
                let mut pts = random_points(&mut rng, n);
                // Include points on cell boundaries and the square's edges.
                if n > 3 {
                    pts[0] = DVec2::new(1.0 / w as f64, 0.0);
                    pts[1] = DVec2::new(1.0, 2.0 / h as f64);
                    pts[2] = DVec2::new(0.0, 1.0);
                }
                let (a, b) = (asd_cells_squared(&pts, &grid), asd_uniform_squared(&pts));
                assert!((a - b).abs() < 1e-12, "asd {w}x{h} n={n}: {a} vs {b}");
                let (a, b) = (
                    l2_star_cells_squared(&pts, &grid),
                    l2_star_uniform_squared(&pts),
                );
                assert!((a - b).abs() < 1e-12, "l2* {w}x{h} n={n}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn l2_star_cells_matches_quadrature_of_definition() {
        let mut rng = SplitMix64::new(42);
        for &(w, h, n) in &[(4usize, 3usize, 9usize), (5, 2, 1), (3, 7, 20)] {
            let grid = random_grid(&mut rng, w, h);
            let mut pts = random_points(&mut rng, n);
            if n > 2 {
                pts[1] = DVec2::new(2.0 / w as f64, pts[1].y); // on a grid line
            }
            let nf = n as f64;
            let reference = integrate_pieces(&pts, &breaks(w), &breaks(h), |a| {
                let c = pts.iter().filter(|p| p.x <= a.x && p.y <= a.y).count() as f64;
                (c / nf - measure(&grid, DVec2::ZERO, a)).powi(2)
            });
            let v = l2_star_cells_squared(&pts, &grid);
            assert!(
                rel_close(v, reference, 1e-10),
                "{w}x{h} n={n}: {v} vs {reference}"
            );
        }
    }

    #[test]
    fn l2_star_cells_matches_midpoint_rule() {
        // The brief's check: midpoint rule on 1000x1000 anchors, exact F.
        let mut rng = SplitMix64::new(9);
        let grid = random_grid(&mut rng, 4, 3);
        let pts = random_points(&mut rng, 6);
        let m = 1000;
        let mut acc = 0.0;
        for i in 0..m {
            for j in 0..m {
                let a = DVec2::new((i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64);
                let c = pts.iter().filter(|p| p.x <= a.x && p.y <= a.y).count() as f64;
                acc += (c / 6.0 - measure(&grid, DVec2::ZERO, a)).powi(2);
            }
        }
        let reference = acc / (m * m) as f64;
        let v = l2_star_cells_squared(&pts, &grid);
        assert!(rel_close(v, reference, 2e-3), "{v} vs {reference}");
    }

    #[test]
    fn asd_cells_matches_quadrature_of_definition() {
        let mut rng = SplitMix64::new(43);
        for &(w, h, n) in &[(4usize, 3usize, 9usize), (2, 5, 1), (6, 3, 15)] {
            let grid = random_grid(&mut rng, w, h);
            let mut pts = random_points(&mut rng, n);
            if n > 2 {
                pts[2] = DVec2::new(pts[2].x, 1.0 / h as f64); // on a grid line
            }
            let nf = n as f64;
            let reference = integrate_pieces(&pts, &breaks(w), &breaks(h), |u| {
                let mut acc = 0.0;
                for (lo, hi) in corner_boxes(u) {
                    let c = pts
                        .iter()
                        .filter(|p| p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y)
                        .count() as f64;
                    acc += 0.25 * (c / nf - measure(&grid, lo, hi)).powi(2);
                }
                acc
            });
            let v = asd_cells_squared(&pts, &grid);
            assert!(
                rel_close(v, reference, 1e-10),
                "{w}x{h} n={n}: {v} vs {reference}"
            );
        }
    }

    /// docs/metrics.md's per-axis formulas, evaluated cell by cell (dense reference).
    fn g_design(x: f64, a: f64, b: f64) -> f64 {
        let g = if x <= a {
            ((b - x).powi(2) - (a - x).powi(2)) / 2.0
        } else if x >= b {
            ((x - a).powi(2) - (x - b).powi(2)) / 2.0
        } else {
            ((x - a).powi(2) + (b - x).powi(2)) / 2.0
        };
        ((b - a) - g) / 2.0
    }

    fn hh_design(a: f64, b: f64, c: f64, d: f64) -> f64 {
        let hf = |u: f64, v: f64| (u.powi(3) + v.powi(3) - (u - v).abs().powi(3)) / 6.0;
        let big_h = hf(b, d) - hf(b, c) - hf(a, d) + hf(a, c);
        ((b - a) * (d - c) - big_h) / 2.0
    }

    #[test]
    fn asd_cells_matches_dense_design_formulas() {
        let mut rng = SplitMix64::new(77);
        let (w, h) = (7usize, 5usize);
        let grid = random_grid(&mut rng, w, h);
        let pts = random_points(&mut rng, 50);
        let (wf, hf) = (w as f64, h as f64);
        let cell = |i: usize| (i % w, i / w);
        let mut self_term = 0.0;
        for i in 0..w * h {
            for j in 0..w * h {
                let ((c, r), (c2, r2)) = (cell(i), cell(j));
                let ix = hh_design(
                    c as f64 / wf,
                    (c + 1) as f64 / wf,
                    c2 as f64 / wf,
                    (c2 + 1) as f64 / wf,
                );
                let iy = hh_design(
                    r as f64 / hf,
                    (r + 1) as f64 / hf,
                    r2 as f64 / hf,
                    (r2 + 1) as f64 / hf,
                );
                self_term += grid.mass[i] * grid.mass[j] * ix * iy * (wf * hf).powi(2);
            }
        }
        let mut cross = 0.0;
        for p in &pts {
            for (i, &m) in grid.mass.iter().enumerate() {
                let (c, r) = cell(i);
                let gx = g_design(p.x, c as f64 / wf, (c + 1) as f64 / wf) * wf;
                let gy = g_design(p.y, r as f64 / hf, (r + 1) as f64 / hf) * hf;
                cross += m * gx * gy;
            }
        }
        let nf = pts.len() as f64;
        let pair: f64 = pts
            .iter()
            .flat_map(|a| {
                pts.iter()
                    .map(move |b| 0.25 * (1.0 - (a.x - b.x).abs()) * (1.0 - (a.y - b.y).abs()))
            })
            .sum();
        let reference = self_term - 2.0 * cross / nf + pair / (nf * nf);
        let v = asd_cells_squared(&pts, &grid);
        assert!(rel_close(v, reference, 1e-9), "{v} vs {reference}");
    }

    #[test]
    fn large_grid_is_fast_and_finite() {
        let mut rng = SplitMix64::new(5);
        let grid = random_grid(&mut rng, 512, 512);
        let pts = random_points(&mut rng, 4096);
        let t = std::time::Instant::now();
        let a = asd_cells(&pts, &grid);
        let b = l2_star_cells(&pts, &grid);
        let dt = t.elapsed().as_secs_f64();
        assert!(a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0);
        assert!(dt < 2.0, "took {dt} s");
    }
}
