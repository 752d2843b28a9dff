//! Optimization of direction sets on the sphere or the upper hemisphere (paper
//! §3.5): the points are kept in the equal-area square of the domain, mapped to
//! directions, scored by the spherical-cap estimator of
//! [`crate::discrepancy::caps`], and the gradient is chained back through the map.

use super::AreaOption;
use crate::baselines::warped_owen_sobol_directions;
use crate::descent::{local_factor, Adam, Descent, EpochLoss, EpochReport, Schedule};
use crate::discrepancy::caps::{cap_loss_and_gradient, epoch_caps, CapArea, CapTree};
use crate::discrepancy::GradientPath;
use crate::seeding::rng;
use crate::sphere::geometry::{fold, map_jacobian};
use crate::sphere::{CapMeasureTable, DirectionDensity};
use glam::{DVec2, DVec3};
use serde::Serialize;

/// Settings of a direction-set optimization. Defaults chosen by experiment
/// (README.md lists the measurements).
#[derive(Clone, Debug, Serialize)]
pub struct DirectionConfig {
    /// Number of epochs.
    pub epochs: usize,
    /// Caps drawn per epoch (`M`).
    pub caps: usize,
    /// Adam step at the start, in units of the angular point spacing
    /// `sqrt(4 pi / N)` (converted to square units by the map's scale).
    pub learning_rate: f64,
    /// Step at the end relative to the start (cosine decay in between).
    pub final_learning_rate_ratio: f64,
    /// Sigmoid sharpness at the start, in units of the inverse angular spacing.
    pub alpha_start: f64,
    /// Sigmoid sharpness at the end, in units of the inverse angular spacing.
    pub alpha_end: f64,
    /// How cap measures are computed.
    pub area: AreaOption,
    /// For targets without a closed-form cap measure (`brdf`, `envmap`): the size of
    /// the quadrature rule of the target whose [`CapMeasureTable`] answers the cap
    /// measures during optimization (built once, `O(sqrt K)` per cap against `O(H)`
    /// or `O(K)` for the exact measures). Default `2^14`: on an envmap with a sun
    /// holding half the light its cap measures are off by 1.5e-4 rms (5.4e-5 at
    /// `2^16`, which costs 2.4 times as much per cap), a few percent of the local
    /// discrepancy of a 256-point set.
    pub table_points: usize,
    /// Work in units of each point's *local* spacing where the target is denser
    /// than uniform: point `i` gets the sigmoid sharpness `alpha f_i` and the Adam
    /// step `lr / f_i`, with `f_i = sqrt(|domain| pdf(x_i))` clamped into
    /// `[1, MAX_LOCAL_FACTOR]` (the ratio of the uniform spacing `sqrt(|domain| / N)`
    /// to the spacing `sqrt(1 / (N pdf))` the target asks for there). Without it, a
    /// sun or a sharp lobe smaller than the global spacing is seen through a sigmoid
    /// wider than itself, every point in it feels the same pull, and they collapse
    /// onto one spot. `false` reproduces the global units of earlier versions.
    pub local_units: bool,
    /// Fast tree-based gradient or the dense reference.
    pub path: GradientPath,
    /// Fixes the initialization and every random draw.
    pub seed: u64,
}

impl Default for DirectionConfig {
    fn default() -> Self {
        Self {
            epochs: 5000,
            caps: 1024,
            learning_rate: 0.02,
            final_learning_rate_ratio: 0.02,
            alpha_start: 8.0,
            alpha_end: 128.0,
            area: AreaOption::Exact,
            table_points: 1 << 14,
            local_units: true,
            path: GradientPath::Fast,
            seed: 0,
        }
    }
}

/// The starting set: Owen-Sobol points warped by the target's standard sampler,
/// expressed in the domain's equal-area square.
pub fn initial_square_points(density: &dyn DirectionDensity, n: usize, seed: u64) -> Vec<DVec2> {
    let domain = density.domain();
    warped_owen_sobol_directions(density, n, seed)
        .into_iter()
        .map(|d| domain.to_square(d))
        .collect()
}

/// The target measure of a cap as the optimizer sees it with
/// [`AreaOption::Exact`]: the closed form where the density has one, else its
/// [`CapMeasureTable`] over `table_points` quadrature points.
struct ExactCapMeasure<'a> {
    density: &'a dyn DirectionDensity,
    table: Option<CapMeasureTable>,
}

impl<'a> ExactCapMeasure<'a> {
    fn new(density: &'a dyn DirectionDensity, table_points: usize) -> Self {
        let table = (!density.has_closed_form_caps())
            .then(|| CapMeasureTable::new(&density.quadrature(table_points)));
        Self { density, table }
    }

    fn measure(&self, c: DVec3, t: f64) -> f64 {
        match &self.table {
            Some(table) => table.measure(c, t),
            None => self.density.cap_measure(c, t),
        }
    }
}

/// Every cap measure of a run, computed once: the caps of each epoch depend only
/// on the seed, the epoch and the cap count, never on `N`, so runs of many sizes
/// with one seed can share them. For targets without closed-form cap measures
/// (`brdf`, `envmap`) the table lookups cost more than the rest of an epoch; a
/// schedule pays them once per seed instead of once per run, with bit-identical
/// results ([`optimize_directions_scheduled`]).
pub struct CapSchedule {
    seed: u64,
    epochs: usize,
    caps: usize,
    table_points: usize,
    /// `mu` of cap `i` of epoch `e` at `e * caps + i`.
    measures: Vec<f64>,
}

impl CapSchedule {
    /// The schedule of `config` (its seed, epochs, caps and table size) for
    /// `density`; `epochs * caps` measures (8 bytes each), computed in parallel.
    pub fn new(density: &dyn DirectionDensity, config: &DirectionConfig) -> Self {
        use rayon::prelude::*;
        let exact = ExactCapMeasure::new(density, config.table_points);
        let per_epoch: Vec<Vec<f64>> = (0..config.epochs)
            .into_par_iter()
            .map(|e| {
                epoch_caps(config.seed, e, config.caps)
                    .iter()
                    .map(|c| exact.measure(c.center, c.cos_theta))
                    .collect()
            })
            .collect();
        Self {
            seed: config.seed,
            epochs: config.epochs,
            caps: config.caps,
            table_points: config.table_points,
            measures: per_epoch.concat(),
        }
    }

    /// Whether this schedule holds the cap measures `config` would compute.
    pub fn matches(&self, config: &DirectionConfig) -> bool {
        config.area == AreaOption::Exact
            && (self.seed, self.epochs, self.caps, self.table_points)
                == (config.seed, config.epochs, config.caps, config.table_points)
    }

    fn epoch(&self, e: usize) -> &[f64] {
        &self.measures[e * self.caps..(e + 1) * self.caps]
    }
}

/// Optimizes `n` directions for `density`; returns their equal-area square points.
pub fn optimize_directions(
    density: &dyn DirectionDensity,
    n: usize,
    config: &DirectionConfig,
    on_epoch: &mut dyn FnMut(&EpochReport),
) -> Vec<DVec2> {
    run(density, n, config, None, on_epoch)
}

/// [`optimize_directions`] with the cap measures taken from `schedule`: the same
/// output bit for bit, without the per-cap table lookups.
///
/// # Panics
/// If the schedule does not [match](CapSchedule::matches) `config`.
pub fn optimize_directions_scheduled(
    density: &dyn DirectionDensity,
    n: usize,
    config: &DirectionConfig,
    schedule: &CapSchedule,
    on_epoch: &mut dyn FnMut(&EpochReport),
) -> Vec<DVec2> {
    assert!(
        schedule.matches(config),
        "cap schedule built for other settings"
    );
    run(density, n, config, Some(schedule), on_epoch)
}

fn run(
    density: &dyn DirectionDensity,
    n: usize,
    config: &DirectionConfig,
    schedule: Option<&CapSchedule>,
    on_epoch: &mut dyn FnMut(&EpochReport),
) -> Vec<DVec2> {
    let domain = density.domain();
    let mut params = initial_square_points(density, n, config.seed);
    let area_of_domain = domain.area();
    let spacing = (area_of_domain / n as f64).sqrt();
    // Square units per radian: the equal-area map scales areas by 1/area_of_domain.
    let square_per_radian = 1.0 / area_of_domain.sqrt();
    let exact = match (schedule, config.area) {
        (None, AreaOption::Exact) => Some(ExactCapMeasure::new(density, config.table_points)),
        _ => None,
    };
    let annealing = Schedule {
        epochs: config.epochs,
        alpha: (config.alpha_start, config.alpha_end),
        final_learning_rate_ratio: config.final_learning_rate_ratio,
    };
    let mut descent = Descent::new(
        Adam::new(n),
        annealing,
        config.learning_rate * spacing * square_per_radian,
        spacing,
    );
    let mut loss = CapLoss {
        density,
        config,
        schedule,
        exact,
        grad3: vec![DVec3::ZERO; n],
        local: vec![1.0; n],
        step: vec![1.0; n],
    };
    descent.run(&mut params, &mut loss, on_epoch);
    params
}

/// The cap loss of one run over equal-area square points: each epoch's caps from
/// the seed, their measures exact, scheduled or Monte Carlo, the gradient chained
/// back through the map, and the local units of [`DirectionConfig::local_units`].
struct CapLoss<'a> {
    density: &'a dyn DirectionDensity,
    config: &'a DirectionConfig,
    schedule: Option<&'a CapSchedule>,
    exact: Option<ExactCapMeasure<'a>>,
    grad3: Vec<DVec3>,
    /// Each point's local factor `f_i` and step scale `1 / f_i`.
    local: Vec<f64>,
    step: Vec<f64>,
}

impl EpochLoss<DVec2> for CapLoss<'_> {
    fn loss_and_gradient(
        &mut self,
        epoch: usize,
        alpha: f64,
        params: &[DVec2],
        grad: &mut [DVec2],
    ) -> f64 {
        let (config, density) = (self.config, self.density);
        let domain = density.domain();
        let exact_measure = &self.exact;
        let exact = |c: DVec3, t: f64| exact_measure.as_ref().map_or(0.0, |m| m.measure(c, t));
        let caps = epoch_caps(config.seed, epoch, config.caps);
        let sample_tree;
        let area = match (self.schedule, config.area) {
            (Some(s), _) => CapArea::Precomputed(s.epoch(epoch)),
            (None, AreaOption::Exact) => CapArea::Exact(&exact),
            (None, AreaOption::MonteCarlo { samples }) => {
                let mut r = rng(config.seed, 2 * epoch as u64 + 2);
                let s: Vec<DVec3> = (0..samples)
                    .map(|_| density.sample_target(&mut r))
                    .collect();
                sample_tree = CapTree::new(&s);
                CapArea::MonteCarlo(&sample_tree)
            }
        };
        let dirs: Vec<DVec3> = params.iter().map(|&p| domain.to_direction(p)).collect();
        if config.local_units {
            let area_of_domain = domain.area();
            for (f, (s, &x)) in self.local.iter_mut().zip(self.step.iter_mut().zip(&dirs)) {
                *f = local_factor(area_of_domain, density.pdf(x));
                *s = 1.0 / *f;
            }
        }
        let sharpness = config.local_units.then_some(self.local.as_slice());
        let loss = cap_loss_and_gradient(
            &dirs,
            &caps,
            area,
            alpha,
            sharpness,
            config.path,
            &mut self.grad3,
        );
        for ((g, &g3), &p) in grad.iter_mut().zip(&self.grad3).zip(params) {
            let (jx, jy) = map_jacobian(domain, p);
            *g = DVec2::new(jx.dot(g3), jy.dot(g3));
        }
        loss
    }

    fn step_scales(&self) -> Option<&[f64]> {
        self.config.local_units.then_some(self.step.as_slice())
    }

    fn project(&self, params: &mut [DVec2]) {
        let domain = self.density.domain();
        params.iter_mut().for_each(|p| *p = fold(domain, *p));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::parse_direction_spec;
    use nuld_core::blob::Domain;

    fn run(threads: usize, domain: Domain, spec: &str, seed: u64) -> (Vec<DVec2>, Vec<f64>) {
        let density = parse_direction_spec(spec, domain).unwrap();
        let cfg = DirectionConfig {
            epochs: 300,
            caps: 300,
            seed,
            ..DirectionConfig::default()
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut losses = Vec::new();
        let pts = pool.install(|| {
            optimize_directions(density.as_ref(), 200, &cfg, &mut |r| losses.push(r.loss))
        });
        (pts, losses)
    }

    #[test]
    fn same_seed_gives_bit_identical_directions_for_any_thread_count() {
        let bits = |v: &[DVec2]| {
            v.iter()
                .flat_map(|p| [p.x.to_bits(), p.y.to_bits()])
                .collect::<Vec<_>>()
        };
        let (a, _) = run(1, Domain::Sphere, "uniform", 4);
        let (b, _) = run(2, Domain::Sphere, "uniform", 4);
        assert_eq!(bits(&a), bits(&b));
        let (c, _) = run(2, Domain::Sphere, "uniform", 5);
        assert_ne!(bits(&a), bits(&c));
    }

    #[test]
    fn optimization_lowers_the_cap_loss_and_stays_in_the_domain() {
        for (domain, spec) in [(Domain::Sphere, "uniform"), (Domain::Hemisphere, "cosine")] {
            let (pts, losses) = run(2, domain, spec, 1);
            assert!(pts
                .iter()
                .all(|p| (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y)));
            if domain == Domain::Hemisphere {
                assert!(pts.iter().all(|&p| domain.to_direction(p).z >= 0.0));
            }
            let head: f64 = losses[..30].iter().sum::<f64>() / 30.0;
            let tail: f64 = losses[losses.len() - 30..].iter().sum::<f64>() / 30.0;
            assert!(tail < 0.85 * head, "{spec}: {head} -> {tail}");
        }
    }

    #[test]
    fn a_cap_schedule_reproduces_the_unscheduled_run_bit_for_bit_for_every_size() {
        // brdf has no closed-form cap measure: the schedule replaces table lookups.
        let density = parse_direction_spec("brdf:0.3,45", Domain::Hemisphere).unwrap();
        let cfg = DirectionConfig {
            epochs: 40,
            caps: 200,
            table_points: 1 << 12,
            seed: 9,
            ..DirectionConfig::default()
        };
        let schedule = CapSchedule::new(density.as_ref(), &cfg);
        assert!(schedule.matches(&cfg));
        for n in [16, 50] {
            let plain = optimize_directions(density.as_ref(), n, &cfg, &mut |_| {});
            let scheduled =
                optimize_directions_scheduled(density.as_ref(), n, &cfg, &schedule, &mut |_| {});
            assert_eq!(plain, scheduled, "N = {n}");
        }
        // Any setting the measures depend on breaks the match.
        for other in [
            DirectionConfig {
                seed: 10,
                ..cfg.clone()
            },
            DirectionConfig {
                epochs: 41,
                ..cfg.clone()
            },
            DirectionConfig {
                caps: 201,
                ..cfg.clone()
            },
            DirectionConfig {
                table_points: 1 << 13,
                ..cfg.clone()
            },
            DirectionConfig {
                area: AreaOption::MonteCarlo { samples: 64 },
                ..cfg.clone()
            },
        ] {
            assert!(!schedule.matches(&other));
        }
    }

    #[test]
    #[should_panic(expected = "cap schedule built for other settings")]
    fn a_mismatched_cap_schedule_is_refused() {
        let density = parse_direction_spec("cosine", Domain::Hemisphere).unwrap();
        let cfg = DirectionConfig {
            epochs: 3,
            caps: 8,
            ..DirectionConfig::default()
        };
        let schedule = CapSchedule::new(density.as_ref(), &cfg);
        let other = DirectionConfig { seed: 1, ..cfg };
        optimize_directions_scheduled(density.as_ref(), 8, &other, &schedule, &mut |_| {});
    }
}
