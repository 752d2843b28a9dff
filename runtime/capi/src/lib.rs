//! # nuld-capi
//!
//! The C ABI of [`nuld_runtime`], for C and C++ renderers: the static library
//! `libnuld_capi.a`, the dynamic library `libnuld_capi.so` and the header
//! `runtime/capi/include/nuld.h`, which cbindgen generates from this crate (the
//! doc comments here are the header's). The contract, in short
//! (`docs/design/capi.md` says it in full):
//!
//! * **Bytes.** [`nuld_blob_parse`] validates caller-owned bytes once and fills a
//!   caller-allocated [`NuldBlob`] that borrows them: no copy, no allocation. The
//!   bytes start at a 16-byte aligned address and stay alive and unchanged while
//!   any `NuldBlob` filled from them is used.
//! * **Calls.** Every function returns `NULD_OK` (0) or a negative `NULD_ERR_*`
//!   code ([`NuldStatus`]) and writes its results through out pointers, only on
//!   success; vectors come in by value. Null and misaligned pointers are errors
//!   (`NULD_ERR_NULL`, `NULD_ERR_MISALIGNED`), as is a `NuldBlob` no successful
//!   parse filled (`NULD_ERR_NOT_PARSED`). [`nuld_error_message`] names a code;
//!   [`nuld_last_error`] is the most recent failure of the process.
//! * **Threads.** A parsed `NuldBlob` is read-only: any number of threads may
//!   sample it at once. Nothing is global but the last-error code.
//!
//! **No panic crosses the boundary.** The runtime never panics on any input (its
//! hostile-input tests run with overflow checks on); this layer adds none: no
//! indexing, no unwrap, no arithmetic that can overflow, which the lints below hold
//! it to. Were a panic reached all the same, it would abort the process, never
//! unwind into C: the functions are `extern "C"`, which cannot unwind, and the
//! freestanding build's panic handler calls `abort`.
#![no_std]
#![deny(missing_docs, unsafe_op_in_unsafe_fn)]
#![deny(
    clippy::indexing_slicing,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented,
    clippy::arithmetic_side_effects,
    clippy::undocumented_unsafe_blocks
)]

// With the `std` feature (every workspace build) std brings its panic runtime;
// without it (the freestanding libraries) the handler below is the crate's own.
// The two cannot coexist: an rlib carrying this handler, linked into a std
// binary, would define `panic_impl` twice (E0152). Unit tests link std too.
#[cfg(feature = "std")]
extern crate std;

mod blob;
mod error;
mod ptr;
mod sample;

pub use blob::{
    nuld_blob_info, nuld_blob_parse, nuld_decode_network, NuldBlob, NuldBlobInfo, NULD_BLOB_WORDS,
    NULD_DOMAIN_HEMISPHERE, NULD_DOMAIN_SPHERE, NULD_DOMAIN_SQUARE, NULD_KIND_CONDITIONAL,
    NULD_KIND_DIRECTION_SET, NULD_KIND_POINT_SET_2D, NULD_TARGET_ENVMAP, NULD_TARGET_GLTF_BRDF,
    NULD_TARGET_NONE,
};
pub use error::{nuld_error_message, nuld_last_error, NuldStatus};
pub use sample::{
    nuld_brdf_pdf, nuld_brdf_sample, nuld_brdf_sample_randomized, nuld_conditional_pdf,
    nuld_conditional_sample, nuld_conditional_sample_randomized, nuld_direction, nuld_envmap_pdf,
    nuld_envmap_sample, nuld_envmap_sample_randomized, nuld_point_2d, NuldSample, NuldVec2,
    NuldVec3, NULD_MODE_NETWORK, NULD_MODE_TABLE,
};

/// The freestanding libraries' panic handler. No panic is reachable (crate docs);
/// should one be reached all the same, the process aborts as a failed C `assert`
/// would, through the C library's `abort`, which every program that links these
/// libraries has.
#[cfg(not(any(feature = "std", test)))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    extern "C" {
        fn abort() -> !;
    }
    // SAFETY: `abort` takes nothing and does not return.
    unsafe { abort() }
}

/// The personality routine an unwinding panic would call. The precompiled `core`
/// is built for unwinding and refers to it, so the freestanding libraries define
/// it to link (else `libnuld_capi.so` would not load and the static library would
/// not link); under their `panic = "abort"` nothing unwinds, and it is never
/// called. With std, std defines it.
#[cfg(not(any(feature = "std", test)))]
#[no_mangle]
extern "C" fn rust_eh_personality() {}
