//! Unscrambled 2D Sobol points with a Cranley–Patterson rotation (a random toroidal
//! shift), the "CP-rotated Sobol" baseline of the paper's §5.
//!
//! `sobol_burley` always Owen-scrambles, so the plain Sobol directions are written
//! here: dimension 0 has direction numbers `m_k = 1` (the van der Corput radical
//! inverse in base 2), dimension 1 the primitive polynomial `x + 1` with `m_1 = 1`,
//! i.e. `m = 1, 3, 5, 15, 17, ...` (Joe & Kuo 2008, the second Sobol dimension).
//! Points are produced in Gray-code order like Joe & Kuo's generator and scipy;
//! the first `2^m` points are the same set in either order.

use glam::DVec2;
use rand::Rng;

use super::streams;
use crate::seeding::rng;

/// The largest point count [`sobol_points`] and [`sobol_cranley_patterson`] produce
/// (32-bit direction numbers); larger `n` are clamped to it.
pub const SOBOL_CP_MAX_POINTS: u64 = 1 << 32;

/// Direction numbers `V_k = m_k 2^(32-k)` of both dimensions, `k = 1..=32`.
fn directions() -> [[u32; 32]; 2] {
    let mut v0 = [0u32; 32];
    let mut v1 = [0u32; 32];
    let mut m: u64 = 1;
    for (k, (a, b)) in v0.iter_mut().zip(v1.iter_mut()).enumerate() {
        *a = 1u32 << (31 - k);
        if k > 0 {
            // m_k = 2 m_{k-1} xor m_{k-1} (polynomial x + 1, degree 1).
            m ^= m << 1;
        }
        *b = ((m << (31 - k)) & 0xFFFF_FFFF) as u32;
    }
    [v0, v1]
}

/// The first `n` points of the unscrambled 2D Sobol sequence in Gray-code order
/// (`x_0 = (0,0), (0.5,0.5), (0.75,0.25), (0.25,0.75), ...`). For `n = 2^m` they form
/// a (0, m, 2)-net: each elementary interval of area `1/n` holds exactly one point.
/// `n` is clamped to [`SOBOL_CP_MAX_POINTS`]. `O(n)` (one XOR per point).
pub fn sobol_points(n: usize) -> Vec<DVec2> {
    let n = (n as u64).min(SOBOL_CP_MAX_POINTS);
    let v = directions();
    let mut out = Vec::with_capacity(n as usize);
    let (mut x, mut y) = (0u32, 0u32);
    let scale = 1.0 / (1u64 << 32) as f64;
    for i in 0..n {
        if i > 0 {
            // Gray code: point i differs from point i-1 by the direction of the
            // lowest zero bit of i-1, i.e. the trailing zeros of i.
            let c = i.trailing_zeros() as usize;
            x ^= v[0][c];
            y ^= v[1][c];
        }
        out.push(DVec2::new(x as f64 * scale, y as f64 * scale));
    }
    out
}

/// Cranley–Patterson rotated Sobol: [`sobol_points`]`(n)` shifted by one random
/// vector `s ~ U[0,1)^2` modulo 1 (`x -> frac(x + s)`), `s` drawn from
/// [`crate::seeding::rng`]`(seed, ..)`. The shift keeps the net structure on the
/// torus and makes every point uniformly distributed. `O(n)`.
pub fn sobol_cranley_patterson(n: usize, seed: u64) -> Vec<DVec2> {
    let mut r = rng(seed, streams::SOBOL_CP);
    let s = DVec2::new(r.random::<f64>(), r.random::<f64>());
    sobol_points(n)
        .into_iter()
        .map(|p| toroidal_shift(p, s))
        .collect()
}

/// `p + shift` modulo 1 in each coordinate (a Cranley–Patterson rotation), for
/// `p, shift in [0,1)^2`; always in `[0,1)^2`.
pub(crate) fn toroidal_shift(p: DVec2, shift: DVec2) -> DVec2 {
    DVec2::new(toroidal_add(p.x, shift.x), toroidal_add(p.y, shift.y))
}

/// `frac(a + b)` for `a, b in [0,1)`, always in `[0,1)`.
fn toroidal_add(a: f64, b: f64) -> f64 {
    let s = a + b;
    let s = if s >= 1.0 { s - 1.0 } else { s };
    s.clamp(0.0, super::BELOW_ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_points_match_published_values() {
        let want = [
            (0.0, 0.0),
            (0.5, 0.5),
            (0.75, 0.25),
            (0.25, 0.75),
            (0.375, 0.375),
            (0.875, 0.875),
            (0.625, 0.125),
            (0.125, 0.625),
        ];
        let pts = sobol_points(8);
        for (p, w) in pts.iter().zip(want) {
            assert_eq!((p.x, p.y), w);
        }
        // Direction numbers m_k of dimension 1: 1, 3, 5, 15, 17, 51.
        let v = directions();
        let m: Vec<u32> = (0..6).map(|k| v[1][k] >> (31 - k)).collect();
        assert_eq!(m, [1, 3, 5, 15, 17, 51]);
    }

    fn assert_net(pts: &[DVec2], m: u32) {
        let n = 1usize << m;
        assert_eq!(pts.len(), n);
        for a in 0..=m {
            let (cx, cy) = (1usize << a, n >> a);
            let mut seen = vec![0u32; n];
            for p in pts {
                seen[(p.y * cy as f64) as usize * cx + (p.x * cx as f64) as usize] += 1;
            }
            assert!(seen.iter().all(|&c| c == 1), "m = {m}, a = {a}");
        }
    }

    #[test]
    fn unshifted_power_of_two_sets_are_0_m_2_nets() {
        for m in 0..=12 {
            assert_net(&sobol_points(1 << m), m);
        }
    }

    #[test]
    fn shift_is_one_toroidal_translation() {
        for seed in 0..8 {
            let plain = sobol_points(256);
            let shifted = sobol_cranley_patterson(256, seed);
            // Point 0 is the origin, so the shifted point 0 is the shift itself.
            let s = shifted[0];
            assert_ne!(s, DVec2::ZERO);
            for (p, q) in plain.iter().zip(&shifted) {
                assert!((0.0..1.0).contains(&q.x) && (0.0..1.0).contains(&q.y));
                let d = *q - *p - s;
                assert!((d.x - d.x.round()).abs() < 1e-15 && (d.y - d.y.round()).abs() < 1e-15);
            }
        }
        assert_eq!(
            sobol_cranley_patterson(64, 5),
            sobol_cranley_patterson(64, 5)
        );
        assert_ne!(
            sobol_cranley_patterson(64, 5),
            sobol_cranley_patterson(64, 6)
        );
    }
}
