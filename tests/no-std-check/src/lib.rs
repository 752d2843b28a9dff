//! Proof that `nuld-runtime` needs neither `std` nor an allocator.
//!
//! A `#![no_std]` staticlib with its own `#[panic_handler]`, calling the runtime API.
//! Built with `cargo build -p nuld-no-std-check --profile nostd-check` (panic=abort):
//! if `std` sneaks into the dependency graph, rustc fails with E0152 (duplicate lang
//! item `panic_impl`); if `alloc` does, with "no global memory allocator found".
//! The features `leak-std` and `leak-alloc` plant such a leak on purpose, so the
//! test in `nuld-tests` can show the check catches it.
#![no_std]

#[cfg(feature = "leak-std")]
extern crate std;

#[cfg(feature = "leak-alloc")]
extern crate alloc;

use nuld_runtime::Blob;

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {}
}

/// Writes point `i` of set `set` of the 2D blob at `ptr..ptr+len` to `out[0..2]`.
/// Returns 0 on success, 1 if the blob does not parse or is not a 2D point set.
///
/// # Safety
/// `ptr` must be valid for `len` bytes and `out` for two `f32` writes.
#[no_mangle]
pub unsafe extern "C" fn nuld_check_point(
    ptr: *const u8,
    len: usize,
    set: u32,
    i: u32,
    out: *mut f32,
) -> i32 {
    let bytes = core::slice::from_raw_parts(ptr, len);
    match Blob::parse(bytes).and_then(|b| b.point_set_2d()) {
        Ok(pts) => {
            let p = pts.point(set as usize, i as usize);
            *out = p.x;
            *out.add(1) = p.y;
            0
        }
        Err(_) => 1,
    }
}

/// Writes direction `i` of set `set` of the direction blob to `out[0..3]`.
/// Returns 0 on success, 1 otherwise.
///
/// # Safety
/// `ptr` must be valid for `len` bytes and `out` for three `f32` writes.
#[no_mangle]
pub unsafe extern "C" fn nuld_check_direction(
    ptr: *const u8,
    len: usize,
    set: u32,
    i: u32,
    out: *mut f32,
) -> i32 {
    let bytes = core::slice::from_raw_parts(ptr, len);
    match Blob::parse(bytes).and_then(|b| b.direction_set()) {
        Ok(dirs) => {
            let d = dirs.direction(set as usize, i as usize);
            *out = d.x;
            *out.add(1) = d.y;
            *out.add(2) = d.z;
            0
        }
        Err(_) => 1,
    }
}

/// Writes sample `i` of instance `instance` of the conditional blob to
/// `out[0..4]` (direction, weight) in the given mode: 0 table mode at
/// `(c0, c1)`, 1 network mode at `(c0, c1)`, 2 `BrdfSampler::sample` with the
/// view `(c1, 0, 1)` and roughness `c0`, 3 `EnvmapSampler::sample` at the normal
/// `(c0, c1, 1)`, 4 network mode at `(c0, c1)` on weights decoded into a stack
/// buffer (`decode_network`). Returns 0 on success, 1 otherwise (also for a
/// network too large for the buffer in mode 4, and for a view of another target).
///
/// # Safety
/// `ptr` must be valid for `len` bytes and `out` for four `f32` writes.
#[no_mangle]
#[allow(clippy::too_many_arguments)] // a flat C signature
pub unsafe extern "C" fn nuld_check_conditional(
    ptr: *const u8,
    len: usize,
    mode: u32,
    c0: f32,
    c1: f32,
    instance: u32,
    i: u32,
    out: *mut f32,
) -> i32 {
    use nuld_runtime::glam::{Vec2, Vec3};
    let bytes = core::slice::from_raw_parts(ptr, len);
    match Blob::parse(bytes).and_then(|b| b.conditional()) {
        Ok(cs) => {
            let mut decoded = [0.0f32; 8192];
            let s = match mode {
                0 => cs.sample(Vec2::new(c0, c1), instance, i),
                1 => cs.network().sample(Vec2::new(c0, c1), instance, i),
                2 => match nuld_runtime::BrdfSampler::try_from(cs) {
                    Ok(brdf) => {
                        // The unbiased mode on the tabulated prior, and its pdf.
                        let wo = Vec3::new(c1, 0.0, 1.0);
                        let s = brdf.sample_randomized(wo, c0, c1, instance, i, instance ^ i);
                        let pdf = brdf.pdf(wo, c0, c1, s.direction);
                        nuld_runtime::Sample { pdf, ..s }
                    }
                    Err(_) => return 1,
                },
                4 => match cs.decode_network(&mut decoded) {
                    Some(fast) => fast.sample(Vec2::new(c0, c1), instance, i),
                    None => return 1,
                },
                _ => match nuld_runtime::EnvmapSampler::try_from(cs) {
                    Ok(env) => env.sample(Vec3::new(c0, c1, 1.0), instance, i),
                    Err(_) => return 1,
                },
            };
            *out = s.direction.x;
            *out.add(1) = s.direction.y;
            *out.add(2) = s.direction.z;
            *out.add(3) = s.weight;
            0
        }
        Err(_) => 1,
    }
}

/// Allocates, which a no-alloc build must refuse to link.
#[cfg(feature = "leak-alloc")]
#[no_mangle]
pub extern "C" fn nuld_check_leak_alloc(n: usize) -> usize {
    alloc::vec![0u8; n].len()
}
