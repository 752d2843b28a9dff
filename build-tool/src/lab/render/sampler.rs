//! The one interface every sampler of the evaluation implements: for a shading
//! point, a pixel's key and a count `n`, the directions of the pixel's set, their
//! estimator weights and their densities.
//!
//! Estimator (one per pixel, direct lighting from the environment only): with the
//! samples `(l_i, w_i)` of a pixel's set,
//! `I ≈ (1/n) Σ w_i L(l_i) V(x, l_i)`, where `L` is the map's radiance and `V` the
//! visibility. The weight carries what the sampler knows of the rest:
//! * BRDF sampling: `w = f(wo, l) cos / p(l)` for the renderer's warp, and the
//!   stored albedo `A(roughness, theta_o, metallic)` for ours' fixed instances
//!   (`∫ L f cos ≈ (A/n) Σ L(l_i)`: `f cos / p` with `p = f cos / A`, the
//!   target their sets follow), the runtime's `f cos / pdf` for ours'
//!   unbiased mode;
//! * environment sampling: `w = f(wo, l) cos / pdf_env(l)`, ours included (its
//!   exact pdf);
//! * multiple importance sampling ([`super::mis`]): `2n` samples, `n` of each
//!   technique, each weight times its power-heuristic weight.

use super::frame::Frame;
use super::scene::Material;
use crate::seeding::{derive_seed, mix64};
use glam::DVec3;

/// One sample: a unit world direction, its estimator weight (see the module
/// docs; finite, `>= 0`) and its density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Unit direction in the world frame.
    pub direction: DVec3,
    /// Estimator weight.
    pub weight: f64,
    /// Solid-angle density of the sampler's warp at `direction` (per steradian),
    /// what [`DirectionSampler::pdf`] returns there; 0 where the sampler knows
    /// none (ours' fixed BRDF instances of blobs of the earlier mixture prior).
    /// For ours' fixed instances it is the density their sets were made to
    /// follow, the target the weight assumes.
    pub pdf: f64,
}

/// What a sampler may know of the point being shaded.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    /// The local frame (`z` = the geometric normal).
    pub frame: Frame,
    /// Unit view direction (towards the camera) in the local frame, `z > 0`.
    pub wo: DVec3,
    /// The surface's material: glTF roughness and metallic.
    pub material: Material,
}

impl ShadingPoint {
    /// The cosine-weighted glTF metallic-roughness BRDF `f(wo, l) max(n.l, 0)`
    /// for the world direction `l` ([`Material::cosine_weighted`],
    /// `nuld_core::brdf::gltf_metallic`).
    pub fn cosine_weighted(&self, l: DVec3) -> f64 {
        self.material
            .cosine_weighted(self.wo, self.frame.to_local(l))
    }

    /// `θo` in degrees, the view angle of the BRDF's condition.
    pub fn theta_o_deg(&self) -> f64 {
        self.wo.z.clamp(0.0, 1.0).acos().to_degrees()
    }
}

/// Which integral a sampler importance-samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Technique {
    /// The cosine-weighted BRDF.
    Brdf,
    /// The environment map.
    Envmap,
    /// Both, by multiple importance sampling with the power heuristic.
    Mis,
}

impl Technique {
    /// Every technique, in table order.
    pub const ALL: [Technique; 3] = [Technique::Brdf, Technique::Envmap, Technique::Mis];

    /// `brdf`, `envmap` or `mis` (the `technique` column of `render.csv`).
    pub fn name(self) -> &'static str {
        match self {
            Technique::Brdf => "brdf",
            Technique::Envmap => "envmap",
            Technique::Mis => "mis",
        }
    }

    /// The technique named `name` ([`Self::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }
}

/// A pixel's key: a hash of `(seed, pixel index)` from which every sampler derives
/// the pixel's scramble, instance or set, so pixels are decorrelated and the image
/// does not depend on the order pixels are rendered in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelKey(pub u64);

/// Stream of [`derive_seed`] for the pixel keys.
const PIXEL_STREAM: u64 = 0x9e4d;

impl PixelKey {
    /// The key of pixel `index` (`y * width + x`) under `seed`.
    pub fn new(seed: u64, index: u64) -> Self {
        Self(mix64(derive_seed(seed, PIXEL_STREAM) ^ index))
    }

    /// The key's high 32 bits: the instance of a conditional sampler.
    pub fn instance(self) -> u32 {
        (self.0 >> 32) as u32
    }

    /// The key's low 32 bits: an Owen scramble seed, and the random number of our
    /// unbiased mode.
    pub fn scramble(self) -> u32 {
        self.0 as u32
    }

    /// An independent key for a second technique at the same pixel (the BRDF
    /// half of multiple importance sampling).
    pub fn second(self) -> Self {
        Self(mix64(self.0 ^ SECOND_STREAM))
    }
}

/// What [`PixelKey::second`] mixes in.
const SECOND_STREAM: u64 = 0x5ec0_4d00_b4df_0001;

/// A sampler of directions for the evaluation (see the module docs).
pub trait DirectionSampler: Send + Sync {
    /// The integral it importance-samples.
    fn technique(&self) -> Technique;

    /// Its name in `render.csv` (`nuld-table`, `owen-sobol`, ...).
    fn name(&self) -> &'static str;

    /// The `n` samples of the set of the pixel with key `key` at `at`, into `out`
    /// (cleared first). Deterministic in `(at, key, n)`.
    fn samples(&self, at: &ShadingPoint, key: PixelKey, n: u32, out: &mut Vec<Sample>);

    /// The solid-angle density with which the sampler's warp at `at` produces the
    /// world direction `l` (0 where it never does), for multiple importance
    /// sampling; `None` when the sampler cannot say (ours' fixed BRDF instances
    /// of blobs of the earlier mixture prior, which store no albedo table).
    fn pdf(&self, at: &ShadingPoint, l: DVec3) -> Option<f64>;
}
