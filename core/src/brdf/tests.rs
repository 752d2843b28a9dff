extern crate std;
use super::*;
use core::f64::consts::{FRAC_PI_2, PI};
use std::vec::Vec;

// The test's own quadrature, independent of the build tool's (which integrates
// over half-vectors with Gauss–Legendre): adaptive Gauss–Kronrod 7/15 over the
// light direction in spherical coordinates, split at the mirror direction.

/// Kronrod nodes on `[-1, 1]` (non-negative half) and their 15-point weights,
/// QUADPACK `qk15`.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// 7-point Gauss weights at `XGK[1], XGK[3], XGK[5], XGK[7]`.
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// `(K15, G7, ∫|f|)` estimates on `[a, b]`.
fn gk15(f: &mut dyn FnMut(f64) -> f64, a: f64, b: f64) -> (f64, f64, f64) {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let (mut k, mut g, mut abs) = (0.0, 0.0, 0.0);
    for j in 0..8 {
        let x = XGK[j] * h;
        let (s, sa) = if j == 7 {
            let y = f(c);
            (y, y.abs())
        } else {
            let (y0, y1) = (f(c - x), f(c + x));
            (y0 + y1, y0.abs() + y1.abs())
        };
        k += WGK[j] * s;
        abs += WGK[j] * sa;
        if j % 2 == 1 {
            g += WG[j / 2] * s;
        }
    }
    (k * h, g * h, abs * h)
}

/// `∫_a^b f` to about `tol` absolute, by bisection until `|K15 - G7|` is below
/// the interval's share of `tol` or below `1e-9 ∫|f|`. The second bound is the
/// noise level of the integrand: at the peak, `D` divides by
/// `(n.h)^2 (alpha^2 - 1) + 1 ~ alpha^2`, computed from `(n.h)^2 ~ 1`, so its
/// relative rounding error is `1e-16 / alpha^2` (up to `1e-10` here), and a
/// tolerance below the noise would bisect forever.
fn adaptive(f: &mut dyn FnMut(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32) -> f64 {
    let (k, g, abs) = gk15(f, a, b);
    if (k - g).abs() <= tol.max(1e-9 * abs) || depth == 0 {
        return k;
    }
    let m = 0.5 * (a + b);
    adaptive(f, a, m, 0.5 * tol, depth - 1) + adaptive(f, m, b, 0.5 * tol, depth - 1)
}

/// `∫_a^b f` over the pieces between consecutive `breaks` (sorted, from `a` to
/// `b`).
fn piecewise(f: &mut dyn FnMut(f64) -> f64, breaks: &[f64], tol: f64) -> f64 {
    let pieces = (breaks.len() - 1) as f64;
    breaks
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| adaptive(f, w[0], w[1], tol / pieces, 40))
        .sum()
}

/// `∫ g(l) dl` over the upper hemisphere for a `g` even in `l.y` (true for every
/// BRDF with the view in the xz-plane):
/// `2 ∫_0^{pi/2} sin(theta) ∫_0^pi g(theta, phi) dphi dtheta`, split in `theta`
/// at `peak_theta` (the mirror direction's polar angle, where the specular lobe
/// sits at `phi = pi`).
fn hemisphere_integral(peak_theta: f64, g: &dyn Fn(DVec3) -> f64) -> f64 {
    let mut outer = |theta: f64| {
        let (s, c) = (theta.sin(), theta.cos());
        let mut inner = |phi: f64| g(DVec3::new(s * phi.cos(), s * phi.sin(), c));
        s * piecewise(&mut inner, &[0.0, FRAC_PI_2, PI], 1e-11)
    };
    2.0 * piecewise(&mut outer, &[0.0, peak_theta, FRAC_PI_2], 1e-10)
}

/// `(diffuse, specular)` directional albedo of the glTF model at a condition.
fn albedo(roughness: f64, theta_o_deg: f64) -> (f64, f64) {
    let v = view_direction(theta_o_deg);
    let t = theta_o_deg.to_radians();
    let part = |spec: bool| {
        hemisphere_integral(t, &|l: DVec3| {
            let p = gltf_parts(v.to_array(), l.to_array(), roughness);
            (if spec { p.specular } else { p.diffuse }) * l.z
        })
    };
    (part(false), part(true))
}

include!("../../tests/data/gltf_albedo_reference.rs");

#[test]
fn gauss_kronrod_rule_is_exact_for_polynomials() {
    // K15 is exact to degree 22, G7 to degree 13.
    let (k, _, _) = gk15(&mut |x| x.powi(22), 0.0, 1.0);
    assert!((k - 1.0 / 23.0).abs() < 1e-15, "{k}");
    let (_, g, _) = gk15(&mut |x| x.powi(13), 0.0, 1.0);
    assert!((g - 1.0 / 14.0).abs() < 1e-15, "{g}");
    let (k, g, _) = gk15(&mut |x| x.powi(14), -1.0, 1.0);
    assert!((k - 2.0 / 15.0).abs() < 1e-15 && (g - 2.0 / 15.0).abs() > 1e-6);
}

#[test]
fn lambert_integrates_to_one() {
    for t in [0.0, 0.7, 1.4] {
        let s = hemisphere_integral(t, &|l: DVec3| l.z / PI);
        assert!((s - 1.0).abs() < 1e-12, "{s}");
    }
}

#[test]
fn ggx_d_is_normalized_over_projected_half_vectors() {
    // ∫ D(n.h) (n.h) dh = 1, from the narrowest lobe of the range (alpha 0.01) to
    // the widest.
    for r in [0.1, 0.2, 0.5, 1.0] {
        let a = alpha(r);
        let s = hemisphere_integral(0.0, &|h: DVec3| ggx_d(h.z, a) * h.z);
        assert!((s - 1.0).abs() < 1e-10, "r={r}: {s}");
    }
}

#[test]
fn directional_albedo_matches_reference_table() {
    for (i, r) in REFERENCE_ROUGHNESSES.iter().enumerate() {
        for (j, t) in REFERENCE_THETAS.iter().enumerate() {
            let (d, s) = albedo(*r, *t);
            let want = REFERENCE_ALBEDO[i][j];
            assert!(
                (d + s - want).abs() < 1e-5,
                "r={r} t={t}: {} vs {want}",
                d + s
            );
            // The diffuse part does not depend on roughness.
            let wd = REFERENCE_DIFFUSE[j];
            assert!((d - wd).abs() < 1e-5, "r={r} t={t}: diffuse {d} vs {wd}");
            if i == 0 {
                let ws = REFERENCE_SPECULAR_R01[j];
                assert!((s - ws).abs() < 1e-5, "t={t}: specular {s} vs {ws}");
            }
        }
    }
}

#[test]
fn smooth_surface_specular_albedo_at_normal_incidence_is_f0() {
    // As alpha -> 0, D tends to a delta at h = n, where F = F0 and G2 = 1, so
    // ∫ F D Vis (n.l) dl -> F0. Below the condition range, through the unclamped
    // evaluation.
    let v = [0.0, 0.0, 1.0];
    for (a, tol) in [(1e-3, 1e-7), (1e-2, 1e-5)] {
        let s = hemisphere_integral(0.0, &|l: DVec3| match pair_cosines(v, l.to_array()) {
            Some(c) => gltf_parts_of(c, a).specular * l.z,
            None => 0.0,
        });
        assert!((s - F0).abs() < tol, "alpha={a}: {s}");
    }
}

#[test]
fn normal_incidence_closed_form() {
    // wo = wi = n: h = n, F = F0, D = 1 / (pi alpha^2), Vis = 0.5 / 2.
    for r in [0.1, 0.3, 0.5, 0.8, 1.0] {
        let a = r * r;
        let want = (1.0 - F0) / PI + F0 / (4.0 * PI * a * a);
        let got = brdf(DVec3::Z, DVec3::Z, r);
        assert!((got - want).abs() < 1e-12 * want, "r={r}: {got} vs {want}");
    }
}

/// `(diffuse, specular)` directional albedo of the glTF model with metallic `m`
/// at a condition.
fn albedo_metallic(roughness: f64, theta_o_deg: f64, m: f64) -> (f64, f64) {
    let v = view_direction(theta_o_deg);
    let t = theta_o_deg.to_radians();
    let part = |spec: bool| {
        hemisphere_integral(t, &|l: DVec3| {
            let p = gltf_metallic_parts(v.to_array(), l.to_array(), roughness, m);
            (if spec { p.specular } else { p.diffuse }) * l.z
        })
    };
    (part(false), part(true))
}

/// A small deterministic generator (SplitMix64) for the bit-equality sweeps.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A unit vector on the upper hemisphere, uniform in `z` (a few in a hundred
    /// below the horizon or not unit, to cover the domain's edges).
    fn direction(&mut self) -> [f64; 3] {
        let z = self.unit();
        let phi = 2.0 * PI * self.unit();
        let s = (1.0 - z * z).sqrt();
        let d = [s * phi.cos(), s * phi.sin(), z];
        match self.next() % 100 {
            0 => [d[0], d[1], -d[2]],
            1 => [2.0 * d[0], 2.0 * d[1], 2.0 * d[2]],
            _ => d,
        }
    }
}

#[test]
fn both_ends_of_the_metallic_axis_are_the_two_calls_bit_for_bit() {
    let mut rng = SplitMix(0x656e_6473);
    for _ in 0..100_000 {
        let (wo, wi) = (rng.direction(), rng.direction());
        let r = 1.2 * rng.unit() - 0.05;
        let [f0, f1] = gltf_metallic_ends(wo, wi, r);
        assert_eq!(f0.to_bits(), gltf_metallic(wo, wi, r, 0.0).to_bits());
        assert_eq!(f1.to_bits(), gltf_metallic(wo, wi, r, 1.0).to_bits());
        let (wo, wi) = (wo.map(|x| x as f32), wi.map(|x| x as f32));
        let [f0, f1] = gltf_metallic_ends(wo, wi, r as f32);
        assert_eq!(f0.to_bits(), gltf_metallic(wo, wi, r as f32, 0.0).to_bits());
        assert_eq!(f1.to_bits(), gltf_metallic(wo, wi, r as f32, 1.0).to_bits());
    }
}

#[test]
fn metallic_zero_is_the_dielectric_bit_for_bit() {
    let mut rng = SplitMix(0x6d65_7461_6c6c_6963);
    let mut counted = 0usize;
    for k in 0..200_000 {
        let (wo, wi) = (rng.direction(), rng.direction());
        // Roughness mostly in range, sometimes outside it.
        let r = 1.2 * rng.unit() - 0.05;
        // Zero of either sign and NaN: all the dielectric.
        let m = [0.0, -0.0, f64::NAN][k % 3];
        let a = gltf_metallic_parts(wo, wi, r, m);
        let b = gltf_parts(wo, wi, r);
        assert_eq!(
            a.diffuse.to_bits(),
            b.diffuse.to_bits(),
            "{wo:?} {wi:?} {r}"
        );
        assert_eq!(
            a.specular.to_bits(),
            b.specular.to_bits(),
            "{wo:?} {wi:?} {r}"
        );
        assert_eq!(
            gltf_metallic(wo, wi, r, m).to_bits(),
            gltf(wo, wi, r).to_bits()
        );
        // And the dielectric is still the formula it was before the metallic
        // model: (1 - F)/pi and (F D) Vis, in that order.
        if let Some([nv, nl, nh, vh]) = pair_cosines(wo, wi) {
            let f = schlick_fresnel(vh);
            let al = alpha(r);
            let d = (1.0 - f) / PI;
            let s = f * ggx_d(nh, al) * smith_vis(nv, nl, al);
            assert_eq!(b.diffuse.to_bits(), d.to_bits());
            assert_eq!(b.specular.to_bits(), s.to_bits());
            counted += 1;
        }
        // The same in f32.
        let wo32 = wo.map(|x| x as f32);
        let wi32 = wi.map(|x| x as f32);
        let a = gltf_metallic_parts(wo32, wi32, r as f32, m as f32);
        let b = gltf_parts(wo32, wi32, r as f32);
        assert_eq!(a.diffuse.to_bits(), b.diffuse.to_bits());
        assert_eq!(a.specular.to_bits(), b.specular.to_bits());
    }
    // Most pairs are valid ones (about 98%), so the formula check is not empty.
    assert!(counted > 190_000, "{counted}");
}

#[test]
fn metallic_closed_forms_and_linearity() {
    // wo = wi = n: F = F0, D = 1 / (pi alpha^2), Vis = 1/4:
    // f = (1 - m)((1 - F0)/pi + F0 / (4 pi alpha^2)) + m / (4 pi alpha^2).
    for r in [0.1, 0.3, 0.5, 0.8, 1.0] {
        for m in [0.0, 0.25, 0.5, 1.0] {
            let a = r * r;
            let lobe = 1.0 / (4.0 * PI * a * a);
            let want = (1.0 - m) * ((1.0 - F0) / PI + F0 * lobe) + m * lobe;
            let got = gltf_metallic([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], r, m);
            assert!((got - want).abs() < 1e-12 * want, "r={r} m={m}: {got}");
        }
    }
    // Linear in m: f_m = (1 - m) f_0 + m f_1, part by part; the metal has no
    // diffuse part.
    let dirs = directions();
    for r in [0.1, 0.4, 1.0] {
        for a in &dirs {
            for b in &dirs {
                let (wo, wi) = (a.to_array(), b.to_array());
                let p0 = gltf_metallic_parts(wo, wi, r, 0.0);
                let p1 = gltf_metallic_parts(wo, wi, r, 1.0);
                assert_eq!(p1.diffuse, 0.0);
                for m in [0.1, 0.5, 0.9] {
                    let p = gltf_metallic_parts(wo, wi, r, m);
                    let d = (1.0 - m) * p0.diffuse;
                    let s = (1.0 - m) * p0.specular + m * p1.specular;
                    assert!((p.diffuse - d).abs() <= 1e-15 * d.max(1.0));
                    assert!((p.specular - s).abs() <= 1e-14 * s.max(1.0), "{s}");
                }
            }
        }
    }
}

#[test]
fn metallic_clamping_and_invalid_inputs() {
    let wo = view_direction(30.0).to_array();
    let wi = DVec3::new(-0.3, 0.2, 0.9).normalize().to_array();
    let at = |m: f64| gltf_metallic(wo, wi, 0.4, m);
    assert_eq!(at(-0.5), at(0.0));
    assert_eq!(at(f64::NAN), at(0.0));
    assert_eq!(at(1.5), at(1.0));
    assert_eq!(at(f64::INFINITY), at(1.0));
    assert_eq!(at(f64::NEG_INFINITY), at(0.0));
    assert_ne!(at(0.5), at(0.6));
    assert_eq!(clamp_metallic(f32::NAN), 0.0f32);
    assert_eq!(clamp_metallic(0.3f32), 0.3f32);
    for m in [0.0, 0.5, 1.0, f64::NAN] {
        // Below the horizon, degenerate or non-finite: 0.
        let below = DVec3::new(1.0, 0.0, -0.1).normalize().to_array();
        assert_eq!(gltf_metallic(wo, below, 0.5, m), 0.0);
        assert_eq!(gltf_metallic([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 0.5, m), 0.0);
        assert_eq!(gltf_metallic(wo, [f64::NAN; 3], 0.5, m), 0.0);
        // Grazing pairs stay finite, at the narrowest lobe too.
        let g = DVec3::new(1.0, 0.0, 1e-12).normalize().to_array();
        let h = DVec3::new(-1.0, 0.0, 1e-12).normalize().to_array();
        for (x, y) in [(g, h), (g, g)] {
            let f = gltf_metallic(x, y, 0.1, m);
            assert!(f.is_finite() && f >= 0.0, "{f}");
            let f = gltf_metallic(x.map(|c| c as f32), y.map(|c| c as f32), 0.1, m as f32);
            assert!(f.is_finite() && f >= 0.0, "{f}");
        }
    }
}

#[test]
fn metallic_reciprocity_and_f32_evaluation() {
    let dirs = directions();
    let mut worst: f64 = 0.0;
    for r in [0.1, 0.3, 1.0] {
        for m in [0.3, 1.0] {
            for a in &dirs {
                for b in &dirs {
                    let (wo, wi) = (a.to_array(), b.to_array());
                    let (x, y) = (gltf_metallic(wo, wi, r, m), gltf_metallic(wi, wo, r, m));
                    assert!((x - y).abs() <= 1e-13 * x.abs().max(1.0), "{x} vs {y}");
                    let (wo, wi) = (a.as_vec3().to_array(), b.as_vec3().to_array());
                    let y = gltf_metallic(wo, wi, r as f32, m as f32);
                    worst = worst.max((f64::from(y) - x).abs() / x);
                }
            }
        }
    }
    // As for the dielectric (`f32_evaluation_follows_f64`).
    assert!(worst < 2e-3, "{worst}");
}

#[test]
fn metallic_albedo_is_linear_and_the_metal_conserves_energy() {
    // The test's own quadrature, independent of the build tool's. Metal: D Vis
    // alone integrates to at most 1 (single scattering loses energy); the
    // mixture's albedo is (1 - m) A(0) + m A(1), and m = 0 is the reference.
    for (r, t) in [(0.1, 0.0), (0.3, 60.0), (1.0, 85.0)] {
        let (d0, s0) = albedo_metallic(r, t, 0.0);
        let (d1, s1) = albedo_metallic(r, t, 1.0);
        let (dh, sh) = albedo_metallic(r, t, 0.5);
        assert_eq!(d1, 0.0);
        assert!(s1 <= 1.0 && s1 > 0.5, "r={r} t={t}: metal {s1}");
        assert!((dh - 0.5 * d0).abs() < 1e-9, "r={r} t={t}: {dh} vs {d0}");
        assert!((sh - 0.5 * (s0 + s1)).abs() < 1e-9, "r={r} t={t}: {sh}");
        let i = REFERENCE_ROUGHNESSES.iter().position(|&x| x == r).unwrap();
        let j = REFERENCE_THETAS.iter().position(|&x| x == t).unwrap();
        let want = REFERENCE_ALBEDO[i][j];
        assert!((d0 + s0 - want).abs() < 1e-5, "{} vs {want}", d0 + s0);
    }
}

include!("../../tests/data/gltf_metal_albedo_reference.rs");

#[test]
fn metal_albedo_matches_reference_table() {
    let thetas = REFERENCE_THETAS.iter().chain([89.0].iter());
    for (i, r) in REFERENCE_ROUGHNESSES.iter().enumerate() {
        for (j, t) in thetas.clone().enumerate() {
            let want = REFERENCE_METAL_ALBEDO
                .get(i)
                .and_then(|row| row.get(j))
                .copied()
                .unwrap_or(REFERENCE_METAL_ALBEDO_89[i]);
            let (d, s) = albedo_metallic(*r, *t, 1.0);
            assert_eq!(d, 0.0);
            // 9 decimals: rounding 5e-10, the two quadratures agree to 7e-12.
            assert!((s - want).abs() < 1e-9, "r={r} t={t}: {s} vs {want}");
            if *r == 1.0 {
                // alpha = 1: D = 1/pi, Vis = 1 / (2 (n.l + n.v)), so
                // A = ∫_0^1 mu_l / (mu_l + mu) dmu_l = 1 - mu ln(1 + 1/mu).
                let mu = t.to_radians().cos();
                let closed = 1.0 - mu * (1.0 + 1.0 / mu).ln();
                assert!((want - closed).abs() < 1e-9, "t={t}: {want} vs {closed}");
            }
        }
    }
}

#[test]
fn smooth_metal_albedo_at_normal_incidence_is_one() {
    // As alpha -> 0, D Vis (n.l) tends to a delta at the mirror direction with
    // G2 = 1: the metal reflects everything. The shadowing loss vanishes like
    // alpha^2 (measured: 1 - A = 1.001e-6 at alpha 1e-3, 1.014e-4 at 1e-2, the
    // range's narrowest lobe). Below the condition range, through the unclamped
    // evaluation.
    let v = [0.0, 0.0, 1.0];
    for a in [1e-3, 1e-2] {
        let s = hemisphere_integral(0.0, &|l: DVec3| match pair_cosines(v, l.to_array()) {
            Some(c) => gltf_metallic_parts_of(c, a, 1.0).specular * l.z,
            None => 0.0,
        });
        let loss = (1.0 - s) / (a * a);
        assert!(s < 1.0 && (0.95..1.05).contains(&loss), "alpha={a}: {s}");
    }
}

#[test]
fn fresnel_and_visibility_closed_forms() {
    assert!((schlick_fresnel(1.0) - 0.04).abs() < 1e-15);
    assert!((schlick_fresnel(0.0) - 1.0).abs() < 1e-15);
    assert!((schlick_fresnel(-0.5) - (0.04 + 0.96 / 32.0)).abs() < 1e-15);
    // Vis = G2 / (4 (n.l)(n.v)) with G2 = 1 / (1 + Λ(v) + Λ(l)),
    // Λ(w) = (sqrt(1 + alpha^2 tan^2 theta_w) - 1) / 2 (Heitz 2014, eq. 72, 99).
    let lambda = |c: f64, a: f64| (((1.0 + a * a * (1.0 - c * c) / (c * c)).sqrt()) - 1.0) / 2.0;
    for a in [0.01, 0.3, 1.0] {
        for (nv, nl) in [(0.9, 0.2), (0.05, 0.7), (1.0, 1.0), (0.3, 0.3)] {
            let g2 = 1.0 / (1.0 + lambda(nv, a) + lambda(nl, a));
            let want = g2 / (4.0 * nv * nl);
            let got = smith_vis(nv, nl, a);
            assert!((got - want).abs() < 1e-12 * want, "a={a}: {got} vs {want}");
            // G1 = 1 / (1 + Λ).
            let g1 = smith_g1(nv, a);
            assert!((g1 - 1.0 / (1.0 + lambda(nv, a))).abs() < 1e-12);
        }
    }
    assert_eq!(smith_g1(0.0, 0.3), 0.0);
    assert_eq!(smith_vis(0.0, 0.0, 0.3), 0.0);
}

fn directions() -> Vec<DVec3> {
    (0..40)
        .map(|k| {
            let z = (k as f64 + 0.5) / 40.0;
            let phi = k as f64 * 2.399_963;
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), z)
        })
        .collect()
}

#[test]
fn reciprocity() {
    let dirs = directions();
    for r in [0.1, 0.3, 0.6, 1.0] {
        for a in &dirs {
            for b in &dirs {
                for m in [BrdfModel::Gltf, BrdfModel::Burley] {
                    let (x, y) = (m.eval(*a, *b, r), m.eval(*b, *a, r));
                    assert!((x - y).abs() <= 1e-13 * x.abs().max(1.0), "{x} vs {y}");
                }
                let (x, y) = (
                    gltf(a.as_vec3().to_array(), b.as_vec3().to_array(), r as f32),
                    gltf(b.as_vec3().to_array(), a.as_vec3().to_array(), r as f32),
                );
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{x} vs {y}");
            }
        }
    }
}

#[test]
fn f32_evaluation_follows_f64() {
    // The same expression in f32. At the narrowest lobe's peak
    // `(n.h)^2 (alpha^2 - 1) + 1` cancels down to about alpha^2 = 1e-4, so f32
    // keeps about 3 significant digits there (as in any f32 shader).
    let dirs = directions();
    let mut worst: f64 = 0.0;
    for r in [0.1, 0.25, 0.6, 1.0] {
        for a in &dirs {
            for b in &dirs {
                let x = brdf(*a, *b, r);
                let y = gltf(a.as_vec3().to_array(), b.as_vec3().to_array(), r as f32);
                worst = worst.max((f64::from(y) - x).abs() / x);
            }
        }
    }
    assert!(worst < 2e-3, "{worst}");
}

#[test]
fn condition_clamping_and_invalid_inputs() {
    let wo = view_direction(30.0);
    let wi = DVec3::new(-0.3, 0.2, 0.9).normalize();
    assert_eq!(brdf(wo, wi, 0.05), brdf(wo, wi, MIN_ROUGHNESS));
    assert_eq!(brdf(wo, wi, f64::NAN), brdf(wo, wi, MIN_ROUGHNESS));
    assert_eq!(brdf(wo, wi, 3.0), brdf(wo, wi, 1.0));
    assert_ne!(brdf(wo, wi, 0.5), brdf(wo, wi, 0.6));
    assert_eq!(clamp_roughness(f32::NAN), 0.1f32);
    assert_eq!(view_direction(f64::NAN), DVec3::Z);
    assert_eq!(view_direction(-5.0), DVec3::Z);
    assert_eq!(view_direction(95.0), view_direction(MAX_THETA_O_DEG));
    let v = view_direction(60.0);
    assert!((v - DVec3::new(0.75f64.sqrt(), 0.0, 0.5)).length() < 1e-15);
    // Below the horizon, degenerate or non-finite: 0.
    for m in [BrdfModel::Gltf, BrdfModel::Burley] {
        assert_eq!(m.eval(wo, DVec3::new(1.0, 0.0, -0.1).normalize(), 0.5), 0.0);
        assert_eq!(m.eval(DVec3::new(0.0, 1.0, 0.0), DVec3::Z, 0.5), 0.0);
        assert_eq!(m.eval(wo, DVec3::splat(f64::NAN), 0.5), 0.0);
        assert_eq!(m.eval(wo, DVec3::new(f64::INFINITY, 0.0, 1.0), 0.5), 0.0);
        // Grazing pairs stay finite.
        let g = DVec3::new(1.0, 0.0, 1e-12).normalize();
        let x = m.eval(g, DVec3::new(-1.0, 0.0, 1e-12).normalize(), 0.1);
        assert!(x.is_finite() && x >= 0.0);
    }
}

#[test]
fn burley_closed_forms() {
    // wo = wi = n: both Burley factors are 1, G1 = 1:
    // f = (1 - F0) / pi + F0 / (4 pi alpha^2).
    for r in [0.1, 0.5, 1.0] {
        let a = r * r;
        let want = (1.0 - F0) / PI + F0 / (4.0 * PI * a * a);
        let got = BrdfModel::Burley.eval(DVec3::Z, DVec3::Z, r);
        assert!((got - want).abs() < 1e-12 * want, "r={r}: {got} vs {want}");
    }
    // Grazing retro-reflection: wo = n, wi -> horizon along +x:
    // h.wi = 1/sqrt2, Fd90 = 0.5 + r, f_diff -> Fd90 / pi.
    for r in [0.2, 0.7, 1.0] {
        let f = burley_diffuse(1.0, 0.0, core::f64::consts::FRAC_1_SQRT_2, r);
        assert!((f - (0.5 + r) / PI).abs() < 1e-14, "{f}");
    }
    // Diffuse albedo at normal incidence: (1 - F0)(1 + 5 r / 84 - 1 / 42)
    // (with (h.wi)^2 = (1 + mu)/2 and B(2,6) = 1/42, B(3,6) = 1/168).
    for r in [0.1, 0.5, 1.0] {
        let want = (1.0 - F0) * (1.0 + 5.0 * r / 84.0 - 1.0 / 42.0);
        let got = hemisphere_integral(0.0, &|l: DVec3| burley_parts(DVec3::Z, l, r).diffuse * l.z);
        assert!((got - want).abs() < 1e-10, "r={r}: {got} vs {want}");
    }
}
