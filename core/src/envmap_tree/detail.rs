//! The detailed leaves of an environment tree ([`EnvmapTree::with_detail`]):
//! inside a leaf whose light is sharper than its corners' bilinear shape can
//! follow (a lamp, a sun smaller than a leaf), the point is drawn by the
//! piecewise-constant warp of the leaf's light on a table of cells
//! ([`crate::cell_table`]), `16 x 16` cells, or `64 x 64` for the few leaves
//! that hold the most light; the leaf's probability is the descent's, so the
//! pdf stays exact. Blob tags 20, 21 and 22.

use super::{EnvmapTree, MAX_TREE_LEVELS};
use crate::cell_table;
use crate::quadtree::QuadtreeError;
use crate::real::Real;

/// The detail sections of `index` and `tables` ([`EnvmapTree::with_detail`]),
/// for a writer to add after [`sections`](super::sections) when the tree has
/// detailed leaves.
pub fn detail_sections<'s>(
    index: &'s [u32],
    tables: &'s [f32],
) -> [crate::blob::SectionSpec<'s>; 2] {
    use crate::blob::{SectionSpec, SectionTag};
    [
        SectionSpec {
            tag: SectionTag::EnvmapTreeDetailIndex,
            elem_size: 4,
            bytes: bytemuck::cast_slice(index),
        },
        SectionSpec {
            tag: SectionTag::EnvmapTreeDetail,
            elem_size: 4,
            bytes: bytemuck::cast_slice(tables),
        },
    ]
}

/// Cells per axis of a detailed leaf's table ([`EnvmapTree::with_detail`]):
/// `16 x 16` cells, 0.025° apart at 9 levels, so the edge of a sun a pixel of a
/// 1024 x 512 map across (0.35°) cuts few of them. (On a clear sky with such a
/// sun, 45° up, the variance of `L cos / (E pdf)` over 64 normals is 0.057 with
/// `8 x 8` cells, 0.034 with these, 0.25 with the corners' bilinear shape
/// alone; `build-tool/examples/leaf_shape`.)
pub const DETAIL_SIDE: usize = 16;

/// Values of one detailed leaf's table: its `DETAIL_SIDE` column masses, then
/// its `DETAIL_SIDE²` cells column by column ([`crate::cell_table`]).
pub const DETAIL_LEN: usize = cell_table::table_len(DETAIL_SIDE);

/// Cells per axis of a *fine* table ([`EnvmapTree::with_fine_detail`]): `64 x
/// 64`, for the few leaves that hold the most light. A sun's edge cuts a quarter
/// as much of a fine table's mass as of a [`DETAIL_SIDE`] table's: on a clear
/// sky (a 0.7° sun, 45° up) the variance of `L cos / (E pdf)` over 64 normals
/// is 0.013 with fine tables in the sun's leaves, 0.034 without.
pub const FINE_SIDE: usize = 64;

/// Values of one fine table: [`crate::cell_table::table_len`]`(FINE_SIDE)`.
pub const FINE_LEN: usize = cell_table::table_len(FINE_SIDE);

/// The bit of a detail-index entry that names a fine table: entry `FINE_BIT |
/// (1 + t)` is fine table `t`.
pub const FINE_BIT: u32 = 1 << 31;

/// The fine-table section of `tables` ([`EnvmapTree::with_fine_detail`]), for a
/// writer to add after [`detail_sections`].
pub fn fine_section(tables: &[f32]) -> crate::blob::SectionSpec<'_> {
    crate::blob::SectionSpec {
        tag: crate::blob::SectionTag::EnvmapTreeFineDetail,
        elem_size: 4,
        bytes: bytemuck::cast_slice(tables),
    }
}

/// [`QuadtreeError::Length`] (the length rounded down to whole tables
/// expected) unless `tables` is a whole number of tables of `len` values.
fn whole_tables(tables: &[f32], len: usize) -> Result<(), QuadtreeError> {
    if tables.len() % len == 0 {
        return Ok(());
    }
    Err(QuadtreeError::Length {
        expected: (tables.len() / len * len) as u64,
        got: tables.len() as u64,
    })
}

/// Entries of the detail index of a tree with `levels` levels: one per leaf,
/// `4^L`.
pub fn detail_index_len(levels: u32) -> usize {
    1usize << (2 * levels.min(MAX_TREE_LEVELS))
}

/// How a point is drawn inside a leaf.
pub(super) enum Shape<'a, T> {
    /// Uniformly.
    Uniform,
    /// By the bilinear warp of its corners `[w00, w10, w01, w11]`.
    Corners([T; 4]),
    /// By the piecewise-constant warp of its detail table.
    Table(&'a [f32]),
    /// By the piecewise-constant warp of its fine table.
    FineTable(&'a [f32]),
}

impl<'a> EnvmapTree<'a> {
    /// The tree with detailed leaves: `index` holds one entry per leaf
    /// ([`detail_index_len`], row-major over the octahedral square), 0 for a
    /// leaf shaped as before (by its corners, or uniform) and `1 + t` for a leaf
    /// whose point is drawn by the piecewise-constant warp of table `t` of
    /// `tables` ([`crate::cell_table`], [`DETAIL_SIDE`]` x `[`DETAIL_SIDE`] values
    /// each, finite and non-negative), the leaf's probability unchanged. Both
    /// empty: no detail. An error if a length is wrong (`O(1)`;
    /// [`Self::check_values`] reads the values). A tree with bad values still
    /// never panics (an index past the tables reads as 0); it describes
    /// another warp.
    pub fn with_detail(self, index: &'a [u32], tables: &'a [f32]) -> Result<Self, QuadtreeError> {
        if index.is_empty() && tables.is_empty() {
            return Ok(Self {
                detail_index: index,
                detail: tables,
                ..self
            });
        }
        if index.len() != detail_index_len(self.levels) {
            return Err(QuadtreeError::Length {
                expected: detail_index_len(self.levels) as u64,
                got: index.len() as u64,
            });
        }
        whole_tables(tables, DETAIL_LEN)?;
        Ok(Self {
            detail_index: index,
            detail: tables,
            ..self
        })
    }

    /// The tree with fine tables besides the detail tables ([`Self::with_detail`]):
    /// a detail-index entry `FINE_BIT | (1 + t)` ([`FINE_BIT`]) draws its leaf's
    /// point by fine table `t` of `tables` ([`FINE_LEN`] values each, `64 x 64`
    /// cells). An error unless the length is a whole number of tables (`O(1)`).
    pub fn with_fine_detail(self, tables: &'a [f32]) -> Result<Self, QuadtreeError> {
        whole_tables(tables, FINE_LEN)?;
        Ok(Self {
            fine: tables,
            ..self
        })
    }

    /// The fine tables.
    pub fn fine_detail(&self) -> &'a [f32] {
        self.fine
    }

    /// The detail index (empty without detailed leaves).
    pub fn detail_index(&self) -> &'a [u32] {
        self.detail_index
    }

    /// The detailed leaves' tables.
    pub fn detail(&self) -> &'a [f32] {
        self.detail
    }

    /// How leaf `(x, y)` draws its point: its detail table, else its corners,
    /// else uniformly.
    #[inline]
    pub(super) fn shape_of<T: Real>(&self, leaf: [u32; 2]) -> Shape<'a, T> {
        if !self.detail_index.is_empty() {
            let side = 1usize << self.levels;
            let entry = self
                .detail_index
                .get(leaf[1] as usize * side + leaf[0] as usize)
                .copied()
                .unwrap_or(0) as usize;
            let fine = entry & FINE_BIT as usize != 0;
            let t = entry & !(FINE_BIT as usize);
            if t > 0 {
                let (tables, len) = if fine {
                    (self.fine, FINE_LEN)
                } else {
                    (self.detail, DETAIL_LEN)
                };
                let start = (t - 1).saturating_mul(len);
                if let Some(table) = tables.get(start..start.saturating_add(len)) {
                    return if fine {
                        Shape::FineTable(table)
                    } else {
                        Shape::Table(table)
                    };
                }
            }
        }
        match self.corners_of(leaf) {
            Some(w) => Shape::Corners(w),
            None => Shape::Uniform,
        }
    }

    /// The detail's per-value checks ([`Self::check_values`]): every index
    /// entry names a table that exists, every table value is finite and
    /// non-negative.
    pub(super) fn check_detail(&self) -> Result<(), QuadtreeError> {
        let tables = (self.detail.len() / DETAIL_LEN) as u64;
        let fine = (self.fine.len() / FINE_LEN) as u64;
        // An entry names a detail table (1 to `tables`), a fine one (`FINE_BIT`
        // with 1 to `fine`), or none (0).
        let named = |e: u32| match (e & FINE_BIT != 0, u64::from(e & !FINE_BIT)) {
            (false, t) => t <= tables,
            (true, t) => (1..=fine).contains(&t),
        };
        if let Some(i) = self.detail_index.iter().position(|&e| !named(e)) {
            return Err(QuadtreeError::BadDetailIndex(i as u64));
        }
        let bad = |v: &f32| !(*v >= 0.0 && v.is_finite());
        if let Some(i) = self.detail.iter().position(bad) {
            return Err(QuadtreeError::BadDetail(i as u64));
        }
        if let Some(i) = self.fine.iter().position(bad) {
            return Err(QuadtreeError::BadFineDetail(i as u64));
        }
        Ok(())
    }
}
