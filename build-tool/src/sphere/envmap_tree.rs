//! A map's hierarchical product warp: the map's luminance in a quadtree over the
//! sphere's equal-area octahedral square, each node with its mass, first moment
//! and spread ([`nuld_core::envmap_tree`]), lit at the query by the cosine about
//! the normal and sampled exactly (Clarberg and Akenine-Möller 2008). This module
//! measures the map into the tree's records; the weights, the descent and the pdf
//! are core's, the runtime's own.
//!
//! Unlike [`super::EnvmapPrior`]'s tables per normal, the state is one pyramid of
//! the map, whatever the normals, at the resolution of the leaves (`2^L x 2^L`;
//! `L = 9` puts leaves 0.4° apart, about a 1024 x 512 map's pixels); the cosine
//! enters at the query, through each node's bound of `Σ mass max(0, n.l)`, which
//! is positive wherever the cosine is, so `L cos / pdf` is unbiased.

use super::envmap::EnvmapDensity;
use super::target::DirectionDensity;
use bytemuck::Zeroable;
use glam::{DVec2, DVec3};
use nuld_core::envmap_tree::{
    build, node_count, top_len, top_normal, top_row, EnvmapTree as CoreTree, NodeRecord,
    MAX_TREE_LEVELS, TOP_LEVELS,
};
use nuld_core::quadtree::QuadtreeError;
use nuld_core::sphere::square_to_sphere;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Supersampled points per leaf and axis at `L` levels: about 1024 per axis over
/// the square.
fn supersampling(levels: u32) -> usize {
    (1024usize >> levels.min(10)).max(1)
}

/// A map's tree (see the module docs).
#[derive(Clone, Debug)]
pub struct EnvmapTree {
    /// Levels below the root.
    pub levels: u32,
    /// The records of levels `1..=L` ([`nuld_core::envmap_tree`]'s layout), of the
    /// map's pdf (mass 1 in all).
    pub nodes: Vec<NodeRecord>,
    /// Normals per axis of the top-weight table.
    pub grid: u32,
    /// The top levels' exact weights on `grid x grid` normals
    /// ([`nuld_core::envmap_tree::top_row`]).
    pub top: Vec<f32>,
}

impl EnvmapTree {
    /// The tree of `map` (its pdf proportional to the luminance) with `levels`
    /// levels and its top levels' weights on `grid x grid` normals: each leaf's
    /// mass and moment the means of the map's pdf (and of `pdf l`) over a grid of
    /// points in it, times its solid angle (leaves have equal area). An error if
    /// `levels` is below [`TOP_LEVELS`] or above the tree's limit, or `grid` below
    /// 2.
    pub fn new(map: &EnvmapDensity, levels: u32, grid: u32) -> Result<Self, QuadtreeError> {
        if !(TOP_LEVELS..=MAX_TREE_LEVELS).contains(&levels) {
            return Err(QuadtreeError::Levels(levels));
        }
        let side = 1usize << levels;
        let k = supersampling(levels);
        let area = 4.0 * PI / (side * side * k * k) as f64;
        let leaves: Vec<[f64; 4]> = (0..side * side)
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
                        let m = map.pdf(d) * area;
                        sum += m;
                        moment += m * d;
                    }
                }
                [sum, moment.x, moment.y, moment.z]
            })
            .collect();
        let mut nodes = vec![NodeRecord::zeroed(); node_count(levels)];
        build(levels, &leaves, &mut nodes)?;
        if grid < 2 {
            return Err(QuadtreeError::Length {
                expected: top_len(2) as u64,
                got: 0,
            });
        }
        let per = node_count(TOP_LEVELS);
        let mut top = vec![0.0; top_len(grid)];
        top.par_chunks_mut(per).enumerate().for_each(|(r, row)| {
            let j = [r as u32 % grid, r as u32 / grid];
            top_row(levels, &nodes, top_normal(grid, j), row);
        });
        // Refuses a map without light, as the runtime would.
        CoreTree::new(levels, &nodes, grid, &top)?;
        Ok(Self {
            levels,
            nodes,
            grid,
            top,
        })
    }

    /// The tree as core reads it: checks every record, so take it once for many
    /// samples.
    pub fn tree(&self) -> CoreTree<'_> {
        CoreTree::new(self.levels, &self.nodes, self.grid, &self.top).expect("checked when built")
    }

    /// The direction at primary sample `u` for the unit normal `n` and its
    /// solid-angle pdf, by `tree` (this map's [`Self::tree`]).
    pub fn sample(tree: &CoreTree<'_>, n: DVec3, u: DVec2) -> (DVec3, f64) {
        let (d, pdf) = tree.sample(n.to_array(), u.to_array());
        (DVec3::from_array(d), pdf)
    }

    /// The solid-angle pdf of [`Self::sample`] at the unit direction `d` for `n`.
    pub fn pdf(tree: &CoreTree<'_>, n: DVec3, d: DVec3) -> f64 {
        tree.pdf(n.to_array(), d.to_array())
    }

    /// Bytes of the records and the top table.
    pub fn state_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice()) + std::mem::size_of_val(self.top.as_slice())
    }
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
    /// leaf); the leaves' masses add up to the map's.
    #[test]
    fn the_estimate_with_the_trees_pdf_is_the_irradiance() {
        let dir = std::env::temp_dir().join(format!("nuld-tree-{}", std::process::id()));
        let map = EnvmapDensity::from_file_filtered(tiny_map(&dir), Domain::Sphere).unwrap();
        let tree = EnvmapTree::new(&map, 6, 9).unwrap();
        assert_eq!(tree.state_bytes(), 16 * node_count(6) + 4 * 81 * 84);
        let total: f32 = tree.nodes[..4].iter().map(|r| r.mass()).sum();
        assert!((total - 1.0).abs() < 1e-3, "{total}");
        let core = tree.tree();
        assert_unbiased_irradiance(
            &map,
            1 << 12,
            0.002,
            |n, u| EnvmapTree::sample(&core, n, u),
            |n, d| EnvmapTree::pdf(&core, n, d),
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
