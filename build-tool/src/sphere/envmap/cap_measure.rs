//! The cap measure of an equirectangular map: exact in `phi`, Gauss–Legendre
//! quadrature in `z` over the band where the rim crosses the rows, graded toward
//! the band ends and adaptive across bright pixels (the method and its measured
//! errors: the parent module's docs).

use super::{EnvmapDensity, ADAPTIVE_DEPTH, ADAPTIVE_TOL, END_GRADING, GL4, PSI_PIECE};
use crate::sphere::geometry::unit_or_z;
use glam::DVec3;
use nuld_core::blob::Domain;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// `∫_a^b f` by 4-point Gauss–Legendre.
fn gl4(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let h = b - a;
    GL4.iter().map(|(x, w)| w * h * f(a + h * x)).sum()
}

/// `∫_a^b f` by [`gl4`] on halves until two successive levels agree to `tol`
/// (at most `depth` halvings): resolves the kinks where an arc end crosses the
/// column edge of a pixel much brighter than its neighbours.
fn gl4_adaptive(f: &impl Fn(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32) -> f64 {
    let m = 0.5 * (a + b);
    let whole = gl4(f, a, b);
    let halves = gl4(f, a, m) + gl4(f, m, b);
    if depth == 0 || (whole - halves).abs() <= tol {
        halves
    } else {
        gl4_adaptive(f, a, m, 0.5 * tol, depth - 1) + gl4_adaptive(f, m, b, 0.5 * tol, depth - 1)
    }
}

/// `∫_a^b` of what `piece` integrates, graded geometrically toward the ends that
/// are flagged (halves, quarters, ... of the piece).
fn graded(piece: &impl Fn(f64, f64) -> f64, a: f64, b: f64, at_a: bool, at_b: bool) -> f64 {
    match (at_a, at_b) {
        (false, false) => piece(a, b),
        (true, true) => {
            let m = 0.5 * (a + b);
            graded(piece, a, m, true, false) + graded(piece, m, b, false, true)
        }
        (true, false) => {
            let mut len = b - a;
            let mut s = 0.0;
            for _ in 0..END_GRADING {
                len *= 0.5;
                s += piece(a + len, a + 2.0 * len);
            }
            s + piece(a, a + len)
        }
        (false, true) => {
            let mut len = b - a;
            let mut s = 0.0;
            for _ in 0..END_GRADING {
                len *= 0.5;
                s += piece(b - 2.0 * len, b - len);
            }
            s + piece(b - len, b)
        }
    }
}

impl EnvmapDensity {
    pub(super) fn row_mass(&self, r: usize) -> f64 {
        self.row_cdf[r + 1] - self.row_cdf[r]
    }

    /// Cumulative mass of row `r` over `[0, phi)`, extended periodically
    /// (`C(phi + 2 pi) = C(phi) + row mass`).
    pub(super) fn row_cum(&self, r: usize, phi: f64) -> f64 {
        let turns = (phi / TAU).floor();
        let f = phi - turns * TAU;
        let x = f / TAU * self.width as f64;
        let c = (x.floor().max(0.0) as usize).min(self.width - 1);
        let frac = (x - c as f64).clamp(0.0, 1.0);
        let base = r * (self.width + 1);
        turns * self.row_mass(r) + self.col_cum[base + c] + frac * self.mass[r * self.width + c]
    }

    /// The cap measure with at least `min_pieces` integration pieces per row (1 in
    /// [`DirectionDensity::cap_measure`](crate::sphere::DirectionDensity::cap_measure); more only to study convergence).
    pub fn cap_measure_with(&self, center: DVec3, cos_theta: f64, min_pieces: usize) -> f64 {
        if cos_theta > 1.0 {
            return 0.0;
        }
        if cos_theta <= -1.0 {
            return 1.0;
        }
        let w = unit_or_z(center);
        let t = cos_theta;
        let cg = w.z.clamp(-1.0, 1.0);
        let sg = (1.0 - cg * cg).max(0.0).sqrt();
        let phi_w = w.y.atan2(w.x);
        // gamma = polar angle of w, theta = acos t; latitudes by polar angle alpha.
        let (gamma, theta) = (cg.acos(), t.acos());
        let alpha_a = (gamma - theta).abs();
        let alpha_b = (gamma + theta).min(TAU - gamma - theta);
        let la = alpha_b - alpha_a;
        let top_full_end = theta - gamma; // alpha <= this: whole latitude inside
        let bottom_full_start = TAU - theta - gamma; // alpha >= this: inside
        let arc_mass = |r: usize, sin_alpha: f64, cos_alpha: f64| -> f64 {
            let a = sin_alpha * sg;
            let b = t - cos_alpha * cg;
            if a <= 1e-300 {
                return if b <= 0.0 { self.row_mass(r) } else { 0.0 };
            }
            let half = (b / a).clamp(-1.0, 1.0).acos();
            self.row_cum(r, phi_w + half) - self.row_cum(r, phi_w - half)
        };
        let row_angle = PI / self.height as f64;
        let mut sum = 0.0;
        // Integration breakpoints of the current row, reused across rows.
        let mut cuts: Vec<f64> = Vec::new();
        // Per column edge, the polar angles `delta -+ spread` about which the rim
        // crosses it (NaN: never), computed once per cap: they do not depend on
        // the row, and a map with many bright pixels asks for the same edges row
        // after row. Sized at the first row with a bright pixel.
        let mut edge_crossings: Vec<Option<[f64; 2]>> = Vec::new();
        for r in 0..self.height {
            let rm = self.row_mass(r);
            let dz = self.z_hi[r] - self.z_lo[r];
            let a0 = r as f64 * row_angle;
            let mut a1 = (r + 1) as f64 * row_angle;
            if self.domain == Domain::Hemisphere {
                a1 = a1.min(FRAC_PI_2);
            }
            if rm <= 0.0 || dz <= 0.0 || a1 <= a0 {
                continue;
            }
            let mut part = 0.0;
            if top_full_end > a0 {
                part += rm * (a0.cos() - a1.min(top_full_end).cos()) / dz;
            }
            if bottom_full_start < a1 {
                part += rm * (a0.max(bottom_full_start).cos() - a1.cos()) / dz;
            }
            let (pa, pb) = (a0.max(alpha_a), a1.min(alpha_b));
            if pb > pa && la > 0.0 {
                // alpha = alpha_a + la (1 - cos psi)/2; dz = sin(alpha) dalpha.
                let psi = |al: f64| (1.0 - 2.0 * (al - alpha_a) / la).clamp(-1.0, 1.0).acos();
                let f = |y: f64| {
                    let (sy, cy) = y.sin_cos();
                    let al = alpha_a + 0.5 * la * (1.0 - cy);
                    let (sa, ca) = al.sin_cos();
                    arc_mass(r, sa, ca) * sa * 0.5 * la * sy
                };
                let (p0, p1) = (psi(pa), psi(pb));
                // Where an arc end crosses an edge of a bright pixel the arc mass
                // has a strong kink: integrate between those angles, adaptively.
                let bright = &self.bright_cols[r];
                cuts.clear();
                cuts.extend([p0, p1]);
                if !bright.is_empty() {
                    edge_crossings.resize(self.width + 1, None);
                }
                for &c in bright {
                    for edge in [c, c + 1] {
                        let [delta, spread] = *edge_crossings[edge].get_or_insert_with(|| {
                            let phi_c = TAU * edge as f64 / self.width as f64;
                            let d = (phi_c - phi_w).rem_euclid(TAU);
                            let cos_d = d.min(TAU - d).cos();
                            // The arc's half width is d where t = cg cos(alpha) + sg cos(d) sin(alpha).
                            let (x, y) = (cg, sg * cos_d);
                            let big_r = (x * x + y * y).sqrt();
                            if big_r <= 0.0 || t.abs() > big_r {
                                return [f64::NAN; 2];
                            }
                            [y.atan2(x), (t / big_r).acos()]
                        });
                        if delta.is_nan() {
                            continue;
                        }
                        for al in [delta - spread, delta + spread, delta - spread + TAU] {
                            if al > pa && al < pb {
                                cuts.push(psi(al));
                            }
                        }
                    }
                }
                cuts.sort_by(f64::total_cmp);
                cuts.dedup();
                let piece = |a: f64, b: f64| {
                    if bright.is_empty() {
                        gl4(&f, a, b)
                    } else {
                        gl4_adaptive(&f, a, b, ADAPTIVE_TOL, ADAPTIVE_DEPTH)
                    }
                };
                let mut s = 0.0;
                for (k, span) in cuts.windows(2).enumerate() {
                    let (q0, q1) = (span[0], span[1]);
                    let least = if cuts.len() == 2 { min_pieces } else { 1 };
                    let pieces = (((q1 - q0) / PSI_PIECE).ceil() as usize).max(least);
                    let h = (q1 - q0) / pieces as f64;
                    for j in 0..pieces {
                        let (x0, x1) = (q0 + j as f64 * h, q0 + (j + 1) as f64 * h);
                        // Pieces at a band end are graded geometrically toward it.
                        let at_start = k == 0 && j == 0 && p0 == 0.0;
                        let at_end = k + 2 == cuts.len() && j + 1 == pieces && p1 == PI;
                        s += graded(&piece, x0, x1, at_start, at_end);
                    }
                }
                part += s / dz;
            }
            sum += part;
        }
        sum.clamp(0.0, 1.0)
    }
}
