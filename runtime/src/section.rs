//! Reading a blob's sections as typed values, once for every kind: a fixed-size
//! record (an info section) and a slice of elements. Each failed check is the
//! caller's own error variant, so a corruption is named by the section it hits.

use nuld_core::blob::{BlobError, Layout, LayoutError, SectionTag};

/// Section `tag` of `layout` as one `T`: the section exists and holds exactly
/// `size_of::<T>()` bytes (else `bad_size(got, expected)`, in bytes). Read
/// unaligned, so any `T: Pod` will do.
pub(crate) fn record<T: bytemuck::Pod, E: Into<BlobError>>(
    layout: &Layout<'_>,
    tag: SectionTag,
    bad_size: fn(u64, u64) -> E,
) -> Result<T, BlobError> {
    let (_, bytes) = layout.section(tag)?;
    let expected = core::mem::size_of::<T>();
    if bytes.len() != expected {
        return Err(bad_size(bytes.len() as u64, expected as u64).into());
    }
    Ok(bytemuck::pod_read_unaligned(bytes))
}

/// Section `tag` of `layout` as a slice of `T`, checked in this order: the section
/// exists; its `elem_size` is `size_of::<T>()` (else `bad_size(elem_size)`); it
/// holds exactly `expected()?` elements (else `bad_length(expected, got)`, in
/// elements); it is aligned for `T` (else [`LayoutError::Misaligned`], which an
/// aligned blob never gives: [`Layout::read`] checks that every section starts
/// 16-byte aligned and is a whole number of elements).
pub(crate) fn typed_section<'a, T: bytemuck::Pod, E: Into<BlobError>>(
    layout: &Layout<'a>,
    tag: SectionTag,
    bad_size: impl FnOnce(u32) -> E,
    expected: impl FnOnce() -> Result<u64, E>,
    bad_length: impl FnOnce(u64, u64) -> E,
) -> Result<&'a [T], BlobError> {
    let (entry, bytes) = layout.section(tag)?;
    let size = core::mem::size_of::<T>();
    if entry.elem_size as usize != size {
        return Err(bad_size(entry.elem_size).into());
    }
    let expected = expected().map_err(Into::into)?;
    let got = (bytes.len() / size) as u64;
    if got != expected {
        return Err(bad_length(expected, got).into());
    }
    bytemuck::try_cast_slice(bytes).map_err(|_| LayoutError::Misaligned.into())
}
