//! Adam (Kingma & Ba 2015) on a vector of parameters: 2D points (the optimizers)
//! or scalars (a network's flat weights).

use super::PARAMETER_CHUNK;
use glam::DVec2;
use rayon::prelude::*;
use std::ops::{Add, Div, Mul, Sub};

/// A parameter Adam updates coordinate by coordinate: `f64` or [`DVec2`].
pub trait AdamParam:
    Copy
    + Send
    + Sync
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + Div<Output = Self>
    + Add<f64, Output = Self>
{
    /// All coordinates zero.
    const ZERO: Self;
    /// Coordinate-wise square root.
    fn sqrt(self) -> Self;
}

impl AdamParam for f64 {
    const ZERO: Self = 0.0;
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

impl AdamParam for DVec2 {
    const ZERO: Self = DVec2::ZERO;
    fn sqrt(self) -> Self {
        self.powf(0.5)
    }
}

/// Adam state for `n` parameters of type `P`.
#[derive(Clone, Debug)]
pub struct Adam<P = DVec2> {
    m: Vec<P>,
    v: Vec<P>,
    t: i32,
    /// First-moment decay, 0.9 by default.
    pub beta1: f64,
    /// Second-moment decay, 0.999 by default.
    pub beta2: f64,
    /// Added to the root of the second moment; tiny, because gradients of the
    /// discrepancy are small in absolute terms.
    pub epsilon: f64,
}

impl<P: AdamParam> Adam<P> {
    /// Fresh state for `n` parameters.
    pub fn new(n: usize) -> Self {
        Self {
            m: vec![P::ZERO; n],
            v: vec![P::ZERO; n],
            t: 0,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-30,
        }
    }

    /// How many parameters the state is for.
    pub fn len(&self) -> usize {
        self.m.len()
    }

    /// Whether the state is for no parameters.
    pub fn is_empty(&self) -> bool {
        self.m.is_empty()
    }

    /// One step of size `lr` against `grad`: `x -= lr * m_hat / (sqrt(v_hat) + eps)`.
    pub fn step(&mut self, params: &mut [P], grad: &[P], lr: f64) {
        self.step_scaled(params, grad, lr, None);
    }

    /// [`Adam::step`] with parameter `i`'s step multiplied by `scale[i]` (e.g. to
    /// move each point in units of its local spacing); `None` is a scale of 1.
    ///
    /// # Panics
    /// If `scale` has a length other than `params.len()`.
    pub fn step_scaled(&mut self, params: &mut [P], grad: &[P], lr: f64, scale: Option<&[f64]>) {
        if let Some(s) = scale {
            assert_eq!(s.len(), params.len(), "one step scale per parameter");
        }
        self.t += 1;
        let c1 = 1.0 - self.beta1.powi(self.t);
        let c2 = 1.0 - self.beta2.powi(self.t);
        let (beta1, beta2, epsilon) = (self.beta1, self.beta2, self.epsilon);
        // Each parameter's update reads only its own state, so the chunks may run
        // in any order on any thread: the same bits.
        let update = |start: usize, x: &mut [P], m: &mut [P], v: &mut [P]| {
            for (j, ((x, m), v)) in x.iter_mut().zip(m).zip(v).enumerate() {
                let i = start + j;
                let g = grad[i];
                *m = *m * beta1 + g * (1.0 - beta1);
                *v = *v * beta2 + g * (1.0 - beta2) * g;
                let m_hat = *m / c1;
                let v_hat = *v / c2;
                let lr_i = scale.map_or(lr, |s| lr * s[i]);
                *x = *x - m_hat * lr_i / (v_hat.sqrt() + epsilon);
            }
        };
        if params.len() <= PARAMETER_CHUNK {
            update(0, params, &mut self.m, &mut self.v);
            return;
        }
        params
            .par_chunks_mut(PARAMETER_CHUNK)
            .zip(self.m.par_chunks_mut(PARAMETER_CHUNK))
            .zip(self.v.par_chunks_mut(PARAMETER_CHUNK))
            .enumerate()
            .for_each(|(c, ((x, m), v))| update(c * PARAMETER_CHUNK, x, m, v));
    }

    /// The state to checkpoint, moved out: first and second moments and the step
    /// count.
    pub fn into_state(self) -> (Vec<P>, Vec<P>, i32) {
        (self.m, self.v, self.t)
    }

    /// Restores a state taken by [`Adam::into_state`] (default decay rates and epsilon).
    ///
    /// # Panics
    /// If `m` and `v` differ in length.
    pub fn from_state(m: Vec<P>, v: Vec<P>, t: i32) -> Self {
        assert_eq!(m.len(), v.len(), "one second moment per first moment");
        Self {
            m,
            v,
            t,
            ..Self::new(0)
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

    #[test]
    fn scaled_steps_move_each_parameter_by_its_scale() {
        // Adam's first step is lr * sign(g) per coordinate.
        let mut x = vec![DVec2::ZERO; 3];
        let g = [
            DVec2::new(1.0, -2.0),
            DVec2::new(-3.0, 4.0),
            DVec2::new(5.0, 6.0),
        ];
        Adam::new(3).step_scaled(&mut x, &g, 0.1, Some(&[1.0, 0.5, 0.01]));
        let want = [
            DVec2::new(-0.1, 0.1),
            DVec2::new(0.05, -0.05),
            DVec2::new(-0.001, -0.001),
        ];
        for (a, b) in x.iter().zip(&want) {
            assert!((*a - *b).length() < 1e-12, "{a:?} vs {b:?}");
        }
        // No scale is the plain step, bit for bit.
        let (mut p, mut q) = (vec![DVec2::ONE; 3], vec![DVec2::ONE; 3]);
        let (mut a, mut b) = (Adam::new(3), Adam::new(3));
        for _ in 0..5 {
            a.step(&mut p, &g, 0.03);
            b.step_scaled(&mut q, &g, 0.03, None);
        }
        assert_eq!(p, q);
    }

    #[test]
    fn a_network_sized_step_is_each_parameters_own_update_bit_for_bit() {
        // Long enough to run in chunks on the pool; every parameter against
        // Adam's formula written out for it alone, with its own scale.
        let n = 3 * PARAMETER_CHUNK + 5;
        let value = |i: usize, k: usize| ((i * 7919 + k * 104_729) % 1000) as f64 / 500.0 - 1.0;
        let scale: Vec<f64> = (0..n).map(|i| 0.5 + value(i, 9).abs()).collect();
        let mut x: Vec<f64> = (0..n).map(|i| value(i, 0)).collect();
        let mut want = x.clone();
        let (mut m, mut v) = (vec![0.0f64; n], vec![0.0f64; n]);
        let mut adam = Adam::<f64>::new(n);
        let (b1, b2) = (adam.beta1, adam.beta2);
        for t in 1..=3 {
            let g: Vec<f64> = (0..n).map(|i| value(i, t)).collect();
            adam.step_scaled(&mut x, &g, 0.01, Some(&scale));
            let (c1, c2) = (1.0 - b1.powi(t as i32), 1.0 - b2.powi(t as i32));
            for i in 0..n {
                m[i] = m[i] * b1 + g[i] * (1.0 - b1);
                v[i] = v[i] * b2 + g[i] * (1.0 - b2) * g[i];
                let step = (m[i] / c1) * (0.01 * scale[i]) / ((v[i] / c2).sqrt() + adam.epsilon);
                want[i] -= step;
            }
        }
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&x), bits(&want));
    }

    #[test]
    fn a_state_moved_out_and_back_continues_bit_for_bit() {
        let g = |k: usize| [0.3 - 0.1 * k as f64, -1.7 / (k + 1) as f64, 2.5];
        let (mut p, mut q) = (vec![1.0f64, -2.0, 0.5], vec![1.0f64, -2.0, 0.5]);
        let mut straight = Adam::<f64>::new(3);
        let mut moved = Adam::<f64>::new(3);
        for k in 0..6 {
            straight.step(&mut p, &g(k), 0.05);
            moved.step(&mut q, &g(k), 0.05);
            let (m, v, t) = moved.into_state();
            assert_eq!(t, k as i32 + 1);
            moved = Adam::from_state(m, v, t);
        }
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&p), bits(&q));
        assert_ne!(p, vec![1.0, -2.0, 0.5]);
    }
}
