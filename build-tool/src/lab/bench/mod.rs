//! Speed measurements printed by `build-tool bench`: [`optimizer`], the 2D and
//! direction optimizers per epoch and per full run; [`baselines`], the baseline
//! generators per set; [`training`], the trainer's time per step; [`runtime`], the
//! runtime's cost per sample against the incumbent a renderer would otherwise use;
//! [`envmap_prior`], the environment sampler's exact product warp per sample;
//! [`rounds`], how the last two time their methods in turn.

pub mod baselines;
pub mod envmap_prior;
pub mod optimizer;
pub mod rounds;
pub mod runtime;
pub mod training;
