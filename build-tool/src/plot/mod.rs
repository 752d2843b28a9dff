//! Pictures: point sets over their target density, and log-log curves.

mod curves;
mod points;

pub use curves::{render_loglog, Series};
pub use points::{render_direction_set, render_point_set, render_square_panels, SquarePanel};

use std::sync::Once;

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
