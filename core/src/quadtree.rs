//! Hierarchical product warping (Clarberg, Jarosz, Akenine-Möller and Jensen 2005;
//! Clarberg and Akenine-Möller 2008): a density on the unit square given by a
//! quadtree of masses (a mip pyramid of sums), reweighted at the query (e.g. by a
//! cosine about a normal), sampled exactly.
//!
//! **The density.** At each node the four children weigh `weight(c)`, which the
//! query computes from the child's level, position and mass; a
//! sample descends from the root, choosing a column by the two columns' weights
//! and then a child in it, and remaps its primary sample into the chosen part (so
//! nearby primary samples stay nearby); at a leaf it is uniform. The density at a
//! point is the product of the chosen children's shares along its path times
//! `4^L` (the leaf's inverse area): [`QuadtreeWarp::pdf`] computes it by the same
//! descent, so it is *exactly* the density of [`QuadtreeWarp::sample`]'s points.
//! A child without mass weighs 0; negative and NaN weights count as 0. Where all
//! four children of a node weigh 0 (the query's weights vanish on a node the path
//! reached), the masses alone decide, and where those are 0 too, the four children
//! share equally: the rule `sample` and `pdf` both follow.
//!
//! **Unbiasedness** of `g / pdf` needs `pdf > 0` wherever `g` is: weights that are
//! positive on every node where the query's function is (for a product
//! `mass x f`, e.g. the mass times an upper bound of `f` over the node) give it.
//!
//! The descent itself ([`sample`], [`pdf`], [`invert`]) is written once over
//! [`ChildWeights`], whatever computes the weights.
//!
//! Work per sample `O(L)` (four weights per level), no allocation, no panic.

use crate::real::{clamp_unit, is_positive_finite, positive, Real};

/// Most levels below the root (`4^24` leaves is far beyond any table).
pub const MAX_LEVELS: u32 = 24;

/// Why a pyramid was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QuadtreeError {
    /// More than [`MAX_LEVELS`] levels.
    Levels(u32),
    /// The leaves are not `4^L` masses, or the pyramid is not `(4^(L+1) - 1) / 3`.
    Length {
        /// Length the levels ask for.
        expected: u64,
        /// Length given.
        got: u64,
    },
    /// A mass is negative, NaN or infinite (index into the pyramid).
    BadMass(u64),
    /// The root's mass is 0.
    NoMass,
    /// A tabulated weight ([`crate::envmap_tree`]'s top table) is negative, NaN or
    /// infinite (index into the table).
    BadTopWeight(u64),
    /// A leaf-corner value ([`crate::envmap_tree`]'s leaf shape) is negative,
    /// NaN or infinite (index into the corners).
    BadCorner(u64),
    /// A detail-index entry ([`crate::envmap_tree::EnvmapTree::with_detail`])
    /// names a table past the tables, or fine table 0 (index into the index).
    BadDetailIndex(u64),
    /// A detail-table value is negative, NaN or infinite (index into the
    /// tables).
    BadDetail(u64),
    /// A fine-table value is negative, NaN or infinite (index into the fine
    /// tables).
    BadFineDetail(u64),
    /// An environment tree's top table names a depth outside
    /// [`crate::envmap_tree::LEGACY_TOP_LEVELS`]`..=`[`crate::envmap_tree::MAX_TOP_LEVELS`].
    TopLevels(u32),
}

impl core::fmt::Display for QuadtreeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Levels(l) => write!(f, "{l} quadtree levels (at most {MAX_LEVELS})"),
            Self::Length { expected, got } => {
                write!(f, "quadtree of {got} masses, expected {expected}")
            }
            Self::BadMass(i) => write!(f, "quadtree mass {i} is negative or not finite"),
            Self::NoMass => write!(f, "quadtree without mass"),
            Self::BadTopWeight(i) => {
                write!(f, "top-level weight {i} is negative or not finite")
            }
            Self::BadCorner(i) => write!(f, "leaf corner {i} is negative or not finite"),
            Self::BadDetailIndex(i) => {
                write!(f, "detail index entry {i} names a table past the tables")
            }
            Self::BadDetail(i) => write!(f, "detail value {i} is negative or not finite"),
            Self::BadFineDetail(i) => {
                write!(f, "fine detail value {i} is negative or not finite")
            }
            Self::TopLevels(t) => write!(
                f,
                "top table of {t} levels (from {} to {})",
                crate::envmap_tree::LEGACY_TOP_LEVELS,
                crate::envmap_tree::MAX_TOP_LEVELS
            ),
        }
    }
}

impl core::error::Error for QuadtreeError {}

/// Offset of level `l`'s first node in a pyramid: `(4^l - 1) / 3`. Level `l`
/// holds `2^l x 2^l` nodes, row-major.
pub fn level_offset(l: u32) -> usize {
    ((1usize << (2 * l)) - 1) / 3
}

/// Length of a pyramid with `levels` levels below the root.
pub fn pyramid_len(levels: u32) -> usize {
    level_offset(levels + 1)
}

/// Fills `pyramid` from the `2^L x 2^L` leaf masses `leaves` (row-major): level
/// `L` is the leaves, every node above the sum of its four children.
pub fn build_pyramid<T: Real>(
    levels: u32,
    leaves: &[T],
    pyramid: &mut [T],
) -> Result<(), QuadtreeError> {
    if levels > MAX_LEVELS {
        return Err(QuadtreeError::Levels(levels));
    }
    let side = 1usize << levels;
    for (expected, got) in [
        (side * side, leaves.len()),
        (pyramid_len(levels), pyramid.len()),
    ] {
        if expected != got {
            return Err(QuadtreeError::Length {
                expected: expected as u64,
                got: got as u64,
            });
        }
    }
    let leaf = level_offset(levels);
    pyramid[leaf..leaf + side * side].copy_from_slice(leaves);
    for l in (0..levels).rev() {
        let (s, o, c) = (1usize << l, level_offset(l), level_offset(l + 1));
        for y in 0..s {
            for x in 0..s {
                let child = |i: usize, j: usize| pyramid[c + (2 * y + j) * 2 * s + 2 * x + i];
                pyramid[o + y * s + x] = child(0, 0) + child(1, 0) + child(0, 1) + child(1, 1);
            }
        }
    }
    Ok(())
}

/// A hierarchical warp over a borrowed pyramid (see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct QuadtreeWarp<'a, T> {
    levels: u32,
    pyramid: &'a [T],
}

/// One level's choice on a path: the column share, the column, the child's share
/// within its column and the row.
#[derive(Clone, Copy)]
struct Step<T> {
    px: T,
    i: usize,
    py: T,
    j: usize,
}

impl<'a, T: Real> QuadtreeWarp<'a, T> {
    /// The warp over `pyramid` (as [`build_pyramid`] writes it) with `levels`
    /// levels below the root; checks the length, every mass finite and
    /// non-negative, and the root's mass positive. A pyramid whose nodes are not
    /// the sums of their children still never makes the warp panic; its pdf is
    /// then the density of the warp it describes all the same (the shares use the
    /// children only).
    pub fn new(levels: u32, pyramid: &'a [T]) -> Result<Self, QuadtreeError> {
        if levels > MAX_LEVELS {
            return Err(QuadtreeError::Levels(levels));
        }
        if pyramid.len() != pyramid_len(levels) {
            return Err(QuadtreeError::Length {
                expected: pyramid_len(levels) as u64,
                got: pyramid.len() as u64,
            });
        }
        if let Some(i) = pyramid
            .iter()
            .position(|&m| !(m >= T::ZERO && m.is_finite()))
        {
            return Err(QuadtreeError::BadMass(i as u64));
        }
        if pyramid[0] <= T::ZERO {
            return Err(QuadtreeError::NoMass);
        }
        Ok(Self { levels, pyramid })
    }

    /// Levels below the root (`2^L x 2^L` leaves).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// The four children's weights of node `(x, y)` of level `l` (`[i + 2 j]` for
    /// child `(2x + i, 2y + j)`), by the module docs' rule.
    fn weights(
        &self,
        l: u32,
        x: usize,
        y: usize,
        weight: &impl Fn(u32, u32, u32, T) -> T,
    ) -> [T; 4] {
        let s = 1usize << (l + 1);
        let o = level_offset(l + 1);
        let mass = |i: usize, j: usize| self.pyramid[o + (2 * y + j) * s + 2 * x + i];
        let m = [mass(0, 0), mass(1, 0), mass(0, 1), mass(1, 1)];
        let mut w = [T::ZERO; 4];
        for k in 0..4 {
            let (cx, cy) = ((2 * x + (k & 1)) as u32, (2 * y + (k >> 1)) as u32);
            if m[k] > T::ZERO {
                w[k] = positive(weight(l + 1, cx, cy, m[k]));
            }
        }
        if sum4(w) > T::ZERO {
            w
        } else {
            m
        }
    }

    /// Draws the point at primary sample `u` in `[0,1]^2` (clamped into it, NaN as
    /// 0), children weighed by `weight(level, x, y, mass)`, and returns it with its
    /// density per unit area of the square ([`Self::pdf`]).
    pub fn sample(&self, u: [T; 2], weight: impl Fn(u32, u32, u32, T) -> T) -> ([T; 2], T) {
        sample(&self.query(weight), u)
    }

    /// The density at `p` (clamped into the square) of [`Self::sample`]'s points.
    pub fn pdf(&self, p: [T; 2], weight: impl Fn(u32, u32, u32, T) -> T) -> T {
        pdf(&self.query(weight), p)
    }

    /// The primary sample that [`Self::sample`] maps to `p` (clamped into the
    /// square).
    pub fn invert(&self, p: [T; 2], weight: impl Fn(u32, u32, u32, T) -> T) -> [T; 2] {
        invert(&self.query(weight), p)
    }

    fn query<F: Fn(u32, u32, u32, T) -> T>(&self, weight: F) -> Query<'_, 'a, T, F> {
        Query { warp: self, weight }
    }
}

/// A [`QuadtreeWarp`] with the weight function of one query.
struct Query<'w, 'a, T, F> {
    warp: &'w QuadtreeWarp<'a, T>,
    weight: F,
}

impl<T: Real, F: Fn(u32, u32, u32, T) -> T> ChildWeights<T> for Query<'_, '_, T, F> {
    fn levels(&self) -> u32 {
        self.warp.levels
    }

    fn children(&self, node: Node) -> [T; 4] {
        self.warp
            .weights(node.level, node.x as usize, node.y as usize, &self.weight)
    }
}

/// A quadtree as one query sees it: the weights of every node's four children.
/// [`sample`], [`pdf`] and [`invert`] descend it; any type that can weigh a node's
/// children (a mass pyramid reweighed by a function, [`QuadtreeWarp`]; a
/// pyramid of moments lit by a cosine, [`crate::envmap_tree`]) is sampled by the
/// same arithmetic.
pub trait ChildWeights<T> {
    /// Levels below the root (`2^L x 2^L` leaves), at most [`MAX_LEVELS`].
    fn levels(&self) -> u32;

    /// The weights of the four children of `node` (`[i + 2 j]` for child `(2x +
    /// i, 2y + j)` of level `node.level + 1`, `node.level < levels()`),
    /// proportional to the share of samples each receives. Negative and NaN
    /// weights count as 0; where all four are 0 (or one is infinite) the four
    /// children share equally.
    fn children(&self, node: Node) -> [T; 4];
}

/// A node of a quadtree as a descent reaches it: its level, column `x` and row
/// `y` (each below `2^level`) and its Morton code `z`, `x`'s bits on the even
/// bits and `y`'s on the odd ones ([`morton`]). A descent keeps `z` as it goes,
/// `z' = 4 z + i + 2 j` for child `(2x + i, 2y + j)`, so that a table in Morton
/// order ([`crate::envmap_tree`]) finds a node's children without interleaving
/// bits on the path from one level's choice to the next level's reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Node {
    /// Levels below the root, at most [`MAX_LEVELS`].
    pub level: u32,
    /// Column, below `2^level`.
    pub x: u32,
    /// Row, below `2^level`.
    pub y: u32,
    /// [`morton`]`(x, y)`.
    pub z: u64,
}

impl Node {
    /// The root.
    pub const ROOT: Self = Self {
        level: 0,
        x: 0,
        y: 0,
        z: 0,
    };

    /// Node `(x, y)` of level `level`, its Morton code computed.
    #[inline]
    pub fn new(level: u32, x: u32, y: u32) -> Self {
        Self {
            level,
            x,
            y,
            z: morton(x, y),
        }
    }

    /// Child `k = i + 2 j` (`k < 4`), node `(2x + i, 2y + j)` of the next level.
    #[inline]
    pub fn child(self, k: u32) -> Self {
        let (i, j) = (k & 1, (k >> 1) & 1);
        Self {
            level: self.level + 1,
            x: 2 * self.x + i,
            y: 2 * self.y + j,
            z: 4 * self.z + (k & 3) as u64,
        }
    }

    /// The ancestor of leaf `leaf` on level `level` of a tree of `levels >=
    /// level` levels, its Morton code `leaf_z >> 2 (levels - level)` (`leaf_z`
    /// the leaf's).
    #[inline]
    fn ancestor(levels: u32, leaf: [u32; 2], leaf_z: u64, level: u32) -> Self {
        let shift = levels - level;
        Self {
            level,
            x: leaf[0] >> shift,
            y: leaf[1] >> shift,
            z: leaf_z >> (2 * shift),
        }
    }
}

/// The Morton code of `(x, y)`: `x`'s bits on the even bits, `y`'s on the odd
/// bits (32 bits each).
#[inline]
pub fn morton(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    }
    spread(x) | (spread(y) << 1)
}

/// The children's weights of a node as every descent reads them
/// ([`sample`], [`pdf`], [`invert`]): negative, NaN and infinite weights read as
/// 0, and four zeros (or a sum that is not positive and finite) as four ones.
/// Never panics.
#[inline]
pub fn usable<T: Real>(w: [T; 4]) -> [T; 4] {
    let w = w.map(positive);
    if is_positive_finite(sum4(w)) {
        w
    } else {
        [T::ONE; 4]
    }
}

/// Draws the point of `tree` at primary sample `u` in `[0,1]^2` (clamped into it,
/// NaN as 0) and returns it with its density per unit area of the square
/// ([`pdf`]). The descent picks a column by `u.x` and a child in it by `u.y` at
/// every level and rescales `u` into the chosen part, so the warp is continuous
/// within each level's split; at a leaf it is uniform. `O(levels)`; never panics.
#[inline]
pub fn sample<T: Real>(tree: &impl ChildWeights<T>, u: [T; 2]) -> ([T; 2], T) {
    let (point, pdf, _) = sample_with_slopes(tree, u);
    (point, pdf)
}

/// [`sample`] with the warp's derivatives `(dx/du.x, dy/du.y)` at `u`: within
/// the piece of the descent that `u` falls in (the same children chosen at every
/// level) the point's `x` is affine in `u.x` with slope `1 / (2^L ∏ column
/// shares)` and its `y` affine in `u.y` with slope `1 / (2^L ∏ row shares)`, the
/// cross derivatives 0. (Across a split the warp jumps; these are the one-sided
/// derivatives of the piece.) What a trainer chains its gradients through.
#[inline]
pub fn sample_with_slopes<T: Real>(tree: &impl ChildWeights<T>, u: [T; 2]) -> ([T; 2], T, [T; 2]) {
    let levels = tree.levels().min(MAX_LEVELS);
    let d = descend(tree, u);
    let side = T::of((1u64 << levels) as f64);
    let slopes = [T::ONE / (side * d.column), T::ONE / (side * d.row)];
    (
        leaf_point(levels, d.leaf, d.local),
        d.share * side * side,
        slopes,
    )
}

/// Where [`sample`]'s descent ends for `u`: the leaf, the rescaled primary
/// sample inside it, and the products of the chosen shares.
#[derive(Clone, Copy, Debug)]
pub struct Descent<T> {
    /// The leaf's column and row, each below `2^levels`.
    pub leaf: [u32; 2],
    /// `u` rescaled into the leaf, in `[0, 1]^2`: where in the leaf the point
    /// falls when the leaf is uniform.
    pub local: [T; 2],
    /// The product of the chosen children's shares (the leaf's probability).
    pub share: T,
    /// The product of the chosen columns' shares along the path.
    pub column: T,
    /// The product of the chosen rows' shares along the path.
    pub row: T,
}

/// The descent of [`sample`] from `u` (clamped into the square, NaN as 0), for a
/// caller that shapes the point inside its leaf ([`crate::envmap_tree`]).
/// `O(levels)`; never panics.
#[inline]
pub fn descend<T: Real>(tree: &impl ChildWeights<T>, u: [T; 2]) -> Descent<T> {
    let levels = tree.levels().min(MAX_LEVELS);
    let (mut ux, mut uy) = (clamp_unit(u[0]), clamp_unit(u[1]));
    let mut node = Node::ROOT;
    let mut p = T::ONE;
    let (mut column, mut row) = (T::ONE, T::ONE);
    for _ in 0..levels {
        let w = usable(tree.children(node));
        let step = choose(w, &mut ux, &mut uy);
        p = p * share(w, step);
        column = column
            * if step.i == 0 {
                step.px
            } else {
                T::ONE - step.px
            };
        row = row
            * if step.j == 0 {
                step.py
            } else {
                T::ONE - step.py
            };
        node = node.child((step.i + 2 * step.j) as u32);
    }
    Descent {
        leaf: [node.x, node.y],
        local: [ux, uy],
        share: p,
        column,
        row,
    }
}

/// The density at `p` (clamped into the square) of [`sample`]'s points: the
/// product of the chosen children's shares along the path to `p`'s leaf times the
/// leaves' count. `O(levels)`; never panics.
#[inline]
pub fn pdf<T: Real>(tree: &impl ChildWeights<T>, p: [T; 2]) -> T {
    let levels = tree.levels().min(MAX_LEVELS);
    let (lx, ly) = (leaf(levels, p[0]), leaf(levels, p[1]));
    let z = morton(lx, ly);
    let mut prob = T::ONE;
    for l in 0..levels {
        let shift = levels - l - 1;
        let w = usable(tree.children(Node::ancestor(levels, [lx, ly], z, l)));
        let k = ((lx >> shift) & 1) + 2 * ((ly >> shift) & 1);
        // `share`'s order of operations: the pdf of a sample is its pdf bit for bit.
        prob = prob * (w[k as usize] / sum4(w));
    }
    let side = T::of((1u64 << levels) as f64);
    prob * side * side
}

/// The primary sample that [`sample`] maps to `p` (clamped into the square).
/// `O(levels)`; never panics.
pub fn invert<T: Real>(tree: &impl ChildWeights<T>, p: [T; 2]) -> [T; 2] {
    let levels = tree.levels().min(MAX_LEVELS);
    let ([lx, ly], [mut ux, mut uy]) = locate(levels, p);
    let z = morton(lx, ly);
    let mut steps = [Step {
        px: T::ZERO,
        i: 0,
        py: T::ZERO,
        j: 0,
    }; MAX_LEVELS as usize];
    for (l, step) in steps.iter_mut().enumerate().take(levels as usize) {
        let shift = levels - l as u32 - 1;
        let w = usable(tree.children(Node::ancestor(levels, [lx, ly], z, l as u32)));
        let (i, j) = (((lx >> shift) & 1) as usize, ((ly >> shift) & 1) as usize);
        let (px, py) = splits(w);
        *step = Step {
            px,
            i,
            py: py[i],
            j,
        };
    }
    for step in steps[..levels as usize].iter().rev() {
        uy = if step.j == 0 {
            uy * step.py
        } else {
            step.py + uy * (T::ONE - step.py)
        };
        ux = if step.i == 0 {
            ux * step.px
        } else {
            step.px + ux * (T::ONE - step.px)
        };
    }
    [clamp_unit(ux), clamp_unit(uy)]
}

/// The leaf column (or row) of coordinate `c` among `2^levels`, clamped into the
/// square.
#[inline]
fn leaf<T: Real>(levels: u32, c: T) -> u32 {
    let side = 1u32 << levels;
    ((clamp_unit(c) * T::of(side as f64)).floor().to_f64() as u32).min(side - 1)
}

/// The leaf of square point `p` (clamped into the square) among `2^levels x
/// 2^levels`, and `p`'s place inside it in `[0, 1]^2`: the inverse of
/// [`leaf_point`].
#[inline]
pub fn locate<T: Real>(levels: u32, p: [T; 2]) -> ([u32; 2], [T; 2]) {
    let side = T::of((1u64 << levels) as f64);
    let leaf = p.map(|c| leaf(levels, c));
    let local = [0, 1].map(|k| clamp_unit(clamp_unit(p[k]) * side - T::of(leaf[k] as f64)));
    (leaf, local)
}

/// The square point at place `local` (in `[0, 1]^2`) inside leaf `leaf` among
/// `2^levels x 2^levels` (clamped to 1 against rounding).
#[inline]
pub fn leaf_point<T: Real>(levels: u32, leaf: [u32; 2], local: [T; 2]) -> [T; 2] {
    let side = T::of((1u64 << levels) as f64);
    [0, 1].map(|k| ((T::of(leaf[k] as f64) + local[k]) / side).min(T::ONE))
}

/// Picks a child by `u` (column by `u.x`, then the row within it by `u.y`) and
/// rescales `u` into the chosen part; an empty part is never picked.
fn choose<T: Real>(w: [T; 4], ux: &mut T, uy: &mut T) -> Step<T> {
    let (left, right) = (w[0] + w[2], w[1] + w[3]);
    // Both columns' row splits are worked out beside the column's, so that the
    // row's choice waits on no division once the column is known.
    let (px, py) = splits(w);
    let i = if (*ux < px && left > T::ZERO) || right <= T::ZERO {
        *ux = clamp_unit(*ux / px);
        0
    } else {
        *ux = clamp_unit((*ux - px) / (T::ONE - px));
        1
    };
    let (bottom, top, py) = if i == 0 {
        (w[0], w[2], py[0])
    } else {
        (w[1], w[3], py[1])
    };
    let j = if (*uy < py && bottom > T::ZERO) || top <= T::ZERO {
        *uy = clamp_unit(*uy / py);
        0
    } else {
        *uy = clamp_unit((*uy - py) / (T::ONE - py));
        1
    };
    Step { px, i, py, j }
}

/// A node's splits: the left column's share of the four children's weights, and
/// in each column the lower child's share, `(w0 + w2) / Σ w` and `[w0 / (w0 + w2),
/// w1 / (w1 + w3)]`. What [`sample`] cuts `u` at and [`invert`] scales it back by.
#[inline]
fn splits<T: Real>(w: [T; 4]) -> (T, [T; 2]) {
    let (left, right) = (w[0] + w[2], w[1] + w[3]);
    let py = [w[0] / (w[0] + w[2]), w[1] / (w[1] + w[3])];
    (left / (left + right), py)
}

/// The share of the chosen child among the four.
fn share<T: Real>(w: [T; 4], s: Step<T>) -> T {
    w[s.i + 2 * s.j] / sum4(w)
}

fn sum4<T: Real>(w: [T; 4]) -> T {
    (w[0] + w[1]) + (w[2] + w[3])
}

#[cfg(test)]
mod tests;
