//! What the environment examples share with `bake --envmap`'s held-out check:
//! its seed, its 16 normals, its judge, and the map loaded as the bake loads it
//! with the bake's network shape at `N` points.
use glam::DVec2;
use nuld_build_tool::lab::eval::prior_judge::{Judge, JudgeSettings};
use nuld_build_tool::sphere::{DirectionDensity, EnvmapDensity};
use nuld_build_tool::train::target::{EnvmapTarget, LoadedTarget};
use nuld_build_tool::train::{TrainConfig, TrainTarget};
use nuld_core::network::Shape;
use nuld_core::sphere::square_to_sphere;
use std::path::PathBuf;
use std::sync::Arc;

/// The held-out check's seed (`QualityConfig::held_out` in `bake`).
pub const CHECK_SEED: u64 = 0x9a11;

/// How many held-out normals the check judges.
pub const NORMALS: usize = 16;

/// Held-out normal `index`'s octahedral point: the centre of cell `index` of a
/// 4 x 4 grid on the square.
pub fn held_out(index: usize) -> [f64; 2] {
    [
        ((index % 4) as f64 + 0.5) / 4.0,
        ((index / 4) as f64 + 0.5) / 4.0,
    ]
}

/// The map at `path` as `bake --envmap` loads it (luminance and tree), and the
/// default bake's network shape at `n` points (its lattice generator and
/// instance offsets). Panics on a map that does not load.
pub fn load(path: &str, n: u32) -> (Shape, Arc<EnvmapTarget>) {
    let target = TrainTarget::envmap(&PathBuf::from(path)).unwrap();
    let shape = TrainConfig {
        target: target.clone(),
        n,
        ..TrainConfig::default()
    }
    .shape()
    .unwrap();
    let LoadedTarget::Envmap(env) = target.load().unwrap() else {
        unreachable!("an environment map")
    };
    (shape, env)
}

/// `map` lit at the normal of octahedral point `u`, `L max(0, n.l)` as a
/// density; `None` where that normal receives no light.
pub fn lit(map: &EnvmapDensity, u: [f64; 2]) -> Option<EnvmapDensity> {
    let (lit, irradiance) = map.cosine_weighted(square_to_sphere(DVec2::from(u))).ok()?;
    (irradiance > 0.0).then_some(lit)
}

/// The check's judge of `N` directions against `lit` (the map lit at the normal
/// of octahedral point `u`): 4096 caps with exact measures drawn from
/// `index`, over the mean cap L2 of 8 Owen-Sobol sets through `lit`'s exact
/// inverse CDF.
pub fn judge(lit: &EnvmapDensity, u: [f64; 2], n: u32, index: u64) -> Judge<[f64; 2]> {
    let settings = JudgeSettings {
        n,
        instances: 8,
        caps: 4096,
        seed: CHECK_SEED,
    };
    // A lit map's own warp is its exact inverse CDF.
    let exact = |p| lit.sample(p);
    Judge::new(u, lit, &exact, &settings, index)
}
