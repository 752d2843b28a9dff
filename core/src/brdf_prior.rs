//! The BRDF sampler's prior: the glTF metallic-roughness BRDF times the cosine,
//! `f(wo, wi) max(n.wi, 0)` ([`crate::brdf::gltf_metallic`], base colour 1),
//! tabulated in the half vector's equal-area square for each node of a grid of
//! conditions `(roughness, θo, metallic)` and sampled exactly between the nodes
//! ([`crate::marginal2d`]).
//!
//! **Nodes.** `G_r x G_t x G_m` conditions at the vertices of a regular grid over
//! roughness `[MIN_ROUGHNESS, MAX_ROUGHNESS]`, `θo` `[0°, MAX_THETA_O_DEG]` and
//! metallic `[0, 1]` (`G_m` 2, or 3 with the metal layer below), the `θo` axis
//! warped so that the nodes crowd towards grazing views ([`theta_o_of_unit`]: a
//! smooth metal's lobe, cut by the horizon, changes fastest there; a lattice
//! through the prior at a metal of roughness 0.13 seen at 85° scores 2.1 of the
//! exact warp's Owen-Sobol instead of 4.8 with uniform nodes); node `(i, j, l)`
//! is table `i + G_r (j + G_t l)` ([`node_condition`]). The view is the
//! xz-plane one of [`crate::brdf::view_direction`].
//!
//! **The half-vector square.** A table point `p` is the hemisphere direction
//! `h' = square_to_hemisphere(p)`, the half vector is `h'` with its slopes
//! scaled, `h = normalize(g h'.x, g h'.y, h'.z)`, and the light direction is
//! the mirror of the view about it, `wi = 2 (wo.h) h - wo`. The specular peak
//! sits at `h = n` for every view, so tables of neighbouring `θo` agree where
//! the lobe is (a direction square needs twice the conditions for the same
//! quality). The scale `g` is the shared layers' **radial square**
//! ([`radial_square`], [`radial_direction`]): `roughness` near the pole, where
//! the specular spike is, so that a smooth lobe spans many cells, and
//! `roughness^(1/4)` ([`stretch`]) beyond the slope [`RADIAL_CROSSOVER`], where
//! the diffuse lobe is (a shifted lattice through the prior at N = 256 on 48
//! held-out conditions: 0.997 of the exact warp's Owen-Sobol, worst 1.56,
//! against 1.038 and 1.86 with one stretch `roughness^(1/4)` everywhere, the
//! blobs before tag 24, now refused; the single stretch itself had taken the
//! plain half vector's 0.936 and 1.22 to 0.922 and 1.08 at N = 64). A point
//! whose `wi` falls below the horizon (or with `wo.h <= 0`) has no direction: a
//! table tabulated from the target holds 0 there, and the bilinear
//! interpolant's rare leak into it returns `(+z, pdf 0)`.
//!
//! **Blending: exact in metallic.** The tables are normalized, and each node's
//! mass before normalization (the tabulated albedo over `2π`) is stored beside
//! them. A query blends the nodes around it with multilinear weights *times
//! their masses* ([`BrdfPrior::blend`]): it samples the interpolation of the
//! unnormalized target `f cos`. The target is linear in metallic, `f_m = (1 - m)
//! f_0 + m f_1`, so two metallic nodes (`G_m = 2`) reproduce every metallic
//! exactly, up to the tabulation of the ends.
//!
//! **The metal layer** (`G_m = 3`, [`has_metal_layer`]). The blend is exact
//! only if both metallic nodes share the square, so the shared square's stretch
//! is the dielectric's compromise, which leaves a smooth metal's lobe (all of
//! its mass) a cell or two wide. A third layer of `G_r x G_t` nodes holds the
//! metal again, in its own square, the star disc of zoom [`metal_zoom`] `α =
//! roughness^2` ([`star_direction`]): its centre is the mirror direction and
//! its rim the horizon for every view, so every node's lobe spans the same
//! share of its table and the horizon cuts it at the same place. A query at
//! metallic 1 exactly reads the layer alone (four nodes), one below metallic 1
//! the first two layers. The sampled density jumps at metallic 1 (both sides
//! exact, with their own pdfs); most materials are metallic 0 or 1. A shifted
//! lattice through the prior at 48 conditions, smooth metals among them: 0.959
//! of the exact warp's Owen-Sobol, worst 2.35, without the layer; 0.940, worst
//! 1.48, with the stretched square `k = roughness` (blobs before tag 23, now
//! refused); 0.927, worst 1.25, with the star disc.
//!
//! **Densities.** The warp's pdf per unit area of the square over `2π` is `h'`'s
//! per steradian (the map is equal-area), so the light direction's pdf is
//! `pdf_square / (2π J)`, `J = |dwi/dω_h'|` the square's Jacobian
//! ([`radial_direction`]: `4 (wo.h) g σ'(t) / L^3`, `L = |(g h'.x, g h'.y,
//! h'.z)|`; the metal layer's: [`star_direction`]). Whatever the tables
//! approximate, [`BrdfPrior::pdf`] is the density of [`BrdfPrior::sample`]'s
//! directions: `f cos / pdf` is an unbiased estimate of the albedo.

use crate::brdf::{
    clamp_metallic, clamp_roughness, clamp_theta_o_deg, gltf_metallic, view_direction_real,
    MAX_METALLIC, MAX_ROUGHNESS, MAX_THETA_O_DEG, MIN_METALLIC, MIN_ROUGHNESS,
};
use crate::marginal2d::{Blend, Marginal2D, Marginal2DError, Marginal2DShape, MAX_BLEND};
use crate::real::Real;
use bytemuck::{Pod, Zeroable};

mod square;
pub use square::{
    half_vector_direction, half_vector_of, half_vector_point, horizon_reach, metal_zoom, mirror,
    radial_direction, radial_point, radial_square, star_direction, star_point, PriorSquare,
    RADIAL_CROSSOVER, RADIAL_INVERSE_STEPS,
};

/// The prior's info section (16 bytes, `#[repr(C)]`, little-endian): the
/// condition grid and the tables' vertices per axis.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct BrdfPriorInfo {
    /// Nodes per condition axis `[G_r, G_t, G_m]`, each at least 2.
    pub grid: [u32; 3],
    /// Vertices per axis of each node's square table, at least 2.
    pub size: u32,
}

/// Size of [`BrdfPriorInfo`] in bytes.
pub const BRDF_PRIOR_INFO_LEN: usize = core::mem::size_of::<BrdfPriorInfo>();

const _: () = assert!(BRDF_PRIOR_INFO_LEN == 16);

/// Most vertices per table axis a blob may declare (a table of `4096^2` values is
/// 64 MiB, more than any prior needs).
pub const MAX_PRIOR_SIZE: u32 = 4096;

/// Most nodes per condition axis a blob may declare.
pub const MAX_PRIOR_GRID: u32 = 256;

impl BrdfPriorInfo {
    /// Node tables `G_r G_t G_m`; `None` unless the roughness and view axes
    /// have 2 to [`MAX_PRIOR_GRID`] nodes, the metallic axis 2 or 3 (the metal
    /// layer, [`has_metal_layer`]), and the size is 2 to [`MAX_PRIOR_SIZE`].
    pub fn nodes(&self) -> Option<u32> {
        let grid_ok = self.grid[..2]
            .iter()
            .all(|g| (2..=MAX_PRIOR_GRID).contains(g))
            && (2..=3).contains(&self.grid[2]);
        (grid_ok && (2..=MAX_PRIOR_SIZE).contains(&self.size))
            .then(|| self.grid[0] * self.grid[1] * self.grid[2])
    }

    /// The tables' shape ([`Self::nodes`] tables of `size x size` vertices).
    pub fn shape(&self) -> Option<Marginal2DShape> {
        Some(Marginal2DShape {
            size: [self.size; 2],
            nodes: self.nodes()?,
        })
    }
}

/// The five sections of a BRDF prior, in the order `core/FORMAT.md` lists them,
/// ready for [`crate::blob::write`] (after a conditional blob's own,
/// [`crate::conditional::sections`]). Checks no length: a reader validates them.
pub fn sections<'s>(
    info: &'s BrdfPriorInfo,
    data: &'s [f32],
    marginal: &'s [f32],
    conditional: &'s [f32],
    masses: &'s [f32],
) -> [crate::blob::SectionSpec<'s>; 5] {
    use crate::blob::{SectionSpec, SectionTag};
    let table = |tag, values: &'s [f32]| SectionSpec {
        tag,
        elem_size: 4,
        bytes: bytemuck::cast_slice(values),
    };
    [
        SectionSpec {
            tag: SectionTag::BrdfPriorInfo,
            elem_size: BRDF_PRIOR_INFO_LEN as u32,
            bytes: bytemuck::bytes_of(info),
        },
        table(SectionTag::BrdfPriorData, data),
        table(SectionTag::BrdfPriorMarginal, marginal),
        table(SectionTag::BrdfPriorConditional, conditional),
        table(SectionTag::BrdfPriorMasses, masses),
    ]
}

/// Whether a prior on `grid` has the metal layer: `G_m = 3`, the third layer of
/// nodes holding metallic 1 again, tabulated in the metal's own square
/// ([`metal_zoom`], [`star_direction`]) and read only at metallic 1 (module
/// docs).
#[inline]
pub fn has_metal_layer(grid: [u32; 3]) -> bool {
    grid[2] == 3
}

/// Whether a query at `metallic` (clamped) on `grid` reads the metal layer:
/// metallic 1 exactly, on a grid that has one ([`has_metal_layer`]).
#[inline]
pub fn reads_metal_layer<T: Real>(grid: [u32; 3], metallic: T) -> bool {
    has_metal_layer(grid) && clamp_metallic(metallic) >= T::ONE
}

/// The square a query at `cond = [roughness, θo, metallic]` reads on `grid`:
/// the metal layer's star disc of zoom [`metal_zoom`] where it reads that layer
/// ([`reads_metal_layer`]), else the shared layers' [`radial_square`].
#[inline]
pub fn query_square<T: Real>(grid: [u32; 3], cond: [T; 3]) -> PriorSquare<T> {
    match reads_metal_layer(grid, cond[2]) {
        true => PriorSquare::Star(metal_zoom(cond[0])),
        false => radial_square(cond[0]),
    }
}

/// Whether node `node` of `grid` is one of the metal layer's (layer 2 of a grid
/// with the layer, [`has_metal_layer`]).
#[inline]
pub fn is_metal_layer_node(grid: [u32; 3], node: u32) -> bool {
    has_metal_layer(grid) && node / (grid[0].max(1) * grid[1].max(1)) >= 2
}

/// The square node `node` of `grid` is tabulated in: the star disc of zoom
/// [`metal_zoom`] for the metal layer's nodes ([`is_metal_layer_node`]), else
/// the shared layers' [`radial_square`], at the node's roughness.
pub fn node_square(grid: [u32; 3], node: u32) -> PriorSquare<f64> {
    let r = node_condition(grid, node)[0];
    match is_metal_layer_node(grid, node) {
        true => PriorSquare::Star(metal_zoom(r)),
        false => radial_square(r),
    }
}

/// The condition `[roughness, θo in degrees, metallic]` of node `node` of `grid`
/// (module docs; an axis of fewer than 2 nodes sits at its lower end; the metal
/// layer's nodes, [`has_metal_layer`], at metallic 1).
pub fn node_condition(grid: [u32; 3], node: u32) -> [f64; 3] {
    let at = |i: u32, count: u32, lo: f64, hi: f64| match count {
        0 | 1 => lo,
        c => lo + (hi - lo) * i as f64 / (c - 1) as f64,
    };
    let g0 = grid[0].max(1);
    let g1 = grid[1].max(1);
    let (i, rest) = (node % g0, node / g0);
    let (j, l) = (rest % g1, rest / g1);
    [
        at(i, grid[0], MIN_ROUGHNESS, MAX_ROUGHNESS),
        theta_o_of_unit(at(j, grid[1], 0.0, 1.0)),
        match has_metal_layer(grid) {
            true => at(l.min(1), 2, MIN_METALLIC, MAX_METALLIC),
            false => at(l, grid[2], MIN_METALLIC, MAX_METALLIC),
        },
    ]
}

/// The view angle in degrees of the unit coordinate `u` of the `θo` axis:
/// `θo = 89 (1 - (1 - u)^2)`, nodes uniform in `u` crowd towards grazing
/// views, where the lobes change fastest with the view (the horizon cuts them).
/// The inverse of [`unit_condition`]'s `θo` coordinate, `u = 1 - sqrt(1 - θo /
/// 89)`.
pub fn theta_o_of_unit(u: f64) -> f64 {
    let v = 1.0 - u.clamp(0.0, 1.0);
    MAX_THETA_O_DEG * (1.0 - v * v)
}

/// The condition `[roughness, θo in degrees, metallic]` clamped into the
/// prior's ranges (NaN to their lower ends) and placed on `[0,1]^3`: roughness
/// and metallic linearly, `θo` as `1 - sqrt(1 - θo / 89)` ([`theta_o_of_unit`]).
#[inline]
pub fn unit_condition<T: Real>(cond: [T; 3]) -> [T; 3] {
    let r = clamp_roughness(cond[0]);
    let t = clamp_theta_o_deg(cond[1]);
    let m = clamp_metallic(cond[2]);
    let rest = (T::ONE - t / T::of(MAX_THETA_O_DEG)).max(T::ZERO);
    [
        (r - T::of(MIN_ROUGHNESS)) / T::of(MAX_ROUGHNESS - MIN_ROUGHNESS),
        T::ONE - rest.sqrt(),
        (m - T::of(MIN_METALLIC)) / T::of(MAX_METALLIC - MIN_METALLIC),
    ]
}

/// The stretch `k = roughness^(1/4)` at `roughness` (clamped into
/// `[MIN_ROUGHNESS, MAX_ROUGHNESS]`), two square roots: the radial square's
/// `k_b`, far from the pole, where the diffuse lobe is ([`radial_square`];
/// before tag 24 the one stretch of the whole shared square). 1 at roughness 1.
#[inline]
pub fn stretch<T: Real>(roughness: T) -> T {
    clamp_roughness(roughness).sqrt().sqrt()
}

/// `roughness^power` at the clamped `roughness`: the stretch of other
/// exponents, for the build tool's measurements ([`stretch`] is the exponent
/// `1/4`; `power = 0` is the plain half vector).
#[inline]
pub fn stretch_with<T: Real>(roughness: T, power: T) -> T {
    if power == T::ZERO {
        return T::ONE;
    }
    (clamp_roughness(roughness).ln() * power).exp()
}

/// The blend at `cond = [roughness, θo in degrees, metallic]` (clamped,
/// [`unit_condition`]) on a node grid `grid` whose node `k` has mass
/// `masses[k]`: the multilinear weights of the (up to 8) nodes around it times
/// their masses, so that a warp over the normalized tables samples the
/// interpolated unnormalized target (module docs). A node past `masses` weighs
/// 0. The one blend of [`BrdfPrior::blend`] and the build tool's priors.
///
/// With the metal layer ([`has_metal_layer`]) a query below metallic 1 blends
/// the first two layers (metallic 0 and 1 in the shared square), and one at
/// metallic 1 the metal layer's four nodes around `(roughness, θo)` alone
/// ([`reads_metal_layer`]).
#[inline]
pub fn mass_weighted_blend<T: Real>(grid: [u32; 3], masses: &[T], cond: [T; 3]) -> Blend<T> {
    let unit = unit_condition(cond);
    let (multilinear, first) = if reads_metal_layer(grid, cond[2]) {
        let layer = grid[0].saturating_mul(grid[1]);
        (
            Blend::multilinear(&unit[..2], &grid[..2]),
            layer.saturating_mul(2),
        )
    } else {
        // Below metallic 1 the metallic axis spans the first two layers.
        let metallic_nodes = if has_metal_layer(grid) { 2 } else { grid[2] };
        let counts = [grid[0], grid[1], metallic_nodes];
        (Blend::multilinear(&unit, &counts), 0)
    };
    let mut pairs = [(0u32, T::ZERO); MAX_BLEND];
    let mut len = 0;
    for (node, w) in multilinear.pairs() {
        let node = node.saturating_add(first);
        let mass = masses.get(node as usize).copied().unwrap_or(T::ZERO);
        if let Some(slot) = pairs.get_mut(len) {
            *slot = (node, w * mass);
            len += 1;
        }
    }
    Blend::from_pairs(&pairs[..len])
}

/// The tabulated BRDF prior over borrowed tables (module docs): node tables as
/// [`crate::marginal2d::tabulate`] writes them and each node's mass.
#[derive(Clone, Copy, Debug)]
pub struct BrdfPrior<'a, T> {
    grid: [u32; 3],
    warp: Marginal2D<'a, T>,
    masses: &'a [T],
}

impl<'a, T: Real> BrdfPrior<'a, T> {
    /// The prior over `info`'s tables, every value checked
    /// ([`Marginal2D::new`]) and every mass finite and positive. `O(nodes
    /// size^2)`, once.
    pub fn new(
        info: BrdfPriorInfo,
        data: &'a [T],
        marginal: &'a [T],
        conditional: &'a [T],
        masses: &'a [T],
    ) -> Result<Self, Marginal2DError> {
        Self::build(info, [data, marginal, conditional], masses, true)
    }

    /// The prior over tables that [`Self::new`] has checked before: shape and
    /// lengths only, `O(1)`. Never panics on any values.
    pub fn view(
        info: BrdfPriorInfo,
        data: &'a [T],
        marginal: &'a [T],
        conditional: &'a [T],
        masses: &'a [T],
    ) -> Result<Self, Marginal2DError> {
        Self::build(info, [data, marginal, conditional], masses, false)
    }

    /// [`Self::new`] (`check`: every value) or [`Self::view`] (lengths only).
    fn build(
        info: BrdfPriorInfo,
        [data, marginal, conditional]: [&'a [T]; 3],
        masses: &'a [T],
        check: bool,
    ) -> Result<Self, Marginal2DError> {
        let shape = info.shape().ok_or(Marginal2DError::Shape)?;
        let warp = match check {
            true => Marginal2D::new(shape, data, marginal, conditional)?,
            false => Marginal2D::view(shape, data, marginal, conditional)?,
        };
        let nodes = shape.nodes;
        if masses.len() != nodes as usize {
            return Err(Marginal2DError::Length {
                slice: 3,
                expected: nodes as u64,
                got: masses.len() as u64,
            });
        }
        if check {
            if let Some(i) = masses.iter().position(|&m| !(m > T::ZERO && m.is_finite())) {
                return Err(Marginal2DError::NoMass { node: i as u32 });
            }
        }
        Ok(Self {
            grid: info.grid,
            warp,
            masses,
        })
    }

    /// Nodes per condition axis `[G_r, G_t, G_m]`.
    pub fn grid(&self) -> [u32; 3] {
        self.grid
    }

    /// The blend at `cond = [roughness, θo in degrees, metallic]` (clamped,
    /// [`unit_condition`]): the multilinear weights of the (up to 8) nodes
    /// around it times the nodes' masses, so that the warp samples the
    /// interpolated unnormalized target (module docs).
    #[inline]
    pub fn blend(&self, cond: [T; 3]) -> Blend<T> {
        mass_weighted_blend(self.grid, self.masses, cond)
    }

    /// The light direction of primary sample `u` in `[0,1]^2` (clamped) for the
    /// xz-plane view of `cond = [roughness, θo in degrees, metallic]`, and its
    /// solid-angle pdf (per steradian); `(+z, 0)` for a point without a
    /// direction (module docs), and where the pdf overflows (only tables with
    /// values near the float range do). `O(8 log size)`, never panics.
    #[inline]
    pub fn sample(&self, cond: [T; 3], u: [T; 2]) -> ([T; 3], T) {
        self.sample_from(view_direction_real(cond[1]), cond, u)
    }

    /// [`Self::sample`] and the estimator weight of its direction, `f cos /
    /// pdf` with `f` the glTF BRDF at `cond` ([`gltf_metallic`]) and `cos` the
    /// direction's `z` (0 where the pdf is 0 or the weight is not finite): what
    /// a sampler returns per sample, with the view direction worked out once.
    #[inline]
    pub fn sample_weighted(&self, cond: [T; 3], u: [T; 2]) -> ([T; 3], T, T) {
        let wo = view_direction_real(cond[1]);
        let (wi, pdf) = self.sample_from(wo, cond, u);
        let weight = match pdf > T::ZERO {
            true => gltf_metallic(wo, wi, cond[0], cond[2]) * wi[2] / pdf,
            false => T::ZERO,
        };
        (wi, pdf, if weight.is_finite() { weight } else { T::ZERO })
    }

    /// The table point of primary sample `u` at `cond`, before the half-vector
    /// map ([`Self::sample`]'s direction is [`query_square`]'s
    /// [`PriorSquare::direction`] of it), its density in the square and its
    /// slopes `[dx/du.x, dx/du.y, dy/du.y]` ([`Marginal2D::sample_with_slopes`]). What a trainer
    /// chains its gradients through.
    pub fn square_with_slopes(&self, cond: [T; 3], u: [T; 2]) -> ([T; 2], T, [T; 3]) {
        self.warp.sample_with_slopes(u, &self.blend(cond))
    }

    /// [`Self::sample`] for the view `wo` of `cond` (`view_direction_real(cond[1])`).
    #[inline]
    fn sample_from(&self, wo: [T; 3], cond: [T; 3], u: [T; 2]) -> ([T; 3], T) {
        let (p, pdf) = self.warp.sample(u, &self.blend(cond));
        let dead = ([T::ZERO, T::ZERO, T::ONE], T::ZERO);
        match query_square(self.grid, cond).direction(wo, p) {
            Some((wi, jac)) => {
                let pdf = pdf / (T::of(2.0) * T::PI * jac);
                // Only tables near the float range (a hostile blob's) overflow.
                if pdf.is_finite() {
                    (wi, pdf)
                } else {
                    dead
                }
            }
            None => dead,
        }
    }

    /// The solid-angle pdf of [`Self::sample`]'s directions at the unit
    /// direction `wi` (xz-plane view); 0 where the prior draws nothing (and
    /// where the pdf overflows, as [`Self::sample`]).
    #[inline]
    pub fn pdf(&self, cond: [T; 3], wi: [T; 3]) -> T {
        let wo = view_direction_real(cond[1]);
        match query_square(self.grid, cond).point(wo, wi) {
            Some((p, jac)) => {
                let pdf = self.warp.pdf(p, &self.blend(cond)) / (T::of(2.0) * T::PI * jac);
                if pdf.is_finite() {
                    pdf
                } else {
                    T::ZERO
                }
            }
            None => T::ZERO,
        }
    }

    /// The primary sample that [`Self::sample`] maps to the unit direction `wi`;
    /// `None` where no table point maps to `wi`.
    pub fn invert(&self, cond: [T; 3], wi: [T; 3]) -> Option<[T; 2]> {
        let wo = view_direction_real(cond[1]);
        let (p, _) = query_square(self.grid, cond).point(wo, wi)?;
        Some(self.warp.invert(p, &self.blend(cond)))
    }
}

#[cfg(test)]
mod tests;
