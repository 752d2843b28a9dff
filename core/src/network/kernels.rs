//! The dot products every dense layer is made of, in a fixed order of operations
//! (lanes, then a fixed reduction), so that `f32` results are the same bits on every
//! target and a shader can reproduce them.

use crate::real::Real;

/// Partial sums of [`dot`]: products `k ≡ c (mod DOT_LANES)` go to partial `c`,
/// so the sum is a fixed tree that compilers turn into SIMD, and is the same on
/// every platform (shaders sum in the same order, runtime/shaders/nuld.wgsl).
pub const DOT_LANES: usize = 8;

/// `sum_k w[k] x[k]` over the shorter length, in this order of operations: partial
/// sums `s[c] = sum over k ≡ c (mod 8), k ascending`, then
/// `((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7))`.
#[inline(always)]
pub fn dot<T: Real>(w: &[T], x: &[T]) -> T {
    let mut s = [T::ZERO; DOT_LANES];
    let len = w.len().min(x.len());
    let (w, x) = (&w[..len], &x[..len]);
    let (wc, xc) = (w.chunks_exact(DOT_LANES), x.chunks_exact(DOT_LANES));
    let (wr, xr) = (wc.remainder(), xc.remainder());
    for (wk, xk) in wc.zip(xc) {
        for (c, sc) in s.iter_mut().enumerate() {
            *sc = *sc + wk[c] * xk[c];
        }
    }
    for (sc, (&wk, &xk)) in s.iter_mut().zip(wr.iter().zip(xr)) {
        *sc = *sc + wk * xk;
    }
    sum_lanes(s)
}

/// The last step of [`dot`]: `((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7))`.
#[inline(always)]
fn sum_lanes<T: Real>(s: [T; DOT_LANES]) -> T {
    ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]))
}

/// Units a dense layer computes together ([`Parameters::block_dot`](super::Parameters::block_dot)).
pub const UNIT_BLOCK: usize = 4;

/// [`dot`] of each of the [`UNIT_BLOCK`] consecutive rows at the start of `rows`
/// (each `x.len()` long) with `x`: the same partial sums in the same order as
/// [`dot`], so each result has `dot`'s bits. Side by side, the rows give the
/// processor four independent chains of sums where one `dot` has one, and each
/// chunk of `x` is loaded once for four rows. A `rows` shorter than the block
/// dots what is there, row by row (never so in a validated network).
#[inline(always)]
pub fn dot_block<T: Real>(rows: &[T], x: &[T]) -> [T; UNIT_BLOCK] {
    let len = x.len();
    let row = |r: usize| {
        let start = (r * len).min(rows.len());
        let end = ((r + 1) * len).min(rows.len());
        rows.get(start..end).unwrap_or(&[])
    };
    if rows.len() < UNIT_BLOCK * len {
        return core::array::from_fn(|r| dot(row(r), x));
    }
    let rows: [&[T]; UNIT_BLOCK] = core::array::from_fn(row);
    let mut s = [[T::ZERO; DOT_LANES]; UNIT_BLOCK];
    // `chunks_exact`, not `as_chunks` (Rust 1.88; core promises 1.85).
    fn lanes<T: Real>(v: &[T]) -> impl Iterator<Item = [T; DOT_LANES]> + '_ {
        v.chunks_exact(DOT_LANES)
            .map(|c| <[T; DOT_LANES]>::try_from(c).unwrap_or([T::ZERO; DOT_LANES]))
    }
    fn tail<T>(v: &[T], done: usize) -> &[T] {
        v.get(done..).unwrap_or(&[])
    }
    let done = len / DOT_LANES * DOT_LANES;
    let [r0, r1, r2, r3] = rows;
    let quads = lanes(r0).zip(lanes(r1)).zip(lanes(r2)).zip(lanes(r3));
    for (xk, (((w0, w1), w2), w3)) in lanes(x).zip(quads) {
        for (sr, wk) in s.iter_mut().zip([w0, w1, w2, w3]) {
            for c in 0..DOT_LANES {
                sr[c] = sr[c] + wk[c] * xk[c];
            }
        }
    }
    for (sr, row) in s.iter_mut().zip(rows) {
        for (sc, (&w, &x)) in sr.iter_mut().zip(tail(row, done).iter().zip(tail(x, done))) {
            *sc = *sc + w * x;
        }
    }
    s.map(sum_lanes)
}

/// [`dot_block`] of [`UNIT_BLOCK`] rows stored **interleaved**: `wt[k UNIT_BLOCK + r]`
/// is weight `k` of row `r` (`x.len()` weights a row), so that one vector of
/// `wt` holds weight `k` of every row. The same products go to the same partial
/// sums in the same order, and each row's partials meet in [`dot`]'s tree, so each
/// result has the bits `dot` gives its row; but the four rows' partial sums `c`
/// share a vector, and the tree sums vectors, where [`dot_block`] ends with a
/// horizontal sum per row. Callers pass whole blocks (`UNIT_BLOCK x.len()`
/// weights); a shorter `wt` sums the products it holds, without a panic.
#[inline(always)]
pub fn dot_block_interleaved<T: Real>(wt: &[T], x: &[T]) -> [T; UNIT_BLOCK] {
    // `s[c][r]`: partial sum `c` of row `r`.
    let mut s = [[T::ZERO; UNIT_BLOCK]; DOT_LANES];
    const CHUNK: usize = DOT_LANES * UNIT_BLOCK;
    let chunks = x.chunks_exact(DOT_LANES).zip(wt.chunks_exact(CHUNK));
    let mut done = 0;
    for (xk, wk) in chunks {
        for (c, sc) in s.iter_mut().enumerate() {
            for (r, src) in sc.iter_mut().enumerate() {
                *src = *src + wk[c * UNIT_BLOCK + r] * xk[c];
            }
        }
        done += DOT_LANES;
    }
    let (xt, wt) = (
        x.get(done..).unwrap_or(&[]),
        wt.get(done * UNIT_BLOCK..).unwrap_or(&[]),
    );
    for (c, sc) in s.iter_mut().enumerate() {
        let (Some(&xc), Some(wc)) = (xt.get(c), wt.get(c * UNIT_BLOCK..)) else {
            continue;
        };
        for (r, src) in sc.iter_mut().enumerate() {
            *src = *src + wc.get(r).copied().unwrap_or(T::ZERO) * xc;
        }
    }
    core::array::from_fn(|r| {
        ((s[0][r] + s[1][r]) + (s[2][r] + s[3][r])) + ((s[4][r] + s[5][r]) + (s[6][r] + s[7][r]))
    })
}
