//! The status codes: one per failed condition a C caller can act on, each with a
//! static message, and the process-wide last error.

use core::ffi::{c_char, CStr};
use core::sync::atomic::{AtomicI32, Ordering};
use nuld_runtime::{BlobError, ConditionalError, LayoutError};

/// The status every function returns: `NULD_OK` (0) or a negative code, one per
/// failed condition a caller can act on (`nuld_error_message` names each). The
/// functions return it as an `int32_t`.
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)] // the C names, as the header spells them
pub enum NuldStatus {
    /// Success.
    NULD_OK = 0,
    /// A pointer argument is null.
    NULD_ERR_NULL = -1,
    /// A pointer argument is not aligned for its type: blob bytes need 16 bytes,
    /// `NuldBlob` 8, floats, `NuldSample` and `NuldBlobInfo` 4 or 8 (their C
    /// alignment).
    NULD_ERR_MISALIGNED = -2,
    /// `len` exceeds `PTRDIFF_MAX`: no object is that long.
    NULD_ERR_TOO_LONG = -3,
    /// Fewer bytes than a blob header, or than the header's `total_len`.
    NULD_ERR_TRUNCATED = -4,
    /// More bytes than the header's `total_len`.
    NULD_ERR_TRAILING_BYTES = -5,
    /// Not a nuld blob: the first eight bytes are not the magic.
    NULD_ERR_BAD_MAGIC = -6,
    /// A blob format version this library does not read.
    NULD_ERR_UNSUPPORTED_VERSION = -7,
    /// The checksum does not match the bytes: the blob is corrupt.
    NULD_ERR_CHECKSUM = -8,
    /// The section table or the metadata bounds are inconsistent.
    NULD_ERR_LAYOUT = -9,
    /// The header names a blob kind this library does not know.
    NULD_ERR_UNKNOWN_KIND = -10,
    /// The metadata does not decode.
    NULD_ERR_METADATA = -11,
    /// A section the blob's kind needs is absent.
    NULD_ERR_MISSING_SECTION = -12,
    /// The sections of a point or direction set are inconsistent.
    NULD_ERR_POINT_SET = -13,
    /// The sections of a conditional sampler are inconsistent.
    NULD_ERR_CONDITIONAL = -14,
    /// An environment sampler of an earlier format, without the exact prior: bake
    /// it again (`build-tool bake --envmap`).
    NULD_ERR_ENVMAP_WITHOUT_PRIOR = -15,
    /// The blob holds another kind than the call serves (a point set asked for a
    /// sample, a sampler asked for a point).
    NULD_ERR_WRONG_KIND = -16,
    /// The sampler serves another target than the call (a BRDF sampler asked for an
    /// environment sample, or the reverse).
    NULD_ERR_WRONG_TARGET = -17,
    /// The `NuldBlob` was not filled by a successful `nuld_blob_parse` or
    /// `nuld_decode_network`.
    NULD_ERR_NOT_PARSED = -18,
    /// The buffer is shorter than the blob's `decoded_network_len`.
    NULD_ERR_BUFFER_TOO_SMALL = -19,
    /// `mode` is neither `NULD_MODE_TABLE` nor `NULD_MODE_NETWORK`.
    NULD_ERR_UNKNOWN_MODE = -20,
}

use NuldStatus::*;

/// The status of a runtime error: one per check a C caller can tell apart, the
/// other layout and section checks by their section.
pub(crate) fn of_blob_error(e: BlobError) -> NuldStatus {
    match e {
        BlobError::Layout(e) => match e {
            LayoutError::Truncated { .. } => NULD_ERR_TRUNCATED,
            LayoutError::Misaligned => NULD_ERR_MISALIGNED,
            LayoutError::BadMagic => NULD_ERR_BAD_MAGIC,
            LayoutError::UnsupportedVersion(_) => NULD_ERR_UNSUPPORTED_VERSION,
            LayoutError::TrailingBytes { .. } => NULD_ERR_TRAILING_BYTES,
            LayoutError::ChecksumMismatch { .. } => NULD_ERR_CHECKSUM,
            LayoutError::TooManySections { .. }
            | LayoutError::SectionTablePastEnd { .. }
            | LayoutError::MetadataOverlapsTable { .. }
            | LayoutError::MetadataPastEnd { .. }
            | LayoutError::SectionRangeOverflow { .. }
            | LayoutError::SectionOverlapsMetadata { .. }
            | LayoutError::SectionPastEnd { .. }
            | LayoutError::SectionMisaligned { .. }
            | LayoutError::ZeroElementSize { .. }
            | LayoutError::PartialElement { .. }
            | LayoutError::SectionsOverlap { .. } => NULD_ERR_LAYOUT,
        },
        BlobError::UnknownKind(_) => NULD_ERR_UNKNOWN_KIND,
        BlobError::BadMetadata => NULD_ERR_METADATA,
        BlobError::MissingSection(_) => NULD_ERR_MISSING_SECTION,
        BlobError::PointSet(_) => NULD_ERR_POINT_SET,
        BlobError::Conditional(ConditionalError::EnvmapWithoutPrior) => {
            NULD_ERR_ENVMAP_WITHOUT_PRIOR
        }
        BlobError::Conditional(_) => NULD_ERR_CONDITIONAL,
        BlobError::WrongKind { .. } => NULD_ERR_WRONG_KIND,
        BlobError::WrongTarget { .. } => NULD_ERR_WRONG_TARGET,
        // Only the writer returns it; a reader never does.
        BlobError::Write(_) => NULD_ERR_LAYOUT,
    }
}

impl NuldStatus {
    /// Every status, `NULD_OK` first, then the codes from -1 down.
    pub const ALL: [Self; 21] = [
        NULD_OK,
        NULD_ERR_NULL,
        NULD_ERR_MISALIGNED,
        NULD_ERR_TOO_LONG,
        NULD_ERR_TRUNCATED,
        NULD_ERR_TRAILING_BYTES,
        NULD_ERR_BAD_MAGIC,
        NULD_ERR_UNSUPPORTED_VERSION,
        NULD_ERR_CHECKSUM,
        NULD_ERR_LAYOUT,
        NULD_ERR_UNKNOWN_KIND,
        NULD_ERR_METADATA,
        NULD_ERR_MISSING_SECTION,
        NULD_ERR_POINT_SET,
        NULD_ERR_CONDITIONAL,
        NULD_ERR_ENVMAP_WITHOUT_PRIOR,
        NULD_ERR_WRONG_KIND,
        NULD_ERR_WRONG_TARGET,
        NULD_ERR_NOT_PARSED,
        NULD_ERR_BUFFER_TOO_SMALL,
        NULD_ERR_UNKNOWN_MODE,
    ];

    /// The status whose code is `code`, if any.
    pub fn from_code(code: i32) -> Option<Self> {
        Self::ALL.into_iter().find(|s| *s as i32 == code)
    }

    /// The static message of [`nuld_error_message`].
    pub fn message(self) -> &'static CStr {
        match self {
            NULD_OK => c"success",
            NULD_ERR_NULL => c"a pointer argument is null",
            NULD_ERR_MISALIGNED => {
                c"a pointer argument is misaligned for its type (blob bytes: 16 bytes)"
            }
            NULD_ERR_TOO_LONG => c"len exceeds PTRDIFF_MAX",
            NULD_ERR_TRUNCATED => c"blob truncated: fewer bytes than its header declares",
            NULD_ERR_TRAILING_BYTES => c"blob has more bytes than its header declares",
            NULD_ERR_BAD_MAGIC => c"not a nuld blob (bad magic)",
            NULD_ERR_UNSUPPORTED_VERSION => c"unsupported blob format version",
            NULD_ERR_CHECKSUM => c"blob checksum mismatch: the bytes are corrupt",
            NULD_ERR_LAYOUT => c"blob section table or metadata bounds are inconsistent",
            NULD_ERR_UNKNOWN_KIND => c"unknown blob kind",
            NULD_ERR_METADATA => c"blob metadata does not decode",
            NULD_ERR_MISSING_SECTION => c"blob lacks a section its kind needs",
            NULD_ERR_POINT_SET => c"blob point set sections are inconsistent",
            NULD_ERR_CONDITIONAL => c"blob conditional sampler sections are inconsistent",
            NULD_ERR_ENVMAP_WITHOUT_PRIOR => {
                c"environment sampler of an earlier format (no exact prior): bake it again"
            }
            NULD_ERR_WRONG_KIND => c"the blob holds another kind than this call serves",
            NULD_ERR_WRONG_TARGET => c"the sampler serves another target than this call",
            NULD_ERR_NOT_PARSED => c"the NuldBlob was not filled by a successful nuld_blob_parse",
            NULD_ERR_BUFFER_TOO_SMALL => c"buffer shorter than the blob's decoded_network_len",
            NULD_ERR_UNKNOWN_MODE => c"mode is neither NULD_MODE_TABLE nor NULD_MODE_NETWORK",
        }
    }
}

/// What [`nuld_error_message`] says of a code that is no [`NuldStatus`].
const UNKNOWN: &CStr = c"unknown nuld status code";

/// A static, NUL-terminated English message for `code`; a code this library
/// does not return reads "unknown nuld status code". Never null; the caller must
/// not free it. Thread-safe.
#[no_mangle]
pub extern "C" fn nuld_error_message(code: i32) -> *const c_char {
    NuldStatus::from_code(code)
        .map_or(UNKNOWN, NuldStatus::message)
        .as_ptr()
}

/// The most recent failure, process-wide.
static LAST_ERROR: AtomicI32 = AtomicI32::new(NULD_OK as i32);

/// The code of the most recent call of this library that failed, in any thread
/// of the process (like `errno`, a success leaves it as it was); `NULD_OK` if
/// none has failed yet. Each function also returns its own code, which is what
/// a multithreaded caller should read.
#[no_mangle]
pub extern "C" fn nuld_last_error() -> i32 {
    LAST_ERROR.load(Ordering::Relaxed)
}

/// The code a function returns for `result`: `NULD_OK`, or its error's code,
/// recorded as the last error.
pub(crate) fn status(result: Result<(), NuldStatus>) -> i32 {
    match result {
        Ok(()) => NULD_OK as i32,
        Err(e) => {
            let code = e as i32;
            LAST_ERROR.store(code, Ordering::Relaxed);
            code
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_code_has_a_message_of_its_own_and_others_read_unknown() {
        // SAFETY: the messages are static C strings.
        let text = |c| unsafe { CStr::from_ptr(nuld_error_message(c)) };
        for (k, s) in NuldStatus::ALL.into_iter().enumerate() {
            assert_eq!(s as i32, -(k as i32));
            assert_eq!(NuldStatus::from_code(s as i32), Some(s));
            let others = NuldStatus::ALL.into_iter().take(k);
            assert!(others.map(|o| text(o as i32)).all(|t| t != text(s as i32)));
            assert_ne!(text(s as i32), UNKNOWN);
        }
        for c in [1, -21, i32::MIN, i32::MAX] {
            assert_eq!(text(c), UNKNOWN);
        }
    }
}
