//! Checks shared by the tests of the BRDF prior's candidate table maps
//! ([`super::radial_half_vector`], [`super::horizon_disc`]): a map takes a point of
//! the equal-area square to a light direction with `|dwi/dω_p|`, and back.

use glam::{DVec2, DVec3};

/// On a 23 x 23 grid of the square: `point` inverts `direction` (to `1e-7` in the
/// square, `1e-6` relative in the Jacobian), and the Jacobian is the solid angle of
/// a small table square's image over the table's (`2π` per unit area; central
/// differences, to `1e-4` relative). Returns how many points the differences
/// checked (the square's diagonals, where the equal-area map has seams, and points
/// whose neighbours leave the map's support are skipped).
pub fn check_inverse_and_jacobian(
    direction: impl Fn(DVec2) -> Option<(DVec3, f64)>,
    point: impl Fn(DVec3) -> Option<(DVec2, f64)>,
) -> usize {
    let mut checked = 0;
    for i in 1..24 {
        for j in 1..24 {
            let p = DVec2::new(i as f64 / 24.0, j as f64 / 24.0);
            let Some((wi, jac)) = direction(p) else {
                continue;
            };
            let (back_p, back) = point(wi).unwrap();
            assert!((back_p - p).length() < 1e-7, "{back_p} {p}");
            assert!((back - jac).abs() < 1e-6 * jac, "{back} {jac} at {p}");
            if i == j || i + j == 24 {
                continue;
            }
            let h = 1e-6;
            let at = |d: DVec2| direction(p + d).map(|x| x.0);
            let (Some(xp), Some(xm), Some(yp), Some(ym)) = (
                at(DVec2::new(h, 0.0)),
                at(DVec2::new(-h, 0.0)),
                at(DVec2::new(0.0, h)),
                at(DVec2::new(0.0, -h)),
            ) else {
                continue;
            };
            let area = (xp - xm).cross(yp - ym).length() / (4.0 * h * h);
            let want = area / (2.0 * std::f64::consts::PI);
            assert!((want - jac).abs() < 1e-4 * jac, "{want} {jac} at {p}");
            checked += 1;
        }
    }
    checked
}
