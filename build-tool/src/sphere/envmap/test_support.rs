//! What the tests of a map's samplers share: the check that a sampler's estimate
//! of the irradiance is unbiased against an independent quadrature, and small
//! maps written as files ([`grey_map`]).

use super::EnvmapDensity;
use crate::sphere::DirectionDensity;
use glam::{DVec2, DVec3};
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// `∫ g(l) dl` over the sphere by the midpoint rule on `q^2` points of the
/// sphere's equal-area square (`dl = 4 pi` times the square's area element).
pub(crate) fn sphere_integral(q: usize, g: impl Fn(DVec3) -> f64 + Sync) -> f64 {
    let sum: f64 = (0..q * q)
        .into_par_iter()
        .map(|k| {
            let p = DVec2::new(
                ((k % q) as f64 + 0.5) / q as f64,
                ((k / q) as f64 + 0.5) / q as f64,
            );
            g(square_to_sphere(p))
        })
        .sum();
    sum * 4.0 * PI / (q * q) as f64
}

/// `∫ L(l) max(0, n.l) dl` of `map` by [`sphere_integral`] on 1024^2 points.
pub(crate) fn irradiance_by_quadrature(map: &EnvmapDensity, n: DVec3) -> f64 {
    sphere_integral(1024, |d| map.pdf(d) * map.integral() * n.dot(d).max(0.0))
}

/// The radical inverse of `i` in base `b` (Halton's second coordinate).
fn radical_inverse(mut i: u32, b: u32) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// Checks at each of `normals` that the mean of `L cos / pdf` over `m` samples of
/// `sample(n, u)` (direction and solid-angle pdf) is the irradiance of the
/// quadrature within 4 standard errors, and that `pdf(n, d)` returns the sample's
/// pdf for all but a fraction `stray` of the samples (a pdf constant per cell may
/// differ for a sample on a cell's edge, which the round trip through the
/// direction in `f32` can move across it).
pub(crate) fn assert_unbiased_irradiance(
    map: &EnvmapDensity,
    m: u32,
    stray: f64,
    sample: impl Fn(DVec3, DVec2) -> (DVec3, f64),
    pdf: impl Fn(DVec3, DVec3) -> f64,
) {
    for n in [
        DVec3::Z,
        DVec3::new(0.3, -0.5, 0.2).normalize(),
        DVec3::new(-0.8, 0.1, -0.3).normalize(),
    ] {
        let e = irradiance_by_quadrature(map, n);
        let (mut sum, mut sq, mut moved) = (0.0, 0.0, 0);
        for i in 0..m {
            let u = DVec2::new((i as f64 + 0.5) / m as f64, radical_inverse(i, 3));
            let (d, p) = sample(n, u);
            if (pdf(n, d) - p).abs() > 1e-3 * p {
                moved += 1;
            }
            let v = map.pdf(d) * map.integral() * n.dot(d).max(0.0) / p;
            sum += v;
            sq += v * v;
        }
        assert!(
            moved as f64 <= stray * m as f64,
            "{moved} of {m} samples disagree with pdf"
        );
        let estimate = sum / m as f64;
        // The error of independent samples (stratified ones do better).
        let se = ((sq / m as f64 - estimate * estimate) / m as f64).sqrt();
        assert!(
            (estimate - e).abs() < 4.0 * se,
            "n {n}: {estimate} vs {e} (se {se})"
        );
    }
}

/// A grey map of `size = [width, height]` pixels, pixel `(x, y)` of value
/// `value(x, y)`, written as PNG to `dir/name` (`dir` created if missing): the
/// map file of a test.
pub(crate) fn grey_map(
    dir: &Path,
    name: &str,
    size: [u32; 2],
    value: impl Fn(u32, u32) -> u8,
) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(name);
    image::RgbImage::from_fn(size[0], size[1], |x, y| image::Rgb([value(x, y); 3]))
        .save(&path)
        .unwrap();
    path
}
