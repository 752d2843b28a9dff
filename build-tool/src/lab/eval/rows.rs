//! The aggregated values of a figure: one [`Row`] per (target, metric, method, N),
//! a line of `figN.csv`. A leaf: the runner produces rows, the report and the
//! summary read them.

use serde::Serialize;

/// Columns of `figN.csv`, in order.
pub const CSV_COLUMNS: [&str; 7] = [
    "target",
    "metric",
    "method",
    "n",
    "mean",
    "stderr",
    "realizations",
];

/// One aggregated value: a CSV line.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// Panel (target or integrand) name.
    pub target: String,
    /// Metric key (`l2-star`, `asd`, `star`, `cap-l2`, `cap-star`, `rmse`).
    pub metric: String,
    /// Method name.
    pub method: String,
    /// Number of points.
    pub n: usize,
    /// The aggregate: the mean over realizations, or the RMSE for `rmse`.
    pub mean: f64,
    /// Its standard error (0 for one realization).
    pub stderr: f64,
    /// Realizations aggregated.
    pub realizations: usize,
}
