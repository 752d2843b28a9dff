//! Small numeric helpers shared by the densities: ulp steps and a safeguarded
//! Newton solver for monotone equations.

/// The next representable `f64` above `x` (for finite `x`; `f64::next_up` needs
/// Rust 1.86, above this workspace's MSRV).
pub(crate) fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let bits = x.to_bits();
    if x > 0.0 {
        f64::from_bits(bits + 1)
    } else {
        f64::from_bits(bits - 1)
    }
}

/// The next representable `f64` below `x` (for finite `x`).
pub(crate) fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

/// Solves `f(x) = target` for `x` in `[lo, hi]`, where `f` is non-decreasing and
/// `eval(x) = (f(x), f'(x))`. Newton steps safeguarded by bisection (Numerical
/// Recipes' `rtsafe`), starting at `x0` (or the midpoint if `x0` is outside the
/// bracket). Stops at a relative residual of a few ulps of `target`, a relative
/// step of a few ulps of `x`, or after 200 iterations; the result is in `[lo, hi]`.
pub(crate) fn solve_increasing(
    eval: impl Fn(f64) -> (f64, f64),
    target: f64,
    mut lo: f64,
    mut hi: f64,
    x0: f64,
) -> f64 {
    const EPS: f64 = f64::EPSILON;
    let mut x = if x0 > lo && x0 < hi {
        x0
    } else {
        0.5 * (lo + hi)
    };
    let mut dx_old = hi - lo;
    let mut dx = dx_old;
    let res_tol = 4.0 * EPS * target.abs() + 1e-300;
    for _ in 0..200 {
        let (v, d) = eval(x);
        let r = v - target;
        if r.abs() <= res_tol {
            return x;
        }
        if r < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - r / d;
        let use_newton =
            d > 0.0 && newton > lo && newton < hi && (2.0 * r).abs() <= (dx_old * d).abs();
        dx_old = dx;
        if use_newton {
            dx = r / d;
            x = newton;
        } else {
            dx = 0.5 * (hi - lo);
            x = lo + dx;
        }
        if dx.abs() <= 2.0 * EPS * x.abs() || hi - lo <= 2.0 * EPS * hi.abs().max(lo.abs()) {
            return x.clamp(lo, hi);
        }
    }
    x.clamp(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ulp_steps() {
        assert!(next_up(1.0) > 1.0 && next_up(1.0) - 1.0 == f64::EPSILON);
        assert!(next_down(1.0) < 1.0);
        assert_eq!(next_up(next_down(0.3)), 0.3);
        assert!(next_up(0.0) > 0.0);
        assert!(next_down(0.0) < 0.0);
        assert!(next_up(-1.0) > -1.0);
    }

    #[test]
    fn solver_cube_root_and_flat_start() {
        for &t in &[1e-30, 1e-9, 0.3, 0.999, 1.0] {
            let x = solve_increasing(|x| (x * x * x, 3.0 * x * x), t, 0.0, 1.0, 0.5);
            assert!(((x * x * x - t) / t).abs() < 1e-13, "t = {t}, x = {x}");
        }
        // Starts where the derivative vanishes.
        let x = solve_increasing(|x| (x * x * x, 3.0 * x * x), 0.125, 0.0, 1.0, 0.0);
        assert!((x - 0.5).abs() < 1e-15);
    }
}
