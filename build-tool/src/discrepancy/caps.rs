//! The spherical-cap estimator (paper §3.5, Eq. 9): caps `C(w, theta)` with `w`
//! uniform on the sphere and `theta` uniform in `[0, pi]` (the paper's measure
//! `nu`), exact counts forward, and backward the gradient of
//! `sigma(alpha (theta - arccos <w, x>))`.
//!
//! ```text
//! loss = (1/M) sum_c r_c^2,   r_c = #{i : <w_c, x_i> >= cos theta_c} / N - mu(C_c)
//! d loss / d x_i = (2/(M N)) sum_c r_c alpha sigma'(alpha sdf) t_c(x_i)
//! ```
//!
//! with `t_c(x)` the unit tangent at `x` pointing toward `w_c` (minus the gradient
//! of the angle). The fast path answers each cap with a [`CapTree`]: nodes whose
//! bounding cap lies entirely inside (or outside) the query cap, further than the
//! sigmoid band from its rim, are counted (or skipped) without touching their
//! points. A set of a few dozen points (a few hundred, under a wide band) is one
//! leaf, every point tested: the walk would cost more than it prunes.

use super::estimator::{sigmoid_slope, sum_partials, SIGMOID_BAND};
use super::GradientPath;
use crate::seeding::derive_seed;
use glam::{DVec2, DVec3};
use nuld_core::sphere::sphere_to_square;
use rayon::prelude::*;

/// A spherical cap `{x : <center, x> >= cos theta}`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cap {
    /// Unit centre direction `w`.
    pub center: DVec3,
    /// Angular radius `theta` in `[0, pi]`.
    pub theta: f64,
    /// `cos theta`, the threshold on `<w, x>`.
    pub cos_theta: f64,
}

impl Cap {
    /// The cap of centre `center` (unit) and angular radius `theta` (radians).
    pub fn new(center: DVec3, theta: f64) -> Self {
        Self {
            center,
            theta,
            cos_theta: theta.cos(),
        }
    }

    /// The cap for a point `s` of the unit cube: centre uniform on the sphere from
    /// `(s.x, s.y)`, `theta = pi s.z` (the paper's measure `nu`).
    pub fn from_unit_cube(s: DVec3) -> Self {
        let z = 1.0 - 2.0 * s.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * std::f64::consts::PI * s.y;
        Self::new(
            DVec3::new(r * phi.cos(), r * phi.sin(), z),
            std::f64::consts::PI * s.z,
        )
    }

    /// Whether `x` lies in the cap (closed).
    #[inline]
    pub fn contains(&self, x: DVec3) -> bool {
        self.center.dot(x) >= self.cos_theta
    }
}

/// Points at most this many per tree leaf.
const LEAF: usize = 8;
/// Up to this many points a [`CapTree`] is one leaf without a bounding cap: each
/// query tests every point, since a few dozen dot products cost less than the
/// walk, its square roots and its branches (a training set of 64 directions).
const FLAT: usize = 96;
/// Up to this many points the gradient's queries test every point too when
/// their rim band is at least [`WIDE_BAND`] wide: few nodes lie clear of so
/// wide a band, so the walk prunes little (a training set of 256 directions,
/// whose sharpness ends at 32 inverse spacings).
const FLAT_WIDE: usize = 256;
/// The band (radians, each side of the rim) from which [`FLAT_WIDE`] applies.
const WIDE_BAND: f64 = 0.05;
/// Depth of the Morton code over the equal-area square.
const LEVELS: u32 = 12;

#[derive(Clone, Copy, Debug)]
struct Node {
    start: u32,
    end: u32,
    /// Index of the first of up to four children (consecutive), 0 for a leaf.
    first_child: u32,
    child_count: u32,
    center: DVec3,
    /// Largest angle between `center` and a point of the node (plus rounding
    /// slack), and its cosine and sine.
    radius: f64,
    cos_radius: f64,
    sin_radius: f64,
}

/// A quadtree over directions (by their equal-area square coordinates), each node
/// holding a bounding cap of its points, for counting points in caps and finding
/// those near a cap's rim without visiting every point.
pub struct CapTree {
    points: Vec<DVec3>,
    index: Vec<u32>,
    nodes: Vec<Node>,
}

/// The Morton code ([`nuld_core::quadtree::morton`]) of `p`'s cell among
/// `2^LEVELS x 2^LEVELS` (2 LEVELS bits, so it fits a `u32`).
fn morton(p: DVec2) -> u32 {
    let cell = |v: f64| ((v * (1u32 << LEVELS) as f64) as u32).min((1 << LEVELS) - 1);
    nuld_core::quadtree::morton(cell(p.x), cell(p.y)) as u32
}

impl CapTree {
    /// Builds the tree over `points` (unit vectors): one flat leaf up to 96
    /// points, else O(N log N).
    pub fn new(points: &[DVec3]) -> Self {
        Self::for_band(points, 0.0)
    }

    /// The tree for queries whose rim band is `band` radians wide each side: one
    /// flat leaf where testing every point costs less ([`FLAT`], [`FLAT_WIDE`]).
    /// The answers are the same either way.
    fn for_band(points: &[DVec3], band: f64) -> Self {
        let n = points.len();
        if n <= FLAT || (n <= FLAT_WIDE && band >= WIDE_BAND) {
            return Self::flat(points);
        }
        let mut keyed: Vec<(u32, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, &x)| (morton(sphere_to_square(x)), i as u32))
            .collect();
        keyed.sort_unstable();
        let codes: Vec<u32> = keyed.iter().map(|k| k.0).collect();
        let index: Vec<u32> = keyed.iter().map(|k| k.1).collect();
        let sorted: Vec<DVec3> = index.iter().map(|&i| points[i as usize]).collect();
        let mut tree = Self {
            points: sorted,
            index,
            nodes: Vec::new(),
        };
        tree.nodes.push(tree.make_node(0, codes.len()));
        // Breadth-first: split every node with more than LEAF points by the next two
        // Morton bits, so children are contiguous.
        let mut k = 0;
        let mut level_of = vec![0u32];
        while k < tree.nodes.len() {
            let (start, end, level) = (
                tree.nodes[k].start as usize,
                tree.nodes[k].end as usize,
                level_of[k],
            );
            if end - start > LEAF && level < LEVELS {
                let shift = 2 * (LEVELS - 1 - level);
                let first = tree.nodes.len() as u32;
                let mut lo = start;
                for q in 0..4u32 {
                    let hi = lo + codes[lo..end].partition_point(|&c| (c >> shift) & 3 <= q);
                    if hi > lo {
                        let node = tree.make_node(lo, hi);
                        tree.nodes.push(node);
                        level_of.push(level + 1);
                    }
                    lo = hi;
                }
                tree.nodes[k].first_child = first;
                tree.nodes[k].child_count = tree.nodes.len() as u32 - first;
            }
            k += 1;
        }
        tree
    }

    /// One leaf over `points` in their order, bounded by the whole sphere so that
    /// no query prunes it: the queries' answers are the tree's (the leaf tests
    /// are the same), found by testing every point.
    fn flat(points: &[DVec3]) -> Self {
        Self {
            points: points.to_vec(),
            index: (0..points.len() as u32).collect(),
            nodes: vec![Node {
                start: 0,
                end: points.len() as u32,
                first_child: 0,
                child_count: 0,
                center: DVec3::Z,
                radius: std::f64::consts::PI,
                cos_radius: -1.0,
                sin_radius: 0.0,
            }],
        }
    }

    fn make_node(&self, start: usize, end: usize) -> Node {
        let pts = &self.points[start..end];
        let sum: DVec3 = pts.iter().copied().sum();
        let center = sum
            .try_normalize()
            .unwrap_or(pts.first().copied().unwrap_or(DVec3::Z));
        let radius = pts
            .iter()
            .map(|&x| center.dot(x).clamp(-1.0, 1.0).acos())
            .fold(0.0, f64::max);
        Node {
            start: start as u32,
            end: end as u32,
            first_child: 0,
            child_count: 0,
            center,
            // Slack absorbs the rounding of the acos above (up to ~1e-8 near 0).
            radius: radius + 1e-7,
            cos_radius: (radius + 1e-7).cos(),
            sin_radius: (radius + 1e-7).sin(),
        }
    }

    /// Number of points in `cap`; calls `on_rim(original index, point)` for every
    /// point whose angular distance to the rim is below `band` (radians).
    ///
    /// Angles are compared through their cosines (`cos(a - b) = cos a cos b +
    /// sin a sin b`), so a query computes no inverse trigonometric function.
    pub fn query(&self, cap: &Cap, band: f64, mut on_rim: impl FnMut(usize, DVec3)) -> u32 {
        use std::f64::consts::PI;
        let band = band.max(1e-9);
        // The rim band in cosines: inner edge theta - band, outer edge theta + band.
        let inner = cap.theta - band;
        let outer = cap.theta + band;
        let cos_inner = if inner <= 0.0 { 2.0 } else { inner.cos() };
        let cos_outer = if outer >= PI { -2.0 } else { outer.cos() };
        let mut count = 0;
        // Depth-first with a fixed stack: at most 3 pending siblings per level.
        let mut stack = [0u32; 4 * LEVELS as usize + 4];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let k = stack[top];
            let node = &self.nodes[k as usize];
            // Every point of the node is within `radius` of its centre, so with
            // c = cos(angle to the centre), all of it lies at angles in
            // [a - radius, a + radius].
            let c = cap.center.dot(node.center);
            let s = (1.0 - c * c).max(0.0).sqrt();
            // a + radius <= pi (so cosine is monotone there) and
            // cos(a + radius) > cos(inner): the whole node is inside, clear of the rim.
            if inner > node.radius
                && c >= -node.cos_radius
                && c * node.cos_radius - s * node.sin_radius > cos_inner + 1e-12
            {
                count += node.end - node.start;
                continue;
            }
            // cos(a - radius) < cos(outer) with a > radius: entirely outside.
            if outer < PI
                && c < node.cos_radius
                && c * node.cos_radius + s * node.sin_radius < cos_outer - 1e-12
            {
                continue;
            }
            if node.child_count == 0 {
                for j in node.start as usize..node.end as usize {
                    let x = self.points[j];
                    let d = cap.center.dot(x);
                    if d >= cap.cos_theta {
                        count += 1;
                    }
                    if d < cos_inner && d > cos_outer {
                        on_rim(self.index[j] as usize, x);
                    }
                }
            } else {
                for c in node.first_child..node.first_child + node.child_count {
                    stack[top] = c;
                    top += 1;
                }
            }
        }
        count
    }
}

/// `alpha sigma'(alpha (theta - angle)) t`, the gradient of the smoothed indicator
/// of `cap` at `x`, as a vector in the tangent plane at `x` (zero at the centre and
/// the antipode, where the angle is not differentiable).
#[inline]
fn rim_gradient(cap: &Cap, x: DVec3, alpha: f64) -> DVec3 {
    let d = cap.center.dot(x).clamp(-1.0, 1.0);
    let tangent = cap.center - d * x;
    let len = tangent.length();
    if len < 1e-12 {
        return DVec3::ZERO;
    }
    let sdf = cap.theta - d.acos();
    (sigmoid_slope(alpha, sdf) / len) * tangent
}

/// How the target measure of a cap is obtained.
#[derive(Clone, Copy)]
pub enum CapArea<'a> {
    /// A closed form or precomputed table: `mu(C)` from `(center, cos theta)`.
    Exact(&'a (dyn Fn(DVec3, f64) -> f64 + Sync)),
    /// The fraction of shared target samples (in a [`CapTree`]) inside the cap.
    MonteCarlo(&'a CapTree),
    /// Measures computed beforehand, `mu(caps[i])` at index `i` (same length as the
    /// caps): how a precomputed cap schedule shares one table lookup per cap among
    /// many optimizations.
    Precomputed(&'a [f64]),
}

/// Fixed number of work chunks (results are summed in chunk order).
const CHUNKS: usize = 32;

/// Residuals `r_c = count / N - mu(C_c)` of every cap, loss `(1/M) sum r^2` and its
/// surrogate gradient with respect to each point (ambient, tangent to the sphere),
/// written to `grad`. Bit-identical for any thread count.
///
/// `alpha` is the sigmoid's sharpness; `local`, if given, multiplies it per point
/// (`alpha_i = alpha local[i]`, each `local[i] >= 1`): point `i`'s indicator is
/// mollified by `sigma(alpha_i sdf)`, which keeps the surrogate's width a fixed
/// fraction of the *local* point spacing where the target concentrates its mass
/// (a sun, a sharp lobe). The forward counts are exact either way.
///
/// # Panics
/// If `area` is [`CapArea::Precomputed`] with a length other than `caps.len()`, or
/// `local` has a length other than `points.len()`.
pub fn cap_loss_and_gradient(
    points: &[DVec3],
    caps: &[Cap],
    area: CapArea<'_>,
    alpha: f64,
    local: Option<&[f64]>,
    path: GradientPath,
    grad: &mut [DVec3],
) -> f64 {
    let n = points.len();
    if let Some(l) = local {
        assert_eq!(l.len(), n, "one local sharpness per point");
    }
    // Points with `local > 1` have narrower bands: the base band covers them all.
    let inv_n = 1.0 / n.max(1) as f64;
    let band = SIGMOID_BAND / alpha;
    let tree = (path == GradientPath::Fast).then(|| CapTree::for_band(points, band));
    let chunk = caps.len().div_ceil(CHUNKS).max(1);
    if let CapArea::Precomputed(mu) = area {
        assert_eq!(mu.len(), caps.len(), "one precomputed measure per cap");
    }
    let chunk_partial = |(ci, cs): (usize, &[Cap])| {
        let mut g = vec![DVec3::ZERO; n];
        let mut loss = 0.0;
        let mut rim: Vec<(usize, DVec3)> = Vec::new();
        for (j, cap) in cs.iter().enumerate() {
            let mu = match area {
                CapArea::Exact(f) => f(cap.center, cap.cos_theta),
                CapArea::Precomputed(mu) => mu[ci * chunk + j],
                CapArea::MonteCarlo(samples) => {
                    samples.query(cap, 0.0, |_, _| {}) as f64 / samples.points.len().max(1) as f64
                }
            };
            rim.clear();
            let count = match &tree {
                Some(t) => t.query(cap, band, |i, x| rim.push((i, x))),
                None => {
                    rim.extend(points.iter().copied().enumerate());
                    points.iter().filter(|&&x| cap.contains(x)).count() as u32
                }
            };
            let r = count as f64 * inv_n - mu;
            loss += r * r;
            match local {
                None => {
                    for &(i, x) in &rim {
                        g[i] += r * rim_gradient(cap, x, alpha);
                    }
                }
                Some(l) => {
                    for &(i, x) in &rim {
                        g[i] += r * rim_gradient(cap, x, alpha * l[i]);
                    }
                }
            }
        }
        (loss, g)
    };
    // Called from the pool's own threads (a training step runs its conditions
    // in parallel, each with its sets' caps), the threads are busy already and
    // handing chunks between them costs more than it saves: the chunks run in
    // turn, the same chunks summed in the same order.
    let partials: Vec<(f64, Vec<DVec3>)> = if rayon::current_thread_index().is_some() {
        caps.chunks(chunk).enumerate().map(chunk_partial).collect()
    } else {
        caps.par_chunks(chunk)
            .enumerate()
            .map(chunk_partial)
            .collect()
    };
    let m = caps.len().max(1) as f64;
    let loss = sum_partials(partials, grad, 2.0 / (m * n.max(1) as f64));
    loss / m
}

/// The caps of epoch `epoch` for seed `seed`: `count` points of a freshly
/// scrambled 3D Owen-Sobol set mapped by [`Cap::from_unit_cube`] (independent of
/// the point count, so every size shares them).
pub(crate) fn epoch_caps(seed: u64, epoch: usize, count: usize) -> Vec<Cap> {
    let scramble = derive_seed(seed, 2 * epoch as u64 + 1) as u32;
    (0..count)
        .map(|i| {
            let (idx, dim) = ((i % (1 << 16)) as u32, 3 * (i >> 16) as u32);
            Cap::from_unit_cube(DVec3::new(
                sobol_burley::sample(idx, dim, scramble) as f64,
                sobol_burley::sample(idx, dim + 1, scramble) as f64,
                sobol_burley::sample(idx, dim + 2, scramble) as f64,
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn random_dirs(n: usize, seed: u64) -> Vec<DVec3> {
        let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        (0..n)
            .map(|_| Cap::from_unit_cube(DVec3::new(r.random(), r.random(), 0.0)).center)
            .collect()
    }

    fn random_caps(m: usize, seed: u64) -> Vec<Cap> {
        let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        (0..m)
            .map(|_| Cap::from_unit_cube(DVec3::new(r.random(), r.random(), r.random())))
            .collect()
    }

    #[test]
    fn tree_counts_equal_brute_force_and_rim_points_are_complete() {
        // One flat leaf up to FLAT points (FLAT_WIDE for wide bands), a tree
        // beyond.
        for n in [1, 5, 64, FLAT, FLAT + 1, FLAT_WIDE, FLAT_WIDE + 1, 3000] {
            for band in [0.0, WIDE_BAND] {
                tree_agrees_with_brute_force(CapTree::for_band(&random_dirs(n, 1), band), n);
            }
        }
    }

    fn tree_agrees_with_brute_force(tree: CapTree, n: usize) {
        let pts = random_dirs(n, 1);
        for (cap, band) in random_caps(300, 2)
            .into_iter()
            .zip([0.02, 0.1].iter().cycle())
        {
            let band = *band;
            let mut rim = Vec::new();
            let count = tree.query(&cap, band, |i, _| rim.push(i));
            let want = pts.iter().filter(|&&x| cap.contains(x)).count() as u32;
            assert_eq!(count, want);
            let mut want_rim: Vec<usize> = (0..pts.len())
                .filter(|&i| {
                    (cap.center.dot(pts[i]).clamp(-1.0, 1.0).acos() - cap.theta).abs() < band
                })
                .collect();
            rim.sort_unstable();
            want_rim.sort_unstable();
            assert_eq!(rim, want_rim);
        }
    }

    #[test]
    fn rim_gradient_is_the_derivative_along_the_sphere() {
        let cap = Cap::new(DVec3::new(0.3, -0.4, 0.866).normalize(), 0.9);
        let alpha = 25.0;
        let smooth =
            |x: DVec3| 1.0 / (1.0 + (-alpha * (cap.theta - cap.center.dot(x).acos())).exp());
        for x in random_dirs(200, 3) {
            let g = rim_gradient(&cap, x, alpha);
            assert!(g.dot(x).abs() < 1e-9 * (1.0 + g.length()), "tangent");
            // Directional derivatives along two tangent directions, by rotation.
            let t1 = x.any_orthonormal_vector();
            let t2 = x.cross(t1);
            for t in [t1, t2] {
                let h = 1e-6;
                let fd =
                    (smooth((x + h * t).normalize()) - smooth((x - h * t).normalize())) / (2.0 * h);
                assert!(
                    (g.dot(t) - fd).abs() < 1e-5 * (1.0 + fd.abs()),
                    "{x:?}: {} vs {fd}",
                    g.dot(t)
                );
            }
        }
    }

    #[test]
    fn fast_gradient_equals_dense_reference() {
        let uniform = |_: DVec3, c: f64| (1.0 - c) / 2.0;
        // A training set's size (one flat leaf), a tree.
        for (n, a) in [
            (64, 3.0),
            (64, 32.0),
            (100, 3.0),
            (1000, 12.0),
            (2048, 40.0),
        ] {
            let pts = random_dirs(n, n as u64);
            let caps = random_caps(200, 7);
            let alpha = a * (n as f64 / (4.0 * std::f64::consts::PI)).sqrt();
            let mut fast = vec![DVec3::ZERO; n];
            let mut dense = fast.clone();
            let lf = cap_loss_and_gradient(
                &pts,
                &caps,
                CapArea::Exact(&uniform),
                alpha,
                None,
                GradientPath::Fast,
                &mut fast,
            );
            let ld = cap_loss_and_gradient(
                &pts,
                &caps,
                CapArea::Exact(&uniform),
                alpha,
                None,
                GradientPath::Dense,
                &mut dense,
            );
            assert_eq!(lf, ld);
            let scale = dense.iter().map(|g| g.length()).fold(0.0, f64::max);
            assert!(scale > 0.0);
            for (i, (x, y)) in fast.iter().zip(&dense).enumerate() {
                assert!(
                    (*x - *y).length() <= 1e-6 * scale,
                    "{n} point {i}: {x:?} vs {y:?}"
                );
            }
        }
    }

    #[test]
    fn chunks_in_turn_on_a_pool_thread_give_the_pools_bits() {
        // From a pool's thread (as a training step calls it) the chunks run in
        // turn; from outside, on the pool. The same sums in the same order.
        let uniform = |_: DVec3, c: f64| (1.0 - c) / 2.0;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for n in [64, 300] {
            let pts = random_dirs(n, 40 + n as u64);
            let caps = random_caps(256, 41);
            let local: Vec<f64> = pts.iter().map(|x| 1.0 + x.z.abs()).collect();
            let run = |g: &mut [DVec3]| {
                cap_loss_and_gradient(
                    &pts,
                    &caps,
                    CapArea::Exact(&uniform),
                    30.0,
                    Some(&local),
                    GradientPath::Fast,
                    g,
                )
            };
            let mut outside = vec![DVec3::ZERO; n];
            let mut inside = vec![DVec3::ZERO; n];
            let lo = run(&mut outside);
            let li = pool.install(|| {
                assert!(rayon::current_thread_index().is_some());
                run(&mut inside)
            });
            assert_eq!(lo.to_bits(), li.to_bits());
            assert!(outside.iter().any(|g| *g != DVec3::ZERO));
            assert_eq!(outside, inside);
        }
    }

    #[test]
    fn per_point_sharpness_is_each_points_own_sigmoid_on_both_paths() {
        let uniform = |_: DVec3, c: f64| (1.0 - c) / 2.0;
        let n = 500;
        let pts = random_dirs(n, 21);
        let caps = random_caps(150, 22);
        let alpha = 20.0;
        // Sharper (1x to 40x) for points with larger x.
        let local: Vec<f64> = pts.iter().map(|x| 1.0 + 39.0 * x.x.max(0.0)).collect();
        let mut fast = vec![DVec3::ZERO; n];
        let mut dense = fast.clone();
        let path_loss = |path, g: &mut [DVec3]| {
            cap_loss_and_gradient(
                &pts,
                &caps,
                CapArea::Exact(&uniform),
                alpha,
                Some(&local),
                path,
                g,
            )
        };
        let lf = path_loss(GradientPath::Fast, &mut fast);
        let ld = path_loss(GradientPath::Dense, &mut dense);
        assert_eq!(lf, ld);
        // Reference: the definition, point by point with its own alpha (the fast
        // path drops contributions beyond the band, below e^-16 of the peak each).
        let m = caps.len() as f64;
        for i in (0..n).step_by(37) {
            let mut want = DVec3::ZERO;
            for cap in &caps {
                let count = pts.iter().filter(|&&x| cap.contains(x)).count() as f64;
                let r = count / n as f64 - uniform(cap.center, cap.cos_theta);
                want += r * rim_gradient(cap, pts[i], alpha * local[i]);
            }
            want *= 2.0 / (m * n as f64);
            let scale = want.length().max(1e-12);
            assert!(
                (fast[i] - want).length() <= 1e-5 * scale,
                "{i}: {:?} vs {want:?}",
                fast[i]
            );
            assert!((dense[i] - want).length() <= 1e-9 * scale, "{i}");
        }
    }

    #[test]
    fn loss_mean_matches_the_theta_uniform_discrepancy_of_iid_points() {
        // For N iid uniform points and a fixed cap, E[r^2] = p (1 - p) / N with
        // p = (1 - cos theta)/2; averaged over theta uniform in [0, pi]:
        // E[(1 - cos^2 theta)/4] / N = (1/8) / N.
        let n = 50;
        let uniform = |_: DVec3, c: f64| (1.0 - c) / 2.0;
        let mut vals = Vec::new();
        for s in 0..400 {
            let pts = random_dirs(n, 100 + s);
            let caps = random_caps(200, 1000 + s);
            let mut g = vec![DVec3::ZERO; n];
            vals.push(cap_loss_and_gradient(
                &pts,
                &caps,
                CapArea::Exact(&uniform),
                10.0,
                None,
                GradientPath::Fast,
                &mut g,
            ));
        }
        let mean = vals.iter().sum::<f64>() / vals.len() as f64;
        let sd =
            (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (vals.len() - 1) as f64).sqrt();
        let se = sd / (vals.len() as f64).sqrt();
        let want = 0.125 / n as f64;
        assert!((mean - want).abs() < 3.0 * se, "{mean} ± {se} vs {want}");
        assert!(se < 0.05 * want);
    }

    #[test]
    fn monte_carlo_cap_areas_match_closed_form() {
        let samples = random_dirs(100_000, 9);
        let tree = CapTree::new(&samples);
        for cap in random_caps(100, 10) {
            let got = tree.query(&cap, 0.0, |_, _| {}) as f64 / samples.len() as f64;
            let want = (1.0 - cap.cos_theta) / 2.0;
            assert!((got - want).abs() < 0.008, "{got} vs {want}");
        }
    }
}
