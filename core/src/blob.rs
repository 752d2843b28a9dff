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
    /// `[grid node][instance][index]` (`elem_size` 4).
    PointTable = 5,
    /// The weight table, `f32` per weight-grid node, axis 0 fastest (`elem_size` 4).
    WeightTable = 6,
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

/// Everything that can be wrong with a blob: one variant per failed check, carrying
/// the numbers that failed it. [`Layout::read`] produces the variants up to
/// [`BlobError::SectionsOverlap`]; the kind, metadata, point-set and conditional
/// variants come from the runtime's `Blob::parse`, the last two from [`write()`].
///
/// `Display` writes one line; the type implements [`core::error::Error`], so `?`
/// converts it into `Box<dyn std::error::Error>` or `anyhow::Error`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlobError {
    /// Fewer bytes than the header or than `total_len` says.
    Truncated {
        /// Bytes needed.
        needed: u64,
        /// Bytes present.
        got: u64,
    },
    /// The slice does not start at a 16-byte aligned address.
    Misaligned,
    /// The first eight bytes are not [`MAGIC`].
    BadMagic,
    /// A format version this reader does not know.
    UnsupportedVersion(u32),
    /// More bytes than `total_len` says.
    TrailingBytes {
        /// Length the header declares.
        declared: u64,
        /// Bytes present.
        got: u64,
    },
    /// The checksum does not match the contents.
    ChecksumMismatch {
        /// Value stored in the header.
        stored: u64,
        /// Value computed from the bytes.
        computed: u64,
    },
    /// More sections than [`MAX_SECTIONS`] (in a header, or given to [`write()`]).
    TooManySections {
        /// Sections declared or given.
        count: u64,
        /// [`MAX_SECTIONS`].
        max: u32,
    },
    /// The section table runs past the end of the blob.
    SectionTablePastEnd {
        /// Byte offset where the table ends.
        table_end: u64,
        /// Length of the blob.
        len: u64,
    },
    /// The metadata starts inside the header or the section table.
    MetadataOverlapsTable {
        /// The metadata offset.
        meta_offset: u64,
        /// Byte offset where the section table ends.
        table_end: u64,
    },
    /// The metadata runs past the end of the blob.
    MetadataPastEnd {
        /// Byte offset where the metadata ends.
        meta_end: u64,
        /// Length of the blob.
        len: u64,
    },
    /// A section's `offset + len` overflows `u64`.
    SectionRangeOverflow {
        /// Row of the section table.
        index: u32,
    },
    /// A section starts before the end of the metadata.
    SectionOverlapsMetadata {
        /// Row of the section table.
        index: u32,
        /// The section's offset.
        offset: u64,
        /// Byte offset where the metadata ends.
        meta_end: u64,
    },
    /// A section runs past the end of the blob.
    SectionPastEnd {
        /// Row of the section table.
        index: u32,
        /// Byte offset where the section ends.
        end: u64,
        /// Length of the blob.
        len: u64,
    },
    /// A section's offset is not a multiple of [`ALIGN`].
    SectionMisaligned {
        /// Row of the section table.
        index: u32,
        /// The section's offset.
        offset: u64,
    },
    /// A section declares an element size of zero.
    ZeroElementSize {
        /// Row of the section table.
        index: u32,
    },
    /// A section's length is not a whole number of elements.
    PartialElement {
        /// Row of the section table.
        index: u32,
        /// The section's length in bytes.
        len: u64,
        /// Its element size in bytes.
        elem_size: u32,
    },
    /// Two sections share bytes.
    SectionsOverlap {
        /// Row of the earlier section in the table.
        first: u32,
        /// Row of the later one.
        second: u32,
    },
    /// An unknown [`BlobKind`] code.
    UnknownKind(u32),
    /// The metadata does not decode.
    BadMetadata,
    /// A required section is absent.
    MissingSection(SectionTag),
    /// The [`SectionTag::PointSetInfo`] section is not one [`PointSetInfo`] long.
    PointSetInfoSize {
        /// Its length in bytes.
        got: u64,
        /// `size_of::<PointSetInfo>()`.
        expected: u64,
    },
    /// [`PointSetInfo::len`] is zero.
    NoPoints,
    /// [`PointSetInfo::set_count`] is zero.
    NoSets,
    /// [`PointSetInfo::domain`] is not a [`Domain`] code.
    UnknownDomain(u32),
    /// The domain does not fit the kind (a 2D point set must be on the square, a
    /// direction set on the sphere or hemisphere).
    DomainMismatch {
        /// The blob's kind.
        kind: BlobKind,
        /// The domain its info section names.
        domain: Domain,
    },
    /// The [`SectionTag::Points`] elements are not 4 bytes (2 x u16).
    PointElementSize(u32),
    /// The [`SectionTag::Points`] length is not `len * set_count * 4` bytes.
    PointsLength {
        /// Bytes the counts call for.
        expected: u64,
        /// Bytes present.
        got: u64,
    },
    /// The [`SectionTag::ConditionalInfo`] section is not one
    /// [`crate::conditional::ConditionalInfo`] long.
    ConditionalInfoSize {
        /// Its length in bytes.
        got: u64,
        /// [`crate::conditional::CONDITIONAL_INFO_LEN`].
        expected: u64,
    },
    /// The conditional info's `n` (points per set) is zero.
    ConditionalNoPoints,
    /// The conditional info's `instances` is zero.
    ConditionalNoInstances,
    /// The conditional info's domain code is not [`Domain::Sphere`] or
    /// [`Domain::Hemisphere`].
    ConditionalDomain(u32),
    /// The conditional info's target is not a
    /// [`crate::conditional::ConditionalTarget`] code.
    UnknownConditionalTarget(u32),
    /// A point-table grid axis has fewer than 2 nodes.
    ConditionalGrid {
        /// The axis (0 or 1).
        axis: u32,
        /// Its node count.
        nodes: u32,
    },
    /// A weight-table grid axis has fewer than 2 nodes.
    ConditionalWeightGrid {
        /// The axis (0 or 1).
        axis: u32,
        /// Its node count.
        nodes: u32,
    },
    /// A condition axis' range is not finite with `cond_min < cond_max` (the bounds
    /// are carried as `f32` bits so the error stays `Eq`).
    ConditionalRange {
        /// The axis (0 or 1).
        axis: u32,
        /// `f32::to_bits` of `cond_min`.
        min_bits: u32,
        /// `f32::to_bits` of `cond_max`.
        max_bits: u32,
    },
    /// The conditional info's activation is not a
    /// [`crate::network::Activation`] code.
    UnknownActivation(u32),
    /// The hidden widths describe no [`crate::network::Shape`]: no first layer, a
    /// width above [`crate::network::MAX_WIDTH`], or a non-zero width after a zero.
    NetworkWidths([u32; 3]),
    /// The conditional info's instance slots `M` make the network's embedding
    /// (`M n h1` numbers) larger than a `u32` counts.
    InstanceSlots(u32),
    /// The reserved field of the conditional info is not zero.
    ConditionalReserved(u32),
    /// The conditional info's warp is not a
    /// [`crate::conditional::PointWarp`] code, or names a warp the target has none of.
    UnknownPointWarp(u32),
    /// The [`SectionTag::NetworkParams`] elements are not 2 bytes (f16).
    ParamElementSize(u32),
    /// The [`SectionTag::NetworkParams`] section does not hold exactly
    /// `Shape::param_len` entries.
    ParamsLength {
        /// Entries the shape calls for.
        expected: u64,
        /// Entries present.
        got: u64,
    },
    /// A network parameter is an f16 infinity or NaN.
    NonFiniteParam {
        /// Its index in the parameter array.
        index: u64,
        /// Its f16 bits.
        bits: u16,
    },
    /// The [`SectionTag::PointTable`] elements are not 4 bytes (2 x u16).
    PointTableElementSize(u32),
    /// `grid[0] grid[1] instances n` overflows `u64`.
    PointTableCountOverflow,
    /// The [`SectionTag::PointTable`] section does not hold exactly
    /// `grid[0] grid[1] instances n` entries.
    PointTableLength {
        /// Entries the counts call for.
        expected: u64,
        /// Entries present.
        got: u64,
    },
    /// The [`SectionTag::WeightTable`] elements are not 4 bytes (f32).
    WeightElementSize(u32),
    /// The [`SectionTag::WeightTable`] section does not hold exactly
    /// `weight_grid[0] weight_grid[1]` entries.
    WeightTableLength {
        /// Entries the grid calls for.
        expected: u64,
        /// Entries present.
        got: u64,
    },
    /// A weight is negative, infinite or NaN.
    BadWeight {
        /// Its index in the weight table.
        index: u64,
        /// Its `f32` bits.
        bits: u32,
    },
    /// The blob holds something other than what was asked for.
    WrongKind {
        /// The kind asked for.
        expected: BlobKind,
        /// The kind the blob holds.
        found: BlobKind,
    },
    /// The sizes given to [`write()`] overflow the blob's `u64` length.
    SizeOverflow,
    /// The output buffer passed to [`write()`] has the wrong size.
    BufferSize {
        /// Bytes needed.
        needed: u64,
        /// Bytes given.
        got: u64,
    },
}

impl core::fmt::Display for BlobError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Truncated { needed, got } => {
                write!(f, "blob truncated: {got} bytes, needs {needed}")
            }
            Self::Misaligned => write!(f, "blob bytes are not {ALIGN}-byte aligned"),
            Self::BadMagic => write!(f, "not a nuld blob (bad magic)"),
            Self::UnsupportedVersion(v) => write!(
                f,
                "unsupported blob format version {v} (reader knows {FORMAT_VERSION})"
            ),
            Self::TrailingBytes { declared, got } => {
                write!(f, "blob has {got} bytes but its header declares {declared}")
            }
            Self::ChecksumMismatch { stored, computed } => write!(
                f,
                "blob checksum mismatch (stored {stored:#018x}, computed {computed:#018x})"
            ),
            Self::TooManySections { count, max } => {
                write!(f, "blob has {count} sections, at most {max} allowed")
            }
            Self::SectionTablePastEnd { table_end, len } => write!(
                f,
                "blob section table ends at byte {table_end}, past the blob's {len} bytes"
            ),
            Self::MetadataOverlapsTable {
                meta_offset,
                table_end,
            } => write!(
                f,
                "blob metadata starts at byte {meta_offset}, inside the header and section table (which end at {table_end})"
            ),
            Self::MetadataPastEnd { meta_end, len } => write!(
                f,
                "blob metadata ends at byte {meta_end}, past the blob's {len} bytes"
            ),
            Self::SectionRangeOverflow { index } => {
                write!(f, "blob section {index}: offset + length overflows")
            }
            Self::SectionOverlapsMetadata {
                index,
                offset,
                meta_end,
            } => write!(
                f,
                "blob section {index} starts at byte {offset}, before the metadata ends ({meta_end})"
            ),
            Self::SectionPastEnd { index, end, len } => write!(
                f,
                "blob section {index} ends at byte {end}, past the blob's {len} bytes"
            ),
            Self::SectionMisaligned { index, offset } => write!(
                f,
                "blob section {index} starts at byte {offset}, not a multiple of {ALIGN}"
            ),
            Self::ZeroElementSize { index } => {
                write!(f, "blob section {index} has element size 0")
            }
            Self::PartialElement {
                index,
                len,
                elem_size,
            } => write!(
                f,
                "blob section {index} is {len} bytes, not a whole number of {elem_size}-byte elements"
            ),
            Self::SectionsOverlap { first, second } => {
                write!(f, "blob sections {first} and {second} overlap")
            }
            Self::UnknownKind(k) => write!(f, "unknown blob kind {k}"),
            Self::BadMetadata => write!(f, "blob metadata does not decode"),
            Self::MissingSection(tag) => write!(f, "blob lacks the {tag:?} section"),
            Self::PointSetInfoSize { got, expected } => write!(
                f,
                "blob point set info section is {got} bytes, not {expected}"
            ),
            Self::NoPoints => write!(f, "blob point sets have 0 points"),
            Self::NoSets => write!(f, "blob holds 0 point sets"),
            Self::UnknownDomain(d) => write!(f, "unknown blob domain code {d}"),
            Self::DomainMismatch { kind, domain } => {
                write!(f, "blob of kind {kind:?} cannot hold points on the {}", domain.name())
            }
            Self::PointElementSize(s) => write!(
                f,
                "blob points section has {s}-byte elements, not 4 (2 x u16)"
            ),
            Self::PointsLength { expected, got } => write!(
                f,
                "blob points section is {got} bytes, the counts call for {expected}"
            ),
            Self::ConditionalInfoSize { got, expected } => write!(
                f,
                "blob conditional info section is {got} bytes, not {expected}"
            ),
            Self::ConditionalNoPoints => write!(f, "blob conditional sampler has 0 points per set"),
            Self::ConditionalNoInstances => write!(f, "blob conditional sampler has 0 instances"),
            Self::ConditionalDomain(d) => write!(
                f,
                "blob conditional domain code {d} is neither the sphere (1) nor the hemisphere (2)"
            ),
            Self::UnknownConditionalTarget(t) => {
                write!(f, "unknown blob conditional target code {t}")
            }
            Self::ConditionalGrid { axis, nodes } => write!(
                f,
                "blob point-table grid axis {axis} has {nodes} nodes, needs at least 2"
            ),
            Self::ConditionalWeightGrid { axis, nodes } => write!(
                f,
                "blob weight-table grid axis {axis} has {nodes} nodes, needs at least 2"
            ),
            Self::ConditionalRange {
                axis,
                min_bits,
                max_bits,
            } => write!(
                f,
                "blob condition axis {axis} range [{}, {}] is not finite with min < max",
                f32::from_bits(min_bits),
                f32::from_bits(max_bits)
            ),
            Self::UnknownActivation(a) => write!(f, "unknown blob network activation code {a}"),
            Self::NetworkWidths(h) => write!(
                f,
                "blob network hidden widths {h:?} are not 1 to 3 layers of 1 to {} units",
                crate::network::MAX_WIDTH
            ),
            Self::InstanceSlots(m) => write!(
                f,
                "blob network instance slots {m} make an embedding larger than 2^32 numbers"
            ),
            Self::ConditionalReserved(r) => {
                write!(f, "blob conditional info reserved field {r} is not zero")
            }
            Self::UnknownPointWarp(w) => write!(f, "blob conditional point warp {w} is unknown"),
            Self::ParamElementSize(s) => write!(
                f,
                "blob network parameters have {s}-byte elements, not 2 (f16)"
            ),
            Self::ParamsLength { expected, got } => write!(
                f,
                "blob network has {got} parameters, its shape calls for {expected}"
            ),
            Self::NonFiniteParam { index, bits } => write!(
                f,
                "blob network parameter {index} is not finite (f16 bits {bits:#06x})"
            ),
            Self::PointTableElementSize(s) => write!(
                f,
                "blob point table has {s}-byte elements, not 4 (2 x u16)"
            ),
            Self::PointTableCountOverflow => {
                write!(f, "blob point-table size grid x instances x n overflows u64")
            }
            Self::PointTableLength { expected, got } => write!(
                f,
                "blob point table has {got} entries, the counts call for {expected}"
            ),
            Self::WeightElementSize(s) => write!(
                f,
                "blob weight table has {s}-byte elements, not 4 (f32)"
            ),
            Self::WeightTableLength { expected, got } => write!(
                f,
                "blob weight table has {got} entries, the grid calls for {expected}"
            ),
            Self::BadWeight { index, bits } => write!(
                f,
                "blob weight {index} is {}, not finite and >= 0",
                f32::from_bits(bits)
            ),
            Self::WrongKind { expected, found } => {
                write!(f, "blob holds {found:?}, not {expected:?}")
            }
            Self::SizeOverflow => write!(f, "blob size overflows u64"),
            Self::BufferSize { needed, got } => {
                write!(f, "output buffer has {got} bytes, blob needs {needed}")
            }
        }
    }
}

impl core::error::Error for BlobError {}

/// FNV-1a 64 of `bytes`, skipping (reading as zero) the header's checksum field.
///
/// FNV-1a's step (`xor` a byte, multiply by an odd constant mod 2^64) is a bijection
/// of the state for a fixed byte, so two inputs that differ in exactly one byte always
/// hash differently: every single-byte corruption of a blob is detected.
pub fn checksum(bytes: &[u8]) -> u64 {
    const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h = OFFSET_BASIS;
    for (i, &b) in bytes.iter().enumerate() {
        let b = if (CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8).contains(&i) {
            0
        } else {
            b
        };
        h = (h ^ b as u64).wrapping_mul(PRIME);
    }
    h
}

/// `x` rounded up to a multiple of [`ALIGN`], or `None` on overflow.
#[inline]
fn align_up(x: u64) -> Option<u64> {
    x.checked_add(ALIGN as u64 - 1)
        .map(|v| v & !(ALIGN as u64 - 1))
}

/// A section to be written: its tag, element size and bytes.
#[derive(Clone, Copy, Debug)]
pub struct SectionSpec<'s> {
    /// The section's [`SectionTag`].
    pub tag: SectionTag,
    /// Size in bytes of one element.
    pub elem_size: u32,
    /// The section's contents.
    pub bytes: &'s [u8],
}

/// Offsets of everything [`write()`] places, computed once for both [`encoded_len`] and
/// [`write()`].
fn plan(meta_len: usize, sections: &[SectionSpec<'_>]) -> Option<(u64, u64)> {
    let table_end = HEADER_LEN as u64 + (sections.len() * SECTION_ENTRY_LEN) as u64;
    let meta_end = table_end.checked_add(meta_len as u64)?;
    let mut end = meta_end;
    for s in sections {
        end = align_up(end)?.checked_add(s.bytes.len() as u64)?;
    }
    Some((table_end, align_up(end)?))
}

/// Number of bytes [`write()`] needs for this metadata and these sections.
pub fn encoded_len(meta: &[u8], sections: &[SectionSpec<'_>]) -> usize {
    plan(meta.len(), sections).map_or(usize::MAX, |(_, total)| total as usize)
}

/// Writes a complete blob into `out`, which must be exactly [`encoded_len`] bytes
/// (zero-initialized or not: padding is zeroed here). Returns the header written.
pub fn write(
    out: &mut [u8],
    kind: BlobKind,
    meta: &[u8],
    sections: &[SectionSpec<'_>],
) -> Result<Header, BlobError> {
    if sections.len() > MAX_SECTIONS as usize {
        return Err(BlobError::TooManySections {
            count: sections.len() as u64,
            max: MAX_SECTIONS,
        });
    }
    let (table_end, total) = plan(meta.len(), sections).ok_or(BlobError::SizeOverflow)?;
    if out.len() as u64 != total {
        return Err(BlobError::BufferSize {
            needed: total,
            got: out.len() as u64,
        });
    }
    out.fill(0);
    let meta_offset = table_end as usize;
    out[meta_offset..meta_offset + meta.len()].copy_from_slice(meta);
    let mut cursor = (table_end + meta.len() as u64) as usize;
    for (k, s) in sections.iter().enumerate() {
        cursor = align_up(cursor as u64).unwrap_or(0) as usize;
        out[cursor..cursor + s.bytes.len()].copy_from_slice(s.bytes);
        let entry = SectionEntry {
            tag: s.tag as u32,
            elem_size: s.elem_size,
            offset: cursor as u64,
            len: s.bytes.len() as u64,
            reserved: 0,
        };
        let at = HEADER_LEN + k * SECTION_ENTRY_LEN;
        out[at..at + SECTION_ENTRY_LEN].copy_from_slice(bytemuck::bytes_of(&entry));
        cursor += s.bytes.len();
    }
    let mut header = Header {
        magic: MAGIC,
        version: FORMAT_VERSION,
        kind: kind as u32,
        total_len: total,
        checksum: 0,
        meta_offset: meta_offset as u32,
        meta_len: meta.len() as u32,
        section_count: sections.len() as u32,
        reserved: 0,
    };
    out[..HEADER_LEN].copy_from_slice(bytemuck::bytes_of(&header));
    header.checksum = checksum(out);
    out[..HEADER_LEN].copy_from_slice(bytemuck::bytes_of(&header));
    Ok(header)
}

/// A blob whose header, section table, metadata bounds and checksum have been
/// validated. Borrowing, allocation-free.
#[derive(Clone, Copy, Debug)]
pub struct Layout<'a> {
    bytes: &'a [u8],
    header: Header,
}

impl<'a> Layout<'a> {
    /// Validates `bytes` as a format-v1 blob: alignment of the slice, length, magic,
    /// version, checksum, and that the metadata and every section lie inside the
    /// blob, after the section table, at 16-byte aligned offsets, with a length that
    /// is a whole number of elements. Sections may not overlap each other.
    ///
    /// The kind is not checked against the known kinds here; see [`BlobKind`].
    pub fn read(bytes: &'a [u8]) -> Result<Self, BlobError> {
        let got = bytes.len() as u64;
        if bytes.len() < HEADER_LEN {
            return Err(BlobError::Truncated {
                needed: HEADER_LEN as u64,
                got,
            });
        }
        if bytes.as_ptr() as usize % ALIGN != 0 {
            return Err(BlobError::Misaligned);
        }
        let header: Header = bytemuck::pod_read_unaligned(&bytes[..HEADER_LEN]);
        if header.magic != MAGIC {
            return Err(BlobError::BadMagic);
        }
        if header.version != FORMAT_VERSION {
            return Err(BlobError::UnsupportedVersion(header.version));
        }
        if header.total_len > got {
            return Err(BlobError::Truncated {
                needed: header.total_len,
                got,
            });
        }
        if header.total_len < got {
            return Err(BlobError::TrailingBytes {
                declared: header.total_len,
                got,
            });
        }
        let computed = checksum(bytes);
        if computed != header.checksum {
            return Err(BlobError::ChecksumMismatch {
                stored: header.checksum,
                computed,
            });
        }
        if header.section_count > MAX_SECTIONS {
            return Err(BlobError::TooManySections {
                count: header.section_count as u64,
                max: MAX_SECTIONS,
            });
        }
        let table_end = HEADER_LEN as u64 + header.section_count as u64 * SECTION_ENTRY_LEN as u64;
        if table_end > got {
            return Err(BlobError::SectionTablePastEnd {
                table_end,
                len: got,
            });
        }
        let meta_offset = header.meta_offset as u64;
        let meta_end = meta_offset + header.meta_len as u64;
        if meta_offset < table_end {
            return Err(BlobError::MetadataOverlapsTable {
                meta_offset,
                table_end,
            });
        }
        if meta_end > got {
            return Err(BlobError::MetadataPastEnd { meta_end, len: got });
        }
        let layout = Self { bytes, header };
        // `k < section_count <= MAX_SECTIONS`, so the row index fits a u32.
        for k in 0..header.section_count {
            let e = layout.entry(k as usize);
            let end = e
                .offset
                .checked_add(e.len)
                .ok_or(BlobError::SectionRangeOverflow { index: k })?;
            if e.offset < meta_end {
                return Err(BlobError::SectionOverlapsMetadata {
                    index: k,
                    offset: e.offset,
                    meta_end,
                });
            }
            if end > got {
                return Err(BlobError::SectionPastEnd {
                    index: k,
                    end,
                    len: got,
                });
            }
            if e.offset % ALIGN as u64 != 0 {
                return Err(BlobError::SectionMisaligned {
                    index: k,
                    offset: e.offset,
                });
            }
            if e.elem_size == 0 {
                return Err(BlobError::ZeroElementSize { index: k });
            }
            if e.len % e.elem_size as u64 != 0 {
                return Err(BlobError::PartialElement {
                    index: k,
                    len: e.len,
                    elem_size: e.elem_size,
                });
            }
            for j in 0..k {
                let o = layout.entry(j as usize);
                if e.offset < o.offset + o.len && o.offset < end {
                    return Err(BlobError::SectionsOverlap {
                        first: j,
                        second: k,
                    });
                }
            }
        }
        Ok(layout)
    }

    /// The validated header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The blob's bytes.
    pub fn bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// The postcard-encoded metadata bytes.
    pub fn meta_bytes(&self) -> &'a [u8] {
        let start = self.header.meta_offset as usize;
        self.bytes
            .get(start..start + self.header.meta_len as usize)
            .unwrap_or(&[])
    }

    /// Decodes the metadata.
    pub fn metadata(&self) -> Result<Metadata<'a>, BlobError> {
        postcard::from_bytes(self.meta_bytes()).map_err(|_| BlobError::BadMetadata)
    }

    /// Row `k` of the section table (`k < section_count`, checked by [`Layout::read`]).
    fn entry(&self, k: usize) -> SectionEntry {
        let at = HEADER_LEN + k * SECTION_ENTRY_LEN;
        self.bytes
            .get(at..at + SECTION_ENTRY_LEN)
            .map(bytemuck::pod_read_unaligned)
            .unwrap_or_else(SectionEntry::zeroed)
    }

    /// The first section with this tag, as its table row and its bytes.
    pub fn section(&self, tag: SectionTag) -> Result<(SectionEntry, &'a [u8]), BlobError> {
        for k in 0..self.header.section_count {
            let e = self.entry(k as usize);
            if e.tag == tag as u32 {
                // In range by `Layout::read`; `get` keeps the lookup panic-free.
                let end = e.offset.saturating_add(e.len);
                let bytes = self.bytes.get(e.offset as usize..end as usize).ok_or(
                    BlobError::SectionPastEnd {
                        index: k,
                        end,
                        len: self.bytes.len() as u64,
                    },
                )?;
                return Ok((e, bytes));
            }
        }
        Err(BlobError::MissingSection(tag))
    }
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
            Err(BlobError::ChecksumMismatch { .. })
        ));
        // A wrongly sized buffer is refused.
        assert!(matches!(
            write(&mut buf.0[..n + 1], BlobKind::PointSet2D, &meta, &sections),
            Err(BlobError::BufferSize { .. })
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
