//! Local units for concentrated targets: where the target is `f^2` times denser
//! than uniform, points are `f` times closer, so a point's sigmoid sharpness is
//! multiplied by `f` and its Adam step divided by `f` (the direction optimizer's
//! `--local-units` and the conditional trainer).

/// Largest local factor: a region may be this many times denser in points (per
/// unit length) than the uniform spacing, i.e. hold `MAX_LOCAL_FACTOR^2` times the
/// uniform density (far beyond a sun in an 8-bit-exponent HDR map at 4k).
pub const MAX_LOCAL_FACTOR: f64 = 1e4;

/// The local factor `f = sqrt(|domain| pdf(x))` of a point where the target's
/// density is `pdf` (per unit area of a domain of area `area_of_domain`), clamped
/// into `[1, MAX_LOCAL_FACTOR]`; 1 where it is not finite.
pub fn local_factor(area_of_domain: f64, pdf: f64) -> f64 {
    let f = (area_of_domain * pdf).sqrt();
    if f.is_finite() {
        f.clamp(1.0, MAX_LOCAL_FACTOR)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_factor_is_the_root_of_the_density_ratio_within_its_bounds() {
        // Uniform density on the sphere (pdf = 1 / 4 pi): factor 1.
        let area = 4.0 * std::f64::consts::PI;
        assert_eq!(local_factor(area, 1.0 / area), 1.0);
        assert!((local_factor(area, 9.0 / area) - 3.0).abs() < 1e-12);
        assert_eq!(local_factor(area, 0.1 / area), 1.0);
        assert_eq!(local_factor(area, 1e30), MAX_LOCAL_FACTOR);
        assert_eq!(local_factor(area, f64::NAN), 1.0);
        assert_eq!(local_factor(area, f64::INFINITY), 1.0);
    }
}
