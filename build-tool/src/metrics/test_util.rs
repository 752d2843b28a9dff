//! Helpers shared by the metrics tests: a tiny deterministic RNG and point sets.

use glam::DVec2;

/// SplitMix64 (Steele et al. 2014): deterministic, good enough for test inputs.
pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0,1) with 53 random bits.
    pub(crate) fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// `n` iid uniform points in [0,1)^2.
pub(crate) fn random_points(rng: &mut SplitMix64, n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|_| DVec2::new(rng.next_f64(), rng.next_f64()))
        .collect()
}

/// Hammersley set: `(i/n, radical inverse base 2 of i)`, `i = 0..n`.
pub(crate) fn hammersley(n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|i| {
            let mut inv = 0.0;
            let mut f = 0.5;
            let mut k = i;
            while k > 0 {
                if k & 1 == 1 {
                    inv += f;
                }
                f *= 0.5;
                k >>= 1;
            }
            DVec2::new(i as f64 / n as f64, inv)
        })
        .collect()
}

/// A random piecewise-constant measure on a `width x height` grid (masses sum to 1,
/// some cells empty).
pub(crate) fn random_grid(
    rng: &mut SplitMix64,
    width: usize,
    height: usize,
) -> crate::density::CellGrid {
    let mut mass: Vec<f64> = (0..width * height)
        .map(|_| {
            let u = rng.next_f64();
            if u < 0.15 {
                0.0
            } else {
                u * u
            }
        })
        .collect();
    let total: f64 = mass.iter().sum();
    mass.iter_mut().for_each(|m| *m /= total);
    crate::density::CellGrid {
        width,
        height,
        mass,
    }
}

/// The uniform measure on a `width x height` grid.
pub(crate) fn uniform_grid(width: usize, height: usize) -> crate::density::CellGrid {
    crate::density::CellGrid {
        width,
        height,
        mass: vec![1.0 / (width * height) as f64; width * height],
    }
}

/// `∫_{[0,1]^2} f` for an `f` that is a polynomial of degree <= 5 per axis on every
/// rectangle cut by the point coordinates and the extra break lines (3-point
/// Gauss–Legendre per axis on each piece, evaluated at interior nodes only, so the
/// value of `f` on the cut lines never matters).
pub(crate) fn integrate_pieces(
    points: &[DVec2],
    x_breaks: &[f64],
    y_breaks: &[f64],
    f: impl Fn(DVec2) -> f64,
) -> f64 {
    let cuts = |coords: Vec<f64>, extra: &[f64]| {
        let mut v: Vec<f64> = coords.into_iter().chain(extra.iter().copied()).collect();
        v.push(0.0);
        v.push(1.0);
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let xs = cuts(points.iter().map(|p| p.x).collect(), x_breaks);
    let ys = cuts(points.iter().map(|p| p.y).collect(), y_breaks);
    let s = (0.6f64).sqrt();
    let nodes = [(-s, 5.0 / 9.0), (0.0, 8.0 / 9.0), (s, 5.0 / 9.0)];
    let mut total = 0.0;
    for wx in xs.windows(2) {
        for wy in ys.windows(2) {
            let (hx, hy) = ((wx[1] - wx[0]) / 2.0, (wy[1] - wy[0]) / 2.0);
            let (cx, cy) = ((wx[1] + wx[0]) / 2.0, (wy[1] + wy[0]) / 2.0);
            let mut acc = 0.0;
            for (tx, ax) in nodes {
                for (ty, ay) in nodes {
                    acc += ax * ay * f(DVec2::new(cx + hx * tx, cy + hy * ty));
                }
            }
            total += acc * hx * hy;
        }
    }
    total
}

/// The four boxes spanned by `u` and the corners of the unit square, as `(lo, hi)`.
pub(crate) fn corner_boxes(u: DVec2) -> [(DVec2, DVec2); 4] {
    [
        (DVec2::ZERO, u),
        (DVec2::new(u.x, 0.0), DVec2::new(1.0, u.y)),
        (DVec2::new(0.0, u.y), DVec2::new(u.x, 1.0)),
        (u, DVec2::ONE),
    ]
}
