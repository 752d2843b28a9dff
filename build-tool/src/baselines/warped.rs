//! The standard baseline for a 2D or a direction target, and the optimizers'
//! starting set: Owen-scrambled Sobol points warped by the target's inverse CDF or
//! its standard direction warp.

use super::owen_sobol;
use crate::density::Density2D;
use crate::seeding::derive_seed;
use crate::sphere::DirectionDensity;
use glam::{DVec2, DVec3};

/// Stream of [`derive_seed`] that turns a run seed into an Owen scramble.
const SCRAMBLE_STREAM: u64 = 0x1417;

/// The first `n` Owen-scrambled Sobol points (see [`owen_sobol`]) of the scramble
/// that run seed `seed` selects, `derive_seed(seed, 0x1417)` truncated to 32 bits.
/// `n` is clamped to [`super::OWEN_SOBOL_MAX_POINTS`].
pub fn seeded_owen_sobol(n: usize, seed: u64) -> Vec<DVec2> {
    owen_sobol(n, derive_seed(seed, SCRAMBLE_STREAM) as u32)
}

/// [`seeded_owen_sobol`] points mapped by `density`'s inverse CDF `T(u)`: the
/// points a renderer gets from the standard sampler, and exactly where
/// [`crate::optimize::optimize`] starts for the same seed.
pub fn warped_owen_sobol(density: &dyn Density2D, n: usize, seed: u64) -> Vec<DVec2> {
    seeded_owen_sobol(n, seed)
        .into_iter()
        .map(|u| density.inverse_cdf(u))
        .collect()
}

/// [`seeded_owen_sobol`] points mapped by `density`'s standard warp
/// ([`DirectionDensity::sample`]; for a BRDF the renderer's importance-sampling
/// mixture): the directions a renderer gets from the standard sampler, the
/// trainer's and the quality check's baseline, and where
/// [`crate::optimize::directions::optimize_directions`] starts for the same seed.
pub fn warped_owen_sobol_directions(
    density: &dyn DirectionDensity,
    n: usize,
    seed: u64,
) -> Vec<DVec3> {
    seeded_owen_sobol(n, seed)
        .into_iter()
        .map(|u| density.sample(u))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::parse_spec;

    #[test]
    fn uniform_target_gives_a_net_for_every_seed() {
        let uniform = parse_spec("uniform").unwrap();
        for seed in 0..4 {
            let pts = warped_owen_sobol(uniform.as_ref(), 64, seed);
            // A (0,6,2)-net: each 1/8 x 1/8 cell holds exactly one point.
            let mut count = [0u32; 64];
            for p in &pts {
                count[(p.y * 8.0) as usize * 8 + (p.x * 8.0) as usize] += 1;
            }
            assert!(count.iter().all(|&c| c == 1), "seed {seed}: {count:?}");
        }
        assert_ne!(
            warped_owen_sobol(uniform.as_ref(), 8, 0),
            warped_owen_sobol(uniform.as_ref(), 8, 1)
        );
    }

    #[test]
    fn points_stay_where_the_target_lives() {
        // The quarter disc x^2 + y^2 <= 2/pi has density 0 outside.
        let disc = parse_spec("quarter-disc").unwrap();
        let r2 = 2.0 / std::f64::consts::PI;
        for p in warped_owen_sobol(disc.as_ref(), 256, 3) {
            assert!(p.length_squared() <= r2 * (1.0 + 1e-9), "{p}");
        }
    }
}
