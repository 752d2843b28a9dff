//! [`TrainTarget`]: what a conditional sampler is trained to sample, as its
//! training settings name it (so a checkpoint records it and a resumed run must
//! use the same), and [`LoadedTarget`], the data a pool is built from.

use crate::seeding::content_hash;
use crate::sphere::EnvmapDensity;
use anyhow::{Context, Result};
use nuld_core::blob::Domain;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The target family of a training run.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TrainTarget {
    /// The glTF 2.0 BRDF over `(roughness, theta_o)`
    /// ([`nuld_core::conditional::ConditionalTarget::GltfBrdf`]).
    #[default]
    GltfBrdf,
    /// An environment map through the cosine about the normal
    /// ([`nuld_core::conditional::ConditionalTarget::EnvmapNormal`]).
    Envmap {
        /// The map's file (HDR, EXR or any image `image` reads).
        path: PathBuf,
        /// [`content_hash`] of the file's bytes: a checkpoint of another map (or
        /// of the file since changed) is refused on resume.
        content_hash: u64,
    },
}

impl TrainTarget {
    /// The environment map at `path`, identified by its bytes; an error (naming
    /// the file) if it cannot be read.
    pub fn envmap(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path)
            .with_context(|| format!("cannot read environment map {}", path.display()))?;
        Ok(Self::envmap_with_bytes(path, &bytes))
    }

    /// The environment map at `path` whose file holds `bytes` (for a caller that
    /// has read it already).
    pub fn envmap_with_bytes(path: &Path, bytes: &[u8]) -> Self {
        Self::Envmap {
            path: path.to_path_buf(),
            content_hash: content_hash(bytes),
        }
    }

    /// `brdf` or `envmap`: the bake's option, the blob's file stem and its
    /// metadata target.
    pub fn name(&self) -> &'static str {
        match self {
            Self::GltfBrdf => "brdf",
            Self::Envmap { .. } => "envmap",
        }
    }

    /// Reads what the pool needs: nothing for the BRDF, the map (on the sphere) for
    /// an environment; one-line errors naming the file.
    pub fn load(&self) -> Result<LoadedTarget> {
        match self {
            Self::GltfBrdf => Ok(LoadedTarget::GltfBrdf),
            Self::Envmap { path, .. } => {
                let map = EnvmapDensity::from_file(path, Domain::Sphere)
                    .with_context(|| format!("environment map {}", path.display()))?;
                Ok(LoadedTarget::Envmap(Arc::new(map)))
            }
        }
    }
}

/// A [`TrainTarget`] with its data read.
#[derive(Clone, Debug)]
pub enum LoadedTarget {
    /// The glTF BRDF (closed form, nothing to read).
    GltfBrdf,
    /// The map's luminance as a density on the sphere.
    Envmap(Arc<EnvmapDensity>),
}
