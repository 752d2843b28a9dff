//! Warps that turn uniform points into samples of a non-uniform target: what the
//! paper's baselines apply to low-discrepancy points (§5, "Non-Uniform
//! Distributions").
//!
//! * [`warp_inverse_cdf`]: marginal-then-conditional inverse CDF.
//! * [`hierarchical_warp`] / [`HierarchicalWarp`]: Clarberg et al. 2005 hierarchical
//!   sample warping for tabulated (image) densities.
//! * [`cosine_hemisphere`]: Malley's method (concentric disk, then lift).

use glam::{DVec2, DVec3};
use nuld_core::warp::square_to_cosine_hemisphere;

use super::BELOW_ONE;
use crate::density::{CellGrid, Density2D};

/// Maps every point through `density.inverse_cdf` (marginal-then-conditional inverse
/// CDF). `O(n)` inverse-CDF evaluations.
pub fn warp_inverse_cdf(points: &[DVec2], density: &dyn Density2D) -> Vec<DVec2> {
    points.iter().map(|u| density.inverse_cdf(*u)).collect()
}

/// Hierarchical sample warping (Clarberg, Jarosz, Akenine-Möller, Jensen 2005,
/// "Wavelet Importance Sampling"; pbrt-v4's `HierarchicalWarp`-style quadtree):
/// a quadtree of 2x2 mass sums over the grid padded with zero-mass cells to a
/// power-of-two square. Built once (`O(S^2)`, `S = next power of two >=
/// max(width, height)`), each warp costs `O(log S)`.
#[derive(Clone, Debug)]
pub struct HierarchicalWarp {
    width: usize,
    height: usize,
    /// `levels[k]`: `2^k x 2^k` node masses, row-major; the last level is the padded
    /// grid.
    levels: Vec<Vec<f64>>,
}

impl HierarchicalWarp {
    /// Builds the quadtree of `grid`'s cell masses (cell `(col, row)` covers
    /// `[col/W, (col+1)/W] x [row/H, (row+1)/H]`). Panics if the grid is empty or
    /// its mass length is not `width * height`.
    pub fn new(grid: &CellGrid) -> Self {
        let (w, h) = (grid.width, grid.height);
        assert!(
            w > 0 && h > 0 && grid.mass.len() == w * h,
            "malformed CellGrid"
        );
        let s = w.max(h).next_power_of_two();
        let mut leaf = vec![0.0; s * s];
        for row in 0..h {
            for col in 0..w {
                leaf[row * s + col] = grid.mass[row * w + col].max(0.0);
            }
        }
        let mut levels = vec![leaf];
        let mut size = s;
        while size > 1 {
            let fine = levels.last().unwrap();
            let half = size / 2;
            let mut coarse = vec![0.0; half * half];
            for y in 0..half {
                for x in 0..half {
                    let at = |dx: usize, dy: usize| fine[(2 * y + dy) * size + 2 * x + dx];
                    coarse[y * half + x] = at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1);
                }
            }
            levels.push(coarse);
            size = half;
        }
        levels.reverse();
        Self {
            width: w,
            height: h,
            levels,
        }
    }

    /// Warps one point `u` in `[0,1)^2`: at each level choose the left or right
    /// column pair by comparing `u.x` with the left mass fraction and rescale `u.x`
    /// into the chosen interval, then the bottom or top child within that column by
    /// `u.y`; at the leaf cell place the point at `cell + u * cell size`. Inside a
    /// cell the map is affine and increasing in each coordinate; the preimage of every
    /// cell is a rectangle of area equal to its mass.
    pub fn warp(&self, u: DVec2) -> DVec2 {
        let mut u = DVec2::new(u.x.clamp(0.0, BELOW_ONE), u.y.clamp(0.0, BELOW_ONE));
        let (mut cx, mut cy) = (0usize, 0usize);
        for k in 1..self.levels.len() {
            let size = 1usize << k;
            let m = &self.levels[k];
            let at = |dx: usize, dy: usize| m[(2 * cy + dy) * size + 2 * cx + dx];
            let (left, right) = (at(0, 0) + at(0, 1), at(1, 0) + at(1, 1));
            let dx = split(&mut u.x, left, right);
            let dy = split(&mut u.y, at(dx, 0), at(dx, 1));
            cx = 2 * cx + dx;
            cy = 2 * cy + dy;
        }
        let x = (cx as f64 + u.x) / self.width as f64;
        let y = (cy as f64 + u.y) / self.height as f64;
        DVec2::new(x.min(BELOW_ONE), y.min(BELOW_ONE))
    }
}

/// Chooses child 0 (mass `a`) if `u < a / (a + b)`, else child 1, and rescales `u`
/// into `[0, 1)` within the chosen interval. A zero-mass child is never chosen.
fn split(u: &mut f64, a: f64, b: f64) -> usize {
    let total = a + b;
    let p = if total > 0.0 { a / total } else { 0.5 };
    if *u < p {
        *u = (*u / p).clamp(0.0, BELOW_ONE);
        0
    } else {
        *u = ((*u - p) / (1.0 - p)).clamp(0.0, BELOW_ONE);
        1
    }
}

/// Warps `points` by hierarchical sample warping over `grid` (see
/// [`HierarchicalWarp`]). `O(S^2 + n log S)`.
pub fn hierarchical_warp(points: &[DVec2], grid: &CellGrid) -> Vec<DVec2> {
    let w = HierarchicalWarp::new(grid);
    points.iter().map(|u| w.warp(*u)).collect()
}

/// Cosine-weighted hemisphere directions (density `cos(theta) / pi` about `+z`) by
/// Malley's method ([`nuld_core::warp::square_to_cosine_hemisphere`]). Unit vectors
/// with `z >= 0`. `O(n)`.
pub fn cosine_hemisphere(points: &[DVec2]) -> Vec<DVec3> {
    points
        .iter()
        .map(|u| square_to_cosine_hemisphere(*u))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::parse_spec;
    use crate::seeding::rng;
    use rand::Rng;

    fn stratified(k: usize) -> Vec<DVec2> {
        (0..k * k)
            .map(|i| DVec2::new((i % k) as f64 + 0.5, (i / k) as f64 + 0.5) / k as f64)
            .collect()
    }

    fn test_grid() -> CellGrid {
        let (w, h) = (12, 7);
        let mut r = rng(11, 0);
        let mut mass: Vec<f64> = (0..w * h)
            .map(|i| {
                if i % 5 == 3 {
                    0.0
                } else {
                    r.random::<f64>().powi(3)
                }
            })
            .collect();
        let t: f64 = mass.iter().sum();
        mass.iter_mut().for_each(|m| *m /= t);
        CellGrid {
            width: w,
            height: h,
            mass,
        }
    }

    #[test]
    fn hierarchical_warp_reproduces_cell_masses() {
        let grid = test_grid();
        let k = 1024;
        let pts = hierarchical_warp(&stratified(k), &grid);
        let mut count = vec![0usize; grid.mass.len()];
        for p in &pts {
            assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
            let col = (p.x * grid.width as f64) as usize;
            let row = (p.y * grid.height as f64) as usize;
            count[row * grid.width + col] += 1;
        }
        // Each cell's preimage is a rectangle of area = mass, so a k x k grid of
        // centres puts within (w + h) k + 1 <= 2k + 1 of mass * k^2 points in it.
        for (c, m) in count.iter().zip(&grid.mass) {
            let want = m * (k * k) as f64;
            assert!(
                (*c as f64 - want).abs() <= 2.0 * k as f64 + 1.0,
                "{c} vs {want}"
            );
            if *m == 0.0 {
                assert_eq!(*c, 0);
            }
        }
        // Also for a density's own grid (power-of-two size).
        let g = parse_spec("gaussian:0.3,0.6,0.2").unwrap().cells(16);
        let pts = hierarchical_warp(&stratified(512), &g);
        let mut count = vec![0usize; 256];
        for p in &pts {
            count[(p.y * 16.0) as usize * 16 + (p.x * 16.0) as usize] += 1;
        }
        for (c, m) in count.iter().zip(&g.mass) {
            assert!((*c as f64 - m * 512.0 * 512.0).abs() <= 2.0 * 512.0 + 1.0);
        }
    }

    #[test]
    fn hierarchical_warp_is_affine_and_increasing_inside_cells() {
        let grid = test_grid();
        let w = HierarchicalWarp::new(&grid);
        let k = 4096;
        let cell = |p: DVec2| ((p.x * 12.0) as usize, (p.y * 7.0) as usize);
        for line in [0.137, 0.5, 0.861] {
            for axis in [0usize, 1] {
                let pts: Vec<DVec2> = (0..k)
                    .map(|i| {
                        let t = (i as f64 + 0.5) / k as f64;
                        if axis == 0 {
                            DVec2::new(t, line)
                        } else {
                            DVec2::new(line, t)
                        }
                    })
                    .map(|u| w.warp(u))
                    .collect();
                let mut slope: Option<((usize, usize), f64)> = None;
                for pair in pts.windows(2) {
                    if cell(pair[0]) != cell(pair[1]) {
                        slope = None;
                        continue;
                    }
                    let d = pair[1] - pair[0];
                    // Only the varied coordinate moves, and it increases.
                    assert_eq!(d[1 - axis], 0.0);
                    assert!(d[axis] > 0.0);
                    // Constant slope inside the cell (affine, hence continuous).
                    match slope {
                        Some((c, s)) if c == cell(pair[0]) => {
                            assert!((d[axis] - s).abs() < 1e-9 * s.max(1e-12) + 1e-15)
                        }
                        _ => slope = Some((cell(pair[0]), d[axis])),
                    }
                }
            }
        }
    }

    #[test]
    fn cosine_hemisphere_has_mean_z_two_thirds() {
        // Midpoint rule on a 1024^2 grid; z = sqrt(1 - r^2) has an infinite slope at
        // the rim, so the error is O(k^-1.5) (4.3e-5 at k = 512).
        let dirs = cosine_hemisphere(&stratified(1024));
        assert!(dirs
            .iter()
            .all(|d| (d.length() - 1.0).abs() < 1e-12 && d.z >= 0.0));
        let n = dirs.len() as f64;
        let mz = dirs.iter().map(|d| d.z).sum::<f64>() / n;
        let mz2 = dirs.iter().map(|d| d.z * d.z).sum::<f64>() / n;
        assert!((mz - 2.0 / 3.0).abs() < 3e-5, "{mz}");
        assert!((mz2 - 0.5).abs() < 3e-5, "{mz2}");
        let mxy = dirs.iter().map(|d| d.truncate()).sum::<DVec2>() / n;
        assert!(mxy.length() < 1e-9);
    }

    #[test]
    fn inverse_cdf_warp_maps_through_the_density() {
        let d = parse_spec("bilinear:1,2,3,4").unwrap();
        let u = stratified(8);
        let x = warp_inverse_cdf(&u, d.as_ref());
        for (a, b) in u.iter().zip(&x) {
            assert_eq!(*b, d.inverse_cdf(*a));
        }
    }
}
