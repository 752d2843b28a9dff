//! `Blob::parse` on hostile bytes: random garbage, truncations, bit flips and
//! re-checksummed field corruptions of valid blobs. It must never panic, and every
//! corruption of a valid blob must be rejected (by the checksum or a bounds check).

use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::blob::{
    checksum, encoded_len, write, BlobError, ConditionalError, Domain, Layout, LayoutError,
    PointSetError, SectionSpec, SectionTag, WriteError, CHECKSUM_OFFSET, MAX_SECTIONS,
};
use nuld_core::conditional::{MetallicNodesError, PointWarp, CONDITIONAL_INFO_LEN};
use nuld_core::network::Activation;
use nuld_core::quantize::f16_decode;
use nuld_runtime::glam::{Vec2, Vec3};
use nuld_runtime::{Blob, BlobKind};
use nuld_tests::{
    as_envmap, conditional_parts, shape, small_brdf_prior, sobol_blob, with_brdf_prior,
    with_metal_points, with_metallic_axis, META,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Parses and, if that succeeds, touches every sample: a view that parsed must be
/// total.
fn parse_and_touch(bytes: &[u8]) -> Result<(), BlobError> {
    let blob = Blob::parse(bytes)?;
    match blob.kind() {
        BlobKind::PointSet2D => {
            let p = blob.point_set_2d()?;
            for i in 0..p.len() * p.set_count() + 3 {
                let v = p.point(i / p.len().max(1), i);
                assert!(v.x > 0.0 && v.x < 1.0 && v.y > 0.0 && v.y < 1.0);
            }
        }
        BlobKind::DirectionSet => {
            let d = blob.direction_set()?;
            for i in 0..d.len() * d.set_count() + 3 {
                let v = d.direction(i / d.len().max(1), i);
                assert!((v.length() - 1.0).abs() < 1e-5);
            }
        }
        BlobKind::Conditional => {
            let cs = blob.conditional()?;
            let info = *cs.info();
            // Every stored table entry (all grid nodes, instances, indices, plus one
            // wrap each), and every index of the network at two instances.
            let [g0, g1] = info.grid;
            for j1 in 0..g1 {
                for j0 in 0..g0 {
                    let c = info.grid_condition([j0, j1]).map(|x| x as f32);
                    let c = Vec2::from(c);
                    for k in 0..=cs.instances() {
                        for i in 0..=cs.len() {
                            check_sample(cs.sample(c, k, i));
                            // The metal layer's own table, where the blob has one.
                            check_sample(cs.sample_metallic(c, 1.0, k, i));
                        }
                    }
                }
            }
            let c = Vec2::new(0.55, 33.0);
            let wo = Vec3::new(-0.3, 0.5, 0.7);
            // The typed view of the blob's target; the other one is refused.
            let (brdf, envmap) = (blob.brdf().ok(), blob.envmap().ok());
            assert!(brdf.is_some() != envmap.is_some());
            for i in 0..=cs.len() {
                for k in [0, u32::MAX] {
                    check_sample(cs.network().sample(c, k, i));
                    if let Some(b) = brdf {
                        for m in [0.0, 0.6, f32::NAN, 7.0] {
                            check_sample(b.sample(wo, c.x, m, k, i));
                            check_sample(b.network().sample(wo, c.x, m, k, i));
                            let s = b.sample_randomized(wo, c.x, m, k, i, k ^ i);
                            check_sample(s);
                            let pdf = b.pdf(wo, c.x, m, s.direction);
                            assert!(pdf.is_finite() && pdf >= 0.0);
                        }
                    }
                    if let Some(e) = envmap {
                        check_sample(e.sample(wo, k, i));
                        check_sample(e.network().sample(wo, k, i));
                        check_sample(e.sample_randomized(wo, k, i, k ^ i));
                        let pdf = e.pdf(wo, e.sample(wo, k, i).direction);
                        assert!(pdf.is_finite() && pdf >= 0.0);
                    }
                }
            }
        }
    }
    Ok(())
}

/// A sample a parsed blob serves: a unit direction, a finite weight `>= 0` and a
/// finite pdf `>= 0`.
fn check_sample(s: nuld_runtime::Sample) {
    let d = s.direction;
    assert!((d.length() - 1.0).abs() < 1e-5, "{d}");
    assert!(s.weight.is_finite() && s.weight >= 0.0, "{}", s.weight);
    assert!(s.pdf.is_finite() && s.pdf >= 0.0, "{}", s.pdf);
}

/// A small conditional blob with random contents (n 4, hidden [3, 2], 2 instances,
/// a 3 x 2 grid, 3 instance slots).
fn conditional_blob() -> AlignedBytes {
    let shape = shape(4, &[3, 2], Activation::Silu, PointWarp::BrdfMixture, 3);
    conditional_parts(shape, 2, [3, 2], 5)
        .to_blob(&META)
        .unwrap()
}

/// [`conditional_blob`]'s shape as an environment sampler on its prior (sphere,
/// condition the octahedral square, the tree warp and its three sections).
fn envmap_blob() -> AlignedBytes {
    let shape = shape(4, &[3, 2], Activation::Relu, PointWarp::EnvmapTree, 0);
    as_envmap(conditional_parts(shape, 2, [3, 2], 6))
        .to_blob(&META)
        .unwrap()
}

/// [`conditional_blob`]'s shape as a BRDF sampler on the tabulated prior, with
/// a small prior (3 x 2 x 3 conditions, 5 x 5 vertices: [`small_brdf_prior`]) so
/// that every truncation stays cheap.
fn brdf_table_blob() -> AlignedBytes {
    // The small prior has the metal layer, which its own points serve.
    brdf_table_parts(small_brdf_prior()).to_blob(&META).unwrap()
}

/// [`brdf_table_blob`] with a metallic axis of three nodes (the default bake's).
fn metallic_axis_blob() -> AlignedBytes {
    with_metallic_axis(brdf_table_parts(small_brdf_prior()), &[0.0, 0.5, 0.95], 9)
        .to_blob(&META)
        .unwrap()
}

/// [`brdf_table_blob`]'s parts on `prior`, with metal points.
fn brdf_table_parts(
    prior: std::sync::Arc<nuld_build_tool::sphere::brdf_prior::BrdfPrior>,
) -> nuld_build_tool::conditional::blob::ConditionalParts {
    let shape = shape(4, &[3, 2], Activation::Relu, PointWarp::BrdfTable, 2);
    with_metal_points(
        with_brdf_prior(conditional_parts(shape, 2, [3, 2], 7), prior),
        8,
    )
}

fn valid_blobs() -> Vec<AlignedBytes> {
    vec![
        sobol_blob(Domain::Square, 5, 2, 1).1,
        sobol_blob(Domain::Sphere, 16, 1, 2).1,
        sobol_blob(Domain::Hemisphere, 3, 3, 3).1,
        sobol_blob(Domain::Square, 200, 1, 4).1,
        conditional_blob(),
        envmap_blob(),
        brdf_table_blob(),
    ]
}

#[test]
fn random_bytes_are_rejected_without_panicking() {
    let mut rng = Pcg64Mcg::seed_from_u64(1);
    let magic_header = &valid_blobs()[0];
    for case in 0..4000 {
        let len = rng.random_range(0..600);
        let mut buf = AlignedBytes::zeroed(len);
        rng.fill(buf.as_mut_slice());
        if case % 2 == 1 && len >= 16 {
            // Get past the magic and version checks to reach deeper validation.
            buf.as_mut_slice()[..16].copy_from_slice(&magic_header.as_slice()[..16]);
        }
        assert!(parse_and_touch(buf.as_slice()).is_err(), "case {case}");
    }
}

#[test]
fn every_truncation_and_extension_is_rejected() {
    for blob in valid_blobs() {
        let bytes = blob.as_slice();
        parse_and_touch(bytes).unwrap();
        for cut in 0..bytes.len() {
            let err = parse_and_touch(&bytes[..cut]).unwrap_err();
            assert!(
                matches!(err, BlobError::Layout(LayoutError::Truncated { .. })),
                "cut {cut}: {err:?}"
            );
        }
        let mut longer = AlignedBytes::zeroed(bytes.len() + 16);
        longer.as_mut_slice()[..bytes.len()].copy_from_slice(bytes);
        assert!(matches!(
            parse_and_touch(longer.as_slice()),
            Err(BlobError::Layout(LayoutError::TrailingBytes { .. }))
        ));
    }
}

#[test]
fn every_single_bit_flip_is_rejected() {
    for blob in valid_blobs() {
        let mut copy = blob.clone();
        for bit in 0..copy.as_slice().len() * 8 {
            copy.as_mut_slice()[bit / 8] ^= 1 << (bit % 8);
            assert!(
                parse_and_touch(copy.as_slice()).is_err(),
                "bit {bit} accepted"
            );
            copy.as_mut_slice()[bit / 8] ^= 1 << (bit % 8);
        }
        parse_and_touch(copy.as_slice()).unwrap();
    }
}

#[test]
fn random_multi_byte_corruptions_are_rejected() {
    let mut rng = Pcg64Mcg::seed_from_u64(2);
    for blob in valid_blobs() {
        for _ in 0..2000 {
            let mut copy = blob.clone();
            let bytes = copy.as_mut_slice();
            for _ in 0..rng.random_range(1..8) {
                let at = rng.random_range(0..bytes.len());
                bytes[at] = bytes[at].wrapping_add(rng.random_range(1..=255));
            }
            if bytes == blob.as_slice() {
                continue;
            }
            assert!(parse_and_touch(bytes).is_err());
        }
    }
}

/// Corrupts header and section-table fields and then *fixes the checksum*, so the
/// bounds checks alone must catch the damage (or the blob must still be safe).
#[test]
fn rechecksummed_field_corruptions_hit_the_bounds_checks() {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let mut rejected = 0;
    let mut total = 0;
    for blob in valid_blobs() {
        let n = blob.as_slice().len();
        // Header, section table, and the point-set info section: everything a
        // reader trusts for sizes and offsets.
        let info_end = 48 + 64 + 64 + 16;
        for _ in 0..3000 {
            let mut copy = blob.clone();
            let bytes = copy.as_mut_slice();
            let at = loop {
                let at = rng.random_range(0..info_end.min(n));
                if !(CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8).contains(&at) {
                    break at;
                }
            };
            bytes[at] = rng.random();
            let sum = checksum(bytes);
            bytes[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
            total += 1;
            // Never panics; whatever parses is total (checked in parse_and_touch).
            if parse_and_touch(bytes).is_err() {
                rejected += 1;
            }
        }
    }
    // Most such corruptions change a size, offset, count or code and are refused.
    assert!(rejected * 2 > total, "{rejected}/{total}");
}

/// Little-endian field writers for the corruptions below.
fn put_u32(bytes: &mut [u8], at: usize, v: u32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn put_u64(bytes: &mut [u8], at: usize, v: u64) {
    bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

fn get_u64(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
}

/// Byte offsets of the header fields and of section-table row `k`'s fields
/// (core/FORMAT.md).
const VERSION: usize = 8;
const KIND: usize = 12;
const META_OFFSET: usize = 32;
const META_LEN: usize = 36;
const SECTION_COUNT: usize = 40;
const fn row(k: usize) -> usize {
    48 + 32 * k
}
const TAG: usize = 0;
const ELEM_SIZE: usize = 4;
const OFFSET: usize = 8;
const LEN: usize = 16;

/// The byte offset of the section-table row of `tag` in the blob `b`, which
/// has one.
fn section_row(b: &[u8], tag: SectionTag) -> usize {
    let count = u32::from_le_bytes(b[SECTION_COUNT..SECTION_COUNT + 4].try_into().unwrap());
    (0..count as usize)
        .map(row)
        .find(|&r| b[r + TAG..r + TAG + 4] == (tag as u32).to_le_bytes())
        .unwrap()
}

/// Applies `damage` to a copy of `blob`, fixes the checksum (so only the check
/// aimed at is hit), and returns the error `Blob::parse` and the view give.
fn damaged(blob: &AlignedBytes, damage: impl FnOnce(&mut [u8])) -> BlobError {
    let mut copy = blob.clone();
    let bytes = copy.as_mut_slice();
    damage(bytes);
    let sum = checksum(bytes);
    bytes[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
    parse_and_touch(bytes).unwrap_err()
}

#[test]
fn each_error_variant_is_produced_by_the_corruption_it_names() {
    // A direction blob: section 0 is the point-set info, section 1 the points.
    let blob = sobol_blob(Domain::Sphere, 16, 1, 2).1;
    let b = blob.as_slice();
    let n = b.len() as u64;
    let info = get_u64(b, row(0) + OFFSET) as usize;
    let (points_at, points_len) = (get_u64(b, row(1) + OFFSET), get_u64(b, row(1) + LEN));
    let meta_end = u64::from(u32::from_le_bytes(
        b[META_OFFSET..META_OFFSET + 4].try_into().unwrap(),
    )) + u64::from(u32::from_le_bytes(
        b[META_LEN..META_LEN + 4].try_into().unwrap(),
    ));
    assert_eq!(points_at + points_len, n, "points are the last section");

    let mut cases: Vec<(BlobError, BlobError)> = vec![
        (
            parse_and_touch(&b[..b.len() - 1]).unwrap_err(),
            BlobError::Layout(LayoutError::Truncated {
                needed: n,
                got: n - 1,
            }),
        ),
        (
            parse_and_touch(&b[..20]).unwrap_err(),
            BlobError::Layout(LayoutError::Truncated {
                needed: 48,
                got: 20,
            }),
        ),
        (
            damaged(&blob, |x| x[0] ^= 1),
            BlobError::Layout(LayoutError::BadMagic),
        ),
        (
            damaged(&blob, |x| put_u32(x, VERSION, 2)),
            BlobError::Layout(LayoutError::UnsupportedVersion(2)),
        ),
        (
            damaged(&blob, |x| put_u32(x, SECTION_COUNT, MAX_SECTIONS + 1)),
            BlobError::Layout(LayoutError::TooManySections {
                count: 65,
                max: MAX_SECTIONS,
            }),
        ),
        (
            damaged(&blob, |x| put_u32(x, SECTION_COUNT, MAX_SECTIONS)),
            BlobError::Layout(LayoutError::SectionTablePastEnd {
                table_end: row(64) as u64,
                len: n,
            }),
        ),
        (
            damaged(&blob, |x| put_u32(x, META_OFFSET, 100)),
            BlobError::Layout(LayoutError::MetadataOverlapsTable {
                meta_offset: 100,
                table_end: row(2) as u64,
            }),
        ),
        (
            damaged(&blob, |x| put_u32(x, META_LEN, n as u32)),
            BlobError::Layout(LayoutError::MetadataPastEnd {
                meta_end: row(2) as u64 + n,
                len: n,
            }),
        ),
        (
            damaged(&blob, |x| put_u64(x, row(0) + LEN, u64::MAX)),
            BlobError::Layout(LayoutError::SectionRangeOverflow { index: 0 }),
        ),
        (
            damaged(&blob, |x| put_u64(x, row(0) + OFFSET, 0)),
            BlobError::Layout(LayoutError::SectionOverlapsMetadata {
                index: 0,
                offset: 0,
                meta_end,
            }),
        ),
        (
            damaged(&blob, |x| put_u64(x, row(1) + LEN, points_len + 4)),
            BlobError::Layout(LayoutError::SectionPastEnd {
                index: 1,
                end: n + 4,
                len: n,
            }),
        ),
        (
            damaged(&blob, |x| {
                put_u64(x, row(1) + OFFSET, points_at + 4);
                put_u64(x, row(1) + LEN, points_len - 4);
            }),
            BlobError::Layout(LayoutError::SectionMisaligned {
                index: 1,
                offset: points_at + 4,
            }),
        ),
        (
            damaged(&blob, |x| put_u32(x, row(0) + ELEM_SIZE, 0)),
            BlobError::Layout(LayoutError::ZeroElementSize { index: 0 }),
        ),
        (
            damaged(&blob, |x| put_u32(x, row(0) + ELEM_SIZE, 3)),
            BlobError::Layout(LayoutError::PartialElement {
                index: 0,
                len: 16,
                elem_size: 3,
            }),
        ),
        (
            damaged(&blob, |x| {
                put_u64(x, row(1) + OFFSET, info as u64);
                put_u64(x, row(1) + LEN, 16);
            }),
            BlobError::Layout(LayoutError::SectionsOverlap {
                first: 0,
                second: 1,
            }),
        ),
        (
            damaged(&blob, |x| put_u32(x, KIND, 9)),
            BlobError::UnknownKind(9),
        ),
        (
            damaged(&blob, |x| put_u32(x, META_LEN, 0)),
            BlobError::BadMetadata,
        ),
        (
            damaged(&blob, |x| put_u32(x, row(1) + TAG, 77)),
            BlobError::MissingSection(SectionTag::Points),
        ),
        (
            damaged(&blob, |x| put_u64(x, row(0) + LEN, 0)),
            BlobError::PointSet(PointSetError::InfoSize {
                got: 0,
                expected: 16,
            }),
        ),
        (
            damaged(&blob, |x| put_u32(x, info, 0)),
            BlobError::PointSet(PointSetError::NoPoints),
        ),
        (
            damaged(&blob, |x| put_u32(x, info + 4, 0)),
            BlobError::PointSet(PointSetError::NoSets),
        ),
        (
            damaged(&blob, |x| put_u32(x, info + 8, 7)),
            BlobError::PointSet(PointSetError::UnknownDomain(7)),
        ),
        (
            damaged(&blob, |x| put_u32(x, info + 8, Domain::Square as u32)),
            BlobError::PointSet(PointSetError::DomainMismatch {
                kind: BlobKind::DirectionSet,
                domain: Domain::Square,
            }),
        ),
        (
            damaged(&blob, |x| put_u32(x, row(1) + ELEM_SIZE, 2)),
            BlobError::PointSet(PointSetError::ElementSize(2)),
        ),
        (
            damaged(&blob, |x| put_u32(x, info, 15)),
            BlobError::PointSet(PointSetError::Length {
                expected: 60,
                got: 64,
            }),
        ),
        (
            Blob::parse(b).unwrap().point_set_2d().unwrap_err(),
            BlobError::WrongKind {
                expected: BlobKind::PointSet2D,
                found: BlobKind::DirectionSet,
            },
        ),
    ];

    // Checks before the checksum: misalignment, trailing bytes, the checksum itself.
    let mut shifted = AlignedBytes::zeroed(b.len() + 1);
    shifted.as_mut_slice()[1..].copy_from_slice(b);
    cases.push((
        parse_and_touch(&shifted.as_slice()[1..]).unwrap_err(),
        BlobError::Layout(LayoutError::Misaligned),
    ));
    let mut longer = AlignedBytes::zeroed(b.len() + 16);
    longer.as_mut_slice()[..b.len()].copy_from_slice(b);
    cases.push((
        parse_and_touch(longer.as_slice()).unwrap_err(),
        BlobError::Layout(LayoutError::TrailingBytes {
            declared: n,
            got: n + 16,
        }),
    ));
    let mut flipped = blob.clone();
    flipped.as_mut_slice()[b.len() - 1] ^= 1;
    assert!(matches!(
        parse_and_touch(flipped.as_slice()),
        Err(BlobError::Layout(LayoutError::ChecksumMismatch { .. }))
    ));

    // The writer's failures.
    let spec = SectionSpec {
        tag: SectionTag::Points,
        elem_size: 4,
        bytes: &[0; 4],
    };
    let too_many = [spec; MAX_SECTIONS as usize + 1];
    let mut out = vec![0u8; encoded_len(&[], &too_many)];
    cases.push((
        write(&mut out, BlobKind::PointSet2D, &[], &too_many)
            .unwrap_err()
            .into(),
        BlobError::Write(WriteError::TooManySections {
            count: 65,
            max: MAX_SECTIONS,
        }),
    ));
    let need = encoded_len(&[], &[spec]);
    let mut out = vec![0u8; need + 16];
    cases.push((
        write(&mut out, BlobKind::PointSet2D, &[], &[spec])
            .unwrap_err()
            .into(),
        BlobError::Write(WriteError::BufferSize {
            needed: need as u64,
            got: need as u64 + 16,
        }),
    ));

    for (got, want) in &cases {
        assert_eq!(got, want);
        let line = got.to_string();
        assert!(!line.is_empty() && !line.contains('\n'), "{line:?}");
    }
}

/// A BRDF prior's metallic axis holds metallic 0 and 1, and perhaps the metal
/// layer: tables of 16 nodes labelled `2 x 2 x 4` (every length consistent) are
/// refused, the same tables as `2 x 4 x 2` load, and `3 x 2 x 3` (the metal
/// layer) loads.
#[test]
fn a_brdf_prior_with_four_metallic_layers_is_refused() {
    use nuld_build_tool::sphere::brdf_prior::{BrdfPrior, PriorSpace};
    let blob = |prior: BrdfPrior| {
        let parts = conditional_parts(
            shape(8, &[4], Activation::Relu, PointWarp::BrdfTable, 2),
            2,
            [3, 2],
            7,
        );
        with_brdf_prior(parts, std::sync::Arc::new(prior))
            .to_blob(&META)
            .unwrap()
    };
    let tables = BrdfPrior::new([2, 4, 2], 5, PriorSpace::HalfVector).unwrap();
    let ok = blob(tables.clone());
    assert!(Blob::parse(ok.as_slice()).unwrap().brdf().is_ok());
    let mut relabelled = tables;
    relabelled.grid = [2, 2, 4];
    let four = blob(relabelled);
    let err = Blob::parse(four.as_slice())
        .and_then(|b| b.brdf())
        .unwrap_err();
    assert!(err.to_string().contains("warp"), "{err}");
    assert!(parse_and_touch(four.as_slice()).is_err());
    assert!(Blob::parse(brdf_table_blob().as_slice())
        .unwrap()
        .brdf()
        .is_ok());
}

/// Each metal-points failure has its error: one of the two sections missing,
/// an element size or a length other than its shared twin's, a non-finite
/// metal parameter, and metal points on a prior without the metal layer.
#[test]
fn each_metal_points_failure_has_its_error() {
    use nuld_build_tool::sphere::brdf_prior::{BrdfPrior, PriorSpace};
    let blob = brdf_table_blob();
    let b = blob.as_slice();
    let row_of = |tag: SectionTag| section_row(b, tag);
    let (params_row, table_row) = (
        row_of(SectionTag::MetalNetworkParams),
        row_of(SectionTag::MetalPointTable),
    );
    let params_len = get_u64(b, params_row + LEN);
    let table_len = get_u64(b, table_row + LEN);
    let mut bad_param = brdf_table_parts(small_brdf_prior());
    bad_param.metal.as_mut().unwrap().params[5] = 0x7c00;
    let no_layer = brdf_table_parts(std::sync::Arc::new(
        BrdfPrior::new([3, 2, 2], 5, PriorSpace::HalfVector).unwrap(),
    ));
    let error = |p: nuld_build_tool::conditional::blob::ConditionalParts| {
        parse_and_touch(p.to_blob(&META).unwrap().as_slice()).unwrap_err()
    };
    let cases = [
        (
            damaged(&blob, |x| put_u32(x, table_row + TAG, 77)),
            ConditionalError::MetalPoints(SectionTag::MetalPointTable as u32),
        ),
        (
            damaged(&blob, |x| put_u32(x, params_row + TAG, 78)),
            ConditionalError::MetalPoints(SectionTag::MetalNetworkParams as u32),
        ),
        (
            damaged(&blob, |x| put_u32(x, table_row + ELEM_SIZE, 2)),
            ConditionalError::MetalElementSize {
                tag: SectionTag::MetalPointTable as u32,
                size: 2,
            },
        ),
        (
            damaged(&blob, |x| put_u64(x, params_row + LEN, params_len - 2)),
            ConditionalError::MetalLength {
                tag: SectionTag::MetalNetworkParams as u32,
                expected: params_len / 2,
                got: params_len / 2 - 1,
            },
        ),
        (
            damaged(&blob, |x| put_u64(x, table_row + LEN, table_len - 4)),
            ConditionalError::MetalLength {
                tag: SectionTag::MetalPointTable as u32,
                expected: table_len / 4,
                got: table_len / 4 - 1,
            },
        ),
        (
            error(bad_param),
            ConditionalError::NonFiniteMetalParam {
                index: 5,
                bits: 0x7c00,
            },
        ),
        (
            error(no_layer),
            ConditionalError::MetalPoints(SectionTag::MetalNetworkParams as u32),
        ),
    ];
    for (k, (got, want)) in cases.into_iter().enumerate() {
        assert_eq!(got, BlobError::Conditional(want), "case {k}");
        let line = got.to_string();
        assert!(!line.contains('\n'), "{line:?}");
    }
}

#[test]
fn blob_errors_convert_into_boxed_std_errors_with_question_mark() {
    fn len(bytes: &[u8]) -> Result<usize, Box<dyn std::error::Error + Send + Sync>> {
        Ok(Blob::parse(bytes)?.point_set_2d()?.len())
    }
    let junk = AlignedBytes::zeroed(64);
    let e = len(junk.as_slice()).unwrap_err();
    assert_eq!(
        e.downcast_ref::<BlobError>(),
        Some(&BlobError::Layout(LayoutError::BadMagic))
    );
    assert_eq!(e.to_string(), "not a nuld blob (bad magic)");
    let blob = sobol_blob(Domain::Square, 5, 1, 1).1;
    assert_eq!(len(blob.as_slice()).unwrap(), 5);
}

/// The info record's fields, read by offset.
struct ConditionalFields {
    n: u32,
    instances: u32,
    domain: u32,
    target: u32,
    grid: [u32; 2],
    weight_grid: [u32; 2],
    cond_min: [f32; 2],
    cond_max: [f32; 2],
    hidden: [u32; 3],
    activation: u32,
    warp: u32,
    instance_slots: u32,
    offset_hash: u32,
}

/// What a parsed conditional blob promises (core/FORMAT.md, "Validation"), checked
/// here from the raw sections by field offset with plain arithmetic, independently of the
/// runtime's validation.
fn conditional_semantics_hold(bytes: &[u8]) -> bool {
    let Ok(layout) = Layout::read(bytes) else {
        return false;
    };
    let section = |tag| layout.section(tag).ok();
    let (Some((_, info)), Some((pe, params)), Some((te, table)), Some((we, weights))) = (
        section(SectionTag::ConditionalInfo),
        section(SectionTag::NetworkParams),
        section(SectionTag::PointTable),
        section(SectionTag::WeightTable),
    ) else {
        return false;
    };
    if info.len() != CONDITIONAL_INFO_LEN {
        return false;
    }
    // The info record's fields at their core/FORMAT.md offsets.
    let word = |at: usize| u32::from_le_bytes(info[at..at + 4].try_into().unwrap());
    let real = |at: usize| f32::from_bits(word(at));
    let info = ConditionalFields {
        n: word(0),
        instances: word(4),
        domain: word(8),
        target: word(12),
        grid: [word(16), word(20)],
        weight_grid: [word(24), word(28)],
        cond_min: [real(32), real(36)],
        cond_max: [real(40), real(44)],
        hidden: [word(48), word(52), word(56)],
        activation: word(60),
        warp: word(68),
        instance_slots: word(72),
        offset_hash: word(76),
    };
    let h = info.hidden;
    let layers = h.iter().take_while(|&&w| w > 0).count();
    let widths_ok =
        layers >= 1 && h[layers..].iter().all(|&w| w == 0) && h.iter().all(|&w| w <= 128);
    let ranges_ok = (0..2).all(|a| {
        let (lo, hi) = (info.cond_min[a], info.cond_max[a]);
        lo.is_finite() && hi.is_finite() && lo < hi
    });
    if !(info.n >= 1
        && info.instances >= 1
        // Each target on its domain: the glTF BRDF on the hemisphere, an
        // environment map on the sphere.
        && ((info.target == 1 && info.domain == 2) || (info.target == 2 && info.domain == 1))
        && info.grid.iter().chain(&info.weight_grid).all(|&g| g >= 2)
        && ranges_ok
        && info.activation <= 1
        && widths_ok
        // Warps 0, 1 and 3 (the BRDF mixture and the tabulated prior, on the
        // hemisphere only) are the glTF BRDF's; warp 2 (the environment tree) is
        // a map's, which requires it.
        && ((info.target == 1
            && (info.warp == 0 || ((info.warp == 1 || info.warp == 3) && info.domain == 2)))
            || (info.target == 2 && info.warp == 2))
        // The plain (0) and the salted (1) instance-offset hash.
        && info.offset_hash <= 1)
    {
        return false;
    }
    // The embedding, max(M, 1) n rows of h1, counts fewer than 2^32 numbers.
    let rows = info.instance_slots.max(1) as u128 * info.n as u128;
    if rows * h[0] as u128 >= 1 << 32 {
        return false;
    }
    // max(M, 1) n h1 + sum over layers (out (in + 1)) + 2 (last + 1), inputs 11.
    let mut expected_params = rows * h[0] as u128;
    let mut fan_in = 11u128;
    for &w in &h[..layers] {
        expected_params += w as u128 * (fan_in + 1);
        fan_in = w as u128;
    }
    expected_params += 2 * (fan_in + 1);
    // A metallic axis (tag 18) multiplies the table by its node count.
    let Some(axis) = metallic_axis_semantics(&layout, info.warp) else {
        return false;
    };
    let table_len = info.grid[0] as u128
        * info.grid[1] as u128
        * info.instances as u128
        * info.n as u128
        * axis.max(1) as u128;
    // Warp 1 stores the lobe probabilities after the weights, warp 3 the metal's
    // albedo.
    let weight_len = info.weight_grid[0] as u128
        * info.weight_grid[1] as u128
        * if info.warp == 1 || info.warp == 3 {
            2
        } else {
            1
        };
    (info.warp != 2 || tree_semantics_hold(&layout))
        && (info.warp != 3 || brdf_prior_semantics_hold(&layout))
        && metal_semantics_hold(&layout, info.warp, params.len(), table.len() / axis.max(1))
        && pe.elem_size == 2
        && te.elem_size == 4
        && we.elem_size == 4
        && params.len() as u128 == 2 * expected_params
        && table.len() as u128 == 4 * table_len
        && weights.len() as u128 == 4 * weight_len
        && params
            .chunks_exact(2)
            .all(|b| f16_decode(u16::from_le_bytes([b[0], b[1]])).is_finite())
        && weights.chunks_exact(4).all(|b| {
            let w = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            w.is_finite() && w >= 0.0
        })
}

/// The BRDF prior's sections (core/FORMAT.md, tags 11-14 and 24), checked from
/// the raw bytes: a 16-byte info of grid counts `G_r, G_t` of 2 to 256 and `G_m` of 2
/// or 3 (the metal layer), and a size `S` of 2 to 4096; `nodes S^2` data and conditional CDF values and `nodes S` marginal CDF
/// values, all finite `f32 >= 0`, each row of `S` CDF values non-decreasing,
/// each node's marginal ending above 0; `nodes` finite masses above 0.
fn brdf_prior_semantics_hold(layout: &Layout<'_>) -> bool {
    let section = |tag| layout.section(tag).ok();
    let Some((_, info)) = section(SectionTag::BrdfPriorInfo) else {
        return false;
    };
    if info.len() != 16 {
        return false;
    }
    let word = |at: usize| u32::from_le_bytes(info[at..at + 4].try_into().unwrap());
    let (grid, size) = ([word(0), word(4), word(8)], word(12));
    let axes = grid[..2].iter().all(|g| (2..=256).contains(g)) && (2..=3).contains(&grid[2]);
    if !(axes && (2..=4096).contains(&size)) {
        return false;
    }
    let nodes = (grid[0] * grid[1] * grid[2]) as usize;
    let s = size as usize;
    let floats = |tag, len: usize| -> Option<Vec<f32>> {
        let (e, bytes) = section(tag)?;
        (e.elem_size == 4 && bytes.len() == 4 * len).then(|| {
            bytes
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect()
        })
    };
    let (Some(data), Some(marginal), Some(conditional), Some(masses)) = (
        floats(SectionTag::BrdfPriorData, nodes * s * s),
        floats(SectionTag::BrdfPriorMarginal, nodes * s),
        floats(SectionTag::BrdfPriorConditional, nodes * s * s),
        floats(SectionTag::BrdfPriorMasses, nodes),
    ) else {
        return false;
    };
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite() && *x >= 0.0);
    let rising = |v: &[f32]| v.chunks(s).all(|row| row.windows(2).all(|w| w[0] <= w[1]));
    finite(&data)
        && finite(&marginal)
        && finite(&conditional)
        && rising(&marginal)
        && rising(&conditional)
        && marginal.chunks(s).all(|m| m[s - 1] > 0.0)
        && masses.iter().all(|m| m.is_finite() && *m > 0.0)
}

/// The metallic axis (core/FORMAT.md, tag 18), checked from the raw bytes:
/// `Some(0)` without one; `Some(L)` for one on warp 3 of 4-byte elements, 2 to
/// 8 finite nodes in `[0, 1]`, each above the one before; `None` otherwise.
fn metallic_axis_semantics(layout: &Layout<'_>, warp: u32) -> Option<usize> {
    let Ok((entry, bytes)) = layout.section(SectionTag::MetallicNodes) else {
        return Some(0);
    };
    let nodes: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let ok = warp == 3
        && entry.elem_size == 4
        && bytes.len() % 4 == 0
        && (2..=8).contains(&nodes.len())
        && nodes
            .iter()
            .all(|m| m.is_finite() && (0.0..=1.0).contains(m))
        && nodes.windows(2).all(|w| w[0] < w[1]);
    ok.then_some(nodes.len())
}

/// The metal points (core/FORMAT.md, tags 16 and 17), checked from the raw
/// bytes: both absent, or both present on a BRDF prior (warp 3) with the metal
/// layer (`G_m = 3`), of 2- and 4-byte elements and as many bytes as the
/// network's (`params` bytes) and the point table's (`table` bytes), every
/// parameter a finite f16.
fn metal_semantics_hold(layout: &Layout<'_>, warp: u32, params: usize, table: usize) -> bool {
    let section = |tag| layout.section(tag).ok();
    let (metal_params, metal_table) = (
        section(SectionTag::MetalNetworkParams),
        section(SectionTag::MetalPointTable),
    );
    let (Some((pe, p)), Some((te, t))) = (metal_params, metal_table) else {
        return metal_params.is_none() && metal_table.is_none();
    };
    let layer = section(SectionTag::BrdfPriorInfo)
        .is_some_and(|(_, info)| info.len() == 16 && info[8..12] == 3u32.to_le_bytes());
    warp == 3
        && layer
        && pe.elem_size == 2
        && te.elem_size == 4
        && p.len() == params
        && t.len() == table
        && p.chunks_exact(2)
            .all(|b| f16_decode(u16::from_le_bytes([b[0], b[1]])).is_finite())
}

/// The environment prior's sections (core/FORMAT.md, tags 7-9), checked from the
/// raw bytes: a 16-byte info (its `elem_size`, as the conditional info's, unread)
/// with levels `T` to 12, a grid of 2 to 1024 normals, top levels `T` 3 to 5 (0
/// read as 3) and a zero reserved word; `(4^(L+1) - 4) / 3` records of four finite `f32` with a
/// spread >= 0 and some level-1 record with mass; `(4^(T+1) - 4) / 3 G^2` finite top weights >= 0;
/// and, if there is a leaf shape (tag 19), `(2^L + 1)^2` finite values >= 0; and
/// if there is detail (tags 20, 21, and the fine tables, 22), both sections, an
/// entry per leaf naming a table, a fine table or none, whole tables of finite
/// values >= 0.
fn tree_semantics_hold(layout: &Layout<'_>) -> bool {
    let section = |tag| layout.section(tag).ok();
    let (Some((_, info)), Some((ne, nodes)), Some((oe, top))) = (
        section(SectionTag::EnvmapTreeInfo),
        section(SectionTag::EnvmapTreeNodes),
        section(SectionTag::EnvmapTreeTop),
    ) else {
        return false;
    };
    if info.len() != 16 || ne.elem_size != 16 || oe.elem_size != 4 {
        return false;
    }
    let word = |b: &[u8], at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    let (levels, grid) = (word(info, 0), word(info, 4));
    let top_levels = match word(info, 8) {
        0 => 3,
        t => t,
    };
    if !((3..=5).contains(&top_levels)
        && (top_levels..=12).contains(&levels)
        && (2..=1024).contains(&grid))
        || word(info, 12) != 0
    {
        return false;
    }
    let records = ((1u128 << (2 * (levels + 1))) - 4) / 3;
    let top_nodes = ((1u128 << (2 * (top_levels + 1))) - 4) / 3;
    if nodes.len() as u128 != 16 * records
        || top.len() as u128 != 4 * top_nodes * (grid as u128).pow(2)
    {
        return false;
    }
    let real = |b: &[u8], at: usize| f32::from_bits(word(b, at));
    let record = |r: usize| [0, 4, 8, 12].map(|o| real(nodes, 16 * r + o));
    let sound = (0..records as usize).all(|r| {
        let v = record(r);
        v.iter().all(|x| x.is_finite()) && v[3] >= 0.0
    });
    let lit = (0..4).any(|r| {
        let v = record(r);
        let mass = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]).sqrt();
        mass > 0.0 && mass.is_finite()
    });
    let finite_non_negative = |bytes: &[u8]| {
        bytes.chunks_exact(4).all(|b| {
            let w = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            w.is_finite() && w >= 0.0
        })
    };
    // The optional leaf shape (tag 19): `(2^L + 1)^2` finite values >= 0.
    let corners = match section(SectionTag::EnvmapTreeCorners) {
        None => true,
        Some((ce, c)) => {
            let side = (1u128 << levels) + 1;
            ce.elem_size == 4 && c.len() as u128 == 4 * side * side && finite_non_negative(c)
        }
    };
    // The optional detail (tags 20 and 21, both or neither, and tag 22 only
    // with them): `4^L` index entries of `u32`, each 0, a table (1 to their
    // count) or, with the high bit, a fine table (1 to theirs); tables of 272,
    // fine tables of 4160 finite values >= 0.
    let fine_section = section(SectionTag::EnvmapTreeFineDetail);
    let detail = match (
        section(SectionTag::EnvmapTreeDetailIndex),
        section(SectionTag::EnvmapTreeDetail),
    ) {
        (None, None) => fine_section.is_none(),
        (Some((ie, index)), Some((te, tables))) => {
            let (table, fine_table) = (4 * (16 + 16 * 16), 4 * (64 + 64 * 64));
            let (fe, fine) = fine_section.map_or((4, &[][..]), |(e, f)| (e.elem_size, f));
            let count = (tables.len() / table) as u32;
            let fine_count = (fine.len() / fine_table) as u32;
            let named = |e: u32| {
                if e & 1 << 31 == 0 {
                    e <= count
                } else {
                    (1..=fine_count).contains(&(e & !(1 << 31)))
                }
            };
            ie.elem_size == 4
                && te.elem_size == 4
                && fe == 4
                && index.len() as u128 == 4 * (1u128 << (2 * levels))
                && tables.len() % table == 0
                && fine.len() % fine_table == 0
                && index.chunks_exact(4).all(|e| named(word(e, 0)))
                && finite_non_negative(tables)
                && finite_non_negative(fine)
        }
        _ => false,
    };
    sound && lit && finite_non_negative(top) && corners && detail
}

/// 100k mutations of a conditional BRDF blob: byte changes and truncations (the
/// checksum or the length check must refuse them), and byte changes with the
/// checksum recomputed, anywhere in the blob, so that the semantic checks are what
/// stands. Nothing panics; whatever parses satisfies the validated semantics
/// (checked independently) and serves only unit directions and finite weights.
#[test]
fn conditional_blob_mutations_are_rejected_or_harmless() {
    mutate(conditional_blob(), 100_000, 13);
}

/// [`conditional_blob_mutations_are_rejected_or_harmless`] for an environment
/// sampler's blob (target 2 on the sphere), 50k mutations.
#[test]
fn envmap_blob_mutations_are_rejected_or_harmless() {
    mutate(envmap_blob(), 50_000, 17);
}

/// [`conditional_blob_mutations_are_rejected_or_harmless`] for a BRDF sampler
/// on the tabulated prior (warp 3 and its five sections), 50k mutations.
#[test]
fn brdf_table_blob_mutations_are_rejected_or_harmless() {
    mutate(brdf_table_blob(), 50_000, 19);
}

/// [`conditional_blob_mutations_are_rejected_or_harmless`] for a BRDF sampler
/// with a metallic axis (tag 18), 50k mutations.
#[test]
fn metallic_axis_blob_mutations_are_rejected_or_harmless() {
    mutate(metallic_axis_blob(), 50_000, 23);
}

/// Each metallic-axis failure has its error: a node count outside 2 to 8, a
/// node out of order, out of `[0, 1]` or not finite, an element size other
/// than 4, the axis on another warp, and a point table short of a layer.
#[test]
fn each_metallic_axis_failure_has_its_error() {
    let blob = metallic_axis_blob();
    let b = blob.as_slice();
    let row_of = |tag: SectionTag| section_row(b, tag);
    let axis_row = row_of(SectionTag::MetallicNodes);
    let axis = get_u64(b, axis_row + OFFSET) as usize;
    let table_row = row_of(SectionTag::PointTable);
    let table_entries = get_u64(b, table_row + LEN) / 4;
    let info = get_u64(b, row_of(SectionTag::ConditionalInfo) + OFFSET) as usize;
    let node = |j: usize, m: f32| move |x: &mut [u8]| put_u32(x, axis + 4 * j, m.to_bits());
    let value = |index: u32, m: f32| {
        ConditionalError::MetallicNodes(MetallicNodesError::Value {
            index,
            bits: m.to_bits(),
        })
    };
    let cases = [
        (
            damaged(&blob, |x| put_u64(x, axis_row + LEN, 4)),
            ConditionalError::MetallicNodes(MetallicNodesError::Count(1)),
        ),
        (damaged(&blob, node(2, 0.5)), value(2, 0.5)),
        (damaged(&blob, node(1, 0.97)), value(2, 0.95)),
        (damaged(&blob, node(2, 1.5)), value(2, 1.5)),
        (damaged(&blob, node(0, -0.0625)), value(0, -0.0625)),
        (damaged(&blob, node(1, f32::NAN)), value(1, f32::NAN)),
        (
            damaged(&blob, |x| put_u32(x, axis_row + ELEM_SIZE, 2)),
            ConditionalError::MetallicNodesElementSize(2),
        ),
        (
            // The warp field of the info record (byte 68): the equal-area map.
            damaged(&blob, |x| {
                put_u32(x, info + 68, PointWarp::EqualArea as u32)
            }),
            ConditionalError::MetallicNodesWarp(PointWarp::EqualArea as u32),
        ),
        (
            // Two of the three layers.
            damaged(&blob, |x| {
                put_u64(x, table_row + LEN, 4 * table_entries / 3 * 2)
            }),
            ConditionalError::PointTableLength {
                expected: table_entries,
                got: table_entries / 3 * 2,
            },
        ),
    ];
    for (k, (got, want)) in cases.into_iter().enumerate() {
        assert_eq!(got, BlobError::Conditional(want), "case {k}");
        let line = got.to_string();
        assert!(!line.contains('\n'), "{line:?}");
    }
    // The tool refuses to write a bad axis.
    let nine: Vec<f32> = (0..9).map(|j| j as f32 / 8.0).collect();
    let parts = with_metallic_axis(brdf_table_parts(small_brdf_prior()), &nine, 9);
    assert!(parts.to_blob(&META).is_err());
}

/// `cases` mutations of `blob` from `seed` (see
/// [`conditional_blob_mutations_are_rejected_or_harmless`]).
fn mutate(blob: AlignedBytes, cases: usize, seed: u64) {
    let valid = blob.as_slice();
    assert!(conditional_semantics_hold(valid));
    parse_and_touch(valid).unwrap();
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let n = valid.len();
    let (mut accepted, mut rejected_semantic) = (0, 0);
    for case in 0..cases {
        let mut copy = blob.clone();
        let bytes = copy.as_mut_slice();
        match case % 4 {
            0 => {
                let at = rng.random_range(0..n);
                bytes[at] = bytes[at].wrapping_add(rng.random_range(1..=255));
                assert!(parse_and_touch(bytes).is_err(), "case {case}");
            }
            1 => {
                let cut = rng.random_range(0..n);
                assert!(parse_and_touch(&bytes[..cut]).is_err(), "case {case}");
            }
            _ => {
                for _ in 0..rng.random_range(1..4) {
                    let at = loop {
                        let at = rng.random_range(0..n);
                        if !(CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8).contains(&at) {
                            break at;
                        }
                    };
                    // Half the time a whole little-endian u32 (counts, codes, bits).
                    if rng.random_bool(0.5) && at + 4 <= n {
                        let v: u32 = match rng.random_range(0..4) {
                            0 => rng.random_range(0..4),
                            1 => u32::MAX - rng.random_range(0..4),
                            2 => 0x7f80_0000 | rng.random_range(0..2) << 31,
                            _ => rng.random(),
                        };
                        put_u32(bytes, at & !3, v);
                    } else {
                        bytes[at] = rng.random();
                    }
                }
                let sum = checksum(bytes);
                bytes[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
                let semantics = conditional_semantics_hold(bytes);
                match parse_and_touch(bytes) {
                    Ok(()) => {
                        accepted += 1;
                        // Accepted as conditional: its semantics must hold.
                        if Blob::parse(bytes).unwrap().kind() == BlobKind::Conditional {
                            assert!(semantics, "case {case}: broken blob accepted");
                        }
                    }
                    Err(_) => {
                        if !semantics {
                            rejected_semantic += 1;
                        }
                    }
                }
            }
        }
    }
    // Both outcomes happen: data bytes (codes, finite parameters) may change
    // harmlessly, and many mutations break a count, code, range or value.
    assert!(
        accepted > cases / 100 && rejected_semantic > cases / 100,
        "{accepted} {rejected_semantic}"
    );
}
