//! The sampler blobs a render needs, BRDF and environment: one per sample count,
//! since a blob's sets have a fixed size `N` and the first `k < N` points of a
//! set are not a good set of `k`. Given blobs serve the sample count equal to
//! their `N`; for every other requested count the blob is baked into the output
//! directory (`DIR/brdf-nN/brdf.nuld`, `DIR/envmap-nN/envmap.nuld`, by
//! [`crate::conditional::bake::bake`]) and reused when already there.
//!
//! This is the only part of the renderer that touches the tool's training code;
//! the samplers read the resulting bytes through `nuld-runtime` alone
//! ([`super::nuld_sampler`]).

use super::environment::Environment;
use super::nuld_sampler::{NuldMode, NuldSampler};
use crate::conditional::bake::{bake, BakeConfig};
use crate::pointset::AlignedBytes;
use anyhow::{anyhow, bail, Context, Result};
use glam::DVec3;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Blob bytes by their set size `N`, of one family: BRDF samplers, or the
/// environment samplers of one map.
#[derive(Debug)]
pub struct SamplerBlobs<'e> {
    /// `None`: BRDF samplers; `Some(env)`: environment samplers of `env`.
    env: Option<&'e Environment>,
    by_n: BTreeMap<u32, (PathBuf, AlignedBytes)>,
}

/// BRDF sampler blobs.
pub type BrdfBlobs = SamplerBlobs<'static>;

impl<'e> SamplerBlobs<'e> {
    /// Reads each of `paths` as BRDF samplers; an error (one line, naming the
    /// file) for an unreadable file, a blob that is not a conditional glTF-BRDF
    /// sampler, or two blobs of the same `N`.
    pub fn read(paths: &[PathBuf]) -> Result<Self> {
        Self::read_family(paths, None)
    }

    /// Reads each of `paths` as environment samplers of `env`; errors as
    /// [`Self::read`], and for a blob baked for another map: one whose weight
    /// table, at nine of its nodes ([`NuldSampler::irradiance_nodes`]), is more
    /// than 1e-3 (of the largest of them) off the map's irradiance there.
    pub fn read_envmap(paths: &[PathBuf], env: &'e Environment) -> Result<Self> {
        Self::read_family(paths, Some(env))
    }

    fn read_family(paths: &[PathBuf], env: Option<&'e Environment>) -> Result<Self> {
        let mut blobs = Self {
            env,
            by_n: BTreeMap::new(),
        };
        for path in paths {
            let bytes = std::fs::read(path)
                .with_context(|| format!("cannot read {} blob {}", blobs.what(), path.display()))?;
            blobs.insert(path.clone(), AlignedBytes::copy_from(&bytes))?;
        }
        Ok(blobs)
    }

    /// `BRDF` or `environment`, for messages.
    fn what(&self) -> &'static str {
        match self.env {
            None => "BRDF",
            Some(_) => "environment",
        }
    }

    fn insert(&mut self, path: PathBuf, buf: AlignedBytes) -> Result<()> {
        let what = self.what();
        let sampler = match self.env {
            None => NuldSampler::new(buf.as_slice(), NuldMode::Table),
            Some(env) => NuldSampler::envmap(buf.as_slice(), NuldMode::Table, env),
        }
        .map_err(|e| anyhow!("{what} blob {}: {e}", path.display()))?;
        if let Some(env) = self.env {
            let (normals, blob): (Vec<DVec3>, Vec<f64>) =
                sampler.irradiance_nodes().into_iter().unzip();
            let map = env.irradiances(&normals);
            let scale = map.iter().fold(0.0, |m: f64, &e| m.max(e));
            for ((b, m), n) in blob.iter().zip(&map).zip(&normals) {
                // NaN compares false: such a blob is refused too.
                let agrees = (b - m).abs() <= 1e-3 * scale;
                if !agrees {
                    bail!(
                        "environment blob {}: an environment sampler baked for another map, or before the light was filtered bilinearly: bake it again (irradiance {b:.4e} in the blob, {m:.4e} from the map, at the normal {n:.3})",
                        path.display()
                    );
                }
            }
        }
        let n = sampler.len();
        if let Some((other, _)) = self.by_n.get(&n) {
            bail!(
                "{what} blobs {} and {} both have N = {n}; give one blob per sample count",
                other.display(),
                path.display()
            );
        }
        self.by_n.insert(n, (path, buf));
        Ok(())
    }

    /// Bakes (or reuses) a blob in `dir/brdf-nN/` (`dir/envmap-nN/`) for every
    /// count of `spp` that no blob serves, with `template` (whose target must be
    /// this family's) at `N` points per set.
    pub fn complete(&mut self, spp: &[u32], dir: &Path, template: &BakeConfig) -> Result<()> {
        let what = self.what();
        let stem = template.train.target.name();
        for &n in spp {
            if self.by_n.contains_key(&n) {
                continue;
            }
            let sub = dir.join(format!("{stem}-n{n}"));
            let path = sub.join(template.blob_name());
            if !path.is_file() {
                let config = template.clone().with_points(n);
                eprintln!(
                    "render: no {what} blob with N = {n}; baking one into {}",
                    sub.display()
                );
                bake(&config, &sub)?;
            }
            let bytes = std::fs::read(&path)
                .with_context(|| format!("cannot read {what} blob {}", path.display()))?;
            self.insert(path, AlignedBytes::copy_from(&bytes))?;
        }
        Ok(())
    }

    /// The bytes and path of the blob with `N = n`, if any.
    pub fn get(&self, n: u32) -> Option<(&Path, &[u8])> {
        self.by_n.get(&n).map(|(p, b)| (p.as_path(), b.as_slice()))
    }
}

/// A tiny baked BRDF sampler with `N = n` (the `--quick` bake, a finer weight
/// grid), baked into a fresh temporary directory: barely trained, so it checks
/// the sampler path, not its quality.
#[cfg(test)]
pub(crate) fn tiny_blob(n: u32) -> AlignedBytes {
    use std::sync::atomic::{AtomicU32, Ordering};
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let dir = std::env::temp_dir().join(format!(
        "nuld-render-blob-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let mut config = super::RenderConfig::quick(PathBuf::new()).bake;
    config.train.n = n;
    config.weight_grid = [32, 32];
    bake(&config, &dir).unwrap();
    let bytes = AlignedBytes::read(&dir.join("brdf.nuld")).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    bytes
}

/// A tiny baked environment sampler of the map at `map` with `N = n` (the
/// `--quick` bake), baked into a fresh temporary directory: barely trained.
#[cfg(test)]
pub(crate) fn tiny_envmap_blob(n: u32, map: &Path) -> AlignedBytes {
    use crate::train::TrainTarget;
    use std::sync::atomic::{AtomicU32, Ordering};
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let dir = std::env::temp_dir().join(format!(
        "nuld-render-envblob-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let mut config = super::RenderConfig::quick(PathBuf::new())
        .envmap_bake
        .with_envmap(TrainTarget::envmap(map).unwrap());
    config.train.n = n;
    config.weight_grid = [16, 16];
    bake(&config, &dir).unwrap();
    let bytes = AlignedBytes::read(&dir.join("envmap.nuld")).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::envmap::tiny_map;

    #[test]
    fn blobs_of_the_wrong_kind_or_a_repeated_n_are_refused_by_name() {
        let dir = std::env::temp_dir().join(format!("nuld-render-blobs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A valid 2D point-set blob (the runtime's doc example) is the wrong kind.
        let points = dir.join("points.nuld");
        std::fs::write(&points, nuld_runtime::doc_example_blob().0).unwrap();
        let e = BrdfBlobs::read(std::slice::from_ref(&points))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("points.nuld") && e.contains("not a conditional sampler"),
            "{e}"
        );
        let junk = dir.join("junk.nuld");
        std::fs::write(&junk, b"not a blob").unwrap();
        let e = BrdfBlobs::read(&[junk]).unwrap_err().to_string();
        assert!(e.contains("not a valid nuld blob"), "{e}");
        let e = BrdfBlobs::read(&[dir.join("missing.nuld")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot read BRDF blob"), "{e}");
        let blob = dir.join("b.nuld");
        std::fs::write(&blob, tiny_blob(4).as_slice()).unwrap();
        let e = BrdfBlobs::read(&[blob.clone(), blob.clone()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("both have N = 4"), "{e}");
        let blobs = BrdfBlobs::read(std::slice::from_ref(&blob)).unwrap();
        assert!(blobs.get(4).is_some() && blobs.get(16).is_none());
        // Environment samplers: a BRDF blob is the wrong target, a blob of
        // another map is refused, the map's own blob is served.
        let map = tiny_map(&dir);
        let env = Environment::from_file(&map).unwrap();
        let e = SamplerBlobs::read_envmap(&[blob], &env)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("environment blob") && e.contains("not an environment map"),
            "{e}"
        );
        let own = dir.join("env.nuld");
        std::fs::write(&own, tiny_envmap_blob(4, &map).as_slice()).unwrap();
        let blobs = SamplerBlobs::read_envmap(std::slice::from_ref(&own), &env).unwrap();
        assert!(blobs.get(4).is_some());
        let brighter = Environment::constant(100.0).unwrap();
        let e = SamplerBlobs::read_envmap(&[own], &brighter)
            .unwrap_err()
            .to_string();
        assert!(e.contains("baked for another map"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A map with a strong sun and a coarse weight grid: between nodes the
    /// interpolated irradiance is far off near the sun's horizon, but the check
    /// reads the nodes, so the map's own blob is accepted (a check of interpolated
    /// values refused it), and the same blob against another map is not.
    #[test]
    fn a_sun_maps_own_blob_is_accepted_at_a_coarse_weight_grid() {
        use crate::train::TrainTarget;
        let dir = std::env::temp_dir().join(format!("nuld-render-sunblob-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let map = dir.join("sun.hdr");
        let img = image::Rgb32FImage::from_fn(64, 32, |x, y| {
            let v = if (x, y) == (10, 8) { 20000.0 } else { 0.3 };
            image::Rgb([v; 3])
        });
        image::DynamicImage::ImageRgb32F(img).save(&map).unwrap();
        let mut config = super::super::RenderConfig::quick(PathBuf::new())
            .envmap_bake
            .with_envmap(TrainTarget::envmap(&map).unwrap());
        config.train.n = 4;
        config.weight_grid = [5, 5];
        bake(&config, &dir.join("b")).unwrap();
        let blob = dir.join("b").join("envmap.nuld");
        let env = Environment::from_file(&map).unwrap();
        let blobs = SamplerBlobs::read_envmap(std::slice::from_ref(&blob), &env).unwrap();
        assert!(blobs.get(4).is_some());
        let sky = Environment::from_file(&tiny_map(&dir)).unwrap();
        let e = SamplerBlobs::read_envmap(&[blob], &sky)
            .unwrap_err()
            .to_string();
        assert!(e.contains("baked for another map"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
