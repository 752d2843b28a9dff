extern crate std;
use super::*;
use crate::Blob;
use crate::{BrdfNetwork, BrdfSampler, EnvmapNetwork, EnvmapSampler};
use bytemuck::Zeroable;
use nuld_core::blob::{encoded_len, write, BlobKind};
use nuld_core::blob::{BlobError, ConditionalError, SectionTag};
use nuld_core::conditional::{randomization_shift, sections, torus_shift};
use nuld_core::envmap_tree::{
    build, detail_index_len, node_count, top_len, top_normal, top_row, EnvmapTree, NodeRecord,
    TreeInfo, DETAIL_LEN, DETAIL_SIDE, FINE_BIT, FINE_LEN, FINE_SIDE, LEGACY_TOP_LEVELS,
    TOP_LEVELS,
};
use nuld_core::network::{instance_offset, interleaved_index, lattice_point, Activation};
use nuld_core::quadtree::QuadtreeError;
use nuld_core::quantize::{f16_decode_finite, f16_encode};
use std::vec::Vec;

/// The four sections of a conditional blob, owned, for building test blobs.
#[derive(Clone)]
struct Parts {
    info: ConditionalInfo,
    params: Vec<u16>,
    table: Vec<u32>,
    weights: Vec<f32>,
    /// An environment prior.
    tree: Option<TreeParts>,
    /// Its detail index and tables (empty: none).
    detail: DetailParts,
}

/// An environment prior's detail, owned: index, tables, fine tables.
type DetailParts = (Vec<u32>, Vec<f32>, Vec<f32>);

/// An environment prior's sections, owned: info, records, top weights.
type TreeParts = (TreeInfo, Vec<NodeRecord>, Vec<f32>);

/// A 16-byte aligned blob.
struct Bytes(Vec<u128>, usize);

impl Bytes {
    fn get(&self) -> &[u8] {
        &bytemuck::cast_slice(&self.0)[..self.1]
    }
}

/// Deterministic pseudo-random numbers for test contents (`hash_u32` chain).
fn noise(seed: u32, k: u32) -> u32 {
    nuld_core::network::hash_u32(seed.wrapping_mul(0x9e37_79b9) ^ nuld_core::network::hash_u32(k))
}

fn parts() -> Parts {
    let info = ConditionalInfo {
        n: 5,
        instances: 3,
        domain: Domain::Hemisphere as u32,
        target: ConditionalTarget::GltfBrdf as u32,
        grid: [5, 3],
        weight_grid: [4, 6],
        cond_min: [0.0, 0.0],
        cond_max: [1.0, 80.0],
        hidden: [4, 3, 0],
        activation: Activation::Silu as u32,
        lattice_generator: 2,
        warp: 0,
        instance_slots: 0,
        offset_hash: 1,
    };
    let len = info.shape().unwrap().param_len();
    let params = (0..len as u32)
        .map(|j| f16_encode((noise(1, j) % 2001) as f32 / 1000.0 - 1.0))
        .collect();
    let table = (0..info.point_table_len().unwrap() as u32)
        .map(|e| noise(2, e))
        .collect();
    // A bilinear function of the normalized condition, which bilinear
    // interpolation must reproduce: w = 1 + 0.5 x - 0.25 y + 0.125 x y.
    let (wx, wy) = (info.weight_grid[0], info.weight_grid[1]);
    let weights = (0..wx * wy)
        .map(|e| {
            let x = (e % wx) as f32 / (wx - 1) as f32;
            let y = (e / wx) as f32 / (wy - 1) as f32;
            bilinear_weight(x, y)
        })
        .collect();
    Parts {
        info,
        params,
        table,
        weights,
        tree: None,
        detail: (Vec::new(), Vec::new(), Vec::new()),
    }
}

fn bilinear_weight(x: f32, y: f32) -> f32 {
    1.0 + 0.5 * x - 0.25 * y + 0.125 * x * y
}

fn encode(p: &Parts) -> Bytes {
    let mut sections = sections(&p.info, &p.params, &p.table, &p.weights).to_vec();
    if let Some((info, nodes, top)) = &p.tree {
        sections.extend(nuld_core::envmap_tree::sections(info, nodes, top));
    }
    let (index, tables, fine) = &p.detail;
    if !index.is_empty() {
        sections.push(nuld_core::envmap_tree::detail_sections(index, tables)[0]);
    }
    if !tables.is_empty() {
        sections.push(nuld_core::envmap_tree::detail_sections(index, tables)[1]);
    }
    if !fine.is_empty() {
        sections.push(nuld_core::envmap_tree::fine_section(fine));
    }
    let meta = [0u8, 0, 0];
    let len = encoded_len(&meta, &sections);
    let mut buf = std::vec![0u128; len.div_ceil(16)];
    let out = &mut bytemuck::cast_slice_mut::<u128, u8>(&mut buf)[..len];
    write(out, BlobKind::Conditional, &meta, &sections).unwrap();
    Bytes(buf, len)
}

fn with(change: impl FnOnce(&mut Parts)) -> Result<(), BlobError> {
    let mut p = parts();
    change(&mut p);
    let bytes = encode(&p);
    Blob::parse(bytes.get()).map(|_| ())
}

#[test]
fn a_decoded_network_samples_the_same_bits() {
    let bytes = encode(&parts());
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    let len = cs.decoded_network_len();
    assert_eq!(len, cs.shape().param_len());
    assert!(cs.decode_network(&mut std::vec![0.0; len - 1]).is_none());
    let mut buf = std::vec![f32::NAN; len + 3];
    let fast = cs.decode_network(&mut buf).unwrap();
    for k in 0..2000u32 {
        let c = Vec2::new(
            (noise(3, k) % 1300) as f32 / 1000.0 - 0.1,
            (noise(4, k) % 900) as f32 / 10.0,
        );
        let (instance, i) = (noise(5, k), k % 11);
        let wo = Vec3::new(c.y.to_radians().sin(), 0.3, c.y.to_radians().cos());
        let n = Vec3::new(c.x - 0.5, 0.2, 1.0);
        assert_eq!(
            fast.sample(c, instance, i),
            cs.network().sample(c, instance, i)
        );
        assert_eq!(
            BrdfNetwork(fast).sample(wo, c.x, 0.0, instance, i),
            BrdfSampler(cs).network().sample(wo, c.x, 0.0, instance, i)
        );
        assert_eq!(
            EnvmapNetwork(fast).sample(n, instance, i),
            EnvmapSampler(cs).network().sample(n, instance, i)
        );
        // Table mode does not read the network.
        assert_eq!(
            fast.table().sample(c, instance, i),
            cs.sample(c, instance, i)
        );
    }
    // Decoding a decoded sampler copies its weights.
    let mut again = std::vec![0.0; len];
    let twice = fast.table().decode_network(&mut again).unwrap();
    let c = Vec2::new(0.4, 33.0);
    assert_eq!(twice.sample(c, 8, 3), cs.network().sample(c, 8, 3));
    assert_eq!(again, buf[..len]);
    // The weights are the f16 values decoded, each where the interleaved layout
    // puts it (the first layer's four rows are a block, interleaved; the rest
    // keep their places); the rest of the buffer is untouched.
    let Parts { params, .. } = parts();
    let shape = cs.shape();
    assert!(params
        .iter()
        .enumerate()
        .all(|(j, &h)| f16_decode_finite(h) == buf[interleaved_index(&shape, j)]));
    let first = shape.layers().next().unwrap();
    assert_eq!(
        buf[first.weights + 1],
        f16_decode_finite(params[first.weights + first.fan_in]),
        "weight 0 of row 1 follows weight 0 of row 0"
    );
    assert!(buf[len..].iter().all(|v| v.is_nan()));
}

#[test]
fn corners_reproduce_the_stored_points_exactly() {
    let p = parts();
    let bytes = encode(&p);
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    let info = p.info;
    for j1 in 0..info.grid[1] {
        for j0 in 0..info.grid[0] {
            let c = info.grid_condition([j0, j1]).map(|x| x as f32);
            let node = (j1 * info.grid[0] + j0) as usize;
            for k in 0..info.instances {
                for i in 0..info.n {
                    let w = p.table[info.point_table_index(node, k, i)];
                    let q = unpack_point(w);
                    let want = Vec2::new(unorm16_decode(q[0]), unorm16_decode(q[1]));
                    assert_eq!(
                        cs.square_point(Vec2::from(c), k, i),
                        want,
                        "{j0} {j1} {k} {i}"
                    );
                }
            }
        }
    }
}

/// A tree of 4 levels over a light brighter towards `+x` and `+z`, top weights
/// on 3 x 3 normals, as written today ([`TOP_LEVELS`] tabulated).
fn test_tree() -> TreeParts {
    test_tree_of(TOP_LEVELS)
}

/// [`test_tree`] with `top_levels` levels in its top table, the info naming
/// them (0, as blobs written before the field, for [`LEGACY_TOP_LEVELS`]).
fn test_tree_of(top_levels: u32) -> TreeParts {
    let levels = 4;
    let side = 1usize << levels;
    let leaves: Vec<[f64; 4]> = (0..side * side)
        .map(|k| {
            let p = [
                ((k % side) as f64 + 0.5) / side as f64,
                ((k / side) as f64 + 0.5) / side as f64,
            ];
            let d = nuld_core::sphere::square_to_sphere_real(p);
            let light = 0.1 + d[0].max(0.0) + 3.0 * d[2].max(0.0).powi(4);
            [light, light * d[0], light * d[1], light * d[2]]
        })
        .collect();
    let mut nodes = std::vec![NodeRecord::zeroed(); node_count(levels)];
    build(levels, &leaves, &mut nodes).unwrap();
    let grid = 3;
    let mut top = std::vec![0.0; top_len(grid, top_levels)];
    for (r, row) in top.chunks_mut(node_count(top_levels)).enumerate() {
        top_row(
            levels,
            top_levels,
            &nodes,
            top_normal(grid, [r as u32 % grid, r as u32 / grid]),
            row,
        );
    }
    let info = TreeInfo {
        levels,
        grid,
        top_levels: if top_levels == LEGACY_TOP_LEVELS {
            0
        } else {
            top_levels
        },
        reserved: 0,
    };
    (info, nodes, top)
}

/// Detail for [`test_tree`]: every third leaf (86 of 256) drawn by its own
/// table, every fifth of those (18) a fine one; each a dim noise with one
/// bright cell (a sun inside the leaf), stored as `cell_table` reads it (column
/// sums, then the cells column by column).
fn test_detail() -> DetailParts {
    let mut index = std::vec![0u32; detail_index_len(4)];
    let (mut tables, mut fine) = (Vec::new(), Vec::new());
    for (k, leaf) in (0..index.len()).step_by(3).enumerate() {
        let (n, out, bit, len) = if k % 5 == 0 {
            (FINE_SIDE, &mut fine, FINE_BIT, FINE_LEN)
        } else {
            (DETAIL_SIDE, &mut tables, 0, DETAIL_LEN)
        };
        let t = (out.len() / len) as u32;
        index[leaf] = bit | (t + 1);
        let bright = noise(t, 7) as usize % (n * n);
        let cells: Vec<f32> = (0..n * n)
            .map(|c| {
                if c == bright {
                    40.0
                } else {
                    0.05 + (noise(t, c as u32) % 1000) as f32 / 1000.0
                }
            })
            .collect();
        out.extend(cells.chunks(n).map(|c| c.iter().sum::<f32>()));
        out.extend(cells);
    }
    (index, tables, fine)
}

/// An environment sampler's parts: `parts()` on the sphere, conditions the
/// octahedral square, the tree prior.
fn envmap_parts() -> Parts {
    let mut p = parts();
    p.info.domain = Domain::Sphere as u32;
    p.info.target = ConditionalTarget::EnvmapNormal as u32;
    p.info.cond_min = [0.0; 2];
    p.info.cond_max = [1.0; 2];
    p.info.warp = PointWarp::EnvmapTree as u32;
    p.tree = Some(test_tree());
    p.detail = test_detail();
    p
}

/// A blob written before `TreeInfo::top_levels` (the field 0, a top table of
/// [`LEGACY_TOP_LEVELS`] levels) still loads, and samples the tree that core
/// reads from its sections, with its pdf.
#[test]
fn envmap_blobs_of_the_legacy_top_depth_load_and_sample_their_tree() {
    let mut p = envmap_parts();
    p.tree = Some(test_tree_of(LEGACY_TOP_LEVELS));
    let (ti, nodes, top) = p.tree.clone().unwrap();
    assert_eq!((ti.top_levels, ti.top_levels()), (0, LEGACY_TOP_LEVELS));
    assert_eq!(top.len(), 9 * 84);
    let bytes = encode(&p);
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    let tree = EnvmapTree::new(ti.levels, &nodes, ti.grid, &top, LEGACY_TOP_LEVELS)
        .and_then(|t| t.with_detail(&p.detail.0, &p.detail.1))
        .and_then(|t| t.with_fine_detail(&p.detail.2))
        .unwrap();
    let today = test_tree();
    let today = EnvmapTree::new(4, &today.1, 3, &today.2, TOP_LEVELS).unwrap();
    let mut differs = 0;
    for k in 0..64u32 {
        let q = [(k % 8) as f32 / 7.0, (k / 8) as f32 / 7.0];
        let u = [0.37f32, 0.81];
        let got = cs.sample_randomized(Vec2::from(q), k, 3, 11);
        let point = torus_shift(
            torus_shift(
                lattice_point::<f32>(3, p.info.n, p.info.lattice_generator),
                instance_offset(k),
            ),
            randomization_shift(11),
        );
        let (want, pdf) = tree.sample_square(q, point);
        assert_eq!((got.direction.to_array(), got.pdf), (want, pdf), "{k}");
        assert_eq!(
            cs.pdf(Vec2::from(q), got.direction),
            tree.pdf_square(q, want)
        );
        // The depth is read: level 4's tabulated weights move some samples.
        differs += usize::from(today.sample_square(q, u) != tree.sample_square(q, u));
    }
    assert!(differs > 8, "{differs}");
}

/// Table mode of an environment sampler: the corners' stored primary points
/// interpolated bilinearly in the square (at a node the stored point), then the
/// tree's warp at the normal of the condition, whose pdf the sample carries;
/// `pdf` answers the same for the direction; the unbiased mode warps the point
/// shifted on the torus; `EnvmapSampler` reads a normal as its octahedral square
/// point.
#[test]
fn envmap_tables_interpolate_primary_points_and_warp_them_through_the_tree() {
    let p = envmap_parts();
    let bytes = encode(&p);
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    assert_eq!(cs.target(), ConditionalTarget::EnvmapNormal);
    let (ti, nodes, top) = p.tree.clone().unwrap();
    let tree = EnvmapTree::new(ti.levels, &nodes, ti.grid, &top, ti.top_levels())
        .and_then(|t| t.with_detail(&p.detail.0, &p.detail.1))
        .and_then(|t| t.with_fine_detail(&p.detail.2))
        .unwrap();
    let info = p.info;
    let stored = |node: u32, k: u32, i: u32| {
        let q = unpack_point(p.table[info.point_table_index(node as usize, k, i)]);
        [unorm16_decode(q[0]), unorm16_decode(q[1])]
    };
    for j1 in 0..info.grid[1] {
        for j0 in 0..info.grid[0] {
            let c = info.grid_condition([j0, j1]).map(|x| x as f32);
            let node = j1 * info.grid[0] + j0;
            let (want, pdf) = tree.sample_square(c, stored(node, 2, 4));
            let got = cs.sample(Vec2::from(c), 2, 4);
            assert_eq!(got.direction.to_array(), want, "{j0} {j1}");
            assert_eq!(got.pdf, pdf);
            assert!(pdf > 0.0);
            assert_eq!(
                cs.pdf(Vec2::from(c), got.direction),
                tree.pdf_square(c, want)
            );
            // The normal's own square point lights the tree as the normal does.
            let normal = nuld_core::sphere::square_to_sphere_real(c);
            let by_normal = tree.pdf(normal, want);
            assert!(
                (by_normal - pdf).abs() <= 1e-3 * pdf,
                "{by_normal} vs {pdf}"
            );
        }
    }
    // Between nodes (0,0), (1,0), (0,1), (1,1) of the 5 x 3 grid: the square
    // points blend, not the directions.
    let u = [0.1f32, 0.3];
    let cell = GridCell::locate(u, info.grid);
    let corners = [
        stored(0, 1, 3),
        stored(1, 1, 3),
        stored(5, 1, 3),
        stored(6, 1, 3),
    ];
    let point: [f32; 2] = core::array::from_fn(|a| {
        cell.lerp(corners[0][a], corners[1][a], corners[2][a], corners[3][a])
    });
    let got = cs.sample(Vec2::from(u), 1, 3);
    let (want, pdf) = tree.sample_square(u, point);
    assert_eq!((got.direction.to_array(), got.pdf), (want, pdf));
    assert!((got.direction.length() - 1.0).abs() < 1e-6);
    assert_eq!(got.weight, cs.weight(Vec2::from(u)));
    // The unbiased mode: the blob's lattice point 3, shifted by instance 1's
    // offset and then by seed 77's vector, warped; the network is not read.
    let l = lattice_point::<f32>(3, info.n, info.lattice_generator);
    let shifted = torus_shift(torus_shift(l, instance_offset(1)), randomization_shift(77));
    let r = cs.sample_randomized(Vec2::from(u), 1, 3, 77);
    assert_eq!(
        (r.direction.to_array(), r.pdf),
        tree.sample_square(u, shifted)
    );
    assert_ne!(r.direction, got.direction);
    let net = cs.network().sample_randomized(Vec2::from(u), 1, 3, 77);
    assert_eq!(net, r);
    assert!((cs.pdf(Vec2::from(u), net.direction) - net.pdf).abs() <= 1e-5 * net.pdf);
    // A normal is read through the octahedral map, at any length; degenerate
    // normals read as +z.
    let n = Vec3::new(0.2, -0.7, 0.4);
    let c = nuld_core::sphere::sphere_to_square_real(n.normalize().to_array());
    let env = EnvmapSampler(cs);
    assert_eq!(env.sample(n * 3.0, 7, 2), cs.sample(Vec2::from(c), 7, 2));
    assert_eq!(
        env.sample_randomized(n, 7, 2, 5),
        cs.sample_randomized(Vec2::from(c), 7, 2, 5)
    );
    let d = env.sample(n, 7, 2).direction;
    assert_eq!(env.pdf(n, d), cs.pdf(Vec2::from(c), d));
    assert_eq!(
        env.network().sample(n, 9, 1),
        cs.network().sample(Vec2::from(c), 9, 1)
    );
    assert_eq!(env.network().pdf(n, d), env.pdf(n, d));
    for bad in [Vec3::ZERO, Vec3::NAN, Vec3::new(f32::INFINITY, 0.0, 1.0)] {
        assert_eq!(env.sample(bad, 0, 0), env.sample(Vec3::Z, 0, 0));
        assert!(env.pdf(bad, Vec3::NAN) >= 0.0);
    }
    let d = cs.network().sample(Vec2::new(0.7, 0.2), 5, 4).direction;
    assert!((d.length() - 1.0).abs() < 1e-5);
}

/// Over many seeds of the unbiased mode at one normal, the mean of `g / pdf` is
/// `∫ g` (here `g = 1` on the sphere's lit part, whose integral the tree's own pdf
/// and an independent midpoint quadrature give), whatever the table holds.
#[test]
fn the_unbiased_mode_estimates_integrals_without_bias() {
    let p = envmap_parts();
    let bytes = encode(&p);
    let env = Blob::parse(bytes.get()).unwrap().envmap().unwrap();
    let n = Vec3::new(0.3, 0.5, 0.8).normalize();
    // g(l) = max(0, n.l)^2: ∫ g over the sphere = 2 pi / 3.
    let g = |d: Vec3| n.dot(d).max(0.0).powi(2);
    let exact = 2.0 * core::f64::consts::PI / 3.0;
    let (mut sum, mut sq, mut count) = (0.0f64, 0.0f64, 0u32);
    for seed in 0..20_000u32 {
        for i in 0..env.len() {
            let s = env.sample_randomized(n, 1, i, seed);
            let v = if s.pdf > 0.0 {
                (g(s.direction) / s.pdf) as f64
            } else {
                0.0
            };
            sum += v;
            sq += v * v;
            count += 1;
        }
    }
    let mean = sum / count as f64;
    let se = ((sq / count as f64 - mean * mean) / count as f64).sqrt();
    assert!(
        (mean - exact).abs() < 4.0 * se + 1e-4,
        "{mean} vs {exact} (se {se})"
    );
}

/// An environment blob of the earlier format (the equal-area output, no tree) is
/// refused with the error that says to bake it again; tree sections that disagree
/// with their info are refused by their own errors.
#[test]
fn environment_blobs_without_a_sound_prior_are_refused() {
    let parse = |p: &Parts| Blob::parse(encode(p).get()).map(|_| ());
    let mut old = envmap_parts();
    old.info.warp = PointWarp::EqualArea as u32;
    old.tree = None;
    let err = parse(&old).unwrap_err();
    assert_eq!(
        err,
        BlobError::Conditional(ConditionalError::EnvmapWithoutPrior)
    );
    assert!(std::format!("{err}").contains("bake it again with `build-tool bake --envmap`"));
    let mut missing = envmap_parts();
    missing.tree = None;
    assert_eq!(
        parse(&missing),
        Err(BlobError::MissingSection(SectionTag::EnvmapTreeInfo))
    );
    let mut brdf_tree = parts();
    brdf_tree.info.warp = PointWarp::EnvmapTree as u32;
    assert_eq!(
        parse(&brdf_tree),
        Err(BlobError::Conditional(ConditionalError::UnknownPointWarp(
            2
        )))
    );
    let tree_err = |e| Err(BlobError::Conditional(e));
    type Mutation = fn(&mut TreeParts);
    let cases: [(Mutation, ConditionalError); 10] = [
        (
            |t| t.0.levels = 2,
            ConditionalError::Tree(QuadtreeError::Levels(2)),
        ),
        // A tree shallower than its top table.
        (
            |t| t.0.levels = 3,
            ConditionalError::Tree(QuadtreeError::Levels(3)),
        ),
        (|t| t.0.reserved = 1, ConditionalError::TreeReserved),
        (
            |t| t.0.top_levels = 2,
            ConditionalError::Tree(QuadtreeError::TopLevels(2)),
        ),
        (
            |t| t.0.top_levels = 6,
            ConditionalError::Tree(QuadtreeError::TopLevels(6)),
        ),
        // The info names another depth than the table holds (0: the legacy 3).
        (
            |t| t.0.top_levels = 0,
            ConditionalError::Tree(QuadtreeError::Length {
                expected: 9 * 84,
                got: 9 * 340,
            }),
        ),
        (
            |t| t.0.grid = 4,
            ConditionalError::Tree(QuadtreeError::Length {
                expected: 16 * 340,
                got: 9 * 340,
            }),
        ),
        (
            |t| {
                t.1.pop();
            },
            ConditionalError::Tree(QuadtreeError::Length {
                expected: 340,
                got: 339,
            }),
        ),
        (
            |t| t.1[17].spread = -1.0,
            ConditionalError::Tree(QuadtreeError::BadMass(17)),
        ),
        (
            |t| t.2[30] = f32::NAN,
            ConditionalError::Tree(QuadtreeError::BadTopWeight(30)),
        ),
    ];
    for (change, want) in cases {
        let mut p = envmap_parts();
        change(p.tree.as_mut().unwrap());
        assert_eq!(parse(&p), tree_err(want));
    }
    type DetailMutation = fn(&mut DetailParts);
    let cases: [(DetailMutation, ConditionalError); 8] = [
        (|d| d.1.clear(), ConditionalError::TreeDetailAlone),
        (|d| d.0.clear(), ConditionalError::TreeDetailAlone),
        (
            |d| {
                d.0.clear();
                d.1.clear();
            },
            ConditionalError::TreeDetailAlone,
        ),
        (
            |d| {
                d.2.pop();
            },
            ConditionalError::Tree(QuadtreeError::Length {
                expected: 17 * FINE_LEN as u64,
                got: 18 * FINE_LEN as u64 - 1,
            }),
        ),
        (
            |d| d.0[0] = FINE_BIT | 19,
            ConditionalError::Tree(QuadtreeError::BadDetailIndex(0)),
        ),
        (
            |d| {
                d.0.pop();
            },
            ConditionalError::Tree(QuadtreeError::Length {
                expected: 256,
                got: 255,
            }),
        ),
        (
            |d| {
                d.1.pop();
            },
            ConditionalError::Tree(QuadtreeError::Length {
                expected: 67 * DETAIL_LEN as u64,
                got: 68 * DETAIL_LEN as u64 - 1,
            }),
        ),
        (
            |d| d.0[3] = 69,
            ConditionalError::Tree(QuadtreeError::BadDetailIndex(3)),
        ),
    ];
    for (change, want) in cases {
        let mut p = envmap_parts();
        change(&mut p.detail);
        assert_eq!(parse(&p), tree_err(want));
    }
    let mut p = envmap_parts();
    p.detail.1[DETAIL_LEN + 20] = -1.0;
    assert_eq!(
        parse(&p),
        tree_err(ConditionalError::Tree(QuadtreeError::BadDetail(
            DETAIL_LEN as u64 + 20
        )))
    );
    let mut p = envmap_parts();
    p.detail.2[FINE_LEN + 5] = f32::NAN;
    assert_eq!(
        parse(&p),
        tree_err(ConditionalError::Tree(QuadtreeError::BadFineDetail(
            FINE_LEN as u64 + 5
        )))
    );
    // The last tables named and every value sound: it parses.
    let mut p = envmap_parts();
    p.detail.0[3] = 68;
    p.detail.0[6] = FINE_BIT | 18;
    assert!(parse(&p).is_ok());
}

#[test]
fn indices_and_instances_wrap_and_conditions_clamp() {
    let p = parts();
    let bytes = encode(&p);
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    let (n, s) = (cs.len(), cs.instances());
    let c = Vec2::new(0.37, 41.0);
    for i in 0..2 * n {
        for k in 0..2 * s {
            assert_eq!(cs.sample(c, k, i), cs.sample(c, k % s, i % n));
            assert_eq!(cs.sample(c, k, i), cs.sample(c, k + s * 1000, i + n * 77));
            assert_eq!(
                cs.network().sample(c, k, i),
                cs.network().sample(c, k, i % n)
            );
        }
    }
    // Network mode hashes the instance: instance S is not instance 0.
    assert_ne!(cs.network().sample(c, s, 0), cs.network().sample(c, 0, 0));
    let lo = Vec2::new(0.0, 0.0);
    let hi = Vec2::new(1.0, 80.0);
    let network = |cs: &ConditionalSampler, c, k, i| cs.network().sample(c, k, i);
    for mode in [ConditionalSampler::sample, network] {
        let at = |x: f32, y: f32| mode(&cs, Vec2::new(x, y), 1, 2);
        assert_eq!(at(f32::NAN, f32::NAN), mode(&cs, lo, 1, 2));
        assert_eq!(at(-3.0, f32::NEG_INFINITY), mode(&cs, lo, 1, 2));
        assert_eq!(at(7.0, 1e30), mode(&cs, hi, 1, 2));
        assert_eq!(
            at(f32::INFINITY, f32::NAN),
            mode(&cs, Vec2::new(1.0, 0.0), 1, 2)
        );
    }
    assert_eq!(
        cs.sample(Vec2::new(u32::MAX as f32, 0.0), u32::MAX, u32::MAX)
            .weight,
        cs.weight(Vec2::new(1.0, 0.0))
    );
}

#[test]
fn weights_interpolate_bilinearly() {
    let p = parts();
    let bytes = encode(&p);
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    for k in 0..500 {
        let x = (noise(3, k) % 10_001) as f32 / 10_000.0;
        let y = (noise(4, k) % 10_001) as f32 / 10_000.0;
        let w = cs.weight(Vec2::new(x, 80.0 * y));
        // Bilinear interpolation reproduces a bilinear function up to rounding.
        assert!((w - bilinear_weight(x, y)).abs() < 1e-6, "{x} {y}: {w}");
        assert_eq!(cs.sample(Vec2::new(x, 80.0 * y), 0, 0).weight, w);
        assert_eq!(cs.network().sample(Vec2::new(x, 80.0 * y), 9, 1).weight, w);
    }
}

#[test]
fn directions_are_unit_vectors_on_the_hemisphere() {
    let p = parts();
    let bytes = encode(&p);
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    let views = [
        Vec3::new(0.3, -0.2, 0.9),
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::INFINITY, 0.0, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(1e-30, 1e-30, 1e-35),
        Vec3::new(3e38, -3e38, 3e38),
        Vec3::Z,
    ];
    for k in 0..400 {
        let c = Vec2::new(
            (noise(5, k) % 1000) as f32 / 900.0 - 0.05,
            (noise(6, k) % 1000) as f32 / 10.0 - 10.0,
        );
        let wo = views[k as usize % views.len()];
        for s in [
            cs.sample(c, k, k / 3),
            cs.network().sample(c, k, k / 3),
            BrdfSampler(cs).sample(wo, c.x, 0.0, k, k / 3),
            BrdfSampler(cs).network().sample(wo, c.x, 0.0, k, k / 3),
        ] {
            let d = s.direction;
            assert!(
                (d.length() - 1.0).abs() < 2e-6 && d.z >= 0.0,
                "{c} {wo}: {d}"
            );
            assert!(s.weight.is_finite() && s.weight > 0.0);
        }
    }
}

/// `BrdfSampler::sample` against an independent frame: `theta_o` and `phi` from `f64`
/// `acos`/`atan2`, the table sample rotated by `phi` in `f64`.
#[test]
fn sample_brdf_rotates_the_xz_plane_set_to_the_view_azimuth() {
    let p = parts();
    let bytes = encode(&p);
    let cs = Blob::parse(bytes.get()).unwrap().conditional().unwrap();
    for k in 0..300u32 {
        let theta = (noise(7, k) % 8000) as f64 / 100.0;
        let phi = ((noise(8, k) % 10_000) as f64 / 5_000.0 - 1.0) * core::f64::consts::PI;
        let len = 0.5 + (noise(9, k) % 100) as f64 / 20.0;
        let (t, f) = (theta.to_radians(), phi);
        let wo = [t.sin() * f.cos(), t.sin() * f.sin(), t.cos()].map(|x| (x * len) as f32);
        let wo = Vec3::from_array(wo);
        let wo64 = wo.as_dvec3();
        let theta_ref = (wo64.z / wo64.length()).clamp(0.0, 1.0).acos().to_degrees();
        let phi_ref = wo64.y.atan2(wo64.x);
        let (r, i) = (0.2 + (k % 7) as f32 / 10.0, k / 5);
        let cond = Vec2::new(r, theta_ref as f32);
        for (got, plain) in [
            (
                BrdfSampler(cs).sample(wo, r, 0.0, k, i),
                cs.sample(cond, k, i),
            ),
            (
                BrdfSampler(cs).network().sample(wo, r, 0.0, k, i),
                cs.network().sample(cond, k, i),
            ),
        ] {
            let d = plain.direction.as_dvec3();
            let (c, s) = (phi_ref.cos(), phi_ref.sin());
            let want = glam::DVec3::new(c * d.x - s * d.y, s * d.x + c * d.y, d.z);
            assert!(
                (got.direction.as_dvec3() - want).length() < 1e-4,
                "{wo}: {got:?} vs {want}"
            );
            assert!((got.weight - plain.weight).abs() < 1e-5);
        }
    }
    // Degenerate views are normal incidence, azimuth 0.
    for wo in [Vec3::ZERO, Vec3::NAN, Vec3::INFINITY, Vec3::Z * 2.0] {
        assert_eq!(
            BrdfSampler(cs).sample(wo, 0.5, 0.0, 1, 1),
            cs.sample(Vec2::new(0.5, 0.0), 1, 1)
        );
    }
    // Below the horizon reads as grazing (clamped to the range's 80°).
    let below = BrdfSampler(cs).sample(Vec3::new(1.0, 0.0, -0.5), 0.5, 0.0, 1, 1);
    assert_eq!(below, cs.sample(Vec2::new(0.5, 90.0), 1, 1));
}

#[test]
fn each_validation_failure_has_its_error() {
    assert_eq!(with(|_| {}), Ok(()));
    type Change = fn(&mut Parts);
    let cases: [(Change, ConditionalError); 28] = [
        (|p| p.info.n = 0, ConditionalError::NoPoints),
        (|p| p.info.instances = 0, ConditionalError::NoInstances),
        (|p| p.info.domain = 0, ConditionalError::Domain(0)),
        (|p| p.info.domain = 9, ConditionalError::Domain(9)),
        (|p| p.info.target = 0, ConditionalError::UnknownTarget(0)),
        (
            |p| p.info.grid[1] = 1,
            ConditionalError::Grid { axis: 1, nodes: 1 },
        ),
        (
            |p| p.info.weight_grid[0] = 0,
            ConditionalError::WeightGrid { axis: 0, nodes: 0 },
        ),
        (
            |p| p.info.cond_max[0] = 0.0,
            ConditionalError::Range {
                axis: 0,
                min_bits: 0,
                max_bits: 0,
            },
        ),
        (
            |p| p.info.cond_min[1] = f32::NEG_INFINITY,
            ConditionalError::Range {
                axis: 1,
                min_bits: f32::NEG_INFINITY.to_bits(),
                max_bits: 80f32.to_bits(),
            },
        ),
        (
            |p| p.info.cond_max[1] = f32::NAN,
            ConditionalError::Range {
                axis: 1,
                min_bits: 0,
                max_bits: f32::NAN.to_bits(),
            },
        ),
        (
            |p| p.info.activation = 2,
            ConditionalError::UnknownActivation(2),
        ),
        (
            |p| p.info.hidden = [4, 0, 3],
            ConditionalError::NetworkWidths([4, 0, 3]),
        ),
        (
            |p| p.info.hidden = [0, 0, 0],
            ConditionalError::NetworkWidths([0, 0, 0]),
        ),
        (
            |p| p.info.hidden = [129, 3, 0],
            ConditionalError::NetworkWidths([129, 3, 0]),
        ),
        (
            |p| p.info.offset_hash = 2,
            ConditionalError::UnknownOffsetHash(2),
        ),
        // 5 n x 4 h1 x M embedding numbers reach 2^32 at M = 2^32 / 20.
        (
            |p| p.info.instance_slots = u32::MAX / 16,
            ConditionalError::InstanceSlots(u32::MAX / 16),
        ),
        // Slots that fit the counts but not the parameters: M n h1 more rows.
        (
            |p| p.info.instance_slots = 2,
            ConditionalError::ParamsLength {
                expected: 2 * 5 * 4 + 4 * 12 + 3 * 5 + 2 * 4,
                got: 91,
            },
        ),
        (|p| p.info.warp = 7, ConditionalError::UnknownPointWarp(7)),
        (
            |p| {
                p.info.warp = 1;
                p.info.target = 2;
                p.info.domain = 1;
            },
            ConditionalError::UnknownPointWarp(1),
        ),
        // Each target has its domain: the BRDF the hemisphere, maps the sphere.
        (|p| p.info.domain = 1, ConditionalError::Domain(1)),
        (
            |p| {
                p.info.warp = 0;
                p.info.target = 2;
            },
            ConditionalError::Domain(2),
        ),
        (
            |p| {
                p.params.pop();
            },
            ConditionalError::ParamsLength {
                expected: 5 * 4 + 4 * 12 + 3 * 5 + 2 * 4,
                got: 90,
            },
        ),
        (
            |p| p.params[17] = 0x7c00,
            ConditionalError::NonFiniteParam {
                index: 17,
                bits: 0x7c00,
            },
        ),
        (
            |p| p.params[3] = 0xfe01,
            ConditionalError::NonFiniteParam {
                index: 3,
                bits: 0xfe01,
            },
        ),
        (
            |p| {
                p.table.push(0);
            },
            ConditionalError::PointTableLength {
                expected: 5 * 3 * 3 * 5,
                got: 226,
            },
        ),
        (
            |p| {
                p.info.instances = u32::MAX;
                p.info.grid = [u32::MAX, u32::MAX];
            },
            ConditionalError::PointTableCountOverflow,
        ),
        (
            |p| {
                p.weights.truncate(3);
            },
            ConditionalError::WeightTableLength {
                expected: 24,
                got: 3,
            },
        ),
        (
            |p| p.weights[5] = -0.5,
            ConditionalError::BadWeight {
                index: 5,
                bits: (-0.5f32).to_bits(),
            },
        ),
    ];
    for (k, (change, want)) in cases.into_iter().enumerate() {
        assert_eq!(with(change), Err(want.into()), "case {k}");
        assert!(!std::format!("{want}").contains('\n'));
    }
    assert_eq!(
        with(|p| p.weights[0] = f32::INFINITY),
        Err(BlobError::Conditional(ConditionalError::BadWeight {
            index: 0,
            bits: f32::INFINITY.to_bits()
        }))
    );
    // Another kind asks for the conditional view in vain, and vice versa.
    let other = crate::doc_example_blob();
    assert_eq!(
        Blob::parse(&other.0).unwrap().conditional().unwrap_err(),
        BlobError::WrongKind {
            expected: BlobKind::Conditional,
            found: BlobKind::PointSet2D
        }
    );
}

#[test]
fn a_view_of_the_other_target_is_refused() {
    let (brdf, env) = (
        crate::doc_example_conditional_blob(),
        crate::doc_example_envmap_blob(),
    );
    let (brdf, env) = (Blob::parse(&brdf.0).unwrap(), Blob::parse(&env.0).unwrap());
    assert!(brdf.brdf().is_ok() && env.envmap().is_ok());
    assert_eq!(
        brdf.envmap().unwrap_err(),
        BlobError::WrongTarget {
            expected: ConditionalTarget::EnvmapNormal,
            found: ConditionalTarget::GltfBrdf
        }
    );
    assert_eq!(
        env.brdf().unwrap_err(),
        BlobError::WrongTarget {
            expected: ConditionalTarget::GltfBrdf,
            found: ConditionalTarget::EnvmapNormal
        }
    );
    let points = crate::doc_example_blob();
    assert_eq!(
        Blob::parse(&points.0).unwrap().brdf().unwrap_err(),
        BlobError::WrongKind {
            expected: BlobKind::Conditional,
            found: BlobKind::PointSet2D
        }
    );
}

#[test]
fn doc_example_conditional_blob_is_exactly_its_array() {
    let b = crate::doc_example_conditional_blob();
    let cs = Blob::parse(&b.0).unwrap().conditional().unwrap();
    assert_eq!((cs.len(), cs.instances()), (2, 2));
}
