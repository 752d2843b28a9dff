//! What each figure evaluates: its panels (one target or integrand each), the
//! methods compared and the metrics reported.

use super::integrands::{SphereIntegrand, SquareIntegrand};
use super::methods::Method;
use super::{EvalSettings, Figure};
use crate::baselines::Baseline;
use crate::density::{parse_spec, Density2D};
use crate::sphere::{parse_direction_spec, BrdfTarget, DirectionDensity, EnvmapDensity};
use anyhow::{bail, Context, Result};
use nuld_core::blob::Domain;
use serde::Serialize;
use std::path::Path;

/// The bilinear target of Fig. 5 (corner values at (0,0), (1,0), (0,1), (1,1)): a
/// ramp rising 20x from the origin corner to the opposite one, steeper along x.
pub const FIG5_BILINEAR: &str = "bilinear:0.1,1,0.5,2";
/// The Gaussian target of Fig. 5.
pub const FIG5_GAUSSIAN: &str = "gaussian:0.5,0.5,0.15";
/// The BRDF target of Figs. 6 and 7 (roughness 0.3, view 45 degrees from the normal).
pub const BRDF_SPEC: &str = "brdf:0.3,45";
/// The image of Fig. 5, relative to the data directory.
pub const IMAGE_FILE: &str = "images/camera.png";
/// The environment map of Figs. 6 and 7, relative to the data directory.
pub const ENVMAP_FILE: &str = "envmaps/courtyard.hdr";

/// How the values of one metric are aggregated over realizations.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Aggregation {
    /// Mean with its standard error.
    Mean,
    /// Root-mean-square error against the reference value.
    Rmse {
        /// The exact or reference value of the integral.
        reference: f64,
    },
}

/// One reported metric of a panel.
#[derive(Clone, Debug, Serialize)]
pub struct MetricDef {
    /// Name in the CSV `metric` column and file names (e.g. `l2-star`).
    pub key: &'static str,
    /// Axis label.
    pub label: &'static str,
    /// Name of the per-realization value it aggregates (cache key).
    pub source: &'static str,
    /// How it is aggregated.
    pub aggregation: Aggregation,
}

/// What a panel evaluates.
pub enum PanelKind {
    /// Discrepancies of 2D point sets against a density; baselines reach it by
    /// `warp`.
    SquareDiscrepancy {
        /// The target.
        density: Box<dyn Density2D>,
        /// Whether baselines use hierarchical warping (images) instead of the
        /// inverse CDF (ignored for the uniform target).
        hierarchical: bool,
    },
    /// Cap discrepancies of directions against a density.
    SphereDiscrepancy {
        /// The target.
        density: Box<dyn DirectionDensity>,
    },
    /// Integration error of a 2D integrand.
    SquareIntegral(SquareIntegrand),
    /// Integration error of a directional integrand.
    SphereIntegral(SphereIntegrand),
}

/// One panel: a target (or integrand), the methods and the metrics.
pub struct Panel {
    /// Short name (CSV `target` column, file names).
    pub target: String,
    /// Human-readable title (plots).
    pub title: String,
    /// The target density's SPEC.
    pub spec: String,
    /// Conventions and remarks for the JSON report.
    pub notes: Vec<String>,
    /// Reported metrics.
    pub metrics: Vec<MetricDef>,
    /// Methods, in legend order.
    pub methods: Vec<Method>,
    /// What is evaluated.
    pub kind: PanelKind,
}

/// A panel that could not be built (e.g. a missing data file).
#[derive(Clone, Debug, Serialize)]
pub struct Skipped {
    /// The panel's short name.
    pub target: String,
    /// Why (one line).
    pub reason: String,
}

const L2_STAR: MetricDef = MetricDef {
    key: "l2-star",
    label: "L2-star discrepancy",
    source: "l2_star",
    aggregation: Aggregation::Mean,
};
const ASD: MetricDef = MetricDef {
    key: "asd",
    label: "L2 discrepancy D2asd (all corners)",
    source: "asd",
    aggregation: Aggregation::Mean,
};
const STAR: MetricDef = MetricDef {
    key: "star",
    label: "star discrepancy D*",
    source: "star",
    aggregation: Aggregation::Mean,
};
const CAP_L2: MetricDef = MetricDef {
    key: "cap-l2",
    label: "cap L2 discrepancy",
    source: "cap_l2",
    aggregation: Aggregation::Mean,
};
const CAP_STAR: MetricDef = MetricDef {
    key: "cap-star",
    label: "cap star discrepancy (lower bound)",
    source: "cap_star",
    aggregation: Aggregation::Mean,
};

fn b(x: Baseline) -> Method {
    Method::Baseline(x)
}

/// Notes shared by the 2D discrepancy panels.
fn square_notes(uniform: bool) -> Vec<String> {
    if uniform {
        vec![
            "l2-star: Warnock's closed form, exact; asd: closed form, exact".into(),
            "star: exact (Bundschuh–Zhu, O(N^2))".into(),
        ]
    } else {
        vec![
            "asd, l2-star: exact for the target's 512x512 cell-mass tabulation (an image's own pixel grid, then exact)".into(),
            "star: exact D*(mu) (Bundschuh–Zhu with the target CDF)".into(),
        ]
    }
}

/// How our direction optimizer gets cap measures of targets without closed forms.
const TABLE_NOTE: &str = "ours: cap measures from a 2^16-point quadrature table of the target (error about 1e-4 per cap), computed once per seed and shared by every N (a cap schedule; bit-identical to per-run lookups)";

/// Notes shared by the direction discrepancy panels.
fn sphere_notes(uniform: bool, s: &EvalSettings) -> Vec<String> {
    let mut v = vec![if uniform {
        "cap-l2: cos-uniform convention (caps C(w,t) = {x: <w,x> >= t}, w uniform, t = cos theta with measure dt on [-1,1]), exact by Stolarsky's invariance".to_string()
    } else {
        format!(
            "cap-l2: cos-uniform convention (caps C(w,t), w uniform, t = cos theta with measure dt on [-1,1]), Monte Carlo over {} random caps per point set with exact counts and the target's cap measure: unbiased for D^2 (the energy-distance form with a quadrature rule was biased by the rule's own discrepancy, ~1e-6 in D^2 at 16k points, more than our sets' D^2 at large N); its noise is part of the stderr",
            s.cap_l2_caps
        )
    }];
    v.push(format!(
        "cap-star: LOWER-BOUND estimate of sup_C |#{{x_i in C}}/N - mu(C)| (no standard error of its own): {} random caps (w uniform, theta uniform on [0,pi]), the best {} refined by radius sweeps and {} rounds of hill climbing on the centre",
        s.cap_star_caps, s.cap_star_refine, s.cap_star_rounds
    ));
    v
}

/// The path of a data file, or why it is unusable.
fn data_file(s: &EvalSettings, rel: &str) -> Result<String, String> {
    let p = s.data.join(rel);
    if Path::new(&p).is_file() {
        Ok(p.display().to_string())
    } else {
        Err(format!("{} not found (set --data)", p.display()))
    }
}

/// The reference value of a directional integrand; quadratures are cached under
/// `OUT/cache/references/`.
fn sphere_reference(it: &SphereIntegrand, s: &EvalSettings) -> Result<f64> {
    if !it.reference_is_quadrature() {
        return Ok(it.reference(s.reference_subdivision));
    }
    let cache = super::cache::Cache::new(s.out.join("cache"));
    let fp = format!(
        "v1|{}|{}|s={}",
        it.name,
        it.factors(),
        s.reference_subdivision
    );
    if let Some(v) = cache.get_scalar(it.name, &fp) {
        return Ok(v);
    }
    let v = it.reference(s.reference_subdivision);
    cache.put_scalar(it.name, &fp, v)?;
    Ok(v)
}

/// The panels of `figure` and the ones skipped for missing data.
pub fn panels(figure: Figure, s: &EvalSettings) -> Result<(Vec<Panel>, Vec<Skipped>)> {
    let mut panels = Vec::new();
    let mut skipped = Vec::new();
    let square = |target: &str, title: &str, spec: &str, hierarchical: bool| -> Result<Panel> {
        let density = parse_spec(spec).with_context(|| format!("target {spec}"))?;
        let uniform = spec == "uniform";
        let (metrics, methods) = if figure == Figure::Fig2 {
            (
                vec![L2_STAR, STAR],
                vec![
                    Method::Ours,
                    b(Baseline::Random),
                    b(Baseline::OwenSobol),
                    b(Baseline::SobolCp),
                    b(Baseline::Halton),
                    b(Baseline::PoissonDisk),
                    b(Baseline::Sot),
                    b(Baseline::Gbn),
                ],
            )
        } else {
            (
                vec![ASD, L2_STAR, STAR],
                vec![
                    Method::Ours,
                    b(Baseline::OwenSobol),
                    b(Baseline::SobolCp),
                    b(Baseline::Halton),
                    b(Baseline::Random),
                ],
            )
        };
        let mut notes = square_notes(uniform);
        if hierarchical {
            notes.push("baselines are warped by hierarchical sample warping (Clarberg et al. 2005) over the image's pixel grid".into());
        } else if !uniform {
            notes.push("baselines are warped by the marginal-then-conditional inverse CDF".into());
        }
        Ok(Panel {
            target: target.into(),
            title: title.into(),
            spec: density.spec(),
            notes,
            metrics,
            methods,
            kind: PanelKind::SquareDiscrepancy {
                density,
                hierarchical,
            },
        })
    };
    let sphere = |target: &str, title: &str, density: Box<dyn DirectionDensity>| -> Panel {
        let uniform = density.spec() == "uniform";
        let methods = if figure == Figure::Fig3 {
            vec![
                Method::Ours,
                b(Baseline::Random),
                b(Baseline::OwenSobol),
                b(Baseline::SobolCp),
                b(Baseline::Halton),
                b(Baseline::PoissonDisk),
                Method::SphericalFibonacci,
            ]
        } else {
            vec![
                Method::Ours,
                b(Baseline::OwenSobol),
                b(Baseline::Halton),
                b(Baseline::Random),
            ]
        };
        let domain = density.domain().name();
        let mut notes = sphere_notes(uniform, s);
        if !density.has_closed_form_caps() {
            notes.push(TABLE_NOTE.into());
        }
        notes.push(format!("domain: {domain}; baselines are warped by the target's standard sampler (uniform: the equal-area octahedral map)"));
        if density.spec().starts_with("brdf:") {
            notes.push("the BRDF's standard sampler (GGX visible normals mixed with a cosine lobe) does not follow the target exactly, so the warped baselines' discrepancy against it levels off as N grows".into());
        }
        Panel {
            target: target.into(),
            title: title.into(),
            spec: density.spec(),
            notes,
            metrics: vec![CAP_L2, CAP_STAR],
            methods,
            kind: PanelKind::SphereDiscrepancy { density },
        }
    };
    let fig7_methods = vec![
        Method::Ours,
        b(Baseline::OwenSobol),
        b(Baseline::Halton),
        b(Baseline::Random),
        b(Baseline::Sot),
        b(Baseline::Gbn),
    ];
    let rmse = |reference: f64| MetricDef {
        key: "rmse",
        label: "RMSE",
        source: "estimate",
        aggregation: Aggregation::Rmse { reference },
    };
    let envmap = |domain: Domain| -> Result<EnvmapDensity, String> {
        let path = data_file(s, ENVMAP_FILE)?;
        EnvmapDensity::from_file(&path, domain).map_err(|e| e.to_string())
    };
    match figure {
        Figure::Fig2 => panels.push(square("uniform", "2D uniform", "uniform", false)?),
        Figure::Fig3 => panels.push(sphere(
            "uniform-sphere",
            "uniform sphere",
            parse_direction_spec("uniform", Domain::Sphere)?,
        )),
        Figure::Fig5 => {
            panels.push(square(
                "gaussian",
                "Gaussian (0.5, 0.5, sigma 0.15)",
                FIG5_GAUSSIAN,
                false,
            )?);
            panels.push(square(
                "quarter-disc",
                "quarter disc",
                "quarter-disc",
                false,
            )?);
            panels.push(square(
                "bilinear",
                "bilinear (0.1, 1, 0.5, 2)",
                FIG5_BILINEAR,
                false,
            )?);
            match data_file(s, IMAGE_FILE) {
                Ok(path) => panels.push(square(
                    "camera",
                    "image (camera.png)",
                    &format!("image:{path}"),
                    true,
                )?),
                Err(reason) => skipped.push(Skipped {
                    target: "camera".into(),
                    reason,
                }),
            }
        }
        Figure::Fig6 => {
            panels.push(sphere(
                "cosine",
                "cosine (hemisphere)",
                parse_direction_spec("cosine", Domain::Hemisphere)?,
            ));
            panels.push(sphere(
                "brdf",
                "BRDF (roughness 0.3, view 45 deg)",
                parse_direction_spec(BRDF_SPEC, Domain::Hemisphere)?,
            ));
            match envmap(Domain::Sphere) {
                Ok(e) => panels.push(sphere("envmap", "environment map (courtyard)", Box::new(e))),
                Err(reason) => skipped.push(Skipped {
                    target: "envmap".into(),
                    reason,
                }),
            }
        }
        Figure::Fig7 => {
            for it in SquareIntegrand::all() {
                let notes = vec![
                    it.formula.to_string(),
                    format!("reference (closed form): {:.17e}", it.reference),
                    "estimate (1/N) sum f(x_i)/q(x_i); rmse over the realizations (independent seeds / scrambles)".into(),
                    "sot and gbn are run against the target density; the others are warped by its inverse CDF".into(),
                ];
                panels.push(Panel {
                    target: it.name.into(),
                    title: it.name.into(),
                    spec: it.density.spec(),
                    notes,
                    metrics: vec![rmse(it.reference)],
                    methods: fig7_methods.clone(),
                    kind: PanelKind::SquareIntegral(it),
                });
            }
            let mut sph = vec![Ok(SphereIntegrand::abs_z())];
            let brdf = BrdfTarget::new(0.3, 45.0, Domain::Hemisphere)?;
            sph.push(envmap(Domain::Sphere).map(|e| SphereIntegrand::brdf_envmap(brdf, e)));
            sph.push(envmap(Domain::Sphere).map(SphereIntegrand::envmap_cosine));
            let names = ["sphere-abs-z", "brdf-envmap", "envmap-cosine"];
            for (it, name) in sph.into_iter().zip(names) {
                match it {
                    Ok(it) => {
                        let reference = sphere_reference(&it, s)?;
                        let notes = vec![
                            it.formula.to_string(),
                            format!(
                                "reference ({}): {reference:.17e}",
                                if it.reference_is_quadrature() {
                                    format!("quadrature over the envmap's pixels, {0}x{0} midpoints each, cached", s.reference_subdivision)
                                } else {
                                    "closed form / exact for the tabulated map".to_string()
                                }
                            ),
                            "estimate (1/N) sum f(w_i)/p(w_i), p the density the points follow (the target for ours, sot, gbn; the standard sampler's for warped baselines); rmse over the realizations".into(),
                            "sot and gbn run in the domain's equal-area square against the target density projected to it (256x256 cells), then mapped".into(),
                        ];
                        let mut notes = notes;
                        if !it.density().has_closed_form_caps() {
                            notes.push(TABLE_NOTE.into());
                        }
                        panels.push(Panel {
                            target: it.name.into(),
                            title: it.name.into(),
                            spec: it.density().spec(),
                            notes,
                            metrics: vec![rmse(reference)],
                            methods: fig7_methods.clone(),
                            kind: PanelKind::SphereIntegral(it),
                        });
                    }
                    Err(reason) => skipped.push(Skipped {
                        target: name.into(),
                        reason,
                    }),
                }
            }
        }
    }
    Ok((panels, skipped))
}

/// The panels and skipped panels of `figure` whose short names are in `names`
/// (all of them when `names` is empty), in the figure's order: a rerun of a few
/// panels, e.g. after a target's definition changed.
///
/// # Errors
/// A name that is no panel of `figure` (the message lists the figure's panels).
pub fn select(
    figure: Figure,
    panels: Vec<Panel>,
    skipped: Vec<Skipped>,
    names: &[String],
) -> Result<(Vec<Panel>, Vec<Skipped>)> {
    if names.is_empty() {
        return Ok((panels, skipped));
    }
    let known: Vec<&str> = panels
        .iter()
        .map(|p| p.target.as_str())
        .chain(skipped.iter().map(|s| s.target.as_str()))
        .collect();
    if let Some(bad) = names.iter().find(|n| !known.contains(&n.as_str())) {
        bail!(
            "{figure} has no panel `{bad}` (its panels: {})",
            known.join(", ")
        );
    }
    let wanted = |t: &str| names.iter().any(|n| n == t);
    Ok((
        panels.into_iter().filter(|p| wanted(&p.target)).collect(),
        skipped.into_iter().filter(|s| wanted(&s.target)).collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_figure_has_panels_and_missing_data_is_skipped() {
        let s = EvalSettings::quick("/nonexistent-out", "/nonexistent-data");
        for f in Figure::ALL {
            let (p, skipped) = panels(f, &s).unwrap();
            assert!(!p.is_empty(), "{f}");
            for panel in &p {
                assert!(panel.methods.contains(&Method::Ours));
                assert!(!panel.metrics.is_empty());
            }
            let expect_skipped = match f {
                Figure::Fig5 | Figure::Fig6 => 1,
                Figure::Fig7 => 2,
                _ => 0,
            };
            assert_eq!(skipped.len(), expect_skipped, "{f}: {skipped:?}");
        }
    }

    #[test]
    fn select_keeps_the_named_panels_in_order_and_rejects_unknown_names() {
        let s = EvalSettings::quick("/nonexistent-out", "/nonexistent-data");
        let names = |p: &[Panel]| p.iter().map(|p| p.target.clone()).collect::<Vec<_>>();
        let (p, k) = panels(Figure::Fig6, &s).unwrap();
        let all = names(&p);
        assert_eq!(all, ["cosine", "brdf"]);
        let (p, k) = select(Figure::Fig6, p, k, &[]).unwrap();
        assert_eq!((names(&p), k.len()), (all, 1));
        let (p, k) = select(Figure::Fig6, p, k, &["brdf".to_string()]).unwrap();
        assert_eq!((names(&p), k.len()), (vec!["brdf".to_string()], 0));
        // The skipped envmap panel is a known name: selecting it runs nothing.
        let (p, k) = panels(Figure::Fig6, &s).unwrap();
        let (p, k) = select(Figure::Fig6, p, k, &["envmap".to_string()]).unwrap();
        assert_eq!((p.len(), k.len()), (0, 1));
        let (p, k) = panels(Figure::Fig6, &s).unwrap();
        let err = select(
            Figure::Fig6,
            p,
            k,
            &["brdf".to_string(), "bdrf".to_string()],
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            err.contains("no panel `bdrf`") && err.contains("cosine, brdf, envmap"),
            "{err}"
        );
    }
}
