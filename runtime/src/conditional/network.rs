//! Network mode: the trained model evaluated per sample, a view of its own so that
//! a renderer picks the mode once, where it picks the sampler.

use super::{ConditionalSampler, Sample};
use glam::Vec2;

/// A conditional sampler in **network mode**, conditions in the blob's units: the
/// f16 network of `nuld_core::network` evaluated per sample, read from the blob
/// (zero-copy, [`ConditionalSampler::network`]) or from the caller's buffer of
/// decoded weights ([`ConditionalSampler::decode_network`], the same bits, faster).
///
/// Every method costs [`nuld_core::network::Shape::multiply_adds`] multiply-adds,
/// allocates nothing and never panics: conditions clamp into the blob's range (NaN
/// reads as the lower end), indices wrap modulo [`Self::len`]. With
/// [`Self::instance_slots`] `M >= 1` instance `k` is the set of slot `k mod M`;
/// with none, every `u32` instance is a different set (its offset hashed from it).
#[derive(Clone, Copy, Debug)]
pub struct NetworkSampler<'a>(pub(super) ConditionalSampler<'a>);

impl<'a> NetworkSampler<'a> {
    /// Points per set `n` (at least 1); indices wrap modulo `n`.
    pub fn len(&self) -> u32 {
        self.0.len()
    }

    /// Always `false`: a parsed blob has at least one point per set.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The network's instance slots `M` (0: every `u32` instance its own set).
    pub fn instance_slots(&self) -> u32 {
        self.0.instance_slots()
    }

    /// The same model in table mode (and the blob's info, shape and weights).
    pub fn table(&self) -> ConditionalSampler<'a> {
        self.0
    }

    /// The point of the unit square for index `i` (mod `n`) of instance `instance`
    /// at condition `cond` (blob units): the network on
    /// `input_features(u, 0, instance, i)` (metallic 0) with
    /// `u = info().normalize(cond)`, its f16 parameters decoded exactly to
    /// `f32`, then `sigmoid` per output. In `[0,1]^2`.
    #[inline]
    pub fn square_point(&self, cond: Vec2, instance: u32, i: u32) -> Vec2 {
        self.square_point_metallic(cond, 0.0, instance, i)
    }

    /// [`Self::square_point`] for a BRDF query at `metallic`: the metal layer's
    /// own network where the query reads it
    /// ([`ConditionalSampler::has_metal_points`], metallic 1); else the network
    /// with `metallic` as its third condition feature where it reads one
    /// ([`ConditionalSampler::metallic_nodes`]); else the same. What
    /// [`Self::sample_metallic`] warps.
    #[inline]
    pub fn square_point_metallic(&self, cond: Vec2, metallic: f32, instance: u32, i: u32) -> Vec2 {
        let u = self.0.info().normalize(cond.to_array());
        self.0
            .at_metallic(metallic)
            .network_square_point_at(u, metallic, instance, i)
    }

    /// The direction of index `i` of instance `instance` at condition `cond` (blob
    /// units): [`Self::square_point`] through the target's warp, with the weight of
    /// [`ConditionalSampler::weight`] (as [`ConditionalSampler::sample`] does for
    /// table mode).
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_conditional_blob();
    /// use nuld_runtime::glam::Vec2;
    /// let net = nuld_runtime::Blob::parse(&bytes.0)?.conditional()?.network();
    /// let s = net.sample(Vec2::new(0.5, 30.0), 123_456, 1);
    /// assert!((s.direction.length() - 1.0).abs() < 1e-5 && s.weight > 0.0);
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    #[inline]
    pub fn sample(&self, cond: Vec2, instance: u32, i: u32) -> Sample {
        self.sample_metallic(cond, 0.0, instance, i)
    }

    /// [`Self::sample`] for a BRDF of metallic `metallic`
    /// ([`ConditionalSampler::sample_metallic`]; at metallic 1 the metal layer's
    /// own network where the blob has one, [`Self::square_point_metallic`]).
    #[inline]
    pub fn sample_metallic(&self, cond: Vec2, metallic: f32, instance: u32, i: u32) -> Sample {
        let u = self.0.info().normalize(cond.to_array());
        let points = self.0.at_metallic(metallic);
        let p = points.network_square_point_at(u, metallic, instance, i);
        self.0.mapped(p, u, metallic)
    }

    /// The unbiased mode, the same samples as
    /// [`ConditionalSampler::sample_randomized`] (a randomly shifted lattice
    /// through the prior; the network is not evaluated).
    #[inline]
    pub fn sample_randomized(&self, cond: Vec2, instance: u32, i: u32, seed: u32) -> Sample {
        self.sample_randomized_metallic(cond, 0.0, instance, i, seed)
    }

    /// [`Self::sample_randomized`] for a BRDF of metallic `metallic`.
    #[inline]
    pub fn sample_randomized_metallic(
        &self,
        cond: Vec2,
        metallic: f32,
        instance: u32,
        i: u32,
        seed: u32,
    ) -> Sample {
        self.0
            .sample_randomized_metallic(cond, metallic, instance, i, seed)
    }

    /// The prior's pdf at `direction` ([`ConditionalSampler::pdf`]; the same
    /// prior serves both modes).
    #[inline]
    pub fn pdf(&self, cond: Vec2, direction: glam::Vec3) -> f32 {
        self.0.pdf(cond, direction)
    }

    /// [`Self::pdf`] for a BRDF of metallic `metallic`.
    #[inline]
    pub fn pdf_metallic(&self, cond: Vec2, metallic: f32, direction: glam::Vec3) -> f32 {
        self.0.pdf_metallic(cond, metallic, direction)
    }
}
