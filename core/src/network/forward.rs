//! The forward pass over any parameter storage: [`Parameters`] (an `f64` slice in
//! the trainer, f16 bits decoded to `f32` in the runtime, [`F16Params`]), the dense
//! layers, and [`Network::forward`]'s [`Trace`].

use super::kernels::{dot, dot_block, UNIT_BLOCK};
use super::{
    input_features, lattice_logit, sigmoid, LayerSpan, Shape, INPUTS, MAX_HIDDEN_LAYERS, MAX_WIDTH,
    OUTPUTS,
};
use crate::quantize::f16_decode_finite;
use crate::real::Real;

/// The values a forward pass went through, which a backward pass needs: the
/// inputs, every hidden layer's pre-activations, and the two outputs before the
/// sigmoid. Fixed-size storage: no allocation.
#[derive(Clone, Copy, Debug)]
pub struct Trace<T> {
    /// The input features.
    pub input: [T; INPUTS],
    /// Pre-activations `z_l` of hidden layer `l` (the first `width_l` entries).
    pub pre: [[T; MAX_WIDTH]; MAX_HIDDEN_LAYERS],
    /// The outputs before the sigmoid.
    pub output: [T; OUTPUTS],
}

impl<T: Real> Default for Trace<T> {
    /// Every value 0.
    fn default() -> Self {
        Self {
            input: [T::ZERO; INPUTS],
            pre: [[T::ZERO; MAX_WIDTH]; MAX_HIDDEN_LAYERS],
            output: [T::ZERO; OUTPUTS],
        }
    }
}

impl<T: Real> Trace<T> {
    /// The point of the unit square: `sigmoid` of each output.
    #[inline]
    pub fn square_point(&self) -> [T; 2] {
        [sigmoid(self.output[0]), sigmoid(self.output[1])]
    }
}

/// Read access to a network's flat parameter array as `T`: an `f64` slice in the
/// trainer, f16 bits decoded to `f32` in the runtime ([`F16Params`]). Reads past
/// the end give 0 (never a panic).
pub trait Parameters<T: Real> {
    /// Whether the storage holds `T` and dots rows where they lie: a forward pass
    /// then needs one row of scratch, not a block of decoded rows (see
    /// [`Parameters::block_dot`]), and clears only that.
    const IN_PLACE: bool = false;
    /// Parameter `j`.
    fn get(&self, j: usize) -> T;
    /// Parameters `start..start + out.len()` into `out`.
    fn read(&self, start: usize, out: &mut [T]);
    /// `dot(row, x)` ([`dot`]) of the row `params[start..start + len]`,
    /// `len = min(x.len(), scratch.len())`: one unit of a dense layer. The default
    /// [`Parameters::read`]s the row into `scratch` first (what decoding storage
    /// needs; the caller owns the buffer so that a layer clears it once, not per
    /// unit); storage that holds `T` dots the row in place, with the same bits.
    #[inline(always)]
    fn row_dot(&self, start: usize, x: &[T], scratch: &mut [T]) -> T {
        read_dot(self, start, x, scratch)
    }
    /// [`Parameters::row_dot`] of the [`UNIT_BLOCK`] consecutive rows of length
    /// `x.len()` from `start`, each with exactly the bits `row_dot` gives it. The
    /// default dots the rows one by one; storage that holds `T` dots them together
    /// ([`dot_block`]), which keeps more multiply-adds in flight per row.
    #[inline(always)]
    fn block_dot(&self, start: usize, x: &[T], scratch: &mut [T]) -> [T; UNIT_BLOCK] {
        rows_one_by_one(self, start, x, scratch)
    }
}

/// [`Parameters::block_dot`] as [`UNIT_BLOCK`] calls of [`Parameters::row_dot`].
#[inline(always)]
pub(super) fn rows_one_by_one<T: Real, W: Parameters<T> + ?Sized>(
    w: &W,
    start: usize,
    x: &[T],
    scratch: &mut [T],
) -> [T; UNIT_BLOCK] {
    let len = x.len();
    core::array::from_fn(|r| w.row_dot(start.saturating_add(r * len), x, scratch))
}

/// [`Parameters::row_dot`] through a copy of the row in `scratch`.
#[inline(always)]
pub(super) fn read_dot<T: Real, W: Parameters<T> + ?Sized>(
    w: &W,
    start: usize,
    x: &[T],
    scratch: &mut [T],
) -> T {
    let len = x.len().min(scratch.len());
    let row = &mut scratch[..len];
    w.read(start, row);
    dot(row, x)
}

impl<T: Real> Parameters<T> for &[T] {
    const IN_PLACE: bool = true;
    #[inline]
    fn get(&self, j: usize) -> T {
        <[T]>::get(self, j).copied().unwrap_or(T::ZERO)
    }
    #[inline]
    fn read(&self, start: usize, out: &mut [T]) {
        match start
            .checked_add(out.len())
            .and_then(|end| <[T]>::get(self, start..end))
        {
            Some(src) => out.copy_from_slice(src),
            None => out.iter_mut().enumerate().for_each(|(k, o)| {
                *o = Parameters::get(self, start.saturating_add(k));
            }),
        }
    }
    /// The row dotted where it lies (the trainer's hot path: no copy); a row that
    /// runs past the end goes through [`Parameters::read`] (missing entries 0).
    #[inline(always)]
    fn row_dot(&self, start: usize, x: &[T], scratch: &mut [T]) -> T {
        let len = x.len().min(scratch.len());
        match start
            .checked_add(len)
            .and_then(|end| <[T]>::get(self, start..end))
        {
            Some(row) => dot(row, &x[..len]),
            None => read_dot(self, start, x, scratch),
        }
    }
    #[inline(always)]
    fn block_dot(&self, start: usize, x: &[T], scratch: &mut [T]) -> [T; UNIT_BLOCK] {
        let len = x.len();
        match start
            .checked_add(UNIT_BLOCK * len)
            .and_then(|end| <[T]>::get(self, start..end))
        {
            Some(rows) => dot_block(rows, x),
            None => rows_one_by_one(self, start, x, scratch),
        }
    }
}

/// Parameters stored as IEEE binary16 bits, all finite (blobs are validated so),
/// decoded exactly to `f32` by [`crate::quantize::f16_decode_finite`].
#[derive(Clone, Copy, Debug)]
pub struct F16Params<'a>(pub &'a [u16]);

impl Parameters<f32> for F16Params<'_> {
    #[inline]
    fn get(&self, j: usize) -> f32 {
        self.0.get(j).map_or(0.0, |&h| f16_decode_finite(h))
    }
    #[inline]
    fn read(&self, start: usize, out: &mut [f32]) {
        match start
            .checked_add(out.len())
            .and_then(|end| self.0.get(start..end))
        {
            // A plain loop over two slices: the compiler vectorizes the decode.
            Some(src) => {
                for (o, &h) in out.iter_mut().zip(src) {
                    *o = f16_decode_finite(h);
                }
            }
            None => out.iter_mut().enumerate().for_each(|(k, o)| {
                *o = self.get(start.saturating_add(k));
            }),
        }
    }
    /// The block's rows decoded into `scratch` in one pass, then [`dot_block`]
    /// (decoding them interleaved, [`super::dot_block_interleaved`]'s layout,
    /// scatters the decode's writes: twice as slow).
    #[inline(always)]
    fn block_dot(&self, start: usize, x: &[f32], scratch: &mut [f32]) -> [f32; UNIT_BLOCK] {
        let len = (UNIT_BLOCK * x.len()).min(scratch.len());
        let rows = &mut scratch[..len];
        self.read(start, rows);
        dot_block(rows, x)
    }
}

/// A network: a [`Shape`] and its [`Parameters`].
#[derive(Clone, Copy, Debug)]
pub struct Network<W> {
    /// The architecture.
    pub shape: Shape,
    /// The flat parameter array of the module documentation.
    pub params: W,
}

impl<W> Network<W> {
    /// Evaluates the network for the embedding row `row` ([`Shape::embedding_row`]
    /// of the instance and index; taken modulo the rows) on `input`
    /// ([`input_features`](super::input_features)) and records what a backward pass needs. `params(j)` must
    /// exist for `j < param_len()` (missing ones read as 0); `O(multiply_adds)`, no allocation.
    #[inline]
    pub fn forward<T: Real>(&self, row: u32, input: [T; INPUTS]) -> Trace<T>
    where
        W: Parameters<T>,
    {
        let mut trace = Trace::default();
        self.forward_into(row, input, &mut trace);
        trace
    }

    /// [`Network::forward`] into `trace` (the same bits): its input, each hidden
    /// layer's first `width_l` pre-activations and its outputs are written, the
    /// entries past a layer's width keep what they held. For a caller that keeps
    /// many traces (the trainer: thousands a step), this writes them in place
    /// rather than clearing and moving 3 kB per point.
    #[inline]
    pub fn forward_into<T: Real>(&self, row: u32, input: [T; INPUTS], trace: &mut Trace<T>)
    where
        W: Parameters<T>,
    {
        trace.input = input;
        let pre = &mut trace.pre;
        trace.output = self.run(row, &input, |l, o, z| {
            if let Some(slot) = pre.get_mut(l).and_then(|p| p.get_mut(o)) {
                *slot = z;
            }
        });
    }

    /// The two outputs before the sigmoid, as [`Network::forward`] computes them
    /// (the same operations in the same order, hence the same bits) without
    /// recording a [`Trace`]: what samplers call.
    #[inline]
    pub fn evaluate<T: Real>(&self, row: u32, input: [T; INPUTS]) -> [T; OUTPUTS]
    where
        W: Parameters<T>,
    {
        self.run(row, &input, |_, _, _| {})
    }

    /// The point of the unit square: `sigmoid` of each output of
    /// [`Network::evaluate`].
    #[inline]
    pub fn square_point<T: Real>(&self, row: u32, input: [T; INPUTS]) -> [T; 2]
    where
        W: Parameters<T>,
    {
        self.evaluate(row, input).map(sigmoid)
    }

    /// [`Network::forward_into`] of index `i` of instance `k` at the normalized
    /// condition `c` and metallic `m`: embedding row [`Shape::embedding_row`]`(k, i)`,
    /// input [`input_features`]`(shape, c, m, k, i)`.
    #[inline]
    pub fn trace_point_into<T: Real>(&self, c: [T; 2], m: T, k: u32, i: u32, trace: &mut Trace<T>)
    where
        W: Parameters<T>,
    {
        let input = input_features(&self.shape, c, m, k, i);
        self.forward_into(self.shape.embedding_row(k, i), input, trace);
    }

    /// [`Network::square_point`] of index `i` of instance `k` at the normalized
    /// condition `c` and metallic `m` (the row and input of
    /// [`Network::trace_point_into`]): what samplers serve.
    #[inline]
    pub fn square_point_at<T: Real>(&self, c: [T; 2], m: T, k: u32, i: u32) -> [T; 2]
    where
        W: Parameters<T>,
    {
        let input = input_features(&self.shape, c, m, k, i);
        self.square_point(self.shape.embedding_row(k, i), input)
    }

    /// The forward pass, in this order of operations (which readers in other
    /// languages reproduce): per unit `acc = b[o]`, then `acc += E[row][o]` in the
    /// first hidden layer, then `acc += dot(W[o], x)` ([`dot`]); with a lattice
    /// residual, each output then `+= lattice_logit(input)[o]`.
    /// `record(layer, unit, pre_activation)` sees every hidden pre-activation.
    #[inline(always)]
    fn run<T: Real>(
        &self,
        row: u32,
        input: &[T; INPUTS],
        record: impl FnMut(usize, usize, T),
    ) -> [T; OUTPUTS]
    where
        W: Parameters<T>,
    {
        // Rows decoded from storage that does not hold `T` (one block at a time),
        // cleared once per evaluation rather than per layer; storage that holds
        // `T` reads its rows in place and needs a row at most.
        if W::IN_PLACE {
            let mut scratch = [T::ZERO; MAX_WIDTH];
            self.run_with(row, input, &mut scratch, record)
        } else {
            let mut scratch = [T::ZERO; UNIT_BLOCK * MAX_WIDTH];
            self.run_with(row, input, &mut scratch, record)
        }
    }

    /// [`Network::run`] with its scratch buffer.
    #[inline(always)]
    fn run_with<T: Real>(
        &self,
        row: u32,
        input: &[T; INPUTS],
        scratch: &mut [T],
        mut record: impl FnMut(usize, usize, T),
    ) -> [T; OUTPUTS]
    where
        W: Parameters<T>,
    {
        let shape = &self.shape;
        let w = &self.params;
        let act = shape.activation;
        // Two buffers used in turn as a layer's input and output (by parity, not
        // swapped: a swap copies both).
        let mut buffers = [[T::ZERO; MAX_WIDTH]; 2];
        buffers[0][..INPUTS].copy_from_slice(input);
        let embedding = shape.embedding_offset(row);
        let hidden = shape.layers as usize;
        let mut out = [T::ZERO; OUTPUTS];
        for (l, span) in shape.layers().enumerate() {
            let [even, odd] = &mut buffers;
            let (a, b) = if l % 2 == 0 { (even, odd) } else { (odd, even) };
            let (x, width) = (&a[..span.fan_in], span.width);
            if l < hidden {
                let first = (l == 0).then_some(embedding);
                layer(w, span, first, x, &mut b[..width], scratch, |o, z| {
                    record(l, o, z);
                    act.apply(z)
                });
            } else {
                layer(w, span, None, x, &mut out, scratch, |_, z| z);
            }
        }
        if shape.lattice_residual {
            let base = lattice_logit(input);
            for (o, b) in out.iter_mut().zip(base) {
                *o = *o + b;
            }
        }
        out
    }
}

/// One dense layer: `out[o] = finish(o, acc)` with
/// `acc = (w(bias + o) [+ w(extra + o)]) + dot(row_o, x)`, `row_o` the `fan_in`
/// parameters from `span.weights + o fan_in`, `bias = span.bias` ([`dot`] fixes the
/// order of the sum; units go in blocks of [`UNIT_BLOCK`], [`Parameters::block_dot`]).
#[inline(always)]
fn layer<T: Real>(
    w: &impl Parameters<T>,
    span: LayerSpan,
    extra: Option<usize>,
    x: &[T],
    out: &mut [T],
    scratch: &mut [T],
    mut finish: impl FnMut(usize, T) -> T,
) {
    let (off, bias) = (span.weights, span.bias);
    let fan_in = x.len().min(MAX_WIDTH);
    let x = &x[..fan_in];
    // The biases (and the embedding row) in one vectorized read each, not a
    // bounds-checked decode per unit: `out` holds each unit's `acc` until its dot.
    w.read(bias, out);
    if let Some(e) = extra {
        let len = out.len().min(scratch.len());
        let extra = &mut scratch[..len];
        w.read(e, extra);
        for (acc, &v) in out.iter_mut().zip(extra.iter()) {
            *acc = *acc + v;
        }
    }
    let first = out.len() / UNIT_BLOCK * UNIT_BLOCK;
    let mut blocks = out.chunks_exact_mut(UNIT_BLOCK);
    for (b, slots) in blocks.by_ref().enumerate() {
        let o = b * UNIT_BLOCK;
        let dots = w.block_dot(off + o * fan_in, x, scratch);
        for (r, (slot, d)) in slots.iter_mut().zip(dots).enumerate() {
            *slot = finish(o + r, *slot + d);
        }
    }
    for (r, slot) in blocks.into_remainder().iter_mut().enumerate() {
        let o = first + r;
        *slot = finish(o, *slot + w.row_dot(off + o * fan_in, x, scratch));
    }
}
