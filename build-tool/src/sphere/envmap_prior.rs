//! The exact product warp of an environment map: `L(l) max(0, n.l)` tabulated on
//! the sphere's equal-area square for each normal `n` of a grid, blended between
//! the grid's normals and sampled exactly ([`nuld_core::marginal2d`]).
//!
//! * **Normals**: `G x G` nodes at the vertices `(a, b) / (G - 1)` of the normal's
//!   octahedral square ([`nuld_core::sphere::square_to_sphere`]); a normal between
//!   them blends the four around it bilinearly in that square.
//! * **Tables**: `S x S` vertices of the directions' octahedral square; vertex
//!   `(i, j)` holds the mean of `L max(0, n.l)` over a `k x k` grid of points in
//!   its dual cell (the square of side `1 / (S - 1)` about it, wrapped across the
//!   octahedral seams), so that a sun smaller than the vertex spacing still lands
//!   in the table. A normal that no light reaches gets the plain cosine lobe.
//! * **Exactness**: whatever the tables approximate, the warp's pdf is the density
//!   of its samples, so `L f cos / pdf` is an unbiased estimate; how well the
//!   tables follow `L cos` decides only its variance. The map's octahedral square
//!   has a constant Jacobian: a solid-angle pdf is the square's over `4 pi`.

use super::envmap::EnvmapDensity;
use super::target::DirectionDensity;
use glam::{DVec2, DVec3};
use nuld_core::marginal2d::{
    tabulate_with_masses, Blend, Marginal2D, Marginal2DError, Marginal2DShape,
};
use nuld_core::sphere::{sphere_to_square, square_to_sphere, wrap_octahedral};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Points per axis of the supersampling grid over the whole square (the `k` of
/// the module docs is this over the table's vertices, at least 1).
const SUPERSAMPLED_AXIS: u32 = 512;

/// A map's product warp over a grid of normals (see the module docs).
#[derive(Clone, Debug)]
pub struct EnvmapPrior {
    /// Normal nodes per axis `G`.
    pub grid: u32,
    /// The tables' shape: `S x S` vertices, `G^2` nodes.
    pub shape: Marginal2DShape,
    /// Normalized vertex values, node `a + G b` after node (see
    /// [`nuld_core::marginal2d::tabulate`] for the layout).
    pub data: Vec<f32>,
    /// Marginal CDFs.
    pub marginal: Vec<f32>,
    /// Conditional CDFs.
    pub conditional: Vec<f32>,
}

impl EnvmapPrior {
    /// The prior of `map` (whose pdf is proportional to its luminance `L`) on
    /// `grid x grid` normals and `size x size` table vertices, tables in `f32`
    /// (as a blob stores them). `O(G^2 R^2)` with `R = 512` supersampled points
    /// per axis, in parallel over the normals; the same bits for any thread count.
    /// An error if `grid` or `size` is below 2.
    pub fn new(map: &EnvmapDensity, grid: u32, size: u32) -> Result<Self, Marginal2DError> {
        if grid < 2 || size < 2 {
            return Err(Marginal2DError::Shape);
        }
        let shape = Marginal2DShape {
            size: [size, size],
            nodes: grid.checked_mul(grid).ok_or(Marginal2DError::Shape)?,
        };
        let k = SUPERSAMPLED_AXIS.div_ceil(size).max(1) as usize;
        let s = size as usize;
        let h = 1.0 / (s - 1) as f64;
        // The supersampled points, `s k` per axis: vertex i's sub-point a sits at
        // `(i - 1/2 + (a + 1/2) / k) h`, wrapped onto the sphere.
        let coord = |q: usize| ((q / k) as f64 - 0.5 + ((q % k) as f64 + 0.5) / k as f64) * h;
        let axis = s * k;
        let points: Vec<(DVec3, f64)> = (0..axis * axis)
            .into_par_iter()
            .map(|q| {
                let p = wrap_octahedral(DVec2::new(coord(q % axis), coord(q / axis)));
                let d = square_to_sphere(p);
                (d, map.pdf(d))
            })
            .collect();
        let g = grid as usize;
        let tables: Vec<Vec<f32>> = (0..g * g)
            .into_par_iter()
            .map(|node| {
                let n = square_to_sphere(DVec2::new(
                    (node % g) as f64 / (g - 1) as f64,
                    (node / g) as f64 / (g - 1) as f64,
                ));
                let lit = vertex_means(&points, s, k, |d, l| l * n.dot(d).max(0.0));
                if lit.iter().any(|&v| v > 0.0) {
                    lit
                } else {
                    vertex_means(&points, s, k, |d, _| n.dot(d).max(0.0))
                }
            })
            .collect();
        let ([data, marginal, conditional], _) = tabulated(shape, &tables)?;
        Ok(Self {
            grid,
            shape,
            data,
            marginal,
            conditional,
        })
    }

    /// The warp over the tables.
    pub fn warp(&self) -> Marginal2D<'_, f32> {
        Marginal2D::new(self.shape, &self.data, &self.marginal, &self.conditional)
            .expect("tables written by tabulate")
    }

    /// The blend of the normals around the unit normal `n`.
    pub fn blend(&self, n: DVec3) -> Blend<f32> {
        let p = sphere_to_square(n);
        Blend::multilinear(&[p.x as f32, p.y as f32], &[self.grid, self.grid])
    }

    /// The direction at primary sample `u` for the normal `n`, and its solid-angle
    /// pdf (per steradian).
    pub fn sample(&self, warp: &Marginal2D<'_, f32>, n: DVec3, u: DVec2) -> (DVec3, f64) {
        let (p, pdf) = warp.sample([u.x as f32, u.y as f32], &self.blend(n));
        let d = square_to_sphere(DVec2::new(p[0] as f64, p[1] as f64));
        (d, pdf as f64 / (4.0 * PI))
    }

    /// The solid-angle pdf of [`Self::sample`] at the unit direction `d` for `n`.
    pub fn pdf(&self, warp: &Marginal2D<'_, f32>, n: DVec3, d: DVec3) -> f64 {
        let p = sphere_to_square(d);
        warp.pdf([p.x as f32, p.y as f32], &self.blend(n)) as f64 / (4.0 * PI)
    }

    /// Bytes the tables take as `f32`: data, conditional and marginal CDFs.
    pub fn state_bytes(&self) -> usize {
        4 * (self.data.len() + self.conditional.len() + self.marginal.len())
    }
}

/// The node tables `tables` (each `nx ny` vertex values) of a warp of `shape`
/// normalized, with their cumulative tables: `[data, marginal, conditional]` as
/// [`Marginal2D::new`] reads them, and each node's mass before normalization
/// ([`tabulate_with_masses`]).
pub(crate) fn tabulated(
    shape: Marginal2DShape,
    tables: &[Vec<f32>],
) -> Result<([Vec<f32>; 3], Vec<f32>), Marginal2DError> {
    let mut data = tables.concat();
    let mut marginal = vec![0.0; shape.marginal_len().ok_or(Marginal2DError::Shape)?];
    let mut conditional = vec![0.0; data.len()];
    let mut masses = vec![0.0; shape.nodes as usize];
    tabulate_with_masses(
        shape,
        &mut data,
        &mut marginal,
        &mut conditional,
        &mut masses,
    )?;
    Ok(([data, marginal, conditional], masses))
}

/// Per table vertex, the mean of `value(direction, L)` over its `k x k`
/// supersampled points (`points` row-major, `s k` per axis).
fn vertex_means(
    points: &[(DVec3, f64)],
    s: usize,
    k: usize,
    value: impl Fn(DVec3, f64) -> f64,
) -> Vec<f32> {
    let axis = s * k;
    let mut out = vec![0.0f32; s * s];
    for j in 0..s {
        for i in 0..s {
            let mut sum = 0.0;
            for b in 0..k {
                let row = (j * k + b) * axis + i * k;
                for &(d, l) in &points[row..row + k] {
                    sum += value(d, l);
                }
            }
            out[j * s + i] = (sum / (k * k) as f64) as f32;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::envmap::test_support::assert_unbiased_irradiance;
    use crate::sphere::envmap::tiny_map;
    use nuld_core::blob::Domain;

    /// The estimate `(1/M) sum L cos / pdf` over the prior's samples is the
    /// irradiance of an independent quadrature, at normals on and between the
    /// grid's nodes: the pdf is the samples' density, whatever the tables
    /// approximate; and `pdf` returns the samples' pdf.
    #[test]
    fn the_estimate_with_the_priors_pdf_is_the_irradiance() {
        let dir = std::env::temp_dir().join(format!("nuld-prior-{}", std::process::id()));
        let map = EnvmapDensity::from_file_filtered(tiny_map(&dir), Domain::Sphere).unwrap();
        let prior = EnvmapPrior::new(&map, 5, 24).unwrap();
        assert_eq!(prior.state_bytes(), 4 * (2 * 25 * 24 * 24 + 25 * 24));
        let warp = prior.warp();
        assert_unbiased_irradiance(
            &map,
            1 << 16,
            0.0,
            |n, u| prior.sample(&warp, n, u),
            |n, d| prior.pdf(&warp, n, d),
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
