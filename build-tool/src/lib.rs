//! # nuld-build-tool
//!
//! The offline half of nuld: it optimizes point sets and trains conditional
//! samplers against non-uniform targets, and writes them as `.nuld` blobs for
//! `nuld-runtime`. The crate is two parts with one boundary: the **product**
//! (everything that makes a blob) never imports the **lab** ([`lab`]: what judges
//! the product), not even in its tests; `tests/architecture.rs` checks it, and that
//! no two top-level modules import each other.
//!
//! The product, bottom up (each module imports only those above it):
//!
//! | module | concept |
//! |---|---|
//! | [`seeding`], [`output`], [`progress`] | seed streams, atomic files, progress bars |
//! | [`density`] | target densities on the unit square and their SPEC grammar |
//! | [`sphere`] | targets on the sphere and hemisphere, cap measures, cap metrics |
//! | [`metrics`] | exact 2D discrepancies |
//! | [`discrepancy`] | the differentiable estimators (boxes, caps) and their gradients |
//! | [`descent`] | Adam, the annealing schedule, the one epoch step of every optimizer |
//! | [`pointset`] | point sets in memory and their blob encoding |
//! | [`plot`] | the pictures a run draws |
//! | [`baselines`] | Owen-Sobol and the other generators the optimizer starts from and is compared with |
//! | [`optimize`] | point-set optimization, 2D and directions |
//! | [`network`] | the conditional network's parameters and backward pass |
//! | [`train`] | training the network over a pool of conditions |
//! | [`conditional`] | distilling and baking a conditional sampler into a blob |
//! | [`shader`] | the runtime's WGSL in other shading languages |
//!
//! [`lab`] holds the paper-figure evaluation, the renderer study and the
//! benchmarks; [`cli`] parses each subcommand and calls one function of either.
#![deny(missing_docs)]

pub mod baselines;
pub mod cli;
pub mod conditional;
pub mod density;
pub mod descent;
pub mod discrepancy;
pub mod lab;
pub mod metrics;
pub mod network;
pub mod optimize;
pub mod output;
pub mod plot;
pub mod pointset;
pub mod progress;
pub mod seeding;
pub mod shader;
pub mod sphere;
pub mod train;
