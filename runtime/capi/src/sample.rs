//! Sampling a parsed blob: points and directions of a set, and the samplers'
//! directions with their weight and pdf in table mode, network mode and the
//! unbiased mode, and the pdf alone for multiple importance sampling.
//!
//! Each entry point reads its arguments, asks the stored view for one runtime
//! call and writes the result: the runtime's function of the same name is the
//! reference, bit for bit.

use crate::blob::{view, NuldBlob, View};
use crate::error::status;
use crate::error::NuldStatus::{self, NULD_ERR_UNKNOWN_MODE};
use crate::ptr::write;
use nuld_runtime::glam::{Vec2, Vec3};
use nuld_runtime::Sample;

/// `mode`: table mode, the stored points interpolated between the grid's
/// conditions (O(1), a few table reads).
pub const NULD_MODE_TABLE: u32 = 0;
/// `mode`: network mode, the trained network evaluated per sample (reads the
/// blob's f16 weights, or the floats of `nuld_decode_network`).
pub const NULD_MODE_NETWORK: u32 = 1;

/// A vector of three floats, passed by value (in registers on x86-64 System V
/// and AArch64: no memory the caller just wrote is read back).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NuldVec3 {
    /// x.
    pub x: f32,
    /// y.
    pub y: f32,
    /// z.
    pub z: f32,
}

/// A pair of floats, passed by value: a condition in the blob's units.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NuldVec2 {
    /// The first axis.
    pub x: f32,
    /// The second axis.
    pub y: f32,
}

impl From<NuldVec3> for Vec3 {
    #[inline(always)]
    fn from(v: NuldVec3) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl From<NuldVec2> for Vec2 {
    #[inline(always)]
    fn from(v: NuldVec2) -> Self {
        Vec2::new(v.x, v.y)
    }
}

/// One sample of a conditional sampler.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NuldSample {
    /// A unit direction: local frame (z = the normal) for a BRDF sampler, the
    /// map's world frame for an environment sampler.
    pub direction: [f32; 3],
    /// The estimator weight, finite and at least 0: for a BRDF sampler f cos /
    /// pdf of the direction (integral of L f cos ~ 1 / N times the sum of L
    /// weight; the albedo A for blobs of the earlier mixture prior), for an
    /// environment sampler the irradiance E(n) of every sample of the normal
    /// (~ E / N times the sum of f(direction)).
    pub weight: f32,
    /// The solid-angle density of the sampler's prior at `direction`, per
    /// steradian, finite and at least 0: exact (for L f cos / pdf and multiple
    /// importance sampling); 0 for BRDF blobs of the earlier mixture prior.
    pub pdf: f32,
}

impl From<Sample> for NuldSample {
    fn from(s: Sample) -> Self {
        Self {
            direction: s.direction.to_array(),
            weight: s.weight,
            pdf: s.pdf,
        }
    }
}

/// Table or network mode.
#[derive(Clone, Copy)]
enum Mode {
    Table,
    Network,
}

/// The mode of a `mode` argument, or [`NULD_ERR_UNKNOWN_MODE`].
fn mode(m: u32) -> Result<Mode, NuldStatus> {
    match m {
        NULD_MODE_TABLE => Ok(Mode::Table),
        NULD_MODE_NETWORK => Ok(Mode::Network),
        _ => Err(NULD_ERR_UNKNOWN_MODE),
    }
}

/// Writes point `index` of set `set` of a 2D point-set blob, in (0,1)^2, to
/// `out[0..2]`. Both indices wrap (set modulo S, index modulo N). O(1).
/// `NULD_ERR_WRONG_KIND` for any other blob.
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing 2 floats.
#[no_mangle]
pub unsafe extern "C" fn nuld_point_2d(
    blob: *const NuldBlob,
    set: u32,
    index: u32,
    out: *mut f32,
) -> i32 {
    // SAFETY: by the caller's contract.
    status(unsafe { view(blob) }.and_then(View::points).and_then(|p| {
        let v = p.point(set as usize, index as usize);
        // SAFETY: by the caller's contract.
        unsafe { write(out.cast::<[f32; 2]>(), v.to_array()) }
    }))
}

/// Writes direction `index` of set `set` of a direction-set blob, a unit vector
/// (z >= 0 on the hemisphere), to `out[0..3]`. Both indices wrap. O(1).
/// `NULD_ERR_WRONG_KIND` for any other blob.
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing 3 floats.
#[no_mangle]
pub unsafe extern "C" fn nuld_direction(
    blob: *const NuldBlob,
    set: u32,
    index: u32,
    out: *mut f32,
) -> i32 {
    // SAFETY: by the caller's contract.
    status(
        unsafe { view(blob) }
            .and_then(View::directions)
            .and_then(|d| {
                let v = d.direction(set as usize, index as usize);
                // SAFETY: by the caller's contract.
                unsafe { write(out.cast::<[f32; 3]>(), v.to_array()) }
            }),
    )
}

/// Sample `index` of instance `instance` of a BRDF sampler for the view `wo`
/// (local frame, z = the normal, any length) at `roughness` and `metallic`, in
/// `mode`, written to `*out`, with its pdf and the weight f cos / pdf. The
/// runtime's `BrdfSampler::sample`: roughness clamps into the blob's range,
/// metallic into [0, 1] (NaN to the lower ends), a view below the horizon reads
/// as grazing and a zero or non-finite one as normal incidence, index wraps
/// modulo N and table mode's instance modulo S. O(1) in table mode.
/// `NULD_ERR_WRONG_TARGET` for an environment sampler.
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing a `NuldSample`.
#[no_mangle]
pub unsafe extern "C" fn nuld_brdf_sample(
    blob: *const NuldBlob,
    mode: u32,
    wo: NuldVec3,
    roughness: f32,
    metallic: f32,
    instance: u32,
    index: u32,
    out: *mut NuldSample,
) -> i32 {
    let material = (roughness, metallic);
    // SAFETY: by the caller's contract (all three functions below).
    status(unsafe { brdf_sample(blob, mode, wo, material, (instance, index), None, out) })
}

/// The **unbiased mode** of `nuld_brdf_sample`: the blob's lattice point
/// `index` shifted on the torus by the instance's offset and by a random vector
/// drawn from `seed` (one random number per pixel), through the prior, so that
/// every sample is distributed exactly as its `pdf`; `mode` is checked but both
/// modes give the same samples (no table or network is read). The runtime's
/// `BrdfSampler::sample_randomized`.
///
/// # Safety
/// As `nuld_brdf_sample`.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn nuld_brdf_sample_randomized(
    blob: *const NuldBlob,
    mode: u32,
    wo: NuldVec3,
    roughness: f32,
    metallic: f32,
    instance: u32,
    index: u32,
    seed: u32,
    out: *mut NuldSample,
) -> i32 {
    let material = (roughness, metallic);
    // SAFETY: by the caller's contract.
    status(unsafe { brdf_sample(blob, mode, wo, material, (instance, index), Some(seed), out) })
}

/// The body of both BRDF entry points, randomized with `seed` if any.
///
/// # Safety
/// As [`nuld_brdf_sample`].
unsafe fn brdf_sample(
    blob: *const NuldBlob,
    m: u32,
    wo: NuldVec3,
    (roughness, metallic): (f32, f32),
    (instance, index): (u32, u32),
    seed: Option<u32>,
    out: *mut NuldSample,
) -> Result<(), NuldStatus> {
    // SAFETY: by the caller's contract.
    let brdf = unsafe { view(blob)?.brdf()? };
    let wo = Vec3::from(wo);
    let (r, mt) = (roughness, metallic);
    let s = match (mode(m)?, seed) {
        (Mode::Table, None) => brdf.sample(wo, r, mt, instance, index),
        (Mode::Table, Some(x)) => brdf.sample_randomized(wo, r, mt, instance, index, x),
        (Mode::Network, None) => brdf.network().sample(wo, r, mt, instance, index),
        (Mode::Network, Some(x)) => brdf
            .network()
            .sample_randomized(wo, r, mt, instance, index, x),
    };
    // SAFETY: by the caller's contract.
    unsafe { write(out, s.into()) }
}

/// The solid-angle density of a BRDF sampler's prior at the unit local
/// `direction` for the view `wo`, `roughness` and `metallic`, written to
/// `*out`: what `NuldSample::pdf` is for a sample there, for any direction
/// (multiple importance sampling); both modes share it; 0 below the horizon and
/// for blobs of the earlier mixture prior. The runtime's `BrdfSampler::pdf`.
/// `NULD_ERR_WRONG_TARGET` for an environment sampler.
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing a float.
#[no_mangle]
pub unsafe extern "C" fn nuld_brdf_pdf(
    blob: *const NuldBlob,
    wo: NuldVec3,
    roughness: f32,
    metallic: f32,
    direction: NuldVec3,
    out: *mut f32,
) -> i32 {
    // SAFETY: by the caller's contract.
    status(unsafe { view(blob) }.and_then(View::brdf).and_then(|brdf| {
        let pdf = brdf.pdf(wo.into(), roughness, metallic, direction.into());
        // SAFETY: by the caller's contract.
        unsafe { write(out, pdf) }
    }))
}

/// Sample `index` of instance `instance` of an environment sampler at the surface
/// normal `normal` (the map's world frame, +z up, any length), in `mode`,
/// written to `*out`: the runtime's `EnvmapSampler::sample`, with the prior's
/// exact pdf. A zero or non-finite normal reads as +z; index wraps modulo N, table
/// mode's instance modulo S. O(1) in table mode. `NULD_ERR_WRONG_TARGET` for a
/// BRDF sampler.
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing a `NuldSample`.
#[no_mangle]
pub unsafe extern "C" fn nuld_envmap_sample(
    blob: *const NuldBlob,
    mode: u32,
    normal: NuldVec3,
    instance: u32,
    index: u32,
    out: *mut NuldSample,
) -> i32 {
    // SAFETY: by the caller's contract.
    status(unsafe { envmap_sample(blob, mode, normal, instance, index, None, out) })
}

/// The **unbiased mode** of `nuld_envmap_sample`: the blob's lattice point
/// `index` shifted on the torus by the instance's offset and by a random vector
/// drawn from `seed` (one random number per pixel), through the prior, so that
/// every sample is distributed exactly as its `pdf` and L f cos / pdf is
/// unbiased; both modes give the same samples. The runtime's
/// `EnvmapSampler::sample_randomized`.
///
/// # Safety
/// As `nuld_envmap_sample`.
#[no_mangle]
pub unsafe extern "C" fn nuld_envmap_sample_randomized(
    blob: *const NuldBlob,
    mode: u32,
    normal: NuldVec3,
    instance: u32,
    index: u32,
    seed: u32,
    out: *mut NuldSample,
) -> i32 {
    // SAFETY: by the caller's contract.
    status(unsafe { envmap_sample(blob, mode, normal, instance, index, Some(seed), out) })
}

/// The body of both environment entry points, randomized with `seed` if any.
///
/// # Safety
/// As [`nuld_envmap_sample`].
unsafe fn envmap_sample(
    blob: *const NuldBlob,
    m: u32,
    normal: NuldVec3,
    instance: u32,
    index: u32,
    seed: Option<u32>,
    out: *mut NuldSample,
) -> Result<(), NuldStatus> {
    // SAFETY: by the caller's contract.
    let env = unsafe { view(blob)?.envmap()? };
    let n = Vec3::from(normal);
    let s = match (mode(m)?, seed) {
        (Mode::Table, None) => env.sample(n, instance, index),
        (Mode::Table, Some(r)) => env.sample_randomized(n, instance, index, r),
        (Mode::Network, None) => env.network().sample(n, instance, index),
        (Mode::Network, Some(r)) => env.network().sample_randomized(n, instance, index, r),
    };
    // SAFETY: by the caller's contract.
    unsafe { write(out, s.into()) }
}

/// The solid-angle density of an environment sampler's prior at the unit
/// `direction` for the normal `normal`, written to `*out`: what
/// `NuldSample::pdf` is for a sample there, for any direction (multiple
/// importance sampling); both modes share it. O(tree levels). The runtime's
/// `EnvmapSampler::pdf`. `NULD_ERR_WRONG_TARGET` for a BRDF sampler.
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing a float.
#[no_mangle]
pub unsafe extern "C" fn nuld_envmap_pdf(
    blob: *const NuldBlob,
    normal: NuldVec3,
    direction: NuldVec3,
    out: *mut f32,
) -> i32 {
    // SAFETY: by the caller's contract.
    status(
        unsafe { view(blob) }
            .and_then(View::envmap)
            .and_then(|env| {
                let pdf = env.pdf(normal.into(), direction.into());
                // SAFETY: by the caller's contract.
                unsafe { write(out, pdf) }
            }),
    )
}

/// Sample `index` of instance `instance` of either sampler at the condition
/// `cond` in the blob's units (`NuldBlobInfo::cond_min` to `cond_max`;
/// for a BRDF sampler roughness and view angle in degrees, the view in the
/// xz-plane on the +x side; for an environment sampler the normal's octahedral
/// square point) and, for a BRDF sampler, `metallic` (ignored by environment
/// samplers), in `mode`, written to `*out`: the runtime's
/// `ConditionalSampler::sample_metallic`, what `build-tool sample --cond
/// A,B,METALLIC` prints. For tools; renderers use `nuld_brdf_sample` and
/// `nuld_envmap_sample`. The condition clamps into the range, metallic into [0,
/// 1] (NaN to the lower ends). O(1) in table mode.
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing a `NuldSample`.
#[no_mangle]
pub unsafe extern "C" fn nuld_conditional_sample(
    blob: *const NuldBlob,
    mode: u32,
    cond: NuldVec2,
    metallic: f32,
    instance: u32,
    index: u32,
    out: *mut NuldSample,
) -> i32 {
    let at = (cond, metallic);
    // SAFETY: by the caller's contract.
    status(unsafe { conditional_sample(blob, mode, at, instance, index, None, out) })
}

/// The unbiased mode of `nuld_conditional_sample` (as
/// `nuld_envmap_sample_randomized`):
/// `ConditionalSampler::sample_randomized_metallic`, what `build-tool sample
/// --cond C --randomize SEED` prints.
///
/// # Safety
/// As `nuld_conditional_sample`.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn nuld_conditional_sample_randomized(
    blob: *const NuldBlob,
    mode: u32,
    cond: NuldVec2,
    metallic: f32,
    instance: u32,
    index: u32,
    seed: u32,
    out: *mut NuldSample,
) -> i32 {
    let at = (cond, metallic);
    // SAFETY: by the caller's contract.
    status(unsafe { conditional_sample(blob, mode, at, instance, index, Some(seed), out) })
}

/// The body of both conditional entry points, randomized with `seed` if any.
///
/// # Safety
/// As [`nuld_conditional_sample`].
unsafe fn conditional_sample(
    blob: *const NuldBlob,
    m: u32,
    (cond, metallic): (NuldVec2, f32),
    instance: u32,
    index: u32,
    seed: Option<u32>,
    out: *mut NuldSample,
) -> Result<(), NuldStatus> {
    // SAFETY: by the caller's contract.
    let cs = unsafe { view(blob)?.conditional()? };
    let (c, mt) = (Vec2::from(cond), metallic);
    let s = match (mode(m)?, seed) {
        (Mode::Table, None) => cs.sample_metallic(c, mt, instance, index),
        (Mode::Table, Some(r)) => cs.sample_randomized_metallic(c, mt, instance, index, r),
        (Mode::Network, None) => cs.network().sample_metallic(c, mt, instance, index),
        (Mode::Network, Some(r)) => cs
            .network()
            .sample_randomized_metallic(c, mt, instance, index, r),
    };
    // SAFETY: by the caller's contract.
    unsafe { write(out, s.into()) }
}

/// The prior's pdf at the unit `direction` for the condition `cond` (blob
/// units) of either sampler and, for a BRDF sampler, `metallic`, written to
/// `*out`: the runtime's `ConditionalSampler::pdf_metallic` (0 for BRDF blobs
/// of the earlier mixture prior).
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing a float.
#[no_mangle]
pub unsafe extern "C" fn nuld_conditional_pdf(
    blob: *const NuldBlob,
    cond: NuldVec2,
    metallic: f32,
    direction: NuldVec3,
    out: *mut f32,
) -> i32 {
    // SAFETY: by the caller's contract.
    status(
        unsafe { view(blob) }
            .and_then(View::conditional)
            .and_then(|cs| {
                let pdf = cs.pdf_metallic(cond.into(), metallic, direction.into());
                // SAFETY: by the caller's contract.
                unsafe { write(out, pdf) }
            }),
    )
}
