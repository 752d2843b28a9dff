//! Sampler views over the quantized point arrays of a blob.

use glam::{Vec2, Vec3};
use nuld_core::blob::Domain;
use nuld_core::quantize::{unorm16_decode, unorm16_decode_f64};

/// `set_count` sets of `len` points each in the unit square, stored as cell-centred
/// u16 unorm coordinates (so every point lies strictly inside `(0,1)^2`).
///
/// Obtained from [`crate::Blob::point_set_2d`]. Copy it freely: it is two integers
/// and a slice.
#[derive(Clone, Copy, Debug)]
pub struct PointSet2D<'a> {
    coords: &'a [[u16; 2]],
    len: usize,
    set_count: usize,
}

impl<'a> PointSet2D<'a> {
    /// `coords.len() == len * set_count` and both counts are non-zero; checked by
    /// [`crate::Blob::parse`].
    pub(crate) fn new(coords: &'a [[u16; 2]], len: u32, set_count: u32) -> Self {
        Self {
            coords,
            len: len as usize,
            set_count: set_count as usize,
        }
    }

    /// Points per set (at least 1).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always `false`: a parsed blob has at least one point per set.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Number of independent sets (at least 1).
    pub fn set_count(&self) -> usize {
        self.set_count
    }

    /// Point `i` of set `set`, in `(0,1)^2`. O(1).
    ///
    /// Both indices wrap: `set` modulo [`Self::set_count`], `i` modulo [`Self::len`].
    /// Never panics.
    ///
    /// ```
    /// # let bytes = nuld_runtime::doc_example_blob();
    /// let pts = nuld_runtime::Blob::parse(&bytes.0)?.point_set_2d()?;
    /// assert_eq!(pts.point(0, 1), pts.point(1, 1 + pts.len()));
    /// # Ok::<(), nuld_runtime::BlobError>(())
    /// ```
    #[inline]
    pub fn point(&self, set: usize, i: usize) -> Vec2 {
        let [x, y] = self.raw(set, i);
        Vec2::new(unorm16_decode(x), unorm16_decode(y))
    }

    /// The stored u16 unorm code of point `i` of set `set` (same wrapping as
    /// [`Self::point`]); decode with `(q + 0.5) / 65536`.
    #[inline]
    pub fn raw(&self, set: usize, i: usize) -> [u16; 2] {
        let s = set.checked_rem(self.set_count).unwrap_or(0);
        let k = i.checked_rem(self.len).unwrap_or(0);
        // `s * len + k < set_count * len == coords.len()` by construction; `get`
        // keeps the lookup panic-free even so.
        self.coords
            .get(s * self.len + k)
            .copied()
            .unwrap_or([u16::MAX / 2; 2])
    }

    /// All stored codes, set-major (`[set][index]`), for upload to a GPU buffer.
    pub fn raw_codes(&self) -> &'a [[u16; 2]] {
        self.coords
    }
}

/// `set_count` sets of `len` unit directions, stored as points of the equal-area
/// square of their [`Domain`] (octahedral map for the sphere, concentric map for the
/// upper hemisphere).
///
/// Obtained from [`crate::Blob::direction_set`].
#[derive(Clone, Copy, Debug)]
pub struct DirectionSet<'a> {
    square: PointSet2D<'a>,
    domain: Domain,
}

impl<'a> DirectionSet<'a> {
    pub(crate) fn new(square: PointSet2D<'a>, domain: Domain) -> Self {
        Self { square, domain }
    }

    /// Directions per set (at least 1).
    pub fn len(&self) -> usize {
        self.square.len()
    }

    /// Always `false`: a parsed blob has at least one direction per set.
    pub fn is_empty(&self) -> bool {
        self.square.is_empty()
    }

    /// Number of independent sets (at least 1).
    pub fn set_count(&self) -> usize {
        self.square.set_count()
    }

    /// [`Domain::Sphere`] or [`Domain::Hemisphere`] (`z >= 0`).
    pub fn domain(&self) -> Domain {
        self.domain
    }

    /// Direction `i` of set `set`, a unit vector (`z >= 0` for the hemisphere). O(1).
    ///
    /// Indices wrap as in [`PointSet2D::point`]. Never panics.
    #[inline]
    pub fn direction(&self, set: usize, i: usize) -> Vec3 {
        let [x, y] = self.square.raw(set, i);
        let p = glam::DVec2::new(unorm16_decode_f64(x), unorm16_decode_f64(y));
        self.domain.to_direction(p).as_vec3()
    }

    /// The square parameterization of direction `i` of set `set`, in `(0,1)^2`.
    #[inline]
    pub fn square_point(&self, set: usize, i: usize) -> Vec2 {
        self.square.point(set, i)
    }

    /// The underlying square point set (for GPU upload of the raw codes).
    pub fn square_points(&self) -> PointSet2D<'a> {
        self.square
    }
}
