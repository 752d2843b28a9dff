//! The exact metrics of one point set against one target, as `optimize`,
//! `metrics` and the reports show them.

use super::aggregate::Summary;
use crate::density::{CellGrid, Density2D};
use glam::DVec2;
use serde::Serialize;

/// Discrepancies of a point set against a target measure `mu` (square roots).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MetricSummary {
    /// Origin-anchored L2 discrepancy `D2*(mu)` (Warnock's formula for uniform).
    pub l2_star: f64,
    /// All-corner average squared discrepancy `D2asd(mu)`: what the optimizer
    /// minimizes.
    pub asd: f64,
    /// Exact star discrepancy `D*(mu)` (Bundschuh–Zhu with the target's CDF).
    pub star: f64,
}

impl Summary for MetricSummary {
    const LABELS: &'static [&'static str] = &["D2asd", "L2-star", "D*"];

    fn values(&self) -> Vec<f64> {
        vec![self.asd, self.l2_star, self.star]
    }

    fn mean(items: &[MetricSummary]) -> MetricSummary {
        let n = items.len().max(1) as f64;
        let avg = |f: fn(&MetricSummary) -> f64| items.iter().map(f).sum::<f64>() / n;
        MetricSummary {
            l2_star: avg(|m| m.l2_star),
            asd: avg(|m| m.asd),
            star: avg(|m| m.star),
        }
    }

    fn ratio(&self, baseline: &MetricSummary) -> MetricSummary {
        MetricSummary {
            l2_star: self.l2_star / baseline.l2_star,
            asd: self.asd / baseline.asd,
            star: self.star / baseline.star,
        }
    }
}

/// How a target is evaluated: closed forms for the uniform target, otherwise the L2
/// metrics of its exact cell-mass tabulation (the image's own pixel grid for
/// `image:` targets, which is then exact) and D* with the exact CDF.
pub struct Target<'a> {
    density: &'a dyn Density2D,
    grid: Option<CellGrid>,
}

/// Grid used to tabulate non-tabulated, non-uniform targets for the L2 metrics.
pub const TABULATION_RESOLUTION: usize = 512;

impl<'a> Target<'a> {
    /// Prepares `density` for evaluation (tabulates it once if needed).
    pub fn new(density: &'a dyn Density2D) -> Self {
        let grid = (density.spec() != "uniform").then(|| density.cells(TABULATION_RESOLUTION));
        Self { density, grid }
    }

    /// The metrics of `points`.
    pub fn evaluate(&self, points: &[DVec2]) -> MetricSummary {
        match &self.grid {
            None => MetricSummary {
                l2_star: super::l2_star_uniform(points),
                asd: super::asd_uniform(points),
                star: super::star_discrepancy_uniform(points),
            },
            Some(grid) => MetricSummary {
                l2_star: super::l2_star_cells(points, grid),
                asd: super::asd_cells(points, grid),
                star: super::star_discrepancy_density(points, self.density),
            },
        }
    }

    /// One line describing how the metrics were computed, for reports.
    pub fn method(&self) -> String {
        match &self.grid {
            None => "closed forms (Warnock, asd closed form, Bundschuh–Zhu)".into(),
            Some(g) => format!(
                "L2 metrics exact for the {}x{} cell-mass tabulation of the target; D* exact with the target CDF",
                g.width, g.height
            ),
        }
    }
}
