//! In-memory point sets and their `.nuld` encoding (through `nuld_core::blob`, the
//! one definition of the layout).

use anyhow::{bail, Context, Result};
use glam::DVec2;
use nuld_core::blob::{
    encoded_len, write, BlobKind, Domain, Metadata, PointSetInfo, SectionSpec, SectionTag,
};
use nuld_core::quantize::unorm16_encode;
use std::path::Path;

/// `sets.len()` sets of equally many points, each point in `[0,1]^2`: the point
/// itself for [`Domain::Square`], the equal-area square parameterization of a
/// direction otherwise.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSets {
    /// Where the points live.
    pub domain: Domain,
    /// The sets; all of the same, non-zero length.
    pub sets: Vec<Vec<DVec2>>,
}

impl PointSets {
    /// Points per set.
    pub fn len(&self) -> usize {
        self.sets.first().map_or(0, Vec::len)
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of sets.
    pub fn set_count(&self) -> usize {
        self.sets.len()
    }

    /// Encodes the sets as a blob: coordinates quantized to cell-centred u16 unorm.
    ///
    /// Fails if the sets are empty, ragged, or too large for u32 counts.
    pub fn to_blob(&self, meta: &Metadata<'_>) -> Result<AlignedBytes> {
        let len = self.len();
        if len == 0 || self.sets.iter().any(|s| s.len() != len) {
            bail!("point sets must be non-empty and of equal length");
        }
        let (n32, s32) = (u32::try_from(len)?, u32::try_from(self.set_count())?);
        let info = PointSetInfo {
            len: n32,
            set_count: s32,
            domain: self.domain as u32,
            reserved: 0,
        };
        let codes: Vec<[u16; 2]> = self
            .sets
            .iter()
            .flatten()
            .map(|p| [unorm16_encode(p.x), unorm16_encode(p.y)])
            .collect();
        let meta_bytes = postcard::to_allocvec(meta).context("cannot encode metadata")?;
        let sections = [
            SectionSpec {
                tag: SectionTag::PointSetInfo,
                elem_size: std::mem::size_of::<PointSetInfo>() as u32,
                bytes: bytemuck::bytes_of(&info),
            },
            SectionSpec {
                tag: SectionTag::Points,
                elem_size: 4,
                bytes: bytemuck::cast_slice(&codes),
            },
        ];
        let mut out = AlignedBytes::zeroed(encoded_len(&meta_bytes, &sections));
        let kind = match self.domain {
            Domain::Square => BlobKind::PointSet2D,
            _ => BlobKind::DirectionSet,
        };
        write(out.as_mut_slice(), kind, &meta_bytes, &sections)?;
        Ok(out)
    }

    /// Writes the blob to `path` atomically.
    pub fn write_blob(&self, path: &Path, meta: &Metadata<'_>) -> Result<()> {
        crate::output::write_atomic(path, self.to_blob(meta)?.as_slice())
    }
}

/// A heap byte buffer whose start is 16-byte aligned (backed by `u128`s), as
/// `nuld_runtime::Blob::parse` requires; `Vec<u8>` from `std::fs::read` is not.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AlignedBytes {
    words: Vec<u128>,
    len: usize,
}

impl AlignedBytes {
    /// `len` zero bytes.
    pub fn zeroed(len: usize) -> Self {
        Self {
            words: vec![0; len.div_ceil(16)],
            len,
        }
    }

    /// A copy of `bytes`, aligned.
    pub fn copy_from(bytes: &[u8]) -> Self {
        let mut out = Self::zeroed(bytes.len());
        out.as_mut_slice().copy_from_slice(bytes);
        out
    }

    /// Reads a whole file into an aligned buffer.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        Ok(Self::copy_from(&bytes))
    }

    /// The bytes.
    pub fn as_slice(&self) -> &[u8] {
        &bytemuck::cast_slice(&self.words)[..self.len]
    }

    /// The bytes, mutably.
    pub fn as_mut_slice(&mut self) -> &mut [u8] {
        &mut bytemuck::cast_slice_mut(&mut self.words)[..self.len]
    }
}
