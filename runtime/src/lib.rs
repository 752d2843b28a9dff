//! # nuld-runtime
//!
//! Reads `.nuld` blobs written by `build-tool` and serves their samples, zero-copy,
//! in constant time per sample. `#![no_std]`, no allocator, and no panics on any
//! input: every malformed blob is rejected by [`Blob::parse`] with a [`BlobError`],
//! and every lookup on a parsed blob is total (indices wrap modulo the counts).
//!
//! Points and directions are [`glam`] vectors; use the re-exported
//! [`nuld_runtime::glam`](glam) so that your glam version always matches.
//!
//! ```
//! use nuld_runtime::{Blob, BlobKind};
//! # let bytes = nuld_runtime::doc_example_blob();
//! # let bytes: &[u8] = &bytes.0;
//! // `bytes` is a blob in memory, 16-byte aligned (see `include_blob!`).
//! let blob = Blob::parse(bytes)?;
//! assert_eq!(blob.kind(), BlobKind::PointSet2D);
//! let pts = blob.point_set_2d()?;
//! for i in 0..pts.len() {
//!     let p: nuld_runtime::glam::Vec2 = pts.point(0, i); // in (0,1)^2
//!     assert!(p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0);
//! }
//! # Ok::<(), nuld_runtime::BlobError>(())
//! ```
//!
//! Where the bytes come from:
//! * compiled in: [`include_blob!`] (no allocation; `runtime/examples/embed.rs`);
//! * read at run time: `AlignedBuf` with the `alloc` feature, and
//!   `AlignedBuf::read` with `std` (`runtime/examples/load_file.rs`). Without the
//!   features, copy the bytes into any 16-byte aligned storage of your own.
//!
//! ## Features
//! * none (default): `no_std`, no allocator;
//! * `alloc`: `AlignedBuf`, an owned aligned copy of a blob;
//! * `std` (implies `alloc`): `AlignedBuf::read` from a file.
#![no_std]
#![deny(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod aligned;
#[cfg(feature = "alloc")]
mod aligned_buf;
mod points;

/// The `glam` this crate returns its vectors in; use it instead of a `glam`
/// dependency of your own so that the versions always match.
pub use glam;

pub use aligned::Aligned;
#[cfg(feature = "alloc")]
pub use aligned_buf::AlignedBuf;
pub use nuld_core::blob::{BlobError, BlobKind, Domain, Metadata};
pub use points::{DirectionSet, PointSet2D};

use nuld_core::blob::{Layout, PointSetInfo, SectionTag};

/// A validated blob, borrowing its bytes.
///
/// Construct it with [`Blob::parse`]; then ask for the sampler view matching its
/// [`Blob::kind`].
#[derive(Clone, Copy, Debug)]
pub struct Blob<'a> {
    layout: Layout<'a>,
    kind: BlobKind,
    metadata: Metadata<'a>,
}

impl<'a> Blob<'a> {
    /// Validates `bytes` and returns a view on them.
    ///
    /// Checks, in order: length, 16-byte alignment of `bytes`, magic, format version,
    /// declared length, checksum, section table and metadata bounds, kind, and the
    /// kind's sections (sizes, counts, domain codes). Never panics, never allocates.
    ///
    /// ```
    /// # use nuld_runtime::{Blob, BlobError, Aligned};
    /// let junk = Aligned([0u8; 64]);
    /// assert_eq!(Blob::parse(&junk.0).unwrap_err(), BlobError::BadMagic);
    /// ```
    pub fn parse(bytes: &'a [u8]) -> Result<Self, BlobError> {
        let layout = Layout::read(bytes)?;
        let code = layout.header().kind;
        let kind = BlobKind::from_code(code).ok_or(BlobError::UnknownKind(code))?;
        let metadata = layout.metadata()?;
        let blob = Self {
            layout,
            kind,
            metadata,
        };
        match kind {
            BlobKind::PointSet2D | BlobKind::DirectionSet => {
                blob.points_view()?;
            }
            // Validated by the conditional sampler view (issue 13, in progress).
            BlobKind::Conditional => return Err(BlobError::UnknownKind(code)),
        }
        Ok(blob)
    }

    /// What the blob holds.
    pub fn kind(&self) -> BlobKind {
        self.kind
    }

    /// The blob's descriptive metadata (generator, target SPEC, seed).
    pub fn metadata(&self) -> Metadata<'a> {
        self.metadata
    }

    /// The point sets of a [`BlobKind::PointSet2D`] blob.
    ///
    /// Errors with [`BlobError::WrongKind`] for any other kind.
    pub fn point_set_2d(&self) -> Result<PointSet2D<'a>, BlobError> {
        self.expect(BlobKind::PointSet2D)?;
        let (info, coords) = self.points_view()?;
        Ok(PointSet2D::new(coords, info.len, info.set_count))
    }

    /// The direction sets of a [`BlobKind::DirectionSet`] blob.
    ///
    /// Errors with [`BlobError::WrongKind`] for any other kind.
    pub fn direction_set(&self) -> Result<DirectionSet<'a>, BlobError> {
        self.expect(BlobKind::DirectionSet)?;
        let (info, coords) = self.points_view()?;
        let domain = Domain::from_code(info.domain).unwrap_or(Domain::Sphere);
        Ok(DirectionSet::new(
            PointSet2D::new(coords, info.len, info.set_count),
            domain,
        ))
    }

    fn expect(&self, expected: BlobKind) -> Result<(), BlobError> {
        if self.kind == expected {
            Ok(())
        } else {
            Err(BlobError::WrongKind {
                expected,
                found: self.kind,
            })
        }
    }

    /// The info section and the coordinate array, validated against each other.
    fn points_view(&self) -> Result<(PointSetInfo, &'a [[u16; 2]]), BlobError> {
        let (_, info_bytes) = self.layout.section(SectionTag::PointSetInfo)?;
        let info_len = core::mem::size_of::<PointSetInfo>();
        if info_bytes.len() != info_len {
            return Err(BlobError::PointSetInfoSize {
                got: info_bytes.len() as u64,
                expected: info_len as u64,
            });
        }
        let info: PointSetInfo = bytemuck::pod_read_unaligned(info_bytes);
        if info.len == 0 {
            return Err(BlobError::NoPoints);
        }
        if info.set_count == 0 {
            return Err(BlobError::NoSets);
        }
        let domain = Domain::from_code(info.domain).ok_or(BlobError::UnknownDomain(info.domain))?;
        let domain_ok = match self.kind {
            BlobKind::PointSet2D => domain == Domain::Square,
            BlobKind::DirectionSet => domain != Domain::Square,
            BlobKind::Conditional => false,
        };
        if !domain_ok {
            return Err(BlobError::DomainMismatch {
                kind: self.kind,
                domain,
            });
        }
        let (entry, bytes) = self.layout.section(SectionTag::Points)?;
        if entry.elem_size != 4 {
            return Err(BlobError::PointElementSize(entry.elem_size));
        }
        let expected = (info.len as u64) * (info.set_count as u64) * 4;
        if bytes.len() as u64 != expected {
            return Err(BlobError::PointsLength {
                expected,
                got: bytes.len() as u64,
            });
        }
        // The length is a whole number of 4-byte elements (checked above) and the
        // section starts 16-byte aligned in an aligned blob (`Layout::read`), so the
        // cast cannot fail; were the bytes misaligned, that would be the cause.
        let coords: &[[u16; 2]] =
            bytemuck::try_cast_slice(bytes).map_err(|_| BlobError::Misaligned)?;
        Ok((info, coords))
    }
}

/// A small valid blob for the crate's documentation examples: 4 points, 1 set.
#[doc(hidden)]
pub fn doc_example_blob() -> Aligned<[u8; 160]> {
    use nuld_core::blob::{write, SectionSpec};
    let info = PointSetInfo {
        len: 4,
        set_count: 1,
        domain: Domain::Square as u32,
        reserved: 0,
    };
    let pts: [[u16; 2]; 4] = [[0, 0], [32768, 16384], [16384, 49152], [49152, 32768]];
    // Metadata { generator: "doc", target: "uniform", seed: 0 } in postcard.
    let meta = [
        3, b'd', b'o', b'c', 7, b'u', b'n', b'i', b'f', b'o', b'r', b'm', 0,
    ];
    let sections = [
        SectionSpec {
            tag: SectionTag::PointSetInfo,
            elem_size: 16,
            bytes: bytemuck::bytes_of(&info),
        },
        SectionSpec {
            tag: SectionTag::Points,
            elem_size: 4,
            bytes: bytemuck::cast_slice(&pts),
        },
    ];
    // 48 + 64 + 13 -> 128 (aligned), + 16 -> 144, + 16 = 160 bytes: exactly the
    // array, which `write` checks (a mismatch would leave zeros and fail to parse).
    let mut out = Aligned([0u8; 160]);
    let _ = write(&mut out.0, BlobKind::PointSet2D, &meta, &sections);
    out
}
