//! [`Checkpoint`]: everything a training run needs to continue bit for bit, and
//! its file (postcard, which stores every `f64` as its exact bits).

use super::TrainConfig;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Magic and version at the front of a checkpoint file.
const MAGIC: &[u8; 8] = b"NULDCKP1";

/// The state of a training run after `step` steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The run's settings (a resumed run must use the same).
    pub config: TrainConfig,
    /// Steps taken.
    pub step: usize,
    /// The network's parameters.
    pub params: Vec<f64>,
    /// Adam's first moments.
    pub adam_m: Vec<f64>,
    /// Adam's second moments.
    pub adam_v: Vec<f64>,
    /// Adam's step count.
    pub adam_t: i32,
    /// Running set loss of each pool condition (infinite until first drawn).
    pub running: Vec<f64>,
    /// The loss of every step taken.
    pub losses: Vec<f64>,
}

impl Checkpoint {
    /// The state before the first step.
    pub fn fresh(config: TrainConfig, params: Vec<f64>, pool: usize) -> Self {
        let len = params.len();
        Self {
            config,
            step: 0,
            params,
            adam_m: vec![0.0; len],
            adam_v: vec![0.0; len],
            adam_t: 0,
            running: vec![f64::INFINITY; pool],
            losses: Vec::new(),
        }
    }

    /// Writes the checkpoint to `path` atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let mut bytes = MAGIC.to_vec();
        bytes.extend(postcard::to_allocvec(self).context("cannot encode checkpoint")?);
        crate::output::write_atomic(path, &bytes)
    }

    /// Reads a checkpoint written by [`Checkpoint::save`].
    pub fn load(path: &Path) -> Result<Self> {
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        let body = bytes
            .strip_prefix(MAGIC.as_slice())
            .with_context(|| format!("{} is not a training checkpoint", path.display()))?;
        postcard::from_bytes(body)
            .with_context(|| format!("{} is a damaged checkpoint", path.display()))
    }
}
