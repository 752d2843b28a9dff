//! A uniform bucket grid over `[0,1)^2` for fixed-radius neighbour queries, shared by
//! the Poisson-disk and Gaussian-blue-noise baselines. Optionally toroidal.

use glam::DVec2;

/// Points bucketed into `g x g` square cells (counting sort, `O(n + g^2)` to build).
pub(crate) struct PointGrid {
    g: usize,
    toroidal: bool,
    /// `start[c]..start[c+1]` indexes `items` for cell `c` (row-major).
    start: Vec<u32>,
    items: Vec<u32>,
}

impl PointGrid {
    /// Buckets `points` into cells of side `>= cell` (at most 2048 per axis and at
    /// most about 4 cells per point, to bound memory).
    pub(crate) fn new(points: &[DVec2], cell: f64, toroidal: bool) -> Self {
        let cap = ((4.0 * points.len() as f64).sqrt().ceil() as usize).clamp(1, 2048);
        let g = if cell > 0.0 && cell.is_finite() {
            ((1.0 / cell).floor() as usize).clamp(1, cap)
        } else {
            1
        };
        let cell_of = |p: &DVec2| Self::cell_index(g, *p);
        let mut start = vec![0u32; g * g + 1];
        for p in points {
            start[cell_of(p) + 1] += 1;
        }
        for c in 0..g * g {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; points.len()];
        for (i, p) in points.iter().enumerate() {
            let c = cell_of(p);
            items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        Self {
            g,
            toroidal,
            start,
            items,
        }
    }

    fn coord(g: usize, v: f64) -> usize {
        ((v * g as f64).max(0.0) as usize).min(g - 1)
    }

    fn cell_index(g: usize, p: DVec2) -> usize {
        Self::coord(g, p.y) * g + Self::coord(g, p.x)
    }

    /// Calls `f(j)` for every point `j` in a cell within distance `r` of `p`'s cell
    /// (each point once; the caller tests the actual distance). Toroidal grids wrap.
    pub(crate) fn for_each_near(&self, p: DVec2, r: f64, mut f: impl FnMut(usize)) {
        let g = self.g as i64;
        let k = ((r * g as f64).ceil() as i64).max(1);
        let (cx, cy) = (
            Self::coord(self.g, p.x) as i64,
            Self::coord(self.g, p.y) as i64,
        );
        let range = |c: i64| -> (i64, i64) {
            if 2 * k + 1 >= g {
                (0, g - 1)
            } else if self.toroidal {
                (c - k, c + k)
            } else {
                ((c - k).max(0), (c + k).min(g - 1))
            }
        };
        let (x0, x1) = range(cx);
        let (y0, y1) = range(cy);
        for y in y0..=y1 {
            let yy = y.rem_euclid(g) as usize;
            for x in x0..=x1 {
                let c = yy * self.g + x.rem_euclid(g) as usize;
                for &j in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                    f(j as usize);
                }
            }
        }
    }
}

/// The minimum-image difference `a - b` on the unit torus (each coordinate in
/// `[-0.5, 0.5]`).
pub(crate) fn torus_delta(a: DVec2, b: DVec2) -> DVec2 {
    let d = a - b;
    d - d.round()
}

/// Minimum pairwise distance of `points`, toroidal or not; `O(n^2)`, test helper.
#[cfg(test)]
pub(crate) fn min_distance(points: &[DVec2], toroidal: bool) -> f64 {
    let mut best = f64::INFINITY;
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            let d = if toroidal {
                torus_delta(points[i], points[j])
            } else {
                points[i] - points[j]
            };
            best = best.min(d.length());
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baselines::random;

    #[test]
    fn queries_find_every_neighbour_once() {
        let pts = random(500, 1);
        for toroidal in [false, true] {
            for r in [0.01, 0.07, 0.3, 0.6] {
                let grid = PointGrid::new(&pts, r, toroidal);
                for p in pts.iter().take(50) {
                    let mut seen = vec![0u32; pts.len()];
                    grid.for_each_near(*p, r, |j| seen[j] += 1);
                    for (j, q) in pts.iter().enumerate() {
                        let d = if toroidal {
                            torus_delta(*p, *q)
                        } else {
                            *p - *q
                        };
                        assert!(seen[j] <= 1);
                        if d.length() < r {
                            assert_eq!(seen[j], 1, "r {r} toroidal {toroidal}");
                        }
                    }
                }
            }
        }
    }
}
