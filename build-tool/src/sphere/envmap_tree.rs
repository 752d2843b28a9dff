//! A map's hierarchical product warp: the map's luminance in a quadtree over the
//! sphere's equal-area octahedral square (a mip pyramid of masses), times a bound
//! of `max(0, n.l)` over each node for the query's normal, sampled exactly by
//! [`nuld_core::quadtree`] (Clarberg and Akenine-Möller 2008).
//!
//! Unlike [`super::EnvmapPrior`]'s tables per normal, the state is one pyramid of
//! the map, whatever the normals, at the resolution of the leaves (`2^L x 2^L`;
//! `L = 9` puts leaves 0.4° apart, about a 1024 x 512 map's pixels); the cosine
//! enters at the query. Each node also stores its first moment `∑ mass l`, so its
//! weight for a normal `n`, `∑ mass max(0, n.l)`, is exactly `n . moment` when the
//! node lies above the horizon of `n`; across the horizon it is estimated, but
//! never 0 where the cosine is positive, so the pdf is positive wherever `L cos`
//! is and `L cos / pdf` is unbiased.

use super::envmap::EnvmapDensity;
use super::geometry::acos_clamped;
use super::target::DirectionDensity;
use glam::{DVec2, DVec3};
use nuld_core::quadtree::{build_pyramid, level_offset, pyramid_len, QuadtreeError, QuadtreeWarp};
use nuld_core::sphere::{sphere_to_square, square_to_sphere};
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// Levels from the root down to which the cosine bound is 1: their nodes span
/// a hemisphere or more, where a bound is no tighter than 1.
const UNBOUNDED_LEVELS: u32 = 2;

/// Supersampled points per leaf and axis at `L` levels: about 1024 per axis over
/// the square.
fn supersampling(levels: u32) -> usize {
    (1024usize >> levels.min(10)).max(1)
}

/// A map's pyramid (see the module docs).
#[derive(Clone, Debug)]
pub struct EnvmapTree {
    /// Levels below the root.
    pub levels: u32,
    /// Node masses, level by level ([`nuld_core::quadtree::build_pyramid`]).
    pub pyramid: Vec<f32>,
    /// Node first moments `∑ mass l` per coordinate of the direction `l`, laid out
    /// as the masses: a node's `∑ mass max(0, n.l)` is `n . moment` when the node
    /// lies above the horizon of `n`.
    pub moments: [Vec<f32>; 3],
    /// Node cones ([`node_cone`]), laid out as the masses: computed once, since a
    /// sample reads many nodes' geometry at every level.
    cones: Vec<(DVec3, f64)>,
}

impl EnvmapTree {
    /// The pyramid of `map` (its pdf proportional to the luminance) with `levels`
    /// levels: each leaf's mass the mean of the map's pdf over a grid of points in
    /// it (it has equal area). An error if `levels` exceeds the quadtree's limit.
    pub fn new(map: &EnvmapDensity, levels: u32) -> Result<Self, QuadtreeError> {
        if levels > 14 {
            return Err(QuadtreeError::Levels(levels));
        }
        let side = 1usize << levels;
        let k = supersampling(levels);
        let leaves: Vec<(f64, DVec3)> = (0..side * side)
            .into_par_iter()
            .map(|leaf| {
                let (x, y) = (leaf % side, leaf / side);
                let (mut sum, mut moment) = (0.0, DVec3::ZERO);
                for b in 0..k {
                    for a in 0..k {
                        let p = DVec2::new(
                            (x as f64 + (a as f64 + 0.5) / k as f64) / side as f64,
                            (y as f64 + (b as f64 + 0.5) / k as f64) / side as f64,
                        );
                        let d = square_to_sphere(p);
                        let m = map.pdf(d);
                        sum += m;
                        moment += m * d;
                    }
                }
                let kk = (k * k) as f64;
                (sum / kk, moment / kk)
            })
            .collect();
        let pyramid_of = |f: &dyn Fn(&(f64, DVec3)) -> f64| -> Result<Vec<f32>, QuadtreeError> {
            let leaf: Vec<f32> = leaves.iter().map(|v| f(v) as f32).collect();
            let mut p = vec![0.0; pyramid_len(levels)];
            build_pyramid(levels, &leaf, &mut p)?;
            Ok(p)
        };
        Ok(Self {
            levels,
            pyramid: pyramid_of(&|v| v.0)?,
            moments: [
                pyramid_of(&|v| v.1.x)?,
                pyramid_of(&|v| v.1.y)?,
                pyramid_of(&|v| v.1.z)?,
            ],
            cones: (0..=levels)
                .flat_map(|l| {
                    let side = 1u32 << l;
                    (0..side * side).map(move |k| (l, k % side, k / side))
                })
                .collect::<Vec<_>>()
                .into_par_iter()
                .map(|(l, x, y)| node_cone(l, x, y))
                .collect(),
        })
    }

    /// The warp over the pyramid.
    pub fn warp(&self) -> QuadtreeWarp<'_, f32> {
        QuadtreeWarp::new(self.levels, &self.pyramid).expect("a pyramid of a map with light")
    }

    /// The direction at primary sample `u` for the unit normal `n` and its
    /// solid-angle pdf (the square's over `4 pi`).
    pub fn sample(&self, warp: &QuadtreeWarp<'_, f32>, n: DVec3, u: DVec2) -> (DVec3, f64) {
        let (p, pdf) = warp.sample([u.x as f32, u.y as f32], |l, x, y, m| {
            self.weight(n, l, x, y, m)
        });
        let d = square_to_sphere(DVec2::new(p[0] as f64, p[1] as f64));
        (d, pdf as f64 / (4.0 * PI))
    }

    /// The solid-angle pdf of [`Self::sample`] at the unit direction `d` for `n`.
    pub fn pdf(&self, warp: &QuadtreeWarp<'_, f32>, n: DVec3, d: DVec3) -> f64 {
        let p = sphere_to_square(d);
        let pdf = warp.pdf([p.x as f32, p.y as f32], |l, x, y, m| {
            self.weight(n, l, x, y, m)
        });
        pdf as f64 / (4.0 * PI)
    }

    /// Bytes of the pyramids (mass and moments) as `f32`.
    pub fn state_bytes(&self) -> usize {
        16 * self.pyramid.len()
    }

    /// The weight of node `(x, y)` of level `l` (mass `m`) for the normal `n`,
    /// an estimate of `∑ mass max(0, n.l)` over it: `n . moment` (exact) where the
    /// node lies above the horizon of `n`, 0 where it lies below, and across the
    /// horizon the sum of its children's weights, [`ACROSS_DEPTH`] levels down,
    /// where the larger of `n . moment` and a twentieth of the mass times an upper
    /// bound of the cosine stands in (positive wherever the cosine is, which keeps
    /// `L cos / pdf` unbiased).
    fn weight(&self, n: DVec3, l: u32, x: u32, y: u32, m: f32) -> f32 {
        self.weight_below(n, l, x, y, m as f64, ACROSS_DEPTH) as f32
    }

    fn weight_below(&self, n: DVec3, l: u32, x: u32, y: u32, m: f64, depth: u32) -> f64 {
        if m <= 0.0 {
            return 0.0;
        }
        let side = 1usize << l;
        let i = level_offset(l) + y as usize * side + x as usize;
        let moment = DVec3::new(
            self.moments[0][i] as f64,
            self.moments[1][i] as f64,
            self.moments[2][i] as f64,
        );
        let dot = n.dot(moment);
        match horizon(n, l, self.cones[i]) {
            Horizon::Above => dot.max(0.0),
            Horizon::Below => 0.0,
            Horizon::Across(bound) if depth == 0 || l == self.levels => dot.max(0.05 * bound * m),
            Horizon::Across(_) => {
                let child_side = 2 * side;
                let o = level_offset(l + 1);
                let mut sum = 0.0;
                for k in 0..4u32 {
                    let (cx, cy) = (2 * x + (k & 1), 2 * y + (k >> 1));
                    let cm = self.pyramid[o + cy as usize * child_side + cx as usize] as f64;
                    sum += self.weight_below(n, l + 1, cx, cy, cm, depth - 1);
                }
                sum
            }
        }
    }
}

/// Levels below a node across the horizon whose nodes' weights are summed for it.
const ACROSS_DEPTH: u32 = 4;

/// Where a node lies against the horizon of a normal.
enum Horizon {
    /// Entirely above (`n.l > 0` on the whole node).
    Above,
    /// Entirely below.
    Below,
    /// Across it, with an upper bound of `max(0, n.l)` over the node.
    Across(f64),
}

/// Where a node of level `l` with cone `(centre, radius)` ([`node_cone`]) lies
/// against the horizon of `n`, from the angle between `n` and the centre; the top
/// levels, whose nodes span a hemisphere, are always across.
fn horizon(n: DVec3, l: u32, (c, radius): (DVec3, f64)) -> Horizon {
    if l <= UNBOUNDED_LEVELS {
        return Horizon::Across(1.0);
    }
    let angle = acos_clamped(n.dot(c));
    if angle + radius < FRAC_PI_2 {
        Horizon::Above
    } else if angle - radius >= FRAC_PI_2 {
        Horizon::Below
    } else {
        Horizon::Across((angle - radius).max(0.0).cos())
    }
}

/// Node `(x, y)` of level `l` as a cone: its centre's direction and its angular
/// radius (the largest angle from the centre to its corners and edge midpoints,
/// with a quarter's margin for the curved edges of the octahedral cells).
fn node_cone(l: u32, x: u32, y: u32) -> (DVec3, f64) {
    let side = (1u64 << l) as f64;
    let at =
        |a: f64, b: f64| square_to_sphere(DVec2::new((x as f64 + a) / side, (y as f64 + b) / side));
    let c = at(0.5, 0.5);
    let radius = [
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (1.0, 1.0),
        (0.5, 0.0),
        (0.0, 0.5),
        (1.0, 0.5),
        (0.5, 1.0),
    ]
    .iter()
    .map(|&(a, b)| acos_clamped(c.dot(at(a, b))))
    .fold(0.0, f64::max)
        * 1.25;
    (c, radius)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::envmap::test_support::assert_unbiased_irradiance;
    use crate::sphere::envmap::tiny_map;
    use nuld_core::blob::Domain;

    /// The estimate `(1/M) sum L cos / pdf` over the tree's samples is the
    /// irradiance of an independent quadrature, and `pdf` returns the samples'
    /// pdf (but for the rare sample on a leaf's edge: the pdf is constant per
    /// leaf).
    #[test]
    fn the_estimate_with_the_trees_pdf_is_the_irradiance() {
        let dir = std::env::temp_dir().join(format!("nuld-tree-{}", std::process::id()));
        let map = EnvmapDensity::from_file_filtered(tiny_map(&dir), Domain::Sphere).unwrap();
        let tree = EnvmapTree::new(&map, 6).unwrap();
        assert_eq!(tree.state_bytes(), 16 * (4usize.pow(7) - 1) / 3);
        let warp = tree.warp();
        assert_unbiased_irradiance(
            &map,
            1 << 12,
            0.002,
            |n, u| tree.sample(&warp, n, u),
            |n, d| tree.pdf(&warp, n, d),
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A node said to be above the horizon has `n.l > 0` everywhere in it, one
    /// below has `n.l <= 0`, and the bound of one across it is at least the
    /// cosine there (a fine grid of points in nodes of every level, many normals).
    #[test]
    fn nodes_are_placed_against_the_horizon_conservatively() {
        let normals = [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.6, -0.3, 0.1).normalize(),
            DVec3::new(-0.2, 0.9, -0.5).normalize(),
        ];
        for l in 3..8u32 {
            let side = 1u32 << l;
            for node in (0..side * side).step_by(7) {
                let (x, y) = (node % side, node / side);
                for n in normals {
                    let h = horizon(n, l, node_cone(l, x, y));
                    for k in 0..64 {
                        let p = DVec2::new(
                            (x as f64 + ((k % 8) as f64 + 0.5) / 8.0) / side as f64,
                            (y as f64 + ((k / 8) as f64 + 0.5) / 8.0) / side as f64,
                        );
                        let c = n.dot(square_to_sphere(p));
                        match h {
                            Horizon::Above => assert!(c > 0.0, "level {l} ({x}, {y}) {n}: {c}"),
                            Horizon::Below => assert!(c <= 1e-12, "level {l} ({x}, {y}) {n}: {c}"),
                            Horizon::Across(b) => assert!(b >= c - 1e-6 && b > 0.0),
                        }
                    }
                }
            }
        }
    }
}
