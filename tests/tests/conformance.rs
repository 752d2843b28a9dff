//! The runtime returns exactly what the build tool meant to write, to the
//! quantization step.

use glam::{DVec2, DVec3};
use nuld_core::blob::{BlobKind, Domain};
use nuld_core::quantize::{unorm16_decode_f64, unorm16_encode, UNORM16_MAX_ERROR};
use nuld_runtime::{Blob, BlobError, LayoutError};
use nuld_tests::sobol_blob;

#[test]
fn point_sets_round_trip_to_the_quantization_step() {
    for (n, sets) in [(1, 1), (7, 3), (256, 1), (1000, 4), (4096, 2)] {
        let (ps, bytes) = sobol_blob(Domain::Square, n, sets, 9);
        let blob = Blob::parse(bytes.as_slice()).unwrap();
        assert_eq!(blob.kind(), BlobKind::PointSet2D);
        assert_eq!(blob.metadata(), nuld_tests::META);
        let pts = blob.point_set_2d().unwrap();
        assert_eq!((pts.len(), pts.set_count()), (n, sets));
        for (s, set) in ps.sets.iter().enumerate() {
            for (i, p) in set.iter().enumerate() {
                let got = pts.point(s, i);
                // Exactly the cell centre of the code the tool wrote...
                let want = DVec2::new(
                    unorm16_decode_f64(unorm16_encode(p.x)),
                    unorm16_decode_f64(unorm16_encode(p.y)),
                );
                assert_eq!(got.as_dvec2(), want, "set {s} point {i}");
                // ...which is within half a cell of the tool's point.
                assert!((got.as_dvec2() - *p).abs().max_element() <= UNORM16_MAX_ERROR);
            }
        }
        // Indices wrap modulo the counts.
        assert_eq!(pts.point(sets, n + 3 % n), pts.point(0, 3 % n));
        assert!(matches!(
            blob.direction_set(),
            Err(BlobError::WrongKind { .. })
        ));
    }
}

#[test]
fn direction_sets_round_trip_through_the_equal_area_maps() {
    for domain in [Domain::Sphere, Domain::Hemisphere] {
        for (n, sets) in [(1, 2), (64, 1), (333, 3), (2048, 2)] {
            let (ps, bytes) = sobol_blob(domain, n, sets, 5);
            let blob = Blob::parse(bytes.as_slice()).unwrap();
            assert_eq!(blob.kind(), BlobKind::DirectionSet);
            let dirs = blob.direction_set().unwrap();
            assert_eq!(
                (dirs.len(), dirs.set_count(), dirs.domain()),
                (n, sets, domain)
            );
            for (s, set) in ps.sets.iter().enumerate() {
                for (i, p) in set.iter().enumerate() {
                    let got = dirs.direction(s, i).as_dvec3();
                    let q = DVec2::new(
                        unorm16_decode_f64(unorm16_encode(p.x)),
                        unorm16_decode_f64(unorm16_encode(p.y)),
                    );
                    let want = domain.to_direction(q);
                    // f32 rounding of a unit vector.
                    assert!((got - want).length() < 2e-7, "{domain:?} {s} {i}");
                    assert!((got.length() - 1.0).abs() < 2e-7);
                    if domain == Domain::Hemisphere {
                        assert!(got.z >= 0.0);
                    }
                    // And close to the tool's unquantized direction: both maps stretch
                    // distances by at most ~2*pi, half a cell is 2^-17 per axis.
                    let exact: DVec3 = domain.to_direction(*p);
                    assert!((got - exact).length() < 1e-4, "{domain:?} {s} {i}");
                }
            }
            assert!(matches!(
                blob.point_set_2d(),
                Err(BlobError::WrongKind { .. })
            ));
        }
    }
}

/// A blob written by `build-tool sobol --domain sphere --n 64 --sets 2 --seed 3`,
/// committed, and embedded at compile time through the aligned helper.
static EMBEDDED: &[u8] = nuld_runtime::include_blob!("../fixtures/sobol_sphere_64x2.nuld");

#[test]
fn embedded_blob_through_the_aligned_helper() {
    assert_eq!(EMBEDDED.as_ptr() as usize % 16, 0);
    let blob = Blob::parse(EMBEDDED).unwrap();
    let dirs = blob.direction_set().unwrap();
    let (ps, fresh) = sobol_blob(Domain::Sphere, 64, 2, 3);
    // The committed file is what today's tool writes for the same arguments (bar
    // the metadata), so the format has not drifted.
    let fresh = Blob::parse(fresh.as_slice())
        .unwrap()
        .direction_set()
        .unwrap();
    assert_eq!(dirs.len(), 64);
    for s in 0..2 {
        for i in 0..64 {
            assert_eq!(dirs.direction(s, i), fresh.direction(s, i));
            let exact = Domain::Sphere.to_direction(ps.sets[s][i]);
            assert!((dirs.direction(s, i).as_dvec3() - exact).length() < 1e-4);
        }
    }
    // An unaligned view of the same bytes is refused, not misread.
    let mut shifted = nuld_build_tool::pointset::AlignedBytes::zeroed(EMBEDDED.len() + 1);
    shifted.as_mut_slice()[1..].copy_from_slice(EMBEDDED);
    assert_eq!(
        Blob::parse(&shifted.as_slice()[1..]).unwrap_err(),
        BlobError::Layout(LayoutError::Misaligned)
    );
}
