//! The conditional sampler of a [`BlobKind::Conditional`](crate::BlobKind) blob
//! (paper §4): for a condition known only at run time, an instance and an index, a
//! direction of a low-discrepancy set for the condition's target, and the
//! estimator weight.
//!
//! Everything here is `f32` arithmetic (transcendentals through `libm`), in the
//! order of operations `core/FORMAT.md` documents, so that a shader reproduces it.

use glam::{Vec2, Vec3};
use nuld_core::blob::{BlobError, Domain};
use nuld_core::brdf_prior::BrdfPrior;
use nuld_core::conditional::{
    randomized_point, unpack_point, ConditionalInfo, ConditionalTarget, GridCell, MetallicCell,
    PointWarp,
};
use nuld_core::envmap_tree::EnvmapTree;
use nuld_core::network::{interleave, F16Params, InterleavedParams, Network, Parameters, Shape};
use nuld_core::quantize::unorm16_decode;

mod network;
#[cfg(test)]
mod tests;
mod validate;

pub use network::NetworkSampler;

/// One sample: a unit direction, the estimator weight of every sample of its
/// condition (for BRDF samplers the directional albedo `A`, so that
/// `∫ L f cos ≈ (A / N) Σ L(direction_i)`; for environment samplers the
/// irradiance `E(n)`, so that `∫ L f cos ≈ (E / N) Σ f(direction_i)`), and the
/// solid-angle density of the sampler's prior warp at the direction.
///
/// **`pdf`** (per steradian) is the density the *unbiased mode*
/// ([`ConditionalSampler::sample_randomized`]) draws each sample from, exactly:
/// with it `(1/N) Σ g(direction_i) / pdf_i` is an unbiased estimate of `∫ g` for
/// any `g`, and it is what multiple importance sampling weighs with
/// ([`ConditionalSampler::pdf`] answers it for any direction). Environment samplers
/// ([`nuld_core::conditional::PointWarp::EnvmapTree`]) return the exact pdf of their
/// prior, the map's light times the cosine; BRDF samplers on the tabulated prior
/// ([`nuld_core::conditional::PointWarp::BrdfTable`]) the exact pdf of their prior,
/// the BRDF times the cosine, and the weight `f cos / pdf` of the direction; BRDF
/// blobs of the earlier mixture prior return 0: use their `weight`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// A unit vector (`z >= 0` on the hemisphere), in the local frame (`z` = normal).
    pub direction: Vec3,
    /// The estimator weight, finite and `>= 0`.
    pub weight: f32,
    /// The prior's solid-angle density at `direction`, finite and `>= 0` (0 for
    /// a sampler without an exact prior).
    pub pdf: f32,
}

/// A conditional sampler in **table mode** ([`Self::sample`]: stored square points
/// interpolated between the four grid conditions around the condition), with
/// conditions in the blob's units, whatever its target; [`Self::network`] is the
/// same trained model in **network mode** (the f16 network evaluated per sample).
/// Renderers use the typed views instead, [`crate::BrdfSampler`] and
/// [`crate::EnvmapSampler`], which take a view direction or a normal.
///
/// Obtained from [`crate::Blob::conditional`]; a copyable view on the blob's bytes.
/// Every method is `O(1)` in the number of points (network mode costs
/// [`Shape::multiply_adds`] multiply-adds), allocates nothing, and never panics:
/// conditions are clamped into the blob's range (NaN reads as the lower end),
/// indices wrap modulo [`Self::len`], table-mode instances modulo
/// [`Self::instances`].
#[derive(Clone, Copy, Debug)]
pub struct ConditionalSampler<'a> {
    info: ConditionalInfo,
    shape: Shape,
    domain: Domain,
    target: ConditionalTarget,
    warp: PointWarp,
    params: NetworkParams<'a>,
    table: &'a [u32],
    weights: &'a [f32],
    /// The environment prior ([`PointWarp::EnvmapTree`] samplers).
    tree: Option<EnvmapTree<'a>>,
    /// The BRDF prior ([`PointWarp::BrdfTable`] samplers).
    brdf_prior: Option<BrdfPrior<'a, f32>>,
    /// The metal layer's own network and point table (BRDF samplers whose
    /// prior has the metal layer, baked with them), read at metallic 1.
    metal: Option<MetalPoints<'a>>,
    /// The metallic axis of the network and the point table
    /// ([`nuld_core::conditional::metallic_axis`]); empty without one (and in
    /// the metal layer's view, [`Self::at_metallic`]).
    metallic_nodes: &'a [f32],
}

/// The learned part of a BRDF prior's metal layer
/// ([`nuld_core::blob::SectionTag::MetalNetworkParams`] and
/// [`nuld_core::blob::SectionTag::MetalPointTable`]): the same shape and
/// layout as the sampler's own network and point table.
#[derive(Clone, Copy, Debug)]
struct MetalPoints<'a> {
    params: NetworkParams<'a>,
    table: &'a [u32],
}

/// Where network mode reads its parameters: the blob's f16 bits (zero-copy), or
/// the caller's buffer holding them decoded ([`ConditionalSampler::decode_network`]).
#[derive(Clone, Copy, Debug)]
enum NetworkParams<'a> {
    F16(&'a [u16]),
    /// Decoded and interleaved ([`nuld_core::network::interleave`]).
    F32(&'a [f32]),
}

/// Square point used if a table lookup ever missed (it cannot in a parsed blob).
const CENTRE_CODE: u16 = 1 << 15;

impl<'a> ConditionalSampler<'a> {
    /// Points per set `n` (at least 1); indices wrap modulo `n`.
    pub fn len(&self) -> u32 {
        self.info.n
    }

    /// Always `false`: a parsed blob has at least one point per set.
    pub fn is_empty(&self) -> bool {
        self.info.n == 0
    }

    /// Instances `S` stored in the point table (at least 1); table mode wraps the
    /// instance modulo `S`, network mode modulo [`Self::instance_slots`].
    pub fn instances(&self) -> u32 {
        self.info.instances
    }

    /// The network's instance slots `M`: network mode serves `M` different sets
    /// per condition and wraps the instance modulo `M`; 0 means every `u32`
    /// instance is its own set (`nuld_core::network::Shape::with_instance_slots`).
    pub fn instance_slots(&self) -> u32 {
        self.info.instance_slots
    }

    /// The blob's info record: grids, condition ranges (blob units; for
    /// [`ConditionalTarget::GltfBrdf`] roughness and `theta_o` in degrees), network
    /// architecture.
    pub fn info(&self) -> &ConditionalInfo {
        &self.info
    }

    /// The network architecture of network mode.
    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// Where the directions live: [`Domain::Hemisphere`] or [`Domain::Sphere`].
    pub fn domain(&self) -> Domain {
        self.domain
    }

    /// What the condition means ([`ConditionalTarget`]).
    pub fn target(&self) -> ConditionalTarget {
        self.target
    }

    /// The sampler, if it samples `expected`; else [`BlobError::WrongTarget`]
    /// (the check of every typed view). `O(1)`.
    pub(crate) fn expect_target(self, expected: ConditionalTarget) -> Result<Self, BlobError> {
        match self.target() {
            found if found == expected => Ok(self),
            found => Err(BlobError::WrongTarget { expected, found }),
        }
    }

    /// The estimator weight at condition `cond` (blob units): the weight table
    /// interpolated bilinearly ([`GridCell::lerp`]) on the weight grid at
    /// `info().normalize(cond)`. Finite and `>= 0`. O(1), never panics.
    #[inline]
    pub fn weight(&self, cond: Vec2) -> f32 {
        self.weight_table_lerp(&self.weight_cell(cond), 0)
    }

    /// The weight-grid cell of `cond` (blob units, clamped like [`Self::weight`]).
    #[inline]
    fn weight_cell(&self, cond: Vec2) -> GridCell {
        self.weight_cell_at(self.info.normalize(cond.to_array()))
    }

    /// The weight-grid cell of the normalized condition `u`.
    #[inline]
    fn weight_cell_at(&self, u: [f32; 2]) -> GridCell {
        GridCell::locate(u, self.info.weight_grid)
    }

    /// Table `table` of the weight section (0: weights, 1: lobe probabilities)
    /// interpolated bilinearly in `cell`.
    #[inline]
    fn weight_table_lerp(&self, cell: &GridCell, table: usize) -> f32 {
        let base = table * self.info.weight_table_len() as usize;
        let w = |dx, dy| {
            let at = base + cell.node(dx, dy);
            self.weights.get(at).copied().unwrap_or(0.0)
        };
        cell.lerp(w(0, 0), w(1, 0), w(0, 1), w(1, 1))
    }

    /// The lobe probability `p_s` of a [`PointWarp::BrdfMixture`] sampler at
    /// `cond`: the second table of the weight section, interpolated as the weights.
    #[inline]
    pub fn lobe_probability(&self, cond: Vec2) -> f32 {
        self.weight_table_lerp(&self.weight_cell(cond), 1)
    }

    /// The directional albedo at `cond` of a BRDF of metallic `metallic`
    /// (clamped into `[0, 1]`, NaN as 0): for a [`PointWarp::BrdfTable`] sampler
    /// `(1 - m) A_0 + m A_1`, the weight section's two tables (the dielectric's
    /// and the metal's albedo) interpolated as the weights, exact in `m` since
    /// the BRDF is linear in it; for every other sampler [`Self::weight`].
    /// Finite and `>= 0`. O(1), never panics.
    #[inline]
    pub fn albedo(&self, cond: Vec2, metallic: f32) -> f32 {
        let cell = self.weight_cell(cond);
        let dielectric = self.weight_table_lerp(&cell, 0);
        if self.warp != PointWarp::BrdfTable {
            return dielectric;
        }
        let m = nuld_core::brdf::clamp_metallic(metallic);
        (1.0 - m) * dielectric + m * self.weight_table_lerp(&cell, 1)
    }

    /// Table mode's point of the unit square for index `i` (mod `n`) of instance
    /// `instance` (mod `S`) at condition `cond` (blob units): with
    /// `u = info().normalize(cond)` and the point-table cell
    /// `GridCell::locate(u, grid)`, the four stored u16 codes of the cell's corners
    /// decoded by `(q + 0.5) / 65536` and interpolated bilinearly
    /// ([`GridCell::lerp`]), x and y separately. In `(0,1)^2`. O(1), never panics.
    /// With a metallic axis ([`Self::metallic_nodes`]) this reads metallic 0
    /// ([`Self::square_point_metallic`] for others).
    #[inline]
    pub fn square_point(&self, cond: Vec2, instance: u32, i: u32) -> Vec2 {
        self.square_point_metallic(cond, 0.0, instance, i)
    }

    /// [`Self::square_point`] for a BRDF query at `metallic`: the metal layer's
    /// own point table where the query reads it ([`Self::has_metal_points`],
    /// metallic 1); else, with a metallic axis, the bilinear points of the two
    /// layers around `metallic` blended by [`MetallicCell::lerp`] (x and y
    /// separately); else the same. What [`Self::sample_metallic`] warps.
    /// O(1), never panics.
    #[inline]
    pub fn square_point_metallic(&self, cond: Vec2, metallic: f32, instance: u32, i: u32) -> Vec2 {
        let u = self.info.normalize(cond.to_array());
        self.at_metallic(metallic)
            .square_point_at(u, metallic, instance, i)
    }

    /// The metallic nodes of the network's input and the point table's layers
    /// ([`nuld_core::conditional::metallic_axis`]; empty without an axis).
    pub fn metallic_nodes(&self) -> &'a [f32] {
        self.metallic_nodes
    }

    /// [`Self::square_point`] at the normalized condition `u` and `metallic`
    /// (read only through a metallic axis).
    #[inline]
    fn square_point_at(&self, u: [f32; 2], metallic: f32, instance: u32, i: u32) -> Vec2 {
        if self.metallic_nodes.is_empty() {
            return self.layer_point(u, 0, instance, i);
        }
        let m = MetallicCell::locate(self.metallic_nodes, metallic);
        if m.t == 0.0 {
            // At a node (metallic 0, the common material): `a + (b - a) 0` is
            // `a` bit for bit (stored points are positive and finite), so the
            // second layer is not read.
            return self.layer_point(u, m.j0, instance, i);
        }
        let (a, b) = (
            self.layer_point(u, m.j0, instance, i),
            self.layer_point(u, m.j0 + 1, instance, i),
        );
        Vec2::new(m.lerp(a.x, b.x), m.lerp(a.y, b.y))
    }

    /// Layer `layer`'s point (0 without a metallic axis), interpolated
    /// bilinearly in the condition.
    #[inline]
    fn layer_point(&self, u: [f32; 2], layer: u32, instance: u32, i: u32) -> Vec2 {
        let (cell, corner) = self.table_corners(u, layer, instance, i);
        let (p00, p10, p01, p11) = (corner(0, 0), corner(1, 0), corner(0, 1), corner(1, 1));
        let axis = |a: usize| cell.lerp(p00[a], p10[a], p01[a], p11[a]);
        Vec2::new(axis(0), axis(1))
    }

    /// The point-table cell of the normalized condition `u` and the stored square
    /// point of its corner `(dx, dy)` in layer `layer` (of a metallic axis; 0
    /// without) for index `i` (mod `n`) of instance `instance` (mod `S`),
    /// decoded by `(q + 0.5) / 65536`: what both table modes interpolate.
    #[inline]
    fn table_corners(
        &self,
        u: [f32; 2],
        layer: u32,
        instance: u32,
        i: u32,
    ) -> (GridCell, impl Fn(u32, u32) -> [f32; 2] + '_) {
        let info = &self.info;
        let cell = GridCell::locate(u, info.grid);
        let k = instance.checked_rem(info.instances).unwrap_or(0);
        let j = i.checked_rem(info.n).unwrap_or(0);
        // In range for every parsed blob, whose table holds every layer;
        // saturating, so that no product can panic.
        let layer_nodes = (info.grid[0] as usize).saturating_mul(info.grid[1] as usize);
        let layer_base = (layer as usize).saturating_mul(layer_nodes);
        let corner = move |dx, dy| {
            let at = info.point_table_index(layer_base.saturating_add(cell.node(dx, dy)), k, j);
            let q = self
                .table
                .get(at)
                .map_or([CENTRE_CODE; 2], |&w| unpack_point(w));
            [unorm16_decode(q[0]), unorm16_decode(q[1])]
        };
        (cell, corner)
    }

    /// [`NetworkSampler::square_point`] at the normalized condition `u` and
    /// `metallic` (read only by a network with [`Shape::metallic_input`]).
    #[inline]
    pub(crate) fn network_square_point_at(
        &self,
        u: [f32; 2],
        metallic: f32,
        instance: u32,
        i: u32,
    ) -> Vec2 {
        let shape = self.shape;
        Vec2::from_array(match self.params {
            // Every index below `param_len` exists and is finite (`validate`).
            NetworkParams::F16(params) => Network {
                shape,
                params: F16Params(params),
            }
            .square_point_at(u, metallic, instance, i),
            NetworkParams::F32(params) => Network {
                shape,
                params: InterleavedParams::new(shape, params),
            }
            .square_point_at(u, metallic, instance, i),
        })
    }

    /// The same trained model in network mode, reading the blob's f16 parameters
    /// (zero-copy). `O(1)`, never panics.
    #[inline]
    pub fn network(&self) -> NetworkSampler<'a> {
        NetworkSampler(*self)
    }

    /// Whether the blob holds the metal layer's own learned points, which a BRDF
    /// query at metallic 1 reads instead of the shared ones (both modes): a
    /// BRDF sampler baked on a prior with the metal layer.
    pub fn has_metal_points(&self) -> bool {
        self.metal.is_some()
    }

    /// The sampler whose network and point table serve a query at `metallic`:
    /// the metal layer's ([`Self::has_metal_points`]) where the query reads the
    /// prior's metal layer ([`nuld_core::brdf_prior::reads_metal_layer`]:
    /// metallic 1, clamped), else this one. `O(1)`.
    #[inline]
    pub(crate) fn at_metallic(&self, metallic: f32) -> Self {
        match (&self.metal, &self.brdf_prior) {
            (Some(m), Some(prior))
                if nuld_core::brdf_prior::reads_metal_layer(prior.grid(), metallic) =>
            {
                Self {
                    params: m.params,
                    table: m.table,
                    // The metal layer's network and table have no metallic axis.
                    shape: self.shape.with_metallic_input(false),
                    metallic_nodes: &[],
                    ..*self
                }
            }
            _ => *self,
        }
    }

    /// Length of the `f32` buffer [`Self::decode_network`] needs:
    /// [`Shape::param_len`], 4 bytes per parameter, twice with the metal
    /// layer's network ([`Self::has_metal_points`]).
    pub fn decoded_network_len(&self) -> usize {
        let networks = if self.metal.is_some() { 2 } else { 1 };
        self.shape.param_len() * networks
    }

    /// [`Self::network`] reading the network's parameters decoded to `f32` into
    /// `buf` (its first [`Self::decoded_network_len`] entries), instead of decoding
    /// each f16 on every sample. The decode is exact, so every method returns the
    /// same bits as on [`Self::network`], faster (the f16 decode is most of network
    /// mode's cost on a CPU without a half-float unit; `build-tool bench --only
    /// runtime` times both). Decode once per blob, as a renderer uploads tables
    /// once; size `buf` by [`Self::decoded_network_len`] (it grows with `n` and the
    /// instance slots). `None` if `buf` is shorter; `O(param_len)`, never panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_conditional_blob();
    /// use nuld_runtime::glam::Vec2;
    /// let cs = nuld_runtime::Blob::parse(&bytes.0)?.conditional()?;
    /// let mut buf = vec![0.0f32; cs.decoded_network_len()];
    /// let fast = cs.decode_network(&mut buf).expect("a long enough buffer");
    /// let c = Vec2::new(0.5, 30.0);
    /// assert_eq!(fast.sample(c, 9, 2), cs.network().sample(c, 9, 2));
    /// assert!(cs.decode_network(&mut [0.0; 1]).is_none());
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    pub fn decode_network<'b>(&self, buf: &'b mut [f32]) -> Option<NetworkSampler<'b>>
    where
        'a: 'b,
    {
        let len = self.shape.param_len();
        let out = buf.get_mut(..self.decoded_network_len())?;
        let (shared, metal_out) = out.split_at_mut(len);
        decode_params(self.params, &self.shape, shared)?;
        let metal = match self.metal {
            Some(m) => {
                decode_params(m.params, &self.shape, metal_out)?;
                Some(MetalPoints {
                    params: NetworkParams::F32(metal_out),
                    table: m.table,
                })
            }
            None => None,
        };
        Some(NetworkSampler(ConditionalSampler {
            params: NetworkParams::F32(shared),
            metal,
            ..*self
        }))
    }

    /// Table mode: the direction of index `i` of instance `instance` at condition
    /// `cond` (blob units; for BRDF samplers `(roughness, theta_o in degrees)`, the
    /// view in the xz-plane on the `+x` side): [`Self::square_point`] through the
    /// domain's equal-area map in `f32` ([`Domain::to_direction_real`]), with
    /// [`Self::weight`]. Instances wrap modulo [`Self::instances`], indices modulo
    /// [`Self::len`], conditions clamp (NaN to the range's lower end). O(1), never
    /// panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_conditional_blob();
    /// use nuld_runtime::glam::Vec2;
    /// let cs = nuld_runtime::Blob::parse(&bytes.0)?.conditional()?;
    /// let c = Vec2::new(0.5, 30.0);
    /// assert_eq!(cs.sample(c, 0, 1), cs.sample(c, cs.instances(), 1 + cs.len()));
    /// assert_eq!(cs.sample(Vec2::new(f32::NAN, -5.0), 0, 0), cs.sample(cs.info().cond_min.into(), 0, 0));
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    #[inline]
    pub fn sample(&self, cond: Vec2, instance: u32, i: u32) -> Sample {
        self.sample_metallic(cond, 0.0, instance, i)
    }

    /// [`Self::sample`] for a BRDF of metallic `metallic` (clamped into `[0,1]`,
    /// NaN as 0): read by [`PointWarp::BrdfTable`] samplers' prior, ignored by
    /// every other warp; at metallic 1 the point comes from the metal layer's
    /// own table where the blob has one ([`Self::square_point_metallic`]).
    /// O(1), never panics.
    #[inline]
    pub fn sample_metallic(&self, cond: Vec2, metallic: f32, instance: u32, i: u32) -> Sample {
        let u = self.info.normalize(cond.to_array());
        let points = self.at_metallic(metallic);
        self.mapped(
            points.square_point_at(u, metallic, instance, i),
            u,
            metallic,
        )
    }

    /// The **unbiased mode**: point `i` (mod `n`) of the blob's rank-1 lattice,
    /// shifted on the unit torus by instance `instance`'s offset and by
    /// [`nuld_core::conditional::randomization_shift`]`(seed)`
    /// ([`nuld_core::conditional::randomized_point`]), through the prior's warp,
    /// so that for a random `seed` (one per pixel) every sample is distributed
    /// exactly as its [`Sample::pdf`]. The table's learned points are not read:
    /// a random shift undoes their refinement, while a lattice keeps its
    /// structure under any shift (measured in the crate's docs/results). The
    /// same samples as [`NetworkSampler::sample_randomized`]. O(1), never panics.
    #[inline]
    pub fn sample_randomized(&self, cond: Vec2, instance: u32, i: u32, seed: u32) -> Sample {
        self.sample_randomized_metallic(cond, 0.0, instance, i, seed)
    }

    /// [`Self::sample_randomized`] for a BRDF of metallic `metallic`
    /// ([`Self::sample_metallic`]).
    #[inline]
    pub fn sample_randomized_metallic(
        &self,
        cond: Vec2,
        metallic: f32,
        instance: u32,
        i: u32,
        seed: u32,
    ) -> Sample {
        let u = self.info.normalize(cond.to_array());
        self.randomized(u, metallic, instance, i, seed)
    }

    /// The unbiased mode's sample at the normalized condition `u`: the
    /// [`randomized_point`] of the blob's lattice, then [`Self::mapped`] (both
    /// modes').
    #[inline]
    pub(crate) fn randomized(
        &self,
        u: [f32; 2],
        metallic: f32,
        instance: u32,
        i: u32,
        seed: u32,
    ) -> Sample {
        let (n, g) = (self.info.n, self.info.lattice_generator);
        let p = randomized_point(n, g, instance, i, seed);
        self.mapped(Vec2::from_array(p), u, metallic)
    }

    /// The solid-angle density at the unit `direction` of the sampler's prior at
    /// `cond` (blob units): what [`Sample::pdf`] returns for a sample there, for
    /// any direction (multiple importance sampling). For environment samplers the
    /// tree's exact pdf ([`EnvmapTree::pdf_square`]) at the normal whose
    /// octahedral square point is the clamped condition; for BRDF samplers on the
    /// tabulated prior the prior's exact pdf at metallic 0 ([`Self::pdf_metallic`]
    /// for others); 0 for samplers without an exact prior. O(tree levels),
    /// never panics.
    #[inline]
    pub fn pdf(&self, cond: Vec2, direction: Vec3) -> f32 {
        self.pdf_metallic(cond, 0.0, direction)
    }

    /// [`Self::pdf`] for a BRDF of metallic `metallic` ([`Self::sample_metallic`]).
    #[inline]
    pub fn pdf_metallic(&self, cond: Vec2, metallic: f32, direction: Vec3) -> f32 {
        let u = self.info.normalize(cond.to_array());
        let c = self.info.denormalize(u);
        match (self.warp, &self.tree, &self.brdf_prior) {
            (PointWarp::EnvmapTree, Some(tree), _) => tree.pdf_square(c, direction.to_array()),
            (PointWarp::BrdfTable, _, Some(prior)) => {
                prior.pdf([c[0], c[1], metallic], direction.to_array())
            }
            _ => 0.0,
        }
    }

    /// The sample of point `p` at the normalized condition `u`: the direction of
    /// [`PointWarp::direction`] (with the prior's pdf for the tree), the weight of
    /// [`Self::weight`]; one weight-grid cell serves the weight and the lobe
    /// probability.
    #[inline]
    pub(crate) fn mapped(&self, p: Vec2, u: [f32; 2], metallic: f32) -> Sample {
        if let (PointWarp::BrdfTable, Some(prior)) = (self.warp, &self.brdf_prior) {
            // The clamped condition in blob units, as the prior's nodes see it.
            let [roughness, theta] = self.info.denormalize(u);
            let cond = [roughness, theta, metallic];
            let (direction, pdf, weight) = prior.sample_weighted(cond, p.to_array());
            return Sample {
                direction: Vec3::from_array(direction),
                weight,
                pdf,
            };
        }
        let cell = self.weight_cell_at(u);
        if let (PointWarp::EnvmapTree, Some(tree)) = (self.warp, &self.tree) {
            // The clamped condition is the normal's octahedral square point.
            let (direction, pdf) = tree.sample_square(self.info.denormalize(u), p.to_array());
            return Sample {
                direction: Vec3::from_array(direction),
                weight: self.weight_table_lerp(&cell, 0),
                pdf,
            };
        }
        // Only the mixture warp reads the condition and `p_s`; the equal-area map
        // skips their lookups.
        let (cond, p_s) = match self.warp {
            PointWarp::BrdfMixture => {
                // The clamped condition in blob units, as the tables see it.
                (self.info.denormalize(u), self.weight_table_lerp(&cell, 1))
            }
            _ => ([0.0; 2], 0.0),
        };
        let direction = self
            .warp
            .direction(self.domain, cond, p_s, None, p.to_array());
        Sample {
            direction: Vec3::from_array(direction),
            weight: self.weight_table_lerp(&cell, 0),
            pdf: 0.0,
        }
    }
}

/// Decodes `params` (the blob's f16 bits, or a buffer decoded before) into
/// `out`, which must be exactly as long (`None` otherwise), in the layout that
/// the CPU's forward pass reads fastest ([`InterleavedParams`]; a decoded
/// buffer holds it already).
fn decode_params(params: NetworkParams<'_>, shape: &Shape, out: &mut [f32]) -> Option<()> {
    match params {
        NetworkParams::F16(params) => {
            if params.len() != out.len() {
                return None;
            }
            F16Params(params).read(0, out);
            interleave(shape, out)?;
        }
        NetworkParams::F32(params) => out.copy_from_slice(params.get(..out.len())?),
    }
    Some(())
}

/// `v` divided by its largest absolute component, or `None` for a zero, infinite
/// or NaN `v`. Scaling first keeps `|v|` finite for huge inputs and away from
/// underflow for tiny ones.
#[inline]
pub(crate) fn scaled_to_largest(v: Vec3) -> Option<Vec3> {
    let m = v.abs().max_element();
    (v.is_finite() && m > 0.0).then(|| v / m)
}
