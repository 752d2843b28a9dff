//! [`Params`]: a network's parameters as one flat `f64` array in the layout of
//! [`nuld_core::network`], with a deterministic initialization and f16 rounding.

use crate::seeding::rng;
use nuld_core::network::{interleave, InterleavedParams, Network, Shape, Trace};
use nuld_core::quantize::{f16_decode, f16_encode};
use rand::Rng;

/// A network's parameters (`shape.param_len()` numbers, order of
/// [`nuld_core::network`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    /// The architecture.
    pub shape: Shape,
    /// The flat parameter array.
    pub values: Vec<f64>,
}

impl Params {
    /// He-style initialization from `seed`: every weight of a layer with fan-in
    /// `m` uniform in `±sqrt(6 / m)` (`±sqrt(3 / m)` for the output layer, so that
    /// the sigmoid starts away from saturation), biases and the per-index rows `E`
    /// zero. Bit-identical for a seed.
    pub fn init(shape: Shape, seed: u64) -> Self {
        let mut values = vec![0.0; shape.param_len()];
        let mut r = rng(seed, 0x6e65_7477);
        let hidden = shape.hidden().len();
        for (l, span) in shape.layers().enumerate() {
            let gain = if l < hidden { 6.0 } else { 3.0 };
            let bound = (gain / span.fan_in as f64).sqrt();
            for w in &mut values[span.weights..span.bias] {
                *w = bound * (2.0 * r.random::<f64>() - 1.0);
            }
        }
        Self { shape, values }
    }

    /// The network over these parameters, as the forward pass reads them.
    pub fn network(&self) -> Network<&[f64]> {
        Network {
            shape: self.shape,
            params: &self.values,
        }
    }

    /// The forward pass of index `i`, instance `k`, normalized condition `c` and
    /// metallic `m` (read only by a shape with
    /// [`Shape::metallic_input`]).
    pub fn trace(&self, c: [f64; 2], m: f64, k: u32, i: u32) -> Trace<f64> {
        let mut trace = Trace::default();
        self.trace_into(c, m, k, i, &mut trace);
        trace
    }

    /// [`Self::trace`] written into `trace` ([`Network::forward_into`]: the
    /// same bits, no 3 kB trace cleared and moved per point).
    pub fn trace_into(&self, c: [f64; 2], m: f64, k: u32, i: u32, trace: &mut Trace<f64>) {
        self.network().trace_point_into(c, m, k, i, trace)
    }

    /// The point of the unit square of index `i`, instance `k`, normalized condition
    /// `c` and metallic `m`: [`Network::square_point`], the same bits as
    /// `self.trace(c, m, k, i).square_point()` without recording a [`Trace`].
    pub fn square_point(&self, c: [f64; 2], m: f64, k: u32, i: u32) -> [f64; 2] {
        self.network().square_point_at(c, m, k, i)
    }

    /// These parameters with the output layer's weights and biases set to 0, or
    /// `None` for a shape without [`Shape::lattice_residual`]. A residual network
    /// adds its output to the shifted lattice point's logit
    /// ([`nuld_core::network::lattice_logit`]), so this one returns every
    /// instance's shifted lattice point unchanged (to the logit's clamp at
    /// `2^-20` of the square's edges): the prior's untrained lattice, which
    /// `bake` ships where training did not beat it.
    pub fn without_residual(&self) -> Option<Self> {
        if !self.shape.lattice_residual() {
            return None;
        }
        let output = self.shape.layers().last()?;
        let mut values = self.values.clone();
        values[output.weights..].fill(0.0);
        Some(Self {
            shape: self.shape,
            values,
        })
    }

    /// The parameters as f16 bits (round to nearest even through `f32`).
    pub fn to_f16_bits(&self) -> Vec<u16> {
        self.values.iter().map(|&x| f16_encode(x as f32)).collect()
    }

    /// The parameters rounded to f16 and read back as `f64`: exactly the values a
    /// blob ships.
    pub fn rounded_to_f16(&self) -> Self {
        Self {
            shape: self.shape,
            values: self
                .to_f16_bits()
                .into_iter()
                .map(|b| f16_decode(b) as f64)
                .collect(),
        }
    }
}

/// A copy of a network's parameters in the layout the forward pass reads
/// fastest ([`InterleavedParams`]): [`Interleaved::network`] gives the traces
/// of [`Params::network`] bit for bit, faster (a quarter of the forward pass at
/// [32, 32]). A copy: [`Interleaved::refresh`] it after each update.
#[derive(Clone, Debug)]
pub struct Interleaved {
    shape: Shape,
    values: Vec<f64>,
}

impl Interleaved {
    /// `values`, a row-major parameter array of `shape`, copied and interleaved.
    pub fn new(shape: Shape, values: &[f64]) -> Self {
        let mut copy = Self {
            shape,
            values: Vec::with_capacity(values.len()),
        };
        copy.refresh(values);
        copy
    }

    /// Copies `values` (the same shape's, after an update) in again; no
    /// allocation.
    pub fn refresh(&mut self, values: &[f64]) {
        self.values.clear();
        self.values.extend_from_slice(values);
        let done = interleave(&self.shape, &mut self.values);
        debug_assert!(done.is_some(), "an array of its shape's param_len values");
    }

    /// The network over the copy.
    pub fn network(&self) -> Network<InterleavedParams<'_, f64>> {
        Network {
            shape: self.shape,
            params: InterleavedParams::new(self.shape, &self.values),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nuld_core::network::{Activation, INPUTS};

    #[test]
    fn without_residual_serves_the_shifted_lattice() {
        let lattice = Shape::new(16, &[8, 8], Activation::Relu, 5)
            .unwrap()
            .with_lattice_residual(true);
        let trained = Params::init(lattice, 7);
        let bare = trained.without_residual().unwrap();
        // Only the output layer (the parameters' tail) changed.
        let output = lattice.layers().last().unwrap();
        assert_eq!(
            output.weights + (output.fan_in + 1) * output.width,
            trained.values.len()
        );
        assert_eq!(
            bare.values[..output.weights],
            trained.values[..output.weights]
        );
        for (k, i, c) in [(0, 0, [0.2, 0.9]), (3, 7, [0.5, 0.5]), (40, 15, [1.0, 0.0])] {
            let z = lattice.instance_offset::<f64>(k);
            let want = nuld_core::network::shifted_lattice_point(i, 16, 5, z);
            let got = bare.square_point(c, 0.0, k, i);
            for a in 0..2 {
                assert!(
                    (got[a] - want[a]).abs() < 1e-12,
                    "{k} {i}: {got:?} {want:?}"
                );
            }
            // The trained network's own residual moves the point.
            assert_ne!(trained.square_point(c, 0.0, k, i), got);
        }
        // A network that is not a residual over the lattice has no such copy.
        let plain = Shape::new(16, &[8, 8], Activation::Relu, 5).unwrap();
        assert!(Params::init(plain, 7).without_residual().is_none());
    }

    #[test]
    fn init_is_deterministic_sized_and_bounded() {
        let shape = Shape::new(16, &[8, 8], Activation::Relu, 5).unwrap();
        let a = Params::init(shape, 3);
        assert_eq!(a.values.len(), shape.param_len());
        assert_eq!(a, Params::init(shape, 3));
        assert_ne!(a, Params::init(shape, 4));
        // E and the first layer's biases start at zero; weights within the bound.
        assert!(a.values[..16 * 8].iter().all(|&x| x == 0.0));
        let w1 = &a.values[128..128 + 8 * INPUTS];
        let bound = (6.0 / INPUTS as f64).sqrt();
        assert!(w1.iter().all(|&x| x.abs() <= bound) && w1.iter().any(|&x| x != 0.0));
        assert!(a.values[128 + 8 * INPUTS..128 + 8 * INPUTS + 8]
            .iter()
            .all(|&x| x == 0.0));
    }

    /// The interleaved copy traces every point as the parameters do, bit for bit,
    /// and follows the parameters when refreshed.
    #[test]
    fn the_interleaved_copy_traces_the_same_bits() {
        let shape = Shape::new(8, &[12, 9], Activation::Relu, 3).unwrap();
        let mut p = Params::init(shape, 5);
        p.values
            .iter_mut()
            .enumerate()
            .for_each(|(j, v)| *v += j as f64 * 1e-4);
        let mut copy = Interleaved::new(shape, &p.values);
        for round in 0..2 {
            let net = copy.network();
            for (k, i) in [(0, 0), (3, 7), (11, 2)] {
                let c = [0.3, 0.8];
                let mut t = Trace::default();
                net.trace_point_into(c, 0.0, k, i, &mut t);
                let want = p.trace(c, 0.0, k, i);
                assert_eq!(t.output.map(f64::to_bits), want.output.map(f64::to_bits));
                assert_eq!(t.pre[0].map(f64::to_bits), want.pre[0].map(f64::to_bits));
                let sq = net.square_point_at(c, 0.0, k, i);
                assert_eq!(sq, p.square_point(c, 0.0, k, i), "round {round}");
            }
            p.values.iter_mut().for_each(|v| *v = -*v);
            copy.refresh(&p.values);
        }
    }

    #[test]
    fn f16_rounding_is_within_half_an_ulp() {
        let shape = Shape::new(4, &[6], Activation::Silu, 1).unwrap();
        let p = Params::init(shape, 1);
        let r = p.rounded_to_f16();
        for (&x, &y) in p.values.iter().zip(&r.values) {
            assert!((x - y).abs() <= x.abs() / 2048.0 + 6e-8, "{x} -> {y}");
        }
    }
}
