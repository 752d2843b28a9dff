//! # nuld-core
//!
//! The vocabulary that the build tool and the runtime must agree on bit for bit,
//! written once:
//!
//! * [`sphere`]: the equal-area maps between the unit square and the sphere
//!   (octahedral, Clarberg 2008) and the hemisphere (concentric disk lifted to the
//!   hemisphere), with their inverses and the edge wrapping used by optimizers;
//! * [`brdf`]: the glTF 2.0 BRDF of `brdf:` targets and conditional samplers, over
//!   [`real::Real`] so that `f32` and `f64` share one formula;
//! * [`brdf_prior`]: the BRDF sampler's prior, the metallic-roughness BRDF times the
//!   cosine tabulated in the half vector's square over (roughness, θo, metallic);
//! * [`warp`]: the warps baselines sample with (concentric disk, cosine hemisphere,
//!   GGX visible normals), each beside its density and its inverse;
//! * [`domain`]: where a set's points live and the map from square to direction;
//! * [`marginal2d`]: tabulated conditional 2D warps, blended between the nodes of a
//!   parameter grid and sampled exactly, with their pdf and inverse;
//! * [`conditional`]: the conditional sampler's info record, condition grid and
//!   bilinear interpolation (blob kind 3);
//! * [`envmap_tree`]: an environment map's light times the cosine about a normal,
//!   sampled exactly by hierarchical warping with bounded work per node (the
//!   environment sampler's prior), with its pdf and inverse;
//! * [`quadtree`]: hierarchical product warping over a mip pyramid of masses times
//!   a factor known at the query, with its pdf and inverse;
//! * [`network`]: the conditional sampler's network (features, forward pass), one
//!   formula for the trainer and the runtime;
//! * [`quantize`]: the u16 unorm and f16 codecs blobs store values with;
//! * [`blob`]: the byte layout of a `.nuld` blob (format v1): header, section table,
//!   checksum, metadata, and a writer that fills a caller-provided buffer.
//!
//! The crate is `#![no_std]` and needs no allocator. Nothing in it panics on any
//! input; functions that can fail return a [`blob::BlobError`].
//!
//! ```
//! use nuld_core::sphere::{square_to_sphere, sphere_to_square};
//! let d = square_to_sphere(glam::DVec2::new(0.75, 0.5));
//! assert!((d - glam::DVec3::new(0.661437828, 0.0, 0.75)).length() < 1e-8);
//! let p = sphere_to_square(d);
//! assert!((p - glam::DVec2::new(0.75, 0.5)).length() < 1e-12);
//! ```
#![no_std]
#![deny(missing_docs)]

// The compiler's square root ([`real::Real::sqrt`]); nothing else of std.
#[cfg(feature = "std")]
extern crate std;

pub mod bilinear;
pub mod blob;
pub mod brdf;
pub mod brdf_prior;
pub mod cell_table;
pub mod conditional;
pub mod domain;
pub mod envmap_tree;
pub mod marginal2d;
pub mod network;
pub mod quadtree;
pub mod quantize;
pub mod real;
pub mod sphere;
#[cfg(test)]
mod test_rng;
pub mod warp;
