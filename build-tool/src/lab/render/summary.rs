//! The numbers of a render: RMSE and bias against the reference per technique,
//! sampler and sample count (`render.csv`), and the equal-sample-count and
//! equal-time tables drawn from them (`render-summary.md`).
//!
//! Over the `P` pixels that show a surface (the background is exact for every
//! sampler and left out), with `e_p` the image minus the reference:
//! `rmse = sqrt((1/P) Σ e_p^2)`, `bias = (1/P) Σ e_p` (each pixel is its own
//! instance of the sampler, so this is the mean signed error over instances too).

use super::integrator::Image;
use std::fmt::Write as _;

/// The header of `render.csv`.
pub const CSV_HEADER: &str = "technique,sampler,spp,rmse,bias,seconds";

/// One line of `render.csv`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Row {
    /// `brdf` or `envmap`.
    pub technique: String,
    /// The sampler's name.
    pub sampler: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Root mean squared error against the reference.
    pub rmse: f64,
    /// Mean signed error against the reference.
    pub bias: f64,
    /// Wall time of the render, seconds.
    pub seconds: f64,
}

/// `(rmse, bias)` of `image` against `reference` over the pixels where `mask` is
/// true. `(0, 0)` when no pixel is.
pub fn errors(image: &Image, reference: &Image, mask: &[bool]) -> (f64, f64) {
    let (mut s, mut s2, mut k) = (0.0, 0.0, 0usize);
    for ((a, b), m) in image.values.iter().zip(&reference.values).zip(mask) {
        if *m {
            let e = a - b;
            s += e;
            s2 += e * e;
            k += 1;
        }
    }
    if k == 0 {
        return (0.0, 0.0);
    }
    ((s2 / k as f64).sqrt(), s / k as f64)
}

/// `render.csv`: [`CSV_HEADER`] and one line per row.
pub fn csv(rows: &[Row]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{:.6e},{:.6e},{:.4}",
            r.technique, r.sampler, r.spp, r.rmse, r.bias, r.seconds
        );
    }
    out
}

/// The samplers of `technique` in first-seen order, and the sample counts sorted.
fn axes<'a>(rows: &'a [Row], technique: &str) -> (Vec<&'a str>, Vec<u32>) {
    let mut samplers: Vec<&str> = Vec::new();
    let mut spp: Vec<u32> = Vec::new();
    for r in rows.iter().filter(|r| r.technique == technique) {
        if !samplers.contains(&r.sampler.as_str()) {
            samplers.push(&r.sampler);
        }
        if !spp.contains(&r.spp) {
            spp.push(r.spp);
        }
    }
    spp.sort_unstable();
    (samplers, spp)
}

fn find<'a>(rows: &'a [Row], technique: &str, sampler: &str, spp: u32) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.technique == technique && r.sampler == sampler && r.spp == spp)
}

/// RMSE of `sampler` at `seconds` of render time, interpolated linearly in
/// `log rmse` against `log seconds` between its two measured sample counts around
/// `seconds`; `None` outside its measured range.
pub fn rmse_at_time(rows: &[Row], technique: &str, sampler: &str, seconds: f64) -> Option<f64> {
    let mut pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.technique == technique && r.sampler == sampler)
        .filter(|r| r.seconds > 0.0 && r.rmse > 0.0)
        .map(|r| (r.seconds, r.rmse))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts.windows(2).find_map(|w| {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if !(t0..=t1).contains(&seconds) {
            return None;
        }
        if t1 <= t0 {
            return Some(e0);
        }
        let f = (seconds.ln() - t0.ln()) / (t1.ln() - t0.ln());
        Some((e0.ln() + f * (e1.ln() - e0.ln())).exp())
    })
}

/// `render-summary.md`: per technique, the RMSE table at equal sample counts
/// (rows = samplers, columns = spp; the lowest of each column in bold), the bias
/// table, and the RMSE table at equal time (the times of `owen-sobol` at each spp;
/// `–` where a sampler's measured times do not reach).
pub fn markdown(rows: &[Row]) -> String {
    let mut out = String::from("# Render summary\n");
    for technique in ["brdf", "envmap"] {
        let (samplers, spp) = axes(rows, technique);
        if samplers.is_empty() {
            continue;
        }
        let at = |s: &str, n: u32| find(rows, technique, s, n);
        let best = |n: u32| {
            samplers
                .iter()
                .filter_map(|s| at(s, n).map(|r| r.rmse))
                .fold(f64::INFINITY, f64::min)
        };
        let spp_columns: Vec<String> = spp.iter().map(|n| n.to_string()).collect();
        table(
            &mut out,
            &format!("{technique}: RMSE at equal sample count (spp)"),
            &spp_columns,
            &samplers,
            |s, c| {
                let n = spp[c];
                at(s, n).map(|r| match r.rmse == best(n) {
                    true => format!("**{:.4e}**", r.rmse),
                    false => format!("{:.4e}", r.rmse),
                })
            },
        );
        table(
            &mut out,
            &format!("{technique}: bias (mean signed error) at equal sample count"),
            &spp_columns,
            &samplers,
            |s, c| at(s, spp[c]).map(|r| format!("{:+.2e}", r.bias)),
        );
        let budgets: Vec<f64> = spp
            .iter()
            .filter_map(|&n| at("owen-sobol", n).map(|r| r.seconds))
            .collect();
        if budgets.len() == spp.len() {
            let columns: Vec<String> = spp
                .iter()
                .zip(&budgets)
                .map(|(n, t)| format!("{t:.3} s (= {n} spp)"))
                .collect();
            table(
                &mut out,
                &format!("{technique}: RMSE at equal time (the render times of owen-sobol)"),
                &columns,
                &samplers,
                |s, c| rmse_at_time(rows, technique, s, budgets[c]).map(|e| format!("{e:.4e}")),
            );
        }
    }
    out
}

/// Appends a markdown section `## title` with a table: a `sampler` column, then
/// `columns` (right-aligned); cell `(sampler, column)` from `cell`, `–` for `None`.
fn table(
    out: &mut String,
    title: &str,
    columns: &[String],
    samplers: &[&str],
    cell: impl Fn(&str, usize) -> Option<String>,
) {
    let _ = write!(out, "\n## {title}\n\n| sampler |");
    for c in columns {
        let _ = write!(out, " {c} |");
    }
    out.push_str("\n|---|");
    out.push_str(&"---:|".repeat(columns.len()));
    out.push('\n');
    for s in samplers {
        let _ = write!(out, "| {s} |");
        for c in 0..columns.len() {
            match cell(s, c) {
                Some(v) => {
                    let _ = write!(out, " {v} |");
                }
                None => out.push_str(" – |"),
            }
        }
        out.push('\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(sampler: &str, spp: u32, rmse: f64, seconds: f64) -> Row {
        Row {
            technique: "brdf".into(),
            sampler: sampler.into(),
            spp,
            rmse,
            bias: 0.0,
            seconds,
        }
    }

    #[test]
    fn errors_are_rmse_and_mean_over_the_mask() {
        let a = Image {
            width: 3,
            height: 1,
            values: vec![1.0, 5.0, 100.0],
        };
        let b = Image {
            width: 3,
            height: 1,
            values: vec![2.0, 2.0, 0.0],
        };
        let (rmse, bias) = errors(&a, &b, &[true, true, false]);
        assert!((rmse - 5f64.sqrt()).abs() < 1e-15 && (bias - 1.0).abs() < 1e-15);
    }

    #[test]
    fn equal_time_interpolates_log_log_and_refuses_to_extrapolate() {
        // rmse = 1/sqrt(t): at t = 4 between (1, 1) and (16, 0.25) it is 0.5.
        let rows = vec![row("a", 4, 1.0, 1.0), row("a", 64, 0.25, 16.0)];
        assert!((rmse_at_time(&rows, "brdf", "a", 4.0).unwrap() - 0.5).abs() < 1e-12);
        assert!(rmse_at_time(&rows, "brdf", "a", 32.0).is_none());
        let csv = csv(&rows);
        assert!(csv.starts_with("technique,sampler,spp,rmse,bias,seconds\nbrdf,a,4,"));
        let md = markdown(&[
            row("owen-sobol", 4, 1.0, 1.0),
            row("owen-sobol", 64, 0.5, 2.0),
        ]);
        assert!(
            md.contains("**1.0000e0**") && md.contains("equal time"),
            "{md}"
        );
    }
}
