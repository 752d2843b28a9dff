//! Exact discrepancy metrics in 2D (docs/metrics.md), used by optimizer reports and the
//! evaluation figures.
//!
//! * [`l2`]: uniform L2 discrepancies — Warnock's L2-star and the all-corner average
//!   squared discrepancy (asd), `O(N log N)`.
//! * [`cells`]: the same two for a piecewise-constant measure on a
//!   [`CellGrid`](crate::density::CellGrid), `O(W H + N log N)`.
//! * [`star`]: the exact star discrepancy D* (Bundschuh–Zhu, `O(N^2)`) for any CDF,
//!   plus a brute-force reference.
//! * [`pairs`]: the point–point kernel means shared by the L2 metrics, fast and dense.
//! * [`summary`], [`cap_summary`]: the metrics reports show for one 2D or direction
//!   set; [`aggregate::Summary`] averages and compares them across sets.
//!
//! Every `*_squared` function returns the squared discrepancy; the unsuffixed one its
//! square root (as docs/metrics.md's reference table and scipy do). Points lie in `[0,1]^2`.
//! Everything is deterministic: sequential, or parallel with fixed chunking and
//! fixed-order (or exact, for maxima) reductions.

pub mod aggregate;
pub mod cap_summary;
pub mod cells;
pub mod l2;
pub mod pairs;
pub mod star;
mod sum;
pub mod summary;
#[cfg(test)]
mod test_util;

pub use aggregate::Summary;
pub use cells::{asd_cells, asd_cells_squared, l2_star_cells, l2_star_cells_squared};
pub use l2::{asd_uniform, asd_uniform_squared, l2_star_uniform, l2_star_uniform_squared};
pub use pairs::{asd_pair_term, asd_pair_term_dense, l2_star_pair_term, l2_star_pair_term_dense};
pub use star::{
    star_discrepancy, star_discrepancy_brute_force, star_discrepancy_density, star_discrepancy_par,
    star_discrepancy_uniform,
};
