//! A network's parameters laid out for a CPU's forward pass: [`InterleavedParams`].
//!
//! The flat array of the module documentation stores each dense layer's weights
//! row-major by output unit, the order a blob and a shader keep. A forward pass
//! computes [`UNIT_BLOCK`] units at a time ([`Parameters::block_dot`]); with their
//! rows side by side in memory, each row's partial sums end in a horizontal sum
//! across a vector's lanes. Interleaving a block's rows (weight `k` of the four
//! rows next to each other) puts the four units' partial sums in one vector, so
//! the sums' last steps add whole vectors ([`dot_block_interleaved`]), with the
//! same operations in the same order: the same bits.
//!
//! Only the weights of whole blocks move, within the block's own span of the
//! array: the embedding `E`, the biases and a layer's last `width mod 4` rows
//! (the output layer's two) keep their places, and the array keeps its length.

use super::forward::{read_dot, rows_one_by_one, Parameters};
use super::kernels::{dot, dot_block_interleaved, UNIT_BLOCK};
use super::{LayerSpan, Shape, MAX_HIDDEN_LAYERS, MAX_WIDTH};
use crate::real::Real;

/// Parameters as `T` in the interleaved layout of the module documentation
/// ([`interleave`] writes it): the same network as the row-major array it was made
/// from, read faster. [`Parameters::get`] and [`Parameters::read`] answer in the
/// row-major numbering; reads past the end give 0 (never a panic).
#[derive(Clone, Copy, Debug)]
pub struct InterleavedParams<'a, T> {
    /// Worked out once rather than per read.
    blocks: Blocks,
    params: &'a [T],
}

/// Each layer's weights that whole blocks of rows hold: `(start, end, fan_in)`
/// (empty past the layers).
#[derive(Clone, Copy, Debug)]
struct Blocks([(usize, usize, usize); LAYERS]);

/// Most dense layers a network has: the hidden ones and the output layer.
const LAYERS: usize = MAX_HIDDEN_LAYERS + 1;

impl<'a, T> InterleavedParams<'a, T> {
    /// `params` in the interleaved layout of `shape`'s network ([`interleave`]).
    pub fn new(shape: Shape, params: &'a [T]) -> Self {
        Self {
            blocks: Blocks::new(&shape),
            params,
        }
    }
}

impl Blocks {
    fn new(shape: &Shape) -> Self {
        let mut blocks = [(0, 0, 1); LAYERS];
        for (b, span) in blocks.iter_mut().zip(shape.layers()) {
            let (start, end) = blocked(&span);
            *b = (start, end, span.fan_in);
        }
        Self(blocks)
    }

    /// The blocked weights `(start, fan_in)` of the layer that holds `j`, if any.
    #[inline(always)]
    fn holding(&self, j: usize) -> Option<(usize, usize)> {
        (self.0.iter())
            .find(|&&(b0, b1, _)| (b0..b1).contains(&j))
            .map(|&(b0, _, fan_in)| (b0, fan_in))
    }

    /// [`interleaved_index`] of `j`.
    #[inline(always)]
    fn index(&self, j: usize) -> usize {
        self.holding(j)
            .map_or(j, |(start, fan_in)| block_index(start, fan_in, j))
    }

    /// Whether `start..start + len` meets the weights of a whole block.
    #[inline(always)]
    fn meet(&self, start: usize, len: usize) -> bool {
        let end = start.saturating_add(len);
        self.0.iter().any(|&(b0, b1, _)| start < b1 && b0 < end)
    }
}

/// The part of `span`'s weights that whole blocks of rows hold: `(start, end)`.
#[inline(always)]
fn blocked(span: &LayerSpan) -> (usize, usize) {
    let rows = span.width / UNIT_BLOCK * UNIT_BLOCK;
    (span.weights, span.weights + rows * span.fan_in)
}

/// Where row-major parameter `j` of `shape`'s network lies in the interleaved
/// layout: weight `k` of row `r` of a layer's block `b` at
/// `weights + b UNIT_BLOCK fan_in + k UNIT_BLOCK + r`; every other parameter
/// where it was. A permutation of `0..shape.param_len()`; `O(layers)`.
pub fn interleaved_index(shape: &Shape, j: usize) -> usize {
    Blocks::new(shape).index(j)
}

/// [`interleaved_index`] of `j` within the blocked weights from `start` of a
/// layer of fan-in `fan_in >= 1`.
#[inline(always)]
fn block_index(start: usize, fan_in: usize, j: usize) -> usize {
    let fan_in = fan_in.max(1);
    let block = UNIT_BLOCK * fan_in;
    let off = j.saturating_sub(start);
    let (b, within) = (off / block, off % block);
    let (r, k) = (within / fan_in, within % fan_in);
    start + b * block + k * UNIT_BLOCK + r
}

/// Rewrites `params`, the row-major array of `shape`'s network, in place into
/// the interleaved layout ([`InterleavedParams`]). `None`, and `params`
/// untouched, unless it holds exactly [`Shape::param_len`] values. `O(param_len)`.
pub fn interleave<T: Real>(shape: &Shape, params: &mut [T]) -> Option<()> {
    if params.len() != shape.param_len() {
        return None;
    }
    let mut block = [T::ZERO; UNIT_BLOCK * MAX_WIDTH];
    for &(start, end, fan_in) in &Blocks::new(shape).0 {
        let len = UNIT_BLOCK * fan_in;
        for rows in params.get_mut(start..end)?.chunks_exact_mut(len) {
            let copy = block.get_mut(..len)?;
            copy.copy_from_slice(rows);
            for (r, row) in copy.chunks_exact(fan_in).enumerate() {
                for (k, &w) in row.iter().enumerate() {
                    if let Some(slot) = rows.get_mut(k * UNIT_BLOCK + r) {
                        *slot = w;
                    }
                }
            }
        }
    }
    Some(())
}

impl<T: Real> InterleavedParams<'_, T> {
    /// The interleaved block of rows that starts at row-major offset `start`
    /// with rows of length `len`, if one does.
    #[inline(always)]
    fn block_at(&self, start: usize, len: usize) -> Option<&[T]> {
        let (b0, fan_in) = self.blocks.holding(start)?;
        let block = UNIT_BLOCK * fan_in;
        if fan_in != len || (start - b0).checked_rem(block) != Some(0) {
            return None;
        }
        self.params.get(start..start + block)
    }
}

impl<T: Real> Parameters<T> for InterleavedParams<'_, T> {
    const IN_PLACE: bool = true;

    #[inline]
    fn get(&self, j: usize) -> T {
        let at = self.blocks.index(j);
        self.params.get(at).copied().unwrap_or(T::ZERO)
    }

    /// A copy where the range meets no block's weights (biases, `E`: the forward
    /// pass's reads), else parameter by parameter.
    #[inline]
    fn read(&self, start: usize, out: &mut [T]) {
        if self.blocks.meet(start, out.len()) {
            for (k, o) in out.iter_mut().enumerate() {
                *o = self.get(start.saturating_add(k));
            }
        } else {
            Parameters::read(&self.params, start, out);
        }
    }

    /// In place where the row is not in a block (a layer's last `width mod 4`
    /// rows), else through [`Parameters::read`].
    #[inline(always)]
    fn row_dot(&self, start: usize, x: &[T], scratch: &mut [T]) -> T {
        let len = x.len().min(scratch.len());
        let row = start
            .checked_add(len)
            .and_then(|end| self.params.get(start..end));
        match row {
            Some(row) if !self.blocks.meet(start, len) => dot(row, &x[..len]),
            _ => read_dot(self, start, x, scratch),
        }
    }

    /// [`dot_block_interleaved`] where `start` begins a block of rows of length
    /// `x.len()` (every call of a forward pass), else row by row.
    #[inline(always)]
    fn block_dot(&self, start: usize, x: &[T], scratch: &mut [T]) -> [T; UNIT_BLOCK] {
        match self.block_at(start, x.len()) {
            Some(rows) => dot_block_interleaved(rows, x),
            None => rows_one_by_one(self, start, x, scratch),
        }
    }
}
