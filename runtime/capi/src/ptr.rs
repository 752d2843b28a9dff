//! Checked writes through the caller's pointers (the results; vectors come in by
//! value): null and misaligned pointers are errors, never dereferenced.

use crate::error::NuldStatus::{self, NULD_ERR_MISALIGNED, NULD_ERR_NULL};

/// `Ok` if `p` may be dereferenced as far as this library can tell: non-null and
/// aligned for `T`.
pub(crate) fn check<T>(p: *const T) -> Result<(), NuldStatus> {
    if p.is_null() {
        Err(NULD_ERR_NULL)
    } else if !p.is_aligned() {
        Err(NULD_ERR_MISALIGNED)
    } else {
        Ok(())
    }
}

/// Writes `value` to `p`.
///
/// # Safety
/// A non-null, aligned `p` must be valid for writing a `T`.
pub(crate) unsafe fn write<T>(p: *mut T, value: T) -> Result<(), NuldStatus> {
    check(p)?;
    // SAFETY: non-null and aligned (checked), valid by the caller's contract.
    unsafe { p.write(value) };
    Ok(())
}
