//! Codecs for the numbers blobs store.
//!
//! * **u16 unorm, cell-centred**: a coordinate `x` in `[0,1)` is stored as
//!   `q = floor(x * 65536)` (clamped to `0..=65535`) and read back as the centre of
//!   its cell, `(q + 0.5) / 65536`. Decoded values therefore lie strictly inside
//!   `(0,1)` (never exactly 0 or 1, so a decoded point never sits on the square's
//!   boundary or on the octahedral seam) and the round-trip error is at most
//!   [`UNORM16_MAX_ERROR`] `= 2^-17`. The decode is exact in `f32`.
//! * **f16**: IEEE 754 binary16 via the `half` crate, for network weights; relative
//!   round-trip error at most [`F16_MAX_RELATIVE_ERROR`] `= 2^-11` for normal values.

/// Number of cells of the u16 unorm code: `2^16`.
pub const UNORM16_CELLS: u32 = 1 << 16;

/// Largest `|decode(encode(x)) - x|` for `x` in `[0,1]`: half a cell, `2^-17`.
pub const UNORM16_MAX_ERROR: f64 = 1.0 / (2.0 * UNORM16_CELLS as f64);

/// Largest relative round-trip error of [`f16_encode`] for values in the normal
/// binary16 range (`6.1e-5 <= |x| <= 65504`): half an ulp, `2^-11`.
pub const F16_MAX_RELATIVE_ERROR: f32 = 1.0 / 2048.0;

/// Encodes `x` in `[0,1)` as a cell-centred u16 unorm.
///
/// Values below 0 (and NaN) encode to 0, values at or above 1 to 65535.
///
/// ```
/// # use nuld_core::quantize::{unorm16_encode, unorm16_decode};
/// assert_eq!(unorm16_encode(0.0), 0);
/// assert_eq!(unorm16_encode(1.0), 65535);
/// assert_eq!(unorm16_decode(unorm16_encode(0.5)), 0.5 + 0.5 / 65536.0);
/// ```
#[inline]
pub fn unorm16_encode(x: f64) -> u16 {
    let scaled = x * UNORM16_CELLS as f64;
    if scaled.is_nan() || scaled <= 0.0 {
        0
    } else if scaled >= (UNORM16_CELLS - 1) as f64 {
        (UNORM16_CELLS - 1) as u16
    } else {
        scaled as u16 // truncation = floor for positive values
    }
}

/// Decodes a cell-centred u16 unorm: `(q + 0.5) / 65536`, exact in `f32`.
#[inline]
pub fn unorm16_decode(q: u16) -> f32 {
    (q as f32 + 0.5) * (1.0 / UNORM16_CELLS as f32)
}

/// Decodes a cell-centred u16 unorm in `f64` (the same value as [`unorm16_decode`]).
#[inline]
pub fn unorm16_decode_f64(q: u16) -> f64 {
    (q as f64 + 0.5) / UNORM16_CELLS as f64
}

/// Encodes an `f32` as IEEE binary16 bits (round to nearest even).
#[inline]
pub fn f16_encode(x: f32) -> u16 {
    half::f16::from_f32(x).to_bits()
}

/// Decodes IEEE binary16 bits to `f32` (exact).
#[inline]
pub fn f16_decode(bits: u16) -> f32 {
    half::f16::from_bits(bits).to_f32()
}

/// Decodes the bits of a *finite* IEEE binary16 to `f32` (exact) with integer and
/// one multiply only, the way a shader without `unpack2x16float` would:
///
/// ```text
/// magnitude = from_bits((h & 0x7fff) << 13) * 2^112      (f32)
/// result    = from_bits(bits(magnitude) | (h & 0x8000) << 16)
/// ```
///
/// Shifting the 15 magnitude bits by 13 lines up binary16's exponent and mantissa
/// with binary32's low exponent and high mantissa bits, which reads the value
/// `2^-112` times too small (bias 127 instead of 15); the power-of-two multiply is
/// exact, also for subnormal inputs. For infinity and NaN codes (exponent bits all
/// ones; conditional blobs reject them at parse) the result is a large finite
/// number, not inf/NaN. Total, no panics.
///
/// ```
/// # use nuld_core::quantize::{f16_decode_finite, f16_encode};
/// assert_eq!(f16_decode_finite(f16_encode(-1.5)), -1.5);
/// assert_eq!(f16_decode_finite(1), 2f32.powi(-24)); // smallest subnormal
/// ```
#[inline]
pub fn f16_decode_finite(h: u16) -> f32 {
    // 2^112 = bits (127 + 112) << 23.
    const SCALE: f32 = f32::from_bits((127 + 112) << 23);
    let magnitude = f32::from_bits(((h & 0x7fff) as u32) << 13) * SCALE;
    f32::from_bits(magnitude.to_bits() | ((h & 0x8000) as u32) << 16)
}

/// Whether binary16 bits encode a finite value (exponent bits not all ones).
#[inline]
pub fn f16_is_finite(h: u16) -> bool {
    h & 0x7c00 != 0x7c00
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unorm16_round_trip_error_is_at_most_half_a_cell() {
        let mut worst: f64 = 0.0;
        for k in 0..=1_000_000u32 {
            let x = k as f64 / 1_000_000.0;
            let y = unorm16_decode(unorm16_encode(x)) as f64;
            assert!(y > 0.0 && y < 1.0);
            worst = worst.max((x - y).abs());
        }
        assert!(worst <= UNORM16_MAX_ERROR + 1e-15, "{worst}");
        // The bound is tight: a cell boundary is exactly half a cell from a centre.
        assert!(worst > 0.99 * UNORM16_MAX_ERROR);
    }

    #[test]
    fn unorm16_decode_is_exact_and_monotone() {
        for q in 0..=u16::MAX {
            assert_eq!(unorm16_decode(q) as f64, unorm16_decode_f64(q));
            assert_eq!(unorm16_encode(unorm16_decode_f64(q)), q);
        }
        assert_eq!(unorm16_encode(-3.0), 0);
        assert_eq!(unorm16_encode(f64::NAN), 0);
        assert_eq!(unorm16_encode(7.0), 65535);
    }

    /// The integer decoder against `half`'s on every finite binary16 (63488 codes:
    /// 2 signs x 31 exponents x 1024 mantissas), bit for bit.
    #[test]
    fn fast_f16_decoder_equals_half_on_every_finite_code() {
        let mut finite = 0;
        for h in 0..=u16::MAX {
            assert_eq!(
                f16_is_finite(h),
                half::f16::from_bits(h).is_finite(),
                "{h:#06x}"
            );
            if f16_is_finite(h) {
                finite += 1;
                assert_eq!(
                    f16_decode_finite(h).to_bits(),
                    f16_decode(h).to_bits(),
                    "{h:#06x}"
                );
            }
        }
        assert_eq!(finite, 63488);
    }

    #[test]
    fn f16_round_trip_relative_error_is_bounded() {
        let mut x = 6.2e-5f32;
        while x < 65000.0 {
            for v in [x, -x] {
                let y = f16_decode(f16_encode(v));
                assert!(((y - v) / v).abs() <= F16_MAX_RELATIVE_ERROR, "{v} -> {y}");
            }
            x *= 1.0137;
        }
        assert_eq!(f16_decode(f16_encode(0.0)), 0.0);
        assert_eq!(f16_decode(f16_encode(1.5)), 1.5);
    }
}
