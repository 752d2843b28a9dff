//! Point sets drawn over a grayscale image of their target density: 2D sets in the
//! unit square, and direction sets both in their equal-area square and as
//! orthographic views of the sphere.

use super::{err, write_png, Area};
use anyhow::Result;
use glam::{DVec2, DVec3};
use plotters::prelude::*;
use std::path::Path;

/// Fills the plotting area of a `[lo, hi]^2` chart with `shade(x, y)` (grayscale,
/// white = high, scaled to the 99th percentile so a sharp peak does not wash out the
/// rest; `None` = outside the domain, drawn white), draws the polyline `outline`
/// (the domain's edge where the chart's frame is not) and `points` on top.
fn draw_panel(
    area: &Area<'_>,
    caption: &str,
    (lo, hi): (f64, f64),
    axes: Option<(&str, &str)>,
    shade: &dyn Fn(f64, f64) -> Option<f64>,
    outline: &[(f64, f64)],
    points: &[(f64, f64)],
) -> Result<()> {
    let mut builder = ChartBuilder::on(area);
    builder.caption(caption, ("sans-serif", 17)).margin(12);
    if axes.is_some() {
        builder.x_label_area_size(34).y_label_area_size(44);
    }
    let mut chart = builder.build_cartesian_2d(lo..hi, lo..hi).map_err(err)?;
    if let Some((xd, yd)) = axes {
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(xd)
            .y_desc(yd)
            .y_label_formatter(&|v| format!("{:.1}", 1.0 - v))
            .draw()
            .map_err(err)?;
    }
    let plot = chart.plotting_area();
    let (xr, yr) = plot.get_pixel_range();
    let (pw, ph) = ((xr.end - xr.start) as usize, (yr.end - yr.start) as usize);
    let values: Vec<Option<f64>> = (0..pw * ph)
        .map(|k| {
            let (i, j) = (k % pw, k / pw);
            let x = lo + (hi - lo) * (i as f64 + 0.5) / pw as f64;
            let y = hi - (hi - lo) * (j as f64 + 0.5) / ph as f64;
            shade(x, y)
        })
        .collect();
    let mut sorted: Vec<f64> = values
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    sorted.sort_by(f64::total_cmp);
    let top = sorted
        .get(sorted.len() * 99 / 100)
        .copied()
        .unwrap_or(1.0)
        .max(1e-300);
    let base = plot.strip_coord_spec();
    for (k, v) in values.iter().enumerate() {
        if let Some(v) = v {
            let g = (60.0 + 195.0 * (v / top).clamp(0.0, 1.0).sqrt()) as u8;
            base.draw_pixel(((k % pw) as i32, (k / pw) as i32), &RGBColor(g, g, g))
                .map_err(err)?;
        }
    }
    if !outline.is_empty() {
        plot.draw(&PathElement::new(outline.to_vec(), BLACK.stroke_width(1)))
            .map_err(err)?;
    }
    let radius = if points.len() > 2000 { 1 } else { 2 };
    for &p in points {
        plot.draw(&Circle::new(p, radius, RGBColor(220, 30, 30).filled()))
            .map_err(err)?;
    }
    Ok(())
}

/// A unit-square panel with y pointing down (row 0 of an image at the top): the
/// density and the points are flipped together.
fn draw_square(
    area: &Area<'_>,
    caption: &str,
    x_desc: &str,
    density: &dyn Fn(DVec2) -> f64,
    points: &[DVec2],
) -> Result<()> {
    let flipped: Vec<(f64, f64)> = points.iter().map(|p| (p.x, 1.0 - p.y)).collect();
    draw_panel(
        area,
        caption,
        (0.0, 1.0),
        Some((x_desc, "y (down)")),
        &|x, y| Some(density(DVec2::new(x, 1.0 - y))),
        &[],
        &flipped,
    )
}

/// Draws `points` (in `[0,1]^2`) over `density` and writes a PNG of
/// `size x (size + 60)` pixels to `path` atomically. The y axis points down, as
/// image rows do (docs/targets.md: y grows with the row index), so an `image:` target
/// appears upright.
pub fn render_point_set(
    path: &Path,
    title: &str,
    density: &dyn Fn(DVec2) -> f64,
    points: &[DVec2],
    size: u32,
) -> Result<()> {
    write_png(path, (size, size + 60), |root| {
        draw_square(root, title, "x", density, points)
    })
}

/// Draws a direction set side by side: its points in the domain's equal-area square
/// over the density, and orthographic views of the sphere from `+z` and, if the
/// domain reaches below the horizon, from `-z` (mirrored, as seen from below), each
/// over the density of the visible half and outlined by the unit circle. Writes a
/// PNG of `3 size x (size + 60)` pixels (`2 size` wide for the hemisphere).
///
/// `to_direction` is the domain's equal-area map; `density` is per solid angle.
pub fn render_direction_set(
    path: &Path,
    title: &str,
    density: &dyn Fn(DVec3) -> f64,
    to_direction: &dyn Fn(DVec2) -> DVec3,
    square_points: &[DVec2],
    size: u32,
) -> Result<()> {
    let dirs: Vec<DVec3> = square_points.iter().map(|&p| to_direction(p)).collect();
    // The map tells the domain: the sphere's map sends the square's corners to -z,
    // the hemisphere's sends the whole square to z >= 0. A 9 x 9 grid includes the
    // corners.
    let has_lower_half = (0..81)
        .any(|k| to_direction(DVec2::new((k % 9) as f64 / 8.0, (k / 9) as f64 / 8.0)).z < 0.0);
    let views: &[(f64, &str)] = if has_lower_half {
        &[
            (1.0, "seen from +z (x right, y up)"),
            (-1.0, "seen from -z (x left, y up)"),
        ]
    } else {
        &[(1.0, "seen from +z (x right, y up)")]
    };
    let circle: Vec<(f64, f64)> = (0..=360)
        .map(|k| (k as f64).to_radians())
        .map(|t| (t.cos(), t.sin()))
        .collect();
    let columns = 1 + views.len();
    write_png(path, (columns as u32 * size, size + 60), |root| {
        let panels = root.split_evenly((1, columns));
        draw_square(
            &panels[0],
            title,
            "equal-area square x",
            &|p| density(to_direction(p)),
            square_points,
        )?;
        for (panel, &(sign, caption)) in panels[1..].iter().zip(views) {
            let visible: Vec<(f64, f64)> = dirs
                .iter()
                .filter(|d| d.z * sign >= 0.0)
                .map(|d| (sign * d.x, d.y))
                .collect();
            draw_panel(
                panel,
                caption,
                (-1.05, 1.05),
                None,
                &|a, b| {
                    let r2 = a * a + b * b;
                    (r2 <= 1.0).then(|| density(DVec3::new(sign * a, b, sign * (1.0 - r2).sqrt())))
                },
                &circle,
                &visible,
            )?;
        }
        Ok(())
    })
}

/// One panel of [`render_square_panels`]: a caption, a density over the unit square
/// and points in it.
pub struct SquarePanel<'a> {
    /// Caption above the panel.
    pub caption: String,
    /// Density at a point of the square (e.g. a direction density through the
    /// domain's equal-area map).
    pub density: &'a dyn Fn(DVec2) -> f64,
    /// Points in `[0,1]^2`.
    pub points: Vec<DVec2>,
}

/// Draws `panels` side by side, each a unit square (y down, as
/// [`render_point_set`]) over its density, and writes a PNG of
/// `panels.len() size x (size + 60)` pixels to `path` atomically.
pub fn render_square_panels(path: &Path, panels: &[SquarePanel<'_>], size: u32) -> Result<()> {
    let columns = panels.len().max(1);
    write_png(path, (columns as u32 * size, size + 60), |root| {
        let areas = root.split_evenly((1, columns));
        for (area, panel) in areas.iter().zip(panels) {
            draw_square(
                area,
                &panel.caption,
                "equal-area square x",
                panel.density,
                &panel.points,
            )?;
        }
        Ok(())
    })
}
