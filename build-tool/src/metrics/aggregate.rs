//! What reports do with the metrics of many sets, whatever the domain: average them
//! over sets, compare them with a baseline, and list them in a table.

use serde::Serialize;

/// The metrics of one point set (a [`MetricSummary`](super::summary::MetricSummary)
/// in 2D, a [`CapMetricSummary`](super::cap_summary::CapMetricSummary) for
/// directions). Lower is better for every metric.
pub trait Summary: Copy + Serialize + Send + Sync {
    /// Short names of the metrics [`Summary::values`] lists, for tables and log
    /// lines; the first is the headline (what the optimizer minimizes).
    const LABELS: &'static [&'static str];

    /// The metrics named by [`Summary::LABELS`], in that order.
    fn values(&self) -> Vec<f64>;

    /// The element-wise mean of `items` (all zero for none).
    fn mean(items: &[Self]) -> Self;

    /// `self / baseline`, metric by metric (below 1: `self` is better); fields that
    /// are not metrics (standard errors) are NaN.
    fn ratio(&self, baseline: &Self) -> Self;
}
