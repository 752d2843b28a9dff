//! An owned, 16-byte aligned byte buffer for blobs read at run time (feature `alloc`).
//!
//! `Blob::parse` borrows its bytes and requires a 16-byte aligned start, which a
//! `Vec<u8>` (alignment 1) does not promise. [`AlignedBuf`] is backed by 16-byte
//! blocks declared `align(16)` (not `u128`, whose alignment is 8 on some targets).

use alloc::vec;
use alloc::vec::Vec;

/// 16 bytes at a 16-byte aligned address; no padding, so any bytes are valid.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
struct Block([u8; 16]);

/// A heap byte buffer whose first byte is 16-byte aligned, as
/// [`crate::Blob::parse`] requires. Needs the `alloc` feature; [`AlignedBuf::read`]
/// needs `std`.
///
/// ```
/// # let example = nuld_runtime::doc_example_blob();
/// # let bytes_from_anywhere: &[u8] = &example.0;
/// use nuld_runtime::{AlignedBuf, Blob};
/// // e.g. bytes received over the network, at any alignment:
/// let buf = AlignedBuf::from_bytes(bytes_from_anywhere);
/// let blob = Blob::parse(buf.as_bytes())?;
/// assert_eq!(blob.point_set_2d()?.len(), 4);
/// # Ok::<(), nuld_runtime::BlobError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct AlignedBuf {
    blocks: Vec<Block>,
    len: usize,
}

impl AlignedBuf {
    /// A copy of `bytes` at a 16-byte aligned address. O(`bytes.len()`), one
    /// allocation of `bytes.len()` rounded up to 16 bytes.
    pub fn from_bytes(bytes: &[u8]) -> Self {
        let mut blocks = vec![Block([0; 16]); bytes.len().div_ceil(16)];
        let dst: &mut [u8] = bytemuck::cast_slice_mut(&mut blocks);
        // `dst.len()` is `bytes.len()` rounded up to 16, so the range is in bounds.
        dst[..bytes.len()].copy_from_slice(bytes);
        Self {
            blocks,
            len: bytes.len(),
        }
    }

    /// Reads the whole file at `path` into an aligned buffer (feature `std`).
    ///
    /// Errors as [`std::fs::read`] does (missing file, permissions, ...).
    ///
    /// ```no_run
    /// let buf = nuld_runtime::AlignedBuf::read("samples.nuld")?;
    /// assert!(nuld_runtime::Blob::parse(buf.as_bytes()).is_ok());
    /// # Ok::<(), std::io::Error>(())
    /// ```
    #[cfg(feature = "std")]
    pub fn read(path: impl AsRef<std::path::Path>) -> std::io::Result<Self> {
        std::fs::read(path).map(|bytes| Self::from_bytes(&bytes))
    }

    /// The bytes, starting at a 16-byte aligned address; `len()` of them.
    pub fn as_bytes(&self) -> &[u8] {
        // `len <= 16 * blocks.len()` by construction; `get` keeps this panic-free.
        let all: &[u8] = bytemuck::cast_slice(&self.blocks);
        all.get(..self.len).unwrap_or(all)
    }

    /// Number of bytes.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the buffer holds no bytes.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl AsRef<[u8]> for AlignedBuf {
    fn as_ref(&self) -> &[u8] {
        self.as_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_any_length_to_an_aligned_start() {
        // Source slices at every offset of a byte array, so most are misaligned.
        let src: Vec<u8> = (0..=255u8).collect();
        for start in 0..17 {
            for len in [0, 1, 15, 16, 17, 100] {
                let s = &src[start..start + len];
                let buf = AlignedBuf::from_bytes(s);
                assert_eq!(buf.as_bytes(), s);
                assert_eq!(buf.len(), len);
                assert_eq!(buf.as_bytes().as_ptr() as usize % 16, 0);
            }
        }
    }
}
