//! A figure at a glance: for every (target, metric), ours against the best other
//! method at the largest N, and at how many N ours is the lowest — the paper's
//! qualitative claims, checked on the computed rows (`figN-summary.md`).

use super::rows::Row;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// One (target, metric) of a figure.
#[derive(Clone, Debug, PartialEq)]
pub struct SummaryLine {
    /// Panel name.
    pub target: String,
    /// Metric key.
    pub metric: String,
    /// The largest N with a value for ours.
    pub largest_n: usize,
    /// Ours at `largest_n`.
    pub ours: f64,
    /// The best (lowest) other method at `largest_n` and its value.
    pub best_other: (String, f64),
    /// Sizes at which ours is strictly below every other method.
    pub ours_lowest: usize,
    /// Sizes with a value for ours and at least one other method.
    pub sizes: usize,
}

impl SummaryLine {
    /// `ours / best other` at the largest N (below 1: ours is better).
    pub fn ratio(&self) -> f64 {
        self.ours / self.best_other.1
    }
}

/// Each method's value at one (target, metric, N).
type MethodValues<'a> = BTreeMap<&'a str, f64>;

/// The summary of a figure's rows (lower is better for every metric), ordered by
/// target then metric. (target, metric) pairs without ours or without any other
/// method are left out.
pub fn summarize(rows: &[Row]) -> Vec<SummaryLine> {
    let mut by: BTreeMap<(&str, &str), BTreeMap<usize, MethodValues>> = BTreeMap::new();
    for r in rows {
        by.entry((&r.target, &r.metric))
            .or_default()
            .entry(r.n)
            .or_default()
            .insert(&r.method, r.mean);
    }
    let mut out = Vec::new();
    for ((target, metric), per_n) in by {
        let best_other = |m: &MethodValues| {
            m.iter()
                .filter(|(k, _)| **k != "ours")
                .map(|(k, v)| (k.to_string(), *v))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        let compared: Vec<(usize, f64, (String, f64))> = per_n
            .iter()
            .filter_map(|(&n, m)| Some((n, *m.get("ours")?, best_other(m)?)))
            .collect();
        let Some((largest_n, ours, best)) = compared.last().cloned() else {
            continue;
        };
        out.push(SummaryLine {
            target: target.into(),
            metric: metric.into(),
            largest_n,
            ours,
            best_other: best,
            ours_lowest: compared.iter().filter(|(_, o, b)| o < &b.1).count(),
            sizes: compared.len(),
        });
    }
    out
}

/// The summary as a Markdown table.
pub fn markdown(figure: &str, lines: &[SummaryLine]) -> String {
    let mut s = String::from(
        "| figure | target | metric | largest N | ours | best other method | ratio | N where ours is lowest |\n|---|---|---|---:|---:|---|---:|---:|\n",
    );
    for l in lines {
        let _ = writeln!(
            s,
            "| {figure} | {} | {} | {} | {:.3e} | {} {:.3e} | {:.2} | {}/{} |",
            l.target,
            l.metric,
            l.largest_n,
            l.ours,
            l.best_other.0,
            l.best_other.1,
            l.ratio(),
            l.ours_lowest,
            l.sizes
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(target: &str, metric: &str, method: &str, n: usize, mean: f64) -> Row {
        Row {
            target: target.into(),
            metric: metric.into(),
            method: method.into(),
            n,
            mean,
            stderr: 0.0,
            realizations: 1,
        }
    }

    #[test]
    fn summary_finds_the_best_other_method_and_counts_the_sizes_ours_wins() {
        let rows = vec![
            // t/m: ours wins at 4 and 16, loses at 8 (tie is not a win at 32).
            row("t", "m", "ours", 4, 1.0),
            row("t", "m", "a", 4, 2.0),
            row("t", "m", "b", 4, 3.0),
            row("t", "m", "ours", 8, 2.0),
            row("t", "m", "a", 8, 1.5),
            row("t", "m", "b", 8, 3.0),
            row("t", "m", "ours", 16, 0.5),
            row("t", "m", "a", 16, 0.9),
            row("t", "m", "b", 16, 0.6),
            row("t", "m", "ours", 32, 0.4),
            row("t", "m", "a", 32, 0.8),
            row("t", "m", "b", 32, 0.4),
            // Ours missing at the largest size: the last compared size counts.
            row("t", "m", "a", 64, 0.1),
            // A metric without ours is left out.
            row("u", "m", "a", 4, 1.0),
        ];
        let s = summarize(&rows);
        assert_eq!(s.len(), 1);
        let l = &s[0];
        assert_eq!((l.target.as_str(), l.metric.as_str()), ("t", "m"));
        assert_eq!(l.largest_n, 32);
        assert_eq!(l.best_other, ("b".to_string(), 0.4));
        assert_eq!((l.ours_lowest, l.sizes), (2, 4));
        assert_eq!(l.ratio(), 1.0);
        let md = markdown("fig9", &s);
        assert!(
            md.contains("| fig9 | t | m | 32 | 4.000e-1 | b 4.000e-1 | 1.00 | 2/4 |"),
            "{md}"
        );
    }
}
