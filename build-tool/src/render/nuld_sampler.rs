//! Ours: the conditional BRDF sampler of a baked blob, reached only through
//! `nuld-runtime`'s public API on the blob's bytes, exactly as a renderer that
//! links the runtime would: `Blob::parse(bytes)?.conditional()?` once, then
//! [`ConditionalSampler::sample_brdf`] (table mode) or
//! [`ConditionalSampler::sample_brdf_network`] (network mode) per sample, with the
//! local view direction, the roughness, the pixel's instance (its key's high 32
//! bits) and the index. The weight is the sample's own (the albedo `A`).

use super::sampler::{DirectionSampler, PixelKey, Sample, ShadingPoint, Technique};
use nuld_runtime::{Blob, BlobError, BlobKind, ConditionalSampler, ConditionalTarget};

/// Table mode or network mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NuldMode {
    /// Interpolated point tables (`nuld-table`).
    Table,
    /// The f16 network per sample (`nuld-network`).
    Network,
}

/// Why a blob cannot serve as the BRDF sampler.
#[derive(Debug, thiserror::Error)]
pub enum NuldBlobError {
    /// The runtime rejected the bytes.
    #[error("not a valid nuld blob: {0}")]
    Parse(BlobError),
    /// A valid blob of another kind.
    #[error("a {0:?} blob, not a conditional BRDF sampler")]
    Kind(BlobKind),
    /// A conditional blob for another target.
    #[error("a conditional sampler for target code {0}, not the glTF BRDF")]
    Target(u32),
}

/// Ours (see the module docs): a view on the blob's bytes.
#[derive(Clone, Copy, Debug)]
pub struct NuldSampler<'a> {
    sampler: ConditionalSampler<'a>,
    mode: NuldMode,
}

impl<'a> NuldSampler<'a> {
    /// The sampler of the blob `bytes` (16-byte aligned, e.g.
    /// `nuld_runtime::AlignedBuf`) in `mode`; an error unless they hold a
    /// conditional glTF-BRDF sampler.
    pub fn new(bytes: &'a [u8], mode: NuldMode) -> Result<Self, NuldBlobError> {
        let blob = Blob::parse(bytes).map_err(NuldBlobError::Parse)?;
        if blob.kind() != BlobKind::Conditional {
            return Err(NuldBlobError::Kind(blob.kind()));
        }
        let sampler = blob.conditional().map_err(NuldBlobError::Parse)?;
        let target = sampler.info().target;
        if ConditionalTarget::from_code(target) != Some(ConditionalTarget::GltfBrdf) {
            return Err(NuldBlobError::Target(target));
        }
        Ok(Self { sampler, mode })
    }

    /// Points per set `N` of the blob.
    pub fn len(&self) -> u32 {
        self.sampler.len()
    }

    /// Always `false` (a parsed blob has points).
    pub fn is_empty(&self) -> bool {
        self.sampler.is_empty()
    }
}

impl DirectionSampler for NuldSampler<'_> {
    fn technique(&self) -> Technique {
        Technique::Brdf
    }

    fn name(&self) -> &'static str {
        match self.mode {
            NuldMode::Table => "nuld-table",
            NuldMode::Network => "nuld-network",
        }
    }

    /// Indices `0..n` of the pixel's instance; `n` is the blob's `N` in the
    /// evaluation (indices wrap modulo `N` otherwise).
    fn samples(&self, at: &ShadingPoint, key: PixelKey, n: u32, out: &mut Vec<Sample>) {
        out.clear();
        let wo = at.wo.as_vec3();
        let r = at.roughness as f32;
        let k = key.instance();
        out.extend((0..n).map(|i| {
            let s = match self.mode {
                NuldMode::Table => self.sampler.sample_brdf(wo, r, k, i),
                NuldMode::Network => self.sampler.sample_brdf_network(wo, r, k, i),
            };
            // The runtime's directions are unit to f32 rounding; used as they come.
            Sample {
                direction: at.frame.to_world(s.direction.as_dvec3()),
                weight: s.weight as f64,
            }
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::blobs::tiny_blob;
    use crate::render::frame::Frame;
    use glam::{DVec3, Vec3};

    /// Ours is the runtime and nothing else: on the same blob bytes, the samples
    /// equal direct `nuld_runtime` calls bit for bit (local frame = world frame
    /// for the normal `+z`).
    #[test]
    fn samples_are_the_runtimes_bit_for_bit() {
        let blob = tiny_blob(8);
        let cs = Blob::parse(blob.as_slice()).unwrap().conditional().unwrap();
        for (mode, name) in [
            (NuldMode::Table, "nuld-table"),
            (NuldMode::Network, "nuld-network"),
        ] {
            let ours = NuldSampler::new(blob.as_slice(), mode).unwrap();
            assert_eq!((ours.name(), ours.len()), (name, 8));
            let wo = Vec3::new(0.3, -0.4, 0.7).normalize();
            let at = ShadingPoint {
                frame: Frame::new(DVec3::Z),
                wo: DVec3::new(wo.x as f64, wo.y as f64, wo.z as f64),
                roughness: 0.4f32 as f64,
            };
            let key = PixelKey(0x1234_5678_9abc_def0);
            let mut out = Vec::new();
            ours.samples(&at, key, 8, &mut out);
            for (i, s) in out.iter().enumerate() {
                let want = match mode {
                    NuldMode::Table => cs.sample_brdf(wo, 0.4, key.instance(), i as u32),
                    NuldMode::Network => cs.sample_brdf_network(wo, 0.4, key.instance(), i as u32),
                };
                let got = s.direction.as_vec3();
                assert_eq!(
                    got.to_array().map(f32::to_bits),
                    want.direction.to_array().map(f32::to_bits)
                );
                assert_eq!(s.weight, want.weight as f64);
            }
            // At a tilted normal the world directions are the runtime's local ones
            // carried by the frame: back in the local frame they agree to rounding,
            // and they lie above the surface.
            let n = DVec3::new(-0.5, 0.3, 0.2).normalize();
            let tilted = ShadingPoint {
                frame: Frame::new(n),
                ..at
            };
            ours.samples(&tilted, key, 8, &mut out);
            for (i, s) in out.iter().enumerate() {
                let want = match mode {
                    NuldMode::Table => cs.sample_brdf(wo, 0.4, key.instance(), i as u32),
                    NuldMode::Network => cs.sample_brdf_network(wo, 0.4, key.instance(), i as u32),
                };
                let local = tilted.frame.to_local(s.direction);
                assert!((local - want.direction.as_dvec3()).length() < 1e-12);
                assert!(s.direction.dot(n) >= 0.0);
            }
        }
    }

    /// The sampler path of the renderer reaches the sampler through
    /// `nuld-runtime` only: no file of `render/` but the blob baker imports the
    /// tool's training, network or conditional-sampler code.
    #[test]
    fn the_renderer_does_not_import_the_tools_sampler_internals() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/render");
        let mut checked = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            // `blobs.rs` bakes missing blobs; `run.rs` only holds the bake settings.
            if name == "blobs.rs" || name == "run.rs" {
                continue;
            }
            let src = std::fs::read_to_string(&path).unwrap();
            // The code, not its tests (this test names what it looks for).
            let code = src.split("#[cfg(test)]").next().unwrap();
            for internal in [
                "crate::train",
                "crate::network",
                "crate::conditional",
                "nuld_core::network",
                "nuld_core::conditional",
            ] {
                assert!(!code.contains(internal), "{name} uses {internal}");
            }
            checked += 1;
        }
        assert!(checked >= 10, "only {checked} files checked");
        let src = std::fs::read_to_string(dir.join("run.rs")).unwrap();
        assert!(
            !src.contains("crate::train::Trainer") && !src.contains("crate::conditional::distill")
        );
    }
}
