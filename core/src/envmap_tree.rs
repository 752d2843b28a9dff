//! An environment map's light times the clamped cosine about a normal, sampled
//! exactly by hierarchical product warping ([`crate::quadtree`]; Clarberg and
//! Akenine-Möller 2008) with bounded work per node: the environment sampler's prior.
//!
//! **The state** is one pyramid of the map over the sphere's equal-area octahedral
//! square ([`crate::sphere`]), whatever the normals: every node of levels `1..=L`
//! holds a [`NodeRecord`], its mass `m0 = Σ mass` (the map's luminance over the
//! node), first moment `m1 = Σ mass l` and *spread* `s = sqrt(m0² - |m1|²)`
//! (`|l| = 1`, so `s² / m0` is the mass times the spread of `l` about its mean:
//! 0 for a point, `m0²` for light balanced about the origin).
//!
//! **The weight of a node for a normal `n`** stands in for `Σ mass max(0, n.l)`:
//!
//! ```text
//! w(n) = ( n.m1 + sqrt((n.m1)² + s²) ) / 2
//! ```
//!
//! the largest `Σ mass max(0, x)` over all distributions of `x = n.l` with the
//! node's mean `n.m1 / m0` and a variance up to `s² / m0²` (Scarf's bound; the
//! variance of `n.l` is at most the spread). So `w` is exact for a point-like
//! node, never below `max(0, n.m1)` (exact above the horizon but for a relative
//! excess of about `s² / (4 (n.m1)²)`, which vanishes with a node's size), small but
//! positive below the horizon, and positive wherever the node has spread: the pdf
//! is positive wherever the map's light meets the cosine, and `L cos / pdf` is
//! unbiased. Four records (64 bytes) and four square roots per level: `O(L)` per
//! sample, no recursion across the horizon.
//!
//! **The top levels are exact.** The bound is loose for a node that spans a large
//! part of the sphere across the horizon, and the first levels' choices move the
//! most mass: with the bound alone, 3 to 20 % of the samples of courtyard's light
//! fell below the horizon. So the weights of the nodes of levels `1..=T` (`T`
//! the tree's *top levels*, [`TOP_LEVELS`] = 4 in a tree written today: 340
//! nodes; 3 and 84 nodes in blobs written before, [`LEGACY_TOP_LEVELS`]) are
//! tabulated exactly, `Σ_leaves max(0, n.m1)`,
//! for a `G x G` grid of normals placed by their octahedral square points (nodes
//! at `j / (G - 1)`, on the square's edges, so no cell crosses the seam), and
//! interpolated bilinearly at the query; the bound times [`TOP_FLOOR`] stands
//! under them, so a node that the query's normal sees keeps a positive weight
//! even where the four grid normals around it see none of it.
//!
//! **Layout** ([`node_index`]): levels `1..=L` one after the other, each in Morton
//! order, so a node's four children are four consecutive records (one 64-byte
//! cache line when the table is 64-byte aligned): the record of child `(2x + i,
//! 2y + j)` of level `l + 1` is `4 (morton(x, y)) + i + 2 j` past the level's
//! first. The root's record is not stored.
//!
//! The square's pdf is the solid angle's times `4 pi` (the octahedral map has a
//! constant Jacobian), so [`EnvmapTree::sample`] and [`EnvmapTree::pdf`] answer
//! per steradian. Everything is generic over [`Real`] (`f32` in the runtime and
//! shaders, `f64` in the tool), allocates nothing and never panics.

use crate::bilinear;
use crate::cell_table;
use crate::quadtree::{self, ChildWeights, Node, QuadtreeError, MAX_LEVELS};
use crate::real::{clamp_unit, Real};
use crate::sphere::{sphere_to_square_real, square_to_sphere_real};
use bytemuck::{Pod, Zeroable};
use detail::Shape;

/// Most levels of an environment tree: `2^12 x 2^12` leaves (0.05° apart) are
/// finer than any map's pixels, and the records (22 M of them, 358 MB) past any
/// table worth shipping.
pub const MAX_TREE_LEVELS: u32 = 12;

/// One node of an environment tree (16 bytes, `#[repr(C)]`, little-endian):
/// `m1` and `s` of the module docs.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct NodeRecord {
    /// First moment `Σ mass l` of the node's light, `l` unit directions.
    pub moment: [f32; 3],
    /// Spread `s = sqrt(m0² - |m1|²) >= 0`.
    pub spread: f32,
}

impl NodeRecord {
    /// The record of a node with mass `m0 >= 0` and first moment `m1`, its spread
    /// at least `floor * m0` (a floor keeps a node's weight positive for every
    /// normal that sees part of it when the node's light was measured at too few
    /// points to show its extent). `m0² - |m1|²` is formed in `f64`.
    pub fn from_moments(m0: f64, m1: [f64; 3], floor: f64) -> Self {
        let s2 = m0 * m0 - (m1[0] * m1[0] + m1[1] * m1[1] + m1[2] * m1[2]);
        let s = libm::sqrt(s2.max(0.0)).max(floor * m0);
        Self {
            moment: m1.map(|v| v as f32),
            spread: s as f32,
        }
    }

    /// The node's mass `m0 = sqrt(|m1|² + s²)`.
    pub fn mass(&self) -> f32 {
        let [x, y, z] = self.moment;
        libm::sqrtf(x * x + y * y + z * z + self.spread * self.spread)
    }

    /// The node's weight for the unit normal `n` (module docs): `(n.m1 +
    /// sqrt((n.m1)² + s²)) / 2`, in `T`'s arithmetic.
    #[inline]
    pub fn weight<T: Real>(&self, n: [T; 3]) -> T {
        let m = self.moment.map(|v| T::of(v as f64));
        let a = n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
        let s = T::of(self.spread as f64);
        (a + (a * a + s * s).sqrt()) * T::of(0.5)
    }
}

/// The environment prior's info section (16 bytes, `#[repr(C)]`, little-endian).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct TreeInfo {
    /// Levels below the root, the top levels to [`MAX_TREE_LEVELS`].
    pub levels: u32,
    /// Normals per axis of the top-weight table, 2 to 1024.
    pub grid: u32,
    /// Levels whose weights the top table holds ([`LEGACY_TOP_LEVELS`] to
    /// [`MAX_TOP_LEVELS`]); 0 in blobs written before this field, which read as
    /// [`LEGACY_TOP_LEVELS`] ([`Self::top_levels`]).
    pub top_levels: u32,
    /// Reserved, zero.
    pub reserved: u32,
}

impl TreeInfo {
    /// The top levels this info names: [`Self::top_levels`], 0 read as
    /// [`LEGACY_TOP_LEVELS`] (the depth of every tree written before the field).
    pub fn top_levels(&self) -> u32 {
        if self.top_levels == 0 {
            LEGACY_TOP_LEVELS
        } else {
            self.top_levels
        }
    }
}

/// Size of [`TreeInfo`] in bytes.
pub const TREE_INFO_LEN: usize = core::mem::size_of::<TreeInfo>();

const _: () = assert!(TREE_INFO_LEN == 16 && core::mem::size_of::<NodeRecord>() == 16);

/// The three sections of an environment prior, in the order `core/FORMAT.md`
/// lists them, ready for [`crate::blob::write`] (after a conditional blob's own,
/// [`crate::conditional::sections`]). Checks no length: a reader validates them.
pub fn sections<'s>(
    info: &'s TreeInfo,
    nodes: &'s [NodeRecord],
    top: &'s [f32],
) -> [crate::blob::SectionSpec<'s>; 3] {
    use crate::blob::{SectionSpec, SectionTag};
    [
        SectionSpec {
            tag: SectionTag::EnvmapTreeInfo,
            elem_size: TREE_INFO_LEN as u32,
            bytes: bytemuck::bytes_of(info),
        },
        SectionSpec {
            tag: SectionTag::EnvmapTreeNodes,
            elem_size: 16,
            bytes: bytemuck::cast_slice(nodes),
        },
        SectionSpec {
            tag: SectionTag::EnvmapTreeTop,
            elem_size: 4,
            bytes: bytemuck::cast_slice(top),
        },
    ]
}

/// The leaf-shape section of `corners` ([`EnvmapTree::with_corners`]), for a
/// writer to add after [`sections`] when the tree has a shape.
pub fn corner_section(corners: &[f32]) -> crate::blob::SectionSpec<'_> {
    crate::blob::SectionSpec {
        tag: crate::blob::SectionTag::EnvmapTreeCorners,
        elem_size: 4,
        bytes: bytemuck::cast_slice(corners),
    }
}

/// Corner values of a tree with `levels` levels: `(2^L + 1)^2`.
pub fn corner_len(levels: u32) -> usize {
    let side = (1usize << levels.min(MAX_TREE_LEVELS)) + 1;
    side * side
}

/// Records of a tree with `levels` levels (levels `1..=L`): `(4^(L+1) - 4) / 3`.
pub fn node_count(levels: u32) -> usize {
    quadtree::pyramid_len(levels) - 1
}

/// Index of node `(x, y)` of level `1 <= level <= L` in the records (module docs'
/// layout). `x, y < 2^level`.
#[inline]
pub fn node_index(level: u32, x: u32, y: u32) -> usize {
    quadtree::level_offset(level) - 1 + quadtree::morton(x, y) as usize
}

/// Index of the first of `node`'s four children in the records,
/// [`node_index`] of child `(2x, 2y)`: `4 z` past the next level's first record
/// (`z` the node's Morton code, which a descent keeps as it goes).
#[inline]
fn first_child(node: Node) -> usize {
    quadtree::level_offset(node.level + 1) - 1 + 4 * node.z as usize
}

/// Levels whose nodes' weights a tree written today tabulates over a grid of
/// normals (module docs): 340 nodes a normal. Below them the bound is loose
/// where a node straddles the normal's horizon, and level 4's nodes (about 13°
/// across) were where most of the leaves' probabilities' distance from `L cos`
/// entered (docs/results/envmap.md#top-levels).
pub const TOP_LEVELS: u32 = 4;

/// The top levels of the trees written before [`TreeInfo::top_levels`] (84
/// nodes a normal), which still load.
pub const LEGACY_TOP_LEVELS: u32 = 3;

/// The deepest top table a reader accepts: 1364 nodes a normal.
pub const MAX_TOP_LEVELS: u32 = 5;

const _: () = assert!(node_count_const(LEGACY_TOP_LEVELS) == 84);
const _: () = assert!(node_count_const(TOP_LEVELS) == 340);

const fn node_count_const(levels: u32) -> usize {
    ((1usize << (2 * (levels + 1))) - 4) / 3
}

/// Records of levels `1..=`[`MAX_TOP_LEVELS`]: the longest top-table row.
const MAX_TOP_NODES: usize = node_count_const(MAX_TOP_LEVELS);

/// Share of the bound that stands under a tabulated top-level weight.
pub const TOP_FLOOR: f64 = 1e-3;

/// Entries of a top-weight table of `top_levels` levels on a grid of `grid x
/// grid` normals: `grid² x node_count(top_levels)` (340 per normal at
/// [`TOP_LEVELS`]), `[normal j1 grid + j0][node]` with the nodes in the
/// records' order.
pub fn top_len(grid: u32, top_levels: u32) -> usize {
    (grid as usize) * (grid as usize) * node_count(top_levels.min(MAX_TOP_LEVELS))
}

/// The unit normal of top-table grid node `(j0, j1)` of `grid x grid`: the
/// octahedral square's point `(j0, j1) / (grid - 1)` on the sphere.
pub fn top_normal(grid: u32, j: [u32; 2]) -> [f64; 3] {
    let g = (grid.max(2) - 1) as f64;
    square_to_sphere_real([j[0] as f64 / g, j[1] as f64 / g])
}

/// One row of a top-weight table of `top_levels` levels (at most
/// [`MAX_TOP_LEVELS`]), for the unit normal `n`: the exact weight `Σ_leaves
/// max(0, n.m1)` of each node of levels `1..=top_levels`, summed from the leaf
/// records of `nodes` (a tree of `levels >= top_levels` levels) in `f64`, each
/// node of the deepest top level over its leaves, every node above over its four
/// children. `row` holds [`node_count`]`(top_levels)` values (zeros for a tree
/// of no levels). `O(4^L)`.
pub fn top_row(levels: u32, top_levels: u32, nodes: &[NodeRecord], n: [f64; 3], row: &mut [f32]) {
    let mut sums = [0.0f64; MAX_TOP_NODES];
    if levels == 0 {
        row.iter_mut().for_each(|v| *v = 0.0);
        return;
    }
    let deepest = top_levels.min(MAX_TOP_LEVELS).min(levels);
    // Level `l`'s records start at its node (0, 0), each level in Morton order.
    let first = |l: u32| node_index(l, 0, 0);
    let leaves = nodes.get(first(levels)..).unwrap_or(&[]);
    // The leaves in their Morton order, which is the records' order (a bake asks
    // for thousands of rows of a tree of megabytes): leaf `k`'s ancestor on level
    // `l` is node `k >> 2 (L - l)` of that level.
    let shift = 2 * (levels - deepest);
    let base = first(deepest);
    for (k, r) in leaves.iter().take(1 << (2 * levels)).enumerate() {
        let m = r.moment;
        let w = (n[0] * m[0] as f64 + n[1] * m[1] as f64 + n[2] * m[2] as f64).max(0.0);
        sums[base + (k >> shift)] += w;
    }
    for l in (1..deepest).rev() {
        let (parents, children) = (first(l), first(l + 1));
        for q in 0..1usize << (2 * l) {
            let c = children + 4 * q;
            sums[parents + q] = sums[c] + sums[c + 1] + sums[c + 2] + sums[c + 3];
        }
    }
    for (out, v) in row.iter_mut().zip(sums) {
        *out = v as f32;
    }
}

/// Spread floor of a node of level `l`, as a fraction of its mass: `SPREAD_FLOOR /
/// 2^l`, about a quarter of the angular radius of a node of that level (a node is
/// about `3.5 / 2^l` radians across).
pub const SPREAD_FLOOR: f64 = 0.25;

/// Fills `nodes` ([`node_count`]`(levels)` records) from the `2^L x 2^L` leaves'
/// `[m0, m1.x, m1.y, m1.z]` (row-major, `f64`): every node's mass and moment are
/// the sums over its leaves (in `f64`), its spread is formed from them with the
/// floor [`SPREAD_FLOOR`]` / 2^l`. `O(L 4^L)`, no allocation. An error if the
/// lengths or `levels` are wrong.
pub fn build(
    levels: u32,
    leaves: &[[f64; 4]],
    nodes: &mut [NodeRecord],
) -> Result<(), QuadtreeError> {
    if levels == 0 || levels > MAX_TREE_LEVELS {
        return Err(QuadtreeError::Levels(levels));
    }
    let side = 1usize << levels;
    for (expected, got) in [
        (side * side, leaves.len()),
        (node_count(levels), nodes.len()),
    ] {
        if expected != got {
            return Err(QuadtreeError::Length {
                expected: expected as u64,
                got: got as u64,
            });
        }
    }
    for l in 1..=levels {
        let (s, block) = (1usize << l, 1usize << (levels - l));
        for y in 0..s {
            for x in 0..s {
                let mut sum = [0.0f64; 4];
                for ly in y * block..(y + 1) * block {
                    for leaf in &leaves[ly * side + x * block..ly * side + (x + 1) * block] {
                        for c in 0..4 {
                            sum[c] += leaf[c];
                        }
                    }
                }
                let floor = SPREAD_FLOOR / s as f64;
                nodes[node_index(l, x as u32, y as u32)] =
                    NodeRecord::from_moments(sum[0], [sum[1], sum[2], sum[3]], floor);
            }
        }
    }
    Ok(())
}

/// A borrowed environment tree (module docs).
#[derive(Clone, Copy, Debug)]
pub struct EnvmapTree<'a> {
    levels: u32,
    nodes: &'a [NodeRecord],
    grid: u32,
    top: &'a [f32],
    /// Levels whose weights `top` holds.
    top_levels: u32,
    /// The leaf shape: `(2^L + 1)^2` corner values, row-major; empty for
    /// uniform leaves.
    corners: &'a [f32],
    /// Per leaf (row-major), 0 or `1 + t` for detail table `t`; empty without
    /// detailed leaves.
    detail_index: &'a [u32],
    /// The detailed leaves' tables, [`DETAIL_LEN`] values each.
    detail: &'a [f32],
    /// The fine tables, [`FINE_LEN`] values each.
    fine: &'a [f32],
}

impl<'a> EnvmapTree<'a> {
    /// The tree of `levels` levels (`top_levels` to [`MAX_TREE_LEVELS`]) over
    /// `nodes`, with the top-weight table `top` of `top_levels` levels
    /// ([`LEGACY_TOP_LEVELS`] to [`MAX_TOP_LEVELS`]) on `grid x grid` normals (at
    /// least 2 per axis): checks the counts ([`node_count`], [`top_len`]), every value
    /// finite, every spread and top weight non-negative, and some light (a level-1
    /// record with positive mass). A tree whose parents are not the sums of their
    /// children, or whose top table is not theirs, still never panics; it
    /// describes another warp, sampled as exactly.
    pub fn new(
        levels: u32,
        nodes: &'a [NodeRecord],
        grid: u32,
        top: &'a [f32],
        top_levels: u32,
    ) -> Result<Self, QuadtreeError> {
        let tree = Self::view(levels, nodes, grid, top, top_levels)?;
        tree.check_values()?;
        Ok(tree)
    }

    /// [`Self::new`] without the per-value checks: the levels, grid and counts
    /// only, `O(1)` (for a reader that checked the values once). A tree with bad
    /// values still never panics; it describes another warp.
    pub fn view(
        levels: u32,
        nodes: &'a [NodeRecord],
        grid: u32,
        top: &'a [f32],
        top_levels: u32,
    ) -> Result<Self, QuadtreeError> {
        if !(LEGACY_TOP_LEVELS..=MAX_TOP_LEVELS).contains(&top_levels) {
            return Err(QuadtreeError::TopLevels(top_levels));
        }
        if !(top_levels..=MAX_TREE_LEVELS.min(MAX_LEVELS)).contains(&levels) {
            return Err(QuadtreeError::Levels(levels));
        }
        if !(2..=1024).contains(&grid) || top.len() != top_len(grid, top_levels) {
            return Err(QuadtreeError::Length {
                expected: top_len(grid.clamp(2, 1024), top_levels) as u64,
                got: top.len() as u64,
            });
        }
        if nodes.len() != node_count(levels) {
            return Err(QuadtreeError::Length {
                expected: node_count(levels) as u64,
                got: nodes.len() as u64,
            });
        }
        Ok(Self {
            levels,
            nodes,
            grid,
            top,
            top_levels,
            corners: &[],
            detail_index: &[],
            detail: &[],
            fine: &[],
        })
    }

    /// The tree with a shape inside its leaves: `corners` holds `(2^L + 1)^2`
    /// values on the leaves' corners (row-major over the octahedral square,
    /// finite and non-negative), and a point inside a leaf is drawn by the
    /// bilinear warp of its four corners ([`bilinear`]), the leaf's probability
    /// unchanged; empty `corners` keep the leaves uniform. An error if the length
    /// is wrong (`O(1)`; [`Self::check_values`] reads the values). A tree with
    /// bad corner values still never panics; it describes another warp.
    pub fn with_corners(self, corners: &'a [f32]) -> Result<Self, QuadtreeError> {
        if !corners.is_empty() && corners.len() != corner_len(self.levels) {
            return Err(QuadtreeError::Length {
                expected: corner_len(self.levels) as u64,
                got: corners.len() as u64,
            });
        }
        Ok(Self { corners, ..self })
    }

    /// The leaf shape's corner values (empty for uniform leaves).
    pub fn corners(&self) -> &'a [f32] {
        self.corners
    }

    /// The four corner values of leaf `(x, y)`, `[w00, w10, w01, w11]`, or
    /// `None` for uniform leaves.
    #[inline]
    fn corners_of<T: Real>(&self, leaf: [u32; 2]) -> Option<[T; 4]> {
        if self.corners.is_empty() {
            return None;
        }
        let side = (1usize << self.levels) + 1;
        let (x, y) = (leaf[0] as usize, leaf[1] as usize);
        let at = |dx: usize, dy: usize| {
            T::of(
                self.corners
                    .get((y + dy) * side + x + dx)
                    .copied()
                    .unwrap_or(0.0) as f64,
            )
        };
        Some([at(0, 0), at(1, 0), at(0, 1), at(1, 1)])
    }

    /// The square point, its pdf per unit area of the square and its
    /// derivatives `[dx/du.x, dy/du.x, dy/du.y]` for `lit` at `u`, shaped inside
    /// the leaf when the tree has corners ([`quadtree::sample_with_slopes`],
    /// [`bilinear::sample_bilinear`]).
    #[inline]
    fn warp<T: Real>(&self, lit: &Lit<'a, T>, u: [T; 2]) -> ([T; 2], T, [T; 3]) {
        let d = quadtree::descend(lit, u);
        let (local, density, s) = match self.shape_of::<T>(d.leaf) {
            Shape::Table(v) => cell_table::sample_table::<T, DETAIL_SIDE>(d.local, v),
            Shape::FineTable(v) => cell_table::sample_table::<T, FINE_SIDE>(d.local, v),
            Shape::Corners(w) => bilinear::sample_bilinear(d.local, w),
            Shape::Uniform => (d.local, T::ONE, [T::ONE, T::ZERO, T::ONE]),
        };
        let side = T::of((1u64 << self.levels) as f64);
        let point = quadtree::leaf_point(self.levels, d.leaf, local);
        // Within the descent's piece the leaf's local primary point is affine
        // per axis (`1 / column`, `1 / row`), and the leaf is `1 / side` wide.
        let slopes = [
            s[0] / (side * d.column),
            s[1] / (side * d.column),
            s[2] / (side * d.row),
        ];
        (point, d.share * side * side * density, slopes)
    }

    /// The density per unit area of the square at `p` for `lit`.
    #[inline]
    fn square_pdf<T: Real>(&self, lit: &Lit<'a, T>, p: [T; 2]) -> T {
        let pdf = quadtree::pdf(lit, p);
        let (leaf, local) = quadtree::locate(self.levels, p);
        match self.shape_of::<T>(leaf) {
            Shape::Table(v) => pdf * cell_table::table_pdf::<T, DETAIL_SIDE>(local, v),
            Shape::FineTable(v) => pdf * cell_table::table_pdf::<T, FINE_SIDE>(local, v),
            Shape::Corners(w) => pdf * bilinear::bilinear_pdf(local, w),
            Shape::Uniform => pdf,
        }
    }

    /// The per-value checks of [`Self::new`]: every top weight, leaf corner and
    /// detail value finite and non-negative, every detail-index entry naming a
    /// table that exists, every record finite with a non-negative spread, some
    /// light on level 1. `O(records)`.
    pub fn check_values(&self) -> Result<(), QuadtreeError> {
        if let Some(i) = self.top.iter().position(|v| !(*v >= 0.0 && v.is_finite())) {
            return Err(QuadtreeError::BadTopWeight(i as u64));
        }
        if let Some(i) = self
            .corners
            .iter()
            .position(|v| !(*v >= 0.0 && v.is_finite()))
        {
            return Err(QuadtreeError::BadCorner(i as u64));
        }
        self.check_detail()?;
        if let Some(i) = self.nodes.iter().position(|r| {
            !(r.moment.iter().all(|v| v.is_finite()) && r.spread >= 0.0 && r.spread.is_finite())
        }) {
            return Err(QuadtreeError::BadMass(i as u64));
        }
        if !self.nodes[..4]
            .iter()
            .any(|r| r.mass() > 0.0 && r.mass().is_finite())
        {
            return Err(QuadtreeError::NoMass);
        }
        Ok(())
    }

    /// Levels below the root (`2^L x 2^L` leaves).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// The records.
    pub fn nodes(&self) -> &'a [NodeRecord] {
        self.nodes
    }

    /// The tree lit by the cosine about `normal` (normalized here; a zero, tiny or
    /// non-finite normal reads as `+z`).
    #[inline]
    pub fn lit<T: Real>(&self, normal: [T; 3]) -> Lit<'a, T> {
        let n = unit_or_z(normal);
        self.lit_with(n, sphere_to_square_real(n))
    }

    /// The tree lit by the cosine about the normal whose octahedral square point
    /// is `q` (clamped into the square): the normal `square_to_sphere(q)`, the top
    /// table's cell read from `q` itself. What the runtime and the shaders use, whose
    /// condition is that point: no inverse trigonometry on the way.
    #[inline]
    pub fn lit_square<T: Real>(&self, q: [T; 2]) -> Lit<'a, T> {
        let q = q.map(clamp_unit);
        self.lit_with(unit_or_z(square_to_sphere_real(q)), q)
    }

    /// The tree lit by the unit normal `n` whose octahedral square point is `q`.
    #[inline]
    fn lit_with<T: Real>(&self, n: [T; 3], q: [T; 2]) -> Lit<'a, T> {
        let g = self.grid.max(2) - 1;
        let cell = q.map(|c| {
            let s = clamp_unit(c) * T::of(g as f64);
            let j0 = (s.floor().to_f64() as u32).min(g - 1);
            (j0, s - T::of(j0 as f64))
        });
        let [(x0, tx), (y0, ty)] = cell;
        let (g, per) = (self.grid as usize, node_count(self.top_levels));
        let row = |dx: usize, dy: usize| ((y0 as usize + dy) * g + x0 as usize + dx) * per;
        Lit {
            tree: *self,
            n,
            top_rows: [row(0, 0), row(1, 0), row(0, 1), row(1, 1)],
            top_at: [tx, ty],
        }
    }

    /// Normals per axis of the top-weight table.
    pub fn grid(&self) -> u32 {
        self.grid
    }

    /// The top-weight table.
    pub fn top(&self) -> &'a [f32] {
        self.top
    }

    /// Levels whose weights the top table holds.
    pub fn top_levels(&self) -> u32 {
        self.top_levels
    }

    /// The direction at primary sample `u` in `[0,1]^2` (clamped) for `normal`,
    /// and its solid-angle pdf ([`Self::pdf`]). `O(L)`; never panics.
    #[inline]
    pub fn sample<T: Real>(&self, normal: [T; 3], u: [T; 2]) -> ([T; 3], T) {
        let (p, pdf, _) = self.warp(&self.lit(normal), u);
        (square_to_sphere_real(p), pdf / (T::of(4.0) * T::PI))
    }

    /// [`Self::sample`] for the normal whose octahedral square point is `q`
    /// ([`Self::lit_square`]). `O(L)`; never panics.
    #[inline]
    pub fn sample_square<T: Real>(&self, q: [T; 2], u: [T; 2]) -> ([T; 3], T) {
        let (p, pdf, _) = self.warp(&self.lit_square(q), u);
        (square_to_sphere_real(p), pdf / (T::of(4.0) * T::PI))
    }

    /// [`Self::sample_square`]'s point of the octahedral square (before the
    /// sphere map), its pdf per unit area of the square, and the derivatives
    /// `[dx/du.x, dy/du.x, dy/du.y]` of the point (`dx/du.y` is 0), exact within
    /// the piece of the tree `u` falls in ([`quadtree::sample_with_slopes`];
    /// `dy/du.x` is nonzero only inside a shaped leaf,
    /// [`bilinear::sample_bilinear`]).
    #[inline]
    pub fn sample_square_with_slopes<T: Real>(&self, q: [T; 2], u: [T; 2]) -> ([T; 2], T, [T; 3]) {
        self.warp(&self.lit_square(q), u)
    }

    /// [`Self::pdf`] for the normal whose octahedral square point is `q`.
    #[inline]
    pub fn pdf_square<T: Real>(&self, q: [T; 2], d: [T; 3]) -> T {
        self.square_pdf(&self.lit_square(q), sphere_to_square_real(d)) / (T::of(4.0) * T::PI)
    }

    /// The solid-angle density of [`Self::sample`]'s directions at the unit
    /// direction `d` for `normal`. `O(L)`; never panics.
    #[inline]
    pub fn pdf<T: Real>(&self, normal: [T; 3], d: [T; 3]) -> T {
        self.square_pdf(&self.lit(normal), sphere_to_square_real(d)) / (T::of(4.0) * T::PI)
    }

    /// The primary sample that [`Self::sample`] maps to the unit direction `d`.
    pub fn invert<T: Real>(&self, normal: [T; 3], d: [T; 3]) -> [T; 2] {
        let p = sphere_to_square_real(d);
        let (leaf, local) = quadtree::locate(self.levels, p);
        // The point the uniform leaf would have put where the shape put `p`.
        let p = match self.shape_of::<T>(leaf) {
            Shape::Table(v) => quadtree::leaf_point(
                self.levels,
                leaf,
                cell_table::invert_table::<T, DETAIL_SIDE>(local, v),
            ),
            Shape::FineTable(v) => quadtree::leaf_point(
                self.levels,
                leaf,
                cell_table::invert_table::<T, FINE_SIDE>(local, v),
            ),
            Shape::Corners(w) => {
                quadtree::leaf_point(self.levels, leaf, bilinear::invert_bilinear(local, w))
            }
            Shape::Uniform => p,
        };
        quadtree::invert(&self.lit(normal), p)
    }
}

/// An [`EnvmapTree`] lit by the cosine about one normal: its [`ChildWeights`].
#[derive(Clone, Copy, Debug)]
pub struct Lit<'a, T> {
    tree: EnvmapTree<'a>,
    n: [T; 3],
    /// Where the top table's rows for the four grid normals around the query
    /// start (`[00, 10, 01, 11]`), worked out once per query rather than per
    /// node.
    top_rows: [usize; 4],
    /// The query's fraction of the way across its top-table cell, per axis.
    top_at: [T; 2],
}

impl<T: Real> Lit<'_, T> {
    /// Bilinear interpolation of the weights of the four top-table nodes from
    /// `first` on (a node's children, stored side by side) at the normal. Each
    /// of the four grid normals' rows is read as one run of four values, not
    /// four lookups (a missing run reads as 0).
    #[inline]
    fn top_weights(&self, first: usize) -> [T; 4] {
        let [tx, ty] = self.top_at;
        let run = |r: usize| -> [f32; 4] {
            match self.tree.top.get(r + first..r + first + 4) {
                Some(&[a, b, c, d]) => [a, b, c, d],
                _ => [0.0; 4],
            }
        };
        let v = self.top_rows.map(run);
        core::array::from_fn(|k| {
            let at = |row: usize| T::of(v[row][k] as f64);
            let a = at(0) + (at(1) - at(0)) * tx;
            let b = at(2) + (at(3) - at(2)) * tx;
            a + (b - a) * ty
        })
    }
}

impl<T: Real> ChildWeights<T> for Lit<'_, T> {
    fn levels(&self) -> u32 {
        self.tree.levels
    }

    #[inline]
    fn children(&self, node: Node) -> [T; 4] {
        let (level, first) = (node.level, first_child(node));
        let Some(c) = self.tree.nodes.get(first..first + 4) else {
            return [T::ONE; 4];
        };
        let bound: [T; 4] = core::array::from_fn(|k| c[k].weight(self.n));
        if level < self.tree.top_levels {
            let top = self.top_weights(first);
            core::array::from_fn(|k| top[k].max(bound[k] * T::of(TOP_FLOOR)))
        } else {
            bound
        }
    }
}

/// `v / |v|`, or `+z` where `|v|` is 0, tiny or not finite.
fn unit_or_z<T: Real>(v: [T; 3]) -> [T; 3] {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if len > T::of(1e-20) && len.is_finite() {
        v.map(|c| c / len)
    } else {
        [T::ZERO, T::ZERO, T::ONE]
    }
}

mod detail;
pub use detail::{
    detail_index_len, detail_sections, fine_section, DETAIL_LEN, DETAIL_SIDE, FINE_BIT, FINE_LEN,
    FINE_SIDE,
};

#[cfg(test)]
mod tests;
