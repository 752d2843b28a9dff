//! [`Baseline`]: the uniform 2D baseline methods as one enum, for evaluation loops.

use glam::DVec2;

use super::{
    gaussian_blue_noise, owen_sobol, poisson_disk_elimination, random, scrambled_halton,
    sliced_optimal_transport, sobol_cranley_patterson, GBN_DEFAULT_ITERATIONS,
    SOT_DEFAULT_ITERATIONS,
};

/// A baseline point-set generator for the uniform target on `[0,1)^2`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Baseline {
    /// Independent uniform points ([`random`]).
    Random,
    /// Owen-scrambled Sobol ([`owen_sobol`]; at most 2^16 points).
    OwenSobol,
    /// Cranley–Patterson rotated plain Sobol ([`sobol_cranley_patterson`]).
    SobolCp,
    /// Owen-scrambled Halton, bases 2 and 3 ([`scrambled_halton`]).
    Halton,
    /// Yuksel's sample-elimination Poisson disk ([`poisson_disk_elimination`]).
    PoissonDisk,
    /// Sliced optimal transport ([`sliced_optimal_transport`], default iterations).
    Sot,
    /// Gaussian blue noise ([`gaussian_blue_noise`], default iterations).
    Gbn,
}

impl Baseline {
    /// Every method, in the order above.
    pub const ALL: [Baseline; 7] = [
        Baseline::Random,
        Baseline::OwenSobol,
        Baseline::SobolCp,
        Baseline::Halton,
        Baseline::PoissonDisk,
        Baseline::Sot,
        Baseline::Gbn,
    ];

    /// Kebab-case name: `random`, `owen-sobol`, `sobol-cp`, `halton`,
    /// `poisson-disk`, `sot`, `gbn`.
    pub fn name(self) -> &'static str {
        match self {
            Baseline::Random => "random",
            Baseline::OwenSobol => "owen-sobol",
            Baseline::SobolCp => "sobol-cp",
            Baseline::Halton => "halton",
            Baseline::PoissonDisk => "poisson-disk",
            Baseline::Sot => "sot",
            Baseline::Gbn => "gbn",
        }
    }

    /// The method whose [`Baseline::name`] is `name`, if any.
    pub fn from_name(name: &str) -> Option<Baseline> {
        Self::ALL.into_iter().find(|b| b.name() == name)
    }

    /// `n` points of this method for the uniform target, fixed by `seed`.
    /// [`Baseline::OwenSobol`] folds the seed to 32 bits (`seed ^ (seed >> 32)`, the
    /// identity below 2^32) and clamps `n` to 2^16; SOT and GBN use their default
    /// iteration counts. Cost: see each generator.
    pub fn generate(self, n: usize, seed: u64) -> Vec<DVec2> {
        match self {
            Baseline::Random => random(n, seed),
            Baseline::OwenSobol => owen_sobol(n, (seed ^ (seed >> 32)) as u32),
            Baseline::SobolCp => sobol_cranley_patterson(n, seed),
            Baseline::Halton => scrambled_halton(n, seed),
            Baseline::PoissonDisk => poisson_disk_elimination(n, seed),
            Baseline::Sot => sliced_optimal_transport(n, seed, None, SOT_DEFAULT_ITERATIONS),
            Baseline::Gbn => gaussian_blue_noise(n, seed, None, GBN_DEFAULT_ITERATIONS),
        }
    }
}

impl std::fmt::Display for Baseline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::asd_uniform;

    #[test]
    fn every_method_generates_n_seeded_points_in_the_square() {
        for b in Baseline::ALL {
            assert_eq!(Baseline::from_name(b.name()), Some(b));
            assert_eq!(b.to_string(), b.name());
            let pts = b.generate(128, 5);
            assert_eq!(pts.len(), 128, "{b}");
            assert!(
                pts.iter()
                    .all(|p| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)),
                "{b}"
            );
            assert_eq!(pts, b.generate(128, 5), "{b}");
            assert_ne!(pts, b.generate(128, 6), "{b}");
            eprintln!("{b:>12}: asd {:.3e}", asd_uniform(&pts));
        }
        assert_eq!(Baseline::from_name("nope"), None);
        for b in Baseline::ALL {
            for n in [0usize, 1, 2, 3] {
                let pts = b.generate(n, 1);
                assert_eq!(pts.len(), n, "{b}");
                assert!(pts
                    .iter()
                    .all(|p| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)));
            }
        }
    }

    #[test]
    fn optimizers_do_not_depend_on_the_thread_count() {
        let d = crate::density::parse_spec("gaussian:0.4,0.6,0.2").unwrap();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                (
                    crate::baselines::sliced_optimal_transport(200, 9, Some(d.as_ref()), 6),
                    crate::baselines::gaussian_blue_noise(200, 9, Some(d.as_ref()), 6),
                    Baseline::Sot.generate(200, 9),
                    Baseline::Gbn.generate(200, 9),
                )
            })
        };
        assert_eq!(run(1), run(3));
    }
}
