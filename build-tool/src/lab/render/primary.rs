//! Primary sample points: the uniform point sets of the unit square that the
//! baseline samplers push through a warp (paper §5's comparison: low-discrepancy
//! points warped by the renderer's importance sampler).
//!
//! * `owen-sobol`: Owen-scrambled Sobol ([`owen_sobol`]), the pixel key's low 32
//!   bits as the scramble: every pixel its own randomization.
//! * `halton`: Owen-scrambled Halton in bases 2, 3 ([`scrambled_halton`]), seeded
//!   by the pixel key.
//! * `random`: independent uniform points ([`random`]), seeded by the pixel key.
//! * `sot`, `gbn`: sliced optimal transport and Gaussian blue noise
//!   ([`sliced_optimal_transport`], [`gaussian_blue_noise`]) are optimized sets,
//!   too slow to generate per pixel. A pool of [`POOL_SETS`] sets per point count
//!   is generated once (seeded, in parallel, cached in memory for the run); a pixel
//!   takes the pool set its key selects, shifted toroidally by a random vector
//!   from its key (Cranley–Patterson rotation), which decorrelates pixels. The
//!   shift keeps GBN's structure (its uniform energy is toroidal); SOT optimizes
//!   in the square, so a shifted SOT set loses a little of it at the wrap, the
//!   price of serving per-pixel randomization from a pool.

use crate::baselines::{
    gaussian_blue_noise, owen_sobol, random, scrambled_halton, sliced_optimal_transport,
    toroidal_shift, GBN_DEFAULT_ITERATIONS, SOT_DEFAULT_ITERATIONS,
};
use crate::seeding::derive_seed;
use glam::DVec2;
use rayon::prelude::*;

use super::sampler::PixelKey;

/// Sets per pool of the optimized generators (SOT, GBN).
pub const POOL_SETS: usize = 16;

/// Stream of [`derive_seed`] for pool sets.
const POOL_STREAM: u64 = 0x9001;
/// Stream of [`derive_seed`] for Cranley–Patterson shifts.
const SHIFT_STREAM: u64 = 0x5417;

/// The uniform generators (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Generator {
    /// Owen-scrambled Sobol.
    OwenSobol,
    /// Owen-scrambled Halton.
    Halton,
    /// Independent uniform points.
    Random,
    /// Sliced optimal transport (pooled).
    Sot,
    /// Gaussian blue noise (pooled).
    Gbn,
}

impl Generator {
    /// The name in `render.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Generator::OwenSobol => "owen-sobol",
            Generator::Halton => "halton",
            Generator::Random => "random",
            Generator::Sot => "sot",
            Generator::Gbn => "gbn",
        }
    }
}

/// A generator ready to serve sets of `n` points: for SOT and GBN the pool.
#[derive(Clone, Debug)]
pub struct PrimaryPoints {
    generator: Generator,
    n: u32,
    pool: Vec<Vec<DVec2>>,
}

impl PrimaryPoints {
    /// `generator` for sets of `n >= 1` points; SOT and GBN generate their pool of
    /// [`POOL_SETS`] sets now (from `seed`; seconds for `n = 256`).
    pub fn new(generator: Generator, n: u32, seed: u64) -> Self {
        let pool = match generator {
            Generator::Sot | Generator::Gbn => (0..POOL_SETS as u64)
                .into_par_iter()
                .map(|k| {
                    let s = derive_seed(derive_seed(seed, POOL_STREAM), k);
                    match generator {
                        Generator::Sot => {
                            sliced_optimal_transport(n as usize, s, None, SOT_DEFAULT_ITERATIONS)
                        }
                        _ => gaussian_blue_noise(n as usize, s, None, GBN_DEFAULT_ITERATIONS),
                    }
                })
                .collect(),
            _ => Vec::new(),
        };
        Self { generator, n, pool }
    }

    /// The generator.
    pub fn generator(&self) -> Generator {
        self.generator
    }

    /// The `n` points of the pixel with key `key`, in `[0,1)^2`.
    pub fn points(&self, key: PixelKey) -> Vec<DVec2> {
        let n = self.n as usize;
        match self.generator {
            Generator::OwenSobol => owen_sobol(n, key.scramble()),
            Generator::Halton => scrambled_halton(n, key.0),
            Generator::Random => random(n, key.0),
            Generator::Sot | Generator::Gbn => {
                let set = &self.pool[(key.0 % self.pool.len() as u64) as usize];
                let shift = random(1, derive_seed(key.0, SHIFT_STREAM))[0];
                set.iter().map(|p| toroidal_shift(*p, shift)).collect()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooled_sets_are_shifted_pool_members_and_pixels_differ() {
        let sot = PrimaryPoints::new(Generator::Sot, 16, 3);
        assert_eq!(sot.pool.len(), POOL_SETS);
        let (a, b) = (
            sot.points(PixelKey(7)),
            sot.points(PixelKey(7 + POOL_SETS as u64)),
        );
        // Same pool set, different shifts: the differences between points agree
        // modulo 1, the points do not.
        assert_ne!(a, b);
        let set = &sot.pool[7];
        for i in 1..16 {
            for (q, s) in [(&a, set), (&b, set)] {
                let d = (q[i] - q[0]) - (s[i] - s[0]);
                assert!((d.x - d.x.round()).abs() < 1e-12 && (d.y - d.y.round()).abs() < 1e-12);
            }
        }
        for g in [
            Generator::OwenSobol,
            Generator::Halton,
            Generator::Random,
            Generator::Gbn,
        ] {
            let p = PrimaryPoints::new(g, 16, 3);
            let (x, y) = (p.points(PixelKey(1)), p.points(PixelKey(2)));
            assert_eq!(x.len(), 16);
            assert_ne!(x, y, "{}", g.name());
            assert!(x
                .iter()
                .all(|q| (0.0..1.0).contains(&q.x) && (0.0..1.0).contains(&q.y)));
        }
    }
}
