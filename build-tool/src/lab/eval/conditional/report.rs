//! The conditional quality report: per-condition scores and ratios, the summary
//! over all conditions and per metallic value, and its files (`conditional.json`,
//! `conditional.csv`, `conditional-summary.md`, ratio heat maps per metallic and
//! sets drawn over their target).

use super::{ConditionalSettings, Diversity};
use crate::lab::eval::cache::sanitize;
use crate::lab::eval::stats;
use crate::plot::{render_direction_set, render_heatmap, Heatmap};
use crate::sphere::{BrdfTarget, DirectionDensity};
use anyhow::Result;
use glam::DVec3;
use nuld_core::blob::Domain;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Name of the exact-inverse-CDF reference (Owen-Sobol warped by the tabulated
/// inverse CDF of the target).
pub const EXACT: &str = "owen-sobol-exact";
/// Name of the renderer's-mixture reference (Owen-Sobol warped by VNDF + cosine).
pub const MIXTURE: &str = "owen-sobol-mixture";
/// Name of the per-condition direct optimization.
pub const DIRECT: &str = "direct";

/// A method's scores at one condition: means over its sets.
#[derive(Clone, Debug, Serialize)]
pub struct MethodScore {
    /// Method name.
    pub method: String,
    /// Sets scored.
    pub sets: usize,
    /// Mean cap L2 discrepancy (theta-uniform, paper Eq. 9).
    pub cap_l2: f64,
    /// Its standard error: `sqrt(se_instances^2 + se_caps^2)`.
    pub cap_l2_se: f64,
    /// Spread over sets, `sd / sqrt(sets)` (0 for one set).
    pub cap_l2_se_instances: f64,
    /// Mean Monte Carlo standard error of one set's estimate (the caps are shared by
    /// every set, so this part does not average out).
    pub cap_l2_se_caps: f64,
    /// Mean of the largest local discrepancy found (a lower bound of the cap star
    /// discrepancy).
    pub cap_star: f64,
}

impl MethodScore {
    /// Aggregates per-set `(cap L2, its MC se, largest local discrepancy)`.
    ///
    /// # Panics
    /// If `scores` is empty.
    pub fn from_scores(method: &str, scores: &[(f64, f64, f64)]) -> Self {
        assert!(!scores.is_empty(), "no sets scored");
        let column =
            |f: fn(&(f64, f64, f64)) -> f64| stats::mean(&scores.iter().map(f).collect::<Vec<_>>());
        let cap_l2 = column(|s| s.0);
        let se_caps = column(|s| s.1).value;
        Self {
            method: method.into(),
            sets: scores.len(),
            cap_l2: cap_l2.value,
            cap_l2_se: cap_l2.stderr.hypot(se_caps),
            cap_l2_se_instances: cap_l2.stderr,
            cap_l2_se_caps: se_caps,
            cap_star: column(|s| s.2).value,
        }
    }
}

/// A sampler's ratios at one condition (its mean over the reference's mean).
#[derive(Clone, Debug, Serialize)]
pub struct SamplerRatios {
    /// Sampler name.
    pub sampler: String,
    /// Cap L2 over the exact-inverse-CDF reference's.
    pub to_exact: f64,
    /// Cap L2 over the mixture reference's.
    pub to_mixture: f64,
    /// Cap L2 over the direct optimization's (where it ran).
    pub to_direct: Option<f64>,
    /// Largest local discrepancy over the exact reference's.
    pub star_to_exact: f64,
}

impl SamplerRatios {
    /// The ratios of `score` to the references at its condition.
    pub fn of(score: &MethodScore, refs: &References<'_>) -> Self {
        Self {
            sampler: score.method.clone(),
            to_exact: score.cap_l2 / refs.exact.cap_l2,
            to_mixture: score.cap_l2 / refs.mixture.cap_l2,
            to_direct: refs.direct.map(|d| score.cap_l2 / d.cap_l2),
            star_to_exact: score.cap_star / refs.exact.cap_star,
        }
    }
}

/// A method's diversity at one condition.
#[derive(Clone, Debug, Serialize)]
pub struct NamedDiversity {
    /// Method name.
    pub method: String,
    /// The figures.
    #[serde(flatten)]
    pub diversity: Diversity,
}

/// Instance 0 of a method at one condition, for pictures.
#[derive(Clone, Debug, Serialize)]
pub struct ExampleSet {
    /// Method name.
    pub method: String,
    /// Unit directions `[x, y, z]`.
    pub directions: Vec<[f64; 3]>,
}

/// The references' scores at one condition.
pub struct References<'a> {
    /// Exact-inverse-CDF reference.
    pub exact: &'a MethodScore,
    /// Mixture reference.
    pub mixture: &'a MethodScore,
    /// Direct optimization, where it ran.
    pub direct: Option<&'a MethodScore>,
}

/// Everything measured at one condition.
#[derive(Clone, Debug, Serialize)]
pub struct ConditionResult {
    /// Roughness.
    pub roughness: f64,
    /// View angle (degrees).
    pub theta_o_deg: f64,
    /// glTF metallic in `[0, 1]`.
    pub metallic: f64,
    /// Directional albedo `A` (the estimator weight).
    pub albedo: f64,
    /// The samplers' scores.
    pub samplers: Vec<MethodScore>,
    /// Exact-inverse-CDF reference.
    pub exact: MethodScore,
    /// Mixture reference.
    pub mixture: MethodScore,
    /// Direct optimization, where it ran.
    pub direct: Option<MethodScore>,
    /// The samplers' ratios.
    pub ratios: Vec<SamplerRatios>,
    /// Diversity of every sampler, then of the exact reference (independent
    /// scrambles: the calibration).
    pub diversity: Vec<NamedDiversity>,
    /// Instance 0 of every sampler and of the exact reference.
    pub examples: Vec<ExampleSet>,
}

impl ConditionResult {
    /// Assembles a condition's result and computes its ratios.
    pub fn new(
        [roughness, theta_o_deg, metallic]: [f64; 3],
        albedo: f64,
        samplers: Vec<MethodScore>,
        [exact, mixture]: [MethodScore; 2],
        direct: Option<MethodScore>,
        diversity: Vec<(String, Diversity)>,
        examples: Vec<(String, Vec<DVec3>)>,
    ) -> Self {
        let refs = References {
            exact: &exact,
            mixture: &mixture,
            direct: direct.as_ref(),
        };
        let ratios = samplers
            .iter()
            .map(|s| SamplerRatios::of(s, &refs))
            .collect();
        Self {
            roughness,
            theta_o_deg,
            metallic,
            albedo,
            samplers,
            exact,
            mixture,
            direct,
            ratios,
            diversity: diversity
                .into_iter()
                .map(|(method, diversity)| NamedDiversity { method, diversity })
                .collect(),
            examples: examples
                .into_iter()
                .map(|(method, d)| ExampleSet {
                    method,
                    directions: d.iter().map(|v| v.to_array()).collect(),
                })
                .collect(),
        }
    }

    /// The references' scores here.
    pub fn references(&self) -> References<'_> {
        References {
            exact: &self.exact,
            mixture: &self.mixture,
            direct: self.direct.as_ref(),
        }
    }

    /// The diversity of `method` here, if measured.
    pub fn diversity_of(&self, method: &str) -> Option<&Diversity> {
        self.diversity
            .iter()
            .find(|d| d.method == method)
            .map(|d| &d.diversity)
    }
}

/// One sampler (or the exact reference, as calibration) over all conditions.
#[derive(Clone, Debug, Serialize)]
pub struct SamplerSummary {
    /// Sampler name.
    pub sampler: String,
    /// Mean over conditions of the cap-L2 ratio to the exact reference.
    pub mean_ratio_exact: f64,
    /// Largest such ratio ...
    pub worst_ratio_exact: f64,
    /// ... and where (`[roughness, theta_o_deg, metallic]`).
    pub worst_condition: [f64; 3],
    /// Conditions where the ratio to the exact reference exceeds 1.
    pub conditions_above_one: usize,
    /// Mean cap-L2 ratio to the mixture reference.
    pub mean_ratio_mixture: f64,
    /// Mean cap-L2 ratio to direct optimization over the conditions where it ran.
    pub mean_ratio_direct: Option<f64>,
    /// Mean ratio of the largest local discrepancy to the exact reference's.
    pub mean_star_ratio_exact: f64,
    /// Mean union ratio ([`Diversity::union_ratio`]; 1/sqrt(K) independent, 1 identical).
    pub mean_union_ratio: f64,
    /// Largest union ratio.
    pub worst_union_ratio: f64,
    /// Mean nearest-neighbour ratio ([`Diversity::nn_ratio`]; 0.65 independent, 0 identical).
    pub mean_nn_ratio: f64,
    /// Smallest nearest-neighbour ratio.
    pub worst_nn_ratio: f64,
}

/// The summary over the conditions of one metallic value.
#[derive(Clone, Debug, Serialize)]
pub struct MetallicSummary {
    /// The metallic value.
    pub metallic: f64,
    /// Conditions at it.
    pub conditions: usize,
    /// As [`ConditionalReport::summary`], over these conditions only.
    pub summary: Vec<SamplerSummary>,
    /// Mean of mixture / exact (cap L2) over them.
    pub mixture_over_exact: f64,
    /// Mean of direct / exact (cap L2) over those with direct optimization.
    pub direct_over_exact: Option<f64>,
}

/// The whole report (`conditional.json`). Deterministic: no timings.
#[derive(Clone, Debug, Serialize)]
pub struct ConditionalReport {
    /// What it shows.
    pub title: String,
    /// Points per set.
    pub n: usize,
    /// The samplers under test.
    pub samplers: Vec<String>,
    /// Settings of the run.
    pub settings: ConditionalSettings,
    /// Per sampler over all conditions; then the exact reference's own diversity
    /// (`exact` row: ratios 1 by definition).
    pub summary: Vec<SamplerSummary>,
    /// Mean over conditions of mixture / exact (cap L2).
    pub mixture_over_exact: f64,
    /// Mean over direct conditions of direct / exact (cap L2).
    pub direct_over_exact: Option<f64>,
    /// The summary per metallic value, in the order of the conditions.
    pub by_metallic: Vec<MetallicSummary>,
    /// Per condition.
    pub conditions: Vec<ConditionResult>,
}

fn mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let (s, k) = v.fold((0.0, 0usize), |(s, k), x| (s + x, k + 1));
    (k > 0).then(|| s / k as f64)
}

impl ConditionalReport {
    /// Assembles the report and its summary.
    pub fn new(
        settings: &ConditionalSettings,
        samplers: Vec<String>,
        n: usize,
        conditions: Vec<ConditionResult>,
    ) -> Self {
        let all: Vec<&ConditionResult> = conditions.iter().collect();
        let (summary, mixture_over_exact, direct_over_exact) = summaries(&samplers, &all);
        let by_metallic = metallic_values(&conditions)
            .into_iter()
            .map(|m| {
                let at: Vec<&ConditionResult> =
                    conditions.iter().filter(|c| c.metallic == m).collect();
                let (summary, mixture_over_exact, direct_over_exact) = summaries(&samplers, &at);
                MetallicSummary {
                    metallic: m,
                    conditions: at.len(),
                    summary,
                    mixture_over_exact,
                    direct_over_exact,
                }
            })
            .collect();
        Self {
            title: format!(
                "conditional sampler on held-out (roughness, θo, metallic), N = {n}: cap L2 and largest \
                 local discrepancy vs Owen-Sobol + exact inverse CDF, Owen-Sobol + \
                 VNDF/cosine mixture, and per-condition optimization; instance diversity"
            ),
            n,
            samplers,
            settings: settings.clone(),
            summary,
            mixture_over_exact,
            direct_over_exact,
            by_metallic,
            conditions,
        }
    }

    /// The summary as Markdown tables (what `eval conditional` prints): over all
    /// conditions, then per metallic value.
    pub fn summary_markdown(&self) -> String {
        let metallic: Vec<String> = self
            .by_metallic
            .iter()
            .map(|m| m.metallic.to_string())
            .collect();
        let mut s = format!(
            "N = {}, {} conditions (metallic {}), {} instances (diversity: {}); cap L2 ratios \
             (mean / worst) to Owen-Sobol + exact inverse CDF, mean to the VNDF/cosine mixture \
             and to direct optimization; diversity: union of instances / one instance \
             (independent sets ~{:.3}, identical 1), nearest-neighbour angle across / within \
             (independent ~0.65, identical 0).\n\n\
             | sampler | / exact (mean) | / exact (worst, at r, θo, m) | above 1 | / mixture | / direct | D* / exact | union ratio (mean, worst) | NN ratio (mean, worst) |\n\
             |---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
            self.n,
            self.conditions.len(),
            metallic.join(", "),
            self.settings.instances,
            self.settings.union_instances,
            1.0 / (self.settings.union_instances as f64).sqrt(),
        );
        for l in &self.summary {
            let _ = writeln!(s, "| {} | {} |", l.sampler, summary_cells(l, true));
        }
        let _ = writeln!(
            s,
            "\nReferences: mixture / exact {:.3}, direct / exact {}.",
            self.mixture_over_exact,
            opt3(self.direct_over_exact)
        );
        s.push_str(
            "\nPer metallic:\n\n\
             | metallic | sampler | / exact (mean) | / exact (worst, at r, θo) | above 1 | / mixture | / direct | D* / exact | union ratio (mean, worst) | NN ratio (mean, worst) |\n\
             |---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        );
        for m in &self.by_metallic {
            for l in &m.summary {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} |",
                    m.metallic,
                    l.sampler,
                    summary_cells(l, false)
                );
            }
        }
        let refs: Vec<String> = self
            .by_metallic
            .iter()
            .map(|m| {
                format!(
                    "metallic {}: mixture / exact {:.3}, direct / exact {}",
                    m.metallic,
                    m.mixture_over_exact,
                    opt3(m.direct_over_exact)
                )
            })
            .collect();
        let _ = writeln!(s, "\nReferences per metallic: {}.", refs.join("; "));
        s
    }

    /// The CSV: one line per (condition, method); ratio and diversity columns empty
    /// where they do not apply.
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "roughness,theta_o_deg,metallic,method,sets,cap_l2,cap_l2_se,cap_star,\
             ratio_to_exact,ratio_to_mixture,ratio_to_direct,union_ratio,nn_ratio\n",
        );
        let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
        for c in &self.conditions {
            let refs = [Some(&c.exact), Some(&c.mixture), c.direct.as_ref()];
            let all = c.samplers.iter().chain(refs.into_iter().flatten());
            for m in all {
                let r = c.ratios.iter().find(|r| r.sampler == m.method);
                let d = c.diversity_of(&m.method);
                let _ = writeln!(
                    out,
                    "{},{},{},{},{},{:e},{:e},{:e},{},{},{},{},{}",
                    c.roughness,
                    c.theta_o_deg,
                    c.metallic,
                    m.method,
                    m.sets,
                    m.cap_l2,
                    m.cap_l2_se,
                    m.cap_star,
                    opt(r.map(|r| r.to_exact)),
                    opt(r.map(|r| r.to_mixture)),
                    opt(r.and_then(|r| r.to_direct)),
                    opt(d.map(|d| d.union_ratio)),
                    opt(d.map(|d| d.nn_ratio)),
                );
            }
        }
        out
    }

    /// Writes `conditional.json`, `conditional.csv`, `conditional-summary.md`, per
    /// metallic value a heat map over `(roughness, theta_o)` of each sampler's
    /// ratio to the exact reference (`conditional-<sampler>-ratio-m<M>.png`) and of
    /// its union ratio (`conditional-<sampler>-union-m<M>.png`), and instance 0 of
    /// every sampler and of the exact reference over the target at up to three
    /// conditions (`conditional-sets-<method>-r<R>-t<T>-m<M>.png`, one file per
    /// method and condition); returns the paths.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        crate::output::ensure_dir(dir)?;
        let mut written = Vec::new();
        let mut put = |name: &str, bytes: &[u8]| -> Result<()> {
            let p = dir.join(name);
            crate::output::write_atomic(&p, bytes)?;
            written.push(p);
            Ok(())
        };
        let mut json = serde_json::to_string_pretty(self)?;
        json.push('\n');
        put("conditional.json", json.as_bytes())?;
        put("conditional.csv", self.csv().as_bytes())?;
        put("conditional-summary.md", self.summary_markdown().as_bytes())?;
        let mut rs: Vec<f64> = self.conditions.iter().map(|c| c.roughness).collect();
        let mut ts: Vec<f64> = self.conditions.iter().map(|c| c.theta_o_deg).collect();
        for v in [&mut rs, &mut ts] {
            v.sort_by(f64::total_cmp);
            v.dedup();
        }
        for (j, name) in self.samplers.iter().enumerate() {
            let ratio = |c: &ConditionResult| Some(c.ratios[j].to_exact);
            let union = |c: &ConditionResult| c.diversity_of(name).map(|d| d.union_ratio);
            let plots: [(&str, f64, &CellValue); 2] =
                [("ratio", 1.0, &ratio), ("union", 0.3, &union)];
            for m in self.by_metallic.iter().map(|m| m.metallic) {
                for &(what, center, value) in &plots {
                    let cells: Vec<Option<f64>> = rs
                        .iter()
                        .flat_map(|&r| ts.iter().map(move |&t| (r, t)))
                        .map(|(r, t)| {
                            self.conditions
                                .iter()
                                .find(|c| c.roughness == r && c.theta_o_deg == t && c.metallic == m)
                                .and_then(value)
                        })
                        .collect();
                    let file = format!("conditional-{}-{what}-m{m}.png", sanitize(name));
                    let title = match what {
                        "ratio" => format!(
                            "{name}: cap L2 / Owen-Sobol + exact inverse CDF, N = {}, metallic {m}",
                            self.n
                        ),
                        _ => format!(
                            "{name}: cap L2 of {} instances' union / one instance's, metallic {m}",
                            self.settings.union_instances
                        ),
                    };
                    render_heatmap(
                        &dir.join(&file),
                        &Heatmap {
                            title: &title,
                            x_label: "theta_o (degrees)",
                            y_label: "roughness",
                            xs: &ts,
                            ys: &rs,
                            values: &cells,
                            center,
                        },
                        (720, 600),
                    )?;
                    written.push(dir.join(file));
                }
            }
        }
        written.extend(self.write_set_pictures(dir)?);
        Ok(written)
    }

    /// Instance 0 of every method over the target at up to three conditions (the
    /// first, middle and last where direct optimization ran, else of all).
    fn write_set_pictures(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let pool: Vec<&ConditionResult> = if self.settings.direct.is_empty() {
            self.conditions.iter().collect()
        } else {
            self.settings
                .direct
                .iter()
                .map(|&i| &self.conditions[i])
                .collect()
        };
        let mut picks = vec![0, pool.len() / 2, pool.len() - 1];
        picks.dedup();
        let mut written = Vec::new();
        for c in picks.into_iter().map(|i| pool[i]) {
            // Only the density is drawn: no cap-measure table worth building.
            let target = BrdfTarget::coarse(c.roughness, c.theta_o_deg, c.metallic, 1 << 10)?;
            for e in &c.examples {
                let square: Vec<glam::DVec2> = e
                    .directions
                    .iter()
                    .map(|d| Domain::Hemisphere.to_square(DVec3::from_array(*d)))
                    .collect();
                let file = format!(
                    "conditional-sets-{}-r{}-t{}-m{}.png",
                    sanitize(&e.method),
                    c.roughness,
                    c.theta_o_deg,
                    c.metallic
                );
                render_direction_set(
                    &dir.join(&file),
                    &format!(
                        "{} instance 0: r {}, theta_o {}, m {}",
                        e.method, c.roughness, c.theta_o_deg, c.metallic
                    ),
                    &|d| target.pdf(d),
                    &|p| Domain::Hemisphere.to_direction(p),
                    &square,
                    360,
                )?;
                written.push(dir.join(file));
            }
        }
        Ok(written)
    }
}

/// A heat map's value at a condition (`None`: an empty cell).
type CellValue<'a> = dyn Fn(&ConditionResult) -> Option<f64> + 'a;

/// The metallic values of `conditions`, in the order they first appear.
fn metallic_values(conditions: &[ConditionResult]) -> Vec<f64> {
    let mut values: Vec<f64> = Vec::new();
    for c in conditions {
        if !values.contains(&c.metallic) {
            values.push(c.metallic);
        }
    }
    values
}

/// Over `conditions`: the summary of every sampler of `samplers` (named in the
/// order of each condition's ratios), then of the exact reference against
/// itself (ratios 1, its own diversity); the mean mixture / exact and the mean
/// direct / exact (cap L2) where direct optimization ran.
fn summaries(
    samplers: &[String],
    conditions: &[&ConditionResult],
) -> (Vec<SamplerSummary>, f64, Option<f64>) {
    let mut summary: Vec<SamplerSummary> = samplers
        .iter()
        .enumerate()
        .map(|(j, name)| summarize(name, conditions, |c| c.ratios[j].clone()))
        .collect();
    summary.push(summarize(EXACT, conditions, |c| {
        SamplerRatios::of(&c.exact, &c.references())
    }));
    let mixture_over_exact =
        mean(conditions.iter().map(|c| c.mixture.cap_l2 / c.exact.cap_l2)).unwrap_or(f64::NAN);
    let direct_over_exact = mean(
        conditions
            .iter()
            .filter_map(|c| c.direct.as_ref().map(|d| d.cap_l2 / c.exact.cap_l2)),
    );
    (summary, mixture_over_exact, direct_over_exact)
}

/// `v` to 3 decimals, `-` for none.
fn opt3(v: Option<f64>) -> String {
    v.map_or("-".to_string(), |v| format!("{v:.3}"))
}

/// The Markdown cells of a summary row after the sampler's name; the worst
/// condition with its metallic when `with_metallic`.
fn summary_cells(l: &SamplerSummary, with_metallic: bool) -> String {
    let [r, t, m] = l.worst_condition;
    let at = if with_metallic {
        format!("{r}, {t}, {m}")
    } else {
        format!("{r}, {t}")
    };
    format!(
        "{:.3} | {:.3} ({at}) | {} | {:.3} | {} | {:.3} | {:.3}, {:.3} | {:.3}, {:.3}",
        l.mean_ratio_exact,
        l.worst_ratio_exact,
        l.conditions_above_one,
        l.mean_ratio_mixture,
        opt3(l.mean_ratio_direct),
        l.mean_star_ratio_exact,
        l.mean_union_ratio,
        l.worst_union_ratio,
        l.mean_nn_ratio,
        l.worst_nn_ratio,
    )
}

/// The summary of one sampler over `conditions`, `ratio(c)` its ratios at
/// condition `c`.
///
/// # Panics
/// If `conditions` is empty.
fn summarize(
    name: &str,
    conditions: &[&ConditionResult],
    ratio: impl Fn(&ConditionResult) -> SamplerRatios,
) -> SamplerSummary {
    let ratios: Vec<SamplerRatios> = conditions.iter().map(|c| ratio(c)).collect();
    let to_exact: Vec<f64> = ratios.iter().map(|r| r.to_exact).collect();
    let (worst_at, worst) =
        to_exact
            .iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |b, (i, v)| if v > b.1 { (i, v) } else { b },
            );
    let div: Vec<&Diversity> = conditions
        .iter()
        .filter_map(|c| c.diversity_of(name))
        .collect();
    SamplerSummary {
        sampler: name.into(),
        mean_ratio_exact: mean(to_exact.iter().copied()).unwrap_or(f64::NAN),
        worst_ratio_exact: worst,
        worst_condition: [
            conditions[worst_at].roughness,
            conditions[worst_at].theta_o_deg,
            conditions[worst_at].metallic,
        ],
        conditions_above_one: to_exact.iter().filter(|&&v| v > 1.0).count(),
        mean_ratio_mixture: mean(ratios.iter().map(|r| r.to_mixture)).unwrap_or(f64::NAN),
        mean_ratio_direct: mean(ratios.iter().filter_map(|r| r.to_direct)),
        mean_star_ratio_exact: mean(ratios.iter().map(|r| r.star_to_exact)).unwrap_or(f64::NAN),
        mean_union_ratio: mean(div.iter().map(|d| d.union_ratio)).unwrap_or(f64::NAN),
        worst_union_ratio: div.iter().map(|d| d.union_ratio).fold(f64::NAN, f64::max),
        mean_nn_ratio: mean(div.iter().map(|d| d.nn_ratio)).unwrap_or(f64::NAN),
        worst_nn_ratio: div.iter().map(|d| d.nn_ratio).fold(f64::NAN, f64::min),
    }
}
