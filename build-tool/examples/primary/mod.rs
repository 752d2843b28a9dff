//! What the fits of a point set in a prior's primary space share (`fit`'s
//! environment normals, `brdf_bounds`' BRDF conditions): their caps, and one
//! step's gradient of the trainer's cap loss chained from the warped
//! directions back to the square.
use glam::{DVec2, DVec3};
use nuld_build_tool::discrepancy::caps::{cap_loss_and_gradient, Cap, CapArea};
use nuld_build_tool::discrepancy::GradientPath;

/// Caps a fit reads per step, in turn from its list: the trainer's window.
pub const WINDOW: usize = 256;

/// `count` caps of the paper's measure from the scrambled Sobol stream
/// `stream` (centre uniform on the sphere, radius uniform in `[0, pi]`).
pub fn caps(count: u32, stream: u32) -> Vec<Cap> {
    (0..count)
        .map(|k| {
            let s = |d| sobol_burley::sample(k, d, stream) as f64;
            Cap::from_unit_cube(DVec3::new(s(0), s(1), s(2)))
        })
        .collect()
}

/// The gradient, per point of the primary square, of the cap loss of the
/// warped points `w` (each direction with its derivatives along `u.x` and
/// `u.y`) on window `t` of `caps` (their target measures `measures`), at
/// sharpness `alpha` inverse `spacing`s times each point's `local` factor.
pub fn step_gradient(
    w: &[(DVec3, DVec3, DVec3)],
    local: &[f64],
    (caps, measures): (&[Cap], &[f64]),
    t: usize,
    alpha: f64,
    spacing: f64,
) -> Vec<DVec2> {
    let dirs: Vec<DVec3> = w.iter().map(|x| x.0).collect();
    let window: Vec<usize> = (0..WINDOW).map(|j| (WINDOW * t + j) % caps.len()).collect();
    let c: Vec<Cap> = window.iter().map(|&j| caps[j]).collect();
    let mu: Vec<f64> = window.iter().map(|&j| measures[j]).collect();
    let mut grad = vec![DVec3::ZERO; w.len()];
    cap_loss_and_gradient(
        &dirs,
        &c,
        CapArea::Precomputed(&mu),
        alpha / spacing,
        Some(local),
        GradientPath::Fast,
        &mut grad,
    );
    w.iter()
        .zip(&grad)
        .map(|(x, g)| DVec2::new(x.1.dot(*g), x.2.dot(*g)))
        .collect()
}
