//! The numbers of a render: RMSE and bias against the reference per technique,
//! sampler and sample count (`render.csv`), and the equal-sample-count and
//! equal-time tables drawn from them (`render-summary.md`).
//!
//! Over the `P` pixels that show a surface (the background is exact for every
//! sampler and left out), with `e_p` the image minus the reference:
//! `rmse = sqrt((1/P) Σ e_p^2)`, `bias = (1/P) Σ e_p` (each pixel is its own
//! instance of the sampler, so this is the mean signed error over instances too),
//! and the RMSE and bias over each [`SurfaceClass`]'s pixels alone (where a few
//! fireflies on the metals decide the image's figure, the ground's still tells
//! the samplers apart; and a fixed instance's bias on one class can hide in the
//! image's mean behind another's of the other sign).
//!
//! A render repeats every image at `K` seeds (other scrambles, instances and
//! pools); the tables give each figure's mean over the seeds and its standard
//! error `sd / sqrt(K)` ([`Stat`]), so that a difference can be told from the
//! seed-to-seed spread.

use super::integrator::Image;
use super::scene::SurfaceClass;
use std::fmt::Write as _;

/// The header of `render.csv`.
pub const CSV_HEADER: &str = "technique,sampler,spp,seed,rmse,bias,seconds,\
rmse_dielectric,rmse_metal,rmse_ground,bias_dielectric,bias_metal,bias_ground";

/// One line of `render.csv`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Row {
    /// `brdf` or `envmap`.
    pub technique: String,
    /// The sampler's name.
    pub sampler: String,
    /// Samples per pixel.
    pub spp: u32,
    /// The render's seed (pixel keys, pools).
    pub seed: u64,
    /// Root mean squared error against the reference.
    pub rmse: f64,
    /// Mean signed error against the reference.
    pub bias: f64,
    /// Wall time of the render, seconds.
    pub seconds: f64,
    /// Root mean squared error over each class's pixels, in
    /// [`SurfaceClass::ALL`]'s order (0 for a class without pixels).
    pub rmse_by_surface: [f64; 3],
    /// Mean signed error over each class's pixels, in [`SurfaceClass::ALL`]'s
    /// order (0 for a class without pixels).
    pub bias_by_surface: [f64; 3],
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

/// `(rmse, bias)` of `image` against `reference` over each class's pixels
/// ([`SurfaceClass::ALL`]'s order; `None` pixels, the background, left out;
/// `(0, 0)` for a class without pixels): [`errors`] over each class's mask.
pub fn errors_by_surface(
    image: &Image,
    reference: &Image,
    classes: &[Option<SurfaceClass>],
) -> [(f64, f64); 3] {
    SurfaceClass::ALL.map(|class| {
        let mask: Vec<bool> = classes.iter().map(|c| *c == Some(class)).collect();
        errors(image, reference, &mask)
    })
}

/// `render.csv`: [`CSV_HEADER`] and one line per row.
pub fn csv(rows: &[Row]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{:.6e},{:.6e},{:.4},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
            r.technique,
            r.sampler,
            r.spp,
            r.seed,
            r.rmse,
            r.bias,
            r.seconds,
            r.rmse_by_surface[0],
            r.rmse_by_surface[1],
            r.rmse_by_surface[2],
            r.bias_by_surface[0],
            r.bias_by_surface[1],
            r.bias_by_surface[2]
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

/// The mean of a figure over seeds and its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stat {
    /// Mean over the seeds.
    pub mean: f64,
    /// `sd / sqrt(K)` (sample standard deviation); 0 for one seed.
    pub stderr: f64,
    /// Seeds `K`.
    pub count: usize,
}

impl Stat {
    /// Of `values` (at least one).
    pub fn of(values: &[f64]) -> Self {
        let k = values.len().max(1) as f64;
        let mean = values.iter().sum::<f64>() / k;
        let var = if values.len() > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0)
        } else {
            0.0
        };
        Self {
            mean,
            stderr: (var / k).sqrt(),
            count: values.len(),
        }
    }

    /// `mean ± stderr` in `format` (`e` for `{:.3e}`, `+` for `{:+.2e}`); the mean
    /// alone for one seed.
    fn show(&self, signed: bool) -> String {
        let m = if signed {
            format!("{:+.2e}", self.mean)
        } else {
            format!("{:.4e}", self.mean)
        };
        match self.count {
            0 | 1 => m,
            _ => format!("{m} ± {:.1e}", self.stderr),
        }
    }
}

/// One figure of `rows` for `(technique, sampler, spp)` over its seeds.
fn stat(
    rows: &[Row],
    technique: &str,
    sampler: &str,
    spp: u32,
    f: impl Fn(&Row) -> f64,
) -> Option<Stat> {
    let v: Vec<f64> = rows
        .iter()
        .filter(|r| r.technique == technique && r.sampler == sampler && r.spp == spp)
        .map(f)
        .collect();
    (!v.is_empty()).then(|| Stat::of(&v))
}

/// `rows` averaged over seeds: one row per `(technique, sampler, spp)` with the
/// means of RMSE, bias and time (seed 0), in first-seen order.
pub fn means(rows: &[Row]) -> Vec<Row> {
    let mut out: Vec<Row> = Vec::new();
    for r in rows {
        if out
            .iter()
            .any(|o| o.technique == r.technique && o.sampler == r.sampler && o.spp == r.spp)
        {
            continue;
        }
        let m = |f: fn(&Row) -> f64| {
            stat(rows, &r.technique, &r.sampler, r.spp, f).map_or(0.0, |s| s.mean)
        };
        out.push(Row {
            seed: 0,
            rmse: m(|r| r.rmse),
            bias: m(|r| r.bias),
            seconds: m(|r| r.seconds),
            rmse_by_surface: [
                m(|r| r.rmse_by_surface[0]),
                m(|r| r.rmse_by_surface[1]),
                m(|r| r.rmse_by_surface[2]),
            ],
            bias_by_surface: [
                m(|r| r.bias_by_surface[0]),
                m(|r| r.bias_by_surface[1]),
                m(|r| r.bias_by_surface[2]),
            ],
            ..r.clone()
        });
    }
    out
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
/// (rows = samplers, columns = spp; mean ± standard error over the seeds, the
/// lowest mean of each column in bold), the bias table likewise, the RMSE and
/// bias tables of each [`SurfaceClass`]'s pixels alone (where the rows hold them), and the RMSE
/// table at equal time (the mean times of `owen-sobol` at each spp; `–` where a
/// sampler's measured times do not reach).
pub fn markdown(rows: &[Row]) -> String {
    let mut out = String::from("# Render summary\n");
    let seeds = {
        let mut s: Vec<u64> = rows.iter().map(|r| r.seed).collect();
        s.sort_unstable();
        s.dedup();
        s.len()
    };
    let _ = writeln!(
        out,
        "\nEvery figure is the mean over {seeds} seed(s) ± its standard error."
    );
    let mean_rows = means(rows);
    for technique in ["brdf", "envmap", "mis"] {
        let (samplers, spp) = axes(rows, technique);
        if samplers.is_empty() {
            continue;
        }
        let at = |s: &str, n: u32, f: fn(&Row) -> f64| stat(rows, technique, s, n, f);
        let spp_columns: Vec<String> = spp.iter().map(|n| n.to_string()).collect();
        let ranked = |out: &mut String, title: &str, figure: &dyn Fn(&Row) -> f64| {
            let best = |n: u32| {
                samplers
                    .iter()
                    .filter_map(|s| stat(rows, technique, s, n, figure).map(|st| st.mean))
                    .fold(f64::INFINITY, f64::min)
            };
            table(out, title, &spp_columns, &samplers, |s, c| {
                let n = spp[c];
                stat(rows, technique, s, n, figure).map(|st| match st.mean == best(n) {
                    true => format!("**{}**", st.show(false)),
                    false => st.show(false),
                })
            });
        };
        ranked(
            &mut out,
            &format!("{technique}: RMSE at equal sample count (spp)"),
            &|r| r.rmse,
        );
        table(
            &mut out,
            &format!("{technique}: bias (mean signed error) at equal sample count"),
            &spp_columns,
            &samplers,
            |s, c| at(s, spp[c], |r| r.bias).map(|st| st.show(true)),
        );
        // Rows of a scene without classes (all 0) have no split to show.
        if rows
            .iter()
            .any(|r| r.rmse_by_surface.iter().any(|&e| e > 0.0))
        {
            for class in SurfaceClass::ALL {
                ranked(
                    &mut out,
                    &format!(
                        "{technique}: RMSE on the {} alone at equal sample count",
                        class.name()
                    ),
                    &|r| r.rmse_by_surface[class.index()],
                );
                table(
                    &mut out,
                    &format!(
                        "{technique}: bias on the {} alone at equal sample count",
                        class.name()
                    ),
                    &spp_columns,
                    &samplers,
                    |s, c| {
                        stat(rows, technique, s, spp[c], |r| {
                            r.bias_by_surface[class.index()]
                        })
                        .map(|st| st.show(true))
                    },
                );
            }
        }
        let budgets: Vec<f64> = spp
            .iter()
            .filter_map(|&n| at("owen-sobol", n, |r| r.seconds).map(|st| st.mean))
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
                |s, c| {
                    rmse_at_time(&mean_rows, technique, s, budgets[c]).map(|e| format!("{e:.4e}"))
                },
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
            seed: 0,
            rmse,
            bias: 0.0,
            seconds,
            rmse_by_surface: [0.0; 3],
            bias_by_surface: [0.0; 3],
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
    fn errors_by_surface_are_each_class_rmse_alone() {
        use SurfaceClass::*;
        let a = Image {
            width: 5,
            height: 1,
            values: vec![1.0, 5.0, 100.0, 3.0, 7.0],
        };
        let b = Image {
            width: 5,
            height: 1,
            values: vec![2.0, 2.0, 0.0, 3.0, 1.0],
        };
        let classes = [
            Some(Ground),
            Some(Ground),
            None,
            Some(MetalSpheres),
            Some(MetalSpheres),
        ];
        // Ground: errors -1 and 3, sqrt(10 / 2); metal: 0 and 6, sqrt(36 / 2);
        // no dielectric pixel: 0; the background's 100 counts nowhere.
        // Biases: ground (-1 + 3) / 2 = 1, metal (0 + 6) / 2 = 3.
        let e = errors_by_surface(&a, &b, &classes);
        assert_eq!(e[DielectricSpheres.index()], (0.0, 0.0));
        assert!((e[Ground.index()].0 - 5f64.sqrt()).abs() < 1e-15);
        assert!((e[MetalSpheres.index()].0 - 18f64.sqrt()).abs() < 1e-15);
        assert_eq!((e[Ground.index()].1, e[MetalSpheres.index()].1), (1.0, 3.0));
        // The summary ranks each class on its own: the sampler lower on the
        // ground is in bold there though higher over the image.
        let with = |sampler: &str, rmse: f64, ground: f64| Row {
            rmse_by_surface: [0.5, 0.5, ground],
            bias_by_surface: [0.0, 0.0, -ground / 2.0],
            ..row(sampler, 4, rmse, 1.0)
        };
        let md = markdown(&[with("ours", 2.0, 0.25), with("owen-sobol", 1.0, 0.75)]);
        let ground = md
            .split("## brdf: RMSE on the ground alone")
            .nth(1)
            .expect("a ground table");
        assert!(ground.contains("| ours | **2.5000e-1** |"), "{md}");
        assert!(md.contains("| owen-sobol | **1.0000e0** |"), "{md}");
        // Each class's bias, signed, in a table of its own.
        let ground_bias = md
            .split("## brdf: bias on the ground alone")
            .nth(1)
            .expect("a ground bias table");
        assert!(ground_bias.contains("| ours | -1.25e-1 |"), "{md}");
        // The CSV's last columns are the classes' RMSEs then their biases, in
        // the classes' order.
        let rmse = SurfaceClass::ALL.map(SurfaceClass::column).join(",");
        let bias = SurfaceClass::ALL.map(SurfaceClass::bias_column).join(",");
        assert!(CSV_HEADER.ends_with(&format!(",{rmse},{bias}")));
        let line = csv(&[with("ours", 2.0, 0.25)]);
        assert!(
            line.ends_with(",2.500000e-1,0.000000e0,0.000000e0,-1.250000e-1\n"),
            "{line}"
        );
        // Rows without classes print no split.
        assert!(!markdown(&[row("a", 4, 1.0, 1.0)]).contains("alone"));
    }

    #[test]
    fn equal_time_interpolates_log_log_and_refuses_to_extrapolate() {
        // rmse = 1/sqrt(t): at t = 4 between (1, 1) and (16, 0.25) it is 0.5.
        let rows = vec![row("a", 4, 1.0, 1.0), row("a", 64, 0.25, 16.0)];
        assert!((rmse_at_time(&rows, "brdf", "a", 4.0).unwrap() - 0.5).abs() < 1e-12);
        assert!(rmse_at_time(&rows, "brdf", "a", 32.0).is_none());
        let csv = csv(&rows);
        assert!(csv.starts_with(
            "technique,sampler,spp,seed,rmse,bias,seconds,rmse_dielectric,rmse_metal,rmse_ground,\
             bias_dielectric,bias_metal,bias_ground\nbrdf,a,4,0,"
        ));
        let md = markdown(&[
            row("owen-sobol", 4, 1.0, 1.0),
            row("owen-sobol", 64, 0.5, 2.0),
        ]);
        assert!(
            md.contains("**1.0000e0**") && md.contains("equal time"),
            "{md}"
        );
    }

    #[test]
    fn seeds_average_into_a_mean_and_its_standard_error() {
        let st = Stat::of(&[1.0, 2.0, 3.0, 6.0]);
        // mean 3, sample variance (4 + 1 + 0 + 9) / 3, stderr sqrt(14/3 / 4).
        assert_eq!(st.mean, 3.0);
        assert!((st.stderr - (14.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert_eq!(Stat::of(&[5.0]).stderr, 0.0);
        let rows: Vec<Row> = [(0, 1.0), (1, 3.0)]
            .into_iter()
            .map(|(seed, e)| Row {
                seed,
                ..row("owen-sobol", 4, e, 1.0)
            })
            .collect();
        let m = means(&rows);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].rmse, 2.0);
        let md = markdown(&rows);
        assert!(
            md.contains("**2.0000e0 ± 1.0e0**") && md.contains("2 seed(s)"),
            "{md}"
        );
    }
}
