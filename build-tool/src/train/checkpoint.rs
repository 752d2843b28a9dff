//! [`Checkpoint`]: everything a training run needs to continue bit for bit, and
//! its file (postcard, which stores every `f64` as its exact bits).

use super::TrainConfig;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Magic and version at the front of a checkpoint file. Version 2: the pool a
/// run trains on is rebuilt from its settings on resume, and since version 1 an
/// environment pool skips normals that no light reaches and lights a map larger
/// than 1024 x 512 through a coarse copy, so a version-1 run would continue on
/// another pool than it began with (the settings it records are the same).
const MAGIC: &[u8; 8] = b"NULDCKP2";

/// The magics of earlier versions, refused with their own message.
const EARLIER_MAGICS: [&[u8; 8]; 1] = [b"NULDCKP1"];

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

    /// Reads a checkpoint written by [`Checkpoint::save`]. A file that does not
    /// decode is refused in one line that names what to do: it is damaged, or
    /// an earlier build-tool wrote it (the settings it records have since gained
    /// fields, the metallic axis's nodes for one), and a run cannot continue it.
    pub fn load(path: &Path) -> Result<Self> {
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        if EARLIER_MAGICS
            .iter()
            .any(|m| bytes.starts_with(m.as_slice()))
        {
            anyhow::bail!(
                "{} was written by an earlier build-tool, whose training pool differs; rerun without --resume",
                path.display()
            );
        }
        let body = bytes
            .strip_prefix(MAGIC.as_slice())
            .with_context(|| format!("{} is not a training checkpoint", path.display()))?;
        postcard::from_bytes(body).map_err(|_| {
            anyhow::anyhow!(
                "{} is damaged or was written by an earlier build-tool; rerun without --resume",
                path.display()
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A checkpoint reads back as it was saved; one cut short (as a checkpoint
    /// of an earlier build-tool's shorter settings decodes), one of version 1
    /// and a file of another kind are refused in one line each, the first two
    /// naming the way out.
    #[test]
    fn a_checkpoint_reads_back_and_unreadable_ones_are_refused_in_one_line() {
        let dir = std::env::temp_dir().join(format!("nuld-checkpoint-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("checkpoint.bin");
        let c = Checkpoint::fresh(TrainConfig::default(), vec![0.5, -1.25, 3.0], 4);
        c.save(&path).unwrap();
        assert_eq!(Checkpoint::load(&path).unwrap(), c);

        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let e = format!("{:#}", Checkpoint::load(&path).unwrap_err());
        assert!(e.contains("without --resume") && !e.contains('\n'), "{e}");

        // A version-1 checkpoint, whole, is refused for its version.
        let mut old = b"NULDCKP1".to_vec();
        old.extend(postcard::to_allocvec(&c).unwrap());
        std::fs::write(&path, &old).unwrap();
        let e = format!("{:#}", Checkpoint::load(&path).unwrap_err());
        assert!(
            e.contains("earlier build-tool") && e.contains("without --resume"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");

        std::fs::write(&path, b"not a checkpoint").unwrap();
        let e = format!("{:#}", Checkpoint::load(&path).unwrap_err());
        assert!(e.ends_with("is not a training checkpoint"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
