//! Log-log line plots: one line per method, as the paper's discrepancy and error
//! figures show them.

use super::{err, write_png};
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;

/// One line of a plot: a label and its `(x, y)` points (non-positive values are
/// skipped, they have no place on a log axis).
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points, in increasing x.
    pub points: Vec<(f64, f64)>,
}

/// Distinguishable colours (Tableau 10), assigned to series in order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Draws `series` on log-log axes with markers and a legend, and writes a
/// `width x height` PNG to `path` atomically. A series labelled `ours` (case
/// insensitive) is drawn thicker and on top.
pub fn render_loglog(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    (width, height): (u32, u32),
) -> Result<()> {
    let positive = |&(x, y): &(f64, f64)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite();
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied().filter(positive))
        .collect();
    if all.is_empty() {
        return Err(anyhow!("nothing to plot for {title}"));
    }
    let (xmin, xmax) = all
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (ymin, ymax) = all
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    write_png(path, (width, height), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 20))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (xmin / 1.2..xmax * 1.2).log_scale(),
                (ymin / 1.5..ymax * 1.5).log_scale(),
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&|v| format!("{}", v.round() as i64))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(err)?;
        let mut order: Vec<usize> = (0..series.len()).collect();
        // "ours" last, so it is drawn on top.
        order.sort_by_key(|&i| series[i].label.eq_ignore_ascii_case("ours"));
        for i in order {
            let s = &series[i];
            let color = PALETTE[i % PALETTE.len()];
            let ours = s.label.eq_ignore_ascii_case("ours");
            let style = ShapeStyle {
                color: color.to_rgba(),
                filled: true,
                stroke_width: if ours { 4 } else { 2 },
            };
            let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(positive).collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), style))
                .map_err(err)?
                .label(s.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(
                        vec![(x, y), (x + 22, y)],
                        ShapeStyle {
                            stroke_width: 3,
                            ..style
                        },
                    )
                });
            chart
                .draw_series(
                    pts.iter()
                        .map(|&p| Circle::new(p, if ours { 4 } else { 3 }, style)),
                )
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(err)?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_a_readable_loglog_png() {
        let dir = std::env::temp_dir().join(format!("nuld-curves-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("plot.png");
        let series = vec![
            Series {
                label: "ours".into(),
                points: (2..10)
                    .map(|k| (f64::from(1 << k), 1.0 / f64::from(1 << k)))
                    .collect(),
            },
            Series {
                label: "random".into(),
                points: (2..10)
                    .map(|k| (f64::from(1 << k), f64::from(1 << k).powf(-0.5)))
                    .collect(),
            },
        ];
        render_loglog(&path, "test", "N", "error", &series, (640, 480)).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (640, 480));
        // Something other than white was drawn in the plot area.
        let coloured = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        assert!(coloured > 5000, "{coloured}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
