//! In-memory point sets and their `.nuld` encoding (through `nuld_core::blob`, the
//! one definition of the layout).

use anyhow::{bail, Context, Result};
use glam::DVec2;
use nuld_core::blob::{
    encoded_len, write, BlobKind, Domain, Metadata, PointSetInfo, SectionSpec, SectionTag,
};
use nuld_core::quantize::{unorm16_decode_f64, unorm16_encode};
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

    /// The sets as a blob stores them: each coordinate moved to the centre of its
    /// u16 cell, `unorm16_decode_f64(unorm16_encode(x))` (at most 2^-17 away), which
    /// is what [`PointSets::from_blob`] reads back from [`PointSets::to_blob`].
    pub fn quantized(&self) -> PointSets {
        let cell = |x: f64| unorm16_decode_f64(unorm16_encode(x));
        PointSets {
            domain: self.domain,
            sets: self
                .sets
                .iter()
                .map(|s| s.iter().map(|p| DVec2::new(cell(p.x), cell(p.y))).collect())
                .collect(),
        }
    }

    /// The sets of a parsed blob, decoded exactly in `f64` (directions as their
    /// square parameterization, the stored form).
    pub fn from_blob(blob: &nuld_runtime::Blob<'_>) -> Result<PointSets> {
        let (domain, square) = match blob.kind() {
            BlobKind::PointSet2D => (Domain::Square, blob.point_set_2d()),
            BlobKind::DirectionSet => {
                let dirs = blob.direction_set();
                (
                    dirs.as_ref().map_or(Domain::Sphere, |d| d.domain()),
                    dirs.map(|d| d.square_points()),
                )
            }
            BlobKind::Conditional => {
                bail!("the blob holds a conditional sampler, not point sets (use `sample`)")
            }
        };
        let square = square.map_err(|e| anyhow::anyhow!("{e}"))?;
        let decode = |[x, y]: [u16; 2]| DVec2::new(unorm16_decode_f64(x), unorm16_decode_f64(y));
        Ok(PointSets {
            domain,
            sets: (0..square.set_count())
                .map(|s| {
                    (0..square.len())
                        .map(|i| decode(square.raw(s, i)))
                        .collect()
                })
                .collect(),
        })
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

#[cfg(test)]
mod tests {
    use super::*;
    use nuld_runtime::Blob;

    #[test]
    fn a_blob_reads_back_as_the_quantized_sets() {
        let meta = Metadata {
            generator: "test",
            target: "uniform",
            seed: 0,
        };
        for domain in [Domain::Square, Domain::Sphere, Domain::Hemisphere] {
            let ps = PointSets {
                domain,
                sets: (0..3)
                    .map(|s| {
                        (0..5)
                            .map(|i| DVec2::new(0.17 * i as f64 + 0.01 * s as f64, 0.999_999))
                            .collect()
                    })
                    .collect(),
            };
            let bytes = ps.to_blob(&meta).unwrap();
            let blob = Blob::parse(bytes.as_slice()).unwrap();
            let read = PointSets::from_blob(&blob).unwrap();
            let stored = ps.quantized();
            assert_eq!(read, stored, "{domain:?}");
            // Within half a u16 cell of the input, and what the runtime decodes.
            let square = match domain {
                Domain::Square => blob.point_set_2d().unwrap(),
                _ => blob.direction_set().unwrap().square_points(),
            };
            for (s, set) in stored.sets.iter().enumerate() {
                for (i, p) in set.iter().enumerate() {
                    assert!((*p - ps.sets[s][i]).abs().max_element() <= 0.5 / 65536.0);
                    assert_eq!(*p, square.point(s, i).as_dvec2());
                }
            }
        }
    }
}
