//! Scrambled Halton points in bases 2 and 3 (Owen 2017 "A randomized Halton
//! algorithm"; the paper's §5 cites Owen 2003 for scrambled Halton/Sobol).
//!
//! Scrambling choice: nested uniform (Owen) scrambling. The permutation applied to
//! digit `k` of `i` depends on the seed, the base and all less significant digits
//! `d_1..d_{k-1}` of `i` (the digits that fix the enclosing elementary interval), so
//! each elementary interval gets its own random permutation of its sub-intervals.
//! Permutations come from a hash chain ([`crate::seeding::mix64`]) instead of stored
//! tables, as Burley 2020 does for base 2. Digits are scrambled beyond the length of
//! `i` (53 digits in base 2, 33 in base 3, i.e. to ~1e-16), so the trailing digits are
//! random too and each point is uniformly distributed. Any permutation of the
//! leading `a` base-2 digits and `b` base-3 digits that depends only on those digits
//! keeps Halton's stratification: for `N` a multiple of `2^a 3^b` each of the
//! `2^a x 3^b` elementary boxes holds exactly `N/(2^a 3^b)` points.

use glam::DVec2;

use super::streams;
use crate::seeding::{derive_seed, mix64};

/// Base-2 digits scrambled per coordinate (`2^-53` resolution).
const DIGITS_2: u32 = 53;
/// Base-3 digits scrambled per coordinate (`3^33 < 2^53`, so the integer is exact).
const DIGITS_3: u32 = 33;

/// The six permutations of `{0, 1, 2}`.
const PERM3: [[u64; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// Owen-scrambled radical inverse of `i` in `base` (2 or 3) with `digits` digits;
/// `key` seeds the hash chain.
fn scrambled_radical_inverse(mut i: u64, base: u64, digits: u32, key: u64) -> f64 {
    let mut h = key;
    let mut acc: u64 = 0;
    for _ in 0..digits {
        let d = i % base;
        i /= base;
        let p = if base == 2 {
            d ^ (h >> 63)
        } else {
            PERM3[(h % 6) as usize][d as usize]
        };
        acc = acc * base + p;
        // Extend the prefix: the next digit's permutation depends on this digit.
        h = mix64(h ^ (d + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    }
    acc as f64 / (base as f64).powi(digits as i32)
}

/// The first `n` points of the Halton sequence in bases 2 (x) and 3 (y), each
/// coordinate Owen-scrambled with independent keys derived from `seed` (see the
/// module doc for the scrambling). Points lie in `[0,1)^2`. For `n` a multiple of
/// `2^a 3^b` every elementary box `[k/2^a, (k+1)/2^a) x [l/3^b, (l+1)/3^b)` holds
/// exactly `n / (2^a 3^b)` points. `O(n)` (86 hashes per point).
pub fn scrambled_halton(n: usize, seed: u64) -> Vec<DVec2> {
    let kx = derive_seed(derive_seed(seed, streams::HALTON), 2);
    let ky = derive_seed(derive_seed(seed, streams::HALTON), 3);
    (0..n as u64)
        .map(|i| {
            DVec2::new(
                scrambled_radical_inverse(i, 2, DIGITS_2, kx),
                scrambled_radical_inverse(i, 3, DIGITS_3, ky),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baselines::random;
    use crate::metrics::l2_star_uniform;

    fn assert_stratified(pts: &[DVec2], a: u32, b: u32) {
        let (cx, cy) = (1usize << a, 3usize.pow(b));
        let want = pts.len() / (cx * cy);
        assert_eq!(want * cx * cy, pts.len());
        let mut count = vec![0usize; cx * cy];
        for p in pts {
            count[(p.y * cy as f64) as usize * cx + (p.x * cx as f64) as usize] += 1;
        }
        assert!(
            count.iter().all(|&c| c == want),
            "a = {a}, b = {b}: {count:?}"
        );
    }

    #[test]
    fn elementary_boxes_hold_equal_counts() {
        for seed in [0, 1, 42] {
            // N = 2^4 3^3 = 432 and N = 2 * 2^3 3^2 = 144.
            for n in [432usize, 144] {
                let pts = scrambled_halton(n, seed);
                assert!(pts
                    .iter()
                    .all(|p| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)));
                for a in 0..=4 {
                    for b in 0..=3 {
                        if n % ((1 << a) * 3usize.pow(b)) == 0 {
                            assert_stratified(&pts, a, b);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn scrambling_randomizes_and_seed_fixes_it() {
        assert_eq!(scrambled_halton(50, 9), scrambled_halton(50, 9));
        assert_ne!(scrambled_halton(50, 9), scrambled_halton(50, 10));
        // Point 0 (unscrambled: the origin) is uniformly distributed over seeds.
        let m = 2000;
        let mean: DVec2 = (0..m).map(|s| scrambled_halton(1, s)[0]).sum::<DVec2>() / m as f64;
        let tol = 4.0 * (1.0f64 / 12.0 / m as f64).sqrt();
        assert!(
            (mean - DVec2::splat(0.5)).abs().max_element() < tol,
            "{mean}"
        );
    }

    #[test]
    fn l2_star_is_far_below_random() {
        let n = 256;
        let halton: f64 = (0..16)
            .map(|s| l2_star_uniform(&scrambled_halton(n, s)))
            .sum::<f64>()
            / 16.0;
        let rnd: f64 = (0..16).map(|s| l2_star_uniform(&random(n, s))).sum::<f64>() / 16.0;
        assert!(halton < 0.25 * rnd, "halton {halton}, random {rnd}");
    }
}
