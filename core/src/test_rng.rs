//! A deterministic stream of uniform numbers for the crate's tests (SplitMix64):
//! `core` has no `rand`; and the chi-square check their histograms share.

extern crate std;

/// SplitMix64 (Steele, Lea and Flood 2014) from seed `0`.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    /// The next uniform number in `[0, 1)`, 53 bits.
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The chi-square check the warps' tests share: `samples` points of `draw` (each
/// in the unit square) counted on `bins x bins` bins, against `mean(i, j)`, the
/// density's mean over bin `(i, j)`. The statistic must lie within 5 standard
/// deviations of its degrees of freedom, no point may fall where the density is
/// 0, and, with `far_from_uniform`, uniform points must fail the same check by
/// a factor of 10 (so that it can fail). `label` names the case in a failure.
pub(crate) fn assert_chi_square(
    label: &str,
    samples: u32,
    bins: usize,
    mut draw: impl FnMut() -> [f64; 2],
    mean: impl Fn(usize, usize) -> f64,
    far_from_uniform: bool,
) {
    let mut counts = std::vec![0u32; bins * bins];
    for _ in 0..samples {
        let p = draw();
        let i = ((p[0] * bins as f64) as usize).min(bins - 1);
        let j = ((p[1] * bins as f64) as usize).min(bins - 1);
        counts[j * bins + i] += 1;
    }
    let (mut chi2, mut dof, mut uniform) = (0.0, 0, 0.0);
    let flat = samples as f64 / (bins * bins) as f64;
    for j in 0..bins {
        for i in 0..bins {
            let expected = samples as f64 * mean(i, j) / (bins * bins) as f64;
            let c = counts[j * bins + i] as f64;
            uniform += (c - flat).powi(2) / flat;
            if expected > 0.0 {
                chi2 += (c - expected).powi(2) / expected;
                dof += 1;
            } else {
                assert_eq!(c, 0.0, "{label}: a sample where the density is 0");
            }
        }
    }
    let sd = (2.0 * dof as f64).sqrt();
    assert!(
        chi2 < dof as f64 + 5.0 * sd,
        "{label}: chi-square {chi2} over {dof}"
    );
    if far_from_uniform {
        assert!(
            uniform > 10.0 * (dof as f64 + 5.0 * sd),
            "{label}: uniform points pass"
        );
    }
}
