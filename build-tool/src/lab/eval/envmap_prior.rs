//! How well a map's product warp ([`EnvmapPrior`]) serves held-out normals, by
//! normal grid and table size (`build-tool eval envmap-prior`): the cap L2
//! discrepancy (paper Eq. 9, `theta` uniform, Monte Carlo over measured caps) of
//! `N` points through the prior's exact warp at the normal, for Owen-Sobol points
//! and for a randomly shifted rank-1 lattice, over that of Owen-Sobol through the
//! exact inverse CDF of the normal's own `L cos` (the baseline of the environment
//! sampler's quality check); and the bytes the tables take.
//!
//! The same for the map's hierarchical product warp ([`EnvmapTree`]), by depth.
//!
//! Points through the prior sample a blend of the grid's tables, not the normal's
//! own target, so a ratio above 1 for Owen-Sobol is the price of the blend and of
//! the tables' resolution; the lattice shows what structure in primary space
//! keeps through the warp.

use super::prior_judge::{score, Judge, JudgeSettings};
use crate::seeding::rng;
use crate::sphere::{DirectionDensity, EnvmapDensity, EnvmapPrior, EnvmapTree};
use anyhow::Result;
use glam::{DVec2, DVec3};
use nuld_core::sphere::square_to_sphere;
use rand::Rng;
use serde::Serialize;
use std::time::Instant;

/// What [`evaluate`] measures.
#[derive(Clone, Debug, Serialize)]
pub struct PriorSettings {
    /// Normal grids `G` (nodes per axis).
    pub grids: Vec<u32>,
    /// Table sizes `S` (vertices per axis).
    pub sizes: Vec<u32>,
    /// Depths `L` of the hierarchical warp (`2^L x 2^L` leaves).
    pub levels: Vec<u32>,
    /// Points per set.
    pub n: u32,
    /// Held-out normals drawn (uniform on the sphere; unlit ones are left out).
    pub normals: usize,
    /// Sets averaged per normal and method.
    pub instances: u32,
    /// Measured caps per normal.
    pub caps: usize,
    /// Seed of the normals, caps, scrambles and shifts.
    pub seed: u64,
}

impl Default for PriorSettings {
    fn default() -> Self {
        Self {
            grids: vec![9, 13, 17],
            sizes: vec![32, 64, 128],
            levels: vec![8, 9, 10],
            n: 64,
            normals: 16,
            instances: 8,
            caps: 4096,
            seed: 0,
        }
    }
}

/// One prior's figures over the held-out normals.
#[derive(Clone, Debug, Serialize)]
pub struct PriorRow {
    /// `table` ([`EnvmapPrior`]) or `tree` ([`EnvmapTree`]).
    pub kind: &'static str,
    /// Normal nodes per axis (0 for a tree: it has none).
    pub grid: u32,
    /// Table vertices per axis, or a tree's leaves per axis.
    pub size: u32,
    /// Bytes of the tables as `f32`.
    pub state_bytes: usize,
    /// Seconds to build the tables.
    pub build_s: f64,
    /// Owen-Sobol through the prior over the baseline: mean and worst over normals.
    pub owen_sobol: (f64, f64),
    /// A shifted lattice through the prior over the baseline: mean and worst.
    pub lattice: (f64, f64),
}

/// The figures of every `(grid, size)` of `s` on `map`, with `progress` told
/// after each held-out normal's judge and each configuration.
pub fn evaluate(
    map: &EnvmapDensity,
    s: &PriorSettings,
    progress: &dyn Fn(&str),
) -> Result<Vec<PriorRow>> {
    let judging = JudgeSettings {
        n: s.n,
        instances: s.instances,
        caps: s.caps,
        seed: s.seed,
    };
    let mut r = rng(s.seed, 0x7072_696f);
    let mut judges: Vec<Judge<DVec3>> = Vec::new();
    for index in 0..s.normals {
        let normal = square_to_sphere(DVec2::new(r.random(), r.random()));
        let (lit, irradiance) = map.cosine_weighted(normal)?;
        if irradiance <= 0.0 {
            continue;
        }
        // A lit map's own warp is its exact inverse CDF.
        let exact = |u| lit.sample(u);
        judges.push(Judge::new(normal, &lit, &exact, &judging, index as u64));
        progress(&format!("normal {index} judged"));
    }
    anyhow::ensure!(!judges.is_empty(), "no held-out normal receives light");
    let mut rows = Vec::new();
    for &grid in &s.grids {
        for &size in &s.sizes {
            let t = Instant::now();
            let prior = EnvmapPrior::new(map, grid, size)?;
            let build_s = t.elapsed().as_secs_f64();
            let warp = prior.warp();
            let (owen_sobol, lattice) =
                score(&judges, &judging, &|n, u| prior.sample(&warp, *n, u).0);
            rows.push(PriorRow {
                kind: "table",
                grid,
                size,
                state_bytes: prior.state_bytes(),
                build_s,
                owen_sobol,
                lattice,
            });
            progress(&format!("grid {grid}, size {size} done"));
        }
    }
    for &grid in &s.grids {
        for &levels in &s.levels {
            let t = Instant::now();
            let tree = EnvmapTree::new(map, levels, grid)?;
            let build_s = t.elapsed().as_secs_f64();
            let core = tree.tree();
            let warp = |n: &DVec3, u| EnvmapTree::sample(&core, *n, u).0;
            let (owen_sobol, lattice) = score(&judges, &judging, &warp);
            rows.push(PriorRow {
                kind: "tree",
                grid,
                size: 1 << levels,
                state_bytes: tree.state_bytes(),
                build_s,
                owen_sobol,
                lattice,
            });
            progress(&format!(
                "tree of {levels} levels, {grid} x {grid} top normals done"
            ));
        }
    }
    Ok(rows)
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[PriorRow]) -> String {
    let mut out = String::from(
        "| prior | normals G | table S / leaves | state (f32) | build s | Owen-Sobol through the prior / baseline (mean, worst) | shifted lattice through the prior / baseline (mean, worst) |\n|---|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} | {} | {:.1} MB | {:.1} | {:.3}, {:.3} | {:.3}, {:.3} |\n",
            r.kind,
            r.grid,
            r.size,
            r.state_bytes as f64 / 1e6,
            r.build_s,
            r.owen_sobol.0,
            r.owen_sobol.1,
            r.lattice.0,
            r.lattice.1
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::envmap::tiny_map;
    use nuld_core::blob::Domain;

    /// On the tiny sky: a row per configuration, finite ratios with the worst at
    /// least the mean, and the state the shape implies.
    #[test]
    fn rows_cover_every_configuration() {
        let dir = std::env::temp_dir().join(format!("nuld-eval-prior-{}", std::process::id()));
        let map = EnvmapDensity::from_file_filtered(tiny_map(&dir), Domain::Sphere).unwrap();
        let s = PriorSettings {
            grids: vec![2, 9],
            sizes: vec![16],
            levels: vec![4],
            n: 16,
            normals: 4,
            instances: 4,
            caps: 512,
            seed: 1,
        };
        let rows = evaluate(&map, &s, &|_| {}).unwrap();
        assert_eq!(rows.len(), 4);
        assert_eq!((rows[2].kind, rows[2].size, rows[2].grid), ("tree", 16, 2));
        // The records, the top table (levels 1 to 4: 340 nodes a normal) and
        // the corners (no leaf of the tiny map is sharp enough for detail).
        assert_eq!(
            rows[3].state_bytes,
            16 * ((4usize.pow(5) - 1) / 3 - 1) + 4 * 81 * ((4usize.pow(5) - 4) / 3) + 4 * 17 * 17
        );
        for r in &rows[..2] {
            let nodes = (r.grid * r.grid) as usize;
            assert_eq!(r.state_bytes, 4 * nodes * (2 * 16 * 16 + 16));
            assert!(
                r.owen_sobol.0.is_finite() && r.lattice.0.is_finite(),
                "{r:?}"
            );
            assert!(r.owen_sobol.1 >= r.owen_sobol.0 && r.lattice.1 >= r.lattice.0);
        }
        for r in &rows[2..] {
            assert!(r.owen_sobol.0.is_finite() && r.lattice.0.is_finite());
        }
        assert_eq!(markdown(&rows).lines().count(), 6);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
