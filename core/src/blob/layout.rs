//! Reading a blob: [`Layout::read`] validates the header, checksum, metadata bounds
//! and section table once, without allocating; [`Layout::section`] then finds a
//! section's bytes.

use super::{
    BlobError, Header, LayoutError, Metadata, SectionEntry, SectionTag, ALIGN, CHECKSUM_OFFSET,
    FORMAT_VERSION, HEADER_LEN, MAGIC, MAX_SECTIONS, SECTION_ENTRY_LEN,
};
use bytemuck::Zeroable;

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
    /// The kind is not checked against the known kinds here; see [`BlobKind`](super::BlobKind).
    pub fn read(bytes: &'a [u8]) -> Result<Self, LayoutError> {
        let got = bytes.len() as u64;
        if bytes.len() < HEADER_LEN {
            return Err(LayoutError::Truncated {
                needed: HEADER_LEN as u64,
                got,
            });
        }
        if bytes.as_ptr() as usize % ALIGN != 0 {
            return Err(LayoutError::Misaligned);
        }
        let header: Header = bytemuck::pod_read_unaligned(&bytes[..HEADER_LEN]);
        if header.magic != MAGIC {
            return Err(LayoutError::BadMagic);
        }
        if header.version != FORMAT_VERSION {
            return Err(LayoutError::UnsupportedVersion(header.version));
        }
        if header.total_len > got {
            return Err(LayoutError::Truncated {
                needed: header.total_len,
                got,
            });
        }
        if header.total_len < got {
            return Err(LayoutError::TrailingBytes {
                declared: header.total_len,
                got,
            });
        }
        let computed = checksum(bytes);
        if computed != header.checksum {
            return Err(LayoutError::ChecksumMismatch {
                stored: header.checksum,
                computed,
            });
        }
        if header.section_count > MAX_SECTIONS {
            return Err(LayoutError::TooManySections {
                count: header.section_count as u64,
                max: MAX_SECTIONS,
            });
        }
        let table_end = HEADER_LEN as u64 + header.section_count as u64 * SECTION_ENTRY_LEN as u64;
        if table_end > got {
            return Err(LayoutError::SectionTablePastEnd {
                table_end,
                len: got,
            });
        }
        let meta_offset = header.meta_offset as u64;
        let meta_end = meta_offset + header.meta_len as u64;
        if meta_offset < table_end {
            return Err(LayoutError::MetadataOverlapsTable {
                meta_offset,
                table_end,
            });
        }
        if meta_end > got {
            return Err(LayoutError::MetadataPastEnd { meta_end, len: got });
        }
        let layout = Self { bytes, header };
        // `k < section_count <= MAX_SECTIONS`, so the row index fits a u32.
        for k in 0..header.section_count {
            let e = layout.entry(k as usize);
            let end = e
                .offset
                .checked_add(e.len)
                .ok_or(LayoutError::SectionRangeOverflow { index: k })?;
            if e.offset < meta_end {
                return Err(LayoutError::SectionOverlapsMetadata {
                    index: k,
                    offset: e.offset,
                    meta_end,
                });
            }
            if end > got {
                return Err(LayoutError::SectionPastEnd {
                    index: k,
                    end,
                    len: got,
                });
            }
            if e.offset % ALIGN as u64 != 0 {
                return Err(LayoutError::SectionMisaligned {
                    index: k,
                    offset: e.offset,
                });
            }
            if e.elem_size == 0 {
                return Err(LayoutError::ZeroElementSize { index: k });
            }
            if e.len % e.elem_size as u64 != 0 {
                return Err(LayoutError::PartialElement {
                    index: k,
                    len: e.len,
                    elem_size: e.elem_size,
                });
            }
            for j in 0..k {
                let o = layout.entry(j as usize);
                if e.offset < o.offset + o.len && o.offset < end {
                    return Err(LayoutError::SectionsOverlap {
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
                let bytes =
                    self.bytes
                        .get(e.offset as usize..end as usize)
                        .ok_or(BlobError::Layout(LayoutError::SectionPastEnd {
                            index: k,
                            end,
                            len: self.bytes.len() as u64,
                        }))?;
                return Ok((e, bytes));
            }
        }
        Err(BlobError::MissingSection(tag))
    }
}
