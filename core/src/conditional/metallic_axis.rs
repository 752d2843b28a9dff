//! The **metallic axis** of a BRDF sampler's learned part
//! ([`SectionTag::MetallicNodes`]): the shared network reads the metallic as an
//! input, and the point table holds one layer of square points per metallic node.
//!
//! Why: the prior's shared square blends the metallic 0 and 1 layers by mass, so
//! the density the learned part refines moves with the metallic. A network that
//! never sees the metallic serves every metallic with one compromise; one that
//! reads it but trains on a continuum of metallics spreads itself over densities
//! it never separates; one that reads it and trains on a few metallic values (the
//! nodes) learns each of them (measured in `docs/results/brdf-sampler.md`).
//!
//! * **network mode**: the shared network's third condition feature, `2 u v - 1`
//!   without the axis, is `2 m - 1` ([`crate::network::Shape::metallic_input`],
//!   `m` the metallic clamped into `[0, 1]`, NaN as 0);
//! * **table mode**: the point table is `L` layers laid out as the plain table,
//!   layer `j` the network's points at metallic `nodes[j]`; a query blends the two
//!   layers around its metallic linearly ([`MetallicCell`]), each layer's point
//!   interpolated bilinearly in the condition first.
//!
//! The metal layer's own network and table (read at metallic 1) have no axis.

use crate::blob::{SectionSpec, SectionTag};

/// Most metallic nodes a blob may hold: a query's search over them is bounded.
pub const MAX_METALLIC_NODES: usize = 8;

/// What is wrong with a [`SectionTag::MetallicNodes`] section's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MetallicNodesError {
    /// Fewer than 2 or more than [`MAX_METALLIC_NODES`] nodes (the count).
    Count(u32),
    /// Node `index` is not finite, not in `[0, 1]`, or not above the one
    /// before it.
    Value {
        /// The node's position.
        index: u32,
        /// Its `f32` bits.
        bits: u32,
    },
}

/// Checks a metallic axis: 2 to [`MAX_METALLIC_NODES`] finite nodes in `[0, 1]`,
/// strictly increasing. `O(L)`.
pub fn check_metallic_nodes(nodes: &[f32]) -> Result<(), MetallicNodesError> {
    if !(2..=MAX_METALLIC_NODES).contains(&nodes.len()) {
        return Err(MetallicNodesError::Count(
            nodes.len().min(u32::MAX as usize) as u32,
        ));
    }
    let mut below = f32::NEG_INFINITY;
    for (index, &m) in (0u32..).zip(nodes) {
        if !(m.is_finite() && (0.0..=1.0).contains(&m) && m > below) {
            return Err(MetallicNodesError::Value {
                index,
                bits: m.to_bits(),
            });
        }
        below = m;
    }
    Ok(())
}

/// Where a metallic falls on the axis: the lower layer `j0` (the upper one is
/// `j0 + 1`) and the fraction `t` in `[0, 1]` between them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetallicCell {
    /// The lower layer, in `0..L - 1`.
    pub j0: u32,
    /// Position between layer `j0` (0) and `j0 + 1` (1).
    pub t: f32,
}

impl MetallicCell {
    /// The cell of metallic `m` on the axis `nodes` (checked by
    /// [`check_metallic_nodes`]): `m` clamped into `[nodes[0], nodes[L - 1]]`
    /// (NaN as `nodes[0]`), `j0` the last layer below `L - 1` with
    /// `nodes[j0] <= m`, `t = (m - nodes[j0]) / (nodes[j0 + 1] - nodes[j0])`
    /// clamped into `[0, 1]`. Total: fewer than 2 nodes give `j0 = 0, t = 0`.
    /// `O(L)`, at most [`MAX_METALLIC_NODES`] comparisons.
    #[inline]
    pub fn locate(nodes: &[f32], m: f32) -> Self {
        let &[first, .., last] = nodes else {
            return Self { j0: 0, t: 0.0 };
        };
        let m = if m.is_nan() {
            first
        } else {
            m.clamp(first, last)
        };
        let top = nodes.len().min(MAX_METALLIC_NODES) - 2;
        let mut j0 = 0;
        while j0 < top && nodes[j0 + 1] <= m {
            j0 += 1;
        }
        let (a, b) = (nodes[j0], nodes[j0 + 1]);
        Self {
            j0: j0 as u32,
            t: ((m - a) / (b - a)).clamp(0.0, 1.0),
        }
    }

    /// The linear blend of layer `j0`'s value `a` and layer `j0 + 1`'s `b`, in
    /// this order of operations (readers reproduce it bit for bit):
    /// `a + (b - a) t`.
    #[inline]
    pub fn lerp(&self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.t
    }
}

/// The section of a sampler's metallic axis (after the other sections), ready
/// for [`crate::blob::write`]. Checks nothing: a reader validates it.
pub fn metallic_section(nodes: &[f32]) -> SectionSpec<'_> {
    SectionSpec {
        tag: SectionTag::MetallicNodes,
        elem_size: 4,
        bytes: bytemuck::cast_slice(nodes),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_must_be_two_to_eight_increasing_values_in_the_unit_interval() {
        assert_eq!(check_metallic_nodes(&[0.0, 0.5, 0.95]), Ok(()));
        assert_eq!(check_metallic_nodes(&[0.0, 1.0]), Ok(()));
        assert_eq!(
            check_metallic_nodes(&[0.5]),
            Err(MetallicNodesError::Count(1))
        );
        assert_eq!(
            check_metallic_nodes(&[0.0; 0]),
            Err(MetallicNodesError::Count(0))
        );
        let nine: [f32; 9] = core::array::from_fn(|j| j as f32 / 8.0);
        assert_eq!(
            check_metallic_nodes(&nine),
            Err(MetallicNodesError::Count(9))
        );
        assert!(check_metallic_nodes(&nine[..8]).is_ok());
        for (bad, index) in [
            ([0.0, 0.5, 0.5], 2),
            ([0.0, 0.6, 0.5], 2),
            ([-0.1, 0.5, 0.9], 0),
            ([0.0, 0.5, 1.5], 2),
            ([0.0, f32::NAN, 0.9], 1),
            ([0.0, 0.5, f32::INFINITY], 2),
        ] {
            let bits = bad[index].to_bits();
            assert_eq!(
                check_metallic_nodes(&bad),
                Err(MetallicNodesError::Value {
                    index: index as u32,
                    bits
                }),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn a_metallic_falls_between_the_nodes_around_it_and_clamps_at_the_ends() {
        let nodes = [0.0, 0.5, 0.95];
        let at = |m| {
            let c = MetallicCell::locate(&nodes, m);
            (c.j0, c.t)
        };
        // At the nodes: weight 1 on that node (the last as t = 1 of the last cell).
        assert_eq!(at(0.0), (0, 0.0));
        assert_eq!(at(0.5), (1, 0.0));
        assert_eq!(at(0.95), (1, 1.0));
        // Between them, the fraction of the way (brute force over a fine grid).
        for s in 0..=1000 {
            let m = s as f32 / 1000.0;
            let c = MetallicCell::locate(&nodes, m);
            let j = c.j0 as usize;
            let mc = m.min(0.95);
            assert!(nodes[j] <= mc && mc <= nodes[j + 1], "{m}");
            let want = (mc - nodes[j]) / (nodes[j + 1] - nodes[j]);
            assert!((c.t - want).abs() < 1e-6, "{m}: {} vs {want}", c.t);
            // The blend of a linear function of the metallic reproduces it.
            let f = |x: f32| 3.0 * x - 1.0;
            assert!((c.lerp(f(nodes[j]), f(nodes[j + 1])) - f(mc)).abs() < 1e-5);
        }
        // Outside and NaN: clamped to the ends.
        assert_eq!(at(1.0), (1, 1.0));
        assert_eq!(at(7.0), (1, 1.0));
        assert_eq!(at(-1.0), (0, 0.0));
        assert_eq!(at(f32::NAN), (0, 0.0));
        // A degenerate axis is total.
        assert_eq!(
            MetallicCell::locate(&[], 0.3),
            MetallicCell { j0: 0, t: 0.0 }
        );
        assert_eq!(
            MetallicCell::locate(&[0.2], 0.3),
            MetallicCell { j0: 0, t: 0.0 }
        );
        // A higher axis start: below it reads the first node.
        assert_eq!(MetallicCell::locate(&[0.25, 0.75], 0.0).t, 0.0);
        assert_eq!(MetallicCell::locate(&[0.25, 0.75], 0.5).t, 0.5);
    }
}
