//! What the examples that split `render`'s error by surface
//! (`render_bias_by_surface`, `mis_error_by_pixel`) share: the scene's surface
//! classes and which one each pixel shows.
use nuld_build_tool::lab::render::integrator::{Primary, Setup};
use nuld_build_tool::lab::render::scene::SurfaceClass;

/// The surface classes, in print order ([`SurfacePixel::class`] indexes it).
pub const CLASSES: [&str; 3] = [
    SurfaceClass::ALL[0].name(),
    SurfaceClass::ALL[1].name(),
    SurfaceClass::ALL[2].name(),
];

/// A pixel that shows a surface.
// Each example reads the fields it needs.
#[allow(dead_code)]
#[derive(Clone, Copy, Debug)]
pub struct SurfacePixel {
    /// Its class, an index into [`CLASSES`].
    pub class: usize,
    /// The surface's glTF roughness.
    pub roughness: f64,
    /// The view angle `θo` in degrees.
    pub theta_o_deg: f64,
}

/// Per pixel of `setup`'s camera, row by row, the surface it shows; `None` on
/// the background; the class is `render`'s ([`SurfaceClass::of`]).
pub fn surface_pixels(setup: &Setup<'_>) -> Vec<Option<SurfacePixel>> {
    let (width, height) = (setup.camera.width(), setup.camera.height());
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| match setup.primary(x, y) {
            Primary::Surface { position, at, .. } => Some(SurfacePixel {
                class: SurfaceClass::of(position, &at.material).index(),
                roughness: at.material.roughness,
                theta_o_deg: at.theta_o_deg(),
            }),
            Primary::Background(_) => None,
        })
        .collect()
}
