//! The optimizers' speed: seconds per epoch of the fast (banded) and the dense
//! gradient, and the wall time of a full default run, 2D and directions
//! (`build-tool bench --only square|directions`).

use crate::density::parse_spec;
use crate::discrepancy::GradientPath;
use crate::optimize::directions::{optimize_directions, DirectionConfig};
use crate::optimize::{optimize, AreaOption, OptimizeConfig};
use crate::sphere::parse_direction_spec;
use anyhow::{Context, Result};
use nuld_core::blob::Domain;
use std::time::Instant;

/// Mean seconds per epoch of `epochs` epochs of the 2D optimizer on `spec` with
/// `n` points and gradient `path` (defaults otherwise).
pub fn square_seconds_per_epoch(
    spec: &str,
    n: usize,
    epochs: usize,
    path: GradientPath,
) -> Result<f64> {
    let density = parse_spec(spec).with_context(|| format!("--density {spec}"))?;
    let cfg = OptimizeConfig {
        epochs,
        path,
        ..OptimizeConfig::default()
    };
    let t = Instant::now();
    let _ = optimize(density.as_ref(), n, &cfg, &mut |_| {});
    Ok(t.elapsed().as_secs_f64() / epochs as f64)
}

/// Seconds of a full default 2D run on `spec` with `n` points and areas `area`.
pub fn square_full_run(spec: &str, n: usize, area: AreaOption) -> Result<f64> {
    let density = parse_spec(spec).with_context(|| format!("--image-density {spec}"))?;
    let cfg = OptimizeConfig {
        area,
        ..OptimizeConfig::default()
    };
    let t = Instant::now();
    let _ = optimize(density.as_ref(), n, &cfg, &mut |_| {});
    Ok(t.elapsed().as_secs_f64())
}

/// Mean seconds per epoch of `epochs` epochs of the direction optimizer on `spec`
/// (on the sphere) with `n` points and gradient `path` (defaults otherwise).
pub fn direction_seconds_per_epoch(
    spec: &str,
    n: usize,
    epochs: usize,
    path: GradientPath,
) -> Result<f64> {
    let density = parse_direction_spec(spec, Domain::Sphere)
        .with_context(|| format!("--direction-density {spec}"))?;
    let cfg = DirectionConfig {
        epochs,
        path,
        ..DirectionConfig::default()
    };
    let t = Instant::now();
    let _ = optimize_directions(density.as_ref(), n, &cfg, &mut |_| {});
    Ok(t.elapsed().as_secs_f64() / epochs as f64)
}

/// Seconds of a full default direction run on `spec` (on the sphere) with `n`
/// points.
pub fn direction_full_run(spec: &str, n: usize) -> Result<f64> {
    let density = parse_direction_spec(spec, Domain::Sphere)
        .with_context(|| format!("--direction-density {spec}"))?;
    let t = Instant::now();
    let _ = optimize_directions(
        density.as_ref(),
        n,
        &DirectionConfig::default(),
        &mut |_| {},
    );
    Ok(t.elapsed().as_secs_f64())
}
