//! The differentiable Monte-Carlo estimator of the average squared discrepancy
//! (paper §3.1–3.3; formulas in docs/estimator.md).
//!
//! For M sampled anchors `u` and the four quadrant boxes `B_c(u)` spanned by `u`
//! and each corner `c` of the square, with `M' = 4M`:
//!
//! ```text
//! loss = (1/M') sum_b r_b^2,   r_b = count_b / N - mu(B_b)
//! d loss / d x_i = (2/M') sum_b r_b (1/N) d sigma(alpha sdf(B_b, x_i)) / d x_i
//! ```
//!
//! The forward pass counts exactly ([`counting`]); the backward pass uses the
//! sigmoid of the signed distance (positive inside) to the box, whose faces on the
//! domain boundary are treated as absent, so each quadrant box is bounded only by
//! the cross through `u` ([`estimator`]). The expectation of `loss` over `u` is the
//! squared average squared discrepancy `(D2asd_mu)^2` of docs/metrics.md.

pub mod caps;
pub mod counting;
pub mod estimator;

pub use counting::{quadrant_counts, QuadrantCounts};
pub use estimator::{
    loss_and_gradient, quadrant_measures, residuals, AreaModel, GradientPath, SIGMOID_BAND,
};

/// The four quadrant boxes around an anchor `u`, as the signs `(sx, sy)` of the
/// direction from `u` toward the box's corner of the square: lower-left
/// `(-1,-1)` = `[0,u.x]x[0,u.y]`, lower-right `(1,-1)`, upper-left `(-1,1)`,
/// upper-right `(1,1)`.
pub const QUADRANTS: [(f64, f64); 4] = [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)];
