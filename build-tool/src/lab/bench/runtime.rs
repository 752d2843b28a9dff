//! The runtime's cost per sample (`build-tool bench --only runtime`): the
//! conditional sampler's table and network modes against the incumbent a renderer
//! would otherwise use, Owen-scrambled Sobol (`sobol_burley`) warped by the BRDF
//! importance-sampling mixture (GGX visible normals with probability
//! `p_s = A_spec / A`, else cosine; [`BrdfTarget`]'s warp).
//!
//! Speed does not depend on the network's values, so the samplers are timed on
//! blobs with random contents ([`random_parts`]); but the table's points decide
//! where a data-dependent prior's search goes, so their tables hold what a bake
//! ships ([`with_lattice_points`]).

use super::rounds::Rounds;
use crate::conditional::blob::{ConditionalParts, MetalParts, Prior};
use crate::conditional::distill::{fill_lattice_table, info};
use crate::pointset::AlignedBytes;
use crate::sphere::{BrdfTarget, DirectionDensity, EnvmapTree};
use crate::train::target::LoadedTarget;
use anyhow::{anyhow, ensure, Result};
use glam::{DVec2, DVec3};
use nuld_core::blob::Metadata;
use nuld_core::brdf::{alpha, CONDITION_MAX, CONDITION_MIN};
use nuld_core::conditional::PointWarp;
use nuld_core::network::{Activation, Shape, MAX_HIDDEN_LAYERS};
use nuld_core::warp::brdf_mixture_real;
use nuld_runtime::glam::{Vec2, Vec3};
use nuld_runtime::Blob;
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::sync::Arc;

/// The network shape of [`random_parts`]: `n` points, the given hidden widths (1
/// to 3) and activation, a lattice residual for every warp but the equal-area
/// map ([`PointWarp::lattice_residual`]), and
/// `instance_slots` instance slots ([`Shape::with_instance_slots`]). Fails if the
/// counts describe no valid network.
pub fn random_shape(
    n: u32,
    hidden: &[u32],
    activation: Activation,
    warp: PointWarp,
    instance_slots: u32,
) -> Result<Shape> {
    ensure!(
        hidden.len() <= MAX_HIDDEN_LAYERS,
        "{} hidden layers, at most {MAX_HIDDEN_LAYERS}",
        hidden.len()
    );
    // Odd: coprime to every power of two, so the lattice's second coordinate is a
    // permutation for such n.
    let lattice_generator = (n / 3) | 1;
    Shape::new(n, hidden, activation, lattice_generator)
        .ok_or_else(|| anyhow!("n {n}, hidden {hidden:?}: no valid network"))?
        .with_lattice_residual(warp.lattice_residual())
        .with_instance_slots(instance_slots)
        .ok_or_else(|| anyhow!("{instance_slots} instance slots overflow the embedding"))
}

/// A BRDF conditional sampler (hemisphere, the BRDF's condition range: [`info`]
/// of [`LoadedTarget::GltfBrdf`]) with random contents: `n` points, `instances`
/// stored instances, a `grid` point table of random codes, a 7 x 9 weight table
/// of weights in `[0.5, 1.6)`, and a network of `shape` ([`random_shape`]) with f16
/// parameters uniform in `[-0.6, 0.6]`, with the point warp `warp` for a
/// lattice-residual shape (for the BRDF mixture a second weight-grid table of
/// lobe probabilities uniform in `[0.02, 0.98)`; for the tabulated BRDF prior its
/// tables, [`crate::sphere::brdf_prior::BrdfPrior::shared`]), else the equal-area
/// map. Deterministic for a seed.
pub fn random_parts(
    shape: Shape,
    warp: PointWarp,
    instances: u32,
    grid: [u32; 2],
    seed: u64,
) -> Result<ConditionalParts> {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let mut info = info(&shape, &LoadedTarget::gltf_brdf(), instances, grid, [7, 9]);
    if shape.lattice_residual() {
        info.warp = warp as u32;
    }
    let table_len = info
        .point_table_len()
        .ok_or_else(|| anyhow!("point table size overflows"))?;
    let MetalParts { params, table } = random_points(shape.param_len(), table_len, &mut rng);
    let nodes = info.weight_table_len();
    let weights = (0..nodes * info.weight_tables())
        .map(|e| {
            if e < nodes {
                rng.random_range(0.5f32..1.6)
            } else {
                rng.random_range(0.02f32..0.98)
            }
        })
        .collect();
    let prior = (info.point_warp() == Some(PointWarp::BrdfTable))
        .then(|| Prior::Brdf(crate::sphere::brdf_prior::BrdfPrior::shared()));
    Ok(ConditionalParts {
        info,
        params,
        table,
        weights,
        prior,
        metal: None,
        metallic_nodes: Vec::new(),
    })
}

/// A network's f16 parameters uniform in `[-0.6, 0.6]` (`params` of them) and a
/// point table of `table` random codes: [`random_parts`]' learned part.
fn random_points(params: usize, table: u64, rng: &mut impl Rng) -> MetalParts {
    MetalParts {
        params: (0..params)
            .map(|_| nuld_core::quantize::f16_encode(rng.random_range(-0.6f32..=0.6)))
            .collect(),
        table: (0..table).map(|_| rng.random()).collect(),
    }
}

/// `parts` with every point-table entry (of every metallic layer, and of the
/// metal layer's table) replaced by its instance's shifted lattice point, the
/// same at every node: the points of a bake of no steps (`bake --steps 0`, the
/// environment sampler's default from N = 256), and a trained bake's up to
/// their learned residual. A prior's search follows the points, and so does its
/// speed: random codes blended between four nodes crowd towards the square's
/// centre, whose descents the caches and the branch predictor favour
/// (environment table mode 2.03x and 2.05x the incumbent on random codes,
/// 2.43x on the lattice, the two builds taking turns).
pub fn with_lattice_points(mut parts: ConditionalParts, shape: &Shape) -> ConditionalParts {
    let instances = parts.info.instances;
    let tables =
        std::iter::once(&mut parts.table).chain(parts.metal.as_mut().map(|m| &mut m.table));
    for table in tables {
        fill_lattice_table(table, shape, instances, |k| shape.instance_offset(k));
    }
    parts
}

/// Random metal points for `parts` (a [`PointWarp::BrdfTable`] sampler on a
/// prior with the metal layer): a network and point table as long as its own,
/// drawn as [`random_parts`] draws them. Deterministic for a seed.
pub fn random_metal_points(parts: &ConditionalParts, seed: u64) -> MetalParts {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    random_points(parts.params.len(), parts.table.len() as u64, &mut rng)
}
/// `parts` (a [`PointWarp::BrdfTable`] sampler without a metallic axis) with
/// the metallic axis `nodes` ([`nuld_core::conditional::metallic_axis`]): its
/// point table grown to a layer per node, the layers after the first random
/// codes drawn as [`random_parts`] draws them (deterministic for `seed`); the
/// blob's network then reads the metallic.
pub fn with_random_metallic_axis(
    mut parts: ConditionalParts,
    nodes: &[f32],
    seed: u64,
) -> ConditionalParts {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let layer = parts.table.len();
    let more = layer * nodes.len().saturating_sub(1);
    parts.table.extend((0..more).map(|_| rng.random::<u32>()));
    parts.metallic_nodes = nodes.to_vec();
    parts
}

/// `parts` (of a lattice-residual network) as an environment sampler on the
/// prior `tree`: the sphere, conditions the normal's octahedral square `[0,1]^2`,
/// [`PointWarp::EnvmapTree`], one weight table (the mixture's lobe probabilities
/// dropped) and the tree's sections.
pub fn envmap_parts(mut parts: ConditionalParts, tree: Arc<EnvmapTree>) -> ConditionalParts {
    use nuld_core::blob::Domain;
    use nuld_core::conditional::ConditionalTarget;
    parts.info.domain = Domain::Sphere as u32;
    parts.info.target = ConditionalTarget::EnvmapNormal as u32;
    parts.info.cond_min = [0.0; 2];
    parts.info.cond_max = [1.0; 2];
    parts.info.warp = PointWarp::EnvmapTree as u32;
    parts
        .weights
        .truncate(parts.info.weight_table_len() as usize);
    parts.prior = Some(Prior::Envmap(tree));
    parts
}

fn sampler(b: &AlignedBytes) -> Result<nuld_runtime::BrdfSampler<'_>> {
    Blob::parse(b.as_slice())
        .and_then(|b| b.brdf())
        .map_err(|e| anyhow!("{e}"))
}

/// Nanoseconds per sample of each method, one thread.
#[derive(Clone, Debug)]
pub struct RuntimeTimings {
    /// `(method, median ns per sample over the rounds)`, the incumbent first.
    pub rows: Vec<(String, f64)>,
}

/// Conditions cycled through by every method: a renderer's shading points each
/// have their own. Many, so that a condition is not paired with one stored
/// instance over and over (as the environment bench's normals,
/// [`super::envmap_prior`]).
const CONDITIONS: usize = 4096;

/// Points of the cap-measure rule of the incumbent's targets: the bench calls only
/// their warp, its density and the albedo, none of which reads the rule, so a small
/// one spares building 64 rules of `2^18` points (seconds) for nothing.
const INCUMBENT_RULE_POINTS: usize = 1 << 10;

/// Times, one thread, `samples` samples per method (a tenth of it for network
/// mode), the methods taking turns over [`super::rounds::ROUNDS`] rounds
/// ([`Rounds`]; each figure the median of its rounds): the incumbent (direction
/// only in `f32`, as a renderer runs it, and in `f64`, and with its estimator
/// weight `f cos / p` as a renderer needs it), table mode (`sample` and `sample_brdf`;
/// on the BRDF mixture prior of earlier blobs, and on the default bake's
/// tabulated prior with metallic 0, 0.5 and 1 in turn, also its unbiased mode and
/// decoded network mode),
/// and network mode at n 64 with hidden [32, 32] ReLU and [64, 64] SiLU, each on
/// the blob's f16 weights and on weights decoded once
/// ([`nuld_runtime::ConditionalSampler::decode_network`]). Every
/// method cycles through the same fixed set of conditions, instance `s / n` and
/// index `s mod n` for sample `s`; the incumbent's per-condition setup (its
/// [`BrdfTarget`], albedos included) is done before timing, which favours it.
pub fn measure(samples: u32) -> Result<RuntimeTimings> {
    let n = 64u32;
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
    let conds: Vec<Vec2> = (0..CONDITIONS)
        .map(|_| {
            let r = rng.random_range(CONDITION_MIN[0] as f32..CONDITION_MAX[0] as f32);
            let t = rng.random_range(CONDITION_MIN[1] as f32..CONDITION_MAX[1] as f32);
            Vec2::new(r, t)
        })
        .collect();
    let views: Vec<Vec3> = conds
        .iter()
        .map(|c| {
            let (t, phi) = (
                c.y.to_radians(),
                rng.random_range(0.0..std::f32::consts::TAU),
            );
            Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
        })
        .collect();
    let targets = conds
        .iter()
        .map(|c| BrdfTarget::coarse(c.x as f64, c.y as f64, 0.0, INCUMBENT_RULE_POINTS))
        .collect::<Result<Vec<_>, _>>()?;
    // The same warp in `f32`, as a renderer runs it: `(wo, alpha, p_s)` per
    // condition, set up before timing as the `f64` targets are.
    let targets32: Vec<([f32; 3], f32, f32)> = targets
        .iter()
        .map(|t| {
            let wo = t.view().as_vec3().to_array();
            (wo, alpha(t.roughness()) as f32, t.lobe_probability() as f32)
        })
        .collect();
    let meta = Metadata {
        generator: "bench",
        target: "random",
        seed: 0,
    };
    // The default bake's instance slots: the embedding rows a sample reads.
    let slots = crate::train::TrainConfig::default().instance_slots;
    let blob = |hidden: &[u32], act| -> Result<AlignedBytes> {
        let shape = random_shape(n, hidden, act, PointWarp::BrdfMixture, slots)?;
        let parts = random_parts(shape, PointWarp::BrdfMixture, 16, [10, 9], 2)?;
        with_lattice_points(parts, &shape).to_blob(&meta)
    };
    let (relu, silu) = (
        blob(&[32, 32], Activation::Relu)?,
        blob(&[64, 64], Activation::Silu)?,
    );
    let (relu, silu) = (sampler(&relu)?, sampler(&silu)?);
    let at = |s: u32| (s as usize / n as usize) % CONDITIONS;
    let incumbent_u = |s: u32| {
        let seed = nuld_core::network::hash_u32(s / n);
        DVec2::new(
            sobol_burley::sample(s % n, 0, seed) as f64,
            sobol_burley::sample(s % n, 1, seed) as f64,
        )
    };
    // The default bake's sampler: the tabulated prior (shared, 17.8 MB), the
    // metal points and the default metallic axis (a query between two nodes
    // reads two layers), metallic 0, 0.5 and 1 in turn.
    let table_blob = {
        let shape = random_shape(n, &[32, 32], Activation::Relu, PointWarp::BrdfTable, slots)?;
        let mut parts = random_parts(shape, PointWarp::BrdfTable, 16, [10, 9], 2)?;
        parts.metal = Some(random_metal_points(&parts, 3));
        let nodes = crate::train::TrainConfig::default().table_metallic_nodes();
        with_lattice_points(with_random_metallic_axis(parts, &nodes, 4), &shape).to_blob(&meta)?
    };
    let prior = sampler(&table_blob)?;
    let metallic = |s: u32| [0.0, 0.5, 1.0][(s / n) as usize % 3];
    let mut prior_buf = vec![0.0f32; prior.decoded_network_len()];
    let prior_net = prior
        .decode_network(&mut prior_buf)
        .ok_or_else(|| anyhow!("decode_network refused a buffer of its own length"))?;
    let networks = [
        ("network [32,32] relu", &relu),
        ("network [64,64] silu", &silu),
    ];
    let mut bufs: Vec<Vec<f32>> = networks
        .iter()
        .map(|(_, cs)| vec![0.0f32; cs.decoded_network_len()])
        .collect();
    let decoded = networks
        .iter()
        .zip(bufs.iter_mut())
        .map(|((_, cs), buf)| {
            cs.conditional()
                .decode_network(buf)
                .ok_or_else(|| anyhow!("decode_network refused a buffer of its own length"))
        })
        .collect::<Result<Vec<_>>>()?;

    let mut rounds = Rounds::new();
    rounds.add("incumbent: owen-sobol + mixture warp (f32)", samples, |s| {
        let (wo, a, ps) = targets32[at(s)];
        let u = incumbent_u(s).as_vec2().to_array();
        black_box(brdf_mixture_real(wo, a, ps, u));
    });
    rounds.add("incumbent: owen-sobol + mixture warp (f64)", samples, |s| {
        black_box(targets[at(s)].sample(incumbent_u(s)));
    });
    rounds.add("incumbent + weight f cos / p (f64)", samples, |s| {
        let t = &targets[at(s)];
        let d: DVec3 = t.sample(incumbent_u(s));
        black_box((d, t.pdf(d) * t.albedo() / t.sample_pdf(d)));
    });
    rounds.add("table: ConditionalSampler::sample", samples, |s| {
        black_box(relu.conditional().sample(conds[at(s)], s / n, s % n));
    });
    rounds.add("table: BrdfSampler::sample", samples, |s| {
        black_box(relu.sample(views[at(s)], conds[at(s)].x, 0.0, s / n, s % n));
    });
    rounds.add(
        "tabulated prior, table: BrdfSampler::sample",
        samples,
        |s| {
            let (v, r) = (views[at(s)], conds[at(s)].x);
            black_box(prior.sample(v, r, metallic(s), s / n, s % n));
        },
    );
    rounds.add(
        "tabulated prior, table: BrdfSampler::sample_randomized",
        samples,
        |s| {
            let (v, r) = (views[at(s)], conds[at(s)].x);
            black_box(prior.sample_randomized(v, r, metallic(s), s / n, s % n, s));
        },
    );
    rounds.add(
        "tabulated prior, network [32,32] relu: decoded, BrdfNetwork::sample",
        samples / 10,
        |s| {
            let (v, r) = (views[at(s)], conds[at(s)].x);
            black_box(prior_net.sample(v, r, metallic(s), s / n, s % n));
        },
    );
    let (conds, at) = (&conds, &at);
    for ((name, cs), decoded) in networks.iter().zip(&decoded) {
        rounds.add(
            format!("{name}: zero-copy, NetworkSampler::sample"),
            samples / 10,
            move |s| {
                black_box(
                    cs.conditional()
                        .network()
                        .sample(conds[at(s)], s / n, s % n),
                );
            },
        );
        rounds.add(
            format!("{name}: decoded, NetworkSampler::sample"),
            samples / 10,
            move |s| {
                black_box(decoded.sample(conds[at(s)], s / n, s % n));
            },
        );
    }
    Ok(RuntimeTimings { rows: rounds.run() })
}
