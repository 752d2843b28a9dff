//! A point set drawn over a grayscale image of its target density.

use super::register_fonts;
use anyhow::{anyhow, Result};
use glam::DVec2;
use plotters::prelude::*;
use std::path::Path;

/// Draws `points` (in `[0,1]^2`) over `density` (grayscale, white = high,
/// scaled to the 99th percentile so a sharp peak does not wash out the rest) and
/// writes a PNG of `size x size + 60` pixels to `path` atomically. The y axis
/// points down, as image rows do (DESIGN.md §3: y grows with the row index), so an
/// `image:` target appears upright.
pub fn render_point_set(
    path: &Path,
    title: &str,
    density: &dyn Fn(DVec2) -> f64,
    points: &[DVec2],
    size: u32,
) -> Result<()> {
    register_fonts();
    let (w, h) = (size, size + 60);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("plot: {e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 17))
            .margin(12)
            .x_label_area_size(34)
            .y_label_area_size(44)
            .build_cartesian_2d(0f64..1f64, 0f64..1f64)
            .map_err(|e| anyhow!("plot: {e}"))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x")
            .y_desc("y (down)")
            .y_label_formatter(&|v| format!("{:.1}", 1.0 - v))
            .draw()
            .map_err(|e| anyhow!("plot: {e}"))?;
        let area = chart.plotting_area();
        let (xr, yr) = area.get_pixel_range();
        let (pw, ph) = ((xr.end - xr.start) as usize, (yr.end - yr.start) as usize);
        let values: Vec<f64> = (0..pw * ph)
            .map(|k| {
                let (i, j) = (k % pw, k / pw);
                density(DVec2::new(
                    (i as f64 + 0.5) / pw as f64,
                    (j as f64 + 0.5) / ph as f64,
                ))
            })
            .collect();
        let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        sorted.sort_by(f64::total_cmp);
        let top = sorted
            .get(sorted.len() * 99 / 100)
            .copied()
            .unwrap_or(1.0)
            .max(1e-300);
        let base = area.strip_coord_spec();
        for (k, v) in values.iter().enumerate() {
            let g = (60.0 + 195.0 * (v / top).clamp(0.0, 1.0).sqrt()) as u8;
            let (i, j) = ((k % pw) as i32, (k / pw) as i32);
            base.draw_pixel((i, j), &RGBColor(g, g, g))
                .map_err(|e| anyhow!("plot: {e}"))?;
        }
        let radius = if points.len() > 2000 { 1 } else { 2 };
        for p in points {
            area.draw(&Circle::new(
                (p.x, 1.0 - p.y),
                radius,
                RGBColor(220, 30, 30).filled(),
            ))
            .map_err(|e| anyhow!("plot: {e}"))?;
        }
        root.present().map_err(|e| anyhow!("plot: {e}"))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| anyhow!("plot buffer size"))?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
    crate::output::write_atomic(path, &png)
}
