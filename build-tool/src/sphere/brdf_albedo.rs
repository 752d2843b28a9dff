//! The directional albedo `A(roughness, theta_o) = ∫ f(v, l) (n.l) dl` of a
//! [`BrdfModel`] by quadrature, and tables of it on a condition grid: the
//! normalizer of `brdf:` targets and the weight of every sample of a condition.
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
//! twice the nodes per panel: `7e-12`, for either model, measured on a 4 x 6 grid
//! that includes the corners roughness 0.1 and 89°); the tests also hold it to
//! published reference albedos.

use glam::DVec3;
use nuld_core::brdf::{alpha, clamp_roughness, view_direction, BrdfModel, BrdfParts};
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

/// The quadrature of the module docs with the `[0, 1]` rule `rule` on every panel.
fn albedo_with(
    model: BrdfModel,
    roughness: f64,
    theta_o_deg: f64,
    rule: &[(f64, f64)],
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
                    let f = model.parts(v, l, r);
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
