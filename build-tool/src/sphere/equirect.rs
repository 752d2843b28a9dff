//! The equirectangular layout shared by a map's density and its filtered
//! luminance: `+z` up, column `c` of `W` covers `phi in [2 pi c / W, 2 pi (c+1) / W)`
//! from `+x` toward `+y`, row `r` of `H` covers `theta in [pi r / H, pi (r+1) / H)`
//! from `+z`.

use super::geometry::acos_clamped;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// Pixel coordinates of the unit direction `w` on a `width x height`
/// equirectangular map (the layout above): `x = W phi / (2 pi)` in `[0, W]`,
/// `y = H theta / pi` in `[0, H]`, so pixel `(c, r)` covers `[c, c + 1) x
/// [r, r + 1)`. The inverse of [`EnvmapDensity::pixel_direction`](super::EnvmapDensity::pixel_direction)'s placement;
/// [`EnvmapDensity::pdf`](super::DirectionDensity::pdf) and [`FilteredLuminance::at`](super::FilteredLuminance::at)
/// both read the map through it.
pub(crate) fn pixel_coords(w: DVec3, width: usize, height: usize) -> DVec2 {
    let theta = acos_clamped(w.z);
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += TAU;
    }
    DVec2::new(phi / TAU * width as f64, theta / PI * height as f64)
}
