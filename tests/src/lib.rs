//! Cross-crate conformance tests for nuld (see `tests/tests/`): the runtime returns
//! what the build tool wrote, hostile bytes never make it panic, and it builds
//! without `std` or an allocator.
//!
//! This library holds the fixtures those tests share.

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
/// one: a BRDF sampler (hemisphere, roughness `[0.1, 1]` x `theta_o` `[0°, 89°]`)
/// with `n` points, `instances` stored instances, a `grid` point table of random
/// codes, a 7 x 9 weight table of random weights in `[0.5, 1.6)`, and a network of
/// the given hidden widths whose f16 parameters are uniform in `[-0.6, 0.6]`.
/// Deterministic for a seed. Speed and conformance do not depend on the values.
pub fn conditional_parts(
    n: u32,
    hidden: &[u32],
    activation: nuld_core::network::Activation,
    instances: u32,
    grid: [u32; 2],
    seed: u64,
) -> nuld_build_tool::conditional::blob::ConditionalParts {
    use nuld_core::conditional::{ConditionalInfo, ConditionalTarget};
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let mut widths = [0u32; 3];
    widths[..hidden.len()].copy_from_slice(hidden);
    let info = ConditionalInfo {
        n,
        instances,
        domain: Domain::Hemisphere as u32,
        target: ConditionalTarget::GltfBrdf as u32,
        grid,
        weight_grid: [7, 9],
        cond_min: [0.1, 0.0],
        cond_max: [1.0, 89.0],
        hidden: widths,
        activation: activation as u32,
        // Coprime to every power of two: the lattice's second coordinate permutes.
        lattice_generator: (n / 3) | 1,
        reserved: [0; 3],
    };
    let shape = info.shape().expect("a valid fixture shape");
    let params = (0..shape.param_len())
        .map(|_| nuld_core::quantize::f16_encode(rng.random_range(-0.6f32..=0.6)))
        .collect();
    let table_len = info.point_table_len().expect("a small fixture table") as usize;
    let table = (0..table_len).map(|_| rng.random()).collect();
    let weights = (0..info.weight_table_len())
        .map(|_| rng.random_range(0.5f32..1.6))
        .collect();
    nuld_build_tool::conditional::blob::ConditionalParts {
        info,
        params,
        table,
        weights,
    }
}
