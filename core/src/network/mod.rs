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
//!   pseudo-random offset `z_k` ([`Shape::instance_offset`]: [`salted_instance_offset`],
//!   or [`instance_offset`] for older blobs), and two points of the unit
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

use crate::real::Real;

mod features;
mod forward;
mod interleaved;
mod kernels;
mod shape;
#[cfg(test)]
mod tests;

pub use features::{
    condition_features, hash_u32, input_features, instance_offset, lattice_features, lattice_logit,
    lattice_point, offset_unit, salted_instance_offset, shifted_lattice_point, OffsetHash,
    LATTICE_LOGIT_EPS, OFFSET_SALTS,
};
pub use forward::{F16Params, Network, Parameters, Trace};
pub use interleaved::{interleave, interleaved_index, InterleavedParams};
pub use kernels::{dot, dot_block, dot_block_interleaved, DOT_LANES, UNIT_BLOCK};
pub use shape::{LayerSpan, Shape};

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
