//! The report of an optimization run, `report.json`: per set the metrics of the
//! starting set and of the optimized set as stored, their means, the mean of the
//! warped Owen-Sobol baseline and the ratios, for any domain through [`Summary`].

use crate::metrics::Summary;
use serde::Serialize;

/// One optimized set in a [`RunReport`].
#[derive(Clone, Debug, Serialize)]
pub struct SetReport<M> {
    /// The set's seed, `derive_seed(run seed, set index)`.
    pub seed: u64,
    /// Metrics of the starting set: Owen-Sobol of this seed warped by the target's
    /// standard sampler.
    pub before: M,
    /// Metrics of the optimized set as `set.nuld` stores it (u16-quantized), so
    /// that `build-tool metrics` on the blob prints the same numbers.
    pub after: M,
    /// The optimizer's last loss (an estimate of the squared discrepancy it
    /// minimizes).
    pub final_loss: f64,
}

/// Everything `report.json` holds. `C` is the optimizer's settings type, `M` the
/// domain's [`Summary`].
#[derive(Clone, Debug, Serialize)]
pub struct RunReport<C, M> {
    /// Canonical target SPEC.
    pub density: String,
    /// `square`, `sphere` or `hemisphere`.
    pub domain: &'static str,
    /// Points per set.
    pub n: usize,
    /// Optimized sets.
    pub sets: usize,
    /// Run seed.
    pub seed: u64,
    /// The optimizer's settings.
    pub settings: C,
    /// Worker threads (results do not depend on it).
    pub threads: usize,
    /// Seconds from the start of the run to the finished report.
    pub wall_time_s: f64,
    /// Seconds spent optimizing.
    pub optimize_time_s: f64,
    /// Seconds spent measuring the sets for this report.
    pub report_time_s: f64,
    /// How the metrics were computed.
    pub metric_method: String,
    /// What the user should know about how the target was built from its input
    /// (e.g. negative pixels of a map set to 0); also printed on stderr.
    pub notes: Vec<String>,
    /// Per set: the start and the optimized result.
    pub per_set: Vec<SetReport<M>>,
    /// Mean over sets of the optimized metrics.
    pub optimized_mean: M,
    /// Mean over `baseline_sets` Owen-Sobol sets of the same N warped by the
    /// target's standard sampler (inverse CDF; for directions the equal-area map,
    /// cosine, GGX-VNDF mixture or envmap sampler).
    pub baseline_warped_owen_sobol_mean: M,
    /// Baseline sets averaged.
    pub baseline_sets: usize,
    /// `optimized_mean / baseline mean`, per metric (below 1 is better).
    pub ratio_to_baseline: M,
}

/// The parts of a [`RunReport`] that describe the run rather than its metrics.
#[derive(Clone, Debug)]
pub struct RunInfo<C> {
    /// Canonical target SPEC.
    pub density: String,
    /// `square`, `sphere` or `hemisphere`.
    pub domain: &'static str,
    /// Points per set.
    pub n: usize,
    /// Run seed.
    pub seed: u64,
    /// The optimizer's settings.
    pub settings: C,
    /// Seconds spent optimizing.
    pub optimize_time_s: f64,
    /// Seconds spent measuring.
    pub report_time_s: f64,
    /// How the metrics were computed.
    pub metric_method: String,
    /// Notes on how the target was built ([`RunReport::notes`]).
    pub notes: Vec<String>,
}

impl<C, M: Summary> RunReport<C, M> {
    /// Assembles the report from the per-set results and the baseline sets'
    /// metrics; means and ratios through [`Summary`].
    pub fn new(info: RunInfo<C>, per_set: Vec<SetReport<M>>, baseline: &[M]) -> Self {
        let optimized = M::mean(&per_set.iter().map(|r| r.after).collect::<Vec<_>>());
        let base = M::mean(baseline);
        Self {
            density: info.density,
            domain: info.domain,
            n: info.n,
            sets: per_set.len(),
            seed: info.seed,
            settings: info.settings,
            threads: rayon::current_num_threads(),
            wall_time_s: info.optimize_time_s + info.report_time_s,
            optimize_time_s: info.optimize_time_s,
            report_time_s: info.report_time_s,
            metric_method: info.metric_method,
            notes: info.notes,
            per_set,
            optimized_mean: optimized,
            baseline_warped_owen_sobol_mean: base,
            baseline_sets: baseline.len(),
            ratio_to_baseline: optimized.ratio(&base),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::summary::MetricSummary;

    fn m(l2_star: f64, asd: f64, star: f64) -> MetricSummary {
        MetricSummary { l2_star, asd, star }
    }

    #[test]
    fn means_and_ratios_are_taken_metric_by_metric() {
        let info = RunInfo {
            density: "uniform".into(),
            domain: "square",
            n: 4,
            seed: 1,
            settings: (),
            optimize_time_s: 2.0,
            report_time_s: 0.5,
            metric_method: "closed forms".into(),
            notes: Vec::new(),
        };
        let set = |after| SetReport {
            seed: 0,
            before: m(9.0, 9.0, 9.0),
            after,
            final_loss: 0.0,
        };
        let r = RunReport::new(
            info,
            vec![set(m(1.0, 2.0, 4.0)), set(m(3.0, 4.0, 8.0))],
            &[m(4.0, 6.0, 6.0), m(4.0, 6.0, 18.0), m(4.0, 6.0, 12.0)],
        );
        assert_eq!(r.optimized_mean, m(2.0, 3.0, 6.0));
        assert_eq!(r.baseline_warped_owen_sobol_mean, m(4.0, 6.0, 12.0));
        assert_eq!(r.ratio_to_baseline, m(0.5, 0.5, 0.5));
        assert_eq!((r.sets, r.baseline_sets, r.wall_time_s), (2, 3, 2.5));
        // The field names other tools read.
        let json = serde_json::to_value(&r).unwrap();
        for key in [
            "density",
            "domain",
            "n",
            "sets",
            "seed",
            "settings",
            "threads",
            "wall_time_s",
            "optimize_time_s",
            "metric_method",
            "per_set",
            "optimized_mean",
            "baseline_warped_owen_sobol_mean",
            "baseline_sets",
            "ratio_to_baseline",
        ] {
            assert!(json.get(key).is_some(), "{key}");
        }
        assert_eq!(json["ratio_to_baseline"]["star"], 0.5);
    }
}
