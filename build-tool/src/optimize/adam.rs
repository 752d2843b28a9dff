//! Adam (Kingma & Ba 2015) on a vector of 2D points.

use glam::DVec2;

/// Adam state for `n` 2D parameters.
#[derive(Clone, Debug)]
pub struct Adam {
    m: Vec<DVec2>,
    v: Vec<DVec2>,
    t: i32,
    /// First-moment decay, 0.9 by default.
    pub beta1: f64,
    /// Second-moment decay, 0.999 by default.
    pub beta2: f64,
    /// Added to the root of the second moment; tiny, because gradients of the
    /// discrepancy are small in absolute terms.
    pub epsilon: f64,
}

impl Adam {
    /// Fresh state for `n` parameters.
    pub fn new(n: usize) -> Self {
        Self {
            m: vec![DVec2::ZERO; n],
            v: vec![DVec2::ZERO; n],
            t: 0,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-30,
        }
    }

    /// One step of size `lr` against `grad`: `x -= lr * m_hat / (sqrt(v_hat) + eps)`.
    pub fn step(&mut self, params: &mut [DVec2], grad: &[DVec2], lr: f64) {
        self.t += 1;
        let c1 = 1.0 - self.beta1.powi(self.t);
        let c2 = 1.0 - self.beta2.powi(self.t);
        for ((x, g), (m, v)) in params
            .iter_mut()
            .zip(grad)
            .zip(self.m.iter_mut().zip(self.v.iter_mut()))
        {
            *m = self.beta1 * *m + (1.0 - self.beta1) * *g;
            *v = self.beta2 * *v + (1.0 - self.beta2) * *g * *g;
            let m_hat = *m / c1;
            let v_hat = *v / c2;
            *x -= lr * m_hat / (v_hat.powf(0.5) + self.epsilon);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimizes_a_quadratic() {
        let target = DVec2::new(0.3, -0.7);
        let mut x = vec![DVec2::new(2.0, 2.0)];
        let mut adam = Adam::new(1);
        for _ in 0..3000 {
            let g = [2.0 * (x[0] - target)];
            adam.step(&mut x, &g, 0.01);
        }
        assert!((x[0] - target).length() < 1e-3, "{:?}", x[0]);
    }
}
