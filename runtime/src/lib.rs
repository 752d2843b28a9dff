//! # nuld-runtime
//!
//! Reads `.nuld` blobs written by `build-tool` and serves their samples, zero-copy,
//! in constant time per sample. `#![no_std]`, no allocator, and no panics on any
//! input: every malformed blob is rejected by [`Blob::parse`] with a [`BlobError`],
//! and every lookup on a parsed blob is total (indices wrap modulo the counts).
//!
//! Points and directions are [`glam`] vectors; use the re-exported
//! [`nuld_runtime::glam`](glam) so that your glam version always matches.
//!
//! ```
//! use nuld_runtime::{Blob, BlobKind};
//! # let bytes = nuld_runtime::doc_example_blob();
//! # let bytes: &[u8] = &bytes.0;
//! // `bytes` is a blob in memory, 16-byte aligned (see `include_blob!`).
//! let blob = Blob::parse(bytes)?;
//! assert_eq!(blob.kind(), BlobKind::PointSet2D);
//! let pts = blob.point_set_2d()?;
//! for i in 0..pts.len() {
//!     let p: nuld_runtime::glam::Vec2 = pts.point(0, i); // in (0,1)^2
//!     assert!(p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0);
//! }
//! # Ok::<(), nuld_runtime::BlobError>(())
//! ```
//!
//! A conditional sampler ([`BlobKind::Conditional`]) serves, for a condition known
//! only at run time, the directions of a low-discrepancy set and the estimator
//! weight. The blob's target decides the view: [`Blob::brdf`] gives a
//! [`BrdfSampler`] (a view direction and a roughness in), [`Blob::envmap`] an
//! [`EnvmapSampler`] (a surface normal in), and asking one blob for the other view
//! is an error ([`BlobError::WrongTarget`]). Each view samples in table mode;
//! `network()` is the same model in network mode, a view of its own:
//!
//! ```
//! use nuld_runtime::{Blob, BlobError, glam::Vec3};
//! # let bytes = nuld_runtime::doc_example_conditional_blob();
//! # let bytes: &[u8] = &bytes.0;
//! let blob = Blob::parse(bytes)?;
//! let brdf = blob.brdf()?; // a blob of `build-tool bake --brdf`
//! let wo = Vec3::new(0.3, 0.4, 0.866); // view, local frame (z = normal)
//! let s = brdf.sample(wo, 0.4, 0.0, 17, 0); // table mode: roughness 0.4, metallic 0, instance 17, index 0
//! let t = brdf.network().sample(wo, 0.4, 0.0, 17, 0); // network mode
//! assert!(s.weight > 0.0 && t.weight > 0.0);
//! assert!(matches!(blob.envmap(), Err(BlobError::WrongTarget { .. })));
//! # Ok::<(), BlobError>(())
//! ```
//!
//! Where the bytes come from:
//! * compiled in: [`include_blob!`] (no allocation; `runtime/examples/embed.rs`);
//! * read at run time: `AlignedBuf` with the `alloc` feature, and
//!   `AlignedBuf::read` with `std` (`runtime/examples/load_file.rs`). Without the
//!   features, copy the bytes into any 16-byte aligned storage of your own.
//!
//! On a GPU, upload the blob's bytes unchanged as a storage buffer and sample it
//! from your shader with the WGSL of [`shader`] (one function per runtime
//! function).
//!
//! ## Features
//! * none (default): `no_std`, no allocator;
//! * `alloc`: `AlignedBuf`, an owned aligned copy of a blob;
//! * `std` (implies `alloc`): `AlignedBuf::read` from a file, and the compiler's
//!   square root in place of libm's (`nuld-core`'s `std` feature): the same bits,
//!   which the compiler can schedule and vectorize (the environment sampler's
//!   table mode about 8 % faster, docs/results/runtime-cost.md#sqrt).
#![no_std]
#![deny(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod aligned;
#[cfg(feature = "alloc")]
mod aligned_buf;
mod brdf;
mod conditional;
mod envmap;
mod points;
mod section;
pub mod shader;

/// The `glam` this crate returns its vectors in; use it instead of a `glam`
/// dependency of your own so that the versions always match.
pub use glam;

pub use aligned::Aligned;
#[cfg(feature = "alloc")]
pub use aligned_buf::AlignedBuf;
pub use brdf::{BrdfNetwork, BrdfSampler};
pub use conditional::{ConditionalSampler, NetworkSampler, Sample};
pub use envmap::{EnvmapNetwork, EnvmapSampler};
pub use nuld_core::blob::{
    BlobError, BlobKind, ConditionalError, Domain, LayoutError, Metadata, PointSetError,
};
pub use nuld_core::conditional::{ConditionalInfo, ConditionalTarget};
pub use points::{DirectionSet, PointSet2D};

use nuld_core::blob::{Layout, PointSetInfo, SectionTag};
use section::{record, typed_section};

/// A validated blob, borrowing its bytes.
///
/// Construct it with [`Blob::parse`]; then ask for the sampler view matching its
/// [`Blob::kind`].
#[derive(Clone, Copy, Debug)]
pub struct Blob<'a> {
    layout: Layout<'a>,
    kind: BlobKind,
    metadata: Metadata<'a>,
}

impl<'a> Blob<'a> {
    /// Validates `bytes` and returns a view on them.
    ///
    /// Checks, in order: length, 16-byte alignment of `bytes`, magic, format version,
    /// declared length, checksum, section table and metadata bounds, kind, and the
    /// kind's sections (sizes, counts, domain codes). Never panics, never allocates.
    ///
    /// ```
    /// # use nuld_runtime::{Blob, BlobError, LayoutError, Aligned};
    /// let junk = Aligned([0u8; 64]);
    /// assert_eq!(Blob::parse(&junk.0).unwrap_err(), BlobError::Layout(LayoutError::BadMagic));
    /// ```
    pub fn parse(bytes: &'a [u8]) -> Result<Self, BlobError> {
        let layout = Layout::read(bytes)?;
        let code = layout.header().kind;
        let kind = BlobKind::from_code(code).ok_or(BlobError::UnknownKind(code))?;
        let metadata = layout.metadata()?;
        let blob = Self {
            layout,
            kind,
            metadata,
        };
        match kind {
            BlobKind::PointSet2D | BlobKind::DirectionSet => {
                blob.points_view()?;
            }
            BlobKind::Conditional => {
                ConditionalSampler::validate(&blob.layout)?;
            }
        }
        Ok(blob)
    }

    /// What the blob holds.
    pub fn kind(&self) -> BlobKind {
        self.kind
    }

    /// The blob's descriptive metadata (generator, target SPEC, seed).
    pub fn metadata(&self) -> Metadata<'a> {
        self.metadata
    }

    /// The point sets of a [`BlobKind::PointSet2D`] blob.
    ///
    /// Errors with [`BlobError::WrongKind`] for any other kind.
    pub fn point_set_2d(&self) -> Result<PointSet2D<'a>, BlobError> {
        self.expect(BlobKind::PointSet2D)?;
        let (info, coords) = self.points_view()?;
        Ok(PointSet2D::new(coords, info.len, info.set_count))
    }

    /// The direction sets of a [`BlobKind::DirectionSet`] blob.
    ///
    /// Errors with [`BlobError::WrongKind`] for any other kind.
    pub fn direction_set(&self) -> Result<DirectionSet<'a>, BlobError> {
        self.expect(BlobKind::DirectionSet)?;
        let (info, coords) = self.points_view()?;
        let domain = Domain::from_code(info.domain).unwrap_or(Domain::Sphere);
        Ok(DirectionSet::new(
            PointSet2D::new(coords, info.len, info.set_count),
            domain,
        ))
    }

    /// The BRDF sampler of a blob of `build-tool bake --brdf`
    /// ([`ConditionalTarget::GltfBrdf`]).
    ///
    /// Errors with [`BlobError::WrongKind`] for a point or direction set and
    /// [`BlobError::WrongTarget`] for another conditional sampler.
    pub fn brdf(&self) -> Result<BrdfSampler<'a>, BlobError> {
        self.conditional()?.try_into()
    }

    /// The environment-map sampler of a blob of `build-tool bake --envmap`
    /// ([`ConditionalTarget::EnvmapNormal`]).
    ///
    /// Errors with [`BlobError::WrongKind`] for a point or direction set and
    /// [`BlobError::WrongTarget`] for another conditional sampler.
    pub fn envmap(&self) -> Result<EnvmapSampler<'a>, BlobError> {
        self.conditional()?.try_into()
    }

    /// The target-agnostic view of a [`BlobKind::Conditional`] blob, conditions
    /// in the blob's units (see [`ConditionalSampler`]); renderers want
    /// [`Self::brdf`] or [`Self::envmap`].
    ///
    /// Errors with [`BlobError::WrongKind`] for any other kind.
    pub fn conditional(&self) -> Result<ConditionalSampler<'a>, BlobError> {
        self.expect(BlobKind::Conditional)?;
        ConditionalSampler::view(&self.layout)
    }

    fn expect(&self, expected: BlobKind) -> Result<(), BlobError> {
        if self.kind == expected {
            Ok(())
        } else {
            Err(BlobError::WrongKind {
                expected,
                found: self.kind,
            })
        }
    }

    /// The info section and the coordinate array, validated against each other.
    fn points_view(&self) -> Result<(PointSetInfo, &'a [[u16; 2]]), BlobError> {
        let info: PointSetInfo =
            record(&self.layout, SectionTag::PointSetInfo, |got, expected| {
                PointSetError::InfoSize { got, expected }
            })?;
        if info.len == 0 {
            return Err(PointSetError::NoPoints.into());
        }
        if info.set_count == 0 {
            return Err(PointSetError::NoSets.into());
        }
        let domain =
            Domain::from_code(info.domain).ok_or(PointSetError::UnknownDomain(info.domain))?;
        let domain_ok = match self.kind {
            BlobKind::PointSet2D => domain == Domain::Square,
            BlobKind::DirectionSet => domain != Domain::Square,
            BlobKind::Conditional => false,
        };
        if !domain_ok {
            return Err(PointSetError::DomainMismatch {
                kind: self.kind,
                domain,
            }
            .into());
        }
        // Lengths in bytes in the error, as the format states them (saturating:
        // two counts near 2^32 make a byte length past 2^64, which no section has).
        let coords: &[[u16; 2]] = typed_section(
            &self.layout,
            SectionTag::Points,
            PointSetError::ElementSize,
            || Ok((info.len as u64) * (info.set_count as u64)),
            |expected, got| PointSetError::Length {
                expected: expected.saturating_mul(4),
                got: got.saturating_mul(4),
            },
        )?;
        Ok((info, coords))
    }
}

/// A small valid blob for the crate's documentation examples: 4 points, 1 set.
#[doc(hidden)]
pub fn doc_example_blob() -> Aligned<[u8; 160]> {
    point_set_blob(4, 1)
}

/// The 4 points of [`doc_example_blob`] in a blob whose info claims `len` points
/// in `set_count` sets (so counts that disagree with the points make a corrupt
/// blob for the tests).
fn point_set_blob(len: u32, set_count: u32) -> Aligned<[u8; 160]> {
    use nuld_core::blob::{write, SectionSpec};
    let info = PointSetInfo {
        len,
        set_count,
        domain: Domain::Square as u32,
        reserved: 0,
    };
    let pts: [[u16; 2]; 4] = [[0, 0], [32768, 16384], [16384, 49152], [49152, 32768]];
    // Metadata { generator: "doc", target: "uniform", seed: 0 } in postcard.
    let meta = [
        3, b'd', b'o', b'c', 7, b'u', b'n', b'i', b'f', b'o', b'r', b'm', 0,
    ];
    let sections = [
        SectionSpec {
            tag: SectionTag::PointSetInfo,
            elem_size: 16,
            bytes: bytemuck::bytes_of(&info),
        },
        SectionSpec {
            tag: SectionTag::Points,
            elem_size: 4,
            bytes: bytemuck::cast_slice(&pts),
        },
    ];
    // 48 + 64 + 13 -> 128 (aligned), + 16 -> 144, + 16 = 160 bytes: exactly the
    // array, which `write` checks (a mismatch would leave zeros and fail to parse).
    let mut out = Aligned([0u8; 160]);
    let _ = write(&mut out.0, BlobKind::PointSet2D, &meta, &sections);
    out
}

/// A small valid conditional BRDF blob for the crate's documentation examples:
/// `n = 2`, 2 instances, 2 x 2 grids over roughness `[0.1, 1]` x `theta_o`
/// `[0°, 89°]`, a one-unit network.
#[doc(hidden)]
pub fn doc_example_conditional_blob() -> Aligned<[u8; 400]> {
    doc_example_sampler(ConditionalTarget::GltfBrdf, [0.1, 0.0], [1.0, 89.0])
}

/// [`doc_example_conditional_blob`] as a BRDF sampler on the tabulated prior
/// ([`nuld_core::conditional::PointWarp::BrdfTable`]): its network and point
/// table, the dielectric's and the metal's albedo as weights, and a prior of 2 x
/// 2 x 2 conditions on 4 x 4 half-vector vertices (`f cos |dwi/dh|` at each
/// vertex), so that its samples carry an exact pdf.
#[doc(hidden)]
pub fn doc_example_brdf_blob() -> Aligned<[u8; 1776]> {
    use nuld_core::brdf::{gltf_metallic, view_direction_real};
    use nuld_core::brdf_prior::{node_condition, radial_square, BrdfPriorInfo};
    use nuld_core::marginal2d::tabulate_with_masses;
    let (info, params, table, _) =
        doc_example_parts(ConditionalTarget::GltfBrdf, [0.1, 0.0], [1.0, 89.0]);
    let info = ConditionalInfo {
        warp: nuld_core::conditional::PointWarp::BrdfTable as u32,
        ..info
    };
    let weights: [f32; 8] = [0.97, 0.97, 0.93, 0.94, 0.99, 0.91, 0.31, 0.78];
    let prior = BrdfPriorInfo {
        grid: [2, 2, 2],
        size: 4,
    };
    let mut data = [0.0f32; 128];
    for (node, table) in data.chunks_mut(16).enumerate() {
        let [r, t, m] = node_condition(prior.grid, node as u32).map(|x| x as f32);
        let wo = view_direction_real(t);
        for (v, value) in table.iter_mut().enumerate() {
            let p = [(v % 4) as f32 / 3.0, (v / 4) as f32 / 3.0];
            if let Some((wi, jac)) = radial_square(r).direction(wo, p) {
                *value = gltf_metallic(wo, wi, r, m) * wi[2] * jac;
            }
        }
    }
    let (mut marginal, mut conditional, mut masses) = ([0.0f32; 32], [0.0f32; 128], [0.0f32; 8]);
    let shape = prior
        .shape()
        .unwrap_or(nuld_core::marginal2d::Marginal2DShape {
            size: [4, 4],
            nodes: 8,
        });
    let _ = tabulate_with_masses(
        shape,
        &mut data,
        &mut marginal,
        &mut conditional,
        &mut masses,
    );
    let meta = [
        3, b'd', b'o', b'c', 7, b'b', b'r', b'd', b'f', b'-', b'd', b'o', 0,
    ];
    let [a, b, c, d] = nuld_core::conditional::sections(&info, &params, &table, &weights);
    let [e, f, g, h, i] =
        nuld_core::brdf_prior::sections(&prior, &data, &marginal, &conditional, &masses);
    // 48 + 9 x 32 + 13 -> 352; info 80 -> 432; params 36 -> 480; table 64 -> 544;
    // weights 32 -> 576; prior info 16 -> 592; data 512 -> 1104; marginal 128 ->
    // 1232; conditional 512 -> 1744; masses 32 -> 1776 bytes.
    let mut out = Aligned([0u8; 1776]);
    let _ = nuld_core::blob::write(
        &mut out.0,
        BlobKind::Conditional,
        &meta,
        &[a, b, c, d, e, f, g, h, i],
    );
    out
}

/// [`doc_example_conditional_blob`] as an environment sampler on its prior: conditions
/// the normal's octahedral square point in `[0, 1]^2`, directions on the sphere, a
/// tree of 3 levels over a sky brighter towards `+z` with its top weights on 2 x 2
/// normals.
#[doc(hidden)]
pub fn doc_example_envmap_blob() -> Aligned<[u8; 3200]> {
    use nuld_core::envmap_tree::{
        build, node_count, top_normal, top_row, NodeRecord, TreeInfo, LEGACY_TOP_LEVELS,
    };
    let (info, params, table, _) =
        doc_example_parts(ConditionalTarget::EnvmapNormal, [0.0, 0.0], [1.0, 1.0]);
    let info = ConditionalInfo {
        warp: nuld_core::conditional::PointWarp::EnvmapTree as u32,
        ..info
    };
    let weights: [f32; 4] = [1.0, 0.95, 1.2, 0.98];
    // A tree of 3 levels, every one of them in the top table (the depth of the
    // trees written before `TreeInfo::top_levels`, which still load).
    let levels = LEGACY_TOP_LEVELS;
    let mut leaves = [[0.0f64; 4]; 64];
    for (k, leaf) in leaves.iter_mut().enumerate() {
        let p = [
            (k % 8) as f64 / 8.0 + 1.0 / 16.0,
            (k / 8) as f64 / 8.0 + 1.0 / 16.0,
        ];
        let d = nuld_core::sphere::square_to_sphere_real(p);
        let light = (1.0 + 3.0 * d[2].max(0.0)) / 64.0;
        *leaf = [light, light * d[0], light * d[1], light * d[2]];
    }
    let mut nodes = [NodeRecord {
        moment: [0.0; 3],
        spread: 0.0,
    }; 84];
    let _ = build(levels, &leaves, &mut nodes[..node_count(levels)]);
    let mut top = [0.0f32; 4 * 84];
    for (r, row) in top.chunks_mut(84).enumerate() {
        top_row(
            levels,
            levels,
            &nodes,
            top_normal(2, [r as u32 % 2, r as u32 / 2]),
            row,
        );
    }
    let tree = TreeInfo {
        levels,
        grid: 2,
        top_levels: levels,
        reserved: 0,
    };
    let meta = [
        3, b'd', b'o', b'c', 7, b'e', b'n', b'v', b'-', b'd', b'o', b'c', 0,
    ];
    let [a, b, c, d] = nuld_core::conditional::sections(&info, &params, &table, &weights);
    let [e, f, g] = nuld_core::envmap_tree::sections(&tree, &nodes, &top);
    // 48 + 7 x 32 + 13 -> 288; info 80 -> 368; params 36 -> 416; table 64 -> 480;
    // weights 16 -> 496; tree info 16 -> 512; 84 nodes 1344 -> 1856; top 1344 ->
    // 3200 bytes.
    let mut out = Aligned([0u8; 3200]);
    let _ = nuld_core::blob::write(
        &mut out.0,
        BlobKind::Conditional,
        &meta,
        &[a, b, c, d, e, f, g],
    );
    out
}

/// The info, parameters and point table of the documentation's samplers (2
/// points, 2 instances, a 2 x 2 grid, a network of one hidden unit), and its
/// weights.
#[allow(clippy::type_complexity)]
fn doc_example_parts(
    target: ConditionalTarget,
    cond_min: [f32; 2],
    cond_max: [f32; 2],
) -> (ConditionalInfo, [u16; 18], [u32; 16], [f32; 4]) {
    let info = ConditionalInfo {
        n: 2,
        instances: 2,
        domain: target.domain() as u32,
        target: target as u32,
        grid: [2, 2],
        weight_grid: [2, 2],
        cond_min,
        cond_max,
        hidden: [1, 0, 0],
        activation: 0,
        lattice_generator: 1,
        warp: 0,
        instance_slots: 0,
        offset_hash: 1,
    };
    // 2 x 1 embedding, 1 x 11 + 1 first layer, 2 x 1 + 2 output: 18 parameters.
    let params: [u16; 18] =
        core::array::from_fn(|j| nuld_core::quantize::f16_encode((j as f32 - 8.0) / 8.0));
    // [node][instance][index]: 4 nodes x 2 instances x 2 indices.
    let table: [u32; 16] = core::array::from_fn(|e| {
        let e = e as u32;
        nuld_core::conditional::pack_point((e * 3_001 + 9_000) as u16, (60_000 - e * 2_503) as u16)
    });
    let weights: [f32; 4] = [1.0, 0.95, 1.2, 0.98];
    (info, params, table, weights)
}

fn doc_example_sampler(
    target: ConditionalTarget,
    cond_min: [f32; 2],
    cond_max: [f32; 2],
) -> Aligned<[u8; 400]> {
    use nuld_core::blob::write;
    let (info, params, table, weights) = doc_example_parts(target, cond_min, cond_max);
    let meta = [
        3, b'd', b'o', b'c', 7, b'g', b'l', b't', b'f', b'-', b'd', b'o', 0,
    ];
    let sections = nuld_core::conditional::sections(&info, &params, &table, &weights);
    // 48 + 4 x 32 + 13 -> 192; info 80 -> 272; params 36 -> 320; table 64 -> 384;
    // weights 16 -> 400 bytes: exactly the array, which `write` checks.
    let mut out = Aligned([0u8; 400]);
    let _ = write(&mut out.0, BlobKind::Conditional, &meta, &sections);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    /// The documentation's BRDF blob parses, on the tabulated prior.
    #[test]
    fn the_doc_brdf_blob_parses_with_its_prior() {
        let bytes = doc_example_brdf_blob();
        let brdf = Blob::parse(&bytes.0).unwrap().brdf().unwrap();
        let s = brdf.sample(glam::Vec3::new(0.3, 0.1, 0.9), 0.5, 0.5, 1, 1);
        assert!(s.pdf > 0.0 && s.weight > 0.0);
    }

    /// A blob of an earlier prior (its info under tag 10, the unstretched
    /// square, tag 15, the stretched metal square, or tag 23, the shared
    /// square of one stretch; the checksum sound) is refused with the advice
    /// to bake it again.
    #[test]
    fn a_brdf_blob_of_an_earlier_prior_is_refused() {
        use nuld_core::blob::{
            checksum, ConditionalError, SectionTag, CHECKSUM_OFFSET, HEADER_LEN, SECTION_ENTRY_LEN,
        };
        let earlier = [
            (10u32, "unstretched"),
            (15, "metal layer in a stretched"),
            (23, "shared layers in a square of one stretch"),
        ];
        for (tag, what) in earlier {
            let mut bytes = doc_example_brdf_blob();
            let b = &mut bytes.0;
            let count = u32::from_le_bytes(b[40..44].try_into().unwrap()) as usize;
            let row = (0..count)
                .map(|k| HEADER_LEN + k * SECTION_ENTRY_LEN)
                .find(|&at| {
                    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
                        == SectionTag::BrdfPriorInfo as u32
                })
                .unwrap();
            b[row..row + 4].copy_from_slice(&tag.to_le_bytes());
            let sum = checksum(b);
            b[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
            let err = Blob::parse(b).unwrap_err();
            assert_eq!(
                err,
                BlobError::Conditional(ConditionalError::BrdfPriorEarlier { tag })
            );
            let message = std::format!("{err}");
            assert!(message.contains("bake it again with `build-tool bake --brdf`"));
            assert!(message.contains(what), "{message}");
        }
    }

    #[test]
    fn point_counts_whose_byte_length_passes_2_pow_64_are_refused_without_overflow() {
        assert!(Blob::parse(&point_set_blob(4, 1).0).is_ok());
        // 4 (2^32 - 1)^2 bytes: past u64, so the byte length saturates.
        assert_eq!(
            Blob::parse(&point_set_blob(u32::MAX, u32::MAX).0).unwrap_err(),
            BlobError::PointSet(PointSetError::Length {
                expected: u64::MAX,
                got: 16
            })
        );
        assert_eq!(
            Blob::parse(&point_set_blob(3, 2).0).unwrap_err(),
            BlobError::PointSet(PointSetError::Length {
                expected: 24,
                got: 16
            })
        );
    }
}
