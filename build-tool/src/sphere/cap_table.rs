//! Fast cap measures of a tabulated measure: a weighted point rule in a cone tree.
//!
//! A measure given as weighted directions `(y_k, w_k)` (a quadrature rule of the
//! target, see [`super::DirectionDensity::quadrature`]) has cap measure
//! `sum_k w_k 1[<c, y_k> >= t]`. A brute-force sum is `O(K)` per cap; the
//! [`CapMeasureTable`] answers the same sum (bit-for-bit the same inclusion test
//! `<c, y> >= t`) in about `O(sqrt K)` by a ball tree on the sphere whose nodes carry
//! a bounding cone (axis, angular radius) and their weight sum: nodes entirely
//! inside the cap add their sum, nodes entirely outside are skipped, only nodes
//! straddling the cap boundary are opened. Cones are padded by `1e-9` rad and
//! pruning decisions keep a margin of `1e-12` on cosines, so they agree with the
//! pointwise test (up to the rounding of the dot product itself).

use super::geometry::{acos_clamped, unit_or_z};
use glam::DVec3;
use std::f64::consts::PI;

/// Points per leaf.
const LEAF: usize = 16;
/// Safety margin on cosines for pruning decisions.
const MARGIN: f64 = 1e-12;
/// Traversal stack size (the tree depth is about `log2(K / LEAF)`).
const STACK: usize = 128;

#[derive(Clone, Debug)]
struct Node {
    axis: DVec3,
    /// Cosine and sine of the angular radius of the bounding cone about `axis`.
    cos_r: f64,
    sin_r: f64,
    /// Sum of the weights below this node.
    weight: f64,
    begin: u32,
    end: u32,
    /// Index of the first child (the second is `left + 1`); 0 for a leaf.
    left: u32,
}

/// A weighted direction rule with `O(sqrt K)` cap-measure queries.
#[derive(Clone, Debug)]
pub struct CapMeasureTable {
    points: Vec<DVec3>,
    weights: Vec<f64>,
    nodes: Vec<Node>,
    total: f64,
}

impl CapMeasureTable {
    /// Builds the tree from `(direction, weight)` pairs. Directions are normalized;
    /// pairs with a zero, negative or non-finite weight or a zero / non-finite
    /// direction are dropped. `O(K log K)`.
    pub fn new(rule: &[(DVec3, f64)]) -> Self {
        let mut pts: Vec<(DVec3, f64)> = rule
            .iter()
            .filter(|(d, w)| *w > 0.0 && w.is_finite() && d.is_finite() && d.length() > 0.0)
            .map(|(d, w)| (d.normalize(), *w))
            .collect();
        let mut nodes = Vec::new();
        if !pts.is_empty() {
            nodes.push(Node {
                axis: DVec3::Z,
                cos_r: 1.0,
                sin_r: 0.0,
                weight: 0.0,
                begin: 0,
                end: pts.len() as u32,
                left: 0,
            });
            build(&mut pts, &mut nodes, 0);
        }
        let total = nodes.first().map_or(0.0, |n| n.weight);
        let (points, weights) = pts.into_iter().unzip();
        Self {
            points,
            weights,
            nodes,
            total,
        }
    }

    /// Number of weighted points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the table holds no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Sum of all weights (the measure of the whole sphere).
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The weighted points, in tree order.
    pub fn points(&self) -> impl Iterator<Item = (DVec3, f64)> + '_ {
        self.points
            .iter()
            .copied()
            .zip(self.weights.iter().copied())
    }

    /// `sum_k w_k 1[<c, y_k> >= t]` for the cap `C(center, cos_theta)`; `center` is
    /// normalized (zero or non-finite: `+z`).
    pub fn measure(&self, center: DVec3, cos_theta: f64) -> f64 {
        if self.nodes.is_empty() || cos_theta > 1.0 {
            return 0.0;
        }
        if cos_theta <= -1.0 {
            return self.total;
        }
        let c = unit_or_z(center);
        let t = cos_theta;
        let mut sum = 0.0;
        let mut stack = [0u32; STACK];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let n = &self.nodes[stack[sp] as usize];
            // beta = angle(c, axis), rho = cone radius: the node is inside the cap if
            // beta + rho <= theta, outside if beta - rho > theta (compared through
            // cosines, with the node's sin(beta +- rho) fixing the branch).
            let cb = c.dot(n.axis).clamp(-1.0, 1.0);
            let sb = (1.0 - cb * cb).max(0.0).sqrt();
            let inside =
                sb * n.cos_r + cb * n.sin_r >= 0.0 && cb * n.cos_r - sb * n.sin_r >= t + MARGIN;
            let outside =
                sb * n.cos_r - cb * n.sin_r > 0.0 && cb * n.cos_r + sb * n.sin_r < t - MARGIN;
            if inside {
                sum += n.weight;
            } else if outside {
                // Entirely outside.
            } else if n.left == 0 || sp + 2 > STACK {
                for k in n.begin as usize..n.end as usize {
                    if c.dot(self.points[k]) >= cos_theta {
                        sum += self.weights[k];
                    }
                }
            } else {
                stack[sp] = n.left + 1;
                stack[sp + 1] = n.left;
                sp += 2;
            }
        }
        sum
    }

    /// The measures of the caps `C(center, t)` for every `t` in `cos_thetas` at once:
    /// one pass over the points, each binned by binary search among the sorted
    /// `t`s. `O(K log n + n log n)`.
    pub fn profile(&self, center: DVec3, cos_thetas: &[f64]) -> Vec<f64> {
        profile_of_rule(self.points(), center, cos_thetas)
    }
}

/// Cap measures `sum_k w_k 1[<c, y_k> >= t_j]` for all `t_j`, by binning each point
/// among the sorted `t`s (shared by [`CapMeasureTable::profile`] and the densities).
pub(crate) fn profile_of_rule(
    rule: impl Iterator<Item = (DVec3, f64)>,
    center: DVec3,
    cos_thetas: &[f64],
) -> Vec<f64> {
    let c = unit_or_z(center);
    let mut order: Vec<usize> = (0..cos_thetas.len()).collect();
    order.sort_by(|&a, &b| cos_thetas[a].total_cmp(&cos_thetas[b]));
    let sorted: Vec<f64> = order.iter().map(|&k| cos_thetas[k]).collect();
    // acc[j]: weight of the points whose largest containing sorted t is sorted[j].
    let mut acc = vec![0.0; sorted.len()];
    for (y, w) in rule {
        let d = c.dot(y);
        let cnt = sorted.partition_point(|&t| t <= d);
        if cnt > 0 {
            acc[cnt - 1] += w;
        }
    }
    let mut out = vec![0.0; sorted.len()];
    let mut run = 0.0;
    for j in (0..sorted.len()).rev() {
        run += acc[j];
        out[order[j]] = run;
    }
    out
}

/// Recursively splits node `i` (points `pts[begin..end]`) at the median of the
/// coordinate of largest extent, and fills its cone and weight.
fn build(pts: &mut [(DVec3, f64)], nodes: &mut Vec<Node>, i: usize) {
    let (b, e) = (nodes[i].begin as usize, nodes[i].end as usize);
    let slice = &mut pts[b..e];
    let mut mean = DVec3::ZERO;
    let mut weight = 0.0;
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (d, w) in slice.iter() {
        mean += *d;
        weight += *w;
        lo = lo.min(*d);
        hi = hi.max(*d);
    }
    let axis = unit_or_z(mean);
    let radius = slice
        .iter()
        .map(|(d, _)| acos_clamped(axis.dot(*d)))
        .fold(0.0, f64::max)
        + 1e-9;
    nodes[i].axis = axis;
    nodes[i].cos_r = radius.min(PI).cos();
    nodes[i].sin_r = radius.min(PI).sin();
    nodes[i].weight = weight;
    if slice.len() <= LEAF {
        return;
    }
    let ext = hi - lo;
    let dim = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = slice.len() / 2;
    slice.select_nth_unstable_by(mid, |a, b| a.0[dim].total_cmp(&b.0[dim]));
    let left = nodes.len();
    nodes[i].left = left as u32;
    let m = (b + mid) as u32;
    nodes.push(Node {
        axis: DVec3::Z,
        cos_r: 1.0,
        sin_r: 0.0,
        weight: 0.0,
        begin: b as u32,
        end: m,
        left: 0,
    });
    nodes.push(Node {
        axis: DVec3::Z,
        cos_r: 1.0,
        sin_r: 0.0,
        weight: 0.0,
        begin: m,
        end: e as u32,
        left: 0,
    });
    build(pts, nodes, left);
    build(pts, nodes, left + 1);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeding::rng;
    use crate::sphere::geometry::random_direction;
    use rand::Rng;

    #[test]
    fn tree_queries_equal_brute_force_sums() {
        let mut r = rng(3, 1);
        // Clustered and spread points, uneven weights.
        let mut rule: Vec<(DVec3, f64)> = (0..20_000)
            .map(|k| {
                let d = random_direction(&mut r);
                let d = if k % 3 == 0 {
                    (DVec3::new(0.3, 0.1, 1.0) + 0.05 * d).normalize()
                } else {
                    d
                };
                (d, r.random::<f64>())
            })
            .collect();
        rule.push((DVec3::ZERO, 1.0)); // dropped
        let table = CapMeasureTable::new(&rule);
        assert_eq!(table.len(), 20_000);
        let brute = |c: DVec3, t: f64| -> f64 {
            rule.iter()
                .filter(|(d, w)| *w > 0.0 && d.length() > 0.0 && c.dot(d.normalize()) >= t)
                .map(|(_, w)| *w)
                .sum()
        };
        let total: f64 = rule[..20_000].iter().map(|p| p.1).sum();
        assert!((table.total() - total).abs() < 1e-9);
        for q in 0..300 {
            let c = if q % 4 == 0 {
                DVec3::new(0.3, 0.1, 1.0).normalize()
            } else {
                random_direction(&mut r)
            };
            let t = 1.0 - 2.0 * r.random::<f64>().powi(if q % 2 == 0 { 1 } else { 8 });
            let (a, b) = (table.measure(c, t), brute(c, t));
            assert!((a - b).abs() < 1e-9 * total, "{a} vs {b}");
        }
        assert_eq!(table.measure(DVec3::Z, 1.5), 0.0);
        assert!((table.measure(DVec3::Z, -1.0) - total).abs() < 1e-9);
        // Profile = individual queries.
        let c = random_direction(&mut r);
        let ts: Vec<f64> = (0..50).map(|_| 1.0 - 2.0 * r.random::<f64>()).collect();
        let p = table.profile(c, &ts);
        for (t, v) in ts.iter().zip(&p) {
            assert!((v - brute(c, *t)).abs() < 1e-9 * total);
        }
    }
}
