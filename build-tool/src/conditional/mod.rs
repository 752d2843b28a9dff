//! Conditional samplers (paper §4): the blob's parts as the tool builds them.
//!
//! The shared definitions (info record, grid arithmetic, network) live in
//! [`nuld_core::conditional`] and [`nuld_core::network`]; this module assembles
//! their bytes.

pub mod blob;

pub use blob::ConditionalParts;
