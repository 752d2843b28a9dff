//! Everything that can be wrong with a blob, nested by where it is wrong
//! (bytemuck-style): the layout every blob shares ([`LayoutError`]), the sections
//! of each kind ([`PointSetError`], [`ConditionalError`]), a view that does not fit
//! the blob, and [`write()`](super::write()) ([`WriteError`]). Each variant is
//! produced by exactly the corruption it names. `Display` writes one line; every
//! type implements [`core::error::Error`], so `?` converts it into
//! `Box<dyn std::error::Error>` or `anyhow::Error`.

use super::{BlobKind, SectionTag, ALIGN, FORMAT_VERSION};
use crate::conditional::ConditionalTarget;
use crate::domain::Domain;

/// Everything that can be wrong with a blob (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlobError {
    /// The header, checksum, metadata bounds or section table
    /// ([`Layout::read`](super::Layout::read)).
    Layout(LayoutError),
    /// An unknown [`BlobKind`] code.
    UnknownKind(u32),
    /// The metadata does not decode.
    BadMetadata,
    /// A section the blob's kind needs is absent.
    MissingSection(SectionTag),
    /// The sections of a point or direction set.
    PointSet(PointSetError),
    /// The sections of a conditional sampler.
    Conditional(ConditionalError),
    /// The blob holds something other than the view asked for.
    WrongKind {
        /// The kind asked for.
        expected: BlobKind,
        /// The kind the blob holds.
        found: BlobKind,
    },
    /// The conditional blob samples another target than the view asked for (a BRDF
    /// view of an environment sampler, or the reverse).
    WrongTarget {
        /// The target asked for.
        expected: ConditionalTarget,
        /// The target the blob samples.
        found: ConditionalTarget,
    },
    /// [`write()`](super::write()) cannot write the blob.
    Write(WriteError),
}

impl core::fmt::Display for BlobError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Layout(e) => e.fmt(f),
            Self::UnknownKind(k) => write!(f, "unknown blob kind {k}"),
            Self::BadMetadata => write!(f, "blob metadata does not decode"),
            Self::MissingSection(tag) => write!(f, "blob lacks the {tag:?} section"),
            Self::PointSet(e) => e.fmt(f),
            Self::Conditional(e) => e.fmt(f),
            Self::WrongKind { expected, found } => {
                write!(f, "blob holds {found:?}, not {expected:?}")
            }
            Self::WrongTarget { expected, found } => {
                write!(f, "blob samples {found:?}, not {expected:?}")
            }
            Self::Write(e) => e.fmt(f),
        }
    }
}

impl core::error::Error for BlobError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Layout(e) => Some(e),
            Self::PointSet(e) => Some(e),
            Self::Conditional(e) => Some(e),
            Self::Write(e) => Some(e),
            _ => None,
        }
    }
}

macro_rules! nest {
    ($($inner:ident => $variant:ident),*) => {$(
        impl From<$inner> for BlobError {
            fn from(e: $inner) -> Self {
                Self::$variant(e)
            }
        }
    )*};
}
nest!(LayoutError => Layout, PointSetError => PointSet, ConditionalError => Conditional, WriteError => Write);

/// What [`Layout::read`](super::Layout::read) finds wrong with a blob's header, checksum,
/// metadata bounds or section table: one variant per failed check, in the order the
/// checks run, carrying the numbers that failed it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutError {
    /// Fewer bytes than the header or than `total_len` says.
    Truncated {
        /// Bytes needed.
        needed: u64,
        /// Bytes present.
        got: u64,
    },
    /// The slice does not start at a 16-byte aligned address.
    Misaligned,
    /// The first eight bytes are not [`MAGIC`](super::MAGIC).
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
    /// More sections than [`MAX_SECTIONS`](super::MAX_SECTIONS) (in a header, or given to [`write()`](super::write())).
    TooManySections {
        /// Sections declared or given.
        count: u64,
        /// [`MAX_SECTIONS`](super::MAX_SECTIONS).
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
}

impl core::fmt::Display for LayoutError {
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
        }
    }
}

impl core::error::Error for LayoutError {}

/// What is wrong with the sections of a point or direction set
/// ([`BlobKind::PointSet2D`], [`BlobKind::DirectionSet`]): one variant per failed check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointSetError {
    /// The [`SectionTag::PointSetInfo`] section is not one [`PointSetInfo`](super::PointSetInfo) long.
    InfoSize {
        /// Its length in bytes.
        got: u64,
        /// `size_of::<PointSetInfo>()`.
        expected: u64,
    },
    /// [`super::PointSetInfo::len`] is zero.
    NoPoints,
    /// [`super::PointSetInfo::set_count`] is zero.
    NoSets,
    /// [`super::PointSetInfo::domain`] is not a [`Domain`] code.
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
    ElementSize(u32),
    /// The [`SectionTag::Points`] length is not `len * set_count * 4` bytes.
    Length {
        /// Bytes the counts call for.
        expected: u64,
        /// Bytes present.
        got: u64,
    },
}

impl core::fmt::Display for PointSetError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::InfoSize { got, expected } => write!(
                f,
                "blob point set info section is {got} bytes, not {expected}"
            ),
            Self::NoPoints => write!(f, "blob point sets have 0 points"),
            Self::NoSets => write!(f, "blob holds 0 point sets"),
            Self::UnknownDomain(d) => write!(f, "unknown blob domain code {d}"),
            Self::DomainMismatch { kind, domain } => {
                write!(
                    f,
                    "blob of kind {kind:?} cannot hold points on the {}",
                    domain.name()
                )
            }
            Self::ElementSize(s) => write!(
                f,
                "blob points section has {s}-byte elements, not 4 (2 x u16)"
            ),
            Self::Length { expected, got } => write!(
                f,
                "blob points section is {got} bytes, the counts call for {expected}"
            ),
        }
    }
}

impl core::error::Error for PointSetError {}

/// What is wrong with the sections of a conditional sampler
/// ([`BlobKind::Conditional`], `core/FORMAT.md`): one variant per failed check, in the
/// order the runtime's validation runs them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConditionalError {
    /// The [`SectionTag::ConditionalInfo`] section is not one
    /// [`crate::conditional::ConditionalInfo`] long.
    InfoSize {
        /// Its length in bytes.
        got: u64,
        /// [`crate::conditional::CONDITIONAL_INFO_LEN`].
        expected: u64,
    },
    /// The conditional info's `n` (points per set) is zero.
    NoPoints,
    /// The conditional info's `instances` is zero.
    NoInstances,
    /// The conditional info's domain code is not [`Domain::Sphere`] or
    /// [`Domain::Hemisphere`].
    Domain(u32),
    /// The conditional info's target is not a
    /// [`crate::conditional::ConditionalTarget`] code.
    UnknownTarget(u32),
    /// A point-table grid axis has fewer than 2 nodes.
    Grid {
        /// The axis (0 or 1).
        axis: u32,
        /// Its node count.
        nodes: u32,
    },
    /// A weight-table grid axis has fewer than 2 nodes.
    WeightGrid {
        /// The axis (0 or 1).
        axis: u32,
        /// Its node count.
        nodes: u32,
    },
    /// A condition axis' range is not finite with `cond_min < cond_max` (the bounds
    /// are carried as `f32` bits so the error stays `Eq`).
    Range {
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
    /// The conditional info's offset hash is not a
    /// [`crate::network::OffsetHash`] code.
    UnknownOffsetHash(u32),
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
    /// Metal points ([`SectionTag::MetalNetworkParams`],
    /// [`SectionTag::MetalPointTable`]) in a blob whose prior has no metal layer
    /// ([`crate::brdf_prior::has_metal_layer`]), or one of the two without the
    /// other (its tag).
    MetalPoints(u32),
    /// A metal-points section whose elements (tag, size in bytes) differ from
    /// its shared twin's (2 bytes for the network, 4 for the table).
    MetalElementSize {
        /// The section's tag.
        tag: u32,
        /// Its element size.
        size: u32,
    },
    /// A metal-points section whose length differs from its shared twin's.
    MetalLength {
        /// The section's tag.
        tag: u32,
        /// Entries the counts call for.
        expected: u64,
        /// Entries present.
        got: u64,
    },
    /// A metal network parameter is an f16 infinity or NaN.
    NonFiniteMetalParam {
        /// Its index in the parameter array.
        index: u64,
        /// Its f16 bits.
        bits: u16,
    },
    /// A metallic axis ([`SectionTag::MetallicNodes`]) on a sampler whose point
    /// warp is not [`crate::conditional::PointWarp::BrdfTable`] (its warp code).
    MetallicNodesWarp(u32),
    /// The metallic axis has elements of this many bytes, not 4 (`f32`).
    MetallicNodesElementSize(u32),
    /// The metallic axis's values ([`crate::conditional::check_metallic_nodes`]).
    MetallicNodes(crate::conditional::MetallicNodesError),
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
    /// An environment sampler without the prior of the current format
    /// ([`crate::conditional::PointWarp::EnvmapTree`] and its tree sections): a
    /// blob baked before the prior existed.
    EnvmapWithoutPrior,
    /// The [`SectionTag::EnvmapTreeInfo`] section is not one
    /// [`crate::envmap_tree::TreeInfo`] long.
    TreeInfoSize {
        /// Its length in bytes.
        got: u64,
        /// [`crate::envmap_tree::TREE_INFO_LEN`].
        expected: u64,
    },
    /// The reserved word of the tree info is not zero.
    TreeReserved,
    /// The [`SectionTag::EnvmapTreeNodes`] elements are not 16 bytes.
    TreeNodeElementSize(u32),
    /// The [`SectionTag::EnvmapTreeTop`] elements are not 4 bytes (f32).
    TreeTopElementSize(u32),
    /// The [`SectionTag::EnvmapTreeCorners`] elements are not 4 bytes (f32).
    TreeCornerElementSize(u32),
    /// The [`SectionTag::EnvmapTreeDetailIndex`], [`SectionTag::EnvmapTreeDetail`]
    /// or [`SectionTag::EnvmapTreeFineDetail`] elements are not 4 bytes (u32, f32).
    TreeDetailElementSize(u32),
    /// One of the two detail sections without the other, or the fine tables
    /// without them.
    TreeDetailAlone,
    /// The tree's levels, counts or values are refused
    /// ([`crate::envmap_tree::EnvmapTree::new`]).
    Tree(crate::quadtree::QuadtreeError),
    /// A BRDF sampler whose prior's tables are of an earlier format: its info
    /// under `tag`, [`SectionTag::BrdfPriorInfoUnstretched`] (the plain
    /// half-vector square), [`SectionTag::BrdfPriorInfoStretchedMetal`] (the
    /// metal layer in a stretched square) or
    /// [`SectionTag::BrdfPriorInfoStretchedShared`] (the shared layers in a
    /// square of one stretch), and no [`SectionTag::BrdfPriorInfo`].
    BrdfPriorEarlier {
        /// The section tag its info is under.
        tag: u32,
    },
    /// The [`SectionTag::BrdfPriorInfo`] section is not one
    /// [`crate::brdf_prior::BrdfPriorInfo`] long.
    BrdfPriorInfoSize {
        /// Its length in bytes.
        got: u64,
        /// [`crate::brdf_prior::BRDF_PRIOR_INFO_LEN`].
        expected: u64,
    },
    /// A BRDF prior table section's elements are not 4 bytes (f32).
    BrdfPriorElementSize {
        /// The section's [`SectionTag`] code.
        tag: u32,
        /// Its element size.
        size: u32,
    },
    /// The BRDF prior's grid, sizes, lengths or values are refused
    /// ([`crate::brdf_prior::BrdfPrior::new`]; a length error's slice 3 is the
    /// masses).
    BrdfPrior(crate::marginal2d::Marginal2DError),
}

impl core::fmt::Display for ConditionalError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::InfoSize { got, expected } => write!(
                f,
                "blob conditional info section is {got} bytes, not {expected}"
            ),
            Self::NoPoints => write!(f, "blob conditional sampler has 0 points per set"),
            Self::NoInstances => write!(f, "blob conditional sampler has 0 instances"),
            Self::Domain(d) => write!(
                f,
                "blob conditional domain code {d} is neither the sphere (1) nor the hemisphere (2)"
            ),
            Self::UnknownTarget(t) => {
                write!(f, "unknown blob conditional target code {t}")
            }
            Self::Grid { axis, nodes } => write!(
                f,
                "blob point-table grid axis {axis} has {nodes} nodes, needs at least 2"
            ),
            Self::WeightGrid { axis, nodes } => write!(
                f,
                "blob weight-table grid axis {axis} has {nodes} nodes, needs at least 2"
            ),
            Self::Range {
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
            Self::UnknownOffsetHash(h) => write!(
                f,
                "blob conditional instance-offset hash {h} is unknown (a newer tool's blob: update the runtime)"
            ),
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
            Self::PointTableElementSize(s) => {
                write!(f, "blob point table has {s}-byte elements, not 4 (2 x u16)")
            }
            Self::MetalPoints(tag) => write!(
                f,
                "blob metal points (sections 16 and 17) are incomplete or have no metal layer to serve (section {tag})"
            ),
            Self::MetalElementSize { tag, size } => write!(
                f,
                "blob metal-points section {tag} has {size}-byte elements, not its shared twin's"
            ),
            Self::MetalLength { tag, expected, got } => write!(
                f,
                "blob metal-points section {tag} has {got} entries, the counts call for {expected}"
            ),
            Self::NonFiniteMetalParam { index, bits } => write!(
                f,
                "blob metal network parameter {index} is not finite (f16 bits {bits:#06x})"
            ),
            Self::MetallicNodesWarp(warp) => write!(
                f,
                "blob metallic axis (section 18) on a sampler of point warp {warp}; only warp 3 (the tabulated BRDF prior) has one"
            ),
            Self::MetallicNodesElementSize(s) => {
                write!(f, "blob metallic axis has {s}-byte elements, not 4 (f32)")
            }
            Self::MetallicNodes(crate::conditional::MetallicNodesError::Count(count)) => write!(
                f,
                "blob metallic axis has {count} nodes, not 2 to {}",
                crate::conditional::MAX_METALLIC_NODES
            ),
            Self::MetallicNodes(crate::conditional::MetallicNodesError::Value { index, bits }) => {
                write!(
                    f,
                    "blob metallic node {index} ({}) is not finite, in [0, 1] and above the one before",
                    f32::from_bits(bits)
                )
            }
            Self::PointTableCountOverflow => {
                write!(
                    f,
                    "blob point-table size grid x instances x n overflows u64"
                )
            }
            Self::PointTableLength { expected, got } => write!(
                f,
                "blob point table has {got} entries, the counts call for {expected}"
            ),
            Self::WeightElementSize(s) => {
                write!(f, "blob weight table has {s}-byte elements, not 4 (f32)")
            }
            Self::WeightTableLength { expected, got } => write!(
                f,
                "blob weight table has {got} entries, the grid calls for {expected}"
            ),
            Self::BadWeight { index, bits } => write!(
                f,
                "blob weight {index} is {}, not finite and >= 0",
                f32::from_bits(bits)
            ),
            Self::EnvmapWithoutPrior => write!(
                f,
                "environment sampler of an earlier format (no exact prior): bake it again with `build-tool bake --envmap`"
            ),
            Self::TreeInfoSize { got, expected } => write!(
                f,
                "blob environment tree info section is {got} bytes, not {expected}"
            ),
            Self::TreeReserved => write!(f, "blob environment tree info's reserved word is not 0"),
            Self::TreeNodeElementSize(e) => {
                write!(f, "blob environment tree nodes are {e} bytes each, not 16")
            }
            Self::TreeTopElementSize(e) => {
                write!(f, "blob environment tree top weights are {e} bytes each, not 4")
            }
            Self::TreeCornerElementSize(e) => {
                write!(f, "blob environment tree leaf corners are {e} bytes each, not 4")
            }
            Self::TreeDetailElementSize(e) => {
                write!(f, "blob environment tree detail entries are {e} bytes each, not 4")
            }
            Self::TreeDetailAlone => write!(
                f,
                "blob environment tree has one of its detail sections (tags 20, 21) without the other, or fine tables (tag 22) without them"
            ),
            Self::Tree(e) => write!(f, "blob environment tree: {e}"),
            Self::BrdfPriorEarlier { tag } => write!(
                f,
                "BRDF sampler of an earlier format (its prior's {}): bake it again with `build-tool bake --brdf`",
                match tag {
                    10 => "tables unstretched",
                    15 => "metal layer in a stretched square",
                    _ => "shared layers in a square of one stretch",
                }
            ),
            Self::BrdfPriorInfoSize { got, expected } => write!(
                f,
                "blob BRDF prior info section is {got} bytes, not {expected}"
            ),
            Self::BrdfPriorElementSize { tag, size } => write!(
                f,
                "blob BRDF prior section {tag} has {size}-byte elements, not 4 (f32)"
            ),
            Self::BrdfPrior(e) => write!(f, "blob BRDF prior: {e}"),
        }
    }
}

impl core::error::Error for ConditionalError {}

/// Why [`write()`](super::write()) cannot write a blob.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WriteError {
    /// More sections than [`MAX_SECTIONS`](super::MAX_SECTIONS) (in a header, or given to [`write()`](super::write())).
    TooManySections {
        /// Sections declared or given.
        count: u64,
        /// [`MAX_SECTIONS`](super::MAX_SECTIONS).
        max: u32,
    },
    /// The sizes given to [`write()`](super::write()) overflow the blob's `u64` length.
    SizeOverflow,
    /// The output buffer passed to [`write()`](super::write()) has the wrong size.
    BufferSize {
        /// Bytes needed.
        needed: u64,
        /// Bytes given.
        got: u64,
    },
}

impl core::fmt::Display for WriteError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::TooManySections { count, max } => {
                write!(f, "blob has {count} sections, at most {max} allowed")
            }
            Self::SizeOverflow => write!(f, "blob size overflows u64"),
            Self::BufferSize { needed, got } => {
                write!(f, "output buffer has {got} bytes, blob needs {needed}")
            }
        }
    }
}

impl core::error::Error for WriteError {}
