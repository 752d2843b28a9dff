//! What the selection examples (`envmap_selection`, `envmap_instance_selection`,
//! `brdf_selection`) share: the candidate sets a table of choices would choose
//! among, and their ranking.
use glam::{DVec2, DVec3};
use nuld_build_tool::lab::eval::prior_judge::Judge;
use nuld_core::network::{shifted_lattice_point, OffsetHash};

/// The rank-1 lattice of `n` points with generator `g` shifted by the first
/// `count` offsets of the salted instance hash (`OffsetHash::Salted`, not
/// wrapped at a shape's instance slots: every candidate its own shift), in the
/// primary square.
pub fn candidates(n: u32, g: u32, count: u32) -> Vec<Vec<DVec2>> {
    (0..count)
        .map(|k| {
            let z = OffsetHash::Salted.offset::<f64>(k);
            (0..n)
                .map(|i| DVec2::from(shifted_lattice_point(i, n, g, z)))
                .collect()
        })
        .collect()
}

/// Indices of `scores` from best (lowest) to worst.
#[allow(dead_code)] // the selection examples' (`envmap_curve` only scores)
pub fn ranking(scores: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..scores.len()).collect();
    order.sort_by(|&a, &b| scores[a].total_cmp(&scores[b]));
    order
}

/// Every set's judged cap L2 over the judge's baseline (lower is better).
pub fn scores<C: Sync>(sets: &[Vec<DVec3>], judge: &Judge<C>) -> Vec<f64> {
    sets.iter()
        .map(|dirs| judge.d(dirs) / judge.baseline())
        .collect()
}

/// The mean over `candidates` (primary-square sets) of their judged cap L2 over
/// the judge's baseline once each point is mapped to a direction by `to`.
#[allow(dead_code)] // the BRDF prior examples'
pub fn mean_score_through<C: Sync>(
    candidates: &[Vec<DVec2>],
    judge: &Judge<C>,
    to: &dyn Fn(DVec2) -> DVec3,
) -> f64 {
    let sets: Vec<Vec<DVec3>> = (candidates.iter())
        .map(|set| set.iter().map(|&u| to(u)).collect())
        .collect();
    let s = scores(&sets, judge);
    s.iter().sum::<f64>() / s.len() as f64
}

/// Mean of `scores` at the first `count` indices of `order`.
#[allow(dead_code)] // the selection examples' (`envmap_curve` only scores)
pub fn mean_of(scores: &[f64], order: &[usize], count: usize) -> f64 {
    order[..count].iter().map(|&k| scores[k]).sum::<f64>() / count as f64
}

/// Prints a condition `[roughness, θo, metallic]`'s row of figures.
#[allow(dead_code)] // the BRDF examples' (the environment ones print normals)
pub fn print_row(c: [f64; 3], row: &[f64]) {
    let cells: Vec<String> = row.iter().map(|x| format!("{x:.3}")).collect();
    println!(
        "({:.2}, {:4.1}°, {:.2}): {}",
        c[0],
        c[1],
        c[2],
        cells.join(" ")
    );
}
