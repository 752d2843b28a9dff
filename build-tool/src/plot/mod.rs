//! Pictures: point sets over their target density, log-log curves, heat maps,
//! labelled grids of pictures.

mod composite;
mod curves;
mod heatmap;
mod points;

pub use composite::{render_composite, Composite, Tile};
pub use curves::{render_loglog, Series};
pub use heatmap::{render_heatmap, Heatmap};
pub use points::{render_direction_set, render_point_set, render_square_panels, SquarePanel};

use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// A drawing area over an RGB buffer.
pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// DejaVu Sans (Bitstream Vera license, `assets/DejaVuSans-LICENSE.txt`), embedded so
/// that plots need no system fonts.
static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Registers the embedded font as plotters' `sans-serif`, once per process.
pub(crate) fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a valid TrueType file, checked by the plot tests.
        let _ =
            plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT);
    });
}

/// A plotters error as this crate's error, `plot: ...`.
pub(crate) fn err(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("plot: {e}")
}

/// Renders into a fresh `w x h` buffer and writes it as PNG to `path` atomically.
pub(crate) fn write_png(
    path: &Path,
    (w, h): (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> Result<()>,
) -> Result<()> {
    register_fonts();
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        draw(&root)?;
        root.present().map_err(err)?;
    }
    write_rgb_png(path, (w, h), buf)
}

/// Writes `rgb` (8-bit RGB, row-major, `3 w h` bytes) as PNG to `path`
/// atomically; an error if the length does not match `w x h`.
pub(crate) fn write_rgb_png(path: &Path, (w, h): (u32, u32), rgb: Vec<u8>) -> Result<()> {
    let img = image::RgbImage::from_raw(w, h, rgb)
        .ok_or_else(|| anyhow!("picture buffer does not match {w}x{h}"))?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
    crate::output::write_atomic(path, &png)
}
