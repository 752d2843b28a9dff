//! What the examples that split `render`'s error by surface
//! (`render_bias_by_surface`, `mis_error_by_pixel`) share: the scene's surface
//! classes and which one each pixel shows.
use nuld_build_tool::lab::render::integrator::{Primary, Setup};

/// The surface classes, in print order ([`SurfacePixel::class`] indexes it).
pub const CLASSES: [&str; 3] = ["dielectric spheres", "metal spheres", "ground"];

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
/// the background. The ground is the plane `z = 0`; the spheres' material tells
/// the rest (metallic above 0.5: a metal sphere).
pub fn surface_pixels(setup: &Setup<'_>) -> Vec<Option<SurfacePixel>> {
    let (width, height) = (setup.camera.width(), setup.camera.height());
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| match setup.primary(x, y) {
            Primary::Surface { position, at, .. } => Some(SurfacePixel {
                class: match position.z < 1e-9 {
                    true => 2,
                    false => usize::from(at.material.metallic > 0.5),
                },
                roughness: at.material.roughness,
                theta_o_deg: at.theta_o_deg(),
            }),
            Primary::Background(_) => None,
        })
        .collect()
}
