//! What the examples that split `render`'s error by surface
//! (`render_bias_by_surface`, `mis_error_by_pixel`, `ground_error_by_instance`)
//! share: `render`'s scene at 160 x 120 pixels, its surface classes, which one
//! each pixel shows, and the reference `render` cached.
use nuld_build_tool::lab::render::brdf_warp::LobeTable;
use nuld_build_tool::lab::render::camera::Camera;
use nuld_build_tool::lab::render::environment::Environment;
use nuld_build_tool::lab::render::integrator::{Image, Primary, Setup};
use nuld_build_tool::lab::render::lineup;
use nuld_build_tool::lab::render::reference::Reference;
use nuld_build_tool::lab::render::sampler::Technique;
use nuld_build_tool::lab::render::scene::{Scene, SurfaceClass};
use std::path::Path;

/// The surface classes, in print order ([`SurfacePixel::class`] indexes it).
// Not every example that declares this module reads it.
#[allow(dead_code)]
pub const CLASSES: [&str; 3] = [
    SurfaceClass::ALL[0].name(),
    SurfaceClass::ALL[1].name(),
    SurfaceClass::ALL[2].name(),
];

/// `render --size 160x120`'s scene and camera, the BRDF lobes the lineup's
/// samplers take, and the surface each pixel shows.
pub struct EvalScene {
    pub scene: Scene,
    pub camera: Camera,
    pub lobes: LobeTable,
    pub pixels: Vec<Option<SurfacePixel>>,
}

impl EvalScene {
    /// Width and height in pixels, as `render --size 160x120`.
    pub const SIZE: (u32, u32) = (160, 120);

    /// The scene lit by `env`, its pixels classified.
    pub fn new(env: &Environment) -> Self {
        let scene = Scene::spheres_on_ground();
        let camera = Camera::evaluation(Self::SIZE.0, Self::SIZE.1);
        let lobes = LobeTable::new(&scene.materials());
        let pixels = surface_pixels(&Setup {
            scene: &scene,
            camera: &camera,
            env,
        });
        Self {
            scene,
            camera,
            lobes,
            pixels,
        }
    }

    /// What `render` renders the scene with under `env`.
    pub fn setup<'a>(&'a self, env: &'a Environment) -> Setup<'a> {
        Setup {
            scene: &self.scene,
            camera: &self.camera,
            env,
        }
    }

    /// The images of the lineup's samplers `names` (`render.csv`'s `sampler`)
    /// under `techniques` at `n` spp and `seed`, with the BRDF and environment
    /// blobs given: bit for bit those `render` makes. Panics on a name the
    /// lineup lacks.
    pub fn render(
        &self,
        env: &Environment,
        techniques: &[Technique],
        [brdf, envmap]: [Option<&[u8]>; 2],
        (n, seed): (u32, u64),
        names: &[&str],
    ) -> Vec<Image> {
        let mut weights = Default::default();
        let samplers = lineup::samplers(
            techniques,
            brdf,
            envmap,
            n,
            seed,
            &self.lobes,
            env,
            &mut weights,
        )
        .unwrap();
        let setup = self.setup(env);
        names
            .iter()
            .map(|&name| {
                let s = samplers
                    .iter()
                    .find(|s| s.name() == name)
                    .unwrap_or_else(|| panic!("no sampler {name} in the lineup"));
                setup.render(s.as_ref(), n, seed, &|| {})
            })
            .collect()
    }
}

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
fn surface_pixels(setup: &Setup<'_>) -> Vec<Option<SurfacePixel>> {
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

/// The one `reference-KEY.bin` `render` cached in `dir`.
// Not every example that declares this module reads it.
#[allow(dead_code)]
pub fn cached_reference(dir: &Path, width: u32, height: u32) -> Reference {
    let key = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .find_map(|f| {
            u64::from_str_radix(f.strip_prefix("reference-")?.strip_suffix(".bin")?, 16).ok()
        })
        .expect("a reference-KEY.bin in REFERENCE_DIR");
    Reference::load(dir, key, width, height)
        .unwrap()
        .expect("the reference of a 160 x 120 render")
}
