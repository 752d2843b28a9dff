//! The bilinear warp of the unit square: a point drawn with density proportional
//! to the bilinear interpolation of four corner values, beside its density, its
//! inverse and its derivatives (pbrt-v4's `SampleBilinear`, `BilinearPDF`,
//! `InvertBilinearSample`).
//!
//! With corners `w = [w00, w10, w01, w11]` (at `(0,0)`, `(1,0)`, `(0,1)`,
//! `(1,1)`), the density per unit area is
//!
//! ```text
//! p(x, y) = 4 ((1-x)(1-y) w00 + x(1-y) w10 + (1-x) y w01 + x y w11) / (w00 + w10 + w01 + w11)
//! ```
//!
//! drawn as the quadtree draws its children: `x` from the marginal, linear
//! between `w00 + w01` and `w10 + w11`, by `u.x`; then `y` from the conditional at
//! that `x`, linear between `lerp(x, w00, w10)` and `lerp(x, w01, w11)`, by
//! `u.y`. Each step is the inverse CDF of a linear density ([`sample_linear`]),
//! exact in closed form. What the environment prior would use inside its leaves,
//! where the map's light is not uniform.
//!
//! The density is 0 at a corner of value 0: a caller that needs it positive
//! wherever its own function is (the environment prior, for an unbiased mode)
//! raises the corners to a floor first. Corners that are negative, NaN or
//! infinite count as 0; if no corner is positive and finite the warp is the
//! identity with density 1. Everything is
//! generic over [`Real`], allocates nothing and never panics.

use crate::real::{clamp_unit, is_positive_finite, positive, Real};

/// The corners as the warp reads them ([`positive`]: negative and non-finite as 0), or `None` where none is
/// positive (or their sum is not finite): the identity.
#[inline]
fn corners<T: Real>(w: [T; 4]) -> Option<[T; 4]> {
    let w = w.map(positive);
    let sum = (w[0] + w[1]) + (w[2] + w[3]);
    is_positive_finite(sum).then_some(w)
}

#[inline]
fn lerp<T: Real>(t: T, a: T, b: T) -> T {
    a + (b - a) * t
}

/// The point of `[0, 1]` at `u` (clamped into `[0, 1]`) under the density
/// proportional to `(1 - x) a + x b` (`a, b >= 0`, not both 0): the inverse of
/// its CDF, `x = u (a + b) / (a + sqrt(lerp(u, a², b²)))`, which needs no
/// division by `b - a`. Clamped into `[0, 1]`.
#[inline]
pub fn sample_linear<T: Real>(u: T, a: T, b: T) -> T {
    let u = clamp_unit(u);
    let d = a + lerp(u, a * a, b * b).max(T::ZERO).sqrt();
    if d > T::ZERO {
        clamp_unit(u * (a + b) / d)
    } else {
        u
    }
}

/// The density at `x` of [`sample_linear`]'s points: `2 lerp(x, a, b) / (a + b)`
/// (1 where `a + b` is 0).
#[inline]
pub fn linear_pdf<T: Real>(x: T, a: T, b: T) -> T {
    if a + b > T::ZERO {
        // Divided first: corners near the float range still give a finite density.
        T::of(2.0) * (lerp(clamp_unit(x), a, b) / (a + b))
    } else {
        T::ONE
    }
}

/// The `u` that [`sample_linear`] maps to `x`: the CDF, `x ((2 - x) a + x b) /
/// (a + b)`.
#[inline]
pub fn invert_linear<T: Real>(x: T, a: T, b: T) -> T {
    let x = clamp_unit(x);
    if a + b > T::ZERO {
        clamp_unit(x * ((T::of(2.0) - x) * a + x * b) / (a + b))
    } else {
        x
    }
}

/// The point of the square at `u` under the bilinear density of the corners `w`
/// (module docs), with its density per unit area ([`bilinear_pdf`]) and its
/// derivatives `[dx/du.x, dy/du.x, dy/du.y]` (`dx/du.y` is 0: `x` reads `u.x`
/// only). `dx/du.x` and `dy/du.y` are each step's inverse density; `dy/du.x` is
/// the conditional's shift as `x` moves, `-(dF/dx) / p(y)` with
/// `F(y) = (c y (2 - y) + d y²) / (c + d)` the conditional's CDF, so
/// `dF/dx = 2 y (1 - y) (d c' - c d') / (c + d)²`.
#[inline]
pub fn sample_bilinear<T: Real>(u: [T; 2], w: [T; 4]) -> ([T; 2], T, [T; 3]) {
    let u = u.map(clamp_unit);
    let Some(w) = corners(w) else {
        return (u, T::ONE, [T::ONE, T::ZERO, T::ONE]);
    };
    let (a, b) = (w[0] + w[2], w[1] + w[3]);
    let x = sample_linear(u[0], a, b);
    let (c, d) = (lerp(x, w[0], w[1]), lerp(x, w[2], w[3]));
    let y = sample_linear(u[1], c, d);
    let (px, py) = (linear_pdf(x, a, b), linear_pdf(y, c, d));
    let slope = |p: T| if p > T::ZERO { T::ONE / p } else { T::ZERO };
    let (dx, dy) = (slope(px), slope(py));
    let cd = c + d;
    let cross = if cd > T::ZERO {
        let df_dx =
            T::of(2.0) * y * (T::ONE - y) * (d * (w[1] - w[0]) - c * (w[3] - w[2])) / (cd * cd);
        -df_dx * dy * dx
    } else {
        T::ZERO
    };
    ([x, y], px * py, [dx, cross, dy])
}

/// The density per unit area of [`sample_bilinear`]'s points at `p` (clamped
/// into the square): the bilinear interpolation of the corners over their mean.
#[inline]
pub fn bilinear_pdf<T: Real>(p: [T; 2], w: [T; 4]) -> T {
    let [x, y] = p.map(clamp_unit);
    let Some(w) = corners(w) else {
        return T::ONE;
    };
    let (a, b) = (w[0] + w[2], w[1] + w[3]);
    let (c, d) = (lerp(x, w[0], w[1]), lerp(x, w[2], w[3]));
    linear_pdf(x, a, b) * linear_pdf(y, c, d)
}

/// The `u` that [`sample_bilinear`] maps to `p` (clamped into the square).
#[inline]
pub fn invert_bilinear<T: Real>(p: [T; 2], w: [T; 4]) -> [T; 2] {
    let [x, y] = p.map(clamp_unit);
    let Some(w) = corners(w) else {
        return [x, y];
    };
    [
        invert_linear(x, w[0] + w[2], w[1] + w[3]),
        invert_linear(y, lerp(x, w[0], w[1]), lerp(x, w[2], w[3])),
    ]
}

#[cfg(test)]
mod tests;
