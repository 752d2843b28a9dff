//! Conditional samplers (paper §4): the blob's parts as the tool builds them.
//!
//! The shared definitions (info record, grid arithmetic, network) live in
//! [`nuld_core::conditional`] and [`nuld_core::network`]; this module assembles
//! their bytes from a trained network ([`distill`]), judges the result
//! ([`quality`]) and runs the whole bake ([`bake`]).

pub mod bake;
pub mod blob;
pub mod distill;
pub mod quality;

pub use blob::ConditionalParts;
