//! The network's inputs: condition features, the instance's pseudo-random offset,
//! and the shifted rank-1 lattice point of each index.

use super::{Shape, CONDITION_FEATURES, INPUTS};
use crate::real::Real;

/// Distance of the clamped shifted lattice point from `0` and `1` in
/// [`lattice_logit`]: `2^-20`, exact in `f32`, so `logit` stays within `+-13.9`.
pub const LATTICE_LOGIT_EPS: f64 = 1.0 / 1_048_576.0;

/// `ln(p_a / (1 - p_a))` of the shifted lattice point read back from the input
/// features (`p_a = (input[7 + a] + 1) / 2`, clamped into
/// `[LATTICE_LOGIT_EPS, 1 - LATTICE_LOGIT_EPS]`): the residual base of a
/// [`Shape::lattice_residual`] network.
#[inline]
pub fn lattice_logit<T: Real>(input: &[T; INPUTS]) -> [T; 2] {
    let eps = T::of(LATTICE_LOGIT_EPS);
    core::array::from_fn(|a| {
        let p = ((input[CONDITION_FEATURES + 2 + a] + T::ONE) * T::of(0.5))
            .max(eps)
            .min(T::ONE - eps);
        (p / (T::ONE - p)).ln()
    })
}

/// The five features of a condition `c` normalized to `[0,1]^2` (each coordinate
/// clamped there first; NaN counts as 0): `(u, v, u v, u^2, v^2)` mapped to `[-1,1]`
/// by `2x - 1`. Polynomial so that neither side needs a transcendental per sample.
#[inline]
pub fn condition_features<T: Real>(c: [T; 2]) -> [T; CONDITION_FEATURES] {
    let unit = |x: T| {
        if x.is_nan() {
            T::ZERO
        } else {
            x.max(T::ZERO).min(T::ONE)
        }
    };
    let (u, v) = (unit(c[0]), unit(c[1]));
    let two = T::of(2.0);
    [u, v, u * v, u * u, v * v].map(|x| two * x - T::ONE)
}

/// `lowbias32` (C. Wellons' integer hash): a bijection of `u32` with good avalanche,
/// cheap in a shader.
#[inline]
pub fn hash_u32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The pseudo-random offset `z_k` in `[0,1)^2` of instance `k` under the plain
/// hash ([`OffsetHash::Plain`]): the top 24 bits of `hash_u32(2k)` and
/// `hash_u32(2k + 1)` (wrapping) times `2^-24`, exact in `f32` and `f64`. Every
/// `u32` is an instance. `hash_u32(0) = 0`, so `z_0 = (0, y)`: what the unbiased
/// mode's shift ([`crate::conditional::randomized_point`]) starts from, and the
/// offsets of blobs baked before [`salted_instance_offset`].
#[inline]
pub fn instance_offset<T: Real>(k: u32) -> [T; 2] {
    let k2 = k.wrapping_mul(2);
    [
        offset_unit(hash_u32(k2)),
        offset_unit(hash_u32(k2.wrapping_add(1))),
    ]
}

/// The salts of [`salted_instance_offset`]'s two hashes, both odd (the golden
/// ratio's and `sqrt(3)`'s fraction bits), apart from the unbiased mode's.
pub const OFFSET_SALTS: [u32; 2] = [0x9e37_79b9, 0xbb67_ae85];

/// The pseudo-random offset `z_k` in `[0,1)^2` of instance `k` under the salted
/// hash ([`OffsetHash::Salted`]): the top 24 bits of `hash_u32(2k ^ S_x)` and
/// `hash_u32(2k ^ S_y)` ([`OFFSET_SALTS`]) times `2^-24`, exact in `f32` and `f64`.
///
/// An odd salt makes each hash's input odd, never 0, and `hash_u32` is a
/// bijection with `hash_u32(0) = 0`, so no hash here is 0. Under the plain hash
/// instance 0's offset is `(0, y)`: its point 0 sits on the square's edge, which
/// the hemisphere's equal-area map sends to the horizon, and the BRDF sampler
/// returned a sample with pdf 0 there at most conditions.
#[inline]
pub fn salted_instance_offset<T: Real>(k: u32) -> [T; 2] {
    let k2 = k.wrapping_mul(2);
    [
        offset_unit(hash_u32(k2 ^ OFFSET_SALTS[0])),
        offset_unit(hash_u32(k2 ^ OFFSET_SALTS[1])),
    ]
}

/// The top 24 bits of `h` times `2^-24`, in `[0, 1)`, exact in `f32`: how a
/// hash becomes a coordinate of an instance offset or of the unbiased mode's
/// shift ([`crate::conditional::randomization_shift`]).
#[inline]
pub fn offset_unit<T: Real>(h: u32) -> T {
    T::of((h >> 8) as f64 * (1.0 / 16_777_216.0))
}

/// How instance numbers hash to offsets: the code of
/// [`crate::conditional::ConditionalInfo::offset_hash`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetHash {
    /// [`instance_offset`] (code 0): blobs baked before the salted hash.
    Plain = 0,
    /// [`salted_instance_offset`] (code 1): what the tool bakes.
    Salted = 1,
}

impl OffsetHash {
    /// The hash of `code`, or `None` for an unknown code.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            0 => Some(Self::Plain),
            1 => Some(Self::Salted),
            _ => None,
        }
    }

    /// The offset of instance `k` under this hash.
    #[inline]
    pub fn offset<T: Real>(self, k: u32) -> [T; 2] {
        match self {
            Self::Plain => instance_offset(k),
            Self::Salted => salted_instance_offset(k),
        }
    }
}

/// Point `i mod n` of the rank-1 lattice with generator `g`:
/// `(i / n, ((i g) mod n) / n)`, in `[0,1)^2`.
#[inline]
pub fn lattice_point<T: Real>(i: u32, n: u32, g: u32) -> [T; 2] {
    let n = n.max(1);
    let i = i % n;
    let j = ((i as u64 * g as u64) % n as u64) as u32;
    let nf = T::of(n as f64);
    [T::of(i as f64) / nf, T::of(j as f64) / nf]
}

/// The lattice point shifted by `z` on the torus: `frac(l + z)`, in `[0,1)^2`.
#[inline]
pub fn shifted_lattice_point<T: Real>(i: u32, n: u32, g: u32, z: [T; 2]) -> [T; 2] {
    let l = lattice_point::<T>(i, n, g);
    let frac = |x: T| x - x.floor();
    [frac(l[0] + z[0]), frac(l[1] + z[1])]
}

/// The lattice features: the shifted lattice point `p` and the lattice point `l`,
/// each coordinate mapped from `[0,1)` to `[-1,1)` by `2x - 1`:
/// `(2 p0 - 1, 2 p1 - 1, 2 l0 - 1, 2 l1 - 1)`.
#[inline]
pub fn lattice_features<T: Real>(p: [T; 2], l: [T; 2]) -> [T; 4] {
    let two = T::of(2.0);
    [
        two * p[0] - T::ONE,
        two * p[1] - T::ONE,
        two * l[0] - T::ONE,
        two * l[1] - T::ONE,
    ]
}

/// The network input of index `i`, instance `k`, normalized condition `c` (in
/// `[0,1]^2`) and metallic `m`: `[condition_features(c), 2 z - 1,
/// lattice_features(p, l_i)]` with `z` the offset [`Shape::instance_offset`]`(k)`
/// (`z_k` without slots), `p` the [`shifted_lattice_point`] and `l_i` the
/// [`lattice_point`]. With [`Shape::metallic_input`] the third condition feature
/// (`2 u v - 1`) is `2 m - 1` instead, `m` clamped into `[0, 1]` (NaN as 0);
/// without, `m` is not read.
#[inline]
pub fn input_features<T: Real>(shape: &Shape, c: [T; 2], m: T, k: u32, i: u32) -> [T; INPUTS] {
    let z = shape.instance_offset::<T>(k);
    let (n, g) = (shape.n, shape.lattice_generator);
    let p = shifted_lattice_point(i, n, g, z);
    let cf = condition_features(c);
    let lf = lattice_features(p, lattice_point(i, n, g));
    let two = T::of(2.0);
    let third = if shape.metallic_input {
        let m = if m.is_nan() {
            T::ZERO
        } else {
            m.max(T::ZERO).min(T::ONE)
        };
        two * m - T::ONE
    } else {
        cf[2]
    };
    [
        cf[0],
        cf[1],
        third,
        cf[3],
        cf[4],
        two * z[0] - T::ONE,
        two * z[1] - T::ONE,
        lf[0],
        lf[1],
        lf[2],
        lf[3],
    ]
}
