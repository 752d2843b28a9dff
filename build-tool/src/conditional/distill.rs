//! Distillation (paper §4): from trained parameters, everything a conditional
//! blob holds.
//!
//! * **network**: the parameters rounded to f16 ([`Params::to_f16_bits`]);
//! * **point table**: for every grid node, instance `0..S` and index `0..N`, the
//!   network's square point evaluated in `f64` on the *f16-rounded* parameters
//!   (exactly what ships), as u16 unorm codes ([`unorm16_encode`], [`pack_point`]);
//!   with a metallic axis ([`nuld_core::conditional::metallic_axis`]) one such
//!   layer per metallic node, the network evaluated at that metallic;
//! * **weight table**: the glTF directional albedo `A` at every weight-grid node
//!   ([`directional_albedo`]), followed for a [`PointWarp::BrdfMixture`] sampler by
//!   the lobe probability `p_s = A_spec / A` at the same nodes (what
//!   [`crate::sphere::brdf_albedo::lobe_probability`] computes, from the same
//!   quadrature); for an environment sampler ([`nuld_core::conditional::ConditionalTarget::EnvmapNormal`])
//!   the irradiance `E(n)` of the map at every node's normal
//!   ([`EnvmapDensity::irradiance`]; of its box-filtered copy for a map larger
//!   than 1024 x 512, [`crate::train::target::EnvmapTarget::coarse_map`]);
//! * **prior**: an environment sampler on the tree
//!   ([`PointWarp::EnvmapTree`]) carries the map's tree, which the pool trained
//!   through;
//! * **metal points**: a BRDF sampler's second network (`metal`, trained on
//!   metals through the prior's metal layer, [`crate::train::BrdfLayer::Metal`]),
//!   as f16 bits with its point table, made as the first's.

use super::blob::{MetalParts, Prior};
use super::ConditionalParts;
use crate::network::{Interleaved, Params};
use crate::progress::Progress;
use crate::sphere::brdf_albedo::{directional_albedo, directional_albedo_metallic};
use crate::sphere::EnvmapDensity;
use crate::train::target::LoadedTarget;
use glam::DVec2;
use nuld_core::brdf::{BrdfModel, BrdfParts};
use nuld_core::conditional::{pack_point, torus_shift, ConditionalInfo, PointWarp};
use nuld_core::network::{lattice_point, Shape, MAX_HIDDEN_LAYERS};
use nuld_core::quantize::unorm16_encode;
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;
use std::sync::Arc;

/// The info record of a sampler of `target` over its condition range
/// ([`LoadedTarget::condition_range`]) and domain, with a network of `shape` (its
/// point warp [`PointWarp::of`]), `instances` stored instances, and the given
/// point and weight grids (nodes per axis, each `>= 2`).
pub fn info(
    shape: &Shape,
    target: &LoadedTarget,
    instances: u32,
    grid: [u32; 2],
    weight_grid: [u32; 2],
) -> ConditionalInfo {
    let mut hidden = [0u32; MAX_HIDDEN_LAYERS];
    hidden[..shape.hidden().len()].copy_from_slice(shape.hidden());
    let (lo, hi) = target.condition_range();
    let kind = target.kind();
    ConditionalInfo {
        n: shape.n(),
        instances,
        domain: kind.domain() as u32,
        target: kind as u32,
        grid,
        weight_grid,
        cond_min: lo.map(|x| x as f32),
        cond_max: hi.map(|x| x as f32),
        hidden,
        activation: shape.activation() as u32,
        lattice_generator: shape.lattice_generator(),
        warp: PointWarp::of(kind, shape) as u32,
        instance_slots: shape.instance_slots(),
        offset_hash: shape.offset_hash() as u32,
    }
}

/// The blob's parts for `params` trained on `target` (see the module docs), with
/// the metal points of `metal` (a network of the same shape, without the
/// metallic input) where given, and a point-table layer per metallic node of
/// `metallic_nodes` (empty: one layer, at metallic 0, for a network that does
/// not read it). Parallel over grid nodes; identical for any thread count.
pub fn distill(
    params: &Params,
    metal: Option<&Params>,
    target: &LoadedTarget,
    instances: u32,
    grid: [u32; 2],
    weight_grid: [u32; 2],
    metallic_nodes: &[f32],
) -> ConditionalParts {
    let info = info(&params.shape, target, instances, grid, weight_grid);
    // Progress in grid nodes: each point-table layer's, then the weight table's.
    let layers = metallic_nodes.len().max(1) + usize::from(metal.is_some());
    let nodes = (grid[0] * grid[1]) as u64;
    let weight_nodes = (weight_grid[0] * weight_grid[1]) as u64;
    let progress = Progress::stderr("distill", layers as u64 * nodes + weight_nodes, "node");
    let table = match metallic_nodes {
        [] => point_table(params, 0.0, instances, grid, &progress),
        nodes => nodes
            .iter()
            .flat_map(|&m| point_table(params, m as f64, instances, grid, &progress))
            .collect(),
    };
    let metal = metal.map(|metal| MetalParts {
        params: metal.to_f16_bits(),
        table: point_table(metal, 1.0, instances, grid, &progress),
    });
    let (weights, prior) = match target {
        LoadedTarget::GltfBrdf(prior) => (
            {
                let w = brdf_weights(&info);
                progress.inc(weight_nodes);
                w
            },
            (info.point_warp() == Some(PointWarp::BrdfTable))
                .then(|| Prior::Brdf(Arc::clone(prior))),
        ),
        LoadedTarget::Envmap(env) => (
            envmap_weights(&info, env.coarse_map(), &progress),
            (info.point_warp() == Some(PointWarp::EnvmapTree))
                .then(|| Prior::Envmap(Arc::new(env.tree.clone()))),
        ),
    };
    progress.finish();
    ConditionalParts {
        info,
        params: params.to_f16_bits(),
        table,
        weights,
        prior,
        metal,
        metallic_nodes: metallic_nodes.to_vec(),
    }
}

/// One layer of the point table of `params` (see the module docs): at every
/// node of `grid`, for instances `0..instances` and every index, the square
/// point of the f16-rounded network at metallic `m` (read only by a network
/// with the metallic input) as u16 unorm codes. Parallel over nodes; identical
/// for any thread count.
fn point_table(
    params: &Params,
    m: f64,
    instances: u32,
    grid: [u32; 2],
    progress: &Progress,
) -> Vec<u32> {
    let shipped = params.rounded_to_f16();
    let forward = Interleaved::new(shipped.shape, &shipped.values);
    let n = shipped.shape.n();
    let nodes = (grid[0] * grid[1]) as usize;
    (0..nodes)
        .into_par_iter()
        .flat_map_iter(|node| {
            progress.inc(1);
            // Node j's normalized condition is j / (nodes - 1), what the reader
            // computes there.
            let unit = [
                (node as u32 % grid[0]) as f64 / (grid[0] - 1) as f64,
                (node as u32 / grid[0]) as f64 / (grid[1] - 1) as f64,
            ];
            let net = forward.network();
            (0..instances).flat_map(move |k| {
                (0..n).map(move |i| {
                    let p = net.square_point_at(unit, m, k, i);
                    pack_point(unorm16_encode(p[0]), unorm16_encode(p[1]))
                })
            })
        })
        .collect()
}

/// Fills a point table (entries `(node, k, i)` in the blob's order, `k` below
/// `instances`) with the untrained lattice: point `i` of `shape`'s rank-1
/// lattice shifted on the torus by `offset(k)`, as u16 unorm codes. What a bake
/// whose learned residual is dropped ships (to its network's rounding), for
/// the benches and examples that time or judge the lattice in a blob's place
/// (`lab::bench::runtime::with_lattice_points`, `examples/offset_sets.rs`).
pub fn fill_lattice_table(
    table: &mut [u32],
    shape: &Shape,
    instances: u32,
    offset: impl Fn(u32) -> [f64; 2],
) {
    let (n, g) = (shape.n() as u64, shape.lattice_generator());
    for (at, code) in table.iter_mut().enumerate() {
        let (k, i) = (
            (at as u64 / n % instances as u64) as u32,
            (at as u64 % n) as u32,
        );
        let p = torus_shift(lattice_point::<f64>(i, n as u32, g), offset(k));
        *code = pack_point(unorm16_encode(p[0]), unorm16_encode(p[1]));
    }
}

/// The irradiance `E(n)` at every weight-grid node's normal.
fn envmap_weights(info: &ConditionalInfo, map: &EnvmapDensity, progress: &Progress) -> Vec<f32> {
    let g = info.weight_grid;
    let normals: Vec<_> = (0..g[0] * g[1])
        .map(|node| {
            let u = info.weight_grid_condition([node % g[0], node / g[0]]);
            square_to_sphere(DVec2::from(u))
        })
        .collect();
    // In rows of nodes, for the progress: each normal's sum is the same alone or
    // in any group (`EnvmapDensity::irradiances`).
    normals
        .chunks(g[0].max(1) as usize)
        .flat_map(|row| {
            let e = map.irradiances(row);
            progress.inc(row.len() as u64);
            e
        })
        .map(|e| e as f32)
        .collect()
}

/// The albedo `A`, then for the mixture warp `p_s`, for the tabulated prior the
/// metal's albedo, at every weight-grid node.
fn brdf_weights(info: &ConditionalInfo) -> Vec<f32> {
    let weight_grid = info.weight_grid;
    let weight_nodes = weight_grid[0] * weight_grid[1];
    let condition =
        |node: u32| info.weight_grid_condition([node % weight_grid[0], node / weight_grid[0]]);
    // One quadrature per node gives both tables: `A` and `p_s = A_spec / A`.
    let albedos: Vec<BrdfParts<f64>> = (0..weight_nodes)
        .into_par_iter()
        .map(|node| {
            let c = condition(node);
            directional_albedo(BrdfModel::Gltf, c[0], c[1])
        })
        .collect();
    let mut weights: Vec<f32> = albedos.iter().map(|a| a.total() as f32).collect();
    match info.point_warp() {
        Some(PointWarp::BrdfMixture) => {
            weights.extend(albedos.iter().map(|a| (a.specular / a.total()) as f32));
        }
        Some(PointWarp::BrdfTable) => {
            let metal: Vec<f32> = (0..weight_nodes)
                .into_par_iter()
                .map(|node| {
                    let c = condition(node);
                    directional_albedo_metallic(c[0], c[1], 1.0).total() as f32
                })
                .collect();
            weights.extend(metal);
        }
        _ => {}
    }
    weights
}

#[cfg(test)]
mod tests {
    use super::*;
    use nuld_core::conditional::unpack_point;
    use nuld_core::network::Activation;
    use nuld_core::quantize::{f16_decode, unorm16_decode_f64};

    #[test]
    fn table_holds_the_shipped_network_and_weights_the_albedo() {
        let shape = Shape::new(5, &[6], Activation::Relu, 2).unwrap();
        let params = Params::init(shape, 4);
        let parts = distill(
            &params,
            None,
            &LoadedTarget::gltf_brdf(),
            3,
            [3, 2],
            [4, 3],
            &[],
        );
        assert_eq!(parts.table.len(), 3 * 2 * 3 * 5);
        assert_eq!(parts.weights.len(), 12);
        // Entry (node (2, 1), instance 2, index 4) against the network evaluated by
        // hand on the decoded f16 parameters at roughness 1, theta_o 89.
        let decoded = Params {
            shape,
            values: parts.params.iter().map(|&b| f16_decode(b) as f64).collect(),
        };
        let want = decoded.trace([1.0, 1.0], 0.0, 2, 4).square_point();
        let got = unpack_point(parts.table[parts.info.point_table_index(5, 2, 4)]);
        for a in 0..2 {
            assert!((unorm16_decode_f64(got[a]) - want[a]).abs() <= 1.0 / 131072.0 + 1e-12);
        }
        // Weight node (3, 0): roughness 1, theta_o 0 (reference albedo 0.972228).
        assert!((parts.weights[3] as f64 - 0.972228).abs() < 1e-6);
        // Node (0, 2) of the weight grid: roughness 0.1, theta_o 89.
        let c = parts.info.weight_grid_condition([0, 2]);
        assert_eq!(c[1], 89.0);
        let a = directional_albedo(BrdfModel::Gltf, c[0], c[1]).total();
        assert_eq!(parts.weights[8], a as f32);
    }

    #[test]
    fn a_metallic_axis_stores_a_layer_per_node_at_that_metallic() {
        let shape = Shape::new(4, &[6], Activation::Relu, 3)
            .unwrap()
            .with_metallic_input(true);
        let params = Params::init(shape, 9);
        let nodes = [0.0, 0.5, 0.95];
        let target = LoadedTarget::gltf_brdf();
        let parts = distill(&params, None, &target, 2, [3, 2], [4, 3], &nodes);
        let layer = 3 * 2 * 2 * 4;
        assert_eq!(parts.table.len(), 3 * layer);
        assert_eq!(parts.metallic_nodes, nodes);
        let decoded = Params {
            shape,
            values: parts.params.iter().map(|&b| f16_decode(b) as f64).collect(),
        };
        // Node (1, 1) = normalized (0.5, 1), instance 1, index 3, in each layer:
        // the network evaluated by hand at the layer's metallic.
        for (j, &m) in nodes.iter().enumerate() {
            let want = decoded.trace([0.5, 1.0], m as f64, 1, 3).square_point();
            let at = j * layer + parts.info.point_table_index(4, 1, 3);
            let got = unpack_point(parts.table[at]);
            for a in 0..2 {
                assert!((unorm16_decode_f64(got[a]) - want[a]).abs() <= 1.0 / 131072.0 + 1e-12);
            }
        }
        // The layers differ: the network reads the metallic.
        assert_ne!(parts.table[..layer], parts.table[layer..2 * layer]);
    }

    #[test]
    fn info_records_each_targets_code_domain_range_and_warp() {
        use nuld_core::blob::Domain;
        use nuld_core::brdf::{CONDITION_MAX, CONDITION_MIN};
        let shape = Shape::new(5, &[6, 3], Activation::Relu, 2).unwrap();
        let brdf = info(
            &shape.with_lattice_residual(true),
            &LoadedTarget::gltf_brdf(),
            3,
            [3, 2],
            [4, 5],
        );
        assert_eq!((brdf.target, brdf.domain), (1, Domain::Hemisphere as u32));
        assert_eq!(brdf.cond_min, CONDITION_MIN.map(|x| x as f32));
        assert_eq!(brdf.cond_max, CONDITION_MAX.map(|x| x as f32));
        assert_eq!(brdf.warp, PointWarp::BrdfTable as u32);
        assert_eq!(
            (brdf.n, brdf.instances, brdf.grid, brdf.weight_grid),
            (5, 3, [3, 2], [4, 5])
        );
        assert_eq!((brdf.hidden, brdf.lattice_generator), ([6, 3, 0], 2));
        assert_eq!(brdf.shape(), Some(shape.with_lattice_residual(true)));

        let dir = std::env::temp_dir().join(format!("nuld-distill-info-{}", std::process::id()));
        let map = crate::train::target::TrainTarget::envmap(&crate::sphere::envmap::tiny_map(&dir))
            .unwrap()
            .load()
            .unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        let env = info(&shape, &map, 3, [3, 2], [4, 5]);
        assert_eq!((env.target, env.domain), (2, Domain::Sphere as u32));
        assert_eq!((env.cond_min, env.cond_max), ([0.0; 2], [1.0; 2]));
        assert_eq!(env.warp, PointWarp::EqualArea as u32);
        assert_eq!(env.shape(), Some(shape));
    }
}
