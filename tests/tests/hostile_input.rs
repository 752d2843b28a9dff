//! `Blob::parse` on hostile bytes: random garbage, truncations, bit flips and
//! re-checksummed field corruptions of valid blobs. It must never panic, and every
//! corruption of a valid blob must be rejected (by the checksum or a bounds check).

use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::blob::{checksum, BlobError, Domain, CHECKSUM_OFFSET};
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
