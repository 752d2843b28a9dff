//! The directional albedo `A(roughness, theta_o) = ∫ f(v, l) (n.l) dl` of a
//! [`BrdfModel`] by quadrature, and tables of it on a condition grid: the
//! normalizer of `brdf:` targets and the weight of every sample of a condition.
//! [`directional_albedo_metallic`] is the same quadrature for the glTF BRDF with
//! metallic `m` (`nuld_core::brdf::gltf_metallic_parts`), whose albedo is
//! `A(m) = (1 - m) A(0) + m A(1)`.
//!
//! **Half-vector form.** With `l = 2 (v.h) h - v` the light direction is a function
//! of the microfacet normal `h`, and `dl = 4 (v.h) dh`:
//! `A = ∫ f (n.l) 4 (v.h) dh` over the `h` whose `l` lies above the horizon. The
//! specular lobe, whatever its width, sits at `h = n`: in `h` it is just the GGX peak
//! `D(n.h)`, a function of the polar angle `theta_h` alone, so a rule graded towards
//! `theta_h = 0` resolves it at every view angle (in `l` the lobe moves with the view
//! and flattens against the horizon at grazing views).
//!
//! **Region.** With `h = (sin theta_h cos phi, sin theta_h sin phi, cos theta_h)` and
//! `v = (sin theta_o, 0, cos theta_o)`, `l.z > 0` iff `cos phi > K(theta_h)`,
//! `K = cos theta_o (1 - 2 cos^2 theta_h) / (2 sin theta_o sin theta_h cos theta_h)`:
//! every `phi` for `theta_h < (90° - theta_o)/2`, none beyond
//! `theta_h = (90° + theta_o)/2`, `|phi| < acos K` in between. The integrand is even
//! in `phi` (the view lies in the xz-plane), so `phi` runs over `[0, phi_max]` and
//! counts twice.
//!
//! **Rule.** A product of composite Gauss–Legendre rules (8 nodes a panel): in
//! `theta_h`, panels graded geometrically away from 0 (from width `alpha / 8`) and
//! from both region boundaries (from `1e-4`), at most `0.1` rad wide; in `phi`,
//! panels graded geometrically towards `phi_max`, where `l` reaches the horizon and `Vis (n.l)`
//! turns over within `n.l ~ alpha`. About 70k evaluations of `f` a condition (a few
//! ms). Its error is below `1e-10` over the condition range (largest change with
//! twice the nodes per panel: `7e-12`, for either model and for the glTF metal,
//! measured on a 4 x 6 grid that includes the corners roughness 0.1 and 89°); the
//! tests also hold it to published reference albedos, the metal's to the adaptive
//! quadrature of the `nuld_core::brdf` tests (within `7e-12`), to its closed form at
//! roughness 1 (`1 - mu ln(1 + 1/mu)`, within `3e-13`) and, with metallic 0, 1/2 and
//! 1, to a Richardson-extrapolated midpoint grid over light directions (within
//! `2.1e-9`).

use glam::DVec3;
use nuld_core::brdf::{
    alpha, clamp_metallic, clamp_roughness, gltf_metallic_parts, view_direction, BrdfModel,
    BrdfParts,
};
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// Gauss–Legendre nodes per panel.
const NODES: usize = 8;
/// Widest `theta_h` panel, radians: the diffuse and Fresnel factors vary on the scale
/// of 1 rad, so 0.1-rad panels of 8 nodes integrate them to rounding.
const MAX_PANEL: f64 = 0.1;
/// Narrowest `theta_h` panel at a region boundary, radians.
const BOUNDARY_GRADING: f64 = 1e-4;
/// Levels of geometric grading towards `phi_max` (the last panel is
/// `2^-PHI_LEVELS` of the range).
const PHI_LEVELS: u32 = 12;

/// The directional albedo of `model` at a condition, split into the diffuse and the
/// specular layer's share ([`BrdfParts`]; `A` is [`BrdfParts::total`]).
///
/// `roughness` and `theta_o_deg` are clamped into the condition range
/// (`nuld_core::brdf::clamp_roughness`, `view_direction`). Deterministic; costs a
/// few ms.
pub fn directional_albedo(model: BrdfModel, roughness: f64, theta_o_deg: f64) -> BrdfParts<f64> {
    albedo_with(model, roughness, theta_o_deg, &gauss_legendre(NODES))
}

/// The directional albedo of the glTF 2.0 BRDF with metallic `metallic` and base
/// colour 1 (`nuld_core::brdf::gltf_metallic_parts`) at a condition
/// `(roughness, theta_o_deg, metallic)`, split into the diffuse and the specular
/// layer's share, by the quadrature of [`directional_albedo`].
///
/// `roughness` and `theta_o_deg` are clamped into the condition range, `metallic`
/// into `[0, 1]` (`nuld_core::brdf::clamp_metallic`, NaN is the dielectric). At
/// `metallic = 0` the result is `directional_albedo(BrdfModel::Gltf, ..)` bit for
/// bit; the metal (`metallic = 1`) has no diffuse share. Deterministic; costs a few
/// ms.
pub fn directional_albedo_metallic(
    roughness: f64,
    theta_o_deg: f64,
    metallic: f64,
) -> BrdfParts<f64> {
    albedo_metallic_with(roughness, theta_o_deg, metallic, &gauss_legendre(NODES))
}

/// The specular share `p_s = A_spec / A` of the albedo at a condition: the
/// probability with which the renderer's mixture warp
/// ([`nuld_core::warp::brdf_mixture_real`]) picks the GGX lobe.
pub fn lobe_probability(model: BrdfModel, roughness: f64, theta_o_deg: f64) -> f64 {
    let a = directional_albedo(model, roughness, theta_o_deg);
    a.specular / a.total()
}

/// [`directional_albedo`] on a grid: entry `i * theta_o_deg.len() + j` is the
/// albedo `A` at `(roughness[i], theta_o_deg[j])` (row-major, roughness slowest).
/// Computed in parallel; the result does not depend on the thread count.
pub fn albedo_table(model: BrdfModel, roughness: &[f64], theta_o_deg: &[f64]) -> Vec<f64> {
    let rule = gauss_legendre(NODES);
    let cells: Vec<(f64, f64)> = roughness
        .iter()
        .flat_map(|&r| theta_o_deg.iter().map(move |&t| (r, t)))
        .collect();
    cells
        .par_iter()
        .map(|&(r, t)| albedo_with(model, r, t, &rule).total())
        .collect()
}

/// [`directional_albedo`] with the `[0, 1]` rule `rule` on every panel.
fn albedo_with(
    model: BrdfModel,
    roughness: f64,
    theta_o_deg: f64,
    rule: &[(f64, f64)],
) -> BrdfParts<f64> {
    quadrature(roughness, theta_o_deg, rule, |v, l, r| model.parts(v, l, r))
}

/// [`directional_albedo_metallic`] with the `[0, 1]` rule `rule` on every panel.
fn albedo_metallic_with(
    roughness: f64,
    theta_o_deg: f64,
    metallic: f64,
    rule: &[(f64, f64)],
) -> BrdfParts<f64> {
    let m = clamp_metallic(metallic);
    quadrature(roughness, theta_o_deg, rule, |v, l, r| {
        gltf_metallic_parts(v.to_array(), l.to_array(), r, m)
    })
}

/// The quadrature of the module docs of `parts(v, l, roughness)` (a BRDF's
/// [`BrdfParts`] for view `v`, light `l` and the clamped roughness) with the
/// `[0, 1]` rule `rule` on every panel.
fn quadrature(
    roughness: f64,
    theta_o_deg: f64,
    rule: &[(f64, f64)],
    parts: impl Fn(DVec3, DVec3, f64) -> BrdfParts<f64>,
) -> BrdfParts<f64> {
    let r = clamp_roughness(roughness);
    let a = alpha(r);
    let v = view_direction(theta_o_deg);
    let (sv, cv) = (v.x, v.z);
    let t = sv.atan2(cv);
    let full = 0.5 * (FRAC_PI_2 - t);
    let last = 0.5 * (FRAC_PI_2 + t);
    let mut sum = BrdfParts::<f64>::default();
    for [lo, hi] in theta_panels(a, full, last) {
        for &(x, wx) in rule {
            let th = lo + (hi - lo) * x;
            let (s, c) = th.sin_cos();
            let phi_max = if th <= full {
                PI
            } else if sv * s * c > 0.0 {
                (cv * (1.0 - 2.0 * c * c) / (2.0 * sv * s * c))
                    .clamp(-1.0, 1.0)
                    .acos()
            } else {
                0.0
            };
            let mut row = BrdfParts::<f64>::default();
            for [plo, phi] in graded_towards_end(phi_max, PHI_LEVELS) {
                for &(y, wy) in rule {
                    let p = plo + (phi - plo) * y;
                    let h = DVec3::new(s * p.cos(), s * p.sin(), c);
                    let v_dot_h = v.dot(h);
                    let l = 2.0 * v_dot_h * h - v;
                    let f = parts(v, l, r);
                    let w = wy * (phi - plo) * l.z.max(0.0) * 4.0 * v_dot_h;
                    row.diffuse += w * f.diffuse;
                    row.specular += w * f.specular;
                }
            }
            let w = wx * (hi - lo) * s * 2.0;
            sum.diffuse += w * row.diffuse;
            sum.specular += w * row.specular;
        }
    }
    sum
}

/// Panels of `[0, last]` in `theta_h`: geometric (ratio 2) away from 0 (from
/// `alpha / 8`) and from both sides of `full` and `last` (from [`BOUNDARY_GRADING`]),
/// none wider than [`MAX_PANEL`].
fn theta_panels(alpha: f64, full: f64, last: f64) -> Vec<[f64; 2]> {
    let mut cuts = vec![0.0, full, last];
    // The GGX peak at 0 has width alpha; at the region boundaries the inner range
    // starts or stops shrinking (`phi_max ~ sqrt` of the distance), a singularity
    // of every width, graded down to BOUNDARY_GRADING.
    for (p, d0) in [
        (0.0, alpha / 8.0),
        (full, BOUNDARY_GRADING),
        (last, BOUNDARY_GRADING),
    ] {
        let mut d = d0;
        while d < 1.0 {
            cuts.extend([p - d, p + d]);
            d *= 2.0;
        }
    }
    let uniform = (last / MAX_PANEL).ceil() as usize;
    cuts.extend((1..uniform).map(|k| k as f64 * last / uniform as f64));
    cuts.retain(|&x| (0.0..=last).contains(&x));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let mut panels: Vec<[f64; 2]> = Vec::new();
    for w in cuts.windows(2) {
        // Split panels the grading left wider than MAX_PANEL.
        let k = ((w[1] - w[0]) / MAX_PANEL).ceil().max(1.0) as usize;
        for i in 0..k {
            let a = w[0] + (w[1] - w[0]) * i as f64 / k as f64;
            let b = w[0] + (w[1] - w[0]) * (i + 1) as f64 / k as f64;
            panels.push([a, b]);
        }
    }
    panels
}

/// Panels of `[0, end]` halving towards `end`: `[0, end/2], [end/2, 3 end/4], ...`,
/// `levels` of them and a last one reaching `end` (none if `end <= 0`).
fn graded_towards_end(end: f64, levels: u32) -> impl Iterator<Item = [f64; 2]> {
    let n = if end > 0.0 { levels + 1 } else { 0 };
    (0..n).map(move |k| {
        let a = end * (1.0 - 0.5f64.powi(k as i32));
        let b = if k == levels {
            end
        } else {
            end * (1.0 - 0.5f64.powi(k as i32 + 1))
        };
        [a, b]
    })
}

/// Gauss–Legendre nodes and weights on `[0, 1]` with `n` nodes: roots of the
/// Legendre polynomial `P_n` by Newton's method from Tricomi's initial guesses,
/// weights `2 / ((1 - x^2) P_n'(x)^2)` (halved for `[0, 1]`).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((0.5 * (1.0 - x), 0.5 * w));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    include!("../../../core/tests/data/gltf_albedo_reference.rs");
    include!("../../../core/tests/data/gltf_metal_albedo_reference.rs");

    /// The test's own quadrature of the metallic albedo, independent of the
    /// module's: a midpoint rule on an `n x 2n` grid of light directions in
    /// `(theta_l, phi_l)` over `[0, pi/2] x [0, pi]` (the integrand is even in
    /// `phi_l`), of `f (n.l) sin(theta_l)`.
    fn midpoint_grid(r: f64, t: f64, m: f64, n: usize) -> BrdfParts<f64> {
        let v = view_direction(t).to_array();
        let (ht, hp) = (FRAC_PI_2 / n as f64, PI / (2 * n) as f64);
        let mut acc = BrdfParts::<f64>::default();
        for i in 0..n {
            let (s, c) = ((i as f64 + 0.5) * ht).sin_cos();
            let mut row = BrdfParts::<f64>::default();
            for j in 0..2 * n {
                let p = (j as f64 + 0.5) * hp;
                let f = gltf_metallic_parts(v, [s * p.cos(), s * p.sin(), c], r, m);
                row.diffuse += f.diffuse;
                row.specular += f.specular;
            }
            acc.diffuse += row.diffuse * c * s;
            acc.specular += row.specular * c * s;
        }
        let w = 2.0 * ht * hp;
        BrdfParts {
            diffuse: acc.diffuse * w,
            specular: acc.specular * w,
        }
    }

    /// [`midpoint_grid`] at `n = 1000` and `2000`, Richardson-extrapolated: the
    /// rule's error is `c h^2` (it shrinks 4x from one to the other wherever the
    /// grid resolves the lobe), so `(4 A(2000) - A(1000)) / 3` removes it.
    fn midpoint_extrapolated(r: f64, t: f64, m: f64) -> BrdfParts<f64> {
        let (a, b) = (midpoint_grid(r, t, m, 1000), midpoint_grid(r, t, m, 2000));
        BrdfParts {
            diffuse: (4.0 * b.diffuse - a.diffuse) / 3.0,
            specular: (4.0 * b.specular - a.specular) / 3.0,
        }
    }

    #[test]
    fn metallic_albedo_matches_an_independent_midpoint_grid() {
        // Conditions the grid resolves (the lobe at least a few cells wide and not
        // squeezed against the horizon: roughness 0.1 at any view and 0.2 at 89°
        // would need a finer grid; the reference table covers them).
        let conditions = [
            (0.2, 0.0),
            (0.2, 60.0),
            (0.2, 85.0),
            (0.3, 30.0),
            (0.3, 75.0),
            (0.5, 0.0),
            (0.5, 45.0),
            (0.5, 89.0),
            (1.0, 0.0),
            (1.0, 60.0),
            (1.0, 89.0),
        ];
        let rows: Vec<_> = conditions
            .par_iter()
            .flat_map(|&(r, t)| {
                [0.0, 0.5, 1.0].into_par_iter().map(move |m| {
                    let want = midpoint_extrapolated(r, t, m);
                    let got = directional_albedo_metallic(r, t, m);
                    (r, t, m, got, want)
                })
            })
            .collect();
        let mut worst: f64 = 0.0;
        for (r, t, m, got, want) in rows {
            let err = (got.diffuse - want.diffuse)
                .abs()
                .max((got.specular - want.specular).abs());
            worst = worst.max(err);
            assert!(err < 2e-8, "r={r} t={t} m={m}: {got:?} vs {want:?}");
        }
        eprintln!("largest difference from the midpoint grid: {worst:.1e}");
    }

    #[test]
    fn metallic_zero_is_the_dielectric_albedo() {
        for (i, r) in REFERENCE_ROUGHNESSES.iter().enumerate() {
            for (j, t) in REFERENCE_THETAS.iter().enumerate() {
                let p = directional_albedo_metallic(*r, *t, 0.0);
                // Bit for bit: the same rule over the same values of f.
                assert_eq!(p, directional_albedo(BrdfModel::Gltf, *r, *t));
                assert_eq!(p, directional_albedo_metallic(*r, *t, f64::NAN));
                assert_eq!(p, directional_albedo_metallic(*r, *t, -1.0));
                let want = REFERENCE_ALBEDO[i][j];
                assert!((p.total() - want).abs() < 1e-5, "r={r} t={t}: {p:?}");
                assert!((p.diffuse - REFERENCE_DIFFUSE[j]).abs() < 1e-5);
                if i == 0 {
                    assert!((p.specular - REFERENCE_SPECULAR_R01[j]).abs() < 1e-5);
                }
            }
        }
    }

    #[test]
    fn metal_albedo_matches_reference_values() {
        for (i, r) in REFERENCE_ROUGHNESSES.iter().enumerate() {
            let row = REFERENCE_METAL_ALBEDO[i].iter().zip(REFERENCE_THETAS);
            for (want, t) in row.chain([(&REFERENCE_METAL_ALBEDO_89[i], 89.0)]) {
                let p = directional_albedo_metallic(*r, t, 1.0);
                assert_eq!(p.diffuse, 0.0);
                assert_eq!(p, directional_albedo_metallic(*r, t, 2.0));
                // 9 decimals: rounding 5e-10, the two quadratures agree to 7e-12.
                assert!((p.specular - want).abs() < 1e-9, "r={r} t={t}: {p:?}");
            }
        }
    }

    #[test]
    fn metallic_albedo_is_linear_in_metallic() {
        // A(m) = (1 - m) A(0) + m A(1), part by part, to rounding (measured: 2e-15).
        for r in [0.1, 0.3, 1.0] {
            for t in [0.0, 45.0, 85.0, 89.0] {
                let a0 = directional_albedo_metallic(r, t, 0.0);
                let a1 = directional_albedo_metallic(r, t, 1.0);
                for m in [0.25, 0.5, 0.75] {
                    let a = directional_albedo_metallic(r, t, m);
                    let d = (1.0 - m) * a0.diffuse;
                    let s = (1.0 - m) * a0.specular + m * a1.specular;
                    assert!((a.diffuse - d).abs() < 1e-14, "r={r} t={t} m={m}");
                    assert!((a.specular - s).abs() < 1e-14, "r={r} t={t} m={m}");
                }
            }
        }
    }

    #[test]
    fn metal_albedo_closed_form_at_roughness_one() {
        // alpha = 1: D = 1/pi and Vis = 1 / (2 (n.l + n.v)), so
        // A = ∫_0^1 mu_l / (mu_l + mu) dmu_l = 1 - mu ln(1 + 1/mu), mu = cos theta_o:
        // 1 - ln 2 at normal incidence, rising towards 1 at grazing views. Measured
        // within 3e-13 (at 89°).
        for t in [0.0f64, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0] {
            let mu = t.to_radians().cos();
            let want = 1.0 - mu * (1.0 + 1.0 / mu).ln();
            let got = directional_albedo_metallic(1.0, t, 1.0).total();
            assert!((got - want).abs() < 1e-12, "t={t}: {got} vs {want}");
        }
    }

    #[test]
    fn smooth_metal_albedo_at_normal_incidence_approaches_one() {
        // F = 1 and a narrow lobe: the metal reflects all but the shadowing loss,
        // about alpha^2 at normal incidence (measured 1 - A = 9.33e-3, 1.70e-3,
        // 1.014e-4 at roughness 0.3, 0.2, 0.1; the range ends at 0.1, alpha 0.01).
        let loss = |r: f64| 1.0 - directional_albedo_metallic(r, 0.0, 1.0).total();
        assert!(loss(0.3) > loss(0.2) && loss(0.2) > loss(0.1));
        let l = loss(0.1);
        assert!(l > 0.0 && (l - 1.0144e-4).abs() < 1e-7, "1 - A = {l:.4e}");
    }

    #[test]
    fn metal_albedo_at_grazing_views() {
        // The metal conserves energy at every condition (unlike the dielectric's
        // fresnel_mix, 1.57 at roughness 0.1 and 85°). At grazing views a narrow
        // lobe is shadowed (0.9048 at roughness 0.1 and 89°, 0.9999 at 0°), a wide
        // one recovers (roughness 1: 0.307 at 0°, 0.929 at 89°).
        for r in [0.1, 0.2, 0.3, 0.5, 0.7, 1.0] {
            for t in [0.0, 30.0, 60.0, 75.0, 80.0, 85.0, 87.0, 89.0] {
                let a = directional_albedo_metallic(r, t, 1.0).total();
                assert!(a > 0.3 && a < 1.0, "r={r} t={t}: {a}");
            }
        }
        let at = |r: f64, t: f64| directional_albedo_metallic(r, t, 1.0).total();
        assert!(at(0.1, 89.0) < at(0.1, 85.0) && at(0.1, 85.0) < at(0.1, 0.0));
        assert!((at(0.1, 89.0) - 0.904837840).abs() < 1e-9);
        assert!(at(1.0, 89.0) > at(1.0, 85.0) && at(1.0, 85.0) > at(1.0, 0.0));
        // The mixture at m = 0.5 sits halfway between the dielectric's excess and
        // the metal's loss.
        let half = directional_albedo_metallic(0.1, 85.0, 0.5).total();
        assert!((half - 1.282194417).abs() < 1e-8, "{half}");
    }

    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        let rule = gauss_legendre(NODES);
        let wsum: f64 = rule.iter().map(|p| p.1).sum();
        assert!((wsum - 1.0).abs() < 1e-15);
        for k in 0..2 * NODES as i32 {
            let s: f64 = rule.iter().map(|&(x, w)| w * x.powi(k)).sum();
            assert!((s - 1.0 / (k + 1) as f64).abs() < 1e-15, "x^{k}: {s}");
        }
    }

    #[test]
    fn albedo_matches_reference_values() {
        let table = albedo_table(BrdfModel::Gltf, &REFERENCE_ROUGHNESSES, &REFERENCE_THETAS);
        for (i, r) in REFERENCE_ROUGHNESSES.iter().enumerate() {
            for (j, t) in REFERENCE_THETAS.iter().enumerate() {
                let p = directional_albedo(BrdfModel::Gltf, *r, *t);
                let want = REFERENCE_ALBEDO[i][j];
                assert!(
                    (p.total() - want).abs() < 1e-5,
                    "r={r} t={t}: {p:?} vs {want}"
                );
                assert_eq!(table[i * REFERENCE_THETAS.len() + j], p.total());
                let wd = REFERENCE_DIFFUSE[j];
                assert!((p.diffuse - wd).abs() < 1e-5, "r={r} t={t}: {p:?} vs {wd}");
                if i == 0 {
                    let ws = REFERENCE_SPECULAR_R01[j];
                    assert!((p.specular - ws).abs() < 1e-5, "t={t}: {p:?} vs {ws}");
                }
            }
        }
    }

    #[test]
    fn rule_is_converged_over_the_condition_range() {
        // Against the same panels with twice the nodes: the measured error bound of
        // the module docs, at the range's corners and inside.
        let fine = gauss_legendre(2 * NODES);
        let coarse = gauss_legendre(NODES);
        let mut worst: f64 = 0.0;
        for model in [BrdfModel::Gltf, BrdfModel::Burley] {
            for r in [0.1, 0.13, 0.4, 1.0] {
                for t in [0.0, 10.0, 44.0, 70.0, 85.0, 89.0] {
                    let a = albedo_with(model, r, t, &coarse).total();
                    let b = albedo_with(model, r, t, &fine).total();
                    worst = worst.max((a - b).abs());
                    assert!((a - b).abs() < 1e-10, "{model:?} r={r} t={t}: {a} vs {b}");
                }
            }
        }
        // The metal (`metallic = 1`, the whole weight on the lobe).
        for r in [0.1, 0.13, 0.4, 1.0] {
            for t in [0.0, 10.0, 44.0, 70.0, 85.0, 89.0] {
                let a = albedo_metallic_with(r, t, 1.0, &coarse).total();
                let b = albedo_metallic_with(r, t, 1.0, &fine).total();
                worst = worst.max((a - b).abs());
                assert!((a - b).abs() < 1e-10, "metal r={r} t={t}: {a} vs {b}");
            }
        }
        eprintln!("largest change with twice the nodes: {worst:.1e}");
    }

    #[test]
    fn diffuse_albedo_at_normal_incidence_closed_form() {
        // v = n: v.h = sqrt((1 + mu)/2) with mu = n.l, so the diffuse albedo is
        // 0.96 - 0.96 J, J = 2 ∫_0^1 (1 - sqrt((1 + mu)/2))^5 mu dmu; with
        // s = sqrt((1 + mu)/2), J = 8 ∫_{1/sqrt2}^1 (1 - s)^5 (2 s^3 - s) ds, a
        // polynomial integral (composite Simpson, error ~h^4 ~ 1e-19).
        let s0 = std::f64::consts::FRAC_1_SQRT_2;
        let n = 20_000;
        let g = |s: f64| (1.0 - s).powi(5) * (2.0 * s * s * s - s);
        let h = (1.0 - s0) / n as f64;
        let mut acc = g(s0) + g(1.0);
        for k in 1..n {
            acc += g(s0 + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        let want = 0.96 - 0.96 * 8.0 * acc * h / 3.0;
        let got = directional_albedo(BrdfModel::Gltf, 0.5, 0.0).diffuse;
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}
