//! # nuld-build-tool
//!
//! The offline half of nuld: target densities, discrepancy estimators and exact
//! metrics, the optimizer, baselines, blob writing and the `build-tool` CLI.
#![deny(missing_docs)]

pub mod baselines;
pub mod cli;
pub mod conditional;
pub mod density;
pub mod discrepancy;
pub mod eval;
pub mod metrics;
pub mod network;
pub mod optimize;
pub mod output;
pub mod plot;
pub mod pointset;
pub mod progress;
pub mod render;
pub mod runtime_speed;
pub mod seeding;
pub mod shader;
pub mod sphere;
pub mod train;
