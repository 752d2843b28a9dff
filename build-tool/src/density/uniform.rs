//! `uniform`: the constant density `q(x, y) = 1` on `[0,1]^2`.

use super::{CellGrid, Density2D};
use glam::{DMat2, DVec2};

/// The uniform density `q = 1` on `[0,1]^2` (SPEC `uniform`): CDF `x y`, measure
/// of a box its area, inverse CDF and Jacobian the identity.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Uniform;

impl Density2D for Uniform {
    fn spec(&self) -> String {
        "uniform".to_string()
    }

    fn pdf(&self, p: DVec2) -> f64 {
        if (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y) {
            1.0
        } else {
            0.0
        }
    }

    fn cdf(&self, p: DVec2) -> f64 {
        let p = p.clamp(DVec2::ZERO, DVec2::ONE);
        p.x * p.y
    }

    fn measure(&self, lo: DVec2, hi: DVec2) -> f64 {
        let lo = lo.clamp(DVec2::ZERO, DVec2::ONE);
        let hi = hi.clamp(DVec2::ZERO, DVec2::ONE);
        (hi.x - lo.x).max(0.0) * (hi.y - lo.y).max(0.0)
    }

    fn inverse_cdf(&self, u: DVec2) -> DVec2 {
        u.clamp(DVec2::ZERO, DVec2::ONE)
    }

    fn inverse_cdf_jacobian(&self, _u: DVec2) -> DMat2 {
        DMat2::IDENTITY
    }

    fn cells(&self, resolution: usize) -> CellGrid {
        let n = resolution.max(1);
        CellGrid {
            width: n,
            height: n,
            mass: vec![1.0 / (n * n) as f64; n * n],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::check::{check_density, Checks};

    #[test]
    fn uniform_passes_generic_checks() {
        check_density(&Uniform, &Checks::smooth());
        assert_eq!(Uniform.spec(), "uniform");
        assert_eq!(Uniform.cells(4).mass.iter().sum::<f64>(), 1.0);
    }
}
