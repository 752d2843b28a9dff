extern crate std;

use super::square::{dot, normalized};
use super::*;
use crate::brdf::{gltf_metallic, view_direction_real};
use crate::marginal2d::tabulate_with_masses;
use crate::sphere::{hemisphere_to_square, hemisphere_to_square_real, square_to_hemisphere_real};
use crate::test_rng::Rng;
use std::vec;
use std::vec::Vec;

include!("../../tests/data/gltf_albedo_reference.rs");
include!("../../tests/data/gltf_metal_albedo_reference.rs");

/// The reference tables hold more than the tests below read.
#[test]
fn the_reference_tables_cover_the_range() {
    assert_eq!(REFERENCE_THETAS[5], 85.0);
    assert_eq!(REFERENCE_ROUGHNESSES[0], crate::brdf::MIN_ROUGHNESS);
    // At roughness 0.1 the diffuse and specular parts make the albedo.
    for (j, (d, s)) in REFERENCE_DIFFUSE
        .iter()
        .zip(REFERENCE_SPECULAR_R01)
        .enumerate()
    {
        assert!((d + s - REFERENCE_ALBEDO[0][j]).abs() < 1e-5);
    }
    assert!(REFERENCE_METAL_ALBEDO_89
        .iter()
        .all(|a| (0.0..1.0).contains(a)));
}

/// Tables of `f cos |dwi/dh|` sampled at each vertex of the half-vector square
/// (no supersampling: the tests need a consistent prior, not a good one), with
/// each node's trapezoid mass.
struct Tables {
    info: BrdfPriorInfo,
    data: Vec<f64>,
    marginal: Vec<f64>,
    conditional: Vec<f64>,
    masses: Vec<f64>,
}

impl Tables {
    fn new(grid: [u32; 3], size: u32) -> Self {
        let info = BrdfPriorInfo { grid, size };
        let shape = info.shape().unwrap();
        let s = size as usize;
        let mut data = Vec::new();
        for node in 0..shape.nodes {
            let [r, t, m] = node_condition(grid, node);
            let wo = view_direction_real(t);
            for j in 0..s {
                for i in 0..s {
                    let p = [i as f64 / (s - 1) as f64, j as f64 / (s - 1) as f64];
                    data.push(match node_square(grid, node).direction(wo, p) {
                        Some((wi, jac)) => gltf_metallic(wo, wi, r, m) * wi[2] * jac,
                        None => 0.0,
                    });
                }
            }
        }
        let raw = data.clone();
        let mut marginal = vec![0.0; shape.marginal_len().unwrap()];
        let mut conditional = vec![0.0; shape.data_len().unwrap()];
        let mut masses = vec![0.0; shape.nodes as usize];
        tabulate_with_masses(
            shape,
            &mut data,
            &mut marginal,
            &mut conditional,
            &mut masses,
        )
        .unwrap();
        // Each node's mass is what its table was divided by: raw over
        // normalized at its largest vertex.
        for (k, mass) in masses.iter().enumerate() {
            let block = k * s * s..(k + 1) * s * s;
            let at = block.max_by(|&a, &b| raw[a].total_cmp(&raw[b])).unwrap();
            assert!((raw[at] / data[at] / mass - 1.0).abs() < 1e-12, "node {k}");
        }
        Self {
            info,
            data,
            marginal,
            conditional,
            masses,
        }
    }

    fn prior(&self) -> BrdfPrior<'_, f64> {
        BrdfPrior::new(
            self.info,
            &self.data,
            &self.marginal,
            &self.conditional,
            &self.masses,
        )
        .unwrap()
    }
}

#[test]
fn the_real_hemisphere_inverse_is_the_f64_one() {
    let mut g = Rng(3);
    for _ in 0..10_000 {
        let p = [g.next(), g.next()];
        let d = square_to_hemisphere_real(p);
        let want = hemisphere_to_square(glam::DVec3::from(d));
        let got = hemisphere_to_square_real(d);
        assert!((got[0] - want.x).abs() < 1e-12 && (got[1] - want.y).abs() < 1e-12);
        assert!((got[0] - p[0]).abs() < 1e-9 && (got[1] - p[1]).abs() < 1e-9);
        let d32 = d.map(|c| c as f32);
        let got32 = hemisphere_to_square_real(d32);
        assert!((got32[0] as f64 - p[0]).abs() < 2e-4, "{got32:?} {p:?}");
    }
    assert_eq!(hemisphere_to_square_real([0.0, 0.0, 1.0]), [0.5, 0.5]);
    assert_eq!(hemisphere_to_square_real([f64::NAN; 3]), [0.5, 0.5]);
}

#[test]
fn the_half_vector_maps_invert_each_other_and_mirror_the_view() {
    let mut g = Rng(5);
    let wo = view_direction_real(50.0f64);
    for k in [1.0, stretch(0.1), 0.3] {
        let mut hits = 0;
        for _ in 0..10_000 {
            let p = [g.next(), g.next()];
            let Some((wi, jac)) = half_vector_direction(wo, p, k) else {
                continue;
            };
            hits += 1;
            let s = square_to_hemisphere_real(p);
            let h = normalized([k * s[0], k * s[1], s[2]]).unwrap();
            // wi and wo make equal angles with h, in the plane of both.
            assert!((dot(wi, h) - dot(wo, h)).abs() < 1e-12);
            if k == 1.0 {
                assert!((jac - 4.0 * dot(wo, h)).abs() < 1e-12);
            }
            let (q, back) = half_vector_point(wo, wi, k).unwrap();
            assert!((q[0] - p[0]).abs() < 1e-9 && (q[1] - p[1]).abs() < 1e-9);
            assert!((back - jac).abs() < 1e-9 * jac);
        }
        assert!(hits > 2_500, "{hits}");
        assert!(half_vector_point(wo, [0.0, 0.0, -1.0], k).is_none());
    }
}

/// The Jacobian against the solid angle it claims: the square is `2π`
/// steradians of `h'`, so over uniform square points `2π |dwi/dω_h'| g(wi)`
/// averages `∫ g dwi` over the directions reached, which are the whole upper
/// hemisphere (each `wi` has one half vector); `g = cos`: `π`.
#[test]
fn the_stretched_jacobian_integrates_the_hemisphere() {
    let mut g = Rng(17);
    for (k, theta) in [
        (1.0, 30.0),
        (stretch(0.1), 60.0),
        (0.3, 80.0),
        (stretch(0.5), 5.0),
    ] {
        let wo = view_direction_real(theta);
        let count = 1 << 18;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..count {
            let p = [g.next(), g.next()];
            if let Some((wi, jac)) = half_vector_direction(wo, p, k) {
                let y = 2.0 * core::f64::consts::PI * jac * wi[2];
                sum += y;
                sum2 += y * y;
            }
        }
        let mean = sum / count as f64;
        let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
        let pi = core::f64::consts::PI;
        assert!(
            (mean - pi).abs() < 4.0 * se + 1e-3,
            "k {k}, θo {theta}: {mean} (se {se})"
        );
    }
    assert_eq!(stretch(1.0f64), 1.0);
    assert!((stretch(0.1296f64) - 0.6).abs() < 1e-15 && stretch(f64::NAN) == stretch(0.1));
    assert_eq!(stretch(0.01f64), stretch(0.1));
    assert!((stretch_with(0.3f64, 0.25) - stretch(0.3f64)).abs() < 1e-15);
}

/// The solid angle that `map` sweeps over a step of `10^-6` about the square
/// point `p`, per unit area of the square (central differences).
fn swept_area(map: &dyn Fn([f64; 2]) -> [f64; 3], p: [f64; 2]) -> f64 {
    let h = 1e-6;
    let d = |dx: f64, dy: f64| map([p[0] + dx, p[1] + dy]);
    let du: Vec<f64> = (0..3).map(|a| d(h, 0.0)[a] - d(-h, 0.0)[a]).collect();
    let dv: Vec<f64> = (0..3).map(|a| d(0.0, h)[a] - d(0.0, -h)[a]).collect();
    let c = [
        du[1] * dv[2] - du[2] * dv[1],
        du[2] * dv[0] - du[0] * dv[2],
        du[0] * dv[1] - du[1] * dv[0],
    ];
    dot(c, c).sqrt() / (4.0 * h * h)
}

/// The star disc: the square's centre is the mirror direction, its rim (the
/// unit disc's, the square's edge) the horizon for every view; `star_point`
/// inverts `star_direction` with the same Jacobian; the Jacobian matches the
/// map's own central differences (`|dwi/dp| / |dω_d/dp|`, the square being
/// `2π` steradians of `d` per unit area), and over uniform square points `2π
/// |dwi/dω_d| cos` averages `π`, the cosine's integral over the whole
/// hemisphere (every direction is reached once).
#[test]
fn the_star_disc_centres_the_mirror_and_rims_the_horizon() {
    let pi = core::f64::consts::PI;
    let mut g = Rng(29);
    for (k, theta) in [
        (0.01, 85.0),
        (0.0169, 30.0),
        (0.25, 70.0),
        (1.0, 0.0),
        (0.5, 89.0),
    ] {
        let wo = view_direction_real(theta);
        let (mirror, _) = star_direction(wo, [0.5, 0.5], k).unwrap();
        let expect = [-wo[0], -wo[1], wo[2]];
        assert!(
            (0..3).all(|a| (mirror[a] - expect[a]).abs() < 1e-12),
            "{mirror:?}"
        );
        for t in 0..64 {
            // A point of the square's edge maps onto the unit circle, the rim.
            let v = t as f64 / 64.0;
            let edge = [[v, 0.0], [1.0, v], [1.0 - v, 1.0], [0.0, 1.0 - v]][t % 4];
            let inner = edge.map(|x| 0.5 + (x - 0.5) * (1.0 - 1e-9));
            if let Some((wi, _)) = star_direction(wo, inner, k) {
                assert!(wi[2] < 1e-4, "k {k}, θo {theta}, {edge:?}: {wi:?}");
            }
        }
        let count = 1 << 17;
        let (mut sum, mut sum2, mut hits) = (0.0, 0.0, 0);
        for i in 0..count {
            let p = [g.next(), g.next()];
            let Some((wi, jac)) = star_direction(wo, p, k) else {
                continue;
            };
            hits += 1;
            let y = 2.0 * pi * jac * wi[2];
            sum += y;
            sum2 += y * y;
            let (q, back) = star_point(wo, wi, k).unwrap();
            assert!(
                (q[0] - p[0]).abs() < 1e-7 && (q[1] - p[1]).abs() < 1e-7,
                "{p:?} {q:?}"
            );
            assert!((back - jac).abs() < 1e-7 * jac, "{back} {jac}");
            if i % 64 == 0 && (0.02..0.98).contains(&p[0]) && (0.02..0.98).contains(&p[1]) {
                let light = |q: [f64; 2]| star_direction(wo, q, k).unwrap().0;
                let numeric = swept_area(&light, p) / swept_area(&square_to_hemisphere_real, p);
                assert!((numeric / jac - 1.0).abs() < 1e-3, "{p:?}: {numeric} {jac}");
            }
        }
        assert!(hits > count * 99 / 100, "{hits}");
        let mean = sum / count as f64;
        let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
        assert!(
            (mean - pi).abs() < 4.0 * se + 1e-3,
            "k {k}, θo {theta}: {mean} (se {se})"
        );
        assert!(star_point(wo, [0.0, 0.0, -1.0], k).is_none());
        // f32 agrees with f64.
        let p = [0.3, 0.71];
        let (w64, j64) = star_direction(wo, p, k).unwrap();
        let wo32 = wo.map(|x| x as f32);
        let (w32, j32) = star_direction(wo32, p.map(|x| x as f32), k as f32).unwrap();
        assert!((0..3).all(|a| (w32[a] as f64 - w64[a]).abs() < 1e-4));
        assert!((j32 as f64 / j64 - 1.0).abs() < 1e-3);
    }
    // The reach towards the viewer, away from it and across (module docs).
    let wo = view_direction_real(60.0f64);
    let (s, c) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
    assert!((horizon_reach(wo, [-1.0, 0.0]) - (1.0 - s) / c).abs() < 1e-12);
    assert!((horizon_reach(wo, [1.0, 0.0]) - (1.0 + s) / c).abs() < 1e-12);
    assert!((horizon_reach(wo, [0.0, 1.0]) - 1.0).abs() < 1e-12);
    assert_eq!(metal_zoom(0.5f64), 0.25);
    assert_eq!(metal_zoom(0.0f64), metal_zoom(0.1));
}

/// The radial square (module docs of `square`): `σ(t) = t g(t)` against its
/// closed form `t (k_b t^2 + k_s a^2) / (t^2 + a^2)` at the point's own slope;
/// `k_s = k_b = k` is the stretched square; `radial_point` inverts
/// `radial_direction` with the same Jacobian (in `f64` and `f32`); the
/// Jacobian matches the map's central differences, and over uniform square
/// points `2π |dwi/dω_s| cos` averages `π` (every direction is reached once).
#[test]
fn the_radial_square_inverts_and_its_jacobian_is_the_solid_angle() {
    let pi = core::f64::consts::PI;
    let a = RADIAL_CROSSOVER;
    let mut g = Rng(31);
    for (r, theta) in [
        (0.1, 85.0),
        (0.13, 40.0),
        (0.3, 70.0),
        (1.0, 0.0),
        (0.5, 89.0),
    ] {
        let (ks, kb) = match radial_square(r) {
            PriorSquare::Radial(ks, kb) => (ks, kb),
            other => panic!("{other:?}"),
        };
        assert!((ks - r).abs() < 1e-15 && (kb - stretch(r)).abs() < 1e-15);
        let wo = view_direction_real(theta);
        let (count, mut sum, mut sum2, mut hits) = (1 << 17, 0.0, 0.0, 0);
        for i in 0..count {
            let p = [g.next(), g.next()];
            let Some((wi, jac)) = radial_direction(wo, p, ks, kb) else {
                continue;
            };
            hits += 1;
            let y = 2.0 * pi * jac * wi[2];
            sum += y;
            sum2 += y * y;
            let (q, back) = radial_point(wo, wi, ks, kb).unwrap();
            assert!(
                (q[0] - p[0]).abs() < 1e-7 && (q[1] - p[1]).abs() < 1e-7,
                "{p:?} {q:?}"
            );
            assert!((back - jac).abs() < 1e-7 * jac, "{back} {jac}");
            if i % 256 != 0 {
                continue;
            }
            // The half vector's slope is σ(t) of the table direction's.
            let s = square_to_hemisphere_real(p);
            let t = (s[0] * s[0] + s[1] * s[1]).sqrt() / s[2];
            let sigma = t * (kb * t * t + ks * a * a) / (t * t + a * a);
            let h = normalized([wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]]).unwrap();
            let got = (h[0] * h[0] + h[1] * h[1]).sqrt() / h[2];
            assert!((got - sigma).abs() < 1e-9 * (1.0 + sigma), "{got} {sigma}");
            if (0.02..0.98).contains(&p[0]) && (0.02..0.98).contains(&p[1]) {
                let light = |q: [f64; 2]| radial_direction(wo, q, ks, kb).map_or([0.0; 3], |x| x.0);
                let numeric = swept_area(&light, p) / swept_area(&square_to_hemisphere_real, p);
                assert!((numeric / jac - 1.0).abs() < 1e-3, "{p:?}: {numeric} {jac}");
            }
        }
        assert!(hits > count / 4, "{hits}");
        let mean = sum / count as f64;
        let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
        assert!(
            (mean - pi).abs() < 4.0 * se + 1e-3,
            "roughness {r}, θo {theta}: {mean} (se {se})"
        );
        assert!(radial_point(wo, [0.0, 0.0, -1.0], ks, kb).is_none());
        // f32 agrees with f64, both ways.
        for p in [[0.3, 0.71], [0.5, 0.52], [0.93, 0.4]] {
            let Some((w64, j64)) = radial_direction(wo, p, ks, kb) else {
                continue;
            };
            let wo32 = wo.map(|x| x as f32);
            let (k32, b32) = (ks as f32, kb as f32);
            let (w32, j32) = radial_direction(wo32, p.map(|x| x as f32), k32, b32).unwrap();
            assert!((0..3).all(|c| (w32[c] as f64 - w64[c]).abs() < 1e-4));
            assert!((j32 as f64 / j64 - 1.0).abs() < 1e-3);
            let (q32, back32) = radial_point(wo32, w32, k32, b32).unwrap();
            assert!(
                (0..2).all(|c| (q32[c] as f64 - p[c]).abs() < 1e-3),
                "{q32:?} {p:?}"
            );
            assert!((back32 / j32 - 1.0).abs() < 1e-2, "{back32} {j32}");
        }
    }
    // One stretch everywhere is the stretched square.
    let wo = view_direction_real(50.0f64);
    for p in [[0.5, 0.5], [0.52, 0.47], [0.3, 0.8], [0.9, 0.15]] {
        match (
            radial_direction(wo, p, 0.6, 0.6),
            half_vector_direction(wo, p, 0.6),
        ) {
            (Some((w1, j1)), Some((w2, j2))) => {
                assert!((0..3).all(|c| (w1[c] - w2[c]).abs() < 1e-12));
                assert!((j1 / j2 - 1.0).abs() < 1e-12);
            }
            (None, None) => {}
            other => panic!("{p:?}: {other:?}"),
        }
    }
}

/// Over the prior's own samples, `(1/M) Σ f cos / pdf` is the albedo of the
/// independent reference table at a reference condition (`A_m = (1 - m) A_0 +
/// m A_1`), at metallic 0, 0.5 and 1 between nodes in roughness and `θo`; and
/// `pdf` and `invert` answer for every sample.
///
/// With the metal layer (`G_m = 3`) the same holds, metallic 1 drawing from the
/// metal's own square and just below it from the shared one.
#[test]
fn the_estimate_with_the_priors_pdf_is_the_reference_albedo() {
    for (grid, metallics) in [
        ([4, 5, 2], &[0.0, 0.5, 1.0][..]),
        ([4, 5, 3], &[0.0, 0.999, 1.0]),
    ] {
        estimate_is_the_reference_albedo(grid, metallics);
    }
}

fn estimate_is_the_reference_albedo(grid: [u32; 3], metallics: &[f64]) {
    let tables = Tables::new(grid, 48);
    let prior = tables.prior();
    let mut g = Rng(11);
    for (ri, ti) in [(3, 1), (4, 3), (5, 4)] {
        for &m in metallics {
            let (r, t) = (REFERENCE_ROUGHNESSES[ri], REFERENCE_THETAS[ti]);
            let want = (1.0 - m) * REFERENCE_ALBEDO[ri][ti] + m * REFERENCE_METAL_ALBEDO[ri][ti];
            let cond = [r, t, m];
            let wo = view_direction_real(t);
            let count = 1 << 16;
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..count {
                let u = [g.next(), g.next()];
                let (wi, pdf) = prior.sample(cond, u);
                if pdf == 0.0 {
                    continue;
                }
                let back = prior.pdf(cond, wi);
                assert!((back - pdf).abs() <= 1e-9 * pdf, "{back} {pdf}");
                let v = prior.invert(cond, wi).unwrap();
                assert!((v[0] - u[0]).abs() < 1e-6 && (v[1] - u[1]).abs() < 1e-6);
                let y = gltf_metallic(wo, wi, r, m) * wi[2] / pdf;
                sum += y;
                sum2 += y * y;
            }
            let mean = sum / count as f64;
            let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
            assert!(
                (mean - want).abs() < 4.0 * se + 1e-6,
                "{grid:?} {cond:?}: {mean} vs {want} (se {se})"
            );
        }
    }
}

/// The metal layer: its nodes hold metallic 1 in the metal's star disc
/// (`node_square`), a query at metallic 1 blends its four nodes around
/// `(roughness, θo)` alone in the star disc, a query below metallic 1 the
/// first two layers in the shared square; at a metal-layer node the density is
/// proportional to the metal's `f cos |dwi/dω_p|` in its disc.
#[test]
fn the_metal_layer_serves_metallic_one_alone() {
    let (grid, size) = ([3, 4, 3], 32);
    let layer = 3 * 4;
    assert!(has_metal_layer(grid) && !has_metal_layer([3, 4, 2]));
    for node in 0..3 * layer {
        let [r, t, m] = node_condition(grid, node);
        let two = node_condition([3, 4, 2], node % (2 * layer));
        assert_eq!([r, t], [two[0], two[1]]);
        assert_eq!(m, if node < layer { 0.0 } else { 1.0 });
        let square = match node < 2 * layer {
            true => PriorSquare::Radial(r, stretch(r)),
            false => PriorSquare::Star(r * r),
        };
        assert_eq!(node_square(grid, node), square);
        assert_eq!(is_metal_layer_node(grid, node), node >= 2 * layer);
    }
    let tables = Tables::new(grid, size);
    let prior = tables.prior();
    let (r, t) = (0.37, 41.0);
    let metal = prior.blend([r, t, 1.0]);
    assert_eq!(metal.pairs().count(), 4);
    assert!(metal.pairs().all(|(n, w)| n >= 2 * layer && w > 0.0));
    assert!(prior
        .blend([r, t, 0.999])
        .pairs()
        .all(|(n, _)| n < 2 * layer));
    assert!(prior.blend([r, t, 0.5]).pairs().all(|(n, _)| n < 2 * layer));
    let star = PriorSquare::Star(r * r);
    let shared = PriorSquare::Radial(r, stretch(r));
    assert_eq!(radial_square(r), shared);
    assert_eq!(query_square(grid, [r, t, 1.0]), star);
    assert_eq!(query_square(grid, [r, t, 2.0]), star);
    assert_eq!(query_square(grid, [r, t, 0.999]), shared);
    assert_eq!(query_square([3, 4, 2], [r, t, 1.0]), shared);
    let node = 2 * layer + 1 + 3 * 2;
    let [r, t, _] = node_condition(grid, node);
    let wo = view_direction_real(t);
    let mut ratios = Vec::new();
    for (i, j) in [(16, 16), (18, 16), (21, 17), (17, 13), (19, 19)] {
        let p = [i as f64 / (size - 1) as f64, j as f64 / (size - 1) as f64];
        let Some((wi, jac)) = star_direction(wo, p, metal_zoom(r)) else {
            continue;
        };
        let target = gltf_metallic(wo, wi, r, 1.0) * wi[2] * jac;
        let pdf_square = prior.pdf([r, t, 1.0], wi) * 2.0 * core::f64::consts::PI * jac;
        ratios.push(pdf_square / target);
    }
    assert!(ratios.len() >= 4);
    for q in &ratios {
        assert!((q / ratios[0] - 1.0).abs() < 1e-9, "{ratios:?}");
    }
}

/// Two metallic nodes give every metallic exactly: at a vertex of a node's
/// table the blend's density is proportional to `f_m cos |dwi/dh|`, with
/// `f_m` from the BRDF itself (not from the tables), for any `m`.
#[test]
fn two_metallic_nodes_blend_into_the_target_at_any_metallic() {
    let size = 32;
    let tables = Tables::new([3, 4, 2], size);
    let prior = tables.prior();
    let [r, t, _] = node_condition([3, 4, 2], 1 + 3 * 2);
    let wo = view_direction_real(t);
    for m in [0.3, 0.77] {
        let mut ratios = Vec::new();
        for (i, j) in [(16, 16), (18, 16), (21, 17), (17, 13), (19, 19)] {
            let p = [i as f64 / (size - 1) as f64, j as f64 / (size - 1) as f64];
            let Some((wi, jac)) = radial_square(r).direction(wo, p) else {
                continue;
            };
            let target = gltf_metallic(wo, wi, r, m) * wi[2] * jac;
            let pdf_square = prior.pdf([r, t, m], wi) * 2.0 * core::f64::consts::PI * jac;
            ratios.push(pdf_square / target);
        }
        assert!(ratios.len() >= 4);
        for q in &ratios {
            assert!((q / ratios[0] - 1.0).abs() < 1e-9, "m {m}: {ratios:?}");
        }
    }
}

#[test]
fn bad_tables_are_refused_and_views_check_lengths_only() {
    let tables = Tables::new([2, 2, 2], 4);
    let bad = BrdfPriorInfo {
        grid: [1, 2, 2],
        size: 4,
    };
    let t = &tables;
    assert!(BrdfPrior::new(bad, &t.data, &t.marginal, &t.conditional, &t.masses).is_err());
    let mut masses = t.masses.clone();
    masses[3] = 0.0;
    assert_eq!(
        BrdfPrior::new(t.info, &t.data, &t.marginal, &t.conditional, &masses).unwrap_err(),
        Marginal2DError::NoMass { node: 3 }
    );
    let view = BrdfPrior::view(t.info, &t.data, &t.marginal, &t.conditional, &masses).unwrap();
    // A zero mass cannot make the view panic; the node just drops out.
    let (wi, pdf) = view.sample([0.5, 30.0, 1.0], [0.3, 0.6]);
    assert!(pdf >= 0.0 && wi[2] >= 0.0);
    assert!(BrdfPrior::view(t.info, &t.data, &t.marginal, &t.conditional, &masses[1..]).is_err());
    assert_eq!(
        BrdfPriorInfo {
            grid: [2, 3, 2],
            size: 5
        }
        .nodes(),
        Some(12)
    );
    assert_eq!(
        BrdfPriorInfo {
            grid: [2, 3, 2],
            size: MAX_PRIOR_SIZE + 1
        }
        .nodes(),
        None
    );
    // The metallic axis: metallic 0 and 1, and perhaps the metal layer.
    for (g_m, nodes) in [(1, None), (2, Some(12)), (3, Some(18)), (4, None)] {
        let info = BrdfPriorInfo {
            grid: [2, 3, g_m],
            size: 5,
        };
        assert_eq!(info.nodes(), nodes, "G_m {g_m}");
    }
}

/// The `θo` axis: nodes at `89 (1 - (1 - u)^2)`, crowding towards grazing (the
/// last interval of 12 nodes spans 0.74°, the first 15.4°), and
/// `unit_condition` places each node back at its `u`.
#[test]
fn view_nodes_crowd_towards_grazing_and_unit_condition_inverts_them() {
    let grid = [2, 12, 2];
    for j in 0..12u32 {
        let [_, t, _] = node_condition(grid, 2 * j);
        let u = j as f64 / 11.0;
        assert!((t - 89.0 * (1.0 - (1.0 - u) * (1.0 - u))).abs() < 1e-12);
        let back = unit_condition([0.5, t, 0.0])[1];
        assert!((back - u).abs() < 1e-12, "{j}: {back} vs {u}");
    }
    let span = |j: u32| node_condition(grid, 2 * (j + 1))[1] - node_condition(grid, 2 * j)[1];
    assert!((span(10) - 89.0 / 121.0).abs() < 1e-12);
    assert!((span(0) - 89.0 * 21.0 / 121.0).abs() < 1e-12);
    assert_eq!(unit_condition([0.5, 200.0, 0.0])[1], 1.0);
    assert_eq!(unit_condition([0.5, f64::NAN, 0.0])[1], 0.0);
    assert_eq!(theta_o_of_unit(2.0), 89.0);
}
