//! The lab: what judges the product, never imported by it.
//!
//! * [`eval`]: the paper's §5 figures and the held-out quality report of a
//!   conditional sampler (`build-tool eval`);
//! * [`render`]: the renderer study of paper Fig. 8 (`build-tool render`);
//! * [`mod@bench`]: speed of the optimizer, the trainer and the runtime
//!   (`build-tool bench`).

pub mod bench;
pub mod eval;
pub mod render;
