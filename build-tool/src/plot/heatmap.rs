//! Heat maps of a value over a grid of two parameters, each cell coloured on a
//! diverging scale about a reference value and labelled with its value.

use super::{err, write_png};
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;

/// What [`render_heatmap`] draws.
pub struct Heatmap<'a> {
    /// Title.
    pub title: &'a str,
    /// Label of the x parameter (columns).
    pub x_label: &'a str,
    /// Label of the y parameter (rows).
    pub y_label: &'a str,
    /// Column values, in order.
    pub xs: &'a [f64],
    /// Row values, in order (drawn bottom to top).
    pub ys: &'a [f64],
    /// `ys.len() x xs.len()` values, row-major (`values[i * xs.len() + j]` at
    /// `(xs[j], ys[i])`); `None` cells are left blank.
    pub values: &'a [Option<f64>],
    /// The value drawn white: larger values go to red, smaller to blue, saturating
    /// at twice and half of it.
    pub center: f64,
}

/// The parameter value at integer tick `v` (cell centres), empty elsewhere.
fn tick_label(values: &[f64], v: f64) -> String {
    let i = v.round() as usize;
    if v.fract() == 0.0 && v >= 0.0 && i < values.len() {
        format!("{}", values[i])
    } else {
        String::new()
    }
}

/// Colour of `v` on the diverging scale about `center` (log scale, saturating at
/// a factor of 2 either way).
fn colour(v: f64, center: f64) -> RGBColor {
    let s = if v > 0.0 && center > 0.0 {
        ((v / center).log2()).clamp(-1.0, 1.0)
    } else {
        -1.0
    };
    let fade = |c: u8| (255.0 - (255.0 - c as f64) * s.abs()) as u8;
    if s >= 0.0 {
        RGBColor(fade(214), fade(39), fade(40))
    } else {
        RGBColor(fade(31), fade(119), fade(180))
    }
}

/// Draws `map` as a `width x height` PNG at `path` (atomically). Fails if the
/// value count does not match the grid.
pub fn render_heatmap(path: &Path, map: &Heatmap<'_>, (width, height): (u32, u32)) -> Result<()> {
    let (nx, ny) = (map.xs.len(), map.ys.len());
    if map.values.len() != nx * ny || nx == 0 || ny == 0 {
        return Err(anyhow!(
            "heat map {}: {} values for a {nx} x {ny} grid",
            map.title,
            map.values.len()
        ));
    }
    write_png(path, (width, height), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(map.title, ("sans-serif", 16))
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(-0.5..nx as f64 - 0.5, -0.5..ny as f64 - 0.5)
            .map_err(err)?;
        let xs = map.xs.to_vec();
        let ys = map.ys.to_vec();
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(map.x_label)
            .y_desc(map.y_label)
            .x_labels(nx)
            .y_labels(ny)
            .x_label_formatter(&move |v| tick_label(&xs, *v))
            .y_label_formatter(&move |v| tick_label(&ys, *v))
            .draw()
            .map_err(err)?;
        for i in 0..ny {
            for j in 0..nx {
                let Some(v) = map.values[i * nx + j] else {
                    continue;
                };
                // Cell (i, j) is centred on (j, i), where the axis labels sit.
                let (x, y) = (j as f64 - 0.5, i as f64 - 0.5);
                chart
                    .draw_series([Rectangle::new(
                        [(x, y), (x + 1.0, y + 1.0)],
                        colour(v, map.center).filled(),
                    )])
                    .map_err(err)?;
                chart
                    .draw_series([Text::new(
                        format!("{v:.3}"),
                        (x + 0.3, y + 0.55),
                        ("sans-serif", 15),
                    )])
                    .map_err(err)?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_is_white_and_extremes_saturate() {
        assert_eq!(colour(0.8, 0.8), RGBColor(255, 255, 255));
        assert_eq!(colour(1.6, 0.8), RGBColor(214, 39, 40));
        assert_eq!(colour(0.1, 0.8), RGBColor(31, 119, 180));
    }

    #[test]
    fn writes_a_png_and_rejects_a_mismatched_grid() {
        let dir = std::env::temp_dir().join(format!("nuld-heatmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("h.png");
        let mut map = Heatmap {
            title: "t",
            x_label: "x",
            y_label: "y",
            xs: &[1.0, 2.0],
            ys: &[0.5],
            values: &[Some(0.9), None],
            center: 1.0,
        };
        render_heatmap(&path, &map, (200, 160)).unwrap();
        let img = image::open(&path).unwrap();
        assert_eq!((img.width(), img.height()), (200, 160));
        map.values = &[Some(1.0)];
        assert!(render_heatmap(&path, &map, (200, 160)).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
