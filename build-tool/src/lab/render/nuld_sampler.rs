//! Ours: the conditional samplers of baked blobs, reached only through
//! `nuld-runtime`'s public API on the blob's bytes, exactly as a renderer that
//! links the runtime would: `Blob::parse(bytes)?.brdf()?` (or `.envmap()?`) once,
//! then per sample, with the pixel's instance (its key's high 32 bits) and the
//! index:
//!
//! Network mode reads the weights decoded once per blob into a buffer of the
//! caller's ([`NuldSampler::decoded`], [`BrdfSampler::decode_network`]; the
//! same bits as the zero-copy f16 path, faster), as a CPU renderer would.
//!
//! * BRDF sampling: [`BrdfSampler::sample`] (table mode) or
//!   [`BrdfNetwork::sample`] (network mode) at the local view direction and the
//!   surface's roughness and metallic, or their unbiased mode
//!   ([`BrdfSampler::sample_randomized`], `nuld-unbiased`, the pixel key's low 32
//!   bits as its random number): the unbiased mode weighs by the sample's own
//!   `f cos / pdf` and knows its pdf ([`BrdfSampler::pdf`]), a fixed instance
//!   weighs by the albedo at the material ([`BrdfSampler::albedo`]; its set
//!   follows the target `f cos / A`, as below) and its density is that target,
//!   `p(l) = f(wo, l) cos / A` (so that its weight is `f cos / p` as every
//!   other sampler's, and multiple importance sampling can weigh its samples
//!   against the environment sampler's; blobs of the earlier mixture prior,
//!   which store no albedo table, know no density);
//! * environment sampling: [`EnvmapSampler::sample`] or
//!   [`EnvmapNetwork::sample`] at the world normal, or their unbiased mode
//!   ([`EnvmapSampler::sample_randomized`], `nuld-unbiased`, the pixel key's low
//!   32 bits as its random number), weighted by a density:
//!   * the unbiased mode's samples are distributed exactly as the runtime's
//!     pdf (the prior's): the weight is the usual `f(wo, l) cos / pdf(l)`, and
//!     [`DirectionSampler::pdf`] is the runtime's `pdf`;
//!   * a fixed instance is weighted the same way, `f cos / pdf` with the
//!     runtime's pdf, and [`DirectionSampler::pdf`] is that pdf: the 64
//!     instances together follow the prior to about 0.1 %, so the estimate's
//!     bias is theirs, small (2 % and 5 % of Owen-Sobol's RMSE with MIS at 256
//!     spp on courtyard and studio). `render --fixed-weight` picks the others
//!     of [`FixedWeight`], for comparison: the target `q = L cos / E` that each
//!     set was trained towards (`f cos / q = E f / L`, `E(n)` the sample's
//!     weight and `L` the map; its pdf `q`, 0 where `L` or the cosine is 0), of
//!     lower variance on studio and biased where the union's prior is not `q`
//!     (12 % on courtyard), and the pdf with each set normalized by its own
//!     estimate of `E(n)` (docs/results/rendering.md#leaf-shape).

use super::environment::Environment;
use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint, Technique};
use glam::{DVec2, DVec3};
use nuld_core::sphere::square_to_sphere;
use nuld_runtime::glam::Vec2;
use nuld_runtime::{
    Blob, BlobError, BlobKind, BrdfNetwork, BrdfSampler, ConditionalSampler, EnvmapNetwork,
    EnvmapSampler,
};

/// Table mode or network mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NuldMode {
    /// Interpolated point tables (`nuld-table`).
    Table,
    /// The f16 network per sample (`nuld-network`).
    Network,
}

/// How a fixed instance of the environment sampler weighs its samples (module
/// docs): each sample's `f cos / p`, `p` a density the set stands for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FixedWeight {
    /// `p` = the prior's pdf, and the set's weights divided by the set's own
    /// estimate of `E(n)` relative to the runtime's: `c = (1/n) Σ L cos / (p E)`
    /// (a self-normalized estimator, whose control variate is `L cos`, of
    /// known integral `E`).
    Normalized,
    /// `p` = the prior's pdf: the renderer's usual `L f cos / pdf`.
    #[default]
    Pdf,
    /// `p` = the target `q = L cos / E`: `f cos / q = E f / L`.
    Target,
}

impl FixedWeight {
    /// The weights by name (`normalized`, `pdf`, `target`).
    pub const ALL: [(&'static str, FixedWeight); 3] = [
        ("normalized", FixedWeight::Normalized),
        ("pdf", FixedWeight::Pdf),
        ("target", FixedWeight::Target),
    ];
}

/// Why a blob cannot serve as the BRDF sampler.
#[derive(Debug, thiserror::Error)]
pub enum NuldBlobError {
    /// The runtime rejected the bytes.
    #[error("not a valid nuld blob: {0}")]
    Parse(BlobError),
    /// A valid blob of another kind.
    #[error("a {0:?} blob, not a conditional sampler")]
    Kind(BlobKind),
    /// A conditional blob for another target.
    #[error("a conditional sampler for target code {0}, not {1}")]
    Target(u32, &'static str),
}

/// What ours samples, through the runtime's typed view of the mode.
#[derive(Clone, Copy, Debug)]
enum Kind<'a> {
    Brdf(BrdfSampler<'a>),
    BrdfNetwork(BrdfNetwork<'a>),
    Envmap(EnvmapSampler<'a>, &'a Environment),
    EnvmapNetwork(EnvmapNetwork<'a>, &'a Environment),
}

/// Ours (see the module docs): a view on the blob's bytes.
#[derive(Clone, Copy, Debug)]
pub struct NuldSampler<'a> {
    sampler: ConditionalSampler<'a>,
    mode: NuldMode,
    kind: Kind<'a>,
    randomized: bool,
    fixed_weight: FixedWeight,
}

/// The runtime's refusal of a view as the reason a blob cannot serve.
fn refused(e: BlobError, name: &'static str) -> NuldBlobError {
    match e {
        BlobError::WrongKind { found, .. } => NuldBlobError::Kind(found),
        BlobError::WrongTarget { found, .. } => NuldBlobError::Target(found as u32, name),
        e => NuldBlobError::Parse(e),
    }
}

impl<'a> NuldSampler<'a> {
    /// The BRDF sampler of the blob `bytes` (16-byte aligned, e.g.
    /// `nuld_runtime::AlignedBuf`) in `mode`; an error unless they hold a
    /// conditional glTF-BRDF sampler.
    pub fn new(bytes: &'a [u8], mode: NuldMode) -> Result<Self, NuldBlobError> {
        let blob = Blob::parse(bytes).map_err(NuldBlobError::Parse)?;
        let brdf = blob.brdf().map_err(|e| refused(e, "the glTF BRDF"))?;
        Ok(Self {
            sampler: brdf.conditional(),
            mode,
            randomized: false,
            fixed_weight: FixedWeight::default(),
            kind: match mode {
                NuldMode::Table => Kind::Brdf(brdf),
                NuldMode::Network => Kind::BrdfNetwork(brdf.network()),
            },
        })
    }

    /// The environment sampler of the blob `bytes` for the map `env` in `mode`;
    /// an error unless they hold a conditional environment sampler. That the
    /// blob was baked for `env` is the reader's check, made once per blob
    /// ([`super::blobs::SamplerBlobs::read_envmap`]).
    pub fn envmap(
        bytes: &'a [u8],
        mode: NuldMode,
        env: &'a Environment,
    ) -> Result<Self, NuldBlobError> {
        let blob = Blob::parse(bytes).map_err(NuldBlobError::Parse)?;
        let sampler = blob
            .envmap()
            .map_err(|e| refused(e, "an environment map"))?;
        Ok(Self {
            sampler: sampler.conditional(),
            mode,
            randomized: false,
            fixed_weight: FixedWeight::default(),
            kind: match mode {
                NuldMode::Table => Kind::Envmap(sampler, env),
                NuldMode::Network => Kind::EnvmapNetwork(sampler.network(), env),
            },
        })
    }

    /// Nine nodes of the weight table (first, middle and last per axis), each as
    /// the normal it stands for and the stored weight `E(n)` there, read back
    /// through [`ConditionalSampler::weight`] at the node's condition: values the
    /// bake computed exactly, to compare with the map's own irradiance (between
    /// nodes the table is an interpolation, which a sun's kink makes coarse).
    pub fn irradiance_nodes(&self) -> Vec<(DVec3, f64)> {
        let info = self.sampler.info();
        let picks = |g: u32| [0, (g - 1) / 2, g - 1];
        picks(info.weight_grid[0])
            .into_iter()
            .flat_map(|j0| picks(info.weight_grid[1]).map(|j1| [j0, j1]))
            .map(|j| {
                let u = info.weight_grid_condition(j);
                let w = self.sampler.weight(Vec2::new(u[0] as f32, u[1] as f32));
                (square_to_sphere(DVec2::from(u)), w as f64)
            })
            .collect()
    }

    /// This sampler with network mode reading the weights decoded into `buf`
    /// (resized to the network's length) instead of the blob's f16 bits: the same
    /// samples, bit for bit, in less time. Table mode is returned as it is.
    pub fn decoded(self, buf: &'a mut Vec<f32>) -> Self {
        if self.mode == NuldMode::Table {
            return self;
        }
        buf.clear();
        buf.resize(self.sampler.decoded_network_len(), 0.0);
        let kind = match self.kind {
            Kind::BrdfNetwork(_) => BrdfSampler::try_from(self.sampler)
                .ok()
                .and_then(|b| b.decode_network(buf))
                .map(Kind::BrdfNetwork),
            Kind::EnvmapNetwork(_, env) => EnvmapSampler::try_from(self.sampler)
                .ok()
                .and_then(|e| e.decode_network(buf))
                .map(|n| Kind::EnvmapNetwork(n, env)),
            _ => None,
        };
        // `None` is unreachable: the buffer has the length asked for.
        kind.map_or(self, |kind| Self { kind, ..self })
    }

    /// The sampler in its unbiased mode (a random torus shift per pixel, the
    /// pixel key's low 32 bits; module docs).
    pub fn unbiased(self) -> Self {
        Self {
            randomized: true,
            ..self
        }
    }

    /// The sampler with a fixed instance's samples weighted by `w` (environment
    /// sampling; module docs). The unbiased mode and BRDF sampling ignore it.
    pub fn with_fixed_weight(self, w: FixedWeight) -> Self {
        Self {
            fixed_weight: w,
            ..self
        }
    }

    /// Points per set `N` of the blob.
    pub fn len(&self) -> u32 {
        self.sampler.len()
    }

    /// Always `false` (a parsed blob has points).
    pub fn is_empty(&self) -> bool {
        self.sampler.is_empty()
    }
}

impl DirectionSampler for NuldSampler<'_> {
    fn technique(&self) -> Technique {
        match self.kind {
            Kind::Brdf(_) | Kind::BrdfNetwork(_) => Technique::Brdf,
            Kind::Envmap(..) | Kind::EnvmapNetwork(..) => Technique::Envmap,
        }
    }

    fn name(&self) -> &'static str {
        match (self.mode, self.randomized) {
            (NuldMode::Table, false) => "nuld-table",
            (NuldMode::Network, false) => "nuld-network",
            (NuldMode::Table, true) => "nuld-unbiased",
            (NuldMode::Network, true) => "nuld-network-unbiased",
        }
    }

    /// Indices `0..n` of the pixel's instance; `n` is the blob's `N` in the
    /// evaluation (indices wrap modulo `N` otherwise).
    fn samples(&self, at: &ShadingPoint, key: PixelKey, n: u32, out: &mut Vec<Sample>) {
        out.clear();
        let k = key.instance();
        let normal = at.frame.to_world(DVec3::Z).as_vec3();
        let m = at.material;
        let (wo, r, m) = (at.wo.as_vec3(), m.roughness as f32, m.metallic as f32);
        // A fixed BRDF instance's albedo, the same for the whole set.
        let albedo = match self.kind {
            Kind::Brdf(_) | Kind::BrdfNetwork(_) if !self.randomized => self.albedo(at),
            _ => None,
        };
        match self.kind {
            Kind::Brdf(t) => out.extend((0..n).map(|i| {
                let s = match self.randomized {
                    false => t.sample(wo, r, m, k, i),
                    true => t.sample_randomized(wo, r, m, k, i, key.scramble()),
                };
                self.brdf_sample(at, s, albedo)
            })),
            Kind::BrdfNetwork(t) => out.extend((0..n).map(|i| {
                let s = match self.randomized {
                    false => t.sample(wo, r, m, k, i),
                    true => t.sample_randomized(wo, r, m, k, i, key.scramble()),
                };
                self.brdf_sample(at, s, albedo)
            })),
            Kind::Envmap(t, env) => {
                let set = (0..n).map(|i| match self.randomized {
                    false => t.sample(normal, k, i),
                    true => t.sample_randomized(normal, k, i, key.scramble()),
                });
                self.envmap_set(at, env, set, out);
            }
            Kind::EnvmapNetwork(t, env) => {
                let set = (0..n).map(|i| match self.randomized {
                    false => t.sample(normal, k, i),
                    true => t.sample_randomized(normal, k, i, key.scramble()),
                });
                self.envmap_set(at, env, set, out);
            }
        }
    }

    fn pdf(&self, at: &ShadingPoint, l: DVec3) -> Option<f64> {
        let normal = at.frame.normal().as_vec3();
        let prior = match self.kind {
            Kind::Brdf(_) | Kind::BrdfNetwork(_) if !self.randomized => {
                return Self::target_pdf(at, self.albedo(at)?, l);
            }
            Kind::Brdf(_) | Kind::BrdfNetwork(_) => {
                let m = at.material;
                let (wo, local) = (at.wo.as_vec3(), at.frame.to_local(l).as_vec3());
                let (r, m) = (m.roughness as f32, m.metallic as f32);
                let pdf =
                    BrdfSampler::try_from(self.sampler).map_or(0.0, |t| t.pdf(wo, r, m, local));
                return Some(pdf as f64);
            }
            Kind::Envmap(t, env) => (t.pdf(normal, l.as_vec3()), env),
            Kind::EnvmapNetwork(t, env) => (t.pdf(normal, l.as_vec3()), env),
        };
        Some(
            match self.randomized || self.fixed_weight != FixedWeight::Target {
                true => prior.0 as f64,
                false => {
                    // The runtime's E(n), the weight its samples carry here.
                    let e = EnvmapSampler::try_from(self.sampler).map_or(0.0, |t| t.weight(normal));
                    target_density(at, prior.1, e as f64, l)
                }
            },
        )
    }
}

impl NuldSampler<'_> {
    /// The blob's albedo `A` at the shading point's view and material
    /// ([`BrdfSampler::albedo`]): the weight of a fixed BRDF instance's
    /// samples; `None` for a blob that stores no albedo table (the earlier
    /// mixture prior).
    fn albedo(&self, at: &ShadingPoint) -> Option<f64> {
        let t = BrdfSampler::try_from(self.sampler).ok()?;
        let m = at.material;
        Some(t.albedo(at.wo.as_vec3(), m.roughness as f32, m.metallic as f32) as f64)
    }

    /// A fixed BRDF instance's density at the world direction `l`: the target
    /// its sets follow, `f(wo, l) cos / A` with `A` the albedo `a`; `None`
    /// where `A` is 0.
    fn target_pdf(at: &ShadingPoint, a: f64, l: DVec3) -> Option<f64> {
        (a > 0.0).then(|| at.cosine_weighted(l) / a)
    }

    /// A BRDF sample in the world frame weighted by the density it follows
    /// (module docs): the runtime's weight `f cos / pdf` and its pdf in the
    /// unbiased mode; for a fixed instance, whose set follows the target
    /// `f cos / A`, the albedo `A` at the material and that target as its pdf
    /// (the weight of blobs of the earlier mixture prior in either mode, whose
    /// samples carry no pdf, with pdf 0).
    /// The unbiased mode keeps the runtime's weight even where its pdf is 0 (a
    /// sample the prior's table leaks past the horizon: weight 0, which keeps
    /// the estimate unbiased; the albedo there would add the leaked mass). The
    /// runtime's directions are unit to f32 rounding; used as they come.
    /// `albedo`: [`Self::albedo`] at `at` (read by a fixed instance only).
    fn brdf_sample(
        &self,
        at: &ShadingPoint,
        s: nuld_runtime::Sample,
        albedo: Option<f64>,
    ) -> Sample {
        let direction = at.frame.to_world(s.direction.as_dvec3());
        let (weight, pdf) = match (self.randomized, albedo) {
            (true, _) => (s.weight as f64, s.pdf as f64),
            (false, Some(a)) => (a, Self::target_pdf(at, a, direction).unwrap_or(0.0)),
            (false, None) => (s.weight as f64, 0.0),
        };
        Sample {
            direction,
            weight,
            pdf,
        }
    }

    /// The runtime's environment samples `set` as [`Self::envmap_sample`]s
    /// into `out`, the fixed instance's set then [`Self::normalize`]d.
    fn envmap_set(
        &self,
        at: &ShadingPoint,
        env: &Environment,
        set: impl Iterator<Item = nuld_runtime::Sample>,
        out: &mut Vec<Sample>,
    ) {
        out.extend(set.map(|s| self.envmap_sample(at, env, s)));
        self.normalize(at, env, out);
    }

    /// An environment sample (world frame) weighted by the density it follows
    /// (module docs): the runtime's exact pdf in the unbiased mode, and for a
    /// fixed instance as [`FixedWeight`] says (before [`Self::normalize`]).
    fn envmap_sample(
        &self,
        at: &ShadingPoint,
        env: &Environment,
        s: nuld_runtime::Sample,
    ) -> Sample {
        let l = s.direction.as_dvec3();
        let pdf = match (self.randomized, self.fixed_weight) {
            (false, FixedWeight::Target) => target_density(at, env, s.weight as f64, l),
            _ => s.pdf as f64,
        };
        let f_cos = at.cosine_weighted(l);
        Sample {
            direction: l,
            weight: if pdf > 0.0 && f_cos > 0.0 {
                f_cos / pdf
            } else {
                0.0
            },
            pdf,
        }
    }

    /// A fixed instance's set weighted [`FixedWeight::Normalized`]: each weight
    /// `f cos / p` divided by `c = (1/n) Σ L cos / (p e)`, the set's own
    /// estimate of the irradiance `e = E(n)` over the runtime's. Where the
    /// prior's pdf is `L cos / E` up to a constant, `c` is that constant and
    /// each sample contributes `E f`, as the target weight; where it is not,
    /// the set's own errors on `L cos` cancel from the estimate. Nothing
    /// otherwise (or when no sample sees light: the weights are then 0).
    fn normalize(&self, at: &ShadingPoint, env: &Environment, set: &mut [Sample]) {
        if self.randomized || self.fixed_weight != FixedWeight::Normalized {
            return;
        }
        let normal = at.frame.normal().as_vec3();
        let e = EnvmapSampler::try_from(self.sampler).map_or(0.0, |t| t.weight(normal)) as f64;
        if e <= 0.0 {
            return;
        }
        let n = set.len() as f64;
        let c = set
            .iter()
            .filter(|s| s.pdf > 0.0)
            .map(|s| lit(at, env, s.direction) / s.pdf)
            .sum::<f64>()
            / (n * e);
        if c > 0.0 && c.is_finite() {
            set.iter_mut().for_each(|s| s.weight /= c);
        }
    }
}

/// The environment sampler's target at the shading point,
/// `q(l) = L(l) max(0, n.l) / E(n)` per steradian, with `E(n) = e`; 0 where the
/// normal sees no light.
fn target_density(at: &ShadingPoint, env: &Environment, e: f64, l: DVec3) -> f64 {
    if e > 0.0 {
        lit(at, env, l) / e
    } else {
        0.0
    }
}

/// The map's light at `l` times the shading point's cosine, `L(l) max(0, n.l)`.
fn lit(at: &ShadingPoint, env: &Environment, l: DVec3) -> f64 {
    let cos = at.frame.normal().dot(l).max(0.0);
    if cos > 0.0 {
        env.radiance(l) * cos
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::render::blobs::tiny_blob;
    use crate::lab::render::frame::Frame;
    use glam::{DVec3, Vec3};

    /// Ours is the runtime and nothing else: on the same blob bytes, the samples
    /// equal direct `nuld_runtime` calls bit for bit (local frame = world frame
    /// for the normal `+z`), network mode on decoded weights included, at the
    /// shading point's roughness and metallic (dielectric, metal, half-metal),
    /// fixed instances and the unbiased mode alike.
    #[test]
    fn samples_are_the_runtimes_bit_for_bit() {
        use crate::lab::render::scene::Material;
        let blob = tiny_blob(8);
        let cs = Blob::parse(blob.as_slice()).unwrap().brdf().unwrap();
        let key = PixelKey(0x1234_5678_9abc_def0);
        let (k, scramble) = (key.instance(), key.scramble());
        let mut unbiased_checked = 0;
        for (mode, unbiased, name) in [
            (NuldMode::Table, false, "nuld-table"),
            (NuldMode::Network, false, "nuld-network"),
            (NuldMode::Table, true, "nuld-unbiased"),
            (NuldMode::Network, true, "nuld-network-unbiased"),
        ] {
            // Network mode on decoded weights, compared below with the runtime's
            // zero-copy f16 path.
            let mut weights = Vec::new();
            let mut ours = NuldSampler::new(blob.as_slice(), mode)
                .unwrap()
                .decoded(&mut weights);
            if unbiased {
                ours = ours.unbiased();
            }
            assert_eq!((ours.name(), ours.len()), (name, 8));
            assert_eq!(ours.technique(), Technique::Brdf);
            for metallic in [0.0f32, 1.0, 0.5] {
                let r = 0.4f32;
                let want = |wo: Vec3, i: u32| match (mode, unbiased) {
                    (NuldMode::Table, false) => cs.sample(wo, r, metallic, k, i),
                    (NuldMode::Network, false) => cs.network().sample(wo, r, metallic, k, i),
                    (NuldMode::Table, true) => {
                        cs.sample_randomized(wo, r, metallic, k, i, scramble)
                    }
                    (NuldMode::Network, true) => cs
                        .network()
                        .sample_randomized(wo, r, metallic, k, i, scramble),
                };
                let wo = Vec3::new(0.3, -0.4, 0.7).normalize();
                let at = ShadingPoint {
                    frame: Frame::new(DVec3::Z),
                    wo: DVec3::new(wo.x as f64, wo.y as f64, wo.z as f64),
                    material: Material {
                        roughness: r as f64,
                        metallic: metallic as f64,
                    },
                };
                let mut out = Vec::new();
                ours.samples(&at, key, 8, &mut out);
                for (i, s) in out.iter().enumerate() {
                    let want = want(wo, i as u32);
                    let got = s.direction.as_vec3();
                    assert_eq!(
                        got.to_array().map(f32::to_bits),
                        want.direction.to_array().map(f32::to_bits)
                    );
                    if unbiased {
                        // The unbiased mode weighs by the sample's own f cos / pdf
                        // (0 where the prior leaks, pdf 0) and knows its pdf, for
                        // any direction.
                        assert_eq!((s.weight, s.pdf), (want.weight as f64, want.pdf as f64));
                        let pdf = cs.pdf(wo, r, metallic, want.direction) as f64;
                        assert_eq!(ours.pdf(&at, s.direction), Some(pdf));
                        unbiased_checked += (want.pdf > 0.0) as usize;
                    } else {
                        // A fixed instance weighs by the albedo at the material
                        // and its density is the target f cos / A (module docs):
                        // f cos from the core's glTF BRDF at the runtime's
                        // direction, in f64.
                        let a = cs.albedo(wo, r, metallic) as f64;
                        assert_eq!(s.weight, a);
                        let l = s.direction;
                        let f_cos = nuld_core::brdf::gltf_metallic(
                            at.wo.to_array(),
                            l.to_array(),
                            r as f64,
                            metallic as f64,
                        ) * l.z.max(0.0);
                        assert!(a > 0.0 && (s.pdf - f_cos / a).abs() <= 1e-12 * s.pdf.max(1.0));
                        assert_eq!(ours.pdf(&at, s.direction), Some(s.pdf));
                    }
                }
                // At a tilted normal the world directions are the runtime's local
                // ones carried by the frame: back in the local frame they agree to
                // rounding, and they lie above the surface.
                let n = DVec3::new(-0.5, 0.3, 0.2).normalize();
                let tilted = ShadingPoint {
                    frame: Frame::new(n),
                    ..at
                };
                ours.samples(&tilted, key, 8, &mut out);
                for (i, s) in out.iter().enumerate() {
                    let local = tilted.frame.to_local(s.direction);
                    assert!((local - want(wo, i as u32).direction.as_dvec3()).length() < 1e-12);
                    assert!(s.direction.dot(n) >= 0.0);
                }
            }
        }
        // The metal's albedo is not the dielectric's: the metallic is read.
        let wo = Vec3::new(0.3, -0.4, 0.7).normalize();
        assert!((cs.albedo(wo, 0.4, 1.0) - cs.albedo(wo, 0.4, 0.0)).abs() > 1e-3);
        assert!(unbiased_checked > 30, "{unbiased_checked}");
    }

    /// Ours for the environment is the runtime's `EnvmapSampler::sample` (or
    /// `sample_randomized` with the key's low bits) at the world normal, bit for
    /// bit. The unbiased mode is weighted `f cos / pdf` by the runtime's pdf,
    /// which `pdf` returns for any direction, and that pdf is the product warp's
    /// of the map (`Environment::product_pdf`, the baselines through ours' prior)
    /// to f32 rounding: the same warp. A fixed instance is weighted by the
    /// density its [`FixedWeight`] names: the target `q = L cos / E` (each
    /// sample contributes `E f`), the runtime's pdf, or that pdf with the set
    /// normalized (the set's estimate of `∫ L cos`, `f` replaced by 1, is then
    /// the runtime's `E(n)` exactly), and `pdf` returns that density.
    #[test]
    fn envmap_samples_are_the_runtimes_weighted_by_the_density_they_follow() {
        use crate::lab::render::blobs::tiny_envmap_blob;
        use crate::lab::render::environment::Environment;
        use crate::sphere::envmap::tiny_map;
        let dir = std::env::temp_dir().join(format!("nuld-envsampler-{}", std::process::id()));
        let map = tiny_map(&dir);
        let env = Environment::from_file(&map).unwrap();
        let blob = tiny_envmap_blob(8, &map);
        let cs = Blob::parse(blob.as_slice()).unwrap().envmap().unwrap();
        let n = DVec3::new(0.3, -0.5, 0.6).normalize();
        let at = ShadingPoint {
            frame: Frame::new(n),
            wo: DVec3::new(0.4, 0.1, 0.8).normalize(),
            material: crate::lab::render::scene::Material::dielectric(0.3),
        };
        let key = PixelKey(0x0fed_cba9_8765_4321);
        let (mut checked, mut compared, mut normalized) = (0, 0, 0);
        let modes = [false, true].into_iter().flat_map(|unbiased| {
            FixedWeight::ALL
                .into_iter()
                .map(move |(_, w)| (unbiased, w))
        });
        for mode in [NuldMode::Table, NuldMode::Network] {
            for (unbiased, fixed_weight) in modes.clone() {
                let mut weights = Vec::new();
                let mut ours = NuldSampler::envmap(blob.as_slice(), mode, &env)
                    .unwrap()
                    .decoded(&mut weights)
                    .with_fixed_weight(fixed_weight);
                if unbiased {
                    ours = ours.unbiased();
                }
                assert_eq!(ours.technique(), Technique::Envmap);
                let mut out = Vec::new();
                ours.samples(&at, key, 8, &mut out);
                let (k, nf) = (key.instance(), n.as_vec3());
                let want = |i: u32| match (mode, unbiased) {
                    (NuldMode::Table, false) => cs.sample(nf, k, i),
                    (NuldMode::Network, false) => cs.network().sample(nf, k, i),
                    (NuldMode::Table, true) => cs.sample_randomized(nf, k, i, key.scramble()),
                    (NuldMode::Network, true) => {
                        cs.network().sample_randomized(nf, k, i, key.scramble())
                    }
                };
                // The fixed instance's normalization, from the runtime's samples.
                let e = cs.weight(nf) as f64;
                let c = (0..8)
                    .map(|i| {
                        let s = want(i);
                        let l = s.direction.as_dvec3();
                        env.radiance(l) * n.dot(l).max(0.0) / s.pdf as f64 / e
                    })
                    .sum::<f64>()
                    / 8.0;
                let mut irradiance = 0.0;
                for (i, s) in out.iter().enumerate() {
                    let want = want(i as u32);
                    assert_eq!(s.direction, want.direction.as_dvec3());
                    let l = s.direction;
                    let f_cos = at.cosine_weighted(l);
                    let l_cos = env.radiance(l) * n.dot(l).max(0.0);
                    let prior = Some(cs.pdf(nf, want.direction) as f64);
                    let scale = match (unbiased, fixed_weight) {
                        (false, FixedWeight::Normalized) => c,
                        _ => 1.0,
                    };
                    if unbiased || fixed_weight != FixedWeight::Target {
                        assert_eq!(s.pdf, want.pdf as f64);
                        assert_eq!(ours.pdf(&at, l), prior);
                    }
                    if unbiased {
                        let product = env.product_pdf(n, l);
                        if product > 0.0 {
                            assert!(
                                (product - s.pdf).abs() <= 1e-4 * product,
                                "{product} {}",
                                s.pdf
                            );
                            compared += 1;
                        }
                    } else if fixed_weight == FixedWeight::Target {
                        // q = L cos / E, E the runtime's weight; f cos / q = E f / L.
                        let e = want.weight as f64;
                        let q = l_cos / e;
                        assert!((s.pdf - q).abs() <= 1e-12 * q, "{} {q}", s.pdf);
                        let back = ours.pdf(&at, l).unwrap();
                        assert!((back - q).abs() <= 1e-5 * q, "{back} {q}");
                        if f_cos > 0.0 {
                            let f = nuld_core::brdf::brdf(at.wo, at.frame.to_local(l), 0.3);
                            let contribution = s.weight * env.radiance(l);
                            assert!((contribution - e * f).abs() <= 1e-9 * e * f);
                        }
                    }
                    if f_cos > 0.0 {
                        let w = f_cos / s.pdf / scale;
                        assert!((s.weight - w).abs() <= 1e-12 * s.weight);
                        irradiance += s.weight * l_cos / f_cos / 8.0;
                        checked += 1;
                    } else {
                        assert_eq!(s.weight, 0.0);
                    }
                }
                if !unbiased && fixed_weight == FixedWeight::Normalized {
                    // Every sample of this normal's set sees the sky (the
                    // dielectric's f cos > 0 wherever the cosine is).
                    assert!((irradiance - e).abs() <= 1e-9 * e, "{irradiance} {e}");
                    assert!(
                        (c - 1.0).abs() > 1e-6,
                        "a set that needs no normalization: {c}"
                    );
                    normalized += 1;
                }
            }
        }
        assert!(checked > 8 && compared > 8 && normalized == 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The sampler path of the renderer reaches the sampler through
    /// `nuld-runtime` only: no file of `render/` but the blob baker imports the
    /// tool's training, network or conditional-sampler code.
    #[test]
    fn the_renderer_does_not_import_the_tools_sampler_internals() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lab/render");
        let mut checked = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            // `blobs.rs` bakes missing blobs; `run.rs` only holds the bake settings.
            if name == "blobs.rs" || name == "run.rs" {
                continue;
            }
            let src = std::fs::read_to_string(&path).unwrap();
            // The code, not its tests (this test names what it looks for).
            let code = src.split("#[cfg(test)]").next().unwrap();
            for internal in [
                "crate::train",
                "crate::network",
                "crate::conditional",
                "nuld_core::network",
                "nuld_core::conditional",
            ] {
                assert!(!code.contains(internal), "{name} uses {internal}");
            }
            checked += 1;
        }
        assert!(checked >= 10, "only {checked} files checked");
        let src = std::fs::read_to_string(dir.join("run.rs")).unwrap();
        assert!(
            !src.contains("crate::train::Trainer") && !src.contains("crate::conditional::distill")
        );
    }
}
