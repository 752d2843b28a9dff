//! [`TrainTarget`]: what a conditional sampler is trained to sample, as its
//! training settings name it (so a checkpoint records it and a resumed run must
//! use the same), and [`LoadedTarget`], the data a pool is built from.

use crate::density::image::image_size;
use crate::progress::Progress;
use crate::seeding::content_hash;
use crate::sphere::brdf_prior::BrdfPrior;
use crate::sphere::envmap::COARSE_CELLS;
use crate::sphere::envmap_tree::{prior_levels, PRIOR_GRID};
use crate::sphere::{EnvmapDensity, EnvmapTree};
use anyhow::{Context, Result};
use nuld_core::blob::Domain;
use nuld_core::brdf::{CONDITION_MAX, CONDITION_MIN};
use nuld_core::conditional::ConditionalTarget;
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

    /// Reads what the pool needs: the shared prior for the BRDF, the map (on the sphere) for
    /// an environment; one-line errors naming the file.
    pub fn load(&self) -> Result<LoadedTarget> {
        match self {
            Self::GltfBrdf => Ok(LoadedTarget::gltf_brdf()),
            Self::Envmap { path, .. } => {
                // Seconds on a large map (8192 x 4096: 17.7 s) before the pool's
                // first line: a phase of its own there. A map of at most 1024 x
                // 512 pixels reads in about a second, and a file whose size
                // cannot be read fails at once: no progress for either, so that
                // a bad map's error stays one line.
                let large = image_size(path).is_some_and(|(w, h)| 4 * w * h > COARSE_CELLS);
                let started = std::time::Instant::now();
                let progress = large.then(|| Progress::stderr("map", 3, "step"));
                // Each line names the step under way.
                let step = |next: &str| {
                    if let Some(p) = &progress {
                        p.set_message(next);
                        p.inc(1);
                    }
                };
                let map = EnvmapDensity::from_file_filtered(path, Domain::Sphere)
                    .with_context(|| format!("environment map {}", path.display()))?;
                step("measuring the prior's tree");
                let tree = EnvmapTree::new(&map, prior_levels(&map), PRIOR_GRID)
                    .with_context(|| format!("environment map {}", path.display()))?;
                step("box-filtering the copy the pool lights");
                let target = EnvmapTarget::new(map, tree);
                step("");
                if let Some(p) = &progress {
                    let seconds = started.elapsed().as_secs_f64();
                    p.finish_with(&format!("{}, in {seconds:.1} s", target.summary()));
                }
                Ok(LoadedTarget::Envmap(Arc::new(target)))
            }
        }
    }
}

/// A [`TrainTarget`] with its data read.
#[derive(Clone, Debug)]
pub enum LoadedTarget {
    /// The glTF metallic-roughness BRDF (closed form) and its tabulated prior
    /// ([`BrdfPrior::shared`]), whose primary space the network refines.
    GltfBrdf(Arc<BrdfPrior>),
    /// The map's bilinearly filtered luminance as a density on the sphere, and its
    /// tree, the sampler's prior.
    Envmap(Arc<EnvmapTarget>),
}

/// An environment map as a sampler is trained on it.
#[derive(Clone, Debug)]
pub struct EnvmapTarget {
    /// The map's bilinearly filtered luminance as a density on the sphere
    /// ([`EnvmapDensity::from_luminance_filtered`]).
    pub map: EnvmapDensity,
    /// The map's tree ([`prior_levels`] levels, top weights on [`PRIOR_GRID`]
    /// normals): the prior whose primary space the network refines.
    pub tree: EnvmapTree,
    /// The map box-filtered to at most [`COARSE_CELLS`] cells where it has more
    /// ([`EnvmapDensity::box_filtered`]), else `None`: see [`Self::coarse_map`].
    coarse: Option<EnvmapDensity>,
}

impl EnvmapTarget {
    /// The map and its tree, with the coarse copy of [`Self::coarse_map`] made
    /// where the map has more than [`COARSE_CELLS`] cells (`O(cells)`).
    pub fn new(map: EnvmapDensity, tree: EnvmapTree) -> Self {
        Self::with_coarse_cells(map, tree, COARSE_CELLS)
    }

    /// [`Self::new`] with the copy made above `max_cells` cells instead (a
    /// map's [`EnvmapDensity::coarse_factor`] of `max_cells`).
    pub fn with_coarse_cells(map: EnvmapDensity, tree: EnvmapTree, max_cells: usize) -> Self {
        let coarse = map.box_filtered(map.coarse_factor(max_cells));
        Self { map, tree, coarse }
    }

    /// The density the bake lights through each pool normal's cosine (the
    /// training's caps, baselines and target) and sums for the irradiance
    /// table, and that the quality check lights for its held-out normals: the
    /// map itself up to [`COARSE_CELLS`] cells (a 1024 x 512 map or smaller: the
    /// same bits as before the copy existed), a box-filtered copy of a larger
    /// one, whose blocks keep their cells' mass. The prior's tree reads
    /// [`Self::map`], every cell.
    pub fn coarse_map(&self) -> &EnvmapDensity {
        self.coarse.as_ref().unwrap_or(&self.map)
    }

    /// What a bake reads of the map, in one line: `2048 x 1024 cells, a prior
    /// of 9 levels` (the filtered density's cells, two a pixel each way), and
    /// `, lit for the pool on a copy of W x H cells` where there is one.
    pub fn summary(&self) -> String {
        let coarse = match &self.coarse {
            Some(c) => format!(
                ", lit for the pool on a copy of {} x {} cells",
                c.width(),
                c.height()
            ),
            None => String::new(),
        };
        format!(
            "{} x {} cells, a prior of {} levels{coarse}",
            self.map.width(),
            self.map.height(),
            self.tree.info().levels
        )
    }
}

impl LoadedTarget {
    /// The glTF BRDF with the shared prior ([`BrdfPrior::shared`]).
    pub fn gltf_brdf() -> Self {
        Self::GltfBrdf(BrdfPrior::shared())
    }

    /// The blob's target code of this family (which also fixes its domain,
    /// [`ConditionalTarget::domain`]).
    pub fn kind(&self) -> ConditionalTarget {
        match self {
            Self::GltfBrdf(_) => ConditionalTarget::GltfBrdf,
            Self::Envmap(_) => ConditionalTarget::EnvmapNormal,
        }
    }

    /// The conditions a sampler of this target serves, in blob units, as the
    /// corners `(lo, hi)` of a box: `(roughness, theta_o in degrees)` from
    /// [`CONDITION_MIN`] to [`CONDITION_MAX`] for the BRDF, the normal's equal-area
    /// octahedral square point in `[0,1]^2` for a map.
    pub fn condition_range(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Self::GltfBrdf(_) => (CONDITION_MIN, CONDITION_MAX),
            Self::Envmap(_) => ([0.0; 2], [1.0; 2]),
        }
    }

    /// The condition at the point `u` of `[0,1]^2`: `lo + u (hi - lo)` per axis.
    pub fn condition(&self, u: [f64; 2]) -> [f64; 2] {
        let (lo, hi) = self.condition_range();
        core::array::from_fn(|a| lo[a] + u[a] * (hi[a] - lo[a]))
    }

    /// The inverse of [`Self::condition`]: the place of `cond` in its range,
    /// `(cond - lo) / (hi - lo)` per axis (the network's condition input).
    pub fn normalized(&self, cond: [f64; 2]) -> [f64; 2] {
        let (lo, hi) = self.condition_range();
        core::array::from_fn(|a| (cond[a] - lo[a]) / (hi[a] - lo[a]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The BRDF's range runs from `CONDITION_MIN` to `CONDITION_MAX` (its corners
    /// map onto them, its centre onto their midpoint); a map's conditions are the
    /// octahedral square itself, bit for bit both ways (the pool relies on it).
    #[test]
    fn conditions_map_the_unit_square_onto_each_targets_range() {
        let brdf = TrainTarget::GltfBrdf.load().unwrap();
        assert_eq!(brdf.condition([0.0, 0.0]), CONDITION_MIN);
        assert_eq!(brdf.condition([1.0, 1.0]), CONDITION_MAX);
        let mid = brdf.condition([0.5, 0.5]);
        for a in 0..2 {
            assert!((mid[a] - 0.5 * (CONDITION_MIN[a] + CONDITION_MAX[a])).abs() < 1e-12);
        }
        let back = brdf.normalized([0.55, 44.5]);
        assert!(back.iter().all(|x| (x - 0.5).abs() < 1e-12), "{back:?}");
        let dir = std::env::temp_dir().join(format!("nuld-target-range-{}", std::process::id()));
        let map = TrainTarget::envmap(&crate::sphere::envmap::tiny_map(&dir))
            .unwrap()
            .load()
            .unwrap();
        for u in [[0.0, 1.0], [0.3, 0.7], [0.123_456_789, 0.999_999]] {
            assert_eq!(map.condition(u), u);
            assert_eq!(map.normalized(u), u);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A map within the limit is lit whole (the coarse map is the map itself, so
    /// its bakes write what they wrote before the copy); above it, the pool and
    /// the irradiance table read a box-filtered copy of at most that many cells
    /// with the map's integral, while the tree is the map's own.
    #[test]
    fn a_map_over_the_limit_is_lit_through_a_coarse_copy() {
        let dir = std::env::temp_dir().join(format!("nuld-target-coarse-{}", std::process::id()));
        let path = crate::sphere::envmap::tiny_map(&dir);
        let map = EnvmapDensity::from_file_filtered(&path, Domain::Sphere).unwrap();
        let tree = EnvmapTree::new(&map, nuld_core::envmap_tree::TOP_LEVELS, 2).unwrap();
        let cells = map.width() * map.height();
        let whole = EnvmapTarget::with_coarse_cells(map.clone(), tree.clone(), cells);
        assert!(std::ptr::eq(whole.coarse_map(), &whole.map));
        let small = EnvmapTarget::with_coarse_cells(map, tree, cells / 4);
        let coarse = small.coarse_map();
        assert!(!std::ptr::eq(coarse, &small.map));
        assert_eq!(coarse.width() * 2, small.map.width());
        assert_eq!(coarse.height() * 2, small.map.height());
        assert!((coarse.integral() / small.map.integral() - 1.0).abs() < 1e-12);
        assert_eq!(coarse.negative_pixels(), small.map.negative_pixels());
        assert_eq!(whole.summary(), "64 x 32 cells, a prior of 4 levels");
        assert_eq!(
            small.summary(),
            "64 x 32 cells, a prior of 4 levels, lit for the pool on a copy of 32 x 16 cells"
        );
        // A real map is over the default limit only from 1024 x 512 pixels up.
        assert_eq!(COARSE_CELLS, 4 * 1024 * 512);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
