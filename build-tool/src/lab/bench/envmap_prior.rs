//! The environment sampler per sample (`build-tool bench --only envmap-prior`):
//! [`nuld_core::envmap_tree`]'s exact product warp of a map's light and a
//! normal's cosine, in `f32` as the runtime calls it, and the runtime's
//! [`nuld_runtime::EnvmapSampler`] on it (table, unbiased and network modes; the
//! default bake's network, random weights, each instance's lattice in the table),
//! against the incumbent a renderer ships, Owen-scrambled Sobol (`sobol_burley`)
//! through the map's luminance warp in `f32` with its pdf ([`EnvmapLight`],
//! Mitsuba 3's `envmap`, which ignores the cosine). The earlier incumbent, the
//! build tool's own `f64` inverse CDF on the filtered map's half-pixel cells
//! ([`EnvmapDensity`]'s warp, 16 MB of tables at 1024 x 512 pixels, no pdf), is
//! timed beside it.

use super::rounds::Rounds;
use super::runtime::{envmap_parts, random_parts, random_shape, with_lattice_points};
use crate::baselines::EnvmapLight;
use crate::conditional::blob::ConditionalParts;
use crate::pointset::AlignedBytes;
use crate::sphere::envmap_tree::{prior_levels, top_table, PRIOR_GRID};
use crate::sphere::{DirectionDensity, EnvmapDensity, EnvmapTree};
use anyhow::{anyhow, Result};
use glam::{DVec2, DVec3};
use nuld_core::blob::Metadata;
use nuld_core::conditional::PointWarp;
use nuld_core::envmap_tree::{EnvmapTree as CoreTree, LEGACY_TOP_LEVELS};
use nuld_core::network::hash_u32;
use nuld_core::network::Activation;
use nuld_runtime::glam::Vec3;
use nuld_runtime::Blob;
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::sync::Arc;

/// Normals cycled through: a renderer's shading points each have their own.
/// Many, so that a normal is not paired with the same stored instance over and
/// over: at 64 normals (sample `s`'s normal `s / N mod 64`, its instance `s / N`
/// of 64 stored) table mode served 64 points a normal, which the caches and the
/// branch predictor learned (2.01x to 2.05x the incumbent, against 2.76x to
/// 2.82x at 4096, the two builds taking turns).
const NORMALS: usize = 4096;

/// Points per set: a set of 64 shares its normal and scramble.
const N: u32 = 64;

/// Levels of the shallow tree timed beside the prior's own.
const SHALLOW_LEVELS: u32 = 5;

/// The environment sampler this bench times, on `tree`: the default bake's
/// shapes ([32, 32] ReLU, [`ENVMAP_INSTANCE_SLOTS`] slots, 64 instances on
/// [`ENVMAP_GRID`] normals, `N` points), a network of random weights
/// ([`random_parts`], seed 3: its speed does not depend on them) and each
/// instance's shifted lattice in the point table ([`with_lattice_points`]: the
/// tree's descent follows the points).
///
/// [`ENVMAP_INSTANCE_SLOTS`]: crate::conditional::bake::ENVMAP_INSTANCE_SLOTS
/// [`ENVMAP_GRID`]: crate::conditional::bake::ENVMAP_GRID
pub fn sampler_parts(tree: Arc<EnvmapTree>) -> Result<ConditionalParts> {
    let defaults = crate::conditional::bake::BakeConfig::default();
    let shape = random_shape(
        N,
        &defaults.train.hidden,
        Activation::Relu,
        PointWarp::EnvmapTree,
        crate::conditional::bake::ENVMAP_INSTANCE_SLOTS,
    )?;
    let parts = random_parts(
        shape,
        PointWarp::EnvmapTree,
        64,
        crate::conditional::bake::ENVMAP_GRID,
        3,
    )?;
    Ok(envmap_parts(with_lattice_points(parts, &shape), tree))
}

/// The blob of `parts` ([`sampler_parts`]) as this bench writes it.
pub fn sampler_blob(parts: ConditionalParts) -> Result<AlignedBytes> {
    parts.to_blob(&Metadata {
        generator: "bench",
        target: "envmap",
        seed: 0,
    })
}

/// `(method, ns per sample)` rows, the incumbent first, over `samples` samples
/// each, one thread, the methods taking turns over the rounds of [`Rounds`]
/// (each figure the median of its rounds): sample `s` has normal `s / N mod 4096`,
/// and index `s mod N` of the set scrambled by `s / N`.
pub fn measure(
    map: &EnvmapDensity,
    light: &EnvmapLight,
    samples: u32,
) -> Result<Vec<(String, f64)>> {
    // The environment sampler's own tree of this map.
    let (levels, grid) = (prior_levels(map), PRIOR_GRID);
    let tree = EnvmapTree::new(map, levels, grid)?;
    let core = tree.tree();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(2);
    let normals: Vec<DVec3> = (0..NORMALS)
        .map(|_| {
            DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize()
        })
        .collect();
    let normals32: Vec<[f32; 3]> = normals.iter().map(|n| n.as_vec3().to_array()).collect();
    let at = |s: u32| (s / N) as usize % NORMALS;
    let u = |s: u32| {
        let seed = hash_u32(s / N);
        [
            sobol_burley::sample(s % N, 0, seed),
            sobol_burley::sample(s % N, 1, seed),
        ]
    };
    // The same tree with the shallower top table of the blobs written before
    // `TOP_LEVELS` was 4: what the deeper table costs.
    let legacy_top = top_table(levels, LEGACY_TOP_LEVELS, &tree.nodes, grid);
    let legacy_core = CoreTree::view(levels, &tree.nodes, grid, &legacy_top, LEGACY_TOP_LEVELS)
        .and_then(|t| t.with_corners(&tree.corners))
        .and_then(|t| t.with_detail(&tree.detail_index, &tree.detail))
        .and_then(|t| t.with_fine_detail(&tree.fine))
        .map_err(|e| anyhow!("{e}"))?;
    // A shallow tree of the same map, whose records (87 KB) stay in the caches:
    // the difference per level from the deep one tells cache misses from the
    // descent's own latency.
    let shallow = EnvmapTree::new(map, SHALLOW_LEVELS, grid)?;
    let shallow_core = shallow.tree();
    let blob = sampler_blob(sampler_parts(Arc::new(tree.clone()))?)?;
    let env = Blob::parse(blob.as_slice())
        .map_err(|e| anyhow!("{e}"))?
        .envmap()
        .map_err(|e| anyhow!("{e}"))?;
    let normals_v: Vec<Vec3> = normals32.iter().map(|&n| Vec3::from(n)).collect();
    let mut buf = vec![0.0f32; env.decoded_network_len()];
    let decoded = env
        .decode_network(&mut buf)
        .ok_or_else(|| anyhow!("decode_network refused a buffer of its own length"))?;

    let light = light.sampler();
    let mut rounds = Rounds::new();
    rounds.add(
        "incumbent: owen-sobol + luminance warp, f32, with pdf (Mitsuba 3)",
        samples,
        |s| {
            black_box(light.sample(u(s)));
        },
    );
    rounds.add(
        "earlier incumbent: owen-sobol + f64 inverse CDF on half pixels",
        samples,
        |s| {
            let [x, y] = u(s);
            black_box(map.sample(DVec2::new(x as f64, y as f64)));
        },
    );
    rounds.add(
        format!("tree L {levels}, top {grid}: sample + pdf (f32)"),
        samples,
        |s| {
            black_box(core.sample(normals32[at(s)], u(s)));
        },
    );
    rounds.add(
        format!("tree L {levels}, top {grid}, {LEGACY_TOP_LEVELS} top levels (blobs before): sample + pdf (f32)"),
        samples,
        |s| {
            black_box(legacy_core.sample(normals32[at(s)], u(s)));
        },
    );
    rounds.add(
        format!("tree L {levels}, top {grid}: pdf of a direction (f32)"),
        samples,
        |s| {
            let [x, y] = u(s);
            let d = nuld_core::sphere::square_to_sphere_real([x, y]);
            black_box(core.pdf(normals32[at(s)], d));
        },
    );
    rounds.add(
        format!("tree L {levels}, top {grid}: sample + pdf (f64)"),
        samples / 4,
        |s| {
            let [x, y] = u(s);
            black_box(core.sample(normals[at(s)].to_array(), [x as f64, y as f64]));
        },
    );
    rounds.add(
        format!("tree L {SHALLOW_LEVELS} (in cache), top {grid}: sample + pdf (f32)"),
        samples,
        |s| {
            black_box(shallow_core.sample(normals32[at(s)], u(s)));
        },
    );
    rounds.add("EnvmapSampler::sample (table mode)", samples, |s| {
        black_box(env.sample(normals_v[at(s)], s / N, s % N));
    });
    rounds.add(
        "EnvmapSampler::sample_randomized (unbiased mode)",
        samples,
        |s| {
            black_box(env.sample_randomized(normals_v[at(s)], s / N, s % N, s));
        },
    );
    rounds.add("EnvmapSampler::pdf of a direction", samples, |s| {
        let [x, y] = u(s);
        let d = Vec3::from(nuld_core::sphere::square_to_sphere_real([x, y]));
        black_box(env.pdf(normals_v[at(s)], d));
    });
    rounds.add(
        "network: zero-copy, EnvmapNetwork::sample",
        samples / 10,
        |s| {
            black_box(env.network().sample(normals_v[at(s)], s / N, s % N));
        },
    );
    rounds.add(
        "network: decoded, EnvmapNetwork::sample",
        samples / 10,
        |s| {
            black_box(decoded.sample(normals_v[at(s)], s / N, s % N));
        },
    );
    Ok(rounds.run())
}
