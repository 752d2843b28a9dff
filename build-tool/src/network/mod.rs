//! The trainable side of the conditional sampler's network (paper §4): flat `f64`
//! parameters of a [`nuld_core::network::Shape`], their initialization, the backward pass of
//! [`nuld_core::network::Network::forward`], and rounding to the f16 that ships.
//!
//! The forward pass is [`nuld_core::network`]'s, written once for the trainer and
//! the runtime; this module only adds what training needs.

pub mod backward;
pub mod params;

pub use backward::{backward, output_gradient};
pub use params::{Interleaved, Params};
