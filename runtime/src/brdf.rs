//! The BRDF sampler's typed views (blobs of `build-tool bake --brdf`): a view
//! direction, a roughness and a metallic in, a direction of the set for that view
//! out, in table mode ([`BrdfSampler`]) or network mode ([`BrdfNetwork`]), with
//! the exact pdf of the sampler's prior and an unbiased mode.
//!
//! **The prior.** Every set is the exact tabulated warp of the glTF
//! metallic-roughness BRDF times the cosine ([`nuld_core::brdf_prior`]) applied
//! to learned points of its primary sample space. [`Sample::pdf`] is that warp's
//! solid-angle density at the direction, [`BrdfSampler::pdf`] answers it for any
//! direction (multiple importance sampling with a light sampler), and
//! [`Sample::weight`] is `f cos / pdf` of the direction, so that
//! `(1/N) Σ L(direction_i) weight_i` estimates `∫ L f cos`: exact in expectation
//! in the **unbiased mode** ([`BrdfSampler::sample_randomized`]); in the
//! fixed-instance modes the learned points follow the pdf only approximately,
//! a small bias that shrinks with the set's discrepancy; there the estimator
//! `(A / N) Σ L(direction_i)` with the albedo [`BrdfSampler::albedo`] treats the
//! sets as following the target `f cos / A` they were trained for instead. Blobs of the earlier
//! VNDF/cosine mixture prior still load: their samples carry `pdf = 0` and the
//! albedo as the weight, and ignore the metallic.

use crate::conditional::{scaled_to_largest, ConditionalSampler, NetworkSampler, Sample};
use glam::{Vec2, Vec3};
use nuld_core::blob::BlobError;
use nuld_core::conditional::ConditionalTarget;

/// Degrees per radian in `f32`, as a shader writes the constant.
const DEGREES_PER_RADIAN: f32 = 180.0 / core::f32::consts::PI;

/// A glTF 2.0 BRDF sampler in **table mode**: for a view `wo` (local frame, `z` =
/// normal), a roughness and a metallic, the directions of a low-discrepancy set for
/// `f(l) max(0, n.l)` with their pdf and the estimator weight `f cos / pdf`, so
/// that `∫ L f cos ≈ (1 / N) Σ L(direction_i) weight_i` (module docs).
///
/// Obtained from [`crate::Blob::brdf`], which refuses any other blob; a copyable
/// view on the blob's bytes. Every method is `O(1)`, allocates nothing and never
/// panics: roughness clamps into the blob's range, metallic into `[0, 1]` (NaN
/// reads as the lower end), indices wrap modulo [`Self::len`], instances modulo
/// [`Self::instances`].
///
/// ```
/// # let bytes = nuld_runtime::doc_example_conditional_blob();
/// use nuld_runtime::glam::Vec3;
/// let brdf = nuld_runtime::Blob::parse(&bytes.0)?.brdf()?;
/// let wo = Vec3::new(0.3, 0.4, 0.866); // the view, any length
/// let (roughness, metallic, instance) = (0.4, 0.0, 17); // instance: e.g. a pixel hash
/// let mut estimate = 0.0;
/// for i in 0..brdf.len() {
///     let s = brdf.sample(wo, roughness, metallic, instance, i);
///     assert!((s.direction.length() - 1.0).abs() < 1e-5 && s.direction.z >= 0.0);
///     let radiance = 1.0; // L(s.direction) in a renderer
///     estimate += s.weight * radiance / brdf.len() as f32;
/// }
/// // Network mode: the same model evaluated per sample.
/// let s = brdf.network().sample(wo, roughness, metallic, instance, 0);
/// assert!(estimate > 0.0 && s.weight > 0.0);
/// # Ok::<(), nuld_runtime::BlobError>(())
/// ```
///
/// The view has no method that takes a surface normal: sampling an environment
/// map's way from a BRDF blob does not compile (and [`crate::Blob::envmap`] refuses
/// the blob at parse time).
///
/// ```compile_fail,E0599
/// # let bytes = nuld_runtime::doc_example_conditional_blob();
/// let brdf = nuld_runtime::Blob::parse(&bytes.0).unwrap().brdf().unwrap();
/// let s = brdf.sample_envmap(nuld_runtime::glam::Vec3::Z, 0, 0);
/// ```
#[derive(Clone, Copy, Debug)]
pub struct BrdfSampler<'a>(pub(crate) ConditionalSampler<'a>);

/// A glTF 2.0 BRDF sampler in **network mode** ([`BrdfSampler::network`],
/// [`BrdfSampler::decode_network`]): as [`BrdfSampler`], the network evaluated per
/// sample. `O(multiply_adds)`, no allocation, no panic.
#[derive(Clone, Copy, Debug)]
pub struct BrdfNetwork<'a>(pub(crate) NetworkSampler<'a>);

impl<'a> TryFrom<ConditionalSampler<'a>> for BrdfSampler<'a> {
    type Error = BlobError;

    /// The typed view of a target-agnostic sampler: [`BlobError::WrongTarget`]
    /// unless it samples [`ConditionalTarget::GltfBrdf`]. `O(1)`.
    fn try_from(sampler: ConditionalSampler<'a>) -> Result<Self, BlobError> {
        sampler.expect_target(ConditionalTarget::GltfBrdf).map(Self)
    }
}

impl<'a> BrdfSampler<'a> {
    /// Points per set `N` (at least 1); indices wrap modulo `N`.
    pub fn len(&self) -> u32 {
        self.0.len()
    }

    /// Always `false`: a parsed blob has at least one point per set.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Instances `S` stored in the table (at least 1); instances wrap modulo `S`.
    pub fn instances(&self) -> u32 {
        self.0.instances()
    }

    /// The directional albedo `A` of the dielectric (metallic 0) at view `wo` and
    /// `roughness`, interpolated on the blob's weight grid ([`Self::albedo`] at
    /// metallic 0).
    #[inline]
    pub fn weight(&self, wo: Vec3, roughness: f32) -> f32 {
        self.0.weight(view_condition(wo, roughness).0)
    }

    /// The directional albedo `A = ∫ f cos` at view `wo`, `roughness` and
    /// `metallic` ([`ConditionalSampler::albedo`]): what the weights of the
    /// unbiased mode average to, and the weight of the fixed-instance modes'
    /// second estimator, `(A / N) Σ L(direction_i)`, which treats the set as
    /// following the target `f cos / A` it was trained for (exact in a white
    /// furnace; module docs). O(1), never panics.
    #[inline]
    pub fn albedo(&self, wo: Vec3, roughness: f32, metallic: f32) -> f32 {
        self.0.albedo(view_condition(wo, roughness).0, metallic)
    }

    /// The direction of index `i` of instance `instance` for the view `wo` (local
    /// frame, `z` = normal, any length) at `roughness` and `metallic`, its pdf and
    /// weight. The set is made for the view in the xz-plane on the `+x` side; this
    /// samples it at `(roughness, theta_o, metallic)` and rotates the direction about `z` by the view's
    /// azimuth `phi = atan2(wo.y, wo.x)` (the target is isotropic), so the set
    /// follows the caller's view.
    ///
    /// `theta_o = acos(clamp(wo.z / |wo|, 0, 1))` in degrees; the rotation uses
    /// `(cos phi, sin phi) = (wo.x, wo.y) / sqrt(wo.x^2 + wo.y^2)`, no
    /// transcendental. A view below the horizon reads as grazing; a zero, infinite
    /// or NaN `wo` reads as normal incidence (`theta_o = 0`, `phi = 0`), as does
    /// `phi` for `wo` along `z`. O(1), never panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_conditional_blob();
    /// use nuld_runtime::glam::{Vec2, Vec3};
    /// let brdf = nuld_runtime::Blob::parse(&bytes.0)?.brdf()?;
    /// // A view at 60° in the yz-plane: the xz-plane set turned by 90° about z.
    /// let wo = Vec3::new(0.0, 3f32.sqrt() / 2.0, 0.5);
    /// let s = brdf.sample(wo, 0.3, 0.5, 7, 2);
    /// let t = brdf.conditional().sample_metallic(Vec2::new(0.3, 60.0), 0.5, 7, 2);
    /// let turned = Vec3::new(-t.direction.y, t.direction.x, t.direction.z);
    /// assert!((s.direction - turned).length() < 1e-5);
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    #[inline]
    pub fn sample(&self, wo: Vec3, roughness: f32, metallic: f32, instance: u32, i: u32) -> Sample {
        let (cond, azimuth) = view_condition(wo, roughness);
        rotate(self.0.sample_metallic(cond, metallic, instance, i), azimuth)
    }

    /// The unbiased mode: the blob's rank-1 lattice point `i`, shifted on the
    /// torus by the instance's offset and by a random vector drawn from `seed`
    /// (the pixel's random number,
    /// [`nuld_core::conditional::randomized_point`]), through the prior, so
    /// that each sample is distributed exactly as its [`Sample::pdf`] and
    /// `L weight` is unbiased. The learned points are not read: a random
    /// shift undoes their refinement, a lattice keeps its structure. O(1),
    /// never panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_brdf_blob();
    /// use nuld_runtime::glam::Vec3;
    /// let brdf = nuld_runtime::Blob::parse(&bytes.0)?.brdf()?;
    /// let wo = Vec3::new(0.5, -0.2, 0.8);
    /// for i in 0..brdf.len() {
    ///     // A metal of roughness 0.3; the pixel's random number 0xdead_beef.
    ///     let s = brdf.sample_randomized(wo, 0.3, 1.0, 0, i, 0xdead_beef);
    ///     // pdf 0 (and weight 0) only where a coarse table leaks below the horizon.
    ///     if s.pdf > 0.0 {
    ///         let pdf = brdf.pdf(wo, 0.3, 1.0, s.direction);
    ///         assert!((pdf - s.pdf).abs() <= 1e-3 * s.pdf && s.weight.is_finite());
    ///     }
    /// }
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    #[inline]
    pub fn sample_randomized(
        &self,
        wo: Vec3,
        roughness: f32,
        metallic: f32,
        instance: u32,
        i: u32,
        seed: u32,
    ) -> Sample {
        let (cond, azimuth) = view_condition(wo, roughness);
        let s = self
            .0
            .sample_randomized_metallic(cond, metallic, instance, i, seed);
        rotate(s, azimuth)
    }

    /// The solid-angle density of the sampler's prior at the unit `direction`
    /// (local frame) for the view `wo`, `roughness` and `metallic`:
    /// [`Sample::pdf`] of a sample there, for any direction (multiple importance
    /// sampling); 0 below the horizon, and for blobs of the mixture prior.
    /// `O(log size)`, never panics.
    #[inline]
    pub fn pdf(&self, wo: Vec3, roughness: f32, metallic: f32, direction: Vec3) -> f32 {
        let (cond, azimuth) = view_condition(wo, roughness);
        self.0
            .pdf_metallic(cond, metallic, unrotate(direction, azimuth))
    }

    /// The same model in network mode, reading the blob's f16 weights (zero-copy).
    #[inline]
    pub fn network(&self) -> BrdfNetwork<'a> {
        BrdfNetwork(self.0.network())
    }

    /// Length of the `f32` buffer [`Self::decode_network`] needs (it grows with
    /// `N` and the network's instance slots).
    pub fn decoded_network_len(&self) -> usize {
        self.0.decoded_network_len()
    }

    /// Network mode on weights decoded once into `buf` (the same bits as
    /// [`Self::network`], faster); `None` if `buf` is shorter than
    /// [`Self::decoded_network_len`]. `O(param_len)`, never panics.
    pub fn decode_network<'b>(&self, buf: &'b mut [f32]) -> Option<BrdfNetwork<'b>>
    where
        'a: 'b,
    {
        self.0.decode_network(buf).map(BrdfNetwork)
    }

    /// The target-agnostic view: conditions `(roughness, theta_o in degrees)` in
    /// the blob's units, the view in the xz-plane (what tools and tests use).
    pub fn conditional(&self) -> ConditionalSampler<'a> {
        self.0
    }
}

impl<'a> BrdfNetwork<'a> {
    /// Points per set `N` (at least 1); indices wrap modulo `N`.
    pub fn len(&self) -> u32 {
        self.0.len()
    }

    /// Always `false`: a parsed blob has at least one point per set.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The network's instance slots `M`: instance `k` is the set of slot `k mod M`
    /// (0: every `u32` instance its own set).
    pub fn instance_slots(&self) -> u32 {
        self.0.instance_slots()
    }

    /// As [`BrdfSampler::sample`], the network evaluated per sample.
    /// `O(multiply_adds)`, never panics.
    #[inline]
    pub fn sample(&self, wo: Vec3, roughness: f32, metallic: f32, instance: u32, i: u32) -> Sample {
        let (cond, azimuth) = view_condition(wo, roughness);
        rotate(self.0.sample_metallic(cond, metallic, instance, i), azimuth)
    }

    /// The unbiased mode ([`BrdfSampler::sample_randomized`], the same samples;
    /// the network is not evaluated).
    #[inline]
    pub fn sample_randomized(
        &self,
        wo: Vec3,
        roughness: f32,
        metallic: f32,
        instance: u32,
        i: u32,
        seed: u32,
    ) -> Sample {
        BrdfSampler(self.0.table()).sample_randomized(wo, roughness, metallic, instance, i, seed)
    }

    /// The prior's pdf ([`BrdfSampler::pdf`]; both modes share the prior).
    #[inline]
    pub fn pdf(&self, wo: Vec3, roughness: f32, metallic: f32, direction: Vec3) -> f32 {
        BrdfSampler(self.0.table()).pdf(wo, roughness, metallic, direction)
    }

    /// The target-agnostic network view, conditions in the blob's units.
    pub fn conditional(&self) -> NetworkSampler<'a> {
        self.0
    }
}

/// The condition `(roughness, theta_o in degrees)` of a view `wo` and its azimuth
/// as `(cos phi, sin phi)`; degenerate views read as normal incidence.
#[inline]
fn view_condition(wo: Vec3, roughness: f32) -> (Vec2, Vec2) {
    let Some(w) = scaled_to_largest(wo) else {
        return (Vec2::new(roughness, 0.0), Vec2::X);
    };
    let cos_theta = (w.z / w.length()).clamp(0.0, 1.0);
    let theta = libm::acosf(cos_theta) * DEGREES_PER_RADIAN;
    let planar = libm::sqrtf(w.x * w.x + w.y * w.y);
    let azimuth = if planar > 0.0 {
        Vec2::new(w.x / planar, w.y / planar)
    } else {
        Vec2::X
    };
    (Vec2::new(roughness, theta), azimuth)
}

/// `d` turned about `z` by minus the azimuth `(cos phi, sin phi)`: a local
/// direction in the frame of the xz-plane view.
#[inline]
fn unrotate(d: Vec3, azimuth: Vec2) -> Vec3 {
    let (c, sn) = (azimuth.x, azimuth.y);
    Vec3::new(c * d.x + sn * d.y, -sn * d.x + c * d.y, d.z)
}

/// The sample turned about `z` by the azimuth `(cos phi, sin phi)`.
#[inline]
fn rotate(s: Sample, azimuth: Vec2) -> Sample {
    let d = s.direction;
    let (c, sn) = (azimuth.x, azimuth.y);
    Sample {
        direction: Vec3::new(c * d.x - sn * d.y, sn * d.x + c * d.y, d.z),
        ..s
    }
}
