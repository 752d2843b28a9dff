//! `NuldBlob`: a parsed blob in caller-allocated storage, and what can be asked
//! of it before sampling (its kind and sizes, a decoded network).

use crate::error::NuldStatus::{
    self, NULD_ERR_BUFFER_TOO_SMALL, NULD_ERR_NOT_PARSED, NULD_ERR_TOO_LONG, NULD_ERR_WRONG_KIND,
    NULD_ERR_WRONG_TARGET,
};
use crate::error::{of_blob_error, status};
use crate::ptr::{check, write};
use nuld_runtime::{
    Blob, BlobKind, BrdfSampler, ConditionalSampler, DirectionSet, EnvmapSampler, PointSet2D,
};

/// Words of private storage in a `NuldBlob` (room for the views of later
/// versions: the struct's size is part of the ABI).
pub const NULD_BLOB_WORDS: usize = 64;

/// A parsed blob: caller-allocated (on the stack, in a struct, anywhere 8-byte
/// aligned), filled by `nuld_blob_parse`, read by every other function. It
/// borrows the parsed bytes, which must outlive it unchanged; it owns nothing,
/// needs no release, and may be copied by value (`memcpy`, assignment) within
/// the process. Its contents are private to the library that filled it.
#[repr(C)]
pub struct NuldBlob {
    /// Private: whether a parse filled the struct.
    state: u64,
    /// Private: the parsed view, read by this library only.
    view: [u64; NULD_BLOB_WORDS],
}

/// [`NuldBlob::state`] of a filled blob ("nuldblob" in ASCII).
const FILLED: u64 = u64::from_le_bytes(*b"nuldblob");

/// The runtime view a [`NuldBlob`] stores: one per thing a blob can hold. The
/// `'static` is the caller's promise that the bytes outlive the `NuldBlob`; a
/// `View` never leaves the call that reads it.
#[derive(Clone, Copy)]
pub(crate) enum View {
    /// [`BlobKind::PointSet2D`].
    Points(PointSet2D<'static>),
    /// [`BlobKind::DirectionSet`].
    Directions(DirectionSet<'static>),
    /// A BRDF sampler (its network possibly decoded into a caller's buffer).
    Brdf(BrdfSampler<'static>),
    /// An environment-map sampler.
    Envmap(EnvmapSampler<'static>),
}

// The view fits the storage the header declares, at its alignment.
const _: () =
    assert!(core::mem::size_of::<View>() <= core::mem::size_of::<[u64; NULD_BLOB_WORDS]>());
const _: () = assert!(core::mem::align_of::<View>() <= core::mem::align_of::<u64>());

impl View {
    /// The point sets, or [`NULD_ERR_WRONG_KIND`].
    pub(crate) fn points(&self) -> Result<&PointSet2D<'static>, NuldStatus> {
        match self {
            Self::Points(p) => Ok(p),
            _ => Err(NULD_ERR_WRONG_KIND),
        }
    }

    /// The direction sets, or [`NULD_ERR_WRONG_KIND`].
    pub(crate) fn directions(&self) -> Result<&DirectionSet<'static>, NuldStatus> {
        match self {
            Self::Directions(d) => Ok(d),
            _ => Err(NULD_ERR_WRONG_KIND),
        }
    }

    /// The BRDF sampler, or [`NULD_ERR_WRONG_KIND`] for a point set and
    /// [`NULD_ERR_WRONG_TARGET`] for an environment sampler.
    pub(crate) fn brdf(&self) -> Result<&BrdfSampler<'static>, NuldStatus> {
        match self {
            Self::Brdf(b) => Ok(b),
            Self::Envmap(_) => Err(NULD_ERR_WRONG_TARGET),
            _ => Err(NULD_ERR_WRONG_KIND),
        }
    }

    /// The environment sampler, or the error [`Self::brdf`] gives the other way.
    pub(crate) fn envmap(&self) -> Result<&EnvmapSampler<'static>, NuldStatus> {
        match self {
            Self::Envmap(e) => Ok(e),
            Self::Brdf(_) => Err(NULD_ERR_WRONG_TARGET),
            _ => Err(NULD_ERR_WRONG_KIND),
        }
    }

    /// Either sampler, target-agnostic, or [`NULD_ERR_WRONG_KIND`].
    pub(crate) fn conditional(&self) -> Result<ConditionalSampler<'static>, NuldStatus> {
        match self {
            Self::Brdf(b) => Ok(b.conditional()),
            Self::Envmap(e) => Ok(e.conditional()),
            _ => Err(NULD_ERR_WRONG_KIND),
        }
    }
}

/// The view stored in `blob`.
///
/// # Safety
/// A non-null, aligned `blob` must point to a `NuldBlob` (any contents: an
/// unfilled one is refused), and the bytes of a filled one must be alive.
pub(crate) unsafe fn view<'b>(blob: *const NuldBlob) -> Result<&'b View, NuldStatus> {
    check(blob)?;
    // SAFETY: non-null and aligned (checked), a `NuldBlob` by the caller's contract.
    let blob = unsafe { &*blob };
    if blob.state != FILLED {
        return Err(NULD_ERR_NOT_PARSED);
    }
    // SAFETY: only `store` sets `state` to FILLED, after writing a `View` to
    // `view`, which is large and aligned enough (asserted above); copies of the
    // struct copy the view's bytes with it, and a `View` is `Copy`.
    Ok(unsafe { &*blob.view.as_ptr().cast::<View>() })
}

/// Writes `v` into `out` and marks it filled.
///
/// # Safety
/// `out` must be non-null, aligned and valid for writing a `NuldBlob` (checked by
/// the callers before any work).
unsafe fn store(out: *mut NuldBlob, v: View) {
    let mut blob = NuldBlob {
        state: FILLED,
        view: [0; NULD_BLOB_WORDS],
    };
    // SAFETY: the storage is large and aligned enough for a `View` (asserted).
    unsafe { blob.view.as_mut_ptr().cast::<View>().write(v) };
    // SAFETY: by this function's contract.
    unsafe { out.write(blob) };
}

/// Marks `out` not parsed.
///
/// # Safety
/// As [`store`].
unsafe fn clear(out: *mut NuldBlob) {
    // SAFETY: by this function's contract.
    unsafe {
        out.write(NuldBlob {
            state: 0,
            view: [0; NULD_BLOB_WORDS],
        })
    };
}

/// Validates the `len` bytes at `bytes` as a nuld blob and fills `*out` with a
/// view on them; returns `NULD_OK` or the code of the first check that failed
/// (`*out` is then marked not parsed, so that using it fails with
/// `NULD_ERR_NOT_PARSED`).
///
/// Checks, in order, as `Blob::parse` of the Rust runtime: length, 16-byte
/// alignment of `bytes`, magic, version, declared length, checksum (FNV-1a 64 of
/// every byte), section table, metadata, kind, and the kind's sections. O(len),
/// once; every later call is O(1) in the blob's size. Copies nothing, allocates
/// nothing.
///
/// # Safety
/// `bytes` must be valid for reading `len` bytes, and stay alive and unchanged
/// while `*out`, or any copy of it, is used. `out` must be valid for writing a
/// `NuldBlob`. Null or misaligned pointers are refused.
#[no_mangle]
pub unsafe extern "C" fn nuld_blob_parse(bytes: *const u8, len: usize, out: *mut NuldBlob) -> i32 {
    if let Err(e) = check(out) {
        return status(Err(e));
    }
    // SAFETY: `out` is checked and valid by the caller's contract.
    unsafe { clear(out) };
    status(check(bytes).and_then(|()| {
        if isize::try_from(len).is_err() {
            return Err(NULD_ERR_TOO_LONG);
        }
        // SAFETY: non-null, `len <= isize::MAX`, and valid and unchanged for the
        // lifetime of the view by the caller's contract.
        let bytes: &'static [u8] = unsafe { core::slice::from_raw_parts(bytes, len) };
        let blob = Blob::parse(bytes).map_err(of_blob_error)?;
        let v = match blob.kind() {
            BlobKind::PointSet2D => View::Points(blob.point_set_2d().map_err(of_blob_error)?),
            BlobKind::DirectionSet => {
                View::Directions(blob.direction_set().map_err(of_blob_error)?)
            }
            BlobKind::Conditional => match (blob.brdf(), blob.envmap()) {
                (Ok(b), _) => View::Brdf(b),
                (_, Ok(e)) => View::Envmap(e),
                (Err(e), _) => return Err(of_blob_error(e)),
            },
        };
        // SAFETY: `out` is checked and valid by the caller's contract.
        unsafe { store(out, v) };
        Ok(())
    }))
}

/// `NuldBlobInfo::kind`: sets of points in the unit square.
pub const NULD_KIND_POINT_SET_2D: u32 = 1;
/// `NuldBlobInfo::kind`: sets of directions.
pub const NULD_KIND_DIRECTION_SET: u32 = 2;
/// `NuldBlobInfo::kind`: a conditional sampler (BRDF or environment map).
pub const NULD_KIND_CONDITIONAL: u32 = 3;

/// `NuldBlobInfo::target` of a point or direction set.
pub const NULD_TARGET_NONE: u32 = 0;
/// `NuldBlobInfo::target`: the glTF 2.0 BRDF (`build-tool bake --brdf`); the
/// condition is (roughness, view angle in degrees).
pub const NULD_TARGET_GLTF_BRDF: u32 = 1;
/// `NuldBlobInfo::target`: an environment map's light times the cosine
/// (`build-tool bake --envmap`); the condition is the normal's point of the
/// equal-area octahedral square.
pub const NULD_TARGET_ENVMAP: u32 = 2;

/// `NuldBlobInfo::domain`: the unit square.
pub const NULD_DOMAIN_SQUARE: u32 = 0;
/// `NuldBlobInfo::domain`: the unit sphere.
pub const NULD_DOMAIN_SPHERE: u32 = 1;
/// `NuldBlobInfo::domain`: the upper hemisphere, z >= 0.
pub const NULD_DOMAIN_HEMISPHERE: u32 = 2;

/// What a parsed blob holds and its sizes (`nuld_blob_info`). The codes are the
/// blob format's (core/FORMAT.md).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NuldBlobInfo {
    /// `NULD_KIND_*`.
    pub kind: u32,
    /// `NULD_TARGET_*` of a conditional sampler; `NULD_TARGET_NONE` otherwise.
    pub target: u32,
    /// `NULD_DOMAIN_*` of the points or directions.
    pub domain: u32,
    /// Points per set N (at least 1); indices wrap modulo N.
    pub len: u32,
    /// Point and direction sets: the sets S (at least 1), wrapping modulo S.
    /// Samplers: the instances S of table mode (at least 1), wrapping modulo S.
    pub sets: u32,
    /// Samplers: network mode's instance slots M (instance k is slot k mod M; 0:
    /// every instance its own set). 0 for point and direction sets.
    pub instance_slots: u32,
    /// Samplers: the lower end of each condition axis, in the blob's units
    /// (`nuld_conditional_sample`); 0 for point and direction sets.
    pub cond_min: [f32; 2],
    /// Samplers: the upper end of each condition axis; 0 for point and
    /// direction sets.
    pub cond_max: [f32; 2],
    /// Samplers: the floats `nuld_decode_network` needs; 0 for point and
    /// direction sets.
    pub decoded_network_len: usize,
}

/// Writes what `*blob` holds and its sizes to `*out`. O(1).
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `out` must be valid
/// for writing a `NuldBlobInfo`.
#[no_mangle]
pub unsafe extern "C" fn nuld_blob_info(blob: *const NuldBlob, out: *mut NuldBlobInfo) -> i32 {
    // SAFETY: by the caller's contract.
    let info = unsafe { view(blob) }.map(|v| match v {
        View::Points(p) => NuldBlobInfo {
            kind: NULD_KIND_POINT_SET_2D,
            domain: NULD_DOMAIN_SQUARE,
            len: u32_of(p.len()),
            sets: u32_of(p.set_count()),
            ..NuldBlobInfo::default()
        },
        View::Directions(d) => NuldBlobInfo {
            kind: NULD_KIND_DIRECTION_SET,
            domain: d.domain() as u32,
            len: u32_of(d.len()),
            sets: u32_of(d.set_count()),
            ..NuldBlobInfo::default()
        },
        View::Brdf(b) => sampler_info(b.conditional()),
        View::Envmap(e) => sampler_info(e.conditional()),
    });
    // SAFETY: by the caller's contract.
    status(info.and_then(|info| unsafe { write(out, info) }))
}

/// The [`NuldBlobInfo`] of a conditional sampler.
fn sampler_info(cs: ConditionalSampler<'_>) -> NuldBlobInfo {
    let info = cs.info();
    NuldBlobInfo {
        kind: NULD_KIND_CONDITIONAL,
        target: cs.target() as u32,
        domain: cs.domain() as u32,
        len: cs.len(),
        sets: cs.instances(),
        instance_slots: cs.instance_slots(),
        cond_min: info.cond_min,
        cond_max: info.cond_max,
        decoded_network_len: cs.decoded_network_len(),
    }
}

/// A count the blob stored as a `u32` (every count of a parsed blob is one).
fn u32_of(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// Decodes the f16 weights of `*blob`'s network once into `buf` (`buf_len`
/// floats, at least `NuldBlobInfo::decoded_network_len`) and fills `*out` with
/// the same sampler, whose network mode then reads `buf`: the same bits as
/// before, faster (the f16 decode is most of network mode's cost on a CPU). Table
/// mode and the pdf are unchanged. `out` may be `blob` itself. O(weights), once.
///
/// Fails with `NULD_ERR_WRONG_KIND` for a point or direction set and
/// `NULD_ERR_BUFFER_TOO_SMALL` for a short buffer (`*out` is then marked not
/// parsed, unless it is `blob`, which is left as it was).
///
/// # Safety
/// `blob` must point to a `NuldBlob` whose bytes are alive; `buf` must be valid
/// for writing `buf_len` floats, and stay alive and unchanged while `*out`, or
/// any copy of it, is used; `out` must be valid for writing a `NuldBlob`.
#[no_mangle]
pub unsafe extern "C" fn nuld_decode_network(
    blob: *const NuldBlob,
    buf: *mut f32,
    buf_len: usize,
    out: *mut NuldBlob,
) -> i32 {
    // SAFETY: by the caller's contract.
    let result = unsafe { view(blob) }.copied().and_then(|v| {
        check(out)?;
        check(buf)?;
        if isize::try_from(buf_len.saturating_mul(4)).is_err() {
            return Err(NULD_ERR_TOO_LONG);
        }
        // SAFETY: non-null, aligned, at most `isize::MAX` bytes, valid and
        // unchanged for the lifetime of the view by the caller's contract.
        let buf: &'static mut [f32] = unsafe { core::slice::from_raw_parts_mut(buf, buf_len) };
        let decoded = match v {
            View::Brdf(b) => b
                .decode_network(buf)
                .map(|n| n.conditional().table())
                .and_then(|cs| BrdfSampler::try_from(cs).ok())
                .map(View::Brdf),
            View::Envmap(e) => e
                .decode_network(buf)
                .map(|n| n.conditional().table())
                .and_then(|cs| EnvmapSampler::try_from(cs).ok())
                .map(View::Envmap),
            View::Points(_) | View::Directions(_) => return Err(NULD_ERR_WRONG_KIND),
        };
        decoded.ok_or(NULD_ERR_BUFFER_TOO_SMALL)
    });
    status(match result {
        Ok(v) => {
            // SAFETY: checked above, valid by the caller's contract.
            unsafe { store(out, v) };
            Ok(())
        }
        Err(e) => {
            if check(out).is_ok() && !core::ptr::eq(out, blob) {
                // SAFETY: checked, valid by the caller's contract.
                unsafe { clear(out) };
            }
            Err(e)
        }
    })
}
