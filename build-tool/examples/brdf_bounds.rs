//! How far the BRDF sampler's sets are from what its prior's primary space
//! allows at one condition, on `eval conditional`'s judge at its ten conditions
//! with direct optimization: `cargo run --release -p nuld-build-tool --example
//! brdf_bounds -- BLOB [STEPS] [STEP] [INSTANCES] [REFINE] [SHIFTS]` (about 2.5 minutes
//! on 2 cores at the defaults: 3000 steps, 0.02, 4 sets a method, 0.25).
//!
//! Besides the blob's table mode, samplers fit each set to its one
//! condition in the prior's primary space, as the trainer moves a network's
//! points: the cap loss on 2048 caps of the condition measured on the
//! trainer's `2^14`-point rule, 256 a step; the sigmoid's sharpness in local
//! units; the table's exact slopes through the half-vector map
//! (`brdf_table_direction`); Adam on the points with the trainer's cosine
//! decay of the step. `fitted-lattice` starts from instance `k`'s shifted
//! lattice (the untrained prior's set), the sharpness ramping from 8 to 32
//! inverse spacings and the step `STEP / sqrt(N)`; `fitted-table` from the
//! blob's own table-mode points of instance `k` (where training left them),
//! at the end sharpness 32 throughout and `REFINE` times the step, so that
//! it refines them rather than starting over; `fitted-table(dr, dθ)` refines
//! the table's set at the condition shifted by each of `SHIFTS` (default
//! `0/-4,0.05/0`: half a cell of the point table away, 4° less of view or 0.05
//! more roughness) and reads it at the condition: how far a refined set
//! carries. The judge, its caps, the exact baseline and the direct
//! optimization are `eval conditional`'s at the same conditions (each seeded
//! by its condition), `INSTANCES` sets a method.
mod primary;

use glam::{DVec2, DVec3};
use nuld_build_tool::descent::{epoch_schedule, local_factor, Adam};
use nuld_build_tool::lab::eval::conditional::{
    blob_sets, evaluate, ConditionalSets, ConditionalSettings,
};
use nuld_build_tool::sphere::brdf_prior::BrdfPrior;
use nuld_build_tool::sphere::{BrdfTarget, DirectionDensity};
use nuld_build_tool::train::pool::{brdf_table_direction, POOL_RULE_POINTS};
use nuld_build_tool::train::target::{LoadedTarget, TrainTarget};
use nuld_core::blob::Domain;
use nuld_core::brdf::{clamp_roughness, clamp_theta_o_deg};
use nuld_core::network::{salted_instance_offset, shifted_lattice_point};
use primary::step_gradient;
use std::sync::Arc;

/// Sets fitted to their one condition in the prior's primary space.
struct Fitted<'a> {
    name: String,
    n: usize,
    prior: Arc<BrdfPrior>,
    /// Where a fit starts: the blob's table-mode points of instance `k`, or
    /// without a sampler instance `k`'s shifted lattice (salted offset).
    table: Option<nuld_runtime::ConditionalSampler<'a>>,
    steps: usize,
    step: f64,
    alpha_start: f64,
    /// Where the set is fitted, `(roughness, θo)` away from the condition it
    /// is read at (clamped into the range): how far a fit carries.
    shift: [f64; 2],
}

impl Fitted<'_> {
    fn start(&self, cond: [f64; 3], k: u32) -> Vec<DVec2> {
        let n = self.n as u32;
        match &self.table {
            None => {
                let g = nuld_build_tool::train::lattice_generator(n);
                let z = salted_instance_offset::<f64>(k);
                (0..n)
                    .map(|i| DVec2::from(shifted_lattice_point(i, n, g, z)))
                    .collect()
            }
            Some(cs) => (0..n)
                .map(|i| {
                    let c = nuld_runtime::glam::Vec2::new(cond[0] as f32, cond[1] as f32);
                    cs.square_point_metallic(c, cond[2] as f32, k, i).as_dvec2()
                })
                .collect(),
        }
    }

    /// Instance `k`'s primary points fitted at `cond`.
    fn fit(&self, cond: [f64; 3], k: u32) -> Vec<DVec2> {
        let n = self.n;
        let target = BrdfTarget::coarse(cond[0], cond[1], cond[2], POOL_RULE_POINTS).unwrap();
        let stream = 0x0b0d_0000 ^ k;
        let caps = primary::caps(2048, stream);
        let measures: Vec<f64> = caps
            .iter()
            .map(|c| target.cap_measure(c.center, c.cos_theta))
            .collect();
        // The target density `q = f cos / A` sets each point's local units.
        let area = Domain::Hemisphere.area();
        let mut p = self.start(cond, k);
        let mut adam = Adam::new(n);
        adam.epsilon = 1e-12;
        let spacing = (area / n as f64).sqrt();
        for t in 0..self.steps {
            let (alpha, ratio) = epoch_schedule(t, self.steps, (self.alpha_start, 32.0), 0.03);
            let w: Vec<_> = p
                .iter()
                .map(|&u| brdf_table_direction(&self.prior, cond, u))
                .collect();
            let local: Vec<f64> = w
                .iter()
                .map(|x| local_factor(area, target.pdf(x.0)))
                .collect();
            let g = step_gradient(&w, &local, (&caps, &measures), t, alpha, spacing);
            adam.step(&mut p, &g, self.step / (n as f64).sqrt() * ratio);
            for u in &mut p {
                *u = u.clamp(DVec2::ZERO, DVec2::splat(1.0 - 1e-12));
            }
        }
        p
    }
}

impl ConditionalSets for Fitted<'_> {
    fn name(&self) -> &str {
        &self.name
    }

    fn len(&self) -> usize {
        self.n
    }

    fn set(&self, roughness: f64, theta_o_deg: f64, metallic: f64, instance: u32) -> Vec<DVec3> {
        let at = [
            clamp_roughness(roughness + self.shift[0]),
            clamp_theta_o_deg(theta_o_deg + self.shift[1]),
            metallic,
        ];
        let cond = [roughness, theta_o_deg, metallic];
        self.fit(at, instance)
            .iter()
            .map(|&u| brdf_table_direction(&self.prior, cond, u).0)
            .collect()
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(2..=7).contains(&args.len()) {
        eprintln!("usage: brdf_bounds BLOB [STEPS] [STEP] [INSTANCES] [REFINE] [SHIFTS]");
        std::process::exit(2);
    }
    let arg = |k: usize, default: f64| args.get(k).map_or(default, |s| s.parse().unwrap());
    let (steps, step, instances) = (arg(2, 3000.0) as usize, arg(3, 0.02), arg(4, 4.0) as usize);
    let refine = arg(5, 0.25);
    // `dr/dθ` pairs, comma-separated: where the refined sets read at each
    // condition are fitted. By default half a cell of the point table's grid
    // away (10 x 12 nodes: roughness 0.1 and θo 8.1° apart), the farthest a
    // nearest-node table of refined sets reads from.
    let shifts: Vec<[f64; 2]> = args
        .get(6)
        .map_or("0/-4,0.05/0", String::as_str)
        .split(',')
        .map(|pair| {
            let (r, t) = pair.split_once('/').expect("a shift is dr/dθ");
            [r.parse().unwrap(), t.parse().unwrap()]
        })
        .collect();
    let bytes = std::fs::read(&args[1]).unwrap();
    let blob = nuld_runtime::Blob::parse(&bytes).unwrap();
    let cs = blob.brdf().unwrap().conditional();
    let n = cs.len() as usize;
    let prior = match TrainTarget::GltfBrdf.load().unwrap() {
        LoadedTarget::GltfBrdf(prior) => prior,
        _ => unreachable!("the BRDF target loads its prior"),
    };
    let table = blob_sets(&bytes).unwrap().swap_remove(0);
    let lattice = Fitted {
        name: "fitted-lattice".into(),
        n,
        prior: Arc::clone(&prior),
        table: None,
        steps,
        step,
        alpha_start: 8.0,
        shift: [0.0; 2],
    };
    let refined = |name: String, shift| Fitted {
        name,
        n,
        prior: Arc::clone(&prior),
        table: Some(cs),
        steps,
        step: step * refine,
        alpha_start: 32.0,
        shift,
    };
    let mut fitted = vec![refined("fitted-table".into(), [0.0; 2])];
    for &[r, t] in &shifts {
        fitted.push(refined(format!("fitted-table({r:+}, {t:+}°)"), [r, t]));
    }
    let full = ConditionalSettings::full(&[0.0, 1.0]);
    let settings = ConditionalSettings {
        conditions: full.direct.iter().map(|&i| full.conditions[i]).collect(),
        direct: (0..full.direct.len()).collect(),
        instances,
        union_instances: instances.max(2),
        ..full
    };
    let mut samplers: Vec<&dyn ConditionalSets> = vec![table.as_ref(), &lattice];
    samplers.extend(fitted.iter().map(|f| f as &dyn ConditionalSets));
    let report = evaluate(&samplers, &settings).unwrap();
    println!("N = {n}, {steps} steps of {step} / sqrt(N), {instances} sets a method");
    println!("roughness, θo, metallic: cap L2 over direct optimization (over the exact warp's Owen-Sobol)");
    for c in &report.conditions {
        let cells: Vec<String> = c
            .ratios
            .iter()
            .map(|r| {
                format!(
                    "{} {:.3} ({:.3})",
                    r.sampler,
                    r.to_direct.unwrap_or(f64::NAN),
                    r.to_exact
                )
            })
            .collect();
        println!(
            "{:.2}, {:>2}°, {}: {}",
            c.roughness,
            c.theta_o_deg,
            c.metallic,
            cells.join("  ")
        );
    }
    for s in &report.summary {
        println!(
            "{}: mean over direct {:.3}, over exact {:.3} (worst {:.3})",
            s.sampler,
            s.mean_ratio_direct.unwrap_or(f64::NAN),
            s.mean_ratio_exact,
            s.worst_ratio_exact
        );
    }
}
