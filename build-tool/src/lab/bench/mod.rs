//! Speed measurements printed by `build-tool bench`: [`training`], the trainer's
//! time per step; [`runtime`], the runtime's cost per sample against the
//! incumbent a renderer would otherwise use.

pub mod runtime;
pub mod training;
