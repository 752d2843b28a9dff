//! [`ConditionalSets`]: what the quality report judges, a conditional sampler seen
//! as one direction set per (condition, instance); the adapters that make one from
//! a per-sample function, from independent warped Owen-Sobol sets (the calibration
//! sampler), and from a `.nuld` blob read through `nuld-runtime`.

use crate::baselines::seeded_owen_sobol;
use crate::seeding::derive_seed;
use crate::sphere::{BrdfTarget, DirectionDensity};
use anyhow::Result;
use glam::DVec3;
use nuld_core::brdf::{clamp_metallic, clamp_roughness, clamp_theta_o_deg};

/// One conditional sampler: the `len()` directions of instance `k` at condition
/// `(roughness, theta_o_deg, metallic)` (glTF metallic-roughness BRDF of
/// `nuld_core::brdf`, base colour 1, view in the `xz`-plane on the `+x` side,
/// directions in the local frame, `z` = normal).
pub trait ConditionalSets: Sync {
    /// Short name (report rows, file names): `table`, `network`, ...
    fn name(&self) -> &str;
    /// Directions per set, `N`.
    fn len(&self) -> usize;
    /// Whether sets are empty (`N = 0`).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The `N` unit directions of instance `instance` at the condition.
    fn set(&self, roughness: f64, theta_o_deg: f64, metallic: f64, instance: u32) -> Vec<DVec3>;
}

/// A [`ConditionalSets`] from a per-sample function `f(roughness, theta_o_deg,
/// metallic, instance, index) -> direction` (what a runtime's
/// `sample_metallic(cond, metallic, instance, i)` is), evaluated for
/// `index = 0..n`.
pub struct SampleFnSets<F> {
    name: String,
    n: usize,
    f: F,
}

impl<F: Fn(f64, f64, f64, u32, u32) -> DVec3 + Sync> SampleFnSets<F> {
    /// The sampler `f` named `name`, `n` samples per set.
    pub fn new(name: impl Into<String>, n: usize, f: F) -> Self {
        Self {
            name: name.into(),
            n,
            f,
        }
    }
}

impl<F: Fn(f64, f64, f64, u32, u32) -> DVec3 + Sync> ConditionalSets for SampleFnSets<F> {
    fn name(&self) -> &str {
        &self.name
    }
    fn len(&self) -> usize {
        self.n
    }
    fn set(&self, roughness: f64, theta_o_deg: f64, metallic: f64, instance: u32) -> Vec<DVec3> {
        (0..self.n as u32)
            .map(|i| (self.f)(roughness, theta_o_deg, metallic, instance, i))
            .collect()
    }
}

/// Independent Owen-scrambled Sobol sets, one scramble per instance
/// (`seeded_owen_sobol(n, derive_seed(seed, instance))`), warped by the renderer's
/// mixture warp for the condition's metallic: the target's own
/// [`BrdfTarget::sample`](DirectionDensity::sample) (VNDF with probability
/// `p_s = A_spec / A` of [`BrdfTarget::metallic`], 1 for the metal, else
/// cosine), what a renderer does today, as a [`ConditionalSets`]. Conditions are
/// clamped into the target's range first.
///
/// It is the calibration sampler of the report: its instances are independent
/// randomizations, so the diversity figures come out near their independent values
/// (union ratio about `1/sqrt(instances)`, nearest-neighbour ratio about 0.65).
pub struct MixtureOwenSobol {
    n: usize,
    seed: u64,
}

/// Points of the cap-measure rule of [`MixtureOwenSobol`]'s targets: only their
/// mixture warp is used, which does not read the rule, so the smallest rule
/// keeps building a target per set cheap (its albedo quadrature, a few ms).
const MIXTURE_RULE_POINTS: usize = 16;

impl MixtureOwenSobol {
    /// Sets of `n` points for scramble seed `seed`.
    pub fn new(n: usize, seed: u64) -> Self {
        Self { n, seed }
    }
}

impl ConditionalSets for MixtureOwenSobol {
    fn name(&self) -> &str {
        "calibration"
    }
    fn len(&self) -> usize {
        self.n
    }
    fn set(&self, roughness: f64, theta_o_deg: f64, metallic: f64, instance: u32) -> Vec<DVec3> {
        let target = BrdfTarget::coarse(
            clamp_roughness(roughness),
            clamp_theta_o_deg(theta_o_deg),
            clamp_metallic(metallic),
            MIXTURE_RULE_POINTS,
        )
        .expect("a clamped condition is in range");
        seeded_owen_sobol(self.n, derive_seed(self.seed, instance as u64))
            .into_iter()
            .map(|u| target.sample(u))
            .collect()
    }
}

/// The table-mode and network-mode samplers of a conditional `.nuld` blob, read
/// through `nuld-runtime` exactly as a renderer reads them:
/// `Blob::parse(bytes)?.brdf()?.conditional()`, then
/// `sample_metallic(Vec2::new(roughness, theta_o_deg), metallic, instance, i).direction`
/// (named `table`) and `network().sample_metallic(..)` (named `network`), in that
/// order. Only a blob on the tabulated prior reads the metallic; others sample
/// their metallic-0 warp at every metallic (the runtime's
/// `ConditionalSampler::sample_metallic`), and the report judges that against
/// each metallic's own target.
pub fn blob_sets(bytes: &[u8]) -> Result<Vec<Box<dyn ConditionalSets + '_>>> {
    let blob = nuld_runtime::Blob::parse(bytes).map_err(|e| anyhow::anyhow!("{e}"))?;
    let cs = match blob.brdf() {
        Ok(brdf) => brdf.conditional(),
        Err(nuld_runtime::BlobError::WrongTarget { .. }) => anyhow::bail!(
            "eval conditional judges glTF BRDF samplers; this blob samples an environment map (bake --envmap)"
        ),
        Err(e) => anyhow::bail!("{e}"),
    };
    let n = cs.len() as usize;
    let cond = |r: f64, t: f64| nuld_runtime::glam::Vec2::new(r as f32, t as f32);
    let table = SampleFnSets::new("table", n, move |r, t, m, k, i| {
        cs.sample_metallic(cond(r, t), m as f32, k, i)
            .direction
            .as_dvec3()
    });
    let network = SampleFnSets::new("network", n, move |r, t, m, k, i| {
        cs.network()
            .sample_metallic(cond(r, t), m as f32, k, i)
            .direction
            .as_dvec3()
    });
    Ok(vec![Box::new(table), Box::new(network)])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// BRDF blobs give their two modes; an environment blob is refused by name.
    #[test]
    fn blob_sets_take_brdf_blobs_only() {
        let brdf = nuld_runtime::doc_example_conditional_blob();
        let sets = blob_sets(&brdf.0).unwrap();
        assert_eq!(sets.len(), 2);
        let dir = std::env::temp_dir().join(format!("nuld-blob-sets-{}", std::process::id()));
        let map = crate::sphere::envmap::tiny_map(&dir);
        let env = crate::lab::render::blobs::tiny_envmap_blob(4, &map);
        let e = blob_sets(env.as_slice()).err().unwrap().to_string();
        assert!(e.contains("bake --envmap"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
