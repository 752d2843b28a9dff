//! The conditional sampler's blob contents (kind 3, paper §4): the info record, the
//! condition grid, and the interpolation arithmetic that the build tool's tables
//! and every reader (the runtime, shaders) must share.
//!
//! A conditional blob serves, for a condition `c` (for BRDF samplers
//! `c = (roughness, theta_o in degrees)`), an instance `k` and an index `i < n`, a
//! direction and the estimator weight. Two ways:
//!
//! * **network mode**: [`crate::network`] evaluated on the f16 parameters;
//! * **table mode**: the network's square points on a regular grid of conditions,
//!   for instances `0..instances`, interpolated bilinearly in the square between the
//!   four grid nodes around `c` ([`GridCell`]), then mapped to the domain.
//!
//! The weight is the target's normalization (for BRDFs the directional albedo
//! `A(c)`) interpolated bilinearly on its own grid.
//!
//! Conditions are clamped into `[cond_min, cond_max]` per axis (NaN reads as
//! `cond_min`), then normalized to `[0,1]^2` ([`ConditionalInfo::normalize`]); the
//! network's condition input is that normalized point.

use crate::blob::{SectionSpec, SectionTag};
use crate::domain::Domain;
use crate::envmap_tree::EnvmapTree;
use crate::network::{offset_unit, Activation, OffsetHash, Shape, MAX_HIDDEN_LAYERS};
use crate::real::Real;

pub mod metallic_axis;
mod target;
use bytemuck::{Pod, Zeroable};
pub use metallic_axis::{
    check_metallic_nodes, metallic_section, MetallicCell, MetallicNodesError, MAX_METALLIC_NODES,
};
pub use target::ConditionalTarget;

/// How a conditional sampler turns the network's point of the unit square into a
/// direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum PointWarp {
    /// The domain's equal-area map (`crate::sphere`) of the network's square
    /// point: the network alone shapes the set.
    EqualArea = 0,
    /// The network's point is a point of the *primary sample space* of the
    /// renderer's mixture warp ([`crate::warp::brdf_mixture_real`]): its outputs
    /// are a residual added to the logit of the instance's shifted lattice point
    /// ([`crate::network::Shape::lattice_residual`]), and the direction is the
    /// mixture warp of the result for the condition's view, `alpha = roughness^2`
    /// and lobe probability `p_s` (a second table after the weights). A strong
    /// prior (paper §4's "correction in primary sample space to a cheap standard
    /// warp"): at zero residual the set is the renderer's warp of a randomly
    /// shifted lattice, so the network only learns a smooth correction, and
    /// instances differ by construction. glTF BRDF blobs only.
    BrdfMixture = 1,
    /// The network's point is a point of the primary sample space of the
    /// environment prior ([`crate::envmap_tree`], the blob's tree sections): a
    /// residual on the logit of the instance's shifted lattice point as for
    /// [`Self::BrdfMixture`], and the direction is the tree's exact product warp of
    /// the map's light and the cosine about the normal whose octahedral square
    /// point is the condition. Its density at the direction is the sampler's pdf.
    /// Environment blobs only.
    EnvmapTree = 2,
    /// The network's point is a point of the primary sample space of the BRDF
    /// prior ([`crate::brdf_prior`], the blob's prior sections): a residual on
    /// the logit of the instance's shifted lattice point as for
    /// [`Self::BrdfMixture`], and the direction is the prior's exact warp of the
    /// glTF metallic-roughness BRDF times the cosine at `(roughness, θo,
    /// metallic)`, metallic given at the query (the learned points are shared by
    /// every metallic; the prior blends the metallic ends exactly). Its density
    /// at the direction is the sampler's pdf, and the weight is `f cos / pdf`.
    /// glTF BRDF blobs only; replaces [`Self::BrdfMixture`] in new blobs.
    BrdfTable = 3,
}

impl PointWarp {
    /// The warp with this code, if any.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            0 => Some(Self::EqualArea),
            1 => Some(Self::BrdfMixture),
            2 => Some(Self::EnvmapTree),
            3 => Some(Self::BrdfTable),
            _ => None,
        }
    }

    /// The warp a network of `shape` is trained for on `target`: for a [lattice
    /// residual](Shape::lattice_residual) the target's prior
    /// ([`BrdfTable`](Self::BrdfTable) or [`EnvmapTree`](Self::EnvmapTree)),
    /// else [`EqualArea`](Self::EqualArea).
    pub fn of(target: ConditionalTarget, shape: &Shape) -> Self {
        match (shape.lattice_residual(), target) {
            (false, _) => Self::EqualArea,
            (true, ConditionalTarget::GltfBrdf) => Self::BrdfTable,
            (true, ConditionalTarget::EnvmapNormal) => Self::EnvmapTree,
        }
    }

    /// Whether the network's outputs are a residual on the shifted lattice's
    /// logit ([`Shape::lattice_residual`]): every warp but the equal-area map.
    pub fn lattice_residual(self) -> bool {
        self != Self::EqualArea
    }

    /// The direction of a sampler's point `p` (the network's output, or the table's
    /// interpolation of it): [`EqualArea`](Self::EqualArea) maps it with
    /// `domain`'s equal-area map; [`BrdfMixture`](Self::BrdfMixture) warps it with
    /// [`brdf_mixture_direction`] at the condition `cond = (roughness, theta_o in
    /// degrees)` and lobe probability `p_s`. A warp ignores the arguments it does not
    /// use. [`EnvmapTree`](Self::EnvmapTree) samples `tree` at the normal whose
    /// octahedral square point is `cond` ([`EnvmapTree::sample_square`]; without a
    /// tree, which no parsed blob lacks, the equal-area map stands in).
    /// [`BrdfTable`](Self::BrdfTable) needs the prior's tables and the metallic,
    /// which this signature does not carry: callers warp through
    /// [`crate::brdf_prior::BrdfPrior::sample`] (here the equal-area map stands
    /// in). Unit vectors; never panics.
    #[inline]
    pub fn direction<T: Real>(
        self,
        domain: Domain,
        cond: [T; 2],
        p_s: T,
        tree: Option<&EnvmapTree<'_>>,
        p: [T; 2],
    ) -> [T; 3] {
        match (self, tree) {
            (Self::BrdfMixture, _) => brdf_mixture_direction(cond, p_s, p),
            (Self::EnvmapTree, Some(tree)) => tree.sample_square(cond, p).0,
            _ => domain.to_direction_real(p),
        }
    }

    /// Central differences of [`Self::direction`] along `p.x` and `p.y` with step
    /// `h`: `(d(p + h e_a) - d(p - h e_a)) / (2 h)` per axis `a`, unclamped (the
    /// caller decides what a difference across the mixture's lobe boundary, a
    /// jump, means). The mixture warp has no closed-form Jacobian worth keeping.
    pub fn direction_differences<T: Real>(
        self,
        domain: Domain,
        cond: [T; 2],
        p_s: T,
        tree: Option<&EnvmapTree<'_>>,
        p: [T; 2],
        h: T,
    ) -> [[T; 3]; 2] {
        core::array::from_fn(|a| {
            let step = |sign: T| {
                let mut q = p;
                q[a] = q[a] + sign * h;
                self.direction(domain, cond, p_s, tree, q)
            };
            let (hi, lo) = (step(T::ONE), step(T::ZERO - T::ONE));
            core::array::from_fn(|c| (hi[c] - lo[c]) / (T::of(2.0) * h))
        })
    }
}

/// Contents of the conditional info section (80 bytes, `#[repr(C)]`,
/// little-endian). Byte offsets in `core/FORMAT.md`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct ConditionalInfo {
    /// Points per set `n >= 1`.
    pub n: u32,
    /// Instances stored in the point table `S >= 1` (network mode serves any).
    pub instances: u32,
    /// A [`crate::domain::Domain`] code (2 = hemisphere for BRDF samplers).
    pub domain: u32,
    /// A [`ConditionalTarget`] code.
    pub target: u32,
    /// Point-table grid nodes per condition axis, each `>= 2`.
    pub grid: [u32; 2],
    /// Weight-table grid nodes per condition axis, each `>= 2`.
    pub weight_grid: [u32; 2],
    /// Lower end of each condition axis (blob units), finite.
    pub cond_min: [f32; 2],
    /// Upper end of each condition axis, finite and `> cond_min`.
    pub cond_max: [f32; 2],
    /// Hidden widths of the network, first layer first; unused trailing entries 0.
    pub hidden: [u32; MAX_HIDDEN_LAYERS],
    /// An [`Activation`] code.
    pub activation: u32,
    /// The rank-1 lattice generator of the network's input.
    pub lattice_generator: u32,
    /// A [`PointWarp`] code.
    pub warp: u32,
    /// The network's instance slots `M` ([`Shape::with_instance_slots`]): 0, an
    /// offset per instance and one embedding row per index; `M >= 1`, instance `k`
    /// is slot `k mod M`, with its own offset and embedding rows.
    pub instance_slots: u32,
    /// An [`OffsetHash`] code: how instance numbers hash to offsets (0: plain,
    /// blobs baked before the salted hash; 1: salted).
    pub offset_hash: u32,
}

/// Size of [`ConditionalInfo`] in bytes.
pub const CONDITIONAL_INFO_LEN: usize = core::mem::size_of::<ConditionalInfo>();

const _: () = assert!(CONDITIONAL_INFO_LEN == 80);

/// Where a normalized condition falls on an axis of `nodes >= 2` grid nodes: the
/// lower node `j0` (the upper one is `j0 + 1`) and the fraction `t` in `[0,1]`
/// between them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisCell {
    /// The lower node, in `0..nodes - 1`.
    pub j0: u32,
    /// Position between node `j0` (0) and `j0 + 1` (1).
    pub t: f32,
}

impl AxisCell {
    /// The cell of `u` in `[0,1]` on an axis with `nodes` nodes at
    /// `j / (nodes - 1)`: `s = u (nodes - 1)`, `j0 = min(floor(s), nodes - 2)`,
    /// `t = s - j0`. Total: `u` outside `[0,1]` or NaN is clamped (NaN to 0), and
    /// `nodes < 2` gives `j0 = 0, t = 0`.
    #[inline]
    pub fn locate(u: f32, nodes: u32) -> Self {
        if nodes < 2 {
            return Self { j0: 0, t: 0.0 };
        }
        let u = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        let s = u * (nodes - 1) as f32;
        // `s` is in [0, nodes - 1]; the cast truncates (= floor for s >= 0).
        let j0 = (s as u32).min(nodes - 2);
        Self {
            j0,
            t: s - j0 as f32,
        }
    }
}

/// The four grid nodes around a condition and their bilinear weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridCell {
    /// Cell along each axis.
    pub axes: [AxisCell; 2],
    /// Nodes per axis.
    pub nodes: [u32; 2],
}

impl GridCell {
    /// The cell of the normalized condition `u` on a grid of `nodes[0] x nodes[1]`.
    #[inline]
    pub fn locate(u: [f32; 2], nodes: [u32; 2]) -> Self {
        Self {
            axes: [
                AxisCell::locate(u[0], nodes[0]),
                AxisCell::locate(u[1], nodes[1]),
            ],
            nodes,
        }
    }

    /// Linear index `j1 * nodes[0] + j0` of corner `(dx, dy)` (each 0 or 1): axis 0
    /// varies fastest.
    #[inline]
    pub fn node(&self, dx: u32, dy: u32) -> usize {
        let j0 = (self.axes[0].j0 + dx) as usize;
        let j1 = (self.axes[1].j0 + dy) as usize;
        j1 * self.nodes[0] as usize + j0
    }

    /// Bilinear interpolation of the corner values `v00, v10, v01, v11` (`vXY`: X
    /// along axis 0) in this exact order of operations, which readers reproduce
    /// bit for bit: `a = v00 + (v10 - v00) t0`, `b = v01 + (v11 - v01) t0`,
    /// `a + (b - a) t1`.
    #[inline]
    pub fn lerp(&self, v00: f32, v10: f32, v01: f32, v11: f32) -> f32 {
        let (t0, t1) = (self.axes[0].t, self.axes[1].t);
        let a = v00 + (v10 - v00) * t0;
        let b = v01 + (v11 - v01) * t0;
        a + (b - a) * t1
    }

    /// Normalized bilinear interpolation of the corner unit vectors `d00, d10,
    /// d01, d11` (order as [`Self::lerp`]): [`Self::lerp`] per component, then
    /// divided by its length. If the blend has no usable length (opposite corners
    /// cancelling, which the blend of one set's neighbouring points does not do),
    /// `d00`. Unit to `f32` rounding; never panics.
    #[inline]
    pub fn nlerp(&self, d00: [f32; 3], d10: [f32; 3], d01: [f32; 3], d11: [f32; 3]) -> [f32; 3] {
        let m: [f32; 3] = core::array::from_fn(|c| self.lerp(d00[c], d10[c], d01[c], d11[c]));
        let len = libm::sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        if len > 1e-6 && len.is_finite() {
            m.map(|x| x / len)
        } else {
            d00
        }
    }
}

impl ConditionalInfo {
    /// The normalized condition in `[0,1]^2`: each axis clamped into
    /// `[cond_min, cond_max]` (NaN to `cond_min`), then
    /// `(c - cond_min) / (cond_max - cond_min)`.
    #[inline]
    pub fn normalize(&self, c: [f32; 2]) -> [f32; 2] {
        core::array::from_fn(|a| {
            let (lo, hi) = (self.cond_min[a], self.cond_max[a]);
            let x = if c[a].is_nan() {
                lo
            } else {
                c[a].clamp(lo, hi)
            };
            let u = (x - lo) / (hi - lo);
            if u.is_finite() {
                u.clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
    }

    /// The condition (blob units) of a normalized `u`: `cond_min + u (cond_max -
    /// cond_min)` per axis, in `f32` in this order. Of [`Self::normalize`]'s
    /// output, the condition clamped into the range, as the tables see it.
    #[inline]
    pub fn denormalize(&self, u: [f32; 2]) -> [f32; 2] {
        let (lo, hi) = (self.cond_min, self.cond_max);
        core::array::from_fn(|a| lo[a] + u[a] * (hi[a] - lo[a]))
    }

    /// The condition (blob units) of point-table node `(j0, j1)`:
    /// `cond_min + j / (grid - 1) (cond_max - cond_min)` per axis, in `f64` (the
    /// tool evaluates the network there).
    pub fn grid_condition(&self, j: [u32; 2]) -> [f64; 2] {
        node_condition(self, self.grid, j)
    }

    /// The condition of weight-table node `(j0, j1)`, as [`Self::grid_condition`].
    pub fn weight_grid_condition(&self, j: [u32; 2]) -> [f64; 2] {
        node_condition(self, self.weight_grid, j)
    }

    /// The network architecture the info describes, if its counts are valid.
    pub fn shape(&self) -> Option<Shape> {
        self.shape_without_slots()?
            .with_instance_slots(self.instance_slots)
    }

    /// [`Self::shape`] before the instance slots are applied: tells a blob whose
    /// slots overflow the embedding from one whose widths are wrong.
    pub fn shape_without_slots(&self) -> Option<Shape> {
        let layers = self.hidden.iter().take_while(|&&h| h != 0).count();
        if self.hidden[layers..].iter().any(|&h| h != 0) {
            return None;
        }
        let act = Activation::from_code(self.activation)?;
        let residual = PointWarp::from_code(self.warp)?.lattice_residual();
        let offsets = OffsetHash::from_code(self.offset_hash)?;
        Shape::new(self.n, &self.hidden[..layers], act, self.lattice_generator)
            .map(|s| s.with_lattice_residual(residual).with_offset_hash(offsets))
    }

    /// The info's [`PointWarp`], if its code is known.
    pub fn point_warp(&self) -> Option<PointWarp> {
        PointWarp::from_code(self.warp)
    }

    /// Number of `u32` entries of the point table:
    /// `grid[0] grid[1] instances n`, or `None` on overflow.
    pub fn point_table_len(&self) -> Option<u64> {
        (self.grid[0] as u64)
            .checked_mul(self.grid[1] as u64)?
            .checked_mul(self.instances as u64)?
            .checked_mul(self.n as u64)
    }

    /// Number of `f32` entries of one table on the weight grid:
    /// `weight_grid[0] weight_grid[1]`.
    pub fn weight_table_len(&self) -> u64 {
        self.weight_grid[0] as u64 * self.weight_grid[1] as u64
    }

    /// Number of tables in the weight section: the weights, then for
    /// [`PointWarp::BrdfMixture`] the lobe probabilities `p_s`, for
    /// [`PointWarp::BrdfTable`] the metal's albedo (the weights being the
    /// dielectric's; the albedo is linear in metallic between them).
    pub fn weight_tables(&self) -> u64 {
        match self.point_warp() {
            Some(PointWarp::BrdfMixture | PointWarp::BrdfTable) => 2,
            _ => 1,
        }
    }

    /// Index of `(node, instance, index)` in the point table: layout
    /// `[node][instance][index]`.
    #[inline]
    pub fn point_table_index(&self, node: usize, instance: u32, i: u32) -> usize {
        (node * self.instances as usize + instance as usize) * self.n as usize + i as usize
    }
}

fn node_condition(info: &ConditionalInfo, nodes: [u32; 2], j: [u32; 2]) -> [f64; 2] {
    core::array::from_fn(|a| {
        let (lo, hi) = (info.cond_min[a] as f64, info.cond_max[a] as f64);
        let steps = (nodes[a].max(2) - 1) as f64;
        lo + (j[a] as f64 / steps) * (hi - lo)
    })
}

/// The direction of a [`PointWarp::BrdfMixture`] sampler's primary point `u` at the
/// condition `(roughness, theta_o in degrees)` (each clamped into its range) with
/// lobe probability `p_s`: [`crate::warp::brdf_mixture_real`] for the view
/// [`crate::brdf::view_direction_real`] and `alpha = roughness^2`
/// ([`crate::brdf::alpha`]).
#[inline]
pub fn brdf_mixture_direction<T: Real>(cond: [T; 2], p_s: T, u: [T; 2]) -> [T; 3] {
    let wo = crate::brdf::view_direction_real(cond[1]);
    crate::warp::brdf_mixture_real(wo, crate::brdf::alpha(cond[0]), p_s, u)
}

/// The four sections of a conditional blob (kind 3) in the order `core/FORMAT.md`
/// lists them, ready for [`crate::blob::write`]: the info record, the f16
/// parameters, the point table and the weight section (weights, then for
/// [`PointWarp::BrdfMixture`] the lobe probabilities). Checks no length: a reader
/// validates them.
pub fn sections<'s>(
    info: &'s ConditionalInfo,
    params: &'s [u16],
    table: &'s [u32],
    weights: &'s [f32],
) -> [SectionSpec<'s>; 4] {
    [
        SectionSpec {
            tag: SectionTag::ConditionalInfo,
            elem_size: CONDITIONAL_INFO_LEN as u32,
            bytes: bytemuck::bytes_of(info),
        },
        SectionSpec {
            tag: SectionTag::NetworkParams,
            elem_size: 2,
            bytes: bytemuck::cast_slice(params),
        },
        SectionSpec {
            tag: SectionTag::PointTable,
            elem_size: 4,
            bytes: bytemuck::cast_slice(table),
        },
        SectionSpec {
            tag: SectionTag::WeightTable,
            elem_size: 4,
            bytes: bytemuck::cast_slice(weights),
        },
    ]
}

/// The two sections of a BRDF sampler's **metal points** (after
/// [`sections`] and the prior's): the metal layer's own network and point
/// table, of the same shape and layout as [`SectionTag::NetworkParams`] and
/// [`SectionTag::PointTable`], which a query that reads the prior's metal layer
/// ([`crate::brdf_prior::reads_metal_layer`]) takes its primary points from.
/// Checks no length: a reader validates them.
pub fn metal_sections<'s>(params: &'s [u16], table: &'s [u32]) -> [SectionSpec<'s>; 2] {
    [
        SectionSpec {
            tag: SectionTag::MetalNetworkParams,
            elem_size: 2,
            bytes: bytemuck::cast_slice(params),
        },
        SectionSpec {
            tag: SectionTag::MetalPointTable,
            elem_size: 4,
            bytes: bytemuck::cast_slice(table),
        },
    ]
}

/// The salts of [`randomization_shift`]'s two hashes (the shaders hold them too).
pub const RANDOMIZE_SALTS: [u32; 2] = [0x5eed_0b1a, 0x68e3_1da4];

/// The unbiased mode's toroidal shift of primary points for the caller's random
/// number `seed` (e.g. one per pixel): two 24-bit unorms hashed from it
/// ([`crate::network::hash_u32`], salted apart from the instance offsets), in
/// `[0, 1)`. A uniform shift makes any primary point uniform, so each sample of
/// the shifted point is distributed as the warp's pdf (to the shift's `2^-24`
/// resolution), whatever the table or network learned.
#[inline]
pub fn randomization_shift(seed: u32) -> [f32; 2] {
    let a = crate::network::hash_u32(seed ^ RANDOMIZE_SALTS[0]);
    let b = crate::network::hash_u32(a ^ RANDOMIZE_SALTS[1]);
    [offset_unit(a), offset_unit(b)]
}

/// The unbiased mode's primary point of index `i` (mod `n`) for instance
/// `instance` and the caller's random number `seed`: point `i` of the rank-1
/// lattice with generator `g` ([`crate::network::lattice_point`]) shifted on
/// the torus by the instance's offset ([`crate::network::instance_offset`]),
/// then by [`randomization_shift`]`(seed)` ([`torus_shift`] both times).
///
/// A uniform shift makes every point uniform, so each sample of the warp is
/// distributed as its pdf. The table's or network's learned points are not
/// used: a random shift moves them off the places their refinement was learned
/// for, and measured on the held-out conditions a shifted learned set loses to
/// the shifted lattice it was learned from (BRDF sampler 1.16 against 0.92 of
/// the exact warp's Owen-Sobol; docs/results). The lattice keeps its structure
/// under any shift. `O(1)`, never panics.
#[inline]
pub fn randomized_point(n: u32, g: u32, instance: u32, i: u32, seed: u32) -> [f32; 2] {
    let l = crate::network::lattice_point::<f32>(i, n, g);
    let at_instance = torus_shift(l, crate::network::instance_offset(instance));
    torus_shift(at_instance, randomization_shift(seed))
}

/// `p + shift` on the unit torus, per axis `x - floor(x)` in `T`'s arithmetic
/// (`f32` in the runtime and shaders, `f64` in the tool's quality check), a
/// result rounded up to 1 read as 0: in `[0, 1)`. NaN reads as 0. Never panics.
#[inline]
pub fn torus_shift<T: Real>(p: [T; 2], shift: [T; 2]) -> [T; 2] {
    core::array::from_fn(|a| {
        let x = p[a] + shift[a];
        let f = x - x.floor();
        if f >= T::ZERO && f < T::ONE {
            f
        } else {
            T::ZERO
        }
    })
}

/// Packs a square point's u16 unorm codes as one table entry: `x | y << 16`.
#[inline]
pub fn pack_point(qx: u16, qy: u16) -> u32 {
    qx as u32 | (qy as u32) << 16
}

/// Unpacks a table entry into its u16 unorm codes `(w & 0xffff, w >> 16)`.
#[inline]
pub fn unpack_point(w: u32) -> [u16; 2] {
    [(w & 0xffff) as u16, (w >> 16) as u16]
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// Over seeds each unbiased point is uniform (a chi-square over 8 x 8 cells
    /// of one index's points, against the 99.9 % quantile of 63 degrees of
    /// freedom), and for one seed the set is the lattice shifted: differences of
    /// points are lattice vectors mod 1.
    #[test]
    fn the_unbiased_points_are_uniform_and_a_shifted_lattice() {
        let (n, g) = (64, 19);
        let mut counts = [0u32; 64];
        let draws = 64_000u32;
        for seed in 0..draws {
            let p = randomized_point(n, g, 5, 3, seed);
            assert!(p.iter().all(|c| (0.0..1.0).contains(c)));
            counts[(p[0] * 8.0) as usize + 8 * (p[1] * 8.0) as usize] += 1;
        }
        let expected = draws as f64 / 64.0;
        let chi2: f64 = counts
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        assert!(chi2 < 103.4, "chi-square {chi2}");
        let set: std::vec::Vec<[f32; 2]> =
            (0..n).map(|i| randomized_point(n, g, 2, i, 99)).collect();
        for i in 1..n as usize {
            let d = [0, 1].map(|a| {
                let x = (set[i][a] - set[0][a]) * n as f32;
                x - x.round()
            });
            assert!(d.iter().all(|e| e.abs() < 1e-3), "{i}: {d:?}");
            let want = crate::network::lattice_point::<f32>(i as u32, n, g);
            let got = [0, 1].map(|a| (set[i][a] - set[0][a]).rem_euclid(1.0));
            assert!((got[0] - want[0]).abs() < 1e-4 || (got[0] - want[0]).abs() > 1.0 - 1e-4);
            assert!((got[1] - want[1]).abs() < 1e-4 || (got[1] - want[1]).abs() > 1.0 - 1e-4);
        }
        // Another instance, another set; the index wraps.
        assert_ne!(randomized_point(n, g, 3, 0, 99), set[0]);
        assert_eq!(randomized_point(n, g, 2, n, 99), set[0]);
    }

    fn info() -> ConditionalInfo {
        ConditionalInfo {
            n: 4,
            instances: 2,
            domain: 2,
            target: 1,
            grid: [3, 5],
            weight_grid: [4, 4],
            cond_min: [0.1, 0.0],
            cond_max: [1.0, 89.0],
            hidden: [8, 8, 0],
            activation: 0,
            lattice_generator: 3,
            warp: 0,
            instance_slots: 0,
            offset_hash: 1,
        }
    }

    #[test]
    fn denormalize_gives_the_clamped_condition() {
        let inf = info();
        let back = |c: [f32; 2]| inf.denormalize(inf.normalize(c));
        assert_eq!(back([0.1, 0.0]), [0.1, 0.0]);
        assert_eq!(back([-3.0, 200.0]), [0.1, 89.0]);
        assert_eq!(back([f32::NAN, f32::NAN]), [0.1, 0.0]);
        let c = back([0.55, 30.0]);
        assert!(
            (c[0] - 0.55).abs() < 1e-6 && (c[1] - 30.0).abs() < 1e-5,
            "{c:?}"
        );
    }

    /// The equal-area maps scale area by the domain's area (4 pi, 2 pi): the cross
    /// product of the two difference columns has that length away from the maps'
    /// creases (the octahedral map's `|u| + |v| = 1` and axes, the concentric
    /// map's diagonals, with `u = 2 p - 1`).
    #[test]
    fn direction_differences_of_the_equal_area_maps_have_their_area_scale() {
        for domain in [Domain::Sphere, Domain::Hemisphere] {
            for p in [[0.3, 0.12], [0.62, 0.41], [0.15, 0.7], [0.8, 0.9]] {
                let [jx, jy] = PointWarp::EqualArea
                    .direction_differences(domain, [0.0; 2], 0.0, None, p, 1e-6);
                let cross = [
                    jx[1] * jy[2] - jx[2] * jy[1],
                    jx[2] * jy[0] - jx[0] * jy[2],
                    jx[0] * jy[1] - jx[1] * jy[0],
                ];
                let area = cross.iter().map(|c| c * c).sum::<f64>().sqrt();
                assert!(
                    (area - domain.area()).abs() < 1e-5,
                    "{domain:?} {p:?}: {area}"
                );
            }
        }
    }

    #[test]
    fn axis_cells_cover_the_range_and_clamp() {
        assert_eq!(AxisCell::locate(0.0, 3), AxisCell { j0: 0, t: 0.0 });
        assert_eq!(AxisCell::locate(1.0, 3), AxisCell { j0: 1, t: 1.0 });
        assert_eq!(AxisCell::locate(0.75, 3), AxisCell { j0: 1, t: 0.5 });
        assert_eq!(AxisCell::locate(f32::NAN, 3), AxisCell { j0: 0, t: 0.0 });
        assert_eq!(AxisCell::locate(7.0, 3), AxisCell { j0: 1, t: 1.0 });
        assert_eq!(AxisCell::locate(0.5, 0), AxisCell { j0: 0, t: 0.0 });
    }

    #[test]
    fn lerp_reproduces_corners_and_bilinear_functions() {
        let cell = GridCell::locate([0.25, 0.6], [3, 5]);
        let f = |x: f32, y: f32| 2.0 + 3.0 * x - y + 0.5 * x * y;
        let (x0, x1) = (0.0, 0.5);
        let (y0, y1) = (0.5, 0.75);
        let v = cell.lerp(f(x0, y0), f(x1, y0), f(x0, y1), f(x1, y1));
        assert!((v - f(0.25, 0.6)).abs() < 1e-6);
        assert_eq!(cell.node(0, 0), 2 * 3);
        assert_eq!(cell.node(1, 1), 3 * 3 + 1);
    }

    /// `nlerp` returns the corners at the corners, unit vectors in between, the
    /// bilinear blend's direction, and `d00` when the blend vanishes.
    #[test]
    fn nlerp_blends_directions_and_stays_unit() {
        let d = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.6, 0.0, 0.8],
        ];
        let at = |u: [f32; 2]| GridCell::locate(u, [2, 2]).nlerp(d[0], d[1], d[2], d[3]);
        assert_eq!(at([0.0, 0.0]), d[0]);
        assert_eq!(at([1.0, 1.0]), d[3]);
        let m = at([0.5, 0.0]);
        let h = core::f32::consts::FRAC_1_SQRT_2;
        assert!((m[0] - h).abs() < 1e-6 && (m[1] - h).abs() < 1e-6 && m[2] == 0.0);
        let c = at([0.3, 0.7]);
        assert!((c.iter().map(|x| x * x).sum::<f32>() - 1.0).abs() < 1e-6);
        let flat = GridCell::locate([0.5, 0.0], [2, 2]);
        let x = [1.0, 0.0, 0.0];
        assert_eq!(flat.nlerp(x, [-1.0, 0.0, 0.0], x, x), x);
    }

    #[test]
    fn targets_have_their_domains() {
        assert_eq!(
            ConditionalTarget::from_code(2),
            Some(ConditionalTarget::EnvmapNormal)
        );
        assert_eq!(ConditionalTarget::EnvmapNormal.domain(), Domain::Sphere);
        assert_eq!(ConditionalTarget::GltfBrdf.domain(), Domain::Hemisphere);
        assert_eq!(ConditionalTarget::from_code(3), None);
    }

    #[test]
    fn normalize_clamps_and_maps_nan_to_the_lower_end() {
        let inf = info();
        assert_eq!(inf.normalize([0.1, 0.0]), [0.0, 0.0]);
        assert_eq!(inf.normalize([5.0, -3.0]), [1.0, 0.0]);
        assert_eq!(inf.normalize([f32::NAN, f32::INFINITY]), [0.0, 1.0]);
        let u = inf.normalize([0.55, 44.5]);
        assert!((u[0] - 0.5).abs() < 1e-6 && (u[1] - 0.5).abs() < 1e-6);
        let c = inf.grid_condition([2, 4]);
        assert!((c[0] - 1.0).abs() < 1e-7 && (c[1] - 89.0).abs() < 1e-9);
    }

    #[test]
    fn shape_and_table_sizes_follow_the_counts() {
        let inf = info();
        let s = inf.shape().unwrap();
        assert_eq!(s.hidden(), &[8, 8]);
        assert_eq!(inf.point_table_len(), Some(3 * 5 * 2 * 4));
        assert_eq!(inf.weight_table_len(), 16);
        assert_eq!(inf.point_table_index(3, 1, 2), (3 * 2 + 1) * 4 + 2);
        let mut gap = inf;
        gap.hidden = [8, 0, 8];
        assert!(gap.shape().is_none());
        assert_eq!(unpack_point(pack_point(7, 65535)), [7, 65535]);
    }
}
