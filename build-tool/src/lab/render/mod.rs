//! The rendering evaluation of paper Fig. 8 (`build-tool render`): a small,
//! physically based renderer whose only job is to compare samplers.
//!
//! Spheres of the glTF metallic-roughness BRDF at roughnesses 0.1 to 1, a row
//! of dielectrics and a row of metals, on a ground plane ([`scene`]), a pinhole camera ([`camera`]), lit only by an environment map
//! ([`environment`]); direct lighting with visibility by ray casting, one
//! estimator per pixel ([`integrator`]). Every sampler implements one trait
//! ([`sampler::DirectionSampler`], returning [`sampler::Sample`]s):
//! * BRDF sampling: ours in table, network and unbiased mode ([`nuld_sampler`],
//!   through `nuld-runtime` on the blob bytes only), and Owen-Sobol, random, SOT and GBN
//!   points ([`primary`]) through the renderer's mixture warp ([`brdf_warp`]);
//! * environment sampling: ours in table, network and unbiased mode; Owen-Sobol,
//!   Halton, random, SOT and GBN points through the product warp of `L cos` that
//!   ours uses as its prior; Owen-Sobol and Halton points through the map's
//!   inverse CDF and Owen-Sobol through hierarchical warping of its luminance,
//!   as renderers ship them ([`envmap_warp`]);
//! * multiple importance sampling of both ([`mis`]): each environment sampler
//!   with Owen-Sobol through the BRDF mixture warp, power heuristic.
//!
//! [`lineup`] lists them in table order. A multiple-importance-sampled reference
//! ([`mod@reference`]) gives RMSE and bias ([`summary`]); [`run`] writes pictures
//! ([`picture`]), the Fig. 8 composites, `render.csv` and the summary tables.

pub mod blobs;
pub mod brdf_warp;
pub mod camera;
pub mod environment;
pub mod envmap_warp;
pub mod frame;
pub mod integrator;
pub mod lineup;
pub mod mis;
pub mod nuld_sampler;
pub mod picture;
pub mod primary;
pub mod reference;
pub mod run;
pub mod sampler;
pub mod scene;
pub mod summary;

pub use run::{render, RenderConfig, RenderReport};
