//! The conditional sampler's network (paper §4), written once for the trainer
//! (`f64`) and the runtime (`f32`, the precision a shader reproduces).
//!
//! Point `i` of instance `k` of the set for condition `c` is
//!
//! ```text
//! x_i(c, k) = M( sigmoid( g(i, features(c, k, i)) ) )
//! ```
//!
//! * `features` ([`input_features`], [`INPUTS`] numbers): five polynomial features of
//!   the condition normalized to `[0,1]^2` ([`condition_features`]), the instance's
//!   pseudo-random offset `z_k` ([`instance_offset`]), and two points of the unit
//!   square ([`lattice_features`]): the rank-1 lattice point
//!   `l_i = (i/N, frac(i g / N))` shifted by `z_k` on the torus, `p = frac(l_i + z_k)`,
//!   and `l_i` itself. The shifted lattice makes every instance a different set by
//!   construction (a warp of `p` is a warp of a randomly shifted lattice, the way a
//!   renderer warps a scrambled point); `l_i` names the index the way `E[i]` does,
//!   so the network can also place each point on its own. A discontinuity in `z_k`
//!   (where `p` wraps) costs nothing: instances are separate sets, and only
//!   continuity in the condition matters (table interpolation).
//! * `g` ([`Network::forward`]): a multilayer perceptron. Its first hidden layer adds
//!   a learned per-index vector `E[i]` (the paper's per-index embedding `e_i`,
//!   composed with the first layer's weights: an `H`-wide bias per index costs no
//!   multiply at run time).
//! * With `M` [instance slots](Shape::with_instance_slots), instance `k` is slot
//!   `s = k mod M`: its offset is `z_s` and its row of `E` is `s n + i`, so every
//!   point of every slot has its own learned bias and the network can place each
//!   slot's points one by one, as the direction optimizer places one set's, while
//!   the slots' different offsets (and the trainer's union term) keep them
//!   different sets. Instances then wrap modulo `M`, as a point table's wrap
//!   modulo `S`. Hidden activations are [`Activation::Relu`] or
//!   [`Activation::Silu`]; the output layer has two linear units.
//! * `sigmoid` maps the two outputs onto the open unit square; `M` is the domain's
//!   equal-area map (for BRDF samplers the hemisphere map of
//!   [`crate::sphere::square_to_hemisphere`]).
//! * With a [lattice residual](Shape::lattice_residual) the outputs are a residual
//!   on the logit of the shifted lattice point, `o_a + ln(p_a / (1 - p_a))`, so that a
//!   zero output leaves `p` where it is; the caller's map is then a warp of primary
//!   sample space (`crate::conditional::PointWarp::BrdfMixture`).
//!
//! Parameters are one flat array in this order ([`Shape::param_len`]):
//!
//! ```text
//! E        R x h1          per-point bias of the first hidden layer, R = max(M, 1) n
//!                          rows: row i = index i (M = 0), s n + i = index i of slot s
//! W1, b1   h1 x INPUTS, h1 first hidden layer, row-major by output unit
//! Wl, bl   hl x h(l-1), hl further hidden layers l = 2..=L
//! Wo, bo   2 x hL, 2       output layer
//! ```
//!
//! Everything here is `O(1)` in the number of points, allocation-free and total:
//! indices wrap modulo `n`, and a shape that does not fit [`MAX_WIDTH`] /
//! [`MAX_HIDDEN_LAYERS`] is rejected by [`Shape::new`].

use crate::quantize::f16_decode_finite;
use crate::real::Real;

/// Number of input features of the network: 5 of the condition, 2 of the instance
/// offset, 4 of the shifted lattice point.
pub const INPUTS: usize = CONDITION_FEATURES + 2 + 4;

/// Number of condition features ([`condition_features`]).
pub const CONDITION_FEATURES: usize = 5;

/// Largest hidden width a [`Shape`] may have.
pub const MAX_WIDTH: usize = 128;

/// Largest number of hidden layers a [`Shape`] may have.
pub const MAX_HIDDEN_LAYERS: usize = 3;

/// Number of network outputs (a point of the unit square, before the sigmoid).
pub const OUTPUTS: usize = 2;

/// The hidden layers' nonlinearity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Activation {
    /// `max(0, x)`: no transcendental per unit, the cheapest at run time.
    Relu = 0,
    /// `x sigmoid(x)` (SiLU / swish): smooth, one `exp` per unit.
    Silu = 1,
}

impl Activation {
    /// The activation with this code, if any.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            0 => Some(Self::Relu),
            1 => Some(Self::Silu),
            _ => None,
        }
    }

    /// `act(x)`.
    #[inline]
    pub fn apply<T: Real>(self, x: T) -> T {
        match self {
            Self::Relu => x.max(T::ZERO),
            Self::Silu => x * sigmoid(x),
        }
    }

    /// `d act / dx` at `x` (for `Relu`, 0 at `x <= 0`).
    #[inline]
    pub fn derivative<T: Real>(self, x: T) -> T {
        match self {
            Self::Relu => {
                if x > T::ZERO {
                    T::ONE
                } else {
                    T::ZERO
                }
            }
            Self::Silu => {
                let s = sigmoid(x);
                s * (T::ONE + x * (T::ONE - s))
            }
        }
    }
}

/// The logistic function `1 / (1 + exp(-x))`, in `(0,1)` for finite `x` (saturating
/// to exactly 0 or 1 only beyond the type's range).
#[inline]
pub fn sigmoid<T: Real>(x: T) -> T {
    T::ONE / (T::ONE + (-x).exp())
}

/// The architecture of a network: points per set, hidden widths, activation, and the
/// rank-1 lattice generator of its input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    n: u32,
    hidden: [u32; MAX_HIDDEN_LAYERS],
    layers: u32,
    activation: Activation,
    lattice_generator: u32,
    lattice_residual: bool,
    instance_slots: u32,
}

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

impl Shape {
    /// A shape with `n >= 1` points per set, `hidden.len()` in
    /// `1..=MAX_HIDDEN_LAYERS` hidden layers of widths in `1..=MAX_WIDTH`, and the
    /// lattice generator `g` (any value; `g` coprime to `n` makes the lattice's second
    /// coordinate a permutation). `None` if a count is out of range.
    pub fn new(
        n: u32,
        hidden: &[u32],
        activation: Activation,
        lattice_generator: u32,
    ) -> Option<Self> {
        if n == 0 || hidden.is_empty() || hidden.len() > MAX_HIDDEN_LAYERS {
            return None;
        }
        let mut widths = [0u32; MAX_HIDDEN_LAYERS];
        for (w, &h) in widths.iter_mut().zip(hidden) {
            if h == 0 || h as usize > MAX_WIDTH {
                return None;
            }
            *w = h;
        }
        Some(Self {
            n,
            hidden: widths,
            layers: hidden.len() as u32,
            activation,
            lattice_generator,
            lattice_residual: false,
            instance_slots: 0,
        })
    }

    /// The shape with `slots` instance slots (`0`, what [`Shape::new`] makes: every
    /// instance its own offset and one embedding row per index), or `None` if
    /// `slots n` or the embedding `slots n h1` does not fit in a `u32`.
    ///
    /// With `slots = M >= 1`, instance `k` is slot `s = k mod M`: its offset is
    /// `z_s` ([`instance_offset`] of `s`) and its first hidden layer adds the row
    /// `E[s n + i]`, so each slot is a set the network can place point by point
    /// (the embedding gives every point of every slot its own learned bias), and
    /// instances wrap modulo `M` as a point table's do.
    pub fn with_instance_slots(self, slots: u32) -> Option<Self> {
        // Both products in u128: `M n` alone can come near 2^64.
        let numbers = slots.max(1) as u128 * self.n as u128 * self.hidden[0] as u128;
        if numbers > u32::MAX as u128 {
            return None;
        }
        Some(Self {
            instance_slots: slots,
            ..self
        })
    }

    /// Instance slots `M` ([`Shape::with_instance_slots`]; 0: none).
    pub fn instance_slots(&self) -> u32 {
        self.instance_slots
    }

    /// The instance whose offset instance `k` uses: `k` itself without slots,
    /// else its slot `k mod M`.
    #[inline]
    pub fn instance_key(&self, k: u32) -> u32 {
        match self.instance_slots {
            0 => k,
            m => k % m,
        }
    }

    /// The row of `E` that index `i` of instance `k` adds: `i mod n` without
    /// slots, else `(k mod M) n + (i mod n)`. What [`Network::forward`] takes.
    #[inline]
    pub fn embedding_row(&self, k: u32, i: u32) -> u32 {
        let i = i % self.n;
        match self.instance_slots {
            0 => i,
            // `M n` fits in a u32 (checked by `with_instance_slots`).
            _ => self.instance_key(k) * self.n + i,
        }
    }

    /// Rows of `E`: `max(M, 1) n`.
    #[inline]
    pub fn embedding_rows(&self) -> usize {
        self.instance_slots.max(1) as usize * self.n as usize
    }

    /// The shape with the outputs a residual on [`lattice_logit`] (`true`) or plain
    /// (`false`, what [`Shape::new`] makes).
    pub fn with_lattice_residual(self, lattice_residual: bool) -> Self {
        Self {
            lattice_residual,
            ..self
        }
    }

    /// Whether the outputs are `o + lattice_logit(input)` (module docs).
    pub fn lattice_residual(&self) -> bool {
        self.lattice_residual
    }

    /// Points per set `n` (the number of per-index rows of `E` per slot).
    pub fn n(&self) -> u32 {
        self.n
    }

    /// The hidden widths, first layer first.
    pub fn hidden(&self) -> &[u32] {
        &self.hidden[..self.layers as usize]
    }

    /// The hidden layers' nonlinearity.
    pub fn activation(&self) -> Activation {
        self.activation
    }

    /// The rank-1 lattice generator `g` of [`lattice_point`].
    pub fn lattice_generator(&self) -> u32 {
        self.lattice_generator
    }

    /// Number of parameters: `max(M, 1) n h1 +` [`Shape::multiply_adds`].
    pub fn param_len(&self) -> usize {
        self.first_layer_offset() + self.multiply_adds()
    }

    /// Multiply-adds of one forward pass (the run-time cost of a network sample,
    /// besides the activations and the map): `sum over layers (out in + out)` with
    /// the input layer of width [`INPUTS`] and the output layer of width
    /// [`OUTPUTS`], i.e. the parameters after `E`. Independent of `n`, so it cannot
    /// overflow however large `n` is.
    pub fn multiply_adds(&self) -> usize {
        self.spans(0)
            .last()
            .map_or(0, |last| last.bias + last.width)
    }

    /// The dense layers in the order of the parameter array: the hidden layers,
    /// first first, then the output layer of width [`OUTPUTS`]; the first has fan-in
    /// [`INPUTS`], each next one the previous width. Offsets are into the whole
    /// array (after `E`, from [`Shape::first_layer_offset`]).
    pub fn layers(&self) -> impl Iterator<Item = LayerSpan> {
        self.spans(self.first_layer_offset())
    }

    /// [`Shape::layers`] with the first layer's weights at `start`.
    fn spans(&self, start: usize) -> impl Iterator<Item = LayerSpan> {
        let (hidden, layers) = (self.hidden, self.layers as usize);
        let widths = (0..layers).map(move |l| hidden[l] as usize);
        let (mut weights, mut fan_in) = (start, INPUTS);
        widths.chain(core::iter::once(OUTPUTS)).map(move |width| {
            let span = LayerSpan {
                weights,
                bias: weights + width * fan_in,
                fan_in,
                width,
            };
            weights = span.bias + width;
            fan_in = width;
            span
        })
    }

    /// Offset of row `row mod rows` of `E` ([`Shape::embedding_row`],
    /// [`Shape::embedding_rows`]) in the parameter array.
    #[inline]
    pub fn embedding_offset(&self, row: u32) -> usize {
        (row as usize % self.embedding_rows()) * self.hidden[0] as usize
    }

    /// Offset of the first hidden layer's weights (its biases follow the weights).
    pub fn first_layer_offset(&self) -> usize {
        self.embedding_rows() * self.hidden[0] as usize
    }
}

/// Where one dense layer lies in the flat parameter array ([`Shape::layers`]): its
/// `width x fan_in` weights row-major by output unit from `weights`, then its
/// `width` biases from `bias = weights + width fan_in`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LayerSpan {
    /// Offset of the first weight (row 0 of `W`).
    pub weights: usize,
    /// Offset of the first bias.
    pub bias: usize,
    /// Inputs per unit (the length of a row of `W`).
    pub fan_in: usize,
    /// Units (rows of `W`, biases).
    pub width: usize,
}

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
fn rows_one_by_one<T: Real, W: Parameters<T> + ?Sized>(
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
fn read_dot<T: Real, W: Parameters<T> + ?Sized>(
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
    /// The block's rows decoded into `scratch` in one pass, then [`dot_block`].
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
    /// ([`input_features`]) and records what a backward pass needs. `params(j)` must
    /// exist for `j < param_len()` (missing ones read as 0); `O(multiply_adds)`, no allocation.
    #[inline]
    pub fn forward<T: Real>(&self, row: u32, input: [T; INPUTS]) -> Trace<T>
    where
        W: Parameters<T>,
    {
        let mut pre = [[T::ZERO; MAX_WIDTH]; MAX_HIDDEN_LAYERS];
        let output = self.run(row, &input, |l, o, z| {
            if let Some(slot) = pre.get_mut(l).and_then(|p| p.get_mut(o)) {
                *slot = z;
            }
        });
        Trace { input, pre, output }
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
        mut record: impl FnMut(usize, usize, T),
    ) -> [T; OUTPUTS]
    where
        W: Parameters<T>,
    {
        let shape = &self.shape;
        let w = &self.params;
        let act = shape.activation;
        // Two buffers used in turn as a layer's input and output.
        let mut a = [T::ZERO; MAX_WIDTH];
        let mut b = [T::ZERO; MAX_WIDTH];
        // Rows decoded from storage that does not hold `T` (one block at a time),
        // cleared once per evaluation rather than per layer.
        let mut scratch = [T::ZERO; UNIT_BLOCK * MAX_WIDTH];
        a[..INPUTS].copy_from_slice(input);
        let embedding = shape.embedding_offset(row);
        let hidden = shape.layers as usize;
        let mut out = [T::ZERO; OUTPUTS];
        for (l, span) in shape.layers().enumerate() {
            let (x, width) = (&a[..span.fan_in], span.width);
            if l < hidden {
                let first = (l == 0).then_some(embedding);
                layer(w, span, first, x, &mut b[..width], &mut scratch, |o, z| {
                    record(l, o, z);
                    act.apply(z)
                });
                core::mem::swap(&mut a, &mut b);
            } else {
                layer(w, span, None, x, &mut out, &mut scratch, |_, z| z);
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

/// Units a dense layer computes together ([`Parameters::block_dot`]).
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
    scratch: &mut [T; UNIT_BLOCK * MAX_WIDTH],
    mut finish: impl FnMut(usize, T) -> T,
) {
    let (off, bias) = (span.weights, span.bias);
    let fan_in = x.len().min(MAX_WIDTH);
    let x = &x[..fan_in];
    // The biases (and the embedding row) in one vectorized read each, not a
    // bounds-checked decode per unit: `out` holds each unit's `acc` until its dot.
    w.read(bias, out);
    if let Some(e) = extra {
        let extra = &mut scratch[..out.len().min(MAX_WIDTH)];
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

/// The pseudo-random offset `z_k` in `[0,1)^2` of instance `k`: the top 24 bits of
/// `hash_u32(2k)` and `hash_u32(2k + 1)` (wrapping) times `2^-24`, exact in `f32`
/// and `f64`. Every `u32` is an instance.
#[inline]
pub fn instance_offset<T: Real>(k: u32) -> [T; 2] {
    let unit = |h: u32| T::of((h >> 8) as f64 * (1.0 / 16_777_216.0));
    let k2 = k.wrapping_mul(2);
    [unit(hash_u32(k2)), unit(hash_u32(k2.wrapping_add(1)))]
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
/// `[0,1]^2`): `[condition_features(c), 2 z - 1, lattice_features(p, l_i)]` with
/// `z` the offset of [`Shape::instance_key`]`(k)` (`z_k` without slots), `p` the
/// [`shifted_lattice_point`] and `l_i` the [`lattice_point`].
#[inline]
pub fn input_features<T: Real>(shape: &Shape, c: [T; 2], k: u32, i: u32) -> [T; INPUTS] {
    let z = instance_offset::<T>(shape.instance_key(k));
    let (n, g) = (shape.n, shape.lattice_generator);
    let p = shifted_lattice_point(i, n, g, z);
    let cf = condition_features(c);
    let lf = lattice_features(p, lattice_point(i, n, g));
    let two = T::of(2.0);
    [
        cf[0],
        cf[1],
        cf[2],
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

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn shape(act: Activation) -> Shape {
        Shape::new(4, &[3, 2], act, 3).unwrap()
    }

    #[test]
    fn param_len_counts_every_matrix_and_bias() {
        let s = shape(Activation::Relu);
        // E 4x3, W1 3x11 + 3, W2 2x3 + 2, Wo 2x2 + 2.
        assert_eq!(s.param_len(), 12 + 36 + 8 + 6);
        assert_eq!(s.multiply_adds(), 36 + 8 + 6);
        let span = |weights, fan_in, width| LayerSpan {
            weights,
            bias: weights + width * fan_in,
            fan_in,
            width,
        };
        let want = [span(12, 11, 3), span(48, 3, 2), span(56, 2, 2)];
        // E 4x3, then W1/b1 at 12/45, W2/b2 at 48/54, Wo/bo at 56/60.
        assert!(s.layers().eq(want));
        assert!(Shape::new(0, &[3], Activation::Relu, 1).is_none());
        assert!(Shape::new(4, &[], Activation::Relu, 1).is_none());
        assert!(Shape::new(4, &[129], Activation::Relu, 1).is_none());
        assert!(Shape::new(4, &[1, 1, 1, 1], Activation::Relu, 1).is_none());
    }

    /// The parameters of the tests' [`shape`] networks (62 of them).
    fn test_params() -> [f64; 62] {
        core::array::from_fn(|j| ((j * 37 % 23) as f64 - 11.0) / 9.0)
    }

    /// The network of [`shape`] written out as explicit matrix products for row 2 of
    /// `E`: the two hidden pre-activations and the outputs.
    fn explicit_forward(
        p: &[f64; 62],
        act: Activation,
        x: &[f64; INPUTS],
    ) -> ([f64; 3], [f64; 2], [f64; 2]) {
        let (e, w1, b1) = (&p[6..9], &p[12..45], &p[45..48]);
        let h1: [f64; 3] = core::array::from_fn(|o| {
            b1[o] + e[o] + (0..INPUTS).map(|k| w1[o * INPUTS + k] * x[k]).sum::<f64>()
        });
        let (w2, b2) = (&p[48..54], &p[54..56]);
        let a1 = h1.map(|z| act.apply(z));
        let h2: [f64; 2] =
            core::array::from_fn(|o| b2[o] + (0..3).map(|k| w2[o * 3 + k] * a1[k]).sum::<f64>());
        let a2 = h2.map(|z| act.apply(z));
        let (wo, bo) = (&p[56..60], &p[60..62]);
        let out: [f64; 2] =
            core::array::from_fn(|o| bo[o] + (0..2).map(|k| wo[o * 2 + k] * a2[k]).sum::<f64>());
        (h1, h2, out)
    }

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < tol)
    }

    /// The forward pass against the same network written out as explicit matrix
    /// products.
    #[test]
    fn forward_equals_explicit_matrix_products() {
        for act in [Activation::Relu, Activation::Silu] {
            let s = shape(act);
            let p = test_params();
            let net = Network {
                shape: s,
                params: &p[..],
            };
            let x: [f64; INPUTS] = core::array::from_fn(|k| (k as f64 - 5.0) / 7.0);
            let i = 6; // wraps to row 2 of E
            let t = net.forward(i, x);
            assert_eq!(
                net.evaluate(i, x),
                t.output,
                "evaluate and forward agree bit for bit"
            );
            let (h1, h2, out) = explicit_forward(&p, act, &x);
            assert!(close(&t.pre[0][..3], &h1, 1e-14));
            assert!(close(&t.pre[1][..2], &h2, 1e-14));
            assert!(close(&t.output, &out, 1e-14));
        }
    }

    /// With a lattice residual the outputs are the explicit matrix products plus
    /// `ln(p / (1 - p))` of the shifted lattice point `p`, taken from
    /// [`shifted_lattice_point`] (not read back from the features); with all-zero
    /// parameters the square point is `p` itself.
    #[test]
    fn lattice_residual_adds_the_logit_of_the_shifted_lattice_point() {
        for act in [Activation::Relu, Activation::Silu] {
            let s = shape(act).with_lattice_residual(true);
            let (c, k, i) = ([0.3, 0.7], 5, 6); // i wraps to row 2 of E
            let x = input_features::<f64>(&s, c, k, i);
            let z = instance_offset::<f64>(k);
            let p = shifted_lattice_point(i, s.n(), s.lattice_generator(), z);
            // Away from the clamp at LATTICE_LOGIT_EPS, where the logit is exact.
            assert!(p.iter().all(|&q| (0.01..0.99).contains(&q)), "{p:?}");
            let logit = p.map(|q| Real::ln(q / (1.0 - q)));
            let params = test_params();
            let net = Network {
                shape: s,
                params: &params[..],
            };
            let (_, _, out) = explicit_forward(&params, act, &x);
            let want = [out[0] + logit[0], out[1] + logit[1]];
            let got = net.evaluate(i, x);
            assert!(close(&got, &want, 1e-12), "{got:?} vs {want:?}");
            let zero = [0.0; 62];
            let net = Network {
                shape: s,
                params: &zero[..],
            };
            assert!(close(&net.square_point(i, x), &p, 1e-12));
        }
    }

    /// With `M` instance slots, instance `k` reads the offset of `k mod M` and the
    /// embedding row `(k mod M) n + i mod n`, placed before the first layer: the
    /// outputs against explicit matrix products with that row; without slots the
    /// row is `i mod n` whatever the instance.
    #[test]
    fn instance_slots_give_each_slot_its_own_rows_and_offset() {
        let base = Shape::new(4, &[3], Activation::Relu, 3).unwrap();
        assert_eq!(base.with_instance_slots(0), Some(base));
        assert_eq!((base.instance_key(9), base.embedding_row(9, 6)), (9, 2));
        let s = base.with_instance_slots(3).unwrap();
        assert_eq!(s.instance_slots(), 3);
        // E 12 x 3, W1 3 x 11 + 3, Wo 2 x 3 + 2.
        assert_eq!(s.param_len(), 36 + 36 + 8);
        assert_eq!(s.first_layer_offset(), 36);
        let (k, i) = (5u32, 6u32);
        assert_eq!(s.instance_key(k), 2);
        assert_eq!(s.embedding_row(k, i), 2 * 4 + 2);
        assert_eq!(s.embedding_offset(s.embedding_row(k, i)), 30);
        // Instance 5 is slot 2: the same input as instance 2, not instance 5's own.
        let c = [0.3, 0.8];
        let x = input_features::<f64>(&s, c, k, i);
        assert_eq!(x, input_features::<f64>(&s, c, 2, i));
        assert_ne!(x, input_features::<f64>(&base, c, k, i));
        let p: Vec<f64> = (0..s.param_len()).map(|j| noise(j) / 2.0).collect();
        let net = Network {
            shape: s,
            params: &p[..],
        };
        let (e, w1, b1, wo, bo) = (&p[30..33], &p[36..69], &p[69..72], &p[72..78], &p[78..80]);
        let h: [f64; 3] = core::array::from_fn(|o| {
            let z = b1[o] + e[o] + (0..INPUTS).map(|j| w1[o * INPUTS + j] * x[j]).sum::<f64>();
            z.max(0.0)
        });
        let want: [f64; 2] =
            core::array::from_fn(|o| bo[o] + (0..3).map(|j| wo[o * 3 + j] * h[j]).sum::<f64>());
        let got = net.evaluate(s.embedding_row(k, i), x);
        assert!(close(&got, &want, 1e-14), "{got:?} vs {want:?}");
        // An embedding of 2^32 numbers or more is no shape.
        let wide = Shape::new(65_536, &[128], Activation::Relu, 1).unwrap();
        assert!(wide.with_instance_slots(511).is_some());
        assert!(wide.with_instance_slots(512).is_none());
    }

    #[test]
    fn activation_derivatives_match_finite_differences() {
        for act in [Activation::Relu, Activation::Silu] {
            for x in [-3.0, -0.7, 0.4, 2.5] {
                let h = 1e-6;
                let fd = (act.apply(x + h) - act.apply(x - h)) / (2.0 * h);
                assert!((act.derivative(x) - fd).abs() < 1e-8, "{act:?} {x}");
            }
        }
    }

    #[test]
    fn instance_offsets_are_exact_in_both_precisions_and_distinct() {
        for k in [0u32, 1, 2, 77, u32::MAX] {
            let a = instance_offset::<f32>(k);
            let b = instance_offset::<f64>(k);
            assert_eq!(a[0] as f64, b[0]);
            assert_eq!(a[1] as f64, b[1]);
            assert!(b.iter().all(|&z| (0.0..1.0).contains(&z)));
        }
        assert_ne!(instance_offset::<f64>(0), instance_offset::<f64>(1));
        // Values of an independent Python implementation of lowbias32.
        assert_eq!(hash_u32(1), 0x6889_90c0);
        assert_eq!(hash_u32(0x1234_5678), 0xf5e7_1c96);
    }

    #[test]
    fn lattice_is_a_permutation_and_shift_wraps() {
        let (n, g) = (8u32, 3u32);
        let mut seen = [false; 8];
        for i in 0..n {
            let p = lattice_point::<f64>(i, n, g);
            assert_eq!(p[0], i as f64 / 8.0);
            seen[(p[1] * 8.0) as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
        let u = shifted_lattice_point::<f64>(7, n, g, [0.5, 0.9]);
        assert!((u[0] - 0.375).abs() < 1e-15 && (u[1] - (5.0 / 8.0 + 0.9 - 1.0)).abs() < 1e-15);
        assert_eq!(lattice_point::<f64>(9, n, g), lattice_point::<f64>(1, n, g));
    }

    #[test]
    fn input_features_hold_the_shifted_and_the_plain_lattice_point() {
        let shape = Shape::new(8, &[4], Activation::Relu, 3).unwrap();
        let f = input_features::<f64>(&shape, [0.5, 0.25], 5, 11);
        let z = instance_offset::<f64>(5);
        // Index 11 wraps to 3: l = (3/8, 1/8).
        let p = [(0.375 + z[0]) % 1.0, (0.125 + z[1]) % 1.0];
        let want = [2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0, -0.25, -0.75];
        assert!(f[7..].iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-15));
        assert_eq!(&f[5..7], &[2.0 * z[0] - 1.0, 2.0 * z[1] - 1.0]);
        assert_eq!(&f[..5], &condition_features([0.5, 0.25]));
    }

    #[test]
    fn condition_features_clamp_and_reject_nan() {
        let f = condition_features::<f64>([f64::NAN, 2.0]);
        assert_eq!(f, [-1.0, 1.0, -1.0, -1.0, 1.0]);
        let g = condition_features::<f32>([0.5, 0.25]);
        assert_eq!(g, [0.0, -0.5, -0.75, -0.5, -0.875]);
    }

    /// A fixed pseudo-random value in `[-1, 1)` for test data.
    fn noise(j: usize) -> f64 {
        (hash_u32(j as u32) as f64 / 2f64.powi(31)) - 1.0
    }

    /// `dot_block` of `rows` against `dot` of each row, compared by `bits`.
    fn assert_block_is_dot<T: Real>(rows: &[T], x: &[T], bits: impl Fn(T) -> u64, what: &str) {
        let got = dot_block(rows, x);
        for (r, row) in rows.chunks_exact(x.len()).enumerate() {
            assert_eq!(
                bits(got[r]),
                bits(dot(row, x)),
                "{what} len {} row {r}",
                x.len()
            );
        }
    }

    #[test]
    fn dot_block_gives_each_row_the_bits_of_dot() {
        for len in [1, 3, 7, 8, 9, 11, 16, 31, 32, 33, 64, 128] {
            let rows: Vec<f64> = (0..UNIT_BLOCK * len)
                .map(|j| noise(j + 1000 * len))
                .collect();
            let x: Vec<f64> = (0..len).map(|j| noise(j + 7)).collect();
            assert_block_is_dot(&rows, &x, f64::to_bits, "f64");
            let rows32: Vec<f32> = rows.iter().map(|&v| v as f32).collect();
            let x32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            assert_block_is_dot(&rows32, &x32, |v| v.to_bits() as u64, "f32");
            // A block cut short dots what is there: the last rows empty (0).
            let short = dot_block(&rows[..2 * len + 1], &x);
            assert_eq!(short[1].to_bits(), dot(&rows[len..2 * len], &x).to_bits());
            assert_eq!(short[2], dot(&rows[2 * len..2 * len + 1], &x));
            assert_eq!(short[3], 0.0);
        }
    }

    /// A network wide enough for blocks of units and a remainder in every layer
    /// (widths 9 and 6, output 2), with an embedding: each unit equals its
    /// explicit `b + (E +) dot(row, x)` bit for bit, in both precisions, and the
    /// f16 storage gives the bits of the same values decoded to `f32`.
    #[test]
    fn blocks_of_units_give_each_unit_its_own_dot() {
        let shape = Shape::new(5, &[9, 6], Activation::Silu, 3).unwrap();
        let p: Vec<f64> = (0..shape.param_len()).map(|j| noise(j) / 2.0).collect();
        let net = Network {
            shape,
            params: &p[..],
        };
        let input: [f64; INPUTS] = core::array::from_fn(|k| noise(k + 99));
        let i = 7u32; // wraps to row 2 of E
        let t = net.forward(i, input);
        let mut x: Vec<f64> = input.to_vec();
        let mut want_out = [0.0; OUTPUTS];
        for (l, span) in shape.layers().enumerate() {
            let z: Vec<f64> = (0..span.width)
                .map(|o| {
                    let mut acc = p[span.bias + o];
                    if l == 0 {
                        acc += p[shape.embedding_offset(i) + o];
                    }
                    let row = &p[span.weights + o * span.fan_in..][..span.fan_in];
                    acc + dot(row, &x)
                })
                .collect();
            if l < shape.hidden().len() {
                for (o, zo) in z.iter().enumerate() {
                    assert_eq!(t.pre[l][o].to_bits(), zo.to_bits(), "layer {l} unit {o}");
                }
                x = z.iter().map(|&v| Activation::Silu.apply(v)).collect();
            } else {
                want_out.copy_from_slice(&z);
            }
        }
        assert_eq!(t.output.map(f64::to_bits), want_out.map(f64::to_bits));

        let bits: Vec<u16> = p
            .iter()
            .map(|&v| crate::quantize::f16_encode(v as f32))
            .collect();
        let decoded: Vec<f32> = bits.iter().map(|&h| f16_decode_finite(h)).collect();
        let input32 = input.map(|v| v as f32);
        let from_f16 = Network {
            shape,
            params: F16Params(&bits),
        }
        .evaluate(i, input32);
        let from_f32 = Network {
            shape,
            params: &decoded[..],
        }
        .evaluate(i, input32);
        assert_eq!(from_f16.map(f32::to_bits), from_f32.map(f32::to_bits));
    }
}
