//! What `envmap_bounds` and `envmap_nearest_node` share: a set fitted to one or
//! more normals' lit maps in the environment tree's primary space, as the
//! trainer moves points, and the tree's warp with its Jacobian.
use crate::primary::{self, step_gradient};
use glam::{DVec2, DVec3};
use nuld_build_tool::descent::{epoch_schedule, local_factor, Adam};
use nuld_build_tool::discrepancy::caps::Cap;
use nuld_build_tool::sphere::geometry::{fold, map_jacobian};
use nuld_build_tool::sphere::{
    CapMeasureTable, DirectionDensity, EnvmapDensity, EnvmapTree as ToolTree,
};
use nuld_core::blob::Domain;
use nuld_core::envmap_tree::EnvmapTree;
use nuld_core::network::{shifted_lattice_point, Shape};
use nuld_core::sphere::square_to_sphere;
use std::f64::consts::PI;

/// The fit's settings.
pub struct Fit {
    pub n: usize,
    pub steps: usize,
    pub step: f64,
}

impl Fit {
    /// The settings from a command line's `MAP [N] [STEPS] [STEP]` (`args[2..5]`):
    /// 64 points, 3000 steps of `0.02 / sqrt(N)` unless given.
    pub fn from_args(args: &[String]) -> Self {
        let arg = |k: usize, default: f64| args.get(k).map_or(default, |s| s.parse().unwrap());
        Self {
            n: arg(2, 64.0) as usize,
            steps: arg(3, 3000.0) as usize,
            step: arg(4, 0.02),
        }
    }
}

/// Instance 0's shifted rank-1 lattice of `shape` at `n` points, where every
/// fit starts (what a network with a zero residual gives).
pub fn lattice(shape: &Shape, n: usize) -> Vec<DVec2> {
    let (g, z) = (shape.lattice_generator(), shape.instance_offset::<f64>(0));
    (0..n as u32)
        .map(|i| DVec2::from(shifted_lattice_point(i, n as u32, g, z)))
        .collect()
}

/// The tree's warp at the normal of octahedral point `u`, and its Jacobian: the
/// sphere map's times the descent's exact slopes (what the trainer's
/// `PoolCondition::direction` does); without a tree, the sphere's equal-area map
/// alone (`p` a point of the sphere's square, the same direction at every
/// normal).
pub fn warp(tree: Option<&EnvmapTree<'_>>, u: [f64; 2], p: DVec2) -> (DVec3, DVec3, DVec3) {
    match tree {
        Some(tree) => ToolTree::sample_with_jacobian(tree, u, p),
        None => {
            let (jx, jy) = map_jacobian(Domain::Sphere, p);
            (square_to_sphere(p), jx, jy)
        }
    }
}

/// What a fit reads at one normal: its octahedral point, lit map, caps and their
/// measures on the lit map's mass rule.
pub struct Site {
    u: [f64; 2],
    lit: EnvmapDensity,
    caps: Vec<Cap>,
    measures: Vec<f64>,
}

impl Site {
    /// The normal of octahedral point `u`, its 2048 caps from `stream`.
    pub fn new(map: &EnvmapDensity, u: [f64; 2], stream: u32) -> Self {
        let (lit, _) = map
            .cosine_weighted(square_to_sphere(DVec2::from(u)))
            .unwrap();
        let table = CapMeasureTable::new(&lit.mass_rule(1 << 14));
        let caps = primary::caps(2048, stream);
        let measures = caps
            .iter()
            .map(|c| table.measure(c.center, c.cos_theta))
            .collect();
        Self {
            u,
            lit,
            caps,
            measures,
        }
    }
}

/// `start` fitted in the primary space of the normals `sites` at once (the sum
/// of their losses; see the module docs), or without a tree in the sphere's
/// equal-area square.
pub fn fit(
    tree: Option<&EnvmapTree<'_>>,
    sites: &[Site],
    start: &[DVec2],
    how: &Fit,
) -> Vec<DVec2> {
    let n = how.n;
    let mut p = start.to_vec();
    let mut adam = Adam::new(n);
    adam.epsilon = 1e-12;
    let spacing = (4.0 * PI / n as f64).sqrt();
    for t in 0..how.steps {
        // The trainer's schedule: sharpness 8 to 64 inverse spacings, the step's
        // cosine decay to 3 %.
        let (alpha, ratio) = epoch_schedule(t, how.steps, (8.0, 64.0), 0.03);
        let mut g = vec![DVec2::ZERO; n];
        for site in sites {
            let w: Vec<_> = p.iter().map(|&q| warp(tree, site.u, q)).collect();
            let local: Vec<f64> = w
                .iter()
                .map(|x| local_factor(4.0 * PI, site.lit.pdf(x.0)))
                .collect();
            let site_g = step_gradient(&w, &local, (&site.caps, &site.measures), t, alpha, spacing);
            for (a, b) in g.iter_mut().zip(site_g) {
                *a += b;
            }
        }
        adam.step(&mut p, &g, how.step / (n as f64).sqrt() * ratio);
        for q in &mut p {
            // The primary square is clamped; the sphere's square wraps at its seam.
            *q = match tree {
                Some(_) => q.clamp(DVec2::ZERO, DVec2::splat(1.0 - 1e-12)),
                None => fold(Domain::Sphere, *q),
            };
        }
    }
    p
}
