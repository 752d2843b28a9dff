//! The backward pass of [`nuld_core::network::Network::forward`] and of the
//! sigmoid onto the square after it (the map from the square to a direction is the
//! caller's: its Jacobian chains in front of [`output_gradient`]).
//!
//! With `a_0` the input, `z_l = W_l a_(l-1) + b_l (+ E[row] for l = 1)`,
//! `a_l = act(z_l)`, `o = W_o a_L + b_o`, `p = sigmoid(o)`, `x = M(p)`:
//!
//! ```text
//! dL/do   = dL/dp * p (1 - p)
//! dL/dW_o = dL/do a_L^T,   dL/db_o = dL/do,   dL/da_L = W_o^T dL/do
//! dL/dz_l = dL/da_l * act'(z_l)
//! dL/dW_l = dL/dz_l a_(l-1)^T,  dL/db_l = dL/dz_l (= dL/dE[row] for l = 1)
//! dL/da_(l-1) = W_l^T dL/dz_l
//! ```

use glam::DVec2;
use nuld_core::network::{
    sigmoid, LayerSpan, Shape, Trace, INPUTS, MAX_HIDDEN_LAYERS, MAX_WIDTH, OUTPUTS,
};

/// `dL/do` of the outputs before the sigmoid from `dL/dp` of the square point
/// `p = sigmoid(o)`: `dL/dp p (1 - p)` per coordinate.
pub fn output_gradient(trace: &Trace<f64>, d_square: DVec2) -> [f64; OUTPUTS] {
    let d = [d_square.x, d_square.y];
    core::array::from_fn(|o| {
        let s = sigmoid(trace.output[o]);
        d[o] * s * (1.0 - s)
    })
}

/// Adds `dL/dparams` to `grad` (length `shape.param_len()`) for the embedding row
/// `embedding_row` ([`Shape::embedding_row`]) whose forward pass left `trace`, given `d_output = dL/do` (module formulas).
/// `O(multiply_adds)`.
///
/// # Panics
/// If `params` or `grad` is shorter than `shape.param_len()`.
pub fn backward(
    shape: &Shape,
    params: &[f64],
    trace: &Trace<f64>,
    embedding_row: u32,
    d_output: [f64; OUTPUTS],
    grad: &mut [f64],
) {
    let act = shape.activation();
    let hidden = shape.hidden();
    let layers = hidden.len();
    // Every layer's place in the array, output layer last: walked backwards below.
    let mut spans = [LayerSpan::default(); MAX_HIDDEN_LAYERS + 1];
    for (slot, span) in spans.iter_mut().zip(shape.layers()) {
        *slot = span;
    }

    let activation = |l: usize| -> [f64; MAX_WIDTH] {
        let mut a = [0.0; MAX_WIDTH];
        if l == 0 {
            a[..INPUTS].copy_from_slice(&trace.input);
        } else {
            for (x, &z) in a
                .iter_mut()
                .zip(&trace.pre[l - 1][..hidden[l - 1] as usize])
            {
                *x = act.apply(z);
            }
        }
        a
    };

    // Output layer.
    let LayerSpan {
        weights: off,
        bias,
        fan_in,
        ..
    } = spans[layers];
    let a = activation(layers);
    let mut delta_a = [0.0; MAX_WIDTH];
    for (o, &d) in d_output.iter().enumerate() {
        let row = off + o * fan_in;
        for k in 0..fan_in {
            grad[row + k] += d * a[k];
            delta_a[k] += params[row + k] * d;
        }
        grad[bias + o] += d;
    }
    // Hidden layers, last first.
    for l in (0..layers).rev() {
        let LayerSpan {
            weights: off,
            bias,
            fan_in,
            width: h,
        } = spans[l];
        let a = activation(l);
        let mut delta_z = [0.0; MAX_WIDTH];
        for o in 0..h {
            delta_z[o] = delta_a[o] * act.derivative(trace.pre[l][o]);
        }
        let mut next = [0.0; MAX_WIDTH];
        for (o, &d) in delta_z.iter().enumerate().take(h) {
            if d == 0.0 {
                continue;
            }
            let row = off + o * fan_in;
            for k in 0..fan_in {
                grad[row + k] += d * a[k];
                next[k] += params[row + k] * d;
            }
            grad[bias + o] += d;
            if l == 0 {
                grad[shape.embedding_offset(embedding_row) + o] += d;
            }
        }
        delta_a = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::Params;
    use crate::sphere::geometry::map_jacobian;
    use glam::DVec3;
    use nuld_core::blob::Domain;
    use nuld_core::network::Activation;
    use nuld_core::sphere::square_to_hemisphere;

    /// A smooth scalar of the direction: `L = <x, u> + 0.3 <x, v>^2`.
    fn loss_of(x: DVec3) -> (f64, DVec3) {
        let (u, v) = (DVec3::new(0.3, -0.7, 0.5), DVec3::new(-0.2, 0.4, 0.9));
        let d = x.dot(v);
        (x.dot(u) + 0.3 * d * d, u + 0.6 * d * v)
    }

    fn total_loss(p: &Params, conds: &[([f64; 2], u32, u32)]) -> f64 {
        conds
            .iter()
            .map(|&(c, k, i)| {
                let s = p.trace(c, 0.0, k, i).square_point();
                loss_of(square_to_hemisphere(DVec2::new(s[0], s[1]))).0
            })
            .sum()
    }

    /// The chain network -> sigmoid -> hemisphere map -> a smooth loss against
    /// central differences of the loss in every parameter.
    #[test]
    fn backward_matches_central_differences() {
        // Index 6 wraps to row 1 of E.
        let conds: Vec<([f64; 2], u32, u32)> = (0..12u32)
            .map(|j| {
                (
                    [(j as f64 * 0.37) % 1.0, (j as f64 * 0.61) % 1.0],
                    5 * j + 1,
                    j % 7,
                )
            })
            .collect();
        for (act, hidden) in [
            (Activation::Silu, &[7u32, 5][..]),
            (Activation::Relu, &[6u32, 5, 4][..]),
            (Activation::Silu, &[9u32][..]),
        ] {
            let shape = Shape::new(5, hidden, act, 2).unwrap();
            let mut p = Params::init(shape, 11);
            // Non-zero E and biases, positive so that most Relu units are on.
            for (j, x) in p.values.iter_mut().enumerate() {
                if *x == 0.0 {
                    *x = 0.15 + 0.1 * (((j * 7919) % 13) as f64 / 6.0 - 1.0);
                }
            }
            let mut grad = vec![0.0; shape.param_len()];
            for &(c, k, i) in &conds {
                let t = p.trace(c, 0.0, k, i);
                let s = t.square_point();
                let sq = DVec2::new(s[0], s[1]);
                let g3 = loss_of(square_to_hemisphere(sq)).1;
                // dL/dp = (J_x . g, J_y . g), the map's Jacobian columns by central
                // differences.
                let (jx, jy) = map_jacobian(Domain::Hemisphere, sq);
                let d_out = output_gradient(&t, DVec2::new(jx.dot(g3), jy.dot(g3)));
                backward(
                    &shape,
                    &p.values,
                    &t,
                    shape.embedding_row(k, i),
                    d_out,
                    &mut grad,
                );
            }
            let h = 1e-6;
            let mut worst: f64 = 0.0;
            for (j, &g) in grad.iter().enumerate() {
                let x = p.values[j];
                p.values[j] = x + h;
                let up = total_loss(&p, &conds);
                p.values[j] = x - h;
                let down = total_loss(&p, &conds);
                p.values[j] = x;
                let fd = (up - down) / (2.0 * h);
                worst = worst.max((g - fd).abs() / (1.0 + fd.abs()));
            }
            // The map's Jacobian is itself a central difference (step 1e-7).
            assert!(worst < 1e-5, "{act:?} {hidden:?}: {worst}");
            // The check is not vacuous: many weights (past the per-index rows) moved
            // (fewer with Relu, whose units are off for some of the three inputs).
            let weights = &grad[shape.first_layer_offset()..];
            let moved = weights.iter().filter(|&&g| g != 0.0).count();
            assert!(
                moved > weights.len() / 5,
                "{act:?} {hidden:?}: {moved} of {}",
                weights.len()
            );
        }
    }
}
