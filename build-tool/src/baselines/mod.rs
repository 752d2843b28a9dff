//! Baseline point sets the optimized sets are compared with (and start from).
//!
//! Every generator is deterministic: a `seed` fixes its output (all randomness comes
//! from [`crate::seeding::rng`], each method on its own stream). Points lie in
//! `[0,1)^2`, directions are unit vectors.
//!
//! * [`random`]: independent uniform points.
//! * [`owen_sobol`]: Owen-scrambled Sobol (`sobol_burley`).
//! * [`sobol_cranley_patterson`]: plain Sobol (Gray-code order) plus a random
//!   toroidal shift.
//! * [`scrambled_halton`]: Halton in bases 2 and 3 with nested (Owen) digit
//!   scrambling.
//! * [`poisson_disk_elimination`]: Yuksel 2015 weighted sample elimination.
//! * [`sliced_optimal_transport`]: Paulin et al. 2020 sliced optimal transport.
//! * [`gaussian_blue_noise`]: Ahmed, Ren, Wonka 2022 Gaussian blue noise.
//! * [`spherical_fibonacci`]: spherical Fibonacci directions.
//! * [`warp`]: the warps baselines use for non-uniform targets.
//! * [`EnvmapLight`]: a shipping renderer's environment-light warp (Mitsuba 3's
//!   `envmap`), the incumbent of the environment sampler's cost.
//! * [`warped_owen_sobol`]: the standard 2D baseline, Owen-Sobol through the
//!   target's inverse CDF (the optimizer's start);
//!   [`warped_owen_sobol_directions`] its twin for direction targets.
//! * [`Baseline`]: an enum over the uniform 2D methods, for evaluation loops.

mod envmap_light;
mod gbn;
mod grid;
mod halton;
mod kind;
mod owen_sobol;
mod poisson_disk;
mod random;
mod sobol_cp;
mod sot;
mod spherical_fibonacci;
pub mod warp;
mod warped;

pub use envmap_light::{EnvmapLight, EnvmapLightSampler};
pub use gbn::{gaussian_blue_noise, gaussian_blue_noise_energy, GBN_DEFAULT_ITERATIONS};
pub use halton::scrambled_halton;
pub use kind::Baseline;
pub use owen_sobol::{owen_sobol, OWEN_SOBOL_MAX_POINTS};
pub use poisson_disk::{poisson_disk_elimination, poisson_disk_max_radius};
pub use random::random;
pub(crate) use sobol_cp::toroidal_shift;
pub use sobol_cp::{sobol_cranley_patterson, sobol_points, SOBOL_CP_MAX_POINTS};
pub use sot::{sliced_optimal_transport, sliced_wasserstein, SOT_BATCH, SOT_DEFAULT_ITERATIONS};
pub use spherical_fibonacci::spherical_fibonacci;
pub use warp::{cosine_hemisphere, hierarchical_warp, warp_inverse_cdf, HierarchicalWarp};
pub use warped::{seeded_owen_sobol, warped_owen_sobol, warped_owen_sobol_directions};

/// The largest `f64` below 1: generators clamp coordinates to `[0, BELOW_ONE]` so that
/// points stay in `[0,1)^2`.
pub(crate) const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;

/// Clamps both coordinates of `p` into `[0, 1)`.
pub(crate) fn clamp_unit(p: glam::DVec2) -> glam::DVec2 {
    glam::DVec2::new(p.x.clamp(0.0, BELOW_ONE), p.y.clamp(0.0, BELOW_ONE))
}

/// Stream ids for [`crate::seeding::rng`], one per method, so that two methods run
/// with the same seed draw unrelated numbers.
pub(crate) mod streams {
    /// [`super::random`].
    pub const RANDOM: u64 = 0xB1_0001;
    /// [`super::sobol_cranley_patterson`].
    pub const SOBOL_CP: u64 = 0xB1_0002;
    /// [`super::scrambled_halton`] (seeds the digit hashes).
    pub const HALTON: u64 = 0xB1_0003;
    /// [`super::poisson_disk_elimination`].
    pub const POISSON_DISK: u64 = 0xB1_0004;
    /// [`super::sliced_optimal_transport`] (initial points and directions).
    pub const SOT: u64 = 0xB1_0005;
    /// [`super::sliced_optimal_transport`] (target samples).
    pub const SOT_TARGET: u64 = 0xB1_0006;
    /// [`super::gaussian_blue_noise`] (initial points).
    pub const GBN: u64 = 0xB1_0007;
    /// [`super::gaussian_blue_noise`] (target samples).
    pub const GBN_TARGET: u64 = 0xB1_0008;
}
