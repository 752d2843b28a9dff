//! The conditional sampler of a [`BlobKind::Conditional`](crate::BlobKind) blob
//! (paper §4): for a condition known only at run time, an instance and an index, a
//! direction of a low-discrepancy set for the condition's target, and the
//! estimator weight.
//!
//! Everything here is `f32` arithmetic (transcendentals through `libm`), in the
//! order of operations `core/FORMAT.md` documents, so that a shader reproduces it.

use glam::{Vec2, Vec3};
use nuld_core::blob::{BlobError, Domain, Layout, SectionTag};
use nuld_core::conditional::{
    unpack_point, ConditionalInfo, ConditionalTarget, GridCell, PointWarp, CONDITIONAL_INFO_LEN,
};
use nuld_core::network::{input_features, Activation, F16Params, Network, Parameters, Shape};
use nuld_core::quantize::{f16_is_finite, unorm16_decode};

/// One sample: a unit direction and the estimator weight of every sample of its
/// condition (for BRDF samplers the directional albedo `A`, so that
/// `∫ L f cos ≈ (A / N) Σ L(direction_i)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// A unit vector (`z >= 0` on the hemisphere), in the local frame (`z` = normal).
    pub direction: Vec3,
    /// The estimator weight, finite and `>= 0`.
    pub weight: f32,
}

/// A conditional sampler served two ways from one trained model: **table mode**
/// ([`Self::sample`]: stored square points interpolated between the four grid
/// conditions around the condition) and **network mode** ([`Self::sample_network`]:
/// the f16 network evaluated per sample).
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
}

/// Where network mode reads its parameters: the blob's f16 bits (zero-copy), or
/// the caller's buffer holding them decoded ([`ConditionalSampler::decode_network`]).
#[derive(Clone, Copy, Debug)]
enum NetworkParams<'a> {
    F16(&'a [u16]),
    F32(&'a [f32]),
}

/// Square point used if a table lookup ever missed (it cannot in a parsed blob).
const CENTRE_CODE: u16 = 1 << 15;

/// Degrees per radian in `f32`, as a shader writes the constant.
const DEGREES_PER_RADIAN: f32 = 180.0 / core::f32::consts::PI;

impl<'a> ConditionalSampler<'a> {
    /// Validates the four sections of a conditional blob against each other (the
    /// checks of `core/FORMAT.md`, one [`BlobError`] variant each) and returns the
    /// sampler. Called by [`crate::Blob::parse`], so every sampler holds:
    /// `n, instances >= 1`; a sphere or hemisphere domain; a known target; grids of
    /// at least 2 x 2 nodes; finite condition ranges with `min < max`; a valid
    /// network shape; exactly `param_len` finite f16 parameters,
    /// `grid[0] grid[1] instances n` table entries, and `weight_grid[0]
    /// weight_grid[1]` finite, non-negative weights.
    pub(crate) fn validate(layout: &Layout<'a>) -> Result<Self, BlobError> {
        let sampler = Self::view(layout)?;
        sampler.check_values()?;
        Ok(sampler)
    }

    /// The sampler over a layout whose values [`Self::validate`] has checked once:
    /// re-checks the counts and section sizes (`O(1)`), not every value.
    pub(crate) fn view(layout: &Layout<'a>) -> Result<Self, BlobError> {
        let (_, info_bytes) = layout.section(SectionTag::ConditionalInfo)?;
        if info_bytes.len() != CONDITIONAL_INFO_LEN {
            return Err(BlobError::ConditionalInfoSize {
                got: info_bytes.len() as u64,
                expected: CONDITIONAL_INFO_LEN as u64,
            });
        }
        let info: ConditionalInfo = bytemuck::pod_read_unaligned(info_bytes);
        if info.n == 0 {
            return Err(BlobError::ConditionalNoPoints);
        }
        if info.instances == 0 {
            return Err(BlobError::ConditionalNoInstances);
        }
        let domain = match Domain::from_code(info.domain) {
            Some(d @ (Domain::Sphere | Domain::Hemisphere)) => d,
            _ => return Err(BlobError::ConditionalDomain(info.domain)),
        };
        let Some(target) = ConditionalTarget::from_code(info.target) else {
            return Err(BlobError::UnknownConditionalTarget(info.target));
        };
        if domain != target.domain() {
            return Err(BlobError::ConditionalDomain(info.domain));
        }
        let warp = match info.point_warp() {
            Some(PointWarp::BrdfMixture)
                if !(target == ConditionalTarget::GltfBrdf && domain == Domain::Hemisphere) =>
            {
                return Err(BlobError::UnknownPointWarp(info.warp))
            }
            Some(w) => w,
            None => return Err(BlobError::UnknownPointWarp(info.warp)),
        };
        type GridError = fn(u32, u32) -> BlobError;
        let grids: [([u32; 2], GridError); 2] = [
            (info.grid, |axis, nodes| BlobError::ConditionalGrid {
                axis,
                nodes,
            }),
            (info.weight_grid, |axis, nodes| {
                BlobError::ConditionalWeightGrid { axis, nodes }
            }),
        ];
        for (grid, error) in grids {
            for (axis, &nodes) in (0u32..).zip(&grid) {
                if nodes < 2 {
                    return Err(error(axis, nodes));
                }
            }
        }
        for axis in 0..2 {
            let (lo, hi) = (info.cond_min[axis], info.cond_max[axis]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(BlobError::ConditionalRange {
                    axis: axis as u32,
                    min_bits: lo.to_bits(),
                    max_bits: hi.to_bits(),
                });
            }
        }
        if Activation::from_code(info.activation).is_none() {
            return Err(BlobError::UnknownActivation(info.activation));
        }
        let shape = info
            .shape_without_slots()
            .ok_or(BlobError::NetworkWidths(info.hidden))?
            .with_instance_slots(info.instance_slots)
            .ok_or(BlobError::InstanceSlots(info.instance_slots))?;
        if info.reserved != 0 {
            return Err(BlobError::ConditionalReserved(info.reserved));
        }

        let params: &[u16] = typed_section(
            layout,
            SectionTag::NetworkParams,
            BlobError::ParamElementSize,
            || {
                // The embedding `max(M, 1) n h1` is below 2^32 (checked by
                // `with_instance_slots`), so it fits a 32-bit `usize`; the sum is
                // taken in u64, where `param_len` could overflow one.
                Ok(shape.first_layer_offset() as u64 + shape.multiply_adds() as u64)
            },
            |expected, got| BlobError::ParamsLength { expected, got },
        )?;
        let table: &[u32] = typed_section(
            layout,
            SectionTag::PointTable,
            BlobError::PointTableElementSize,
            || {
                info.point_table_len()
                    .ok_or(BlobError::PointTableCountOverflow)
            },
            |expected, got| BlobError::PointTableLength { expected, got },
        )?;
        let weights: &[f32] = typed_section(
            layout,
            SectionTag::WeightTable,
            BlobError::WeightElementSize,
            // Saturating: two grid counts near 2^32 make a length near 2^64, whose
            // double would overflow (no section is that long, so it is refused).
            || Ok(info.weight_table_len().saturating_mul(info.weight_tables())),
            |expected, got| BlobError::WeightTableLength { expected, got },
        )?;
        Ok(Self {
            info,
            shape,
            domain,
            target,
            warp,
            params: NetworkParams::F16(params),
            table,
            weights,
        })
    }

    /// Every parameter a finite f16 (so [`f16_decode_finite`] applies), every
    /// weight finite and `>= 0`. `O(param_len + weight_table_len)`.
    fn check_values(&self) -> Result<(), BlobError> {
        let NetworkParams::F16(params) = self.params else {
            return Ok(());
        };
        let bad_param = params.iter().enumerate().find(|(_, &h)| !f16_is_finite(h));
        if let Some((index, &bits)) = bad_param {
            let index = index as u64;
            return Err(BlobError::NonFiniteParam { index, bits });
        }
        let bad_weight = self
            .weights
            .iter()
            .enumerate()
            .find(|(_, w)| !(w.is_finite() && **w >= 0.0));
        if let Some((index, w)) = bad_weight {
            let (index, bits) = (index as u64, w.to_bits());
            return Err(BlobError::BadWeight { index, bits });
        }
        Ok(())
    }

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

    /// Table mode's point of the unit square for index `i` (mod `n`) of instance
    /// `instance` (mod `S`) at condition `cond` (blob units): with
    /// `u = info().normalize(cond)` and the point-table cell
    /// `GridCell::locate(u, grid)`, the four stored u16 codes of the cell's corners
    /// decoded by `(q + 0.5) / 65536` and interpolated bilinearly
    /// ([`GridCell::lerp`]), x and y separately. In `(0,1)^2`. O(1), never panics.
    #[inline]
    pub fn square_point(&self, cond: Vec2, instance: u32, i: u32) -> Vec2 {
        self.square_point_at(self.info.normalize(cond.to_array()), instance, i)
    }

    /// [`Self::square_point`] at the normalized condition `u`.
    #[inline]
    fn square_point_at(&self, u: [f32; 2], instance: u32, i: u32) -> Vec2 {
        let (cell, corner) = self.table_corners(u, instance, i);
        let (p00, p10, p01, p11) = (corner(0, 0), corner(1, 0), corner(0, 1), corner(1, 1));
        let axis = |a: usize| cell.lerp(p00[a], p10[a], p01[a], p11[a]);
        Vec2::new(axis(0), axis(1))
    }

    /// The point-table cell of the normalized condition `u` and the stored square
    /// point of its corner `(dx, dy)` for index `i` (mod `n`) of instance
    /// `instance` (mod `S`), decoded by `(q + 0.5) / 65536`: what both table
    /// modes interpolate.
    #[inline]
    fn table_corners(
        &self,
        u: [f32; 2],
        instance: u32,
        i: u32,
    ) -> (GridCell, impl Fn(u32, u32) -> [f32; 2] + '_) {
        let info = &self.info;
        let cell = GridCell::locate(u, info.grid);
        let k = instance.checked_rem(info.instances).unwrap_or(0);
        let j = i.checked_rem(info.n).unwrap_or(0);
        let corner = move |dx, dy| {
            let at = info.point_table_index(cell.node(dx, dy), k, j);
            let q = self
                .table
                .get(at)
                .map_or([CENTRE_CODE; 2], |&w| unpack_point(w));
            [unorm16_decode(q[0]), unorm16_decode(q[1])]
        };
        (cell, corner)
    }

    /// Network mode's point of the unit square for index `i` (mod `n`) of any
    /// instance at condition `cond` (blob units): the network of
    /// [`nuld_core::network`] on `input_features(u, instance, i)` with
    /// `u = info().normalize(cond)`, its f16 parameters decoded exactly to `f32`,
    /// then `sigmoid` per output. In `[0,1]^2`. `O(multiply_adds)`, never panics.
    #[inline]
    pub fn network_square_point(&self, cond: Vec2, instance: u32, i: u32) -> Vec2 {
        self.network_square_point_at(self.info.normalize(cond.to_array()), instance, i)
    }

    /// [`Self::network_square_point`] at the normalized condition `u`.
    #[inline]
    fn network_square_point_at(&self, u: [f32; 2], instance: u32, i: u32) -> Vec2 {
        let input = input_features::<f32>(&self.shape, u, instance, i);
        let shape = self.shape;
        let row = shape.embedding_row(instance, i);
        Vec2::from_array(match self.params {
            // Every index below `param_len` exists and is finite (`validate`).
            NetworkParams::F16(params) => Network {
                shape,
                params: F16Params(params),
            }
            .square_point(row, input),
            NetworkParams::F32(params) => Network { shape, params }.square_point(row, input),
        })
    }

    /// Length of the `f32` buffer [`Self::decode_network`] needs:
    /// [`Shape::param_len`], 4 bytes per parameter.
    pub fn decoded_network_len(&self) -> usize {
        self.shape.param_len()
    }

    /// This sampler with network mode reading the network's parameters decoded to
    /// `f32` into `buf` (its first [`Self::decoded_network_len`] entries), instead
    /// of decoding each f16 on every sample. The decode is exact, so every method
    /// returns the same bits as on `self`; network mode gets faster (the f16
    /// decode is most of its cost on a CPU without a half-float unit; `build-tool
    /// bench --only runtime` times both), table mode is unchanged. Decode once per
    /// blob, as a renderer uploads tables once. `None` if `buf` is shorter;
    /// `O(param_len)`, never panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_conditional_blob();
    /// use nuld_runtime::glam::Vec2;
    /// let cs = nuld_runtime::Blob::parse(&bytes.0)?.conditional()?;
    /// let mut buf = [0.0f32; 64];
    /// let fast = cs.decode_network(&mut buf).expect("a long enough buffer");
    /// let c = Vec2::new(0.5, 30.0);
    /// assert_eq!(fast.sample_network(c, 9, 2), cs.sample_network(c, 9, 2));
    /// assert!(cs.decode_network(&mut [0.0; 1]).is_none());
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    pub fn decode_network<'b>(&self, buf: &'b mut [f32]) -> Option<ConditionalSampler<'b>>
    where
        'a: 'b,
    {
        let len = self.decoded_network_len();
        let out = buf.get_mut(..len)?;
        match self.params {
            NetworkParams::F16(params) => {
                if params.len() != len {
                    return None;
                }
                F16Params(params).read(0, out);
            }
            NetworkParams::F32(params) => out.copy_from_slice(params.get(..len)?),
        }
        Some(ConditionalSampler {
            params: NetworkParams::F32(out),
            ..*self
        })
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
    ///
    /// An environment sampler ([`ConditionalTarget::EnvmapNormal`]) interpolates
    /// directions instead: each corner's stored point through the map, the four
    /// unit vectors blended by [`GridCell::nlerp`] with the cell's bilinear weights
    /// ([`Self::sample_envmap`] takes a normal).
    #[inline]
    pub fn sample(&self, cond: Vec2, instance: u32, i: u32) -> Sample {
        let u = self.info.normalize(cond.to_array());
        if self.target == ConditionalTarget::EnvmapNormal {
            return Sample {
                direction: Vec3::from_array(self.table_direction_at(u, instance, i)),
                weight: self.weight_table_lerp(&self.weight_cell_at(u), 0),
            };
        }
        self.mapped(self.square_point_at(u, instance, i), u)
    }

    /// Table mode's direction for an environment sampler: the four corners'
    /// stored square points decoded by `(q + 0.5) / 65536`, each through the
    /// domain's equal-area map in `f32`, then [`GridCell::nlerp`].
    #[inline]
    fn table_direction_at(&self, u: [f32; 2], instance: u32, i: u32) -> [f32; 3] {
        let (cell, corner) = self.table_corners(u, instance, i);
        let d = |dx, dy| self.domain.to_direction_real(corner(dx, dy));
        cell.nlerp(d(0, 0), d(1, 0), d(0, 1), d(1, 1))
    }

    /// Table mode for an environment sampler ([`ConditionalTarget::EnvmapNormal`])
    /// at the surface normal `normal` (world frame, the map's `+z` up; any length):
    /// [`Self::sample`] at the condition `sphere_to_square(normal / |normal|)`
    /// ([`nuld_core::sphere::sphere_to_square_real`] in `f32`). A zero, infinite or
    /// NaN normal reads as `+z`. The direction is in the world frame; the weight
    /// is the irradiance `E(n)` of the weight table, so that
    /// `∫ L f max(0, n.l) ≈ (E / N) Σ f(l_i)`. O(1), never panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_conditional_blob();
    /// use nuld_runtime::glam::{Vec2, Vec3};
    /// let cs = nuld_runtime::Blob::parse(&bytes.0)?.conditional()?;
    /// // A BRDF blob reads the normal's square point as its condition, clamped.
    /// let s = cs.sample_envmap(Vec3::Z, 3, 1);
    /// assert_eq!(s, cs.sample(Vec2::new(0.5, 0.5), 3, 1));
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    #[inline]
    pub fn sample_envmap(&self, normal: Vec3, instance: u32, i: u32) -> Sample {
        self.sample(normal_condition(normal), instance, i)
    }

    /// Network mode for an environment sampler: as [`Self::sample_envmap`] with
    /// [`Self::sample_network`]. `O(multiply_adds)`, never panics.
    #[inline]
    pub fn sample_envmap_network(&self, normal: Vec3, instance: u32, i: u32) -> Sample {
        self.sample_network(normal_condition(normal), instance, i)
    }

    /// Network mode: as [`Self::sample`] with [`Self::network_square_point`]. With
    /// [`Self::instance_slots`] `M >= 1` instance `k` is the set of slot `k mod M`
    /// (instances wrap as table mode's do modulo [`Self::instances`]); with none,
    /// every `u32` instance is a different set (its offset hashed from it).
    /// `O(multiply_adds)`, never panics.
    #[inline]
    pub fn sample_network(&self, cond: Vec2, instance: u32, i: u32) -> Sample {
        let u = self.info.normalize(cond.to_array());
        self.mapped(self.network_square_point_at(u, instance, i), u)
    }

    /// Table mode for a BRDF sampler ([`ConditionalTarget::GltfBrdf`]) at any view:
    /// `wo` the view direction in the local frame (`z` = normal, any length),
    /// `roughness` in blob units. The set is made for the view in the xz-plane on
    /// the `+x` side; this samples it at `(roughness, theta_o)` and rotates the
    /// direction about `z` by the view's azimuth `phi = atan2(wo.y, wo.x)` (the target
    /// is isotropic), so the set follows the caller's view.
    ///
    /// `theta_o = acos(clamp(wo.z / |wo|, 0, 1))` in degrees; the rotation uses
    /// `(cos phi, sin phi) = (wo.x, wo.y) / sqrt(wo.x^2 + wo.y^2)`, no
    /// transcendental. A view below the horizon reads as grazing; a zero, infinite
    /// or NaN `wo` reads as normal incidence (`theta_o = 0`, `phi = 0`), as does
    /// `phi` for `wo` along `z`. The weight is the table's at `(roughness,
    /// theta_o)`. O(1), never panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_conditional_blob();
    /// use nuld_runtime::glam::{Vec2, Vec3};
    /// let cs = nuld_runtime::Blob::parse(&bytes.0)?.conditional()?;
    /// // A view at 60° in the yz-plane: the xz-plane set turned by 90° about z.
    /// let wo = Vec3::new(0.0, 3f32.sqrt() / 2.0, 0.5);
    /// let s = cs.sample_brdf(wo, 0.3, 7, 2);
    /// let t = cs.sample(Vec2::new(0.3, 60.0), 7, 2);
    /// let turned = Vec3::new(-t.direction.y, t.direction.x, t.direction.z);
    /// assert!((s.direction - turned).length() < 1e-5);
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    #[inline]
    pub fn sample_brdf(&self, wo: Vec3, roughness: f32, instance: u32, i: u32) -> Sample {
        let (cond, azimuth) = view_condition(wo, roughness);
        rotate(self.sample(cond, instance, i), azimuth)
    }

    /// Network mode for a BRDF sampler: as [`Self::sample_brdf`] with
    /// [`Self::sample_network`]. `O(multiply_adds)`, never panics.
    #[inline]
    pub fn sample_brdf_network(&self, wo: Vec3, roughness: f32, instance: u32, i: u32) -> Sample {
        let (cond, azimuth) = view_condition(wo, roughness);
        rotate(self.sample_network(cond, instance, i), azimuth)
    }

    /// The sample of point `p` at the normalized condition `u`: the direction of
    /// [`PointWarp::direction`], the weight of [`Self::weight`]; one weight-grid
    /// cell serves the weight and the lobe probability.
    #[inline]
    fn mapped(&self, p: Vec2, u: [f32; 2]) -> Sample {
        let cell = self.weight_cell_at(u);
        // Only the mixture warp reads the condition and `p_s`; the equal-area map
        // skips their lookups.
        let (cond, p_s) = match self.warp {
            PointWarp::EqualArea => ([0.0; 2], 0.0),
            PointWarp::BrdfMixture => {
                // The clamped condition in blob units, as the tables see it.
                (self.info.denormalize(u), self.weight_table_lerp(&cell, 1))
            }
        };
        let direction = self.warp.direction(self.domain, cond, p_s, p.to_array());
        Sample {
            direction: Vec3::from_array(direction),
            weight: self.weight_table_lerp(&cell, 0),
        }
    }
}

/// Section `tag` of `layout` as a slice of `T`, checked in this order: the section
/// exists; its `elem_size` is `size_of::<T>()` (else `bad_size(elem_size)`); it holds
/// exactly `expected()?` elements (else `bad_length(expected, got)`); it is aligned
/// for `T` (else [`BlobError::Misaligned`]).
fn typed_section<'a, T: bytemuck::Pod>(
    layout: &Layout<'a>,
    tag: SectionTag,
    bad_size: fn(u32) -> BlobError,
    expected: impl FnOnce() -> Result<u64, BlobError>,
    bad_length: fn(u64, u64) -> BlobError,
) -> Result<&'a [T], BlobError> {
    let (entry, bytes) = layout.section(tag)?;
    let size = core::mem::size_of::<T>();
    if entry.elem_size as usize != size {
        return Err(bad_size(entry.elem_size));
    }
    let expected = expected()?;
    let got = (bytes.len() / size) as u64;
    if got != expected {
        return Err(bad_length(expected, got));
    }
    bytemuck::try_cast_slice(bytes).map_err(|_| BlobError::Misaligned)
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

/// `v` divided by its largest absolute component, or `None` for a zero, infinite
/// or NaN `v`. Scaling first keeps `|v|` finite for huge inputs and away from
/// underflow for tiny ones.
#[inline]
fn scaled_to_largest(v: Vec3) -> Option<Vec3> {
    let m = v.abs().max_element();
    (v.is_finite() && m > 0.0).then(|| v / m)
}

/// The condition of a normal: its equal-area octahedral square point; a
/// degenerate normal reads as `+z`.
#[inline]
fn normal_condition(n: Vec3) -> Vec2 {
    let d = scaled_to_largest(n).map_or(Vec3::Z, |w| w / w.length());
    Vec2::from_array(nuld_core::sphere::sphere_to_square_real(d.to_array()))
}

/// The sample turned about `z` by the azimuth `(cos phi, sin phi)`.
#[inline]
fn rotate(s: Sample, azimuth: Vec2) -> Sample {
    let d = s.direction;
    let (c, sn) = (azimuth.x, azimuth.y);
    Sample {
        direction: Vec3::new(c * d.x - sn * d.y, sn * d.x + c * d.y, d.z),
        weight: s.weight,
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::Blob;
    use nuld_core::blob::{encoded_len, write, BlobKind};
    use nuld_core::conditional::sections;
    use nuld_core::quantize::{f16_decode_finite, f16_encode};
    use std::vec::Vec;

    /// The four sections of a conditional blob, owned, for building test blobs.
    #[derive(Clone)]
    struct Parts {
        info: ConditionalInfo,
        params: Vec<u16>,
        table: Vec<u32>,
        weights: Vec<f32>,
    }

    /// A 16-byte aligned blob.
    struct Bytes(Vec<u128>, usize);

    impl Bytes {
        fn get(&self) -> &[u8] {
            &bytemuck::cast_slice(&self.0)[..self.1]
        }
    }

    /// Deterministic pseudo-random numbers for test contents (`hash_u32` chain).
    fn noise(seed: u32, k: u32) -> u32 {
        nuld_core::network::hash_u32(
            seed.wrapping_mul(0x9e37_79b9) ^ nuld_core::network::hash_u32(k),
        )
    }

    fn parts() -> Parts {
        let info = ConditionalInfo {
            n: 5,
            instances: 3,
            domain: Domain::Hemisphere as u32,
            target: ConditionalTarget::GltfBrdf as u32,
            grid: [5, 3],
            weight_grid: [4, 6],
            cond_min: [0.0, 0.0],
            cond_max: [1.0, 80.0],
            hidden: [4, 3, 0],
            activation: Activation::Silu as u32,
            lattice_generator: 2,
            warp: 0,
            instance_slots: 0,
            reserved: 0,
        };
        let len = info.shape().unwrap().param_len();
        let params = (0..len as u32)
            .map(|j| f16_encode((noise(1, j) % 2001) as f32 / 1000.0 - 1.0))
            .collect();
        let table = (0..info.point_table_len().unwrap() as u32)
            .map(|e| noise(2, e))
            .collect();
        // A bilinear function of the normalized condition, which bilinear
        // interpolation must reproduce: w = 1 + 0.5 x - 0.25 y + 0.125 x y.
        let (wx, wy) = (info.weight_grid[0], info.weight_grid[1]);
        let weights = (0..wx * wy)
            .map(|e| {
                let x = (e % wx) as f32 / (wx - 1) as f32;
                let y = (e / wx) as f32 / (wy - 1) as f32;
                bilinear_weight(x, y)
            })
            .collect();
        Parts {
            info,
            params,
            table,
            weights,
        }
    }

    fn bilinear_weight(x: f32, y: f32) -> f32 {
        1.0 + 0.5 * x - 0.25 * y + 0.125 * x * y
    }

    fn encode(p: &Parts) -> Bytes {
        let sections = sections(&p.info, &p.params, &p.table, &p.weights);
        let meta = [0u8, 0, 0];
        let len = encoded_len(&meta, &sections);
        let mut buf = std::vec![0u128; len.div_ceil(16)];
        let out = &mut bytemuck::cast_slice_mut::<u128, u8>(&mut buf)[..len];
        write(out, BlobKind::Conditional, &meta, &sections).unwrap();
        Bytes(buf, len)
    }

    fn with(change: impl FnOnce(&mut Parts)) -> Result<(), BlobError> {
        let mut p = parts();
        change(&mut p);
        let bytes = encode(&p);
        Blob::parse(bytes.get()).map(|_| ())
    }

    #[test]
    fn a_decoded_network_samples_the_same_bits() {
        let bytes = encode(&parts());
        let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
        let len = cs.decoded_network_len();
        assert_eq!(len, cs.shape().param_len());
        assert!(cs.decode_network(&mut std::vec![0.0; len - 1]).is_none());
        let mut buf = std::vec![f32::NAN; len + 3];
        let fast = cs.decode_network(&mut buf).unwrap();
        for k in 0..2000u32 {
            let c = Vec2::new(
                (noise(3, k) % 1300) as f32 / 1000.0 - 0.1,
                (noise(4, k) % 900) as f32 / 10.0,
            );
            let (instance, i) = (noise(5, k), k % 11);
            let wo = Vec3::new(c.y.to_radians().sin(), 0.3, c.y.to_radians().cos());
            let n = Vec3::new(c.x - 0.5, 0.2, 1.0);
            assert_eq!(
                fast.sample_network(c, instance, i),
                cs.sample_network(c, instance, i)
            );
            assert_eq!(
                fast.sample_brdf_network(wo, c.x, instance, i),
                cs.sample_brdf_network(wo, c.x, instance, i)
            );
            assert_eq!(
                fast.sample_envmap_network(n, instance, i),
                cs.sample_envmap_network(n, instance, i)
            );
            // Table mode does not read the network.
            assert_eq!(fast.sample(c, instance, i), cs.sample(c, instance, i));
        }
        // Decoding a decoded sampler copies its weights.
        let mut again = std::vec![0.0; len];
        let twice = fast.decode_network(&mut again).unwrap();
        let c = Vec2::new(0.4, 33.0);
        assert_eq!(twice.sample_network(c, 8, 3), cs.sample_network(c, 8, 3));
        assert_eq!(again, buf[..len]);
        // The weights are the f16 values decoded; the rest of the buffer is untouched.
        let Parts { params, .. } = parts();
        assert!(params
            .iter()
            .zip(&buf)
            .all(|(&h, &v)| f16_decode_finite(h) == v));
        assert!(buf[len..].iter().all(|v| v.is_nan()));
    }

    #[test]
    fn corners_reproduce_the_stored_points_exactly() {
        let p = parts();
        let bytes = encode(&p);
        let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
        let info = p.info;
        for j1 in 0..info.grid[1] {
            for j0 in 0..info.grid[0] {
                let c = info.grid_condition([j0, j1]).map(|x| x as f32);
                let node = (j1 * info.grid[0] + j0) as usize;
                for k in 0..info.instances {
                    for i in 0..info.n {
                        let w = p.table[info.point_table_index(node, k, i)];
                        let q = unpack_point(w);
                        let want = Vec2::new(unorm16_decode(q[0]), unorm16_decode(q[1]));
                        assert_eq!(
                            cs.square_point(Vec2::from(c), k, i),
                            want,
                            "{j0} {j1} {k} {i}"
                        );
                    }
                }
            }
        }
    }

    /// An environment sampler's parts: `parts()` on the sphere, conditions the
    /// octahedral square.
    fn envmap_parts() -> Parts {
        let mut p = parts();
        p.info.domain = Domain::Sphere as u32;
        p.info.target = ConditionalTarget::EnvmapNormal as u32;
        p.info.cond_min = [0.0; 2];
        p.info.cond_max = [1.0; 2];
        p
    }

    /// Table mode of an environment sampler: at a node the stored point's
    /// direction (nlerp of one corner), between nodes the normalized bilinear
    /// blend of the corners' directions (not of their square points), and
    /// `sample_envmap` reads a normal as its octahedral square point.
    #[test]
    fn envmap_tables_interpolate_directions() {
        let p = envmap_parts();
        let bytes = encode(&p);
        let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
        assert_eq!(cs.target(), ConditionalTarget::EnvmapNormal);
        let info = p.info;
        let stored = |node: u32, k: u32, i: u32| {
            let q = unpack_point(p.table[info.point_table_index(node as usize, k, i)]);
            Domain::Sphere.to_direction_real([unorm16_decode(q[0]), unorm16_decode(q[1])])
        };
        for j1 in 0..info.grid[1] {
            for j0 in 0..info.grid[0] {
                let c = info.grid_condition([j0, j1]).map(|x| x as f32);
                let node = j1 * info.grid[0] + j0;
                let got = cs.sample(Vec2::from(c), 2, 4).direction.to_array();
                let want = stored(node, 2, 4);
                for a in 0..3 {
                    assert!(
                        (got[a] - want[a]).abs() < 1e-6,
                        "{j0} {j1}: {got:?} {want:?}"
                    );
                }
            }
        }
        // Between nodes (0,0), (1,0), (0,1), (1,1) of the 5 x 3 grid.
        let u = [0.1f32, 0.3];
        let (t0, t1) = (u[0] * 4.0, u[1] * 2.0);
        let corners = [
            stored(0, 1, 3),
            stored(1, 1, 3),
            stored(5, 1, 3),
            stored(6, 1, 3),
        ];
        let want: [f32; 3] = core::array::from_fn(|a| {
            let lo = corners[0][a] + (corners[1][a] - corners[0][a]) * t0;
            let hi = corners[2][a] + (corners[3][a] - corners[2][a]) * t0;
            lo + (hi - lo) * t1
        });
        let len = want.iter().map(|x| x * x).sum::<f32>().sqrt();
        let got = cs.sample(Vec2::from(u), 1, 3);
        let want = Vec3::from_array(want) / len;
        assert!((got.direction - want).length() < 1e-6, "{got:?} {want}");
        assert!((got.direction.length() - 1.0).abs() < 1e-6);
        assert_eq!(got.weight, cs.weight(Vec2::from(u)));
        // A normal is read through the octahedral map, at any length; degenerate
        // normals read as +z.
        let n = Vec3::new(0.2, -0.7, 0.4);
        let c = nuld_core::sphere::sphere_to_square_real(n.normalize().to_array());
        assert_eq!(
            cs.sample_envmap(n * 3.0, 7, 2),
            cs.sample(Vec2::from(c), 7, 2)
        );
        assert_eq!(
            cs.sample_envmap_network(n, 9, 1),
            cs.sample_network(Vec2::from(c), 9, 1)
        );
        for bad in [Vec3::ZERO, Vec3::NAN, Vec3::new(f32::INFINITY, 0.0, 1.0)] {
            assert_eq!(cs.sample_envmap(bad, 0, 0), cs.sample_envmap(Vec3::Z, 0, 0));
        }
        let d = cs.sample_network(Vec2::new(0.7, 0.2), 5, 4).direction;
        assert!((d.length() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn indices_and_instances_wrap_and_conditions_clamp() {
        let p = parts();
        let bytes = encode(&p);
        let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
        let (n, s) = (cs.len(), cs.instances());
        let c = Vec2::new(0.37, 41.0);
        for i in 0..2 * n {
            for k in 0..2 * s {
                assert_eq!(cs.sample(c, k, i), cs.sample(c, k % s, i % n));
                assert_eq!(cs.sample(c, k, i), cs.sample(c, k + s * 1000, i + n * 77));
                assert_eq!(cs.sample_network(c, k, i), cs.sample_network(c, k, i % n));
            }
        }
        // Network mode hashes the instance: instance S is not instance 0.
        assert_ne!(cs.sample_network(c, s, 0), cs.sample_network(c, 0, 0));
        let lo = Vec2::new(0.0, 0.0);
        let hi = Vec2::new(1.0, 80.0);
        for mode in [
            ConditionalSampler::sample,
            ConditionalSampler::sample_network,
        ] {
            let at = |x: f32, y: f32| mode(&cs, Vec2::new(x, y), 1, 2);
            assert_eq!(at(f32::NAN, f32::NAN), mode(&cs, lo, 1, 2));
            assert_eq!(at(-3.0, f32::NEG_INFINITY), mode(&cs, lo, 1, 2));
            assert_eq!(at(7.0, 1e30), mode(&cs, hi, 1, 2));
            assert_eq!(
                at(f32::INFINITY, f32::NAN),
                mode(&cs, Vec2::new(1.0, 0.0), 1, 2)
            );
        }
        assert_eq!(
            cs.sample(Vec2::new(u32::MAX as f32, 0.0), u32::MAX, u32::MAX)
                .weight,
            cs.weight(Vec2::new(1.0, 0.0))
        );
    }

    #[test]
    fn weights_interpolate_bilinearly() {
        let p = parts();
        let bytes = encode(&p);
        let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
        for k in 0..500 {
            let x = (noise(3, k) % 10_001) as f32 / 10_000.0;
            let y = (noise(4, k) % 10_001) as f32 / 10_000.0;
            let w = cs.weight(Vec2::new(x, 80.0 * y));
            // Bilinear interpolation reproduces a bilinear function up to rounding.
            assert!((w - bilinear_weight(x, y)).abs() < 1e-6, "{x} {y}: {w}");
            assert_eq!(cs.sample(Vec2::new(x, 80.0 * y), 0, 0).weight, w);
            assert_eq!(cs.sample_network(Vec2::new(x, 80.0 * y), 9, 1).weight, w);
        }
    }

    #[test]
    fn directions_are_unit_vectors_on_the_hemisphere() {
        let p = parts();
        let bytes = encode(&p);
        let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
        let views = [
            Vec3::new(0.3, -0.2, 0.9),
            Vec3::ZERO,
            Vec3::splat(f32::NAN),
            Vec3::new(f32::INFINITY, 0.0, 1.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1e-30, 1e-30, 1e-35),
            Vec3::new(3e38, -3e38, 3e38),
            Vec3::Z,
        ];
        for k in 0..400 {
            let c = Vec2::new(
                (noise(5, k) % 1000) as f32 / 900.0 - 0.05,
                (noise(6, k) % 1000) as f32 / 10.0 - 10.0,
            );
            let wo = views[k as usize % views.len()];
            for s in [
                cs.sample(c, k, k / 3),
                cs.sample_network(c, k, k / 3),
                cs.sample_brdf(wo, c.x, k, k / 3),
                cs.sample_brdf_network(wo, c.x, k, k / 3),
            ] {
                let d = s.direction;
                assert!(
                    (d.length() - 1.0).abs() < 2e-6 && d.z >= 0.0,
                    "{c} {wo}: {d}"
                );
                assert!(s.weight.is_finite() && s.weight > 0.0);
            }
        }
    }

    /// `sample_brdf` against an independent frame: `theta_o` and `phi` from `f64`
    /// `acos`/`atan2`, the table sample rotated by `phi` in `f64`.
    #[test]
    fn sample_brdf_rotates_the_xz_plane_set_to_the_view_azimuth() {
        let p = parts();
        let bytes = encode(&p);
        let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
        for k in 0..300u32 {
            let theta = (noise(7, k) % 8000) as f64 / 100.0;
            let phi = ((noise(8, k) % 10_000) as f64 / 5_000.0 - 1.0) * core::f64::consts::PI;
            let len = 0.5 + (noise(9, k) % 100) as f64 / 20.0;
            let (t, f) = (theta.to_radians(), phi);
            let wo = [t.sin() * f.cos(), t.sin() * f.sin(), t.cos()].map(|x| (x * len) as f32);
            let wo = Vec3::from_array(wo);
            let wo64 = wo.as_dvec3();
            let theta_ref = (wo64.z / wo64.length()).clamp(0.0, 1.0).acos().to_degrees();
            let phi_ref = wo64.y.atan2(wo64.x);
            let (r, i) = (0.2 + (k % 7) as f32 / 10.0, k / 5);
            let cond = Vec2::new(r, theta_ref as f32);
            for (got, plain) in [
                (cs.sample_brdf(wo, r, k, i), cs.sample(cond, k, i)),
                (
                    cs.sample_brdf_network(wo, r, k, i),
                    cs.sample_network(cond, k, i),
                ),
            ] {
                let d = plain.direction.as_dvec3();
                let (c, s) = (phi_ref.cos(), phi_ref.sin());
                let want = glam::DVec3::new(c * d.x - s * d.y, s * d.x + c * d.y, d.z);
                assert!(
                    (got.direction.as_dvec3() - want).length() < 1e-4,
                    "{wo}: {got:?} vs {want}"
                );
                assert!((got.weight - plain.weight).abs() < 1e-5);
            }
        }
        // Degenerate views are normal incidence, azimuth 0.
        for wo in [Vec3::ZERO, Vec3::NAN, Vec3::INFINITY, Vec3::Z * 2.0] {
            assert_eq!(
                cs.sample_brdf(wo, 0.5, 1, 1),
                cs.sample(Vec2::new(0.5, 0.0), 1, 1)
            );
        }
        // Below the horizon reads as grazing (clamped to the range's 80°).
        let below = cs.sample_brdf(Vec3::new(1.0, 0.0, -0.5), 0.5, 1, 1);
        assert_eq!(below, cs.sample(Vec2::new(0.5, 90.0), 1, 1));
    }

    #[test]
    fn each_validation_failure_has_its_error() {
        assert_eq!(with(|_| {}), Ok(()));
        type Change = fn(&mut Parts);
        let cases: [(Change, BlobError); 28] = [
            (|p| p.info.n = 0, BlobError::ConditionalNoPoints),
            (|p| p.info.instances = 0, BlobError::ConditionalNoInstances),
            (|p| p.info.domain = 0, BlobError::ConditionalDomain(0)),
            (|p| p.info.domain = 9, BlobError::ConditionalDomain(9)),
            (
                |p| p.info.target = 0,
                BlobError::UnknownConditionalTarget(0),
            ),
            (
                |p| p.info.grid[1] = 1,
                BlobError::ConditionalGrid { axis: 1, nodes: 1 },
            ),
            (
                |p| p.info.weight_grid[0] = 0,
                BlobError::ConditionalWeightGrid { axis: 0, nodes: 0 },
            ),
            (
                |p| p.info.cond_max[0] = 0.0,
                BlobError::ConditionalRange {
                    axis: 0,
                    min_bits: 0,
                    max_bits: 0,
                },
            ),
            (
                |p| p.info.cond_min[1] = f32::NEG_INFINITY,
                BlobError::ConditionalRange {
                    axis: 1,
                    min_bits: f32::NEG_INFINITY.to_bits(),
                    max_bits: 80f32.to_bits(),
                },
            ),
            (
                |p| p.info.cond_max[1] = f32::NAN,
                BlobError::ConditionalRange {
                    axis: 1,
                    min_bits: 0,
                    max_bits: f32::NAN.to_bits(),
                },
            ),
            (|p| p.info.activation = 2, BlobError::UnknownActivation(2)),
            (
                |p| p.info.hidden = [4, 0, 3],
                BlobError::NetworkWidths([4, 0, 3]),
            ),
            (
                |p| p.info.hidden = [0, 0, 0],
                BlobError::NetworkWidths([0, 0, 0]),
            ),
            (
                |p| p.info.hidden = [129, 3, 0],
                BlobError::NetworkWidths([129, 3, 0]),
            ),
            (|p| p.info.reserved = 1, BlobError::ConditionalReserved(1)),
            // 5 n x 4 h1 x M embedding numbers reach 2^32 at M = 2^32 / 20.
            (
                |p| p.info.instance_slots = u32::MAX / 16,
                BlobError::InstanceSlots(u32::MAX / 16),
            ),
            // Slots that fit the counts but not the parameters: M n h1 more rows.
            (
                |p| p.info.instance_slots = 2,
                BlobError::ParamsLength {
                    expected: 2 * 5 * 4 + 4 * 12 + 3 * 5 + 2 * 4,
                    got: 91,
                },
            ),
            (|p| p.info.warp = 7, BlobError::UnknownPointWarp(7)),
            (
                |p| {
                    p.info.warp = 1;
                    p.info.target = 2;
                    p.info.domain = 1;
                },
                BlobError::UnknownPointWarp(1),
            ),
            // Each target has its domain: the BRDF the hemisphere, maps the sphere.
            (|p| p.info.domain = 1, BlobError::ConditionalDomain(1)),
            (
                |p| {
                    p.info.warp = 0;
                    p.info.target = 2;
                },
                BlobError::ConditionalDomain(2),
            ),
            (
                |p| {
                    p.params.pop();
                },
                BlobError::ParamsLength {
                    expected: 5 * 4 + 4 * 12 + 3 * 5 + 2 * 4,
                    got: 90,
                },
            ),
            (
                |p| p.params[17] = 0x7c00,
                BlobError::NonFiniteParam {
                    index: 17,
                    bits: 0x7c00,
                },
            ),
            (
                |p| p.params[3] = 0xfe01,
                BlobError::NonFiniteParam {
                    index: 3,
                    bits: 0xfe01,
                },
            ),
            (
                |p| {
                    p.table.push(0);
                },
                BlobError::PointTableLength {
                    expected: 5 * 3 * 3 * 5,
                    got: 226,
                },
            ),
            (
                |p| {
                    p.info.instances = u32::MAX;
                    p.info.grid = [u32::MAX, u32::MAX];
                },
                BlobError::PointTableCountOverflow,
            ),
            (
                |p| {
                    p.weights.truncate(3);
                },
                BlobError::WeightTableLength {
                    expected: 24,
                    got: 3,
                },
            ),
            (
                |p| p.weights[5] = -0.5,
                BlobError::BadWeight {
                    index: 5,
                    bits: (-0.5f32).to_bits(),
                },
            ),
        ];
        for (k, (change, want)) in cases.into_iter().enumerate() {
            assert_eq!(with(change), Err(want), "case {k}");
            assert!(!std::format!("{want}").contains('\n'));
        }
        assert_eq!(
            with(|p| p.weights[0] = f32::INFINITY),
            Err(BlobError::BadWeight {
                index: 0,
                bits: f32::INFINITY.to_bits()
            })
        );
        // Another kind asks for the conditional view in vain, and vice versa.
        let other = crate::doc_example_blob();
        assert_eq!(
            Blob::parse(&other.0).unwrap().conditional().unwrap_err(),
            BlobError::WrongKind {
                expected: BlobKind::Conditional,
                found: BlobKind::PointSet2D
            }
        );
    }

    #[test]
    fn doc_example_conditional_blob_is_exactly_its_array() {
        let b = crate::doc_example_conditional_blob();
        let cs = Blob::parse(&b.0).unwrap().conditional().unwrap();
        assert_eq!((cs.len(), cs.instances()), (2, 2));
    }
}
