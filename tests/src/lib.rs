//! Cross-crate conformance tests for nuld (see `tests/tests/`): the runtime returns
//! what the build tool wrote, hostile bytes never make it panic, and it builds
//! without `std` or an allocator.
//!
//! This library holds the fixtures those tests share.

pub mod capi;

use nuld_build_tool::pointset::{AlignedBytes, PointSets};
use nuld_core::blob::{Domain, Metadata};

/// Metadata used by the fixtures.
pub const META: Metadata<'static> = Metadata {
    generator: "conformance-test",
    target: "uniform",
    seed: 42,
};

/// Owen-scrambled Sobol sets as the build tool makes them, encoded as a blob.
pub fn sobol_blob(domain: Domain, n: usize, sets: usize, seed: u64) -> (PointSets, AlignedBytes) {
    let ps = PointSets {
        domain,
        sets: (0..sets)
            .map(|s| {
                nuld_build_tool::baselines::owen_sobol(
                    n,
                    nuld_build_tool::seeding::derive_seed(seed, s as u64) as u32,
                )
            })
            .collect(),
    };
    let bytes = ps.to_blob(&META).expect("encodable point sets");
    (ps, bytes)
}

/// A conditional sampler (kind 3) with random contents, as a stand-in for a trained
/// one ([`nuld_build_tool::lab::bench::runtime::random_parts`]; the benchmark times the
/// same blobs), of a network [`shape`].
pub fn conditional_parts(
    (shape, warp): (nuld_core::network::Shape, nuld_core::conditional::PointWarp),
    instances: u32,
    grid: [u32; 2],
    seed: u64,
) -> nuld_build_tool::conditional::blob::ConditionalParts {
    nuld_build_tool::lab::bench::runtime::random_parts(shape, warp, instances, grid, seed)
        .expect("a valid fixture")
}

/// The network shape of a [`conditional_parts`] fixture
/// ([`nuld_build_tool::lab::bench::runtime::random_shape`]) and the warp it is
/// made for.
pub fn shape(
    n: u32,
    hidden: &[u32],
    activation: nuld_core::network::Activation,
    warp: nuld_core::conditional::PointWarp,
    instance_slots: u32,
) -> (nuld_core::network::Shape, nuld_core::conditional::PointWarp) {
    let shape = nuld_build_tool::lab::bench::runtime::random_shape(
        n,
        hidden,
        activation,
        warp,
        instance_slots,
    )
    .expect("a valid fixture shape");
    (shape, warp)
}

/// A BRDF sampler briefly trained (40 + 40 steps of a 16-point, [16, 16] network:
/// enough to leave the initialization, a few seconds) and distilled into `instances`
/// stored instances on a `grid` point table and a `weight_grid` weight table,
/// with its metal points (a second network, trained as briefly on metals).
pub fn distilled_parts(
    instances: u32,
    grid: [u32; 2],
    weight_grid: [u32; 2],
) -> nuld_build_tool::conditional::blob::ConditionalParts {
    use nuld_build_tool::train::{TrainConfig, Trainer};
    let config = TrainConfig {
        n: 16,
        hidden: vec![16, 16],
        steps: 40,
        pretrain_steps: 40,
        conditions_per_step: 4,
        instances_per_condition: 2,
        pool_conditions: 8,
        pool_caps: 128,
        caps_per_step: 64,
        ..TrainConfig::default()
    };
    let trained = |config: TrainConfig| {
        let mut trainer = Trainer::new(config, None).expect("the BRDF pool reads no file");
        while !trainer.done() {
            trainer.step();
        }
        trainer
    };
    let metal = trained(TrainConfig {
        layer: nuld_build_tool::train::BrdfLayer::Metal,
        ..config.clone()
    });
    let nodes = config.table_metallic_nodes();
    let trainer = trained(config);
    nuld_build_tool::conditional::distill::distill(
        &trainer.params(),
        Some(&metal.params()),
        &trainer.pool.target,
        instances,
        grid,
        weight_grid,
        &nodes,
    )
}

/// `parts` (a [`nuld_core::conditional::PointWarp::BrdfTable`] sampler without
/// a metallic axis) with the metallic axis `nodes`, the layers after the first
/// random: the benchmark's own fixture.
pub use nuld_build_tool::lab::bench::runtime::with_random_metallic_axis as with_metallic_axis;

/// A tree of 4 levels (top weights on 3 x 3 normals) over a closed-form light, a
/// sky brighter towards `+z`, a small sun and a dim lamp 2° across: the sun's
/// leaves drawn by fine tables (tag 22), the lamp's by a detail table (tags 20
/// and 21): the prior of the environment fixtures (built once per test binary).
pub fn fixture_tree() -> std::sync::Arc<nuld_build_tool::sphere::EnvmapTree> {
    static TREE: std::sync::OnceLock<std::sync::Arc<nuld_build_tool::sphere::EnvmapTree>> =
        std::sync::OnceLock::new();
    let tree = TREE.get_or_init(|| {
        use nuld_runtime::glam::{DVec2, DVec3};
        let sun = DVec3::new(0.6, -0.3, 0.5).normalize();
        // At a leaf's centre, so that the tree's contrast test sees it; 0.3 %
        // of the light, under the share that earns a fine table.
        let lamp = nuld_core::sphere::square_to_sphere(DVec2::new(3.5 / 16.0, 12.5 / 16.0));
        let lamp_edge = 2f64.to_radians().cos();
        let light = move |d: DVec3| {
            let lamp = if d.dot(lamp) > lamp_edge { 3.0 } else { 0.0 };
            0.2 + d.z.max(0.0) + 20.0 * (-(1.0 - d.dot(sun)) * 300.0).exp() + lamp
        };
        let tree =
            nuld_build_tool::sphere::EnvmapTree::from_light(light, 4, 3).expect("a lit fixture");
        // The conformance and shader tests read the detail through it.
        assert!(
            !tree.detail.is_empty() && !tree.fine.is_empty(),
            "the fixture's sun has fine tables, its lamp a detail table"
        );
        std::sync::Arc::new(tree)
    });
    std::sync::Arc::clone(tree)
}

/// `parts` as an environment sampler on its prior, [`fixture_tree`]
/// ([`nuld_build_tool::lab::bench::runtime::envmap_parts`]); the shape's output a
/// lattice residual (as [`shape`] makes for a non-equal-area warp).
pub fn as_envmap(
    parts: nuld_build_tool::conditional::blob::ConditionalParts,
) -> nuld_build_tool::conditional::blob::ConditionalParts {
    nuld_build_tool::lab::bench::runtime::envmap_parts(parts, fixture_tree())
}

/// A small tabulated BRDF prior (3 x 2 x 3 conditions, the metal layer
/// included, 5 x 5 half-vector vertices; built once per test binary): for
/// blobs whose every byte a test visits.
pub fn small_brdf_prior() -> std::sync::Arc<nuld_build_tool::sphere::brdf_prior::BrdfPrior> {
    use nuld_build_tool::sphere::brdf_prior::{BrdfPrior, PriorSpace};
    static PRIOR: std::sync::OnceLock<std::sync::Arc<BrdfPrior>> = std::sync::OnceLock::new();
    let prior = PRIOR.get_or_init(|| {
        std::sync::Arc::new(
            BrdfPrior::new([3, 2, 3], 5, PriorSpace::HalfVector).expect("a valid prior"),
        )
    });
    std::sync::Arc::clone(prior)
}

/// `parts` (a [`nuld_core::conditional::PointWarp::BrdfTable`] sampler on a
/// prior with the metal layer) with random metal points
/// ([`nuld_build_tool::lab::bench::runtime::random_metal_points`]).
pub fn with_metal_points(
    mut parts: nuld_build_tool::conditional::blob::ConditionalParts,
    seed: u64,
) -> nuld_build_tool::conditional::blob::ConditionalParts {
    parts.metal = Some(nuld_build_tool::lab::bench::runtime::random_metal_points(
        &parts, seed,
    ));
    parts
}

/// `parts` (a [`nuld_core::conditional::PointWarp::BrdfTable`] sampler) with
/// `prior` as its tabulated prior.
pub fn with_brdf_prior(
    mut parts: nuld_build_tool::conditional::blob::ConditionalParts,
    prior: std::sync::Arc<nuld_build_tool::sphere::brdf_prior::BrdfPrior>,
) -> nuld_build_tool::conditional::blob::ConditionalParts {
    parts.prior = Some(nuld_build_tool::conditional::blob::Prior::Brdf(prior));
    parts
}
