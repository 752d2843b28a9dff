//! The `.nuld` blob layout, format version 1 (the byte-level description, for readers
//! in other languages and shaders, is `core/FORMAT.md`).
//!
//! ```text
//! offset 0    Header (48 bytes, #[repr(C)], little-endian)
//! offset 48   section table: section_count x SectionEntry (32 bytes each)
//! then        metadata: postcard-encoded [`Metadata`]
//! then        sections, each at a 16-byte aligned offset, zero padding between
//! ```
//!
//! The header's checksum is FNV-1a 64 over the whole blob with the checksum field
//! itself read as zero bytes, so any single changed byte anywhere is detected.
//!
//! [`Layout::read`] validates a byte slice against this layout without allocating;
//! [`write()`] fills a caller-provided buffer of [`encoded_len`] bytes. Both halves of
//! the project go through these two functions, so the layout is defined once.

use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

pub use crate::domain::Domain;

mod error;
mod layout;
mod write;

pub use error::{BlobError, ConditionalError, LayoutError, PointSetError, WriteError};
pub use layout::{checksum, Layout};
pub use write::{encoded_len, write, SectionSpec};

/// First eight bytes of every blob.
pub const MAGIC: [u8; 8] = *b"NULDBLOB";
/// The format version this crate reads and writes.
pub const FORMAT_VERSION: u32 = 1;
/// Alignment, in bytes, of the blob start and of every section.
pub const ALIGN: usize = 16;
/// Upper bound on the number of sections a reader accepts.
pub const MAX_SECTIONS: u32 = 64;
/// Byte offset of the header's checksum field.
pub const CHECKSUM_OFFSET: usize = 24;

/// The fixed header at offset 0. All integers little-endian.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct Header {
    /// [`MAGIC`].
    pub magic: [u8; 8],
    /// [`FORMAT_VERSION`].
    pub version: u32,
    /// What the blob holds, a [`BlobKind`] code.
    pub kind: u32,
    /// Length of the whole blob in bytes.
    pub total_len: u64,
    /// FNV-1a 64 of the blob with these 8 bytes read as zero ([`checksum`]).
    pub checksum: u64,
    /// Offset of the postcard metadata.
    pub meta_offset: u32,
    /// Length of the postcard metadata in bytes.
    pub meta_len: u32,
    /// Number of [`SectionEntry`]s following the header.
    pub section_count: u32,
    /// Reserved, zero.
    pub reserved: u32,
}

/// Size of [`Header`] in bytes.
pub const HEADER_LEN: usize = core::mem::size_of::<Header>();

/// One row of the section table.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct SectionEntry {
    /// What the section holds, a [`SectionTag`] code.
    pub tag: u32,
    /// Size in bytes of one element (the section length is a multiple of it).
    pub elem_size: u32,
    /// Offset of the section from the blob start; a multiple of [`ALIGN`].
    pub offset: u64,
    /// Length of the section in bytes.
    pub len: u64,
    /// Reserved, zero.
    pub reserved: u64,
}

/// Size of [`SectionEntry`] in bytes.
pub const SECTION_ENTRY_LEN: usize = core::mem::size_of::<SectionEntry>();

/// What a blob holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum BlobKind {
    /// Point sets in `[0,1)^2` ([`SectionTag::PointSetInfo`] + [`SectionTag::Points`]).
    PointSet2D = 1,
    /// Direction sets stored as square points of an equal-area map (same sections).
    DirectionSet = 2,
    /// A conditional sampler (paper §4): [`SectionTag::ConditionalInfo`],
    /// [`SectionTag::NetworkParams`], [`SectionTag::PointTable`],
    /// [`SectionTag::WeightTable`]; see [`crate::conditional`].
    Conditional = 3,
}

impl BlobKind {
    /// The kind with this code, if any.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            1 => Some(Self::PointSet2D),
            2 => Some(Self::DirectionSet),
            3 => Some(Self::Conditional),
            _ => None,
        }
    }
}

/// Which section a table row describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum SectionTag {
    /// One [`PointSetInfo`].
    PointSetInfo = 1,
    /// `set_count * len * 2` u16 unorm coordinates, set-major, then index, then axis.
    Points = 2,
    /// One [`crate::conditional::ConditionalInfo`] (80 bytes).
    ConditionalInfo = 3,
    /// The network's parameters as f16 bits, in the order of [`crate::network`]
    /// (`elem_size` 2).
    NetworkParams = 4,
    /// The point table, `u32` entries `x | y << 16` of u16 unorm codes, laid out
    /// `[grid node][instance][index]` (`elem_size` 4); with
    /// [`Self::MetallicNodes`], one such layer per metallic node.
    PointTable = 5,
    /// The weight table, `f32` per weight-grid node, axis 0 fastest (`elem_size` 4).
    WeightTable = 6,
    /// One [`crate::envmap_tree::TreeInfo`] (16 bytes): the environment prior's
    /// levels and top grid (samplers with [`crate::conditional::PointWarp::EnvmapTree`]).
    EnvmapTreeInfo = 7,
    /// The environment prior's [`crate::envmap_tree::NodeRecord`]s (`elem_size` 16),
    /// levels `1..=L` in Morton order ([`crate::envmap_tree::node_index`]).
    EnvmapTreeNodes = 8,
    /// The environment prior's top-level weights, `f32` (`elem_size` 4),
    /// `[normal][node]` ([`crate::envmap_tree::top_len`]).
    EnvmapTreeTop = 9,
    /// The info of an earlier BRDF prior, whose tables lived in the plain
    /// half-vector square: no longer read; a blob with it and without
    /// [`Self::BrdfPriorInfo`] is refused with the advice to bake it again.
    BrdfPriorInfoUnstretched = 10,
    /// The BRDF prior's normalized vertex values, `f32` (`elem_size` 4),
    /// `[node][row][column]` ([`crate::marginal2d::tabulate`]).
    BrdfPriorData = 11,
    /// The BRDF prior's marginal CDFs, `f32`, `[node][row]`.
    BrdfPriorMarginal = 12,
    /// The BRDF prior's conditional CDFs, `f32`, laid out as the data.
    BrdfPriorConditional = 13,
    /// The BRDF prior's node masses before normalization, `f32`, one per node.
    BrdfPriorMasses = 14,
    /// The info of an earlier BRDF prior, whose metal layer lived in a
    /// stretched half-vector square (`k = roughness`): no longer read; a blob
    /// with it and without [`Self::BrdfPriorInfo`] is refused with the advice
    /// to bake it again.
    BrdfPriorInfoStretchedMetal = 15,
    /// The metal layer's network ([`crate::brdf_prior::has_metal_layer`]): f16
    /// bits in the order of [`Self::NetworkParams`], the same shape; read by a
    /// query at metallic 1 instead of [`Self::NetworkParams`]. Optional, with
    /// [`Self::MetalPointTable`].
    MetalNetworkParams = 16,
    /// The metal layer's point table, laid out as [`Self::PointTable`]; read by a
    /// query at metallic 1 instead of it. Optional, with
    /// [`Self::MetalNetworkParams`].
    MetalPointTable = 17,
    /// The metallic axis of a BRDF sampler's learned part
    /// ([`crate::conditional::metallic_axis`]): `L` in `2..=8` metallic nodes,
    /// `f32` (`elem_size` 4), strictly increasing in `[0, 1]`. With it the shared
    /// network reads the metallic as its third condition feature and
    /// [`Self::PointTable`] holds `L` layers, `[metallic node][grid node]
    /// [instance][index]`. Optional; only with
    /// [`crate::conditional::PointWarp::BrdfTable`].
    MetallicNodes = 18,
    /// The environment prior's leaf shape, `f32` (`elem_size` 4): `(2^L + 1)^2`
    /// values on the leaves' corners, row-major over the octahedral square
    /// ([`crate::envmap_tree::EnvmapTree::with_corners`]). Optional: without it
    /// the leaves are uniform.
    EnvmapTreeCorners = 19,
    /// The environment prior's detail index, `u32` (`elem_size` 4): one entry
    /// per leaf, row-major over the octahedral square, 0 or `1 + t` for detail
    /// table `t` ([`crate::envmap_tree::EnvmapTree::with_detail`]). Optional,
    /// with [`Self::EnvmapTreeDetail`].
    EnvmapTreeDetailIndex = 20,
    /// The environment prior's detail tables, `f32` (`elem_size` 4),
    /// [`crate::envmap_tree::DETAIL_LEN`] values each: a detailed leaf's light
    /// on a `16 x 16` grid of cells, its column masses first, then the cells
    /// column by column ([`crate::cell_table`]).
    /// Optional, with [`Self::EnvmapTreeDetailIndex`].
    EnvmapTreeDetail = 21,
    /// The environment prior's fine tables, `f32` (`elem_size` 4),
    /// [`crate::envmap_tree::FINE_LEN`] values each (`64 x 64` cells, laid out
    /// as [`Self::EnvmapTreeDetail`]'s), named by the detail-index entries with
    /// [`crate::envmap_tree::FINE_BIT`] set. Optional, with the detail sections.
    EnvmapTreeFineDetail = 22,
    /// The info of an earlier BRDF prior, whose shared layers lived in the
    /// half-vector square of one stretch (`roughness^(1/4)`): no longer read;
    /// a blob with it and without [`Self::BrdfPriorInfo`] is refused with the
    /// advice to bake it again.
    BrdfPriorInfoStretchedShared = 23,
    /// One [`crate::brdf_prior::BrdfPriorInfo`] (16 bytes): the BRDF prior's
    /// condition grid and table size (samplers with
    /// [`crate::conditional::PointWarp::BrdfTable`]); its shared layers' tables
    /// live in the radial half-vector square
    /// ([`crate::brdf_prior::radial_square`]), its metal layer's in the star
    /// disc ([`crate::brdf_prior::star_direction`]).
    BrdfPriorInfo = 24,
}

/// Contents of the [`SectionTag::PointSetInfo`] section.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct PointSetInfo {
    /// Points per set, at least 1.
    pub len: u32,
    /// Number of sets, at least 1.
    pub set_count: u32,
    /// A [`Domain`] code.
    pub domain: u32,
    /// Reserved, zero.
    pub reserved: u32,
}

/// Descriptive metadata, postcard-encoded. Nothing a sampler needs lives here, so a
/// shader can skip it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Metadata<'a> {
    /// What produced the blob, e.g. `"optimize"` or `"owen-sobol"`.
    pub generator: &'a str,
    /// The target density SPEC (docs/targets.md), e.g. `"gaussian:0.5,0.5,0.15"`.
    pub target: &'a str,
    /// The seed the generator was run with.
    pub seed: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[repr(C, align(16))]
    struct Buf([u8; 512]);

    #[test]
    fn header_and_entry_sizes_are_fixed() {
        assert_eq!(HEADER_LEN, 48);
        assert_eq!(SECTION_ENTRY_LEN, 32);
        assert_eq!(core::mem::size_of::<PointSetInfo>(), 16);
        assert_eq!(core::mem::offset_of!(Header, checksum), CHECKSUM_OFFSET);
    }

    #[test]
    fn write_then_read_places_sections_aligned() {
        let info = PointSetInfo {
            len: 3,
            set_count: 1,
            domain: 0,
            reserved: 0,
        };
        let pts: [u16; 6] = [1, 2, 3, 4, 5, 6];
        let meta = [0u8, 0, 7];
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
        let n = encoded_len(&meta, &sections);
        // header 48 + table 64 + meta 3 -> 115 -> 128; +16 -> 144; +12 -> 156 -> 160
        assert_eq!(n, 160);
        let mut buf = Buf([0xAA; 512]);
        let header = write(&mut buf.0[..n], BlobKind::PointSet2D, &meta, &sections).unwrap();
        assert_eq!(header.total_len, 160);
        let layout = Layout::read(&buf.0[..n]).unwrap();
        let (e, bytes) = layout.section(SectionTag::Points).unwrap();
        assert_eq!((e.offset, e.len), (144, 12));
        assert_eq!(bytes, bytemuck::cast_slice::<u16, u8>(&pts));
        assert_eq!(layout.meta_bytes(), &meta);
        // One changed byte anywhere is caught.
        buf.0[150] ^= 1;
        assert!(matches!(
            Layout::read(&buf.0[..n]),
            Err(LayoutError::ChecksumMismatch { .. })
        ));
        // A wrongly sized buffer is refused.
        assert!(matches!(
            write(&mut buf.0[..n + 1], BlobKind::PointSet2D, &meta, &sections),
            Err(WriteError::BufferSize { .. })
        ));
    }

    #[test]
    fn checksum_is_fnv1a_64() {
        // Published FNV-1a 64 test vectors (the skipped field is past these lengths).
        assert_eq!(checksum(b""), 0xcbf29ce484222325);
        assert_eq!(checksum(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(checksum(b"foobar"), 0x85944171f73967e8);
    }
}
