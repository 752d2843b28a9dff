//! [`Real`]: the few floating-point operations that shared formulas need, for `f32`
//! and `f64`.
//!
//! A formula written once over `T: Real` serves the build tool (in `f64`, for
//! quadratures and references) and the runtime (in `f32`, the precision a shader
//! reproduces) without a second copy. Transcendentals go through `libm`, so both
//! instantiations are `no_std` and give the same bits on every platform.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A real scalar type (`f32` or `f64`) with the operations shared formulas use.
///
/// Every method is total: NaN propagates as IEEE 754 says, except in [`Real::max`]
/// and [`Real::min`], which return the other argument when one is NaN (IEEE
/// `maxNum`/`minNum`, like `f64::max`).
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// `0`.
    const ZERO: Self;
    /// `1`.
    const ONE: Self;
    /// `pi`.
    const PI: Self;
    /// The largest finite value.
    const MAX: Self;
    /// `x` rounded to the nearest value of `Self` (exact for `f64`).
    fn of(x: f64) -> Self;
    /// The correctly rounded square root (NaN for negative arguments): the
    /// compiler's with the crate's `std` feature, libm's without, the same bits.
    fn sqrt(self) -> Self;
    /// The larger argument; the other one if either is NaN.
    fn max(self, other: Self) -> Self;
    /// The smaller argument; the other one if either is NaN.
    fn min(self, other: Self) -> Self;
    /// The absolute value.
    fn abs(self) -> Self;
    /// Whether `self` is NaN.
    fn is_nan(self) -> bool;
    /// Whether `self` is neither infinite nor NaN.
    fn is_finite(self) -> bool;
    /// `cos` of an angle in radians.
    fn cos(self) -> Self;
    /// `sin` of an angle in radians.
    fn sin(self) -> Self;
    /// `(sin, cos)` of an angle in radians, each with the bits of [`Real::sin`]
    /// and [`Real::cos`]: libm's `sincos` and `sincosf`, one argument reduction
    /// for both (their reductions and kernels are those of `sin` and `cos`, up to
    /// the kernels' evenness and oddness, which are exact; tested).
    fn sin_cos(self) -> (Self, Self);
    /// `atan`, in radians in `[-pi/2, pi/2]`.
    fn atan(self) -> Self;
    /// Rounded towards negative infinity.
    fn floor(self) -> Self;
    /// `e^self`.
    fn exp(self) -> Self;
    /// The natural logarithm (NaN for negative arguments, `-inf` at 0).
    fn ln(self) -> Self;
    /// `self` with the sign bit of `sign` (IEEE 754 `copySign`; `-0.0` and negative
    /// NaNs count as negative).
    fn copysign(self, sign: Self) -> Self;
    /// The value as `f64` (exact).
    fn to_f64(self) -> f64;
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const PI: Self = core::f64::consts::PI;
    const MAX: Self = f64::MAX;
    #[inline]
    fn of(x: f64) -> Self {
        x
    }
    #[inline]
    fn sqrt(self) -> Self {
        root::sqrt(self)
    }
    #[inline]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }
    #[inline]
    fn min(self, other: Self) -> Self {
        f64::min(self, other)
    }
    /// The sign bit cleared: libm's `fabs` bit for bit, inlined (libm's is a
    /// call, which the warps' hot paths paid several times per sample). Core's
    /// own `abs` (LLVM's `fabs`: a mask in the vector register), not the bits
    /// moved through an integer register and back, which cost the environment
    /// sampler's `pdf` 2 to 5 % (docs/results/runtime-cost.md#morton).
    #[inline]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline]
    fn is_nan(self) -> bool {
        f64::is_nan(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline]
    fn cos(self) -> Self {
        libm::cos(self)
    }
    #[inline]
    fn sin(self) -> Self {
        libm::sin(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        libm::sincos(self)
    }
    #[inline]
    fn atan(self) -> Self {
        libm::atan(self)
    }
    #[inline]
    fn floor(self) -> Self {
        // Inline rather than libm's call (no SSE4.1 `roundsd` in the baseline
        // x86-64 target): below 2^52 in magnitude the truncation is exact in
        // i64; at or above it, and for NaN and infinities, `self` is its floor.
        // The same value as libm's for every input, -0.0 included.
        if Real::abs(self) < 4_503_599_627_370_496.0 {
            floor_of_truncation(self, self as i64 as f64)
        } else {
            self
        }
    }
    #[inline]
    fn exp(self) -> Self {
        libm::exp(self)
    }
    #[inline]
    fn ln(self) -> Self {
        libm::log(self)
    }
    /// `self`'s magnitude with `sign`'s sign bit: libm's `copysign` bit for bit
    /// (NaNs included), inlined (core's own, as for [`Real::abs`]).
    #[inline]
    fn copysign(self, sign: Self) -> Self {
        f64::copysign(self, sign)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const PI: Self = core::f32::consts::PI;
    const MAX: Self = f32::MAX;
    #[inline]
    fn of(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn sqrt(self) -> Self {
        root::sqrtf(self)
    }
    #[inline]
    fn max(self, other: Self) -> Self {
        f32::max(self, other)
    }
    #[inline]
    fn min(self, other: Self) -> Self {
        f32::min(self, other)
    }
    /// As for `f64`: libm's `fabsf` bit for bit, inlined.
    #[inline]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline]
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline]
    fn cos(self) -> Self {
        libm::cosf(self)
    }
    #[inline]
    fn sin(self) -> Self {
        libm::sinf(self)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        libm::sincosf(self)
    }
    #[inline]
    fn atan(self) -> Self {
        libm::atanf(self)
    }
    #[inline]
    fn floor(self) -> Self {
        // As for `f64`, below 2^23 (exact in i32): the warps' hot paths floor
        // several times per sample.
        if Real::abs(self) < 8_388_608.0 {
            floor_of_truncation(self, self as i32 as f32)
        } else {
            self
        }
    }
    #[inline]
    fn exp(self) -> Self {
        libm::expf(self)
    }
    #[inline]
    fn ln(self) -> Self {
        libm::logf(self)
    }
    /// As for `f64`: libm's `copysignf` bit for bit, inlined.
    #[inline]
    fn copysign(self, sign: Self) -> Self {
        f32::copysign(self, sign)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

/// `x` clamped into `[0, 1]`, NaN as 0: a primary sample or a cell position made
/// safe to index with (the warps of [`crate::marginal2d`] and [`crate::quadtree`]).
#[inline]
pub fn clamp_unit<T: Real>(x: T) -> T {
    if x >= T::ZERO {
        x.min(T::ONE)
    } else {
        T::ZERO
    }
}

/// `v` if positive and finite, else 0: a weight or density value made safe to
/// sum and divide by (the warps of [`crate::quadtree`] and [`crate::bilinear`]).
#[inline]
pub fn positive<T: Real>(v: T) -> T {
    if is_positive_finite(v) {
        v
    } else {
        T::ZERO
    }
}

/// Whether `v` is positive and finite (not NaN): `0 < v <= MAX`, two
/// comparisons that stay in the vector registers. (`v > 0 && v.is_finite()`,
/// the same test, compiles to a test of the bits' class in the integer
/// registers, and the warps' descents waited on the moves there and back at
/// every level: docs/results/runtime-cost.md#morton.)
#[inline]
pub fn is_positive_finite<T: Real>(v: T) -> bool {
    v > T::ZERO && v <= T::MAX
}

/// IEEE 754's correctly rounded square roots, named as libm names them. With the
/// `std` feature they are the compiler's (LLVM's `sqrt`, which it can schedule and
/// vectorize: the environment tree's four children take one `sqrtps`); without
/// it, libm's, whose inline `sqrtss`/`sqrtsd` the compiler can do neither with.
/// Both round the exact root once: the same bits (a test).
#[cfg(feature = "std")]
mod root {
    /// The square root of an `f64`.
    #[inline]
    pub fn sqrt(x: f64) -> f64 {
        f64::sqrt(x)
    }

    /// The square root of an `f32`.
    #[inline]
    pub fn sqrtf(x: f32) -> f32 {
        f32::sqrt(x)
    }
}

#[cfg(not(feature = "std"))]
use libm as root;

/// The floor of `x` from its truncation toward zero `t` (exact): `x` itself
/// when it is whole (keeping -0.0), else `t`, or `t - 1` below zero.
#[inline]
fn floor_of_truncation<T>(x: T, t: T) -> T
where
    T: Copy + PartialOrd + core::ops::Sub<Output = T> + From<u8>,
{
    if t == x {
        x
    } else if t > x {
        t - T::from(1u8)
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    fn hypot<T: Real>(a: T, b: T) -> T {
        (a * a + b * b).sqrt()
    }

    /// `count` pseudo-random bit patterns from `seed` (a linear congruential
    /// sequence).
    fn random_bits(seed: u64, count: usize) -> impl Iterator<Item = u64> {
        (0..count).scan(seed, |h, _| {
            *h = h
                .wrapping_mul(0x5851_f42d_4c95_7f2d)
                .wrapping_add(0x1405_7b7e_f767_814f);
            Some(*h)
        })
    }

    /// `f64` bit patterns that the bitwise tests start from: signed zeros, the
    /// smallest subnormals of both signs, the smallest normal, 1 and 2, the largest
    /// finite values and infinities of both signs, and NaNs of either sign; then
    /// `count` pseudo-random ones from `seed`.
    fn special_and_random_bits(seed: u64, count: usize) -> std::vec::Vec<u64> {
        let mut bits = std::vec![0u64, 1, 1 << 63, (1 << 63) | 1, 0x0010_0000_0000_0000];
        bits.extend([0x3ff0_0000_0000_0000, 0x4000_0000_0000_0000]);
        bits.extend([0x7fef_ffff_ffff_ffff, 0xffef_ffff_ffff_ffff]);
        bits.extend([0x7ff0_0000_0000_0000, 0xfff0_0000_0000_0000]);
        bits.extend([0x7ff8_0000_0000_0001, 0xfff8_0000_0000_0002]);
        bits.extend(random_bits(seed, count));
        bits
    }

    /// `abs` and `copysign` against libm's, bit for bit, on signed zeros,
    /// infinities, NaNs of either sign, subnormals and pseudo-random bits.
    #[test]
    fn abs_and_copysign_are_libms_bit_for_bit() {
        let bits = special_and_random_bits(0x9e37_79b9_7f4a_7c15, 2000);
        for &a in &bits {
            let x = f64::from_bits(a);
            assert_eq!(Real::abs(x).to_bits(), libm::fabs(x).to_bits());
            let x32 = f32::from_bits((a >> 32) as u32);
            assert_eq!(Real::abs(x32).to_bits(), libm::fabsf(x32).to_bits());
            for &b in bits.iter().take(40) {
                let y = f64::from_bits(b);
                let want = libm::copysign(x, y).to_bits();
                assert_eq!(Real::copysign(x, y).to_bits(), want);
                let y32 = f32::from_bits((b >> 32) as u32);
                let want = libm::copysignf(x32, y32).to_bits();
                assert_eq!(Real::copysign(x32, y32).to_bits(), want);
            }
        }
    }

    /// `sqrt` against libm's, bit for bit, in both precisions: the compiler's
    /// square root with the `std` feature (the workspace's builds), libm's own
    /// without. Signed zeros, subnormals, infinities, negative values and NaNs
    /// (NaN out, compared as NaN), and pseudo-random bits.
    #[test]
    fn sqrt_is_libms_bit_for_bit() {
        let bits = special_and_random_bits(0x6a09_e667_f3bc_c908, 50_000);
        for &b in &bits {
            let x = f64::from_bits(b);
            let (got, want) = (Real::sqrt(x), libm::sqrt(x));
            assert!(got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()));
            // The same bits made positive, compared bit for bit: every value
            // has a root, and a NaN passes its payload through in both.
            let x = f64::from_bits(b & !(1 << 63));
            assert_eq!(Real::sqrt(x).to_bits(), libm::sqrt(x).to_bits(), "{x:e}");
            for b32 in [(b >> 32) as u32, b as u32 & 0x7fff_ffff] {
                let x = f32::from_bits(b32);
                let (got, want) = (Real::sqrt(x), libm::sqrtf(x));
                assert!(got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()));
            }
        }
    }

    /// `is_positive_finite` (and `positive`) against the class test it stands
    /// for, `v > 0 && v.is_finite()`, on signed zeros, the smallest and largest
    /// values of both signs, infinities, NaNs of either sign and pseudo-random
    /// bits, in both precisions.
    #[test]
    fn positive_finite_is_the_class_test() {
        let bits = special_and_random_bits(0x2545_f491_4f6c_dd1d, 20_000);
        let mut f32_bits: std::vec::Vec<u32> = bits.iter().map(|&b| (b >> 32) as u32).collect();
        f32_bits.extend([
            0,
            1,
            1 << 31,
            0x7f7f_ffff,
            0xff7f_ffff,
            0x7f80_0000,
            0xff80_0000,
        ]);
        f32_bits.extend([0x7fc0_0001, 0xffc0_0000, 0x0080_0000]);
        for &b in &bits {
            let x = f64::from_bits(b);
            let want = x > 0.0 && x.is_finite();
            assert_eq!(is_positive_finite(x), want, "{x:e}");
            assert_eq!(positive(x).to_bits(), if want { b } else { 0 });
        }
        for &b in &f32_bits {
            let x = f32::from_bits(b);
            let want = x > 0.0 && x.is_finite();
            assert_eq!(is_positive_finite(x), want, "{x:e}");
            assert_eq!(positive(x).to_bits(), if want { b } else { 0 });
        }
    }

    /// `sin_cos` has the bits of `sin` and `cos` in both precisions: on special
    /// values, on every 97th `f32` of `[0, pi/2]` (the angles the warps feed it),
    /// on the `f64`s around the kernels' small-argument cut-offs (`2^-27` to
    /// `2^-25`), and on pseudo-random bits and angles (every range of libm's
    /// argument reduction).
    #[test]
    fn sin_cos_has_the_bits_of_sin_and_cos() {
        fn check<T: Real>(x: T, bits: impl Fn(T) -> u64) {
            let (s, c) = Real::sin_cos(x);
            let want = (bits(Real::sin(x)), bits(Real::cos(x)));
            assert_eq!((bits(s), bits(c)), want, "{}", x.to_f64());
        }
        let b32 = |v: f32| v.to_bits() as u64;
        for x in [
            0.0,
            1e-30,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NAN,
            1e30,
            1e300,
        ] {
            for x in [x, -x] {
                check(x, f64::to_bits);
                check(x as f32, b32);
            }
        }
        let end = core::f32::consts::FRAC_PI_2.to_bits();
        (0..=end)
            .step_by(97)
            .for_each(|b| check(f32::from_bits(b), b32));
        let (lo, hi) = ((2f64).powi(-27).to_bits(), (2f64).powi(-25).to_bits());
        (lo..hi)
            .step_by(1 << 30)
            .for_each(|b| check(f64::from_bits(b), f64::to_bits));
        let mut h = 0x2545_f491_4f6c_dd1du64;
        for k in 0..1_000_000u64 {
            h ^= h << 13;
            h ^= h >> 7;
            h ^= h << 17;
            check(f32::from_bits(h as u32), b32);
            let x = match k % 2 {
                0 => f64::from_bits(h),
                _ => (h >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0,
            };
            check(x, f64::to_bits);
        }
    }

    #[test]
    fn both_instantiations_agree_with_std() {
        assert_eq!(hypot(3.0f64, 4.0), 5.0);
        assert_eq!(hypot(3.0f32, 4.0), 5.0);
        assert_eq!(<f32 as Real>::of(0.1), 0.1f32);
        assert_eq!(Real::max(f64::NAN, 2.0), 2.0);
        assert_eq!(Real::min(1.0f32, f32::NAN), 1.0);
        assert_eq!(Real::floor(-0.5f64), -1.0);
        assert!((Real::cos(<f32 as Real>::PI) + 1.0).abs() < 1e-7);
        assert_eq!(Real::to_f64(0.5f32), 0.5);
    }

    /// `Real::floor` against `libm` on `xs` and their negatives, bit for bit
    /// (compared widened to f64, which keeps every value and -0.0), and NaN.
    fn floor_matches<T: Real>(xs: impl IntoIterator<Item = T>, libm_floor: fn(T) -> T, nan: T) {
        for x in xs {
            for v in [x, T::ZERO - x] {
                let (got, want) = (Real::floor(v).to_f64(), libm_floor(v).to_f64());
                assert_eq!(got.to_bits(), want.to_bits(), "{}", v.to_f64());
            }
        }
        assert!(Real::floor(nan).is_nan());
    }

    /// The inline floors return libm's bits: a dense sweep of f32 over
    /// `[2^-31, 2^25]` (both sides of the 2^23 switch) and of f64 over `[2^-63,
    /// 2^65]` (both sides of 2^52), their negatives, signed zeros, infinities,
    /// NaN and the values next to the switches.
    #[test]
    fn floor_is_libms_bit_for_bit() {
        let specials = [0.5, 1.0, 2.7, 3.0, 123_456.789, f64::INFINITY];
        let f32s = (0x3000_0000u32..0x4c00_0000)
            .step_by(997)
            .map(f32::from_bits);
        let f32_edges = [-0.0, 8_388_607.5, 8_388_608.0, 8_388_609.0, f32::MAX];
        floor_matches(
            f32s.chain(f32_edges)
                .chain(specials.map(|x| x as f32))
                .chain([f32::MIN_POSITIVE]),
            libm::floorf,
            f32::NAN,
        );
        let f64s = (0x3c00_0000_0000_0000u64..0x4400_0000_0000_0000)
            .step_by(0x0000_1234_5678_9abc)
            .map(f64::from_bits);
        let f64_edges = [
            -0.0,
            1e-300,
            4_503_599_627_370_495.5,
            4_503_599_627_370_496.0,
        ];
        floor_matches(
            f64s.chain(f64_edges).chain(specials).chain([9.1e15, 1e300]),
            libm::floor,
            f64::NAN,
        );
    }
}
