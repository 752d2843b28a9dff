//! What the environment examples share with `bake --envmap`'s held-out check:
//! its seed, its 16 normals, and the map loaded as the bake loads it with the
//! bake's network shape at `N` points.
use nuld_build_tool::train::target::{EnvmapTarget, LoadedTarget};
use nuld_build_tool::train::{TrainConfig, TrainTarget};
use nuld_core::network::Shape;
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
