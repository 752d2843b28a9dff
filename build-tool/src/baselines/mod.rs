//! Baseline point sets the optimized sets are compared with (and start from).

mod owen_sobol;

pub use owen_sobol::{owen_sobol, OWEN_SOBOL_MAX_POINTS};
