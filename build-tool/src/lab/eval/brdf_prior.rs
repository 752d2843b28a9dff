//! How well the tabulated BRDF warp ([`BrdfPrior`]) serves held-out conditions, by
//! condition grid, table size and table space (`build-tool eval brdf-prior`):
//! [`super::prior_judge`]'s ratios at held-out `(roughness, θo, metallic)`, with
//! the renderer's VNDF/cosine mixture warp (today's prior) as a row of its own;
//! and the bytes the tables take.

use super::prior_judge::{score, Judge, JudgeSettings};
use crate::seeding::rng;
use crate::sphere::brdf_prior::{BrdfPrior, PriorSpace};
use crate::sphere::{BrdfTarget, DirectionDensity, TabulatedWarp};
use anyhow::Result;
use nuld_core::blob::Domain;
use rand::Rng;
use serde::Serialize;
use std::time::Instant;

/// Cells per axis of the exact inverse CDF of a held-out condition's target
/// (2 x 2 midpoints per cell), as `eval conditional`'s.
const EXACT_TABULATION: usize = 1024;

/// What [`evaluate`] measures.
#[derive(Clone, Debug, Serialize)]
pub struct BrdfPriorSettings {
    /// Condition grids `[G_r, G_t, G_m]`.
    pub grids: Vec<[u32; 3]>,
    /// Table sizes `S` (vertices per axis).
    pub sizes: Vec<u32>,
    /// Table spaces.
    pub spaces: Vec<PriorSpace>,
    /// Points per set.
    pub n: u32,
    /// Held-out conditions: roughness `0.1 + 0.9 u^2` (the smooth end is the
    /// hard one), `θo` uniform in `[0°, 85°]`, metallic 0, 0.5, 1 and uniform in
    /// turn.
    pub conditions: usize,
    /// Sets averaged per condition and method.
    pub instances: u32,
    /// Measured caps per condition.
    pub caps: usize,
    /// Seed of the conditions, caps, scrambles and shifts.
    pub seed: u64,
}

impl Default for BrdfPriorSettings {
    fn default() -> Self {
        Self {
            grids: vec![[10, 12, 3]],
            sizes: vec![32, 64, 128],
            spaces: vec![PriorSpace::Direction, PriorSpace::HalfVector],
            n: 64,
            conditions: 16,
            instances: 8,
            caps: 4096,
            seed: 0,
        }
    }
}

/// One prior's figures over the held-out conditions.
#[derive(Clone, Debug, Serialize)]
pub struct BrdfPriorRow {
    /// `mixture` (the VNDF/cosine warp) or the table space's name.
    pub kind: String,
    /// Condition nodes per axis (0 for the mixture).
    pub grid: [u32; 3],
    /// Table vertices per axis (0 for the mixture).
    pub size: u32,
    /// Bytes of the tables as `f32`.
    pub state_bytes: usize,
    /// Seconds to build the tables.
    pub build_s: f64,
    /// Owen-Sobol through the prior over the baseline: mean and worst.
    pub owen_sobol: (f64, f64),
    /// A shifted lattice through the prior over the baseline: mean and worst.
    pub lattice: (f64, f64),
}

/// The held-out conditions of `s` (see [`BrdfPriorSettings::conditions`]).
pub fn held_out(s: &BrdfPriorSettings) -> Vec<[f64; 3]> {
    let mut r = rng(s.seed, 0x6272_6466);
    (0..s.conditions)
        .map(|k| {
            let u: f64 = r.random();
            let t = 85.0 * r.random::<f64>();
            let m = match k % 4 {
                0 => 0.0,
                1 => 0.5,
                2 => 1.0,
                _ => r.random(),
            };
            [0.1 + 0.9 * u * u, t, m]
        })
        .collect()
}

/// The judge settings of `s`.
pub fn judging(s: &BrdfPriorSettings) -> JudgeSettings {
    JudgeSettings {
        n: s.n,
        instances: s.instances,
        caps: s.caps,
        seed: s.seed,
    }
}

/// The judge of the condition `c = [roughness, θo in degrees, metallic]` on the
/// hemisphere, its caps drawn from `index`: the baseline is Owen-Sobol through
/// the exact inverse CDF of the condition's own target (tabulated on 1024 x 1024
/// cells).
pub fn judge(c: [f64; 3], judging: &JudgeSettings, index: u64) -> Result<Judge<BrdfTarget>> {
    let target = BrdfTarget::metallic(c[0], c[1], c[2], Domain::Hemisphere)?;
    let exact = TabulatedWarp::new(&target, EXACT_TABULATION, 2)?;
    Ok(Judge::new(
        target.clone(),
        &target,
        &|u| exact.warp(u),
        judging,
        index,
    ))
}

/// The figures of the mixture and of every `(space, grid, size)` of `s`, with
/// `progress` told after each held-out condition's judge and each configuration;
/// and the judges (for a baked sampler's figures, [`super::brdf_sampler`]).
pub fn evaluate(
    s: &BrdfPriorSettings,
    progress: &dyn Fn(&str),
) -> Result<(Vec<BrdfPriorRow>, Vec<Judge<BrdfTarget>>)> {
    let judging = judging(s);
    let mut judges: Vec<Judge<BrdfTarget>> = Vec::new();
    for (index, c) in held_out(s).into_iter().enumerate() {
        judges.push(judge(c, &judging, index as u64)?);
        progress(&format!("condition {index} judged"));
    }
    anyhow::ensure!(!judges.is_empty(), "no held-out condition");
    let mut rows = Vec::new();
    let (owen_sobol, lattice) = score(&judges, &judging, &|t: &BrdfTarget, u| t.sample(u));
    rows.push(BrdfPriorRow {
        kind: "mixture".into(),
        grid: [0; 3],
        size: 0,
        state_bytes: 0,
        build_s: 0.0,
        owen_sobol,
        lattice,
    });
    for &space in &s.spaces {
        for &grid in &s.grids {
            for &size in &s.sizes {
                let t = Instant::now();
                let prior = BrdfPrior::new(grid, size, space)?;
                let build_s = t.elapsed().as_secs_f64();
                let warp = prior.warp();
                let through = |t: &BrdfTarget, u| {
                    let c = [t.roughness(), t.theta_o_deg(), t.metallic_value()];
                    prior.sample(&warp, c, u).0
                };
                let (owen_sobol, lattice) = score(&judges, &judging, &through);
                rows.push(BrdfPriorRow {
                    kind: space.name(),
                    grid,
                    size,
                    state_bytes: prior.state_bytes(),
                    build_s,
                    owen_sobol,
                    lattice,
                });
                progress(&format!("{} {grid:?} x {size} done", space.name()));
            }
        }
    }
    Ok((rows, judges))
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[BrdfPriorRow]) -> String {
    let mut out = String::from(
        "| prior | conditions (r x θo x m) | table S | state (f32) | build s | Owen-Sobol through the prior / baseline (mean, worst) | shifted lattice through the prior / baseline (mean, worst) |\n|---|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} x {} x {} | {} | {:.1} MB | {:.1} | {:.3}, {:.3} | {:.3}, {:.3} |\n",
            r.kind,
            r.grid[0],
            r.grid[1],
            r.grid[2],
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

    /// A row per configuration and the mixture's, finite ratios with the worst at
    /// least the mean, the state the shape implies; held-out conditions in range
    /// with every metallic class.
    #[test]
    fn rows_cover_every_configuration() {
        let s = BrdfPriorSettings {
            grids: vec![[2, 3, 2]],
            sizes: vec![8, 16],
            spaces: vec![PriorSpace::Direction, PriorSpace::HalfVector],
            n: 16,
            conditions: 4,
            instances: 2,
            caps: 256,
            seed: 3,
        };
        let conds = held_out(&s);
        assert!(conds
            .iter()
            .all(|c| (0.1..=1.0).contains(&c[0]) && (0.0..=85.0).contains(&c[1])));
        assert_eq!(
            conds.iter().map(|c| c[2]).take(3).collect::<Vec<_>>(),
            [0.0, 0.5, 1.0]
        );
        let (rows, judges) = evaluate(&s, &|_| {}).unwrap();
        assert_eq!(judges.len(), 4);
        assert_eq!(rows.len(), 5);
        assert_eq!(rows[0].kind, "mixture");
        for r in &rows[1..] {
            assert_eq!(
                r.state_bytes,
                4 * 12 * (2 * (r.size * r.size) as usize + r.size as usize + 1)
            );
        }
        for r in &rows {
            assert!(
                r.owen_sobol.0.is_finite() && r.lattice.0.is_finite(),
                "{r:?}"
            );
            assert!(r.owen_sobol.1 >= r.owen_sobol.0 && r.lattice.1 >= r.lattice.0);
        }
        assert_eq!(markdown(&rows).lines().count(), 7);
    }
}
