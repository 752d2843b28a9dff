//! A map's hierarchical product warp: the map's luminance in a quadtree over the
//! sphere's equal-area octahedral square, each node with its mass, first moment
//! and spread ([`nuld_core::envmap_tree`]), lit at the query by the cosine about
//! the normal and sampled exactly (Clarberg and Akenine-Möller 2008). This module
//! measures the map into the tree's records; the weights, the descent and the pdf
//! are core's, the runtime's own.
//!
//! Unlike [`super::EnvmapPrior`]'s tables per normal, the state is one pyramid of
//! the map, whatever the normals, at the resolution of the leaves (`2^L x 2^L`;
//! `L = 9` puts leaves 0.4° apart, about a 1024 x 512 map's pixels); the cosine
//! enters at the query, through each node's bound of `Σ mass max(0, n.l)`, which
//! is positive wherever the cosine is, so `L cos / pdf` is unbiased.

use super::envmap::EnvmapDensity;
use super::geometry::map_jacobian;
use super::target::DirectionDensity;
use bytemuck::Zeroable;
use glam::{DVec2, DVec3};
use nuld_core::blob::{Domain, SectionSpec};
use nuld_core::envmap_tree::{
    build, detail_index_len, node_count, node_index, top_len, top_normal, top_row,
    EnvmapTree as CoreTree, NodeRecord, TreeInfo, DETAIL_SIDE, FINE_BIT, FINE_SIDE,
    MAX_TREE_LEVELS, TOP_LEVELS,
};
use nuld_core::quadtree::QuadtreeError;
use nuld_core::sphere::{sphere_to_square, square_to_sphere};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Fewest levels of the environment sampler's prior: 256 x 256 leaves (0.7°
/// apart), for maps of fewer than `4^9` pixels.
pub const PRIOR_MIN_LEVELS: u32 = 8;

/// Most levels of the environment sampler's prior: 1024 x 1024 leaves (0.2°
/// apart, 22 MB of records), whatever the map's size.
pub const PRIOR_MAX_LEVELS: u32 = 10;

/// Levels of the prior of `map`: about a leaf per pixel of the map,
/// `floor(log4(pixels))` within [`PRIOR_MIN_LEVELS`]`..=`[`PRIOR_MAX_LEVELS`]
/// (9 for a 1024 x 512 map). The leaves' resolution does not move the sets'
/// discrepancy (`eval envmap-prior`: 8 to 10 levels score alike), but inside a
/// leaf the warp is uniform while the light is not, and with multiple importance
/// sampling on a map of small lights that decides the variance: Owen-Sobol
/// through the product warp renders studio at 64 spp with an RMSE of 2.02e-2
/// at 8 levels, 1.42e-2 at 9 and 1.29e-2 at 10 (docs/results/rendering.md).
pub fn prior_levels(map: &EnvmapDensity) -> u32 {
    // The density is tabulated on half pixels: four cells a pixel.
    let pixels = (map.width() * map.height() / 4).max(1) as u64;
    (pixels.ilog2() / 2).clamp(PRIOR_MIN_LEVELS, PRIOR_MAX_LEVELS)
}

/// Normals per axis of the prior's top-weight table: the figures of `eval
/// envmap-prior` stop improving there (docs/results/envmap-prior.md).
pub const PRIOR_GRID: u32 = 49;

/// Supersampled points per leaf and axis at `L` levels: about 1024 per axis over
/// the square, a point per cell of a 1024 x 512 map's density table (half pixels).
fn supersampling(levels: u32) -> usize {
    (1024usize >> levels.min(10)).max(1)
}

/// Points per leaf and axis where the light changes fast ([`REFINE_CONTRAST`]):
/// about 8192 per axis over the square (64 a density cell at 9 levels), at most
/// 16 a leaf and never fewer than [`supersampling`]. The density is constant per
/// cell (half a pixel), so a point per cell weighs a lamp a pixel across by what
/// the points happen to catch of it. (A midpoint rule of such a light converges
/// slowly and unevenly: 32 points a leaf came no closer than 16 to a rule of
/// 128, both within about 1 % of a lamp's mass.)
fn refined_supersampling(levels: u32) -> usize {
    (8192usize >> levels.min(13))
        .min(16)
        .max(supersampling(levels))
}

/// Where a cell of the map's density exceeds its smallest neighbour by more than
/// this many times the density's mean over the sphere, the leaves around it are
/// measured at [`refined_supersampling`] ([`sharp_leaves`]): around lamps and
/// the sun's edge, not in the smooth sky.
/// Measured (`build-tool/examples/envmap_prior_floor`): on four 2 x 1-pixel lamps
/// in a dark room (`scripts/synthetic-maps.py`) a point per density cell
/// missed up to 6 % of a lamp's mass, and the cap L2 of the tree's own
/// distribution against the lit map (65 536 Owen-Sobol points through the tree,
/// over the baseline of 64 points) was 0.37 on average over the bake's held-out
/// normals; with these leaves measured again, 0.15, as with 8192 points per axis
/// everywhere; on courtyard 0.04 either way.
const REFINE_CONTRAST: f64 = 4.0;

/// The leaf shape's floor: a corner's value is at least this share of the mean
/// density of the brightest leaf it touches, so the shape's density stays
/// within a bounded factor of the leaf's mean wherever the leaf has light (the
/// light's `L` at a corner can be 0 beside a lamp whose light reaches into the
/// leaf), and positive wherever the map's light is.
const SHAPE_FLOOR: f64 = 0.25;

/// The leaf shape's corner values ([`nuld_core::envmap_tree::EnvmapTree::with_corners`]):
/// `light` at the octahedral square's points `(cx, cy) / 2^L`, each raised to
/// [`SHAPE_FLOOR`] times the mean density of the brightest of the up to four
/// leaves around it (`leaves` row-major `[m0, m1]`, each of solid angle `4 pi /
/// 4^L`).
fn leaf_corners(
    light: &(impl Fn(DVec3) -> f64 + Sync),
    levels: u32,
    leaves: &[[f64; 4]],
) -> Vec<f32> {
    let side = 1usize << levels;
    let area = 4.0 * PI / (side * side) as f64;
    (0..(side + 1) * (side + 1))
        .into_par_iter()
        .map(|k| {
            let (cx, cy) = (k % (side + 1), k / (side + 1));
            // The up to four leaves around the corner (`wrapping_sub` past the
            // square's edge gives an index the bound leaves out).
            let (x0, y0) = (cx.wrapping_sub(1), cy.wrapping_sub(1));
            let brightest = [(x0, y0), (cx, y0), (x0, cy), (cx, cy)]
                .into_iter()
                .filter(|&(lx, ly)| lx < side && ly < side)
                .map(|(lx, ly)| leaves[ly * side + lx][0] / area)
                .fold(0.0, f64::max);
            let p = DVec2::new(cx as f64 / side as f64, cy as f64 / side as f64);
            light(square_to_sphere(p)).max(SHAPE_FLOOR * brightest) as f32
        })
        .collect()
}

/// A leaf's mass and moment `[m0, m1.x, m1.y, m1.z]` from `k x k` points of
/// `light` in it (midpoints of a `k x k` grid of the leaf).
fn measure_leaf(
    light: &(impl Fn(DVec3) -> f64 + Sync),
    levels: u32,
    (x, y): (usize, usize),
    k: usize,
) -> [f64; 4] {
    let side = 1usize << levels;
    let area = 4.0 * PI / (side * side * k * k) as f64;
    let (mut sum, mut moment) = (0.0, DVec3::ZERO);
    for b in 0..k {
        for a in 0..k {
            let p = DVec2::new(
                (x as f64 + (a as f64 + 0.5) / k as f64) / side as f64,
                (y as f64 + (b as f64 + 0.5) / k as f64) / side as f64,
            );
            let d = square_to_sphere(p);
            let m = light(d) * area;
            sum += m;
            moment += m * d;
        }
    }
    [sum, moment.x, moment.y, moment.z]
}

/// The leaves (row-major, `2^L x 2^L`) that [`EnvmapTree::new`] measures at
/// [`refined_supersampling`]: those that hold a corner or the centre of a cell of
/// `map`'s density whose value exceeds its smallest neighbour's (of eight, the
/// columns wrapping in azimuth) by more than [`REFINE_CONTRAST`] times the
/// density's mean, and their eight neighbours. Read from the map's cells, not
/// from points: near the poles a cell is narrower than the points' spacing.
fn sharp_leaves(map: &EnvmapDensity, levels: u32) -> Vec<bool> {
    let side = 1usize << levels;
    let (w, h) = (map.width(), map.height());
    let density = |c: usize, r: usize| {
        let (lo, hi) = map.row_z_range(r);
        let omega = (hi - lo) * 2.0 * PI / w as f64;
        if omega > 0.0 {
            map.pixel_mass(c, r) / omega
        } else {
            0.0
        }
    };
    let threshold = REFINE_CONTRAST / (4.0 * PI);
    let cells: Vec<(usize, usize)> = (0..w * h)
        .into_par_iter()
        .filter_map(|cell| {
            let (c, r) = (cell % w, cell / w);
            let v = density(c, r);
            let mut low = v;
            for nr in r.saturating_sub(1)..(r + 2).min(h) {
                for dc in [w - 1, 0, 1] {
                    low = low.min(density((c + dc) % w, nr));
                }
            }
            (v - low > threshold).then_some((c, r))
        })
        .collect();
    let mut sharp = vec![false; side * side];
    for (c, r) in cells {
        for f in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [0.5, 0.5]] {
            let q = sphere_to_square(map.pixel_direction(c, r, DVec2::from(f)));
            let leaf = |v: f64| ((v * side as f64) as usize).min(side - 1);
            let (x, y) = (leaf(q.x), leaf(q.y));
            for ny in y.saturating_sub(1)..(y + 2).min(side) {
                for nx in x.saturating_sub(1)..(x + 2).min(side) {
                    sharp[ny * side + nx] = true;
                }
            }
        }
    }
    sharp
}

/// Points per detail cell and axis with which a detailed leaf's table is
/// measured (a midpoint rule of `4 x 4` points a cell, `32 x 32` a leaf).
const DETAIL_SUPERSAMPLING: usize = 4;

/// A detail cell's floor, as a share of its leaf's mean density: keeps the
/// table's density positive wherever the leaf has light (a sliver of a bright
/// pixel that no point of a cell caught), at the cost of that share of the
/// samples in the leaf's dark cells.
const DETAIL_FLOOR: f64 = 1.0 / 64.0;

/// Leaf `(x, y)`'s detail table of `n x n` cells ([`DETAIL_SIDE`], or
/// [`FINE_SIDE`] for a fine one; [`nuld_core::envmap_tree::EnvmapTree::with_detail`]):
/// `light`'s mass over each cell by
/// [`DETAIL_SUPERSAMPLING`] points a cell and axis, each raised to
/// [`DETAIL_FLOOR`] times the cells' mean, stored as [`nuld_core::cell_table`]
/// reads it (the column sums, then the cells column by column). The cells have
/// equal solid angle (the square's map is equal-area), so masses are densities
/// up to a constant.
fn detail_table(
    light: &(impl Fn(DVec3) -> f64 + Sync),
    levels: u32,
    (x, y): (usize, usize),
    n: usize,
) -> Vec<f32> {
    let side = (1usize << levels) as f64;
    let k = DETAIL_SUPERSAMPLING;
    let points = (n * k) as f64;
    // Column-major: cell `(a, b)` at `a n + b`.
    let cells: Vec<f64> = (0..n * n)
        .map(|c| {
            let (a, b) = (c / n, c % n);
            let mut sum = 0.0;
            for j in 0..k {
                for i in 0..k {
                    let p = DVec2::new(
                        (x as f64 + ((a * k + i) as f64 + 0.5) / points) / side,
                        (y as f64 + ((b * k + j) as f64 + 0.5) / points) / side,
                    );
                    sum += light(square_to_sphere(p));
                }
            }
            sum
        })
        .collect();
    let floor = DETAIL_FLOOR * cells.iter().sum::<f64>() / (n * n) as f64;
    let cells: Vec<f32> = cells.iter().map(|v| v.max(floor) as f32).collect();
    let mut table: Vec<f32> = cells
        .chunks(n)
        .map(|column| column.iter().map(|&v| v as f64).sum::<f64>() as f32)
        .collect();
    table.extend(cells);
    debug_assert_eq!(table.len(), nuld_core::cell_table::table_len(n));
    table
}

/// The leaves (row-major) whose light `light` varies by more than
/// [`REFINE_CONTRAST`] times its mean over the sphere (`mean`) between the
/// leaf's corners and centre: where a light with no map behind it
/// ([`EnvmapTree::from_light`]) is sharp.
fn contrast_leaves(light: &(impl Fn(DVec3) -> f64 + Sync), levels: u32, mean: f64) -> Vec<bool> {
    let side = 1usize << levels;
    (0..side * side)
        .into_par_iter()
        .map(|leaf| {
            let (x, y) = ((leaf % side) as f64, (leaf / side) as f64);
            let values = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [0.5, 0.5]].map(|f| {
                let p = DVec2::new((x + f[0]) / side as f64, (y + f[1]) / side as f64);
                light(square_to_sphere(p))
            });
            let hi = values.iter().copied().fold(f64::MIN, f64::max);
            let lo = values.iter().copied().fold(f64::MAX, f64::min);
            hi - lo > REFINE_CONTRAST * mean
        })
        .collect()
}

/// Share of the light a detailed leaf must hold to get a fine table
/// ([`FINE_SIDE`] cells a side) instead of a [`DETAIL_SIDE`] one: the leaves of
/// a sun, where the cells that its edge cuts decide the variance (and, with
/// multiple importance sampling, whether the luminance warp, which follows the
/// sun pixel for pixel, wins). Measured (`examples/leaf_shape`, the variance of
/// `L cos / (E pdf)` over 64 normals): a clear sky's sun 45° up spans 10 such
/// leaves, 0.034 → 0.013 with them fine; on studio a share of 1/1024 gave 256
/// lamp leaves fine tables (4 MB) for no change (0.0056), this share none.
const FINE_SHARE: f64 = 1.0 / 256.0;

/// Most fine tables a tree holds (the brightest leaves first; 1 MB).
const FINE_MAX: usize = 64;

/// The detail index, tables and fine tables of the leaves marked in `detail`
/// (row-major), the leaves of mass (`masses`, row-major) at least
/// [`FINE_SHARE`] of the total given fine tables, at most [`FINE_MAX`] of them.
fn detail_tables(
    light: &(impl Fn(DVec3) -> f64 + Sync),
    levels: u32,
    detail: &[bool],
    masses: &[f64],
) -> (Vec<u32>, Vec<f32>, Vec<f32>) {
    let side = 1usize << levels;
    let marked: Vec<usize> = (0..side * side)
        .filter(|&l| detail.get(l).copied().unwrap_or(false))
        .collect();
    if marked.is_empty() {
        return (Vec::new(), Vec::new(), Vec::new());
    }
    let total: f64 = masses.iter().sum();
    let mass = |l: usize| masses.get(l).copied().unwrap_or(0.0);
    let mut bright: Vec<usize> = marked
        .iter()
        .copied()
        .filter(|&l| mass(l) >= FINE_SHARE * total)
        .collect();
    // The brightest first; ties by leaf, so the choice is deterministic.
    bright.sort_by(|&a, &b| mass(b).total_cmp(&mass(a)).then(a.cmp(&b)));
    bright.truncate(FINE_MAX);
    bright.sort_unstable();
    let coarse: Vec<usize> = marked
        .iter()
        .copied()
        .filter(|l| bright.binary_search(l).is_err())
        .collect();
    let measure = |leaves: &[usize], n: usize| -> Vec<f32> {
        leaves
            .par_iter()
            .flat_map_iter(|&l| detail_table(light, levels, (l % side, l / side), n))
            .collect()
    };
    let (tables, fine) = (measure(&coarse, DETAIL_SIDE), measure(&bright, FINE_SIDE));
    let mut index = vec![0u32; detail_index_len(levels)];
    for (t, &l) in coarse.iter().enumerate() {
        index[l] = t as u32 + 1;
    }
    for (t, &l) in bright.iter().enumerate() {
        index[l] = FINE_BIT | (t as u32 + 1);
    }
    (index, tables, fine)
}

/// The top-weight table of `top_levels` levels for the tree of `levels` levels
/// whose records are `nodes`: [`top_row`] at each of the `grid x grid` normals
/// ([`top_normal`]), [`top_len`]`(grid, top_levels)` values, the rows in
/// parallel (each row reads every leaf record once).
pub fn top_table(levels: u32, top_levels: u32, nodes: &[NodeRecord], grid: u32) -> Vec<f32> {
    let mut top = vec![0.0; top_len(grid, top_levels)];
    top.par_chunks_mut(node_count(top_levels))
        .enumerate()
        .for_each(|(r, row)| {
            let j = [r as u32 % grid, r as u32 / grid];
            top_row(levels, top_levels, nodes, top_normal(grid, j), row);
        });
    top
}

/// [`QuadtreeError::Levels`] unless `levels` is in [`TOP_LEVELS`]`..=`[`MAX_TREE_LEVELS`].
fn check_levels(levels: u32) -> Result<(), QuadtreeError> {
    if (TOP_LEVELS..=MAX_TREE_LEVELS).contains(&levels) {
        Ok(())
    } else {
        Err(QuadtreeError::Levels(levels))
    }
}

/// A map's tree (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvmapTree {
    /// Levels below the root.
    pub levels: u32,
    /// The records of levels `1..=L` ([`nuld_core::envmap_tree`]'s layout), of the
    /// map's pdf (mass 1 in all).
    pub nodes: Vec<NodeRecord>,
    /// Normals per axis of the top-weight table.
    pub grid: u32,
    /// The top levels' exact weights on `grid x grid` normals
    /// ([`nuld_core::envmap_tree::top_row`]).
    pub top: Vec<f32>,
    /// The leaf shape's `(2^L + 1)^2` corner values: the light at the square's
    /// lattice points, each raised to a quarter of the mean density of the
    /// brightest leaf it touches.
    pub corners: Vec<f32>,
    /// The detail index: per leaf (row-major) 0, or `1 + t` for a leaf drawn
    /// by table `t` ([`nuld_core::envmap_tree::EnvmapTree::with_detail`]);
    /// empty without detailed leaves.
    pub detail_index: Vec<u32>,
    /// The detailed leaves' tables: the light's mass over `16 x 16` cells of
    /// each, floored at a sixteenth of their mean.
    pub detail: Vec<f32>,
    /// The fine tables (`64 x 64` cells) of the detailed leaves that hold the
    /// most light, named by index entries with `FINE_BIT` set.
    pub fine: Vec<f32>,
}

impl EnvmapTree {
    /// The tree of `map` (its pdf proportional to the luminance) with `levels`
    /// levels and its top levels' weights on `grid x grid` normals: each leaf's
    /// mass and moment the means of the map's pdf (and of `pdf l`) over a grid of
    /// points in it, times its solid angle (leaves have equal area), 16 x 16 points
    /// a leaf at 9 levels around cells of the map's density that exceed a
    /// neighbour by more than 4 times its mean (lamps, the sun's edge). An error if
    /// `levels` is below [`TOP_LEVELS`] or above the tree's limit, or `grid` below
    /// 2.
    pub fn new(map: &EnvmapDensity, levels: u32, grid: u32) -> Result<Self, QuadtreeError> {
        check_levels(levels)?;
        Self::measured(|d| map.pdf(d), levels, grid, &sharp_leaves(map, levels))
    }

    /// The tree of any light on the sphere, `light(direction)` its radiance (a
    /// map's pdf, or a closed form for tests and fixtures); as [`Self::new`],
    /// the leaves whose corners and centre differ by more than 4 times the
    /// light's mean detailed.
    pub fn from_light(
        light: impl Fn(DVec3) -> f64 + Sync,
        levels: u32,
        grid: u32,
    ) -> Result<Self, QuadtreeError> {
        check_levels(levels)?;
        let mut tree = Self::measured(&light, levels, grid, &[])?;
        // The leaves hold the light's integral; its mean is that over 4 pi.
        let total: f64 = tree.nodes[..4].iter().map(|r| r.mass() as f64).sum();
        let sharp = contrast_leaves(&light, levels, total / (4.0 * PI));
        let side = 1usize << levels;
        let masses: Vec<f64> = (0..side * side)
            .map(|l| {
                let record = node_index(levels, (l % side) as u32, (l / side) as u32);
                tree.nodes[record].mass() as f64
            })
            .collect();
        (tree.detail_index, tree.detail, tree.fine) =
            detail_tables(&light, levels, &sharp, &masses);
        tree.tree().check_values()?;
        Ok(tree)
    }

    /// The tree of `light` with the leaves marked in `sharp` (row-major; missing
    /// entries unmarked) measured at [`refined_supersampling`].
    fn measured(
        light: impl Fn(DVec3) -> f64 + Sync,
        levels: u32,
        grid: u32,
        sharp: &[bool],
    ) -> Result<Self, QuadtreeError> {
        let side = 1usize << levels;
        let (coarse, fine) = (supersampling(levels), refined_supersampling(levels));
        let leaves: Vec<[f64; 4]> = (0..side * side)
            .into_par_iter()
            .map(|leaf| {
                let k = if sharp.get(leaf).copied().unwrap_or(false) {
                    fine
                } else {
                    coarse
                };
                measure_leaf(&light, levels, (leaf % side, leaf / side), k)
            })
            .collect();
        let mut nodes = vec![NodeRecord::zeroed(); node_count(levels)];
        build(levels, &leaves, &mut nodes)?;
        if grid < 2 {
            return Err(QuadtreeError::Length {
                expected: top_len(2, TOP_LEVELS) as u64,
                got: 0,
            });
        }
        let top = top_table(levels, TOP_LEVELS, &nodes, grid);
        let corners = leaf_corners(&light, levels, &leaves);
        let masses: Vec<f64> = leaves.iter().map(|m| m[0]).collect();
        let (detail_index, detail, fine) = detail_tables(&light, levels, sharp, &masses);
        // Refuses a map without light, as the runtime would (every value,
        // corners and detail included, read once).
        CoreTree::view(levels, &nodes, grid, &top, TOP_LEVELS)?
            .with_corners(&corners)?
            .with_detail(&detail_index, &detail)?
            .with_fine_detail(&fine)?
            .check_values()?;
        Ok(Self {
            levels,
            nodes,
            grid,
            top,
            corners,
            detail_index,
            detail,
            fine,
        })
    }

    /// The tree as core reads it (`O(1)`: the values were checked when built).
    pub fn tree(&self) -> CoreTree<'_> {
        CoreTree::view(self.levels, &self.nodes, self.grid, &self.top, TOP_LEVELS)
            .and_then(|t| t.with_corners(&self.corners))
            .and_then(|t| t.with_detail(&self.detail_index, &self.detail))
            .and_then(|t| t.with_fine_detail(&self.fine))
            .expect("checked when built")
    }

    /// The tree's info record for a blob.
    pub fn info(&self) -> TreeInfo {
        TreeInfo {
            levels: self.levels,
            grid: self.grid,
            top_levels: TOP_LEVELS,
            reserved: 0,
        }
    }

    /// The blob sections of the tree ([`nuld_core::envmap_tree::sections`]) and
    /// its leaf shape ([`nuld_core::envmap_tree::corner_section`]).
    pub fn sections<'s>(&'s self, info: &'s TreeInfo) -> Vec<SectionSpec<'s>> {
        let mut sections = nuld_core::envmap_tree::sections(info, &self.nodes, &self.top).to_vec();
        sections.push(nuld_core::envmap_tree::corner_section(&self.corners));
        if !self.detail_index.is_empty() {
            sections.extend(nuld_core::envmap_tree::detail_sections(
                &self.detail_index,
                &self.detail,
            ));
        }
        if !self.fine.is_empty() {
            sections.push(nuld_core::envmap_tree::fine_section(&self.fine));
        }
        sections
    }

    /// The direction at primary sample `u` for the unit normal `n` and its
    /// solid-angle pdf, by `tree` (this map's [`Self::tree`]).
    pub fn sample(tree: &CoreTree<'_>, n: DVec3, u: DVec2) -> (DVec3, f64) {
        let (d, pdf) = tree.sample(n.to_array(), u.to_array());
        (DVec3::from_array(d), pdf)
    }

    /// The direction at primary sample `p` for the normal of octahedral square
    /// point `q`, and its derivatives along `p.x` and `p.y`: the sphere map's
    /// Jacobian times the tree's, exact within the piece of the tree `p` falls in
    /// ([`nuld_core::envmap_tree::EnvmapTree::sample_square_with_slopes`]). What
    /// a trainer chains its gradients through.
    pub fn sample_with_jacobian(
        tree: &CoreTree<'_>,
        q: [f64; 2],
        p: DVec2,
    ) -> (DVec3, DVec3, DVec3) {
        let (s, _, [dx_dux, dy_dux, dy_duy]) = tree.sample_square_with_slopes(q, p.to_array());
        let s = DVec2::from(s);
        let (jx, jy) = map_jacobian(Domain::Sphere, s);
        (square_to_sphere(s), jx * dx_dux + jy * dy_dux, jy * dy_duy)
    }

    /// The solid-angle pdf of [`Self::sample`] at the unit direction `d` for `n`.
    pub fn pdf(tree: &CoreTree<'_>, n: DVec3, d: DVec3) -> f64 {
        tree.pdf(n.to_array(), d.to_array())
    }

    /// Bytes of the records, the top table, the corners and the detail.
    pub fn state_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.top.as_slice())
            + std::mem::size_of_val(self.corners.as_slice())
            + std::mem::size_of_val(self.detail_index.as_slice())
            + std::mem::size_of_val(self.detail.as_slice())
            + std::mem::size_of_val(self.fine.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::envmap::test_support::{assert_unbiased_irradiance, sphere_integral};
    use crate::sphere::envmap::tiny_map;
    use nuld_core::blob::Domain;

    /// The estimate `(1/M) sum L cos / pdf` over the tree's samples is the
    /// irradiance of an independent quadrature, and `pdf` returns the samples'
    /// pdf (but for the rare sample on a leaf's edge: the pdf is constant per
    /// leaf); the leaves' masses add up to the map's.
    #[test]
    fn the_prior_has_about_a_leaf_per_pixel() {
        use crate::density::image::LuminanceImage;
        let map = |w: usize, h: usize| {
            let img = LuminanceImage {
                width: w,
                height: h,
                values: vec![1.0; w * h],
            };
            EnvmapDensity::from_luminance_filtered(&img, nuld_core::blob::Domain::Sphere, "t")
                .unwrap()
        };
        // 4^9 = 512 x 512 pixels: 1024 x 512 has 2^19, 9 levels.
        assert_eq!(prior_levels(&map(1024, 512)), 9);
        assert_eq!(prior_levels(&map(2048, 1024)), 10);
        assert_eq!(prior_levels(&map(8192, 4096)), PRIOR_MAX_LEVELS);
        assert_eq!(prior_levels(&map(16, 8)), PRIOR_MIN_LEVELS);
    }

    /// Small lamps keep their mass: on a 1024 x 512 map of a dim room with five
    /// one-pixel lamps (one near each pole), the tree's mass of the 8 x 8 leaves
    /// around each lamp (9 levels, the bake's) is that of an independent
    /// midpoint rule of 128 x 128 points a leaf over the block, within 2e-3 of
    /// the map's mass (the lamps hold 0.006 to 0.17 each; measured: 8e-4 at
    /// most); the coarse rule alone (2 x 2 points a leaf, about a point per cell
    /// of the map's density) misses more than 0.01 at some lamp (0.066, and
    /// nearly all of the lamps at the poles), so the test sees the refinement.
    #[test]
    fn small_lamps_keep_their_mass() {
        use crate::density::image::LuminanceImage;
        let (w, h) = (1024, 512);
        let mut values = vec![0.01f64; w * h];
        let lamps = [(100, 7), (333, 101), (517, 260), (780, 333), (901, 506)];
        for &(x, y) in &lamps {
            values[y * w + x] = 1000.0;
        }
        let img = LuminanceImage {
            width: w,
            height: h,
            values,
        };
        let map = EnvmapDensity::from_luminance_filtered(&img, Domain::Sphere, "lamps").unwrap();
        let levels = 9;
        let tree = EnvmapTree::new(&map, levels, 2).unwrap();
        let side = 1usize << levels;
        let (mut worst_tree, mut worst_coarse) = (0.0f64, 0.0f64);
        for &(x, y) in &lamps {
            // The lamp's pixel centre on the square, and the 8 x 8 leaves around it.
            let (phi, theta) = (
                2.0 * PI * (x as f64 + 0.5) / w as f64,
                PI * (y as f64 + 0.5) / h as f64,
            );
            let d = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let q = sphere_to_square(d);
            let at = |v: f64| ((v * side as f64) as usize).saturating_sub(4).min(side - 8);
            let (x0, y0) = (at(q.x), at(q.y));
            // The block's mass by 64 x 64 points a leaf, and by 2 x 2.
            let rule = |k: usize| -> f64 {
                let n = 8 * k;
                let area = 4.0 * PI / (side * side * k * k) as f64;
                let mut sum = 0.0;
                for b in 0..n {
                    for a in 0..n {
                        let p = DVec2::new(
                            (x0 as f64 + (a as f64 + 0.5) / k as f64) / side as f64,
                            (y0 as f64 + (b as f64 + 0.5) / k as f64) / side as f64,
                        );
                        sum += map.pdf(square_to_sphere(p)) * area;
                    }
                }
                sum
            };
            let (exact, coarse) = (rule(128), rule(2));
            let in_tree: f64 = (y0..y0 + 8)
                .flat_map(|by| (x0..x0 + 8).map(move |bx| (bx, by)))
                .map(|(bx, by)| {
                    let node = nuld_core::envmap_tree::node_index(levels, bx as u32, by as u32);
                    tree.nodes[node].mass() as f64
                })
                .sum();
            worst_tree = worst_tree.max((in_tree - exact).abs());
            worst_coarse = worst_coarse.max((coarse - exact).abs());
        }
        assert!(worst_tree < 2e-3, "tree off by {worst_tree}");
        assert!(
            worst_coarse > 1e-2,
            "the coarse rule off by only {worst_coarse}"
        );
    }

    #[test]
    fn the_estimate_with_the_trees_pdf_is_the_irradiance() {
        let dir = std::env::temp_dir().join(format!("nuld-tree-{}", std::process::id()));
        let map = EnvmapDensity::from_file_filtered(tiny_map(&dir), Domain::Sphere).unwrap();
        let tree = EnvmapTree::new(&map, 6, 9).unwrap();
        // The records, the top table (levels 1 to 4: 340 nodes a normal), the
        // corners and the detail.
        let detail = 4 * (tree.detail_index.len() + tree.detail.len());
        assert_eq!(
            tree.state_bytes(),
            16 * node_count(6) + 4 * 81 * ((4usize.pow(5) - 4) / 3) + 4 * 65 * 65 + detail
        );
        let total: f32 = tree.nodes[..4].iter().map(|r| r.mass()).sum();
        assert!((total - 1.0).abs() < 1e-3, "{total}");
        let core = tree.tree();
        assert_unbiased_irradiance(
            &map,
            1 << 12,
            0.002,
            |n, u| EnvmapTree::sample(&core, n, u),
            |n, d| EnvmapTree::pdf(&core, n, d),
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The unbiased mode on a map: the 64 points of `randomized_point` (instance
    /// 3, the pixel's `seed`) warped at one normal; over 4096
    /// seeds the mean of `(1/N) Σ g / pdf` is `∫ g` within 3 standard errors, for
    /// `g = L cos` and for `g = L cos f` (`f` the glTF BRDF at roughness 0.3, the
    /// view 40° from the normal), both integrals by an independent midpoint rule on
    /// the sphere. The pdf is the `f32` runtime's, the normal lit through its
    /// octahedral square point.
    #[test]
    fn the_unbiased_mode_is_unbiased_for_the_light_and_for_light_times_a_brdf() {
        use nuld_core::conditional::randomized_point;
        let dir = std::env::temp_dir().join(format!("nuld-tree-unbiased-{}", std::process::id()));
        let map = EnvmapDensity::from_file_filtered(tiny_map(&dir), Domain::Sphere).unwrap();
        let tree = EnvmapTree::new(&map, 7, 9).unwrap();
        let core = tree.tree();
        let n = DVec3::new(0.3, -0.4, 0.85).normalize();
        let q = nuld_core::sphere::sphere_to_square(n).as_vec2().to_array();
        let normal = DVec3::from_array(nuld_core::sphere::square_to_sphere_real(q).map(f64::from));
        // A frame about the normal for the BRDF: `t` any unit vector across it.
        let t = n.any_orthonormal_vector();
        let b = n.cross(t);
        let wo_world = (40f64.to_radians().sin() * t + 40f64.to_radians().cos() * n).normalize();
        let local = |d: DVec3| DVec3::new(d.dot(t), d.dot(b), d.dot(n));
        let wo = local(wo_world);
        let light = |d: DVec3| map.pdf(d) * map.integral();
        let g_light = |d: DVec3| light(d) * normal.dot(d).max(0.0);
        let g_brdf = |d: DVec3| {
            let c = normal.dot(d);
            if c <= 0.0 {
                return 0.0;
            }
            light(d) * nuld_core::brdf::BrdfModel::Gltf.cosine_weighted(wo, local(d), 0.3)
        };
        let exact = |g: &(dyn Fn(DVec3) -> f64 + Sync)| sphere_integral(2048, g);
        let n_points = 64u32;
        for (name, g) in [
            ("L cos", &g_light as &(dyn Fn(DVec3) -> f64 + Sync)),
            ("L cos f", &g_brdf),
        ] {
            let want = exact(g);
            let estimates: Vec<f64> = (0..4096u32)
                .into_par_iter()
                .map(|seed| {
                    (0..n_points)
                        .map(|i| {
                            let p = randomized_point(n_points, 19, 3, i, seed);
                            let (d, pdf) = core.sample_square(q, p);
                            let d = DVec3::from_array(d.map(f64::from));
                            if pdf > 0.0 {
                                g(d) / pdf as f64
                            } else {
                                0.0
                            }
                        })
                        .sum::<f64>()
                        / n_points as f64
                })
                .collect();
            let mean = estimates.iter().sum::<f64>() / estimates.len() as f64;
            let var = estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>()
                / (estimates.len() - 1) as f64;
            let se = (var / estimates.len() as f64).sqrt();
            assert!(
                (mean - want).abs() < 3.0 * se + 1e-3 * want,
                "{name}: {mean} vs {want} (se {se})"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
