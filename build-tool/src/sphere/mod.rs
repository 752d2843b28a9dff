//! Directions on the sphere and the upper hemisphere: target densities, their
//! samplers and cap measures, and spherical cap discrepancy metrics (docs/targets.md,
//! docs/metrics.md; paper §2.1 Eqs. 7–9 and §3.5).
//!
//! * [`target`]: the [`DirectionDensity`] trait, its error and shared helpers;
//! * [`spec`]: [`parse_direction_spec`] for the SPECs `uniform`, `cosine`,
//!   `brdf:ROUGHNESS,THETA_O_DEG` (`brdf-burley:...`), `envmap:PATH`;
//! * [`closed_form`]: the `uniform` and `cosine` targets;
//! * [`brdf_target`], [`envmap`]: the two tabulated targets;
//! * [`envmap_prior`]: [`EnvmapPrior`], a map's `L cos` tabulated for a grid of
//!   normals and sampled exactly between them (the environment sampler's prior);
//! * [`envmap_tree`]: [`EnvmapTree`], a map measured into the records of
//!   [`nuld_core::envmap_tree`] (mass, first moment and spread per node of a
//!   pyramid on that square), sampled exactly times the cosine about the query's
//!   normal;
//! * [`filtered_luminance`]: a map's bilinearly filtered luminance (the light of
//!   `bake --envmap` and `render`) and its exact tabulation on half pixels;
//! * [`radial_half_vector`]: a candidate square of the BRDF prior's tables, the
//!   half vector's slopes stretched by their own size and along the view's plane;
//! * [`horizon_disc`]: candidate squares of the BRDF prior's metal layer whose
//!   rim is the horizon at every view;
//! * [`brdf_albedo`]: the BRDF's directional albedo (the `brdf` normalizer and the
//!   per-condition sample weight) and tables of it;
//! * [`geometry`]: closed-form cap measures (uniform sphere and hemisphere, cosine);
//! * [`cap_table`]: [`CapMeasureTable`], fast cap sums over a weighted point rule;
//! * [`tabulated_warp`]: [`TabulatedWarp`], a target's exact tabulated inverse CDF
//!   on its equal-area square (the exact-warp baseline);
//! * [`metrics`]: cap L2 discrepancy (Stolarsky closed form, energy distance,
//!   Monte Carlo in the paper's theta-uniform convention) and a lower bound of the
//!   cap star discrepancy.
//!
//! Imports run one way: [`target`] <- the targets <- [`spec`].
//!
//! A cap is `C(w, t) = {x : <w, x> >= t}`, `t = cos theta`.

pub mod brdf_albedo;
pub mod brdf_prior;
pub mod brdf_target;
pub mod cap_table;
pub mod closed_form;
pub mod envmap;
pub mod envmap_prior;
pub mod envmap_tree;
pub mod equirect;
pub mod filtered_luminance;
pub mod geometry;
pub mod horizon_disc;
pub mod metrics;
pub mod radial_half_vector;
pub mod spec;
#[cfg(test)]
mod table_map_checks;
pub mod tabulated_warp;
pub mod target;

pub use brdf_target::BrdfTarget;
pub use cap_table::CapMeasureTable;
pub use closed_form::{CosineDirections, UniformDirections};
pub use envmap::EnvmapDensity;
pub use envmap_prior::EnvmapPrior;
pub use envmap_tree::EnvmapTree;
pub use filtered_luminance::FilteredLuminance;
pub use geometry::{
    cosine_cap_measure, random_direction, uniform_hemisphere_cap_measure,
    uniform_sphere_cap_measure,
};
pub use metrics::{
    cap_l2_for_density, cap_l2_for_density_squared, cap_l2_mc_squared, cap_l2_nonuniform,
    cap_l2_nonuniform_squared, cap_l2_theta_uniform_estimate, cap_l2_uniform,
    cap_l2_uniform_squared, cap_star_estimate, cap_star_estimate_screened, cap_star_estimate_with,
    root_with_stderr, CapRadius, CapStarEstimate, CapStarOptions, EnergyReference, MeasuredCaps,
};
pub use spec::parse_direction_spec;
pub use tabulated_warp::{square_cell_masses, TabulatedWarp};
pub use target::{DirectionDensity, DirectionSpecError};
