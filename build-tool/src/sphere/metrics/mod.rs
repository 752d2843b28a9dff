//! Spherical cap discrepancy of direction sets (docs/metrics.md, paper Eqs. 7–9).
//!
//! Two conventions for the cap radius appear in the literature; every function
//! states which one it uses:
//!
//! * **cos-uniform** (Stolarsky): caps `C(w, t)`, `w` uniform on the sphere, `t`
//!   with Lebesgue measure `dt` on `[-1, 1]` (total mass 2, not normalized):
//!   `D^2 = ∫_{-1}^{1} ∫_{S^2} (#{x_i in C}/N - mu(C))^2 dσ(w) dt`. Then
//!   Stolarsky's invariance gives [`cap_l2_uniform`] in closed form and its
//!   energy-distance generalization gives [`cap_l2_nonuniform`]; for `N` iid
//!   uniform points `E[D^2] = 1/(3N)`.
//! * **theta-uniform** (the paper's Eq. 9): `w` uniform, `theta` uniform on
//!   `[0, pi]` (a probability measure): estimated by Monte Carlo in
//!   [`cap_l2_theta_uniform_estimate`].
//!
//! The cap star discrepancy `D*_cap = sup_C |#{x_i in C}/N - mu(C)|` (Eq. 8) is
//! bounded from below by a search ([`cap_star_estimate`]).
//!
//! Parallel sums use fixed chunks combined in a fixed order, so every result is
//! bit-identical whatever the number of threads.//!
//! [`cap_l2`] holds the L2 forms, [`cap_star`] the star search, [`mod@diversity`] the
//! diversity of many instances of a conditional sampler (their union and their
//! nearest neighbours).

pub mod cap_l2;
pub mod cap_star;
pub mod diversity;
#[cfg(test)]
mod tests;

pub use cap_l2::*;
pub use cap_star::*;
pub use diversity::{diversity, Diversity};
