//! Owen-scrambled Sobol points in `[0,1)^2` (Burley 2020 hash-based scrambling, via
//! the `sobol_burley` crate).

use glam::DVec2;

/// The largest point count `sobol_burley` supports (sample index < 2^16).
pub const OWEN_SOBOL_MAX_POINTS: usize = 1 << 16;

/// The first `n` points of the Owen-scrambled Sobol sequence with scramble `seed`,
/// dimensions 0 and 1. For `n` a power of two these form a (0, m, 2)-net: every
/// elementary interval of area `1/n` holds exactly one point. `n` is clamped to
/// [`OWEN_SOBOL_MAX_POINTS`].
pub fn owen_sobol(n: usize, seed: u32) -> Vec<DVec2> {
    (0..n.min(OWEN_SOBOL_MAX_POINTS) as u32)
        .map(|i| {
            DVec2::new(
                sobol_burley::sample(i, 0, seed) as f64,
                sobol_burley::sample(i, 1, seed) as f64,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_design_reference_values() {
        let want = [
            0.262153625,
            0.971313715,
            0.682580113,
            0.022617221,
            0.217882037,
            0.608052135,
        ];
        let pts = owen_sobol(6, 0);
        for (p, w) in pts.iter().zip(want) {
            assert!((p.x - w).abs() < 1e-8, "{} vs {w}", p.x);
        }
    }

    #[test]
    fn power_of_two_sets_are_0_m_2_nets() {
        let n = 256usize;
        for seed in [0, 1, 99] {
            let pts = owen_sobol(n, seed);
            // Every elementary interval shape 2^a x 2^(8-a) holds exactly one point.
            for a in 0..=8u32 {
                let (cx, cy) = (1usize << a, n >> a);
                let mut seen = vec![0u32; n];
                for p in &pts {
                    let i = (p.x * cx as f64) as usize;
                    let j = (p.y * cy as f64) as usize;
                    seen[j * cx + i] += 1;
                }
                assert!(seen.iter().all(|&c| c == 1), "seed {seed}, a = {a}");
            }
        }
    }
}
