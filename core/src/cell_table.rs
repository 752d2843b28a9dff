//! The piecewise-constant warp of the unit square: a point drawn with density
//! proportional to a `K x K` table of cell values, beside its density, its inverse
//! and its derivatives (pbrt-v4's `PiecewiseConstant2D` on one small table).
//!
//! A table is `K + K²` values: the column masses `c_a` (`a` along `x`), then the
//! cells column by column, `v[K + a K + b]` for row `b` (along `y`) of column
//! `a`. The point's column is drawn from the marginal `c_a / Σ c` by `u.x`, its
//! row from the column's own values `v_ab / s_a` (`s_a = Σ_b v_ab`, summed here)
//! by `u.y`, uniformly inside the cell, so the density per unit area is
//!
//! ```text
//! p(x, y) = K² (c_a / Σ_a' c_a') (v_ab / s_a),   a = floor(x K), b = floor(y K)
//! ```
//!
//! which is `K² v_ab / Σ v` when each `c_a` is its column's sum, as a writer
//! stores it: storing them spares a reader the `K²` additions. Both steps are
//! exact inverse CDFs of what they read, so the density returned is the density
//! of the points produced, whatever the values. What the environment prior uses
//! inside a leaf whose light is sharper than the bilinear shape of its corners
//! can follow (a sun smaller than a leaf).
//!
//! The density is 0 in a cell of value 0: a caller that needs it positive
//! wherever its own function is raises the values to a floor first. Values that
//! are negative, NaN or infinite count as 0; if no column mass is positive, or
//! their sum is not finite, or the table is short of `K + K²` values, the warp
//! is the identity with density 1, and a chosen column without positive values
//! is uniform along `y`.
//! Work is `O(K)`, bounded; everything is generic over [`Real`], allocates
//! nothing and never panics.

use crate::real::{clamp_unit, is_positive_finite, positive, Real};

/// Values of a `K x K` table: `K` column masses and `K²` cells.
pub const fn table_len(k: usize) -> usize {
    k + k * k
}

/// A value as the warp reads it ([`positive`]).
#[inline]
fn read<T: Real>(v: f32) -> T {
    positive(T::of(v as f64))
}

/// The column masses of `v`, or `None` for a table shorter than
/// [`table_len`]`(K)` (which the warp reads as no table: the identity).
#[inline]
fn masses<const K: usize>(v: &[f32]) -> Option<&[f32; K]> {
    if v.len() < table_len(K) {
        return None;
    }
    v.get(..K)?.try_into().ok()
}

/// Column `a`'s `K` cells (`None` only past a short table).
#[inline]
fn column<const K: usize>(v: &[f32], a: usize) -> Option<&[f32; K]> {
    let start = K + a * K;
    v.get(start..start + K)?.try_into().ok()
}

/// The sum of `w`'s values as read, in order.
#[inline]
fn sum<T: Real>(w: &[f32]) -> T {
    let mut s = T::ZERO;
    for &x in w {
        s = s + read(x);
    }
    s
}

/// The column masses and their sum, or `None` where the table is short or the
/// sum is not positive and finite (the identity).
#[inline]
fn total<T: Real, const K: usize>(v: &[f32]) -> Option<(&[f32; K], T)> {
    let m = masses::<K>(v)?;
    let t = sum(m);
    is_positive_finite(t).then_some((m, t))
}

/// The interval of `u` (clamped into `[0, 1]`) among the weights `w` (as
/// read) of sum `total > 0`: the first `i` whose cumulative sum passes `u
/// total` (stepping over weights of 0), and `u`'s place in it, `(u total -
/// W_i) / w_i` clamped into `[0, 1]`.
#[inline]
fn interval<T: Real>(u: T, w: &[f32], total: T) -> (usize, T) {
    let target = clamp_unit(u) * total;
    let (mut below, mut last) = (T::ZERO, 0);
    for (i, &x) in w.iter().enumerate() {
        let wi: T = read(x);
        if wi > T::ZERO {
            last = i;
            if target < below + wi {
                return (i, clamp_unit((target - below) / wi));
            }
            below = below + wi;
        }
    }
    // `u` at 1, or rounding past the last weight: the end of the last interval
    // that has weight.
    (last, T::ONE)
}

/// The cell of `x` (clamped into `[0, 1]`) on `k` cells: `min(floor(x k), k - 1)`,
/// and `x`'s place in it.
#[inline]
fn locate<T: Real>(x: T, k: usize) -> (usize, T) {
    let s = clamp_unit(x) * T::of(k as f64);
    let i = (s.floor().to_f64() as usize).min(k - 1);
    (i, clamp_unit(s - T::of(i as f64)))
}

/// Column `a`'s cells and their sum, or `None` where the sum is not positive
/// and finite (uniform along `y`).
#[inline]
fn column_sum<T: Real, const K: usize>(v: &[f32], a: usize) -> Option<(&[f32; K], T)> {
    let c = column::<K>(v, a)?;
    let s = sum(c);
    is_positive_finite(s).then_some((c, s))
}

/// The point of the square at `u` under the density of the table `v` (module
/// docs; [`table_len`]`(K)` values), with its density per unit area
/// ([`table_pdf`]) and its derivatives `[dx/du.x, dy/du.x, dy/du.y]` inside the
/// cell (`dx/du.y` is 0: `x` reads `u.x` only; `dy/du.x` is 0 inside a column):
/// each step's inverse density, `Σ c / (K c_a)` and `s_a / (K v_ab)`.
#[inline]
pub fn sample_table<T: Real, const K: usize>(u: [T; 2], v: &[f32]) -> ([T; 2], T, [T; 3]) {
    let u = u.map(clamp_unit);
    let Some((m, total)) = total::<T, K>(v) else {
        return (u, T::ONE, [T::ONE, T::ZERO, T::ONE]);
    };
    let k = T::of(K as f64);
    let (a, tx) = interval(u[0], m, total);
    let x = clamp_unit((T::of(a as f64) + tx) / k);
    let px = k * (read::<T>(m[a]) / total);
    let (y, py) = match column_sum::<T, K>(v, a) {
        Some((c, s)) => {
            let (b, ty) = interval(u[1], c, s);
            (
                clamp_unit((T::of(b as f64) + ty) / k),
                k * (read::<T>(c[b]) / s),
            )
        }
        None => (u[1], T::ONE),
    };
    ([x, y], px * py, [T::ONE / px, T::ZERO, T::ONE / py])
}

/// The density per unit area of [`sample_table`]'s points at `p` (clamped into
/// the square): `K c_a / Σ c` times `K v_ab / s_a` of `p`'s cell (module docs).
#[inline]
pub fn table_pdf<T: Real, const K: usize>(p: [T; 2], v: &[f32]) -> T {
    let Some((m, total)) = total::<T, K>(v) else {
        return T::ONE;
    };
    let (a, _) = locate(p[0], K);
    let (b, _) = locate(p[1], K);
    let k = T::of(K as f64);
    let px = k * (read::<T>(m[a]) / total);
    match column_sum::<T, K>(v, a) {
        Some((c, s)) => px * (k * (read::<T>(c[b]) / s)),
        None => px,
    }
}

/// The `u` that [`sample_table`] maps to `p` (clamped into the square): the
/// marginal CDF at `x`, the column's conditional CDF at `y`.
#[inline]
pub fn invert_table<T: Real, const K: usize>(p: [T; 2], v: &[f32]) -> [T; 2] {
    let p = p.map(clamp_unit);
    let Some((m, total)) = total::<T, K>(v) else {
        return p;
    };
    let (a, tx) = locate(p[0], K);
    let (b, ty) = locate(p[1], K);
    let below: T = sum(&m[..a]);
    let ux = clamp_unit((below + tx * read::<T>(m[a])) / total);
    let uy = match column_sum::<T, K>(v, a) {
        Some((c, s)) => {
            let below: T = sum(&c[..b]);
            clamp_unit((below + ty * read::<T>(c[b])) / s)
        }
        None => p[1],
    };
    [ux, uy]
}

#[cfg(test)]
mod tests;
