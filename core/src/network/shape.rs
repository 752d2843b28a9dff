//! The network's architecture: widths, instance slots, the flat parameter layout
//! ([`Shape::param_len`], [`Shape::layers`]).

use super::{Activation, OffsetHash, INPUTS, MAX_HIDDEN_LAYERS, MAX_WIDTH, OUTPUTS};
use crate::real::Real;

/// The architecture of a network: points per set, hidden widths, activation, and the
/// rank-1 lattice generator of its input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    pub(crate) n: u32,
    pub(crate) hidden: [u32; MAX_HIDDEN_LAYERS],
    pub(crate) layers: u32,
    pub(crate) activation: Activation,
    pub(crate) lattice_generator: u32,
    pub(crate) lattice_residual: bool,
    pub(crate) metallic_input: bool,
    pub(crate) instance_slots: u32,
    pub(crate) offset_hash: OffsetHash,
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
            metallic_input: false,
            instance_slots: 0,
            offset_hash: OffsetHash::Salted,
        })
    }

    /// The shape with `slots` instance slots (`0`, what [`Shape::new`] makes: every
    /// instance its own offset and one embedding row per index), or `None` if
    /// `slots n` or the embedding `slots n h1` does not fit in a `u32`.
    ///
    /// With `slots = M >= 1`, instance `k` is slot `s = k mod M`: its offset is
    /// `z_s` ([`Shape::instance_offset`]) and its first hidden layer adds the row
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

    /// The shape whose instances hash to offsets by `offset_hash`
    /// ([`OffsetHash::Salted`] is what [`Shape::new`] makes).
    pub fn with_offset_hash(self, offset_hash: OffsetHash) -> Self {
        Self {
            offset_hash,
            ..self
        }
    }

    /// How instance numbers hash to offsets.
    pub fn offset_hash(&self) -> OffsetHash {
        self.offset_hash
    }

    /// The offset `z` of instance `k`: the [`OffsetHash::offset`] of
    /// [`Shape::instance_key`]`(k)`.
    #[inline]
    pub fn instance_offset<T: Real>(&self, k: u32) -> [T; 2] {
        self.offset_hash.offset(self.instance_key(k))
    }

    /// The row of `E` that index `i` of instance `k` adds: `i mod n` without
    /// slots, else `(k mod M) n + (i mod n)`. What [`Network::forward`](super::Network::forward) takes.
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

    /// The shape with the outputs a residual on [`lattice_logit`](super::lattice_logit) (`true`) or plain
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

    /// The shape whose third condition feature is the metallic, `2 m - 1`
    /// (`true`: the shared network of a BRDF sampler with a metallic axis,
    /// [`crate::conditional::metallic_axis`]), or `2 u v - 1` (`false`, what
    /// [`Shape::new`] makes). See [`input_features`](super::input_features).
    pub fn with_metallic_input(self, metallic_input: bool) -> Self {
        Self {
            metallic_input,
            ..self
        }
    }

    /// Whether the third condition feature is the metallic.
    pub fn metallic_input(&self) -> bool {
        self.metallic_input
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

    /// The rank-1 lattice generator `g` of [`lattice_point`](super::lattice_point).
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
