//! Writing a blob: [`write()`] fills a caller-provided buffer of [`encoded_len`]
//! bytes, so that the tool and any other writer place sections the way
//! [`Layout::read`](super::Layout::read) expects.

use super::checksum;
use super::{
    BlobKind, Header, SectionEntry, SectionTag, WriteError, ALIGN, FORMAT_VERSION, HEADER_LEN,
    MAGIC, MAX_SECTIONS, SECTION_ENTRY_LEN,
};

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
) -> Result<Header, WriteError> {
    if sections.len() > MAX_SECTIONS as usize {
        return Err(WriteError::TooManySections {
            count: sections.len() as u64,
            max: MAX_SECTIONS,
        });
    }
    let (table_end, total) = plan(meta.len(), sections).ok_or(WriteError::SizeOverflow)?;
    if out.len() as u64 != total {
        return Err(WriteError::BufferSize {
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
