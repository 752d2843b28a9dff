//! 16-byte alignment for blobs embedded with `include_bytes!` (whose alignment is 1).

/// Wraps a value so that it starts at a 16-byte aligned address, as [`crate::Blob::parse`]
/// requires of its bytes.
///
/// ```
/// use nuld_runtime::Aligned;
/// static BYTES: &Aligned<[u8]> = &Aligned(*b"sixteen bytes!!!");
/// assert_eq!(BYTES.0.as_ptr() as usize % 16, 0);
/// ```
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Aligned<B: ?Sized>(pub B);

/// Embeds a blob file at compile time, 16-byte aligned, as a `&'static [u8]`.
///
/// The path is resolved like `include_bytes!`'s: relative to the file that invokes
/// the macro.
///
/// ```ignore
/// static SAMPLES: &[u8] = nuld_runtime::include_blob!("samples.nuld");
/// let blob = nuld_runtime::Blob::parse(SAMPLES)?;
/// ```
#[macro_export]
macro_rules! include_blob {
    ($path:expr) => {{
        static ALIGNED: &$crate::Aligned<[u8]> = &$crate::Aligned(*include_bytes!($path));
        &ALIGNED.0
    }};
}
