//! `Blob::parse` on hostile bytes: random garbage, truncations, bit flips and
//! re-checksummed field corruptions of valid blobs. It must never panic, and every
//! corruption of a valid blob must be rejected (by the checksum or a bounds check).

use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::blob::{
    checksum, encoded_len, write, BlobError, Domain, SectionSpec, SectionTag, CHECKSUM_OFFSET,
    MAX_SECTIONS,
};
use nuld_runtime::{Blob, BlobKind};
use nuld_tests::sobol_blob;
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
        BlobKind::Conditional => unreachable!("Blob::parse does not accept conditional blobs yet"),
    }
    Ok(())
}

fn valid_blobs() -> Vec<AlignedBytes> {
    vec![
        sobol_blob(Domain::Square, 5, 2, 1).1,
        sobol_blob(Domain::Sphere, 16, 1, 2).1,
        sobol_blob(Domain::Hemisphere, 3, 3, 3).1,
        sobol_blob(Domain::Square, 200, 1, 4).1,
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
                matches!(err, BlobError::Truncated { .. }),
                "cut {cut}: {err:?}"
            );
        }
        let mut longer = AlignedBytes::zeroed(bytes.len() + 16);
        longer.as_mut_slice()[..bytes.len()].copy_from_slice(bytes);
        assert!(matches!(
            parse_and_touch(longer.as_slice()),
            Err(BlobError::TrailingBytes { .. })
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
            BlobError::Truncated {
                needed: n,
                got: n - 1,
            },
        ),
        (
            parse_and_touch(&b[..20]).unwrap_err(),
            BlobError::Truncated {
                needed: 48,
                got: 20,
            },
        ),
        (damaged(&blob, |x| x[0] ^= 1), BlobError::BadMagic),
        (
            damaged(&blob, |x| put_u32(x, VERSION, 2)),
            BlobError::UnsupportedVersion(2),
        ),
        (
            damaged(&blob, |x| put_u32(x, SECTION_COUNT, MAX_SECTIONS + 1)),
            BlobError::TooManySections {
                count: 65,
                max: MAX_SECTIONS,
            },
        ),
        (
            damaged(&blob, |x| put_u32(x, SECTION_COUNT, MAX_SECTIONS)),
            BlobError::SectionTablePastEnd {
                table_end: row(64) as u64,
                len: n,
            },
        ),
        (
            damaged(&blob, |x| put_u32(x, META_OFFSET, 100)),
            BlobError::MetadataOverlapsTable {
                meta_offset: 100,
                table_end: row(2) as u64,
            },
        ),
        (
            damaged(&blob, |x| put_u32(x, META_LEN, n as u32)),
            BlobError::MetadataPastEnd {
                meta_end: row(2) as u64 + n,
                len: n,
            },
        ),
        (
            damaged(&blob, |x| put_u64(x, row(0) + LEN, u64::MAX)),
            BlobError::SectionRangeOverflow { index: 0 },
        ),
        (
            damaged(&blob, |x| put_u64(x, row(0) + OFFSET, 0)),
            BlobError::SectionOverlapsMetadata {
                index: 0,
                offset: 0,
                meta_end,
            },
        ),
        (
            damaged(&blob, |x| put_u64(x, row(1) + LEN, points_len + 4)),
            BlobError::SectionPastEnd {
                index: 1,
                end: n + 4,
                len: n,
            },
        ),
        (
            damaged(&blob, |x| {
                put_u64(x, row(1) + OFFSET, points_at + 4);
                put_u64(x, row(1) + LEN, points_len - 4);
            }),
            BlobError::SectionMisaligned {
                index: 1,
                offset: points_at + 4,
            },
        ),
        (
            damaged(&blob, |x| put_u32(x, row(0) + ELEM_SIZE, 0)),
            BlobError::ZeroElementSize { index: 0 },
        ),
        (
            damaged(&blob, |x| put_u32(x, row(0) + ELEM_SIZE, 3)),
            BlobError::PartialElement {
                index: 0,
                len: 16,
                elem_size: 3,
            },
        ),
        (
            damaged(&blob, |x| {
                put_u64(x, row(1) + OFFSET, info as u64);
                put_u64(x, row(1) + LEN, 16);
            }),
            BlobError::SectionsOverlap {
                first: 0,
                second: 1,
            },
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
            BlobError::PointSetInfoSize {
                got: 0,
                expected: 16,
            },
        ),
        (damaged(&blob, |x| put_u32(x, info, 0)), BlobError::NoPoints),
        (
            damaged(&blob, |x| put_u32(x, info + 4, 0)),
            BlobError::NoSets,
        ),
        (
            damaged(&blob, |x| put_u32(x, info + 8, 7)),
            BlobError::UnknownDomain(7),
        ),
        (
            damaged(&blob, |x| put_u32(x, info + 8, Domain::Square as u32)),
            BlobError::DomainMismatch {
                kind: BlobKind::DirectionSet,
                domain: Domain::Square,
            },
        ),
        (
            damaged(&blob, |x| put_u32(x, row(1) + ELEM_SIZE, 2)),
            BlobError::PointElementSize(2),
        ),
        (
            damaged(&blob, |x| put_u32(x, info, 15)),
            BlobError::PointsLength {
                expected: 60,
                got: 64,
            },
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
        BlobError::Misaligned,
    ));
    let mut longer = AlignedBytes::zeroed(b.len() + 16);
    longer.as_mut_slice()[..b.len()].copy_from_slice(b);
    cases.push((
        parse_and_touch(longer.as_slice()).unwrap_err(),
        BlobError::TrailingBytes {
            declared: n,
            got: n + 16,
        },
    ));
    let mut flipped = blob.clone();
    flipped.as_mut_slice()[b.len() - 1] ^= 1;
    assert!(matches!(
        parse_and_touch(flipped.as_slice()),
        Err(BlobError::ChecksumMismatch { .. })
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
        write(&mut out, BlobKind::PointSet2D, &[], &too_many).unwrap_err(),
        BlobError::TooManySections {
            count: 65,
            max: MAX_SECTIONS,
        },
    ));
    let need = encoded_len(&[], &[spec]);
    let mut out = vec![0u8; need + 16];
    cases.push((
        write(&mut out, BlobKind::PointSet2D, &[], &[spec]).unwrap_err(),
        BlobError::BufferSize {
            needed: need as u64,
            got: need as u64 + 16,
        },
    ));

    for (got, want) in &cases {
        assert_eq!(got, want);
        let line = got.to_string();
        assert!(!line.is_empty() && !line.contains('\n'), "{line:?}");
    }
}

#[test]
fn blob_errors_convert_into_boxed_std_errors_with_question_mark() {
    fn len(bytes: &[u8]) -> Result<usize, Box<dyn std::error::Error + Send + Sync>> {
        Ok(Blob::parse(bytes)?.point_set_2d()?.len())
    }
    let junk = AlignedBytes::zeroed(64);
    let e = len(junk.as_slice()).unwrap_err();
    assert_eq!(e.downcast_ref::<BlobError>(), Some(&BlobError::BadMagic));
    assert_eq!(e.to_string(), "not a nuld blob (bad magic)");
    let blob = sobol_blob(Domain::Square, 5, 1, 1).1;
    assert_eq!(len(blob.as_slice()).unwrap(), 5);
}
