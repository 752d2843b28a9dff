//! A tabulated conditional warp of the glTF metallic-roughness BRDF, the candidate
//! prior of the BRDF sampler: `f(wo, wi) max(n.wi, 0)` tabulated on a square for
//! each node of a grid of conditions `(roughness, θo, metallic)`, blended
//! trilinearly between the nodes and sampled exactly ([`nuld_core::marginal2d`]).
//!
//! * **Nodes**: `G_r x G_t x G_m` conditions at the vertices of a regular grid over
//!   roughness `[0.1, 1]`, `θo` `[0°, 89°]` (crowding towards grazing,
//!   [`nuld_core::brdf_prior::theta_o_of_unit`]) and metallic `[0, 1]`. Before
//!   normalization the target is linear in metallic, and the blend weighs each
//!   node by its mass before normalization (the tabulated albedo), so two
//!   metallic nodes reproduce every metallic exactly
//!   ([`nuld_core::brdf_prior`]).
//! * **Space** ([`PriorSpace`]): the square of the tables is the hemisphere's
//!   equal-area square of either the light direction `wi` itself, or of the half
//!   vector `h`, with `wi = reflect(wo, h) = 2 (wo.h) h - wo`, its slopes
//!   stretched by powers of the roughness (the blob's: `roughness` near the
//!   pole and `roughness^(1/4)` beyond, [`nuld_core::brdf_prior::radial_square`];
//!   the metal layer's star disc, [`nuld_core::brdf_prior::star_direction`]). In half-vector space the specular peak
//!   sits at `h = n` for every view, so tables of neighbouring `θo` agree where
//!   the lobe is; the density there is the direction's times the Jacobian
//!   `|dwi/dω_h'|` (0 where `wo.h <= 0` or `wi` is below the horizon).
//! * **Tables**: `S x S` vertices; vertex `(i, j)` holds the mean of the density
//!   over `k x k` points of its dual cell clipped to the square (`k` from
//!   [`SUPERSAMPLED_AXIS`]), so a lobe narrower than the vertex spacing still
//!   lands in the table.
//! * **Exactness**: whatever the tables approximate, the warp's pdf is the density
//!   of its samples (`f cos / pdf` is an unbiased estimate); how well the tables
//!   follow `f cos` decides the variance and how much low discrepancy survives
//!   the warp (`build-tool eval brdf-prior`).

use super::envmap_prior::tabulated;
use super::horizon_disc::{HorizonDisc, HorizonMap, StarDisc};
use super::radial_half_vector::RadialMap;
use crate::progress::Progress;
use glam::{DVec2, DVec3};
use nuld_core::brdf::{gltf_metallic, gltf_metallic_ends, view_direction};
use nuld_core::brdf_prior::{
    is_metal_layer_node, mass_weighted_blend, metal_zoom, node_condition, radial_square,
    reads_metal_layer, stretch_with, BrdfPriorInfo, PriorSquare,
};
use nuld_core::marginal2d::{Blend, Marginal2D, Marginal2DError, Marginal2DShape};
use nuld_core::sphere::{hemisphere_to_square, square_to_hemisphere};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Points per axis of the supersampling grid over the whole square (the `k` of
/// the module docs is this over the table's vertices, at least 1).
pub const SUPERSAMPLED_AXIS: u32 = 1024;

/// The BRDF sampler's prior grid `[G_r, G_t, G_m]`: metallic 0 and 1 (two
/// metallic nodes are exact, module docs) and the metal layer
/// ([`nuld_core::brdf_prior::has_metal_layer`]); 10 x 12 conditions in
/// half-vector tables are where more nodes stopped paying (`eval brdf-prior`,
/// docs/results/brdf-prior.md). The metal layer, on `eval brdf-prior
/// --conditions 48` (smooth metals among them), a shifted lattice through the
/// prior: 0.959 of the exact warp's Owen-Sobol, worst 2.35, without it; 0.940,
/// worst 1.48, with it (+50 % state, 26.7 MB).
pub const PRIOR_GRID: [u32; 3] = [10, 12, 3];

/// The BRDF sampler's prior table size: 96 vertices per axis (64: 7.9 MB of
/// state with two metallic layers, a shifted lattice 0.979 of the exact warp's
/// Owen-Sobol; 96: 17.8 MB, 0.936; 128: 31.6 MB, 0.919). On the 48 conditions
/// above, without the metal layer, 128 vertices took the worst from 2.35 to
/// 1.70 and the mean from 0.959 to 0.939, and trained (N = 64) the mean from
/// 0.866 to 0.853 but the default judge's worst from 0.927 to 0.977: the metal
/// layer does more for less.
pub const PRIOR_SIZE: u32 = 96;

/// Which square the tables live on (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum PriorSpace {
    /// The equal-area square of the light direction `wi`.
    Direction,
    /// The equal-area square of the half vector `h`, its slopes divided by the
    /// blob's radial stretch at the condition's roughness
    /// ([`nuld_core::brdf_prior::radial_square`]), the metal layer's in the
    /// star disc ([`nuld_core::brdf_prior::star_direction`]): the blob's prior.
    HalfVector,
    /// The half vector's square with the slopes divided by `roughness^p`, `p`
    /// the hundredths held here (0: the plain half vector), the metal layer's
    /// in the star disc as [`Self::HalfVector`]'s; for measurements.
    HalfVectorPower {
        /// The stretch's exponent in hundredths.
        stretch_percent: u32,
    },
    /// The half vector's square under a radial stretch and an in-plane
    /// anisotropy ([`super::radial_half_vector`]); for measurements. Each layer
    /// holds `[A, B, C, Q]` in hundredths: `k_s = roughness^(A/100)`, `k_b =
    /// roughness^(B/100)`, the crossover `a = C/100` (> 0) and `β = max(cos θo,
    /// 0.05)^(Q/100)`. `[100, 25, 25, 0]` is the blob's shared square
    /// ([`nuld_core::brdf_prior::radial_square`]), `[25, 25, C, 0]` the one
    /// stretch of blobs before it; `[100, 100, C, 0]` the stretched metal
    /// square of blobs before the star disc.
    Radial {
        /// The shared square's (metallic 0 and 1).
        shared: [u32; 4],
        /// The metal layer's.
        metal: [u32; 4],
    },
    /// The blob's shared square, and the metal layer on a disc whose rim is the
    /// horizon at every view ([`super::horizon_disc`]); for measurements.
    /// `horizon:C_Q_P`: the half vector's slope disc moved to put the mirror
    /// direction at its centre, zoom `k = (C/100) α / cos^(P/100) θo`,
    /// anisotropy `β = max(cos θo, 0.05)^(Q/100)`
    /// ([`super::horizon_disc::HorizonDisc`]); `star:C_E_Q`: the slope disc
    /// drawn from the mirror direction, zoom `k = (C/100) roughness^(E/100)`,
    /// anisotropy as above ([`super::horizon_disc::StarDisc`]); `starl:C_E_Q`
    /// the same in the half vector's Lambert radius.
    Horizon {
        /// The metal layer's three numbers, then 0 for `horizon`, 1 for `star`,
        /// 2 for `starl`.
        metal: [u32; 4],
    },
}

impl PriorSpace {
    /// `direction`, `half-vector` (the blob's), `half-vector:P` (the stretch's
    /// exponent `P` in hundredths), `radial:A_B_C_Q:A_B_C_Q` (shared square,
    /// metal layer; [`Self::Radial`]), `horizon:C_Q_P`, `star:C_E_Q` or `starl:C_E_Q`
    /// (the metal layer; [`Self::Horizon`]).
    pub fn name(self) -> String {
        match self {
            Self::Direction => "direction".into(),
            Self::HalfVector => "half-vector".into(),
            Self::HalfVectorPower { stretch_percent } => format!("half-vector:{stretch_percent}"),
            Self::Radial {
                shared: s,
                metal: m,
            } => format!(
                "radial:{}_{}_{}_{}:{}_{}_{}_{}",
                s[0], s[1], s[2], s[3], m[0], m[1], m[2], m[3]
            ),
            Self::Horizon { metal: m } => format!(
                "{}:{}_{}_{}",
                ["horizon", "star", "starl"][m[3] as usize],
                m[0],
                m[1],
                m[2]
            ),
        }
    }

    /// The space named `name` ([`Self::name`]).
    pub fn parse(name: &str) -> Option<Self> {
        match name.trim() {
            "direction" => Some(Self::Direction),
            "half-vector" => Some(Self::HalfVector),
            other
                if other.starts_with("horizon:")
                    || other.starts_with("star:")
                    || other.starts_with("starl:") =>
            {
                let star = match &other[..other.find(':')?] {
                    "star" => 1,
                    "starl" => 2,
                    _ => 0,
                };
                let v: Vec<u32> = other[other.find(':')? + 1..]
                    .split('_')
                    .map(|x| x.parse().ok())
                    .collect::<Option<_>>()?;
                let v: [u32; 3] = v.try_into().ok()?;
                (v[0] > 0 && v[0] <= 10_000 && v[1] <= 400 && v[2] <= 400).then_some(
                    Self::Horizon {
                        metal: [v[0], v[1], v[2], star],
                    },
                )
            }
            other if other.starts_with("radial:") => {
                let layer = |text: &str| -> Option<[u32; 4]> {
                    let v: Vec<u32> = text
                        .split('_')
                        .map(|x| x.parse().ok())
                        .collect::<Option<_>>()?;
                    let v: [u32; 4] = v.try_into().ok()?;
                    (v[0] <= 400 && v[1] <= 400 && v[2] > 0 && v[3] <= 400).then_some(v)
                };
                let (shared, metal) = other["radial:".len()..].split_once(':')?;
                Some(Self::Radial {
                    shared: layer(shared)?,
                    metal: layer(metal)?,
                })
            }
            other => {
                let p = other.strip_prefix("half-vector:")?.parse().ok()?;
                (p <= 400).then_some(Self::HalfVectorPower { stretch_percent: p })
            }
        }
    }

    /// The half-vector square at `roughness`: the metal layer's star disc (the
    /// blob's, [`metal_zoom`]) if `metal_layer`, else the shared square of this
    /// space's stretch (1 for [`Self::Direction`] and [`Self::Radial`], whose
    /// [`Self::radial`] stretches instead).
    fn square(self, roughness: f64, metal_layer: bool) -> PriorSquare<f64> {
        match self {
            Self::Direction | Self::Radial { .. } => PriorSquare::Stretched(1.0),
            _ if metal_layer => PriorSquare::Star(metal_zoom(roughness)),
            Self::HalfVector | Self::Horizon { .. } => radial_square(roughness),
            Self::HalfVectorPower { stretch_percent } => {
                PriorSquare::Stretched(stretch_with(roughness, stretch_percent as f64 / 100.0))
            }
        }
    }

    /// The radial map of [`Self::Radial`] at `roughness` for the view `wo` (in
    /// the metal layer's square if `metal_layer`); `None` for the other spaces.
    fn radial(self, wo: DVec3, roughness: f64, metal_layer: bool) -> Option<RadialMap> {
        let Self::Radial { shared, metal } = self else {
            return None;
        };
        let [a, b, c, q] = match metal_layer {
            true => metal,
            false => shared,
        }
        .map(|x| x as f64 / 100.0);
        Some(RadialMap {
            k_small: stretch_with(roughness, a),
            k_big: stretch_with(roughness, b),
            crossover: c,
            aniso: wo.z.max(0.05).powf(q),
        })
    }

    /// The light direction of the square point `p` for the view `wo` at
    /// `roughness` (in the metal layer's square if `metal_layer`), and
    /// `|dwi/dω_p|`, the solid angle of `wi` per solid angle of the table's own
    /// direction (1 for [`Self::Direction`]); `None` below the horizon.
    fn direction(
        self,
        wo: DVec3,
        (roughness, metal_layer): (f64, bool),
        p: DVec2,
    ) -> Option<(DVec3, f64)> {
        match self {
            Self::Direction => {
                let d = square_to_hemisphere(p);
                (d.z > 0.0).then_some((d, 1.0))
            }
            Self::Radial { .. } => self.radial(wo, roughness, metal_layer)?.direction(wo, p),
            Self::Horizon { metal } if metal_layer => {
                horizon(metal, wo, roughness).direction(wo, p)
            }
            Self::HalfVector | Self::HalfVectorPower { .. } | Self::Horizon { .. } => {
                let square = self.square(roughness, metal_layer);
                square
                    .direction(wo.to_array(), p.to_array())
                    .map(|(wi, jac)| (DVec3::from_array(wi), jac))
            }
        }
    }

    /// The square point of the light direction `wi` for `wo` at `roughness` and
    /// the same Jacobian; `None` where no table point maps to `wi`.
    fn point(
        self,
        wo: DVec3,
        (roughness, metal_layer): (f64, bool),
        wi: DVec3,
    ) -> Option<(DVec2, f64)> {
        match self {
            Self::Direction => (wi.z > 0.0).then(|| (hemisphere_to_square(wi), 1.0)),
            Self::Radial { .. } => self.radial(wo, roughness, metal_layer)?.point(wo, wi),
            Self::Horizon { metal } if metal_layer => horizon(metal, wo, roughness).point(wo, wi),
            Self::HalfVector | Self::HalfVectorPower { .. } | Self::Horizon { .. } => {
                let square = self.square(roughness, metal_layer);
                square
                    .point(wo.to_array(), wi.to_array())
                    .map(|(p, jac)| (DVec2::from_array(p), jac))
            }
        }
    }
}

/// The metal layer's map of [`PriorSpace::Horizon`] at `roughness` for the view
/// `wo`: `horizon:C_Q_P`'s disc, or the star disc of `star:C_E_Q` and
/// `starl:C_E_Q` (`k = (C/100) roughness^(E/100)`, `β = max(cos θo,
/// 0.05)^(Q/100)`).
fn horizon(metal: [u32; 4], wo: DVec3, roughness: f64) -> HorizonMap {
    let [a, b, c] = [metal[0], metal[1], metal[2]].map(|x| x as f64 / 100.0);
    match metal[3] {
        0 => HorizonMap::Moved(HorizonDisc::at(wo, roughness, a, b, c)),
        kind => HorizonMap::Star(StarDisc {
            zoom: a * roughness.powf(b),
            lambert: kind == 2,
            aniso: wo.z.max(0.05).powf(c),
        }),
    }
}

/// The tabulated BRDF warp (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct BrdfPrior {
    /// Nodes per condition axis `[G_r, G_t, G_m]`.
    pub grid: [u32; 3],
    /// The square the tables live on.
    pub space: PriorSpace,
    /// The tables' shape: `S x S` vertices, `G_r G_t G_m` nodes.
    pub shape: Marginal2DShape,
    /// Normalized vertex values, node `r + G_r (t + G_t m)` after node.
    pub data: Vec<f32>,
    /// Marginal CDFs.
    pub marginal: Vec<f32>,
    /// Conditional CDFs.
    pub conditional: Vec<f32>,
    /// Each node's mass before normalization
    /// ([`nuld_core::marginal2d::tabulate_with_masses`]): the blend's weights are
    /// multiplied by them ([`nuld_core::brdf_prior::BrdfPrior::blend`]).
    pub masses: Vec<f32>,
    /// The four tables widened to `f64` (data, marginal, conditional, masses):
    /// the trainer warps in `f64` ([`Self::core_f64`]) for its differences.
    wide: [Vec<f64>; 4],
}

impl BrdfPrior {
    /// The prior on `grid` condition nodes and `size x size` table vertices in
    /// `space`, tables in `f32` (as a blob stores them). `O(nodes R^2)` with
    /// `R` = [`SUPERSAMPLED_AXIS`], in parallel over the nodes; the same bits for
    /// any thread count. An error if the grid and size are not a blob's
    /// ([`BrdfPriorInfo::shape`]: 2 to 256 roughness and view nodes, 2 or 3
    /// metallic layers, 2 to 4096 vertices), or a node's table has no mass.
    pub fn new(grid: [u32; 3], size: u32, space: PriorSpace) -> Result<Self, Marginal2DError> {
        let shape = BrdfPriorInfo { grid, size }
            .shape()
            .ok_or(Marginal2DError::Shape)?;
        let nodes = shape.nodes;
        let s = size as usize;
        let k = SUPERSAMPLED_AXIS.div_ceil(size).max(1) as usize;
        let h = 1.0 / (s - 1) as f64;
        // Layers 0 and 1 (metallic 0 and 1) share the square, so a node of
        // layer 0 and the node above it in layer 1 are tabulated together, at
        // the same directions, each BRDF value the one `gltf_metallic` gives
        // ([`gltf_metallic_ends`]); the metal layer's nodes one by one.
        let layer = grid[0] * grid[1];
        let jobs: Vec<Vec<u32>> = (0..layer)
            .map(|n| vec![n, n + layer])
            .chain((2 * layer..nodes).map(|n| vec![n]))
            .collect();
        // Seconds at the start of every BRDF bake: shown like its other phases.
        let progress = Progress::stderr("prior", nodes as u64, "node");
        let tabulated_jobs: Vec<Vec<Vec<f32>>> = jobs
            .par_iter()
            .map(|job| {
                let [r, t, m] = node_condition(grid, job[0]);
                let metal_layer = is_metal_layer_node(grid, job[0]);
                let ends = job.len() == 2;
                debug_assert!(!ends || (m == 0.0 && node_condition(grid, job[1])[2] == 1.0));
                let wo = view_direction(t);
                let mut out = vec![vec![0.0f32; s * s]; job.len()];
                for j in 0..s {
                    for i in 0..s {
                        let mut sum = [0.0; 2];
                        for b in 0..k {
                            for a in 0..k {
                                // The dual cell of vertex (i, j), clipped to the square.
                                let at = |v: usize, q: usize| {
                                    ((v as f64 - 0.5 + (q as f64 + 0.5) / k as f64) * h)
                                        .clamp(0.0, 1.0)
                                };
                                let p = DVec2::new(at(i, a), at(j, b));
                                if let Some((wi, jac)) = space.direction(wo, (r, metal_layer), p) {
                                    let (wo, wi) = (wo.to_array(), wi.to_array());
                                    let f = match ends {
                                        true => gltf_metallic_ends(wo, wi, r),
                                        false => [gltf_metallic(wo, wi, r, m), 0.0],
                                    };
                                    for (sum, f) in sum.iter_mut().zip(f) {
                                        *sum += f * wi[2] * jac;
                                    }
                                }
                            }
                        }
                        for (table, sum) in out.iter_mut().zip(sum) {
                            table[j * s + i] = (sum / (k * k) as f64) as f32;
                        }
                    }
                }
                progress.inc(job.len() as u64);
                out
            })
            .collect();
        progress.finish();
        // Back in node order: layer 0, layer 1, then the metal layer.
        let mut tables = vec![Vec::new(); nodes as usize];
        for (job, out) in jobs.iter().zip(tabulated_jobs) {
            for (&node, table) in job.iter().zip(out) {
                tables[node as usize] = table;
            }
        }
        let ([data, marginal, conditional], masses) = tabulated(shape, &tables)?;
        let widen = |v: &Vec<f32>| v.iter().map(|&x| x as f64).collect();
        let wide = [
            widen(&data),
            widen(&marginal),
            widen(&conditional),
            widen(&masses),
        ];
        Ok(Self {
            grid,
            space,
            shape,
            data,
            marginal,
            conditional,
            masses,
            wide,
        })
    }

    /// The BRDF sampler's prior ([`PRIOR_GRID`], [`PRIOR_SIZE`], half-vector
    /// tables), built once per process (about 4 s on 2 cores) and shared.
    pub fn shared() -> std::sync::Arc<Self> {
        static PRIOR: std::sync::OnceLock<std::sync::Arc<BrdfPrior>> = std::sync::OnceLock::new();
        PRIOR
            .get_or_init(|| {
                std::sync::Arc::new(
                    Self::new(PRIOR_GRID, PRIOR_SIZE, PriorSpace::HalfVector)
                        .expect("the BRDF has mass at every node"),
                )
            })
            .clone()
    }

    /// [`Self::core`] over the tables widened to `f64` (the same values; the
    /// warp's arithmetic in `f64`).
    pub fn core_f64(&self) -> Option<nuld_core::brdf_prior::BrdfPrior<'_, f64>> {
        (self.space == PriorSpace::HalfVector).then(|| {
            let [data, marginal, conditional, masses] = &self.wide;
            nuld_core::brdf_prior::BrdfPrior::view(self.info(), data, marginal, conditional, masses)
                .expect("tables written by tabulate")
        })
    }

    /// The blob sections of the tables ([`nuld_core::brdf_prior::sections`]).
    pub fn sections<'s>(
        &'s self,
        info: &'s BrdfPriorInfo,
    ) -> [nuld_core::blob::SectionSpec<'s>; 5] {
        nuld_core::brdf_prior::sections(
            info,
            &self.data,
            &self.marginal,
            &self.conditional,
            &self.masses,
        )
    }

    /// The blob's info record of these tables.
    pub fn info(&self) -> BrdfPriorInfo {
        BrdfPriorInfo {
            grid: self.grid,
            size: self.shape.size[0],
        }
    }

    /// `[roughness, θo in degrees, metallic]` of node `node` of `grid`.
    pub fn node_condition(grid: [u32; 3], node: u32) -> [f64; 3] {
        node_condition(grid, node)
    }

    /// The warp over the tables.
    pub fn warp(&self) -> Marginal2D<'_, f32> {
        Marginal2D::new(self.shape, &self.data, &self.marginal, &self.conditional)
            .expect("tables written by tabulate")
    }

    /// The runtime's prior over these tables (half-vector tables only; `None`
    /// for direction ones): the one implementation every sampler draws from.
    pub fn core(&self) -> Option<nuld_core::brdf_prior::BrdfPrior<'_, f32>> {
        (self.space == PriorSpace::HalfVector).then(|| {
            nuld_core::brdf_prior::BrdfPrior::view(
                self.info(),
                &self.data,
                &self.marginal,
                &self.conditional,
                &self.masses,
            )
            .expect("tables written by tabulate")
        })
    }

    /// The blend of the nodes around `[roughness, θo in degrees, metallic]`:
    /// multilinear weights times the nodes' masses, as
    /// [`nuld_core::brdf_prior::BrdfPrior::blend`] (in both spaces).
    pub fn blend(&self, condition: [f64; 3]) -> Blend<f32> {
        mass_weighted_blend(self.grid, &self.masses, condition.map(|x| x as f32))
    }

    /// The light direction at primary sample `u` for `condition`, and its
    /// solid-angle pdf (per steradian); `(+z, 0)` for the rare table point whose
    /// direction lies below the horizon (a vertex of zero value next to a
    /// positive one).
    pub fn sample(
        &self,
        warp: &Marginal2D<'_, f32>,
        condition: [f64; 3],
        u: DVec2,
    ) -> (DVec3, f64) {
        let wo = view_direction(condition[1]);
        let (p, pdf) = warp.sample([u.x as f32, u.y as f32], &self.blend(condition));
        let p = DVec2::new(p[0] as f64, p[1] as f64);
        let layer = (condition[0], reads_metal_layer(self.grid, condition[2]));
        match self.space.direction(wo, layer, p) {
            Some((wi, jac)) => (wi, pdf as f64 / (2.0 * PI * jac)),
            None => (DVec3::Z, 0.0),
        }
    }

    /// The solid-angle pdf of [`Self::sample`] at the unit direction `wi`.
    pub fn pdf(&self, warp: &Marginal2D<'_, f32>, condition: [f64; 3], wi: DVec3) -> f64 {
        let wo = view_direction(condition[1]);
        let layer = (condition[0], reads_metal_layer(self.grid, condition[2]));
        match self.space.point(wo, layer, wi) {
            Some((p, jac)) => {
                let pdf = warp.pdf([p.x as f32, p.y as f32], &self.blend(condition));
                pdf as f64 / (2.0 * PI * jac)
            }
            None => 0.0,
        }
    }

    /// Bytes of the tables as `f32`: data, conditional and marginal CDFs, masses.
    pub fn state_bytes(&self) -> usize {
        4 * (self.data.len() + self.conditional.len() + self.marginal.len() + self.masses.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeding::rng;
    use crate::sphere::brdf_albedo::directional_albedo_metallic;
    use rand::Rng;

    /// Every space's name parses back to it; malformed names are refused.
    #[test]
    fn space_names_parse_back() {
        for name in [
            "direction",
            "half-vector",
            "half-vector:35",
            "radial:100_25_25_0:100_100_50_100",
            "horizon:50_0_100",
            "star:100_200_0",
            "starl:70_150_50",
        ] {
            let space = PriorSpace::parse(name).unwrap();
            assert_eq!(space.name(), name);
        }
        for bad in [
            "horizon:0_0_100",
            "star:100_200",
            "starl:100_200_0_1",
            "star:100_500_0",
            "stars:100_200_0",
            "radial:1_1_0_1:1_1_1_1",
        ] {
            assert_eq!(PriorSpace::parse(bad), None, "{bad}");
        }
    }

    /// `(1/M) Σ f cos / pdf` over the prior's samples is the albedo of the
    /// independent quadrature (`directional_albedo_metallic`), on and between the
    /// nodes, in both spaces: the pdf is the samples' density, whatever the
    /// tables approximate; and `pdf` returns the samples' pdf.
    #[test]
    fn the_estimate_with_the_priors_pdf_is_the_albedo() {
        let radial = PriorSpace::parse("radial:100_25_50_0:150_100_50_100").unwrap();
        let horizon = PriorSpace::parse("horizon:100_100_100").unwrap();
        let star = PriorSpace::parse("star:100_100_0").unwrap();
        let starl = PriorSpace::parse("starl:100_200_100").unwrap();
        for space in [
            PriorSpace::Direction,
            PriorSpace::HalfVector,
            radial,
            horizon,
            star,
            starl,
        ] {
            let grid = [
                3,
                4,
                2 + !matches!(space, PriorSpace::Direction | PriorSpace::HalfVector) as u32,
            ];
            let prior = BrdfPrior::new(grid, 32, space).unwrap();
            let nodes = grid.iter().product::<u32>() as usize;
            assert_eq!(prior.state_bytes(), 4 * nodes * (2 * 32 * 32 + 32 + 1));
            let warp = prior.warp();
            for (c, condition) in [
                [0.55, 29.666666666666668, 0.0],
                [0.4, 50.0, 0.3],
                [0.8, 75.0, 1.0],
                [0.15, 80.0, 1.0],
                [0.15, 80.0, 0.5],
            ]
            .into_iter()
            .enumerate()
            {
                let [r, t, m] = condition;
                let wo = view_direction(t);
                let want = directional_albedo_metallic(r, t, m).total();
                let mut g = rng(7, c as u64);
                let count = 1 << 17;
                let (mut sum, mut sum2) = (0.0, 0.0);
                for _ in 0..count {
                    let u = DVec2::new(g.random(), g.random());
                    let (wi, pdf) = prior.sample(&warp, condition, u);
                    if pdf <= 0.0 {
                        continue;
                    }
                    let back = prior.pdf(&warp, condition, wi);
                    assert!((back - pdf).abs() <= 1e-3 * pdf, "{back} {pdf}");
                    let y = gltf_metallic(wo.to_array(), wi.to_array(), r, m) * wi.z / pdf;
                    sum += y;
                    sum2 += y * y;
                }
                let mean = sum / count as f64;
                let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
                assert!(
                    (mean - want).abs() < 4.0 * se + 1e-4,
                    "{} at {condition:?}: {mean} vs {want} (se {se})",
                    space.name()
                );
            }
        }
    }

    /// The prior's tables, whose metallic-0 and metallic-1 nodes are tabulated
    /// in pairs, are bit for bit those of each node tabulated alone at its own
    /// condition with `gltf_metallic` (written out here), metal layer included.
    #[test]
    fn paired_nodes_tabulate_as_each_node_alone() {
        let (grid, size) = ([2, 3, 3], 6);
        let prior = BrdfPrior::new(grid, size, PriorSpace::HalfVector).unwrap();
        let s = size as usize;
        let k = SUPERSAMPLED_AXIS.div_ceil(size) as usize;
        let h = 1.0 / (s - 1) as f64;
        let alone: Vec<Vec<f32>> = (0..prior.shape.nodes)
            .map(|node| {
                let [r, t, m] = node_condition(grid, node);
                let wo = view_direction(t);
                let key = (r, is_metal_layer_node(grid, node));
                let mut out = vec![0.0f32; s * s];
                for (v, value) in out.iter_mut().enumerate() {
                    let (i, j) = (v % s, v / s);
                    let mut sum = 0.0;
                    for q in 0..k * k {
                        let at = |v: usize, q: usize| {
                            ((v as f64 - 0.5 + (q as f64 + 0.5) / k as f64) * h).clamp(0.0, 1.0)
                        };
                        let p = DVec2::new(at(i, q % k), at(j, q / k));
                        if let Some((wi, jac)) = PriorSpace::HalfVector.direction(wo, key, p) {
                            sum += gltf_metallic(wo.to_array(), wi.to_array(), r, m) * wi.z * jac;
                        }
                    }
                    *value = (sum / (k * k) as f64) as f32;
                }
                out
            })
            .collect();
        let (tables, masses) = tabulated(prior.shape, &alone).unwrap();
        assert_eq!(tables, [prior.data, prior.marginal, prior.conditional]);
        assert_eq!(masses, prior.masses);
    }

    #[test]
    fn nodes_are_the_grid_and_a_query_at_a_node_reads_its_table_alone() {
        let grid = [3, 4, 2];
        assert_eq!(BrdfPrior::node_condition(grid, 0), [0.1, 0.0, 0.0]);
        assert_eq!(BrdfPrior::node_condition(grid, 23), [1.0, 89.0, 1.0]);
        let [r, t, m] = BrdfPrior::node_condition(grid, 1 + 3 * (2 + 4));
        // θo node 2 of 4: 89 (1 - (1/3)^2), the axis crowding towards grazing.
        assert!((r - 0.55).abs() < 1e-12 && (t - 89.0 * 8.0 / 9.0).abs() < 1e-12 && m == 1.0);
        let prior = BrdfPrior::new(grid, 8, PriorSpace::HalfVector).unwrap();
        let b = prior.blend([r, t, m]);
        let pairs: Vec<(u32, f32)> = b.pairs().filter(|p| p.1 > 1e-6).collect();
        assert_eq!(pairs.len(), 1);
        assert_eq!(pairs[0].0, 1 + 3 * (2 + 4));
    }
}
