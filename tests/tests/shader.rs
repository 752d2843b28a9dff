//! The WGSL sampler (`nuld_runtime::shader`) run by a real Vulkan driver through
//! wgpu, against `nuld-runtime` on the CPU, over grids of (condition, instance,
//! index): point and direction sets, a briefly trained and distilled BRDF sampler
//! (on the tabulated prior, warp 3), and random-content samplers with the shapes
//! training does not use (SiLU, three layers, a lattice generator whose products
//! overflow 32 bits) on every point warp; the tabulated prior's samplers at
//! metallic 0, 0.5 and 1, with the unbiased mode, the pdf of a direction and the
//! albedo.
//!
//! On a machine without an adapter the tests print why (on stderr, shown with
//! `--nocapture`) and pass, except under CI (the `CI` environment variable set),
//! where they fail: CI installs lavapipe, the CPU Vulkan driver
//! (`apt-get install mesa-vulkan-drivers libvulkan1`).
//!
//! Tolerances, in absolute terms on unit-vector components and weights, relative
//! on the pdf:
//! * 2D point sets: exact;
//! * directions and weights in table mode, at conditions and at BRDF views
//!   (`BrdfSampler::sample`): [`TABLE_TOLERANCE`] = 8 f32 ulps of 1.0 (`8 * 2^-23`, 9.5e-7):
//!   both sides evaluate the same `f32` operations in the same order (the shader
//!   ports libm's `acosf`), and differ by the driver's rounding of `sin`, `cos`,
//!   `sqrt` and division (and, for direction sets, the runtime's `f64` map). On
//!   lavapipe the largest difference measured is 6 ulps;
//! * network mode: [`NETWORK_TOLERANCE`] = 1e-4 (the driver's `exp` and fused
//!   multiply-adds through the layers);
//! * for the BRDF mixture warp (warp 1) both tolerances apply to the difference
//!   divided by the warp's local gain `1 + J` ([`warp_gain`], `J` its Jacobian's
//!   largest column norm): near the rim of the visible-normal disk a rounding of
//!   the square point or of an intermediate moves the direction by up to a few
//!   hundred times as much, for the runtime as for the shader. The raw maxima are
//!   printed too;
//! * for the tabulated BRDF prior (warp 3) they apply to each part of the sample
//!   divided by its own gain ([`brdf_table_gain`]): the direction's (the inverted
//!   CDFs move the square point by a rounding over the density), the weight's
//!   `f cos / pdf` (GGX at roughness 0.1 turns an ulp of `n.h` into up to `4
//!   10^4` ulps of `f`) and the pdf's (the pdf of a direction reads its square
//!   point through `sqrt(1 - h.z)`). The raw differences are the runtime's own
//!   `f32` error's size: on lavapipe up to 6.4e-4 on a direction, 0.39 on a
//!   weight (of a 5 x 5 prior's; 2.6e-2 on the trained sampler's, whose weights
//!   reach 10 at roughness 0.1) and 2.2e-3 relative on a pdf, in network mode;
//!   2.5e-4, 0.36 and 1.2e-3 in table mode. Divided by their gains the largest is
//!   3.6e-7 in table mode (3 ulps of 1.0), 3.9e-7 in network mode.
//!
//! Each test prints the largest difference it measured.

#[path = "../examples/shader_sample.rs"]
mod shader_sample;

use nuld_core::blob::{Domain, Layout, SectionTag};
use nuld_core::brdf::{alpha, gltf_metallic_parts, view_direction_real};
use nuld_core::brdf_prior::{query_square, BrdfPrior, BrdfPriorInfo};
use nuld_core::conditional::randomized_point;
use nuld_core::conditional::PointWarp;
use nuld_core::network::{Activation, OffsetHash};
use nuld_runtime::glam::{DVec2, DVec3, Vec2, Vec3};
use nuld_runtime::shader::SAMPLE_STRIDE;
use nuld_runtime::shader::{kernel_wgsl, KernelMode, KernelParams, KERNEL_ENTRY_POINT};
use nuld_runtime::{Blob, BrdfSampler, ConditionalSampler, Sample};
use nuld_tests::{
    as_envmap, conditional_parts, distilled_parts, fixture_tree, shape, small_brdf_prior,
    sobol_blob, with_brdf_prior, with_metal_points, with_metallic_axis, META,
};
use shader_sample::Gpu;
use std::sync::OnceLock;

/// Table mode (plain and at BRDF views) and point lookups: 8 f32 ulps of 1.0.
const TABLE_TOLERANCE: f32 = 8.0 * f32::EPSILON;
/// Network mode.
const NETWORK_TOLERANCE: f32 = 1e-4;

/// The device and the kernel's pipeline, shared by the tests (the driver compiles
/// the kernel once).
struct Kernel {
    gpu: Gpu,
    pipeline: wgpu::ComputePipeline,
}

/// One `NuldSample` read back: direction xyz and weight, then pdf and padding.
type GpuSample = ([f32; 4], [f32; 4]);

impl Kernel {
    /// The kernel's samples of `p` over `blob`.
    fn run(&self, blob: &[u8], p: &KernelParams) -> Vec<GpuSample> {
        let count = p.sample_count().expect("a small range") as u64;
        let uniform = Some(bytemuck::bytes_of(p));
        let groups = p.workgroups();
        // A sample is two 16-byte slots of the host's buffer.
        let slots = SAMPLE_STRIDE / 16;
        let out = self
            .gpu
            .run(&self.pipeline, blob, uniform, slots * count, groups, 1)
            .0;
        out.chunks_exact(2).map(|c| (c[0], c[1])).collect()
    }
}

/// The shared kernel; `None` (after a message) if there is no adapter outside CI.
///
/// # Panics
/// Under CI (`CI` set) when there is no adapter.
fn kernel() -> Option<&'static Kernel> {
    static KERNEL: OnceLock<Option<Kernel>> = OnceLock::new();
    let kernel = KERNEL
        .get_or_init(|| {
            quiet_wayland();
            let gpu = Gpu::new()?;
            // Both streams: the CI log shows it with or without --nocapture.
            println!("shader tests: adapter {}", gpu.adapter);
            eprintln!("shader tests: adapter {}", gpu.adapter);
            let pipeline = gpu.pipeline(kernel_wgsl(), KERNEL_ENTRY_POINT);
            Some(Kernel { gpu, pipeline })
        })
        .as_ref();
    if kernel.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "no GPU adapter: CI must run the shader tests on lavapipe \
             (apt-get install mesa-vulkan-drivers libvulkan1; .ci/run does)"
        );
        eprintln!(
            "shader tests skipped: no GPU adapter (apt-get install mesa-vulkan-drivers libvulkan1)"
        );
    }
    kernel
}

/// Mesa's Vulkan drivers look for a Wayland display when the instance starts, and
/// libwayland prints `error: XDG_RUNTIME_DIR is invalid or not set` to stderr
/// where the variable is unset (CI, containers), which reads like a failure. A
/// private empty directory silences it (no display is found there, as before).
fn quiet_wayland() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("nuld-xdg-runtime-{}", std::process::id()));
    let made = std::fs::create_dir_all(&dir).and_then(|()| {
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700))?;
        }
        Ok(())
    });
    if made.is_ok() {
        // Once, before any thread of this test binary starts a Vulkan instance.
        std::env::set_var("XDG_RUNTIME_DIR", &dir);
    }
}

/// `(condition, instance, index)` of sample `e` of `p`, as the kernel computes them.
/// The tests' conditions are exact in `f32` (steps of powers of two times small
/// integers), so a driver that fuses the multiply and the add agrees.
fn sample_of(p: &KernelParams, e: u32) -> (Vec2, u32, u32) {
    let i = e % p.index_count;
    let rest = e / p.index_count;
    let k = rest % p.instance_count;
    let c = rest / p.instance_count;
    let (cx, cy) = (c % p.cond_count[0], c / p.cond_count[0]);
    let cond = Vec2::new(
        p.cond_first[0] + cx as f32 * p.cond_step[0],
        p.cond_first[1] + cy as f32 * p.cond_step[1],
    );
    (cond, p.instance_first + k, p.index_first + i)
}

/// The differences of a sample: the largest of the direction's components, the
/// weight's, and the pdf's relative to the runtime's.
#[derive(Clone, Copy, Debug, Default)]
struct Gap {
    direction: f32,
    weight: f32,
    pdf: f32,
}

impl Gap {
    /// The largest of the three.
    fn max(self) -> f32 {
        self.direction.max(self.weight).max(self.pdf)
    }

    /// The largest of the three, each over its gain.
    fn scaled(self, gain: Gain) -> f32 {
        (self.direction / gain.direction)
            .max(self.weight / gain.weight)
            .max(self.pdf / gain.pdf)
    }
}

/// How much a warp magnifies a rounding, per part of the sample ([`warp_gain`]):
/// the factor on the tolerance of the direction's, the weight's and the pdf's
/// difference.
#[derive(Clone, Copy, Debug)]
struct Gain {
    direction: f32,
    weight: f32,
    pdf: f32,
}

impl Gain {
    /// The same gain for every part.
    fn all(g: f32) -> Self {
        Self {
            direction: g,
            weight: g,
            pdf: g,
        }
    }
}

/// The gap of the kernel's sample from the runtime's.
fn gap(gpu: &GpuSample, cpu: Sample) -> Gap {
    let (g, more) = gpu;
    let d = Vec3::new(g[0], g[1], g[2]) - cpu.direction;
    Gap {
        direction: d.abs().max_element(),
        weight: (g[3] - cpu.weight).abs(),
        pdf: (more[0] - cpu.pdf).abs() / cpu.pdf.max(f32::MIN_POSITIVE),
    }
}

#[test]
fn shader_point_and_direction_sets_match_the_runtime() {
    let Some(kernel) = kernel() else { return };
    let cases = [
        (Domain::Square, 100, 3),
        (Domain::Sphere, 64, 2),
        (Domain::Hemisphere, 37, 4),
    ];
    for (domain, n, sets) in cases {
        let (_, bytes) = sobol_blob(domain, n, sets, 7);
        let blob = Blob::parse(bytes.as_slice()).unwrap();
        // Instances (sets) and indices past the counts wrap.
        let p = KernelParams::new(
            KernelMode::Table,
            [0.0; 2],
            [0.0; 2],
            [1, 1],
            0..sets as u32 + 2,
            0..n as u32 + 5,
        );
        let out = kernel.run(bytes.as_slice(), &p);
        let mut worst = 0.0f32;
        for (e, got) in out.iter().enumerate() {
            let (_, set, i) = sample_of(&p, e as u32);
            let (set, i) = (set as usize, i as usize);
            if domain == Domain::Square {
                let want = blob.point_set_2d().unwrap().point(set, i);
                assert_eq!(got.0, [want.x, want.y, 0.0, 1.0], "set {set} index {i}");
                assert_eq!(got.1[0], 0.0);
            } else {
                let dirs = blob.direction_set().unwrap();
                let want = Sample {
                    direction: dirs.direction(set, i),
                    weight: 1.0,
                    pdf: 0.0,
                };
                worst = worst.max(gap(got, want).max());
            }
        }
        println!(
            "shader {}: {} samples, max |gpu - cpu| {worst:.2e} (tolerance {TABLE_TOLERANCE:.2e})",
            domain.name(),
            out.len()
        );
        assert!(worst <= TABLE_TOLERANCE, "{}: {worst}", domain.name());
    }
}

/// How much the blob's point warp at condition `cond` (blob units) amplifies a
/// perturbation of the square point `p`, the factor on the tolerances: 1 for the
/// equal-area maps; for the BRDF mixture and the environment tree `1 + J`, `J`
/// the largest column norm of the warp's Jacobian
/// (`PointWarp::direction_differences` in `f64`, step `2^-20`; for the tree
/// [`fixture_tree`], the prior of every environment fixture here, and at a
/// split of the tree a jump, where a rounding may choose the other side). The mixture's GGX branch is ill-conditioned where `u.x / p_s`
/// nears 1 (the rim of the visible-normal disk, where `sqrt(1 - p1^2 - p2^2)`
/// cancels): there the same `f32` operations, rounded by another `sqrt`, `sin` or
/// division, move the direction by far more than a few ulps (the runtime's own
/// `f32` result is as far from the exact direction). For the tabulated BRDF
/// prior `prior` (the blob's, in `f64`) at `metallic`, one gain per part of the
/// sample: [`brdf_table_gain`].
fn warp_gain(
    cs: &ConditionalSampler,
    prior: Option<&BrdfPrior<'_, f64>>,
    cond: Vec2,
    metallic: f32,
    p: Vec2,
) -> Gain {
    let info = cs.info();
    let warp = info.point_warp().expect("a parsed blob's warp");
    if warp == PointWarp::EqualArea {
        return Gain::all(1.0);
    }
    // The clamped condition, as the runtime's tables and warp see it.
    let c = info.denormalize(info.normalize(cond.to_array()));
    if warp == PointWarp::BrdfTable {
        let prior = prior.expect("the prior of a warp-3 blob");
        let cond = [c[0] as f64, c[1] as f64, metallic as f64];
        return brdf_table_gain(prior, cond, p.as_dvec2().to_array());
    }
    let fixture = fixture_tree();
    let tree = fixture.tree();
    let columns = warp.direction_differences(
        cs.domain(),
        c.map(f64::from),
        cs.lobe_probability(cond) as f64,
        Some(&tree),
        p.as_dvec2().to_array(),
        1.0 / 1_048_576.0,
    );
    let j = columns
        .iter()
        .map(|d| DVec3::from_array(*d).length())
        .fold(0.0, f64::max);
    if warp != PointWarp::EnvmapTree || tree.corners().is_empty() {
        return Gain::all(1.0 + j as f32);
    }
    // Inside a shaped leaf the pdf depends on where the point falls: a rounding
    // of the square point (the descent's rescaled `u`, the driver's division and
    // `atan`) moves it by `|d ln pdf / dp|` relatively. That slope, by central
    // differences of step `2^-20` along both axes at the sample's square point.
    let q = c.map(f64::from);
    let (d, _) = tree.sample_square(q, p.as_dvec2().to_array());
    let sq = nuld_core::sphere::sphere_to_square(DVec3::from_array(d));
    let ln_pdf = |s: DVec2| {
        let d = nuld_core::sphere::square_to_sphere(s.clamp(DVec2::ZERO, DVec2::ONE));
        tree.pdf_square(q, d.to_array()).ln()
    };
    let h = 1.0 / 1_048_576.0;
    let jp = [DVec2::X, DVec2::Y]
        .map(|e| ((ln_pdf(sq + e * h) - ln_pdf(sq - e * h)) / (2.0 * h)).abs())
        .into_iter()
        .fold(0.0, f64::max);
    let g = 1.0 + j as f32;
    Gain {
        direction: g,
        weight: g,
        pdf: g
            * (1.0
                + if jp.is_finite() {
                    jp as f32
                } else {
                    f32::INFINITY
                }),
    }
}

/// The gains of the tabulated BRDF prior's warp (warp 3) at the clamped
/// condition `cond = [roughness, θo, metallic]` and primary point `u`, each
/// `1 + J` in `f64` over the blob's tables widened (central differences of step
/// `2^-20`, the largest over two axes):
/// * the direction: `J` the length of its differences along `u`. The warp inverts
///   the tables' CDFs, so a rounding of a CDF value moves the square point `p` by
///   the rounding over the density, as a perturbation of `u` does;
/// * the weight `f cos / pdf` and the pdf (compared relatively): along `u`, `f
///   cos` and the pdf vary together, but a rounding moves `p` in any direction,
///   by up to `1 + P` ulps (`P` the largest column norm of `dp/du`), and across
///   the tables' cells the two do not follow each other: `J` the larger of their
///   differences along `u` and those along `p` times `1 + P`;
/// * both also along the direction (two tangents; the weight's `f cos` at the
///   sample's pdf, the pdf of the direction) times the direction's gain: the
///   half-vector map's own roundings (the reflection cancels at grazing views)
///   move the direction but not `p`;
/// * the weight also: `weight (specular / f) 4 c (1 - a^2) / t`, its change per
///   unit of `c = n.h`: GGX's `D = a^2 / (pi t^2)` with `t = c^2 (a^2 - 1) + 1`
///   cancels near the peak of a smooth lobe (`t` down to `a^2 = 10^-4` at
///   roughness 0.1), so an ulp of `n.h` (another rounding of the view's `sin` and
///   `cos`, of a normalization, a fused multiply-add) changes `f` by up to
///   `4 10^4` ulps, for the runtime as for the shader;
/// * the pdf also (the pdf of a given direction): the relative differences of
///   the square's density `pdf 2 pi J` (`J` the half-vector map's Jacobian)
///   along the half vector's `h.z`: the
///   pdf of a direction reads the half vector's square point through `r =
///   sqrt(1 - h.z)`, which turns an ulp of `h.z`, from the normalization of `wo +
///   wi`, into a radial step of `ulp / (4 r)` in the square near the normal (60
///   ulps of the point where `1 - h.z` is 250 ulps), a step the solid-angle
///   pdf's Jacobian `4 wo.h` does not take with it.
///
/// At a cell's edge the differences see the density's kink, at a point without
/// direction (`(+z, 0)`) a jump.
fn brdf_table_gain(prior: &BrdfPrior<'_, f64>, cond: [f64; 3], u: [f64; 2]) -> Gain {
    let h = 1.0 / 1_048_576.0;
    let wo = view_direction_real(cond[1]);
    let wo3 = DVec3::from_array(wo);
    // The square the query reads (the metal layer's star disc at metallic 1).
    let square = query_square(prior.grid(), cond);
    let clamped = |q: [f64; 2]| q.map(|x| x.clamp(0.0, 1.0));
    // What a sample of the light direction `wi` with pdf `pdf` holds, and its
    // square point.
    let sample = |wi: [f64; 3], pdf: f64| {
        let f = gltf_metallic_parts(wo, wi, cond[0], cond[2]);
        let weight = if pdf > 0.0 {
            f.total() * wi[2] / pdf
        } else {
            0.0
        };
        let p = square.point(wo, wi).map_or([0.5; 2], |(p, _)| p);
        (DVec3::from_array(wi), weight, pdf, f, DVec2::from_array(p))
    };
    let by_u = |q: [f64; 2]| {
        let (wi, pdf) = prior.sample(cond, clamped(q));
        sample(wi, pdf)
    };
    let by_p = |q: [f64; 2]| match square.direction(wo, clamped(q)) {
        Some((wi, _)) => sample(wi, prior.pdf(cond, wi)),
        None => sample([0.0, 0.0, 1.0], 0.0),
    };
    let (wi, weight, pdf, f, p) = by_u(u);
    let relative = |d: f64| d / pdf.max(f64::MIN_POSITIVE);
    // The largest differences of `at` along the two axes from `start`: of the
    // direction, the weight, the pdf (relative) and the square point.
    let differences = |at: &dyn Fn([f64; 2]) -> _, start: [f64; 2]| {
        let mut most = [0.0f64; 4];
        for axis in 0..2 {
            let (mut lo, mut hi) = (start, start);
            lo[axis] -= h;
            hi[axis] += h;
            let (d0, w0, p0, _, q0): (DVec3, f64, f64, _, DVec2) = at(lo);
            let (d1, w1, p1, _, q1) = at(hi);
            let parts = [
                (d1 - d0).length(),
                (w1 - w0).abs(),
                relative((p1 - p0).abs()),
                (q1 - q0).length(),
            ];
            for (m, d) in most.iter_mut().zip(parts) {
                *m = m.max(d / (2.0 * h));
            }
        }
        most
    };
    let [direction, weight_u, pdf_u, point] = differences(&by_u, u);
    let [_, weight_p, pdf_p, _] = differences(&by_p, p.to_array());
    let mut dweight = weight_u.max(weight_p * (1.0 + point));
    let mut dpdf = pdf_u.max(pdf_p * (1.0 + point));
    if pdf > 0.0 {
        // The direction turned by `h` along two tangents: the pdf there, and the
        // weight at the sample's pdf.
        let t1 = wi.any_orthonormal_vector();
        for t in [t1, wi.cross(t1)] {
            let turned = |s: f64| (wi + s * h * t).normalize().to_array();
            let pdf_at = |s: f64| prior.pdf(cond, turned(s));
            let weight_at = |s: f64| sample(turned(s), pdf).1;
            let along = |a: f64, b: f64| (a - b).abs() / (2.0 * h) * (1.0 + direction);
            dpdf = dpdf.max(relative(along(pdf_at(1.0), pdf_at(-1.0))));
            dweight = dweight.max(along(weight_at(1.0), weight_at(-1.0)));
        }
        // The square's density with the half vector's `h.z` moved by `eta`, its
        // azimuth kept.
        let hv = (wo3 + wi).normalize();
        let planar = hv.truncate().length();
        let eta = h.min(0.5 * (1.0 - hv.z));
        if planar > 0.0 && eta > 0.0 {
            let square_pdf_at = |s: f64| {
                let z = hv.z + s * eta;
                let k = (1.0 - z * z).max(0.0).sqrt() / planar;
                let h2 = DVec3::new(hv.x * k, hv.y * k, z);
                let c = wo3.dot(h2);
                let wi2 = (2.0 * c * h2 - wo3).to_array();
                let jac = square.point(wo, wi2).map_or(0.0, |(_, j)| j);
                prior.pdf(cond, wi2) * jac
            };
            let d = (square_pdf_at(1.0) - square_pdf_at(-1.0)).abs() / (2.0 * eta);
            let jac = square.point(wo, wi.to_array()).map_or(0.0, |(_, j)| j);
            dpdf = dpdf.max(relative(d / jac.max(f64::MIN_POSITIVE)));
        }
        // GGX's conditioning in `c = n.h`.
        let c = hv.z;
        let a2 = alpha(cond[0]) * alpha(cond[0]);
        let t = c * c * (a2 - 1.0) + 1.0;
        let share = f.specular / f.total().max(f64::MIN_POSITIVE);
        dweight = dweight.max(weight * share * 4.0 * c * (1.0 - a2) / t);
    }
    Gain {
        direction: (1.0 + direction) as f32,
        weight: (1.0 + dweight) as f32,
        pdf: (1.0 + dpdf) as f32,
    }
}

/// The blob's tabulated BRDF prior (warp 3) with its tables widened to `f64`:
/// what [`brdf_table_gain`] differentiates. `None` for other blobs.
struct WidePrior {
    info: BrdfPriorInfo,
    tables: [Vec<f64>; 4],
}

impl WidePrior {
    fn of(bytes: &[u8]) -> Option<Self> {
        let layout = Layout::read(bytes).ok()?;
        let (_, info) = layout.section(SectionTag::BrdfPriorInfo).ok()?;
        let info: BrdfPriorInfo = bytemuck::pod_read_unaligned(info);
        let table = |tag| {
            let (_, bytes) = layout.section(tag).expect("a warp-3 blob's prior section");
            bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect::<Vec<f64>>()
        };
        Some(Self {
            info,
            tables: [
                table(SectionTag::BrdfPriorData),
                table(SectionTag::BrdfPriorMarginal),
                table(SectionTag::BrdfPriorConditional),
                table(SectionTag::BrdfPriorMasses),
            ],
        })
    }

    fn prior(&self) -> BrdfPrior<'_, f64> {
        let [data, marginal, conditional, masses] = &self.tables;
        BrdfPrior::view(self.info, data, marginal, conditional, masses).expect("a parsed prior")
    }
}

/// `theta_o` in degrees of a BRDF view `wo` (any length; zero, infinite or NaN:
/// normal incidence), in `f64`: the condition `BrdfSampler::sample` samples at.
fn view_theta_deg(wo: Vec3) -> f64 {
    let w = wo.as_dvec3();
    let len = w.length();
    if !(len.is_finite() && len > 0.0) {
        return 0.0;
    }
    (w.z / len).clamp(0.0, 1.0).acos().to_degrees()
}

/// The largest `|gpu - cpu| / gain` ([`Gap::max`]) and the largest `|gpu - cpu|`
/// of samples, per part of the sample.
#[derive(Default)]
struct Worst {
    scaled: f32,
    raw: Gap,
}

impl Worst {
    fn add(&mut self, gap: Gap, gain: Gain) {
        self.scaled = self.scaled.max(gap.scaled(gain));
        self.raw.direction = self.raw.direction.max(gap.direction);
        self.raw.weight = self.raw.weight.max(gap.weight);
        self.raw.pdf = self.raw.pdf.max(gap.pdf);
    }

    fn merge(&mut self, other: Worst) {
        self.scaled = self.scaled.max(other.scaled);
        self.raw.direction = self.raw.direction.max(other.raw.direction);
        self.raw.weight = self.raw.weight.max(other.raw.weight);
        self.raw.pdf = self.raw.pdf.max(other.raw.pdf);
    }

    /// `scaled` and the raw maxima, for the report.
    fn line(&self) -> String {
        format!(
            "{:.2e} (unscaled: direction {:.2e}, weight {:.2e}, pdf {:.2e} relative)",
            self.scaled, self.raw.direction, self.raw.weight, self.raw.pdf
        )
    }
}

/// The runtime's sample `(c, k, i)` of `p` in its mode at the metallic
/// `p.view[3]` (the BRDF modes at the view `p.view`, roughness `c.x`) and the
/// warp's gain there ([`warp_gain`]). The BRDF modes' rotation to the view's
/// azimuth keeps lengths: their gain is the set's at (roughness, theta_o).
fn runtime_sample(
    cs: &ConditionalSampler,
    prior: Option<&BrdfPrior<'_, f64>>,
    p: &KernelParams,
    e: u32,
) -> (Sample, Gain) {
    let (c, k, i) = sample_of(p, e);
    let wo = Vec3::new(p.view[0], p.view[1], p.view[2]);
    let m = p.view[3];
    let brdf_cond = || Vec2::new(c.x, view_theta_deg(wo) as f32);
    let brdf = || BrdfSampler::try_from(*cs).unwrap();
    let mode = [
        KernelMode::Table,
        KernelMode::Network,
        KernelMode::BrdfTable,
        KernelMode::BrdfNetwork,
        KernelMode::TableRandomized,
        KernelMode::NetworkRandomized,
        KernelMode::Pdf,
        KernelMode::BrdfTableRandomized,
        KernelMode::BrdfNetworkRandomized,
        KernelMode::BrdfPdf,
    ]
    .into_iter()
    .find(|&mode| mode as u32 == p.mode)
    .expect("a kernel mode");
    let info = cs.info();
    let randomized = || Vec2::from(randomized_point(info.n, info.lattice_generator, k, i, e));
    let (want, cond, point) = match mode {
        KernelMode::Table => (
            cs.sample_metallic(c, m, k, i),
            c,
            cs.square_point_metallic(c, m, k, i),
        ),
        KernelMode::Network => (
            cs.network().sample_metallic(c, m, k, i),
            c,
            cs.network().square_point_metallic(c, m, k, i),
        ),
        KernelMode::TableRandomized => (
            cs.sample_randomized_metallic(c, m, k, i, e),
            c,
            randomized(),
        ),
        KernelMode::NetworkRandomized => (
            cs.network().sample_randomized_metallic(c, m, k, i, e),
            c,
            randomized(),
        ),
        KernelMode::Pdf => {
            let s = cs.sample_metallic(c, m, k, i);
            let s = Sample {
                pdf: cs.pdf_metallic(c, m, s.direction),
                weight: cs.albedo(c, m),
                ..s
            };
            (s, c, cs.square_point_metallic(c, m, k, i))
        }
        KernelMode::BrdfTable => {
            let cond = brdf_cond();
            (
                brdf().sample(wo, c.x, m, k, i),
                cond,
                cs.square_point_metallic(cond, m, k, i),
            )
        }
        KernelMode::BrdfNetwork => {
            let cond = brdf_cond();
            (
                brdf().network().sample(wo, c.x, m, k, i),
                cond,
                cs.network().square_point_metallic(cond, m, k, i),
            )
        }
        KernelMode::BrdfTableRandomized => {
            let cond = brdf_cond();
            (
                brdf().sample_randomized(wo, c.x, m, k, i, e),
                cond,
                randomized(),
            )
        }
        KernelMode::BrdfNetworkRandomized => {
            let cond = brdf_cond();
            (
                brdf().network().sample_randomized(wo, c.x, m, k, i, e),
                cond,
                randomized(),
            )
        }
        KernelMode::BrdfPdf => {
            let cond = brdf_cond();
            let s = brdf().sample(wo, c.x, m, k, i);
            let s = Sample {
                pdf: brdf().pdf(wo, c.x, m, s.direction),
                weight: brdf().albedo(wo, c.x, m),
                ..s
            };
            (s, cond, cs.square_point_metallic(cond, m, k, i))
        }
    };
    (want, warp_gain(cs, prior, cond, m, point))
}

/// Whether one side has a direction within its mode's tolerance of the horizon
/// and the other none (`pdf` 0, `+z`): a square point that close to where the
/// half-vector map leaves the hemisphere falls on either side by the rounding
/// the tolerance allows (the network's outputs differ by up to 1e-4), and both
/// answers carry nothing there (`f cos` vanishes at the horizon).
fn at_the_horizon_either_side(mode: u32, gpu: &GpuSample, cpu: Sample) -> bool {
    let network = [
        KernelMode::Network,
        KernelMode::NetworkRandomized,
        KernelMode::BrdfNetwork,
        KernelMode::BrdfNetworkRandomized,
    ]
    .iter()
    .any(|&m| m as u32 == mode);
    let tolerance = if network {
        NETWORK_TOLERANCE
    } else {
        TABLE_TOLERANCE
    };
    let (g, more) = gpu;
    let near = |z: f32| z.abs() <= tolerance;
    (more[0] == 0.0 && cpu.pdf > 0.0 && near(cpu.direction.z))
        || (cpu.pdf == 0.0 && more[0] > 0.0 && near(g[2]))
}

/// The kernel's samples of `p` over `bytes` against the runtime's
/// ([`runtime_sample`]); pairs [`at_the_horizon_either_side`] are left out.
fn compare(
    kernel: &Kernel,
    bytes: &[u8],
    cs: &ConditionalSampler,
    prior: Option<&BrdfPrior<'_, f64>>,
    p: &KernelParams,
) -> Worst {
    let mut worst = Worst::default();
    for (e, got) in kernel.run(bytes, p).iter().enumerate() {
        let (want, gain) = runtime_sample(cs, prior, p, e as u32);
        if at_the_horizon_either_side(p.mode, got, want) {
            continue;
        }
        worst.add(gap(got, want), gain);
    }
    worst
}

/// Compares the kernel with the runtime in table and network mode on a grid of
/// conditions that runs past the blob's range on every side (clamping), instances
/// and indices past the stored counts (wrapping), and on views for `BrdfSampler::sample`;
/// for environment samplers and BRDF samplers on the tabulated prior also the
/// unbiased mode and the pdf of a direction (and the albedo), the latter at
/// metallic 0, 0.5 and 1.
/// Each difference is divided by the warp's gain at the sample ([`warp_gain`]; 1
/// for the equal-area maps) before it is held to the tolerance.
fn check_conditional(kernel: &Kernel, bytes: &[u8], label: &str) {
    let cs: ConditionalSampler = Blob::parse(bytes).unwrap().conditional().unwrap();
    let info = *cs.info();
    let table_prior = info.point_warp() == Some(PointWarp::BrdfTable);
    let wide = WidePrior::of(bytes);
    let prior = wide.as_ref().map(WidePrior::prior);
    let prior = prior.as_ref();
    // The metallic: read by the tabulated prior only; with a metallic axis
    // also between its nodes (0, 0.5, 0.95) and beyond its last.
    let metallics: &[f32] = if !cs.metallic_nodes().is_empty() {
        &[0.0, 0.3, 0.5, 0.97, 1.0]
    } else if table_prior {
        &[0.0, 0.5, 1.0]
    } else {
        &[0.0]
    };
    // Roughness 0 to 1.0625 by 1/16, theta_o -6 to 90 by 6 degrees.
    let grid = |mode, metallic| {
        let mut p = KernelParams::new(
            mode,
            [0.0, -6.0],
            [0.0625, 6.0],
            [18, 17],
            0..cs.instances() + 2,
            0..cs.len() + 3,
        );
        p.view[3] = metallic;
        p
    };
    // The unbiased mode and the pdf of any direction: samplers with an exact prior.
    let env = cs.target() == nuld_core::conditional::ConditionalTarget::EnvmapNormal;
    let exact = env || table_prior;
    let mut worst_table = Worst::default();
    let mut worst_network = Worst::default();
    for &m in metallics {
        let run = |mode| compare(kernel, bytes, &cs, prior, &grid(mode, m));
        worst_table.merge(run(KernelMode::Table));
        worst_network.merge(run(KernelMode::Network));
        if exact {
            worst_table.merge(run(KernelMode::TableRandomized));
            worst_table.merge(run(KernelMode::Pdf));
            worst_network.merge(run(KernelMode::NetworkRandomized));
        }
    }
    // Views: generic, along z, grazing, below the horizon, zero, huge, tiny, NaN.
    let views = [
        Vec3::new(0.3, 0.4, 0.866),
        Vec3::new(-0.7, 0.2, 0.3),
        Vec3::new(0.0, -2.0, 1.0),
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::new(1.0, 0.0, 0.01),
        Vec3::new(0.5, 0.5, -0.2),
        Vec3::ZERO,
        Vec3::new(3e38, -3e38, 3e38),
        Vec3::new(1e-30, 2e-30, 1e-30),
        Vec3::NAN,
    ];
    let mut worst_view = Worst::default();
    let mut worst_view_network = Worst::default();
    // The BRDF views exist for BRDF samplers only (`Blob::brdf` refuses others).
    let brdf = cs.target() == nuld_core::conditional::ConditionalTarget::GltfBrdf;
    let mut view_modes = vec![
        (KernelMode::BrdfTable, false),
        (KernelMode::BrdfNetwork, true),
    ];
    if table_prior {
        view_modes.extend([
            (KernelMode::BrdfTableRandomized, false),
            (KernelMode::BrdfNetworkRandomized, true),
            (KernelMode::BrdfPdf, false),
        ]);
    }
    for wo in views.into_iter().filter(|_| brdf) {
        for &m in metallics {
            for &(mode, network) in &view_modes {
                let mut p = KernelParams::new(
                    mode,
                    [0.0, 0.0],
                    [0.0625, 0.0],
                    [18, 1],
                    0..cs.instances() + 1,
                    0..cs.len(),
                );
                p.view = [wo.x, wo.y, wo.z, m];
                let worst = if network {
                    &mut worst_view_network
                } else {
                    &mut worst_view
                };
                worst.merge(compare(kernel, bytes, &cs, prior, &p));
            }
        }
    }
    // What is held to the tolerance is the difference over the warp's gain; the
    // unscaled differences follow for reference (a warp magnifies f32 rounding
    // of the square point by its gain, so they may exceed the tolerance).
    let views_line = if brdf {
        format!(
            "; brdf views: table {}, network {}",
            worst_view.line(),
            worst_view_network.line()
        )
    } else {
        String::from("; no brdf views (an environment sampler)")
    };
    println!(
        "shader {label} (n {}, hidden {:?}, activation {}, warp {}, metallic {metallics:?}): \
         max |gpu - cpu| / warp gain: table {} (tolerance {TABLE_TOLERANCE:.2e}), \
         network {} (tolerance {NETWORK_TOLERANCE:.0e}){views_line}",
        info.n,
        info.hidden,
        info.activation,
        info.warp,
        worst_table.line(),
        worst_network.line(),
    );
    for (what, worst, tolerance) in [
        ("table", &worst_table, TABLE_TOLERANCE),
        ("network", &worst_network, NETWORK_TOLERANCE),
        ("views", &worst_view, TABLE_TOLERANCE),
        ("views, network", &worst_view_network, NETWORK_TOLERANCE),
    ] {
        assert!(
            worst.scaled <= tolerance,
            "{label} {what}: {}",
            worst.scaled
        );
    }
}

#[test]
fn shader_distilled_brdf_sampler_matches_the_runtime() {
    let Some(kernel) = kernel() else { return };
    // The fixture of tests/distilled.rs: 3 instances, a 5 x 6 point grid.
    let parts = distilled_parts(3, [5, 6], [10, 9]);
    let bytes = parts.to_blob(&META).unwrap();
    check_conditional(kernel, bytes.as_slice(), "distilled");
}

#[test]
fn shader_random_samplers_of_every_shape_match_the_runtime() {
    let Some(kernel) = kernel() else { return };
    let shapes: [(u32, &[u32], Activation, u32, u32); 3] = [
        (37, &[5, 3, 9], Activation::Silu, 3_000_000_019, 64),
        (8, &[128], Activation::Relu, 3, 3),
        (33, &[20, 12], Activation::Silu, 7, 0),
    ];
    for (s, (n, hidden, act, g, slots)) in shapes.into_iter().enumerate() {
        let warps = [
            PointWarp::EqualArea,
            PointWarp::BrdfMixture,
            PointWarp::BrdfTable,
        ];
        for warp in warps {
            let shape = shape(n, hidden, act, warp, slots);
            let mut parts = conditional_parts(shape, 2, [4, 3], s as u64);
            // A generator whose products `i g` overflow 32 bits: the shader's
            // 64-bit-free `(i g) mod n`.
            parts.info.lattice_generator = g;
            let mut label = format!("random {s} {warp:?}");
            if s == 1 && warp == PointWarp::EqualArea {
                // A blob of the plain instance-offset hash (code 0, before the
                // salted one): both branches of the shader's offsets.
                parts.info.offset_hash = OffsetHash::Plain as u32;
                label = format!("random {s} {warp:?}, plain offsets");
            }
            if s == 2 && warp == PointWarp::BrdfMixture {
                // An environment sampler on its tree: the sphere, the tree's warp.
                parts = as_envmap(parts);
                label = format!("random {s} {:?}", PointWarp::EnvmapTree);
            }
            if warp == PointWarp::BrdfTable && s < 2 {
                // The small prior (5 x 5 vertices: coarse tables, points that
                // leak below the horizon); the last shape keeps the sampler's own
                // prior (`BrdfPrior::shared`, as the distilled test).
                parts = with_brdf_prior(parts, small_brdf_prior());
                label = format!("random {s} {warp:?}, small prior");
            }
            if warp == PointWarp::BrdfTable && s != 1 {
                // The metal layer's own network and table, read at metallic 1.
                parts = with_metal_points(parts, 40 + s as u64);
                label = format!("{label}, metal points");
            }
            if warp == PointWarp::BrdfTable && s == 2 {
                // A metallic axis of four nodes that starts above 0.
                parts = with_metallic_axis(parts, &[0.1, 0.4, 0.6, 0.9], 50);
                label = format!("{label}, metallic axis");
            }
            let bytes = parts.to_blob(&META).unwrap();
            check_conditional(kernel, bytes.as_slice(), &label);
        }
    }
}

/// The README's shader (tests/examples/shader_sample.wgsl, run by the host code of
/// tests/examples/shader_sample.rs) gives the runtime's `BrdfSampler::sample` samples,
/// on a blob of the equal-area warp and on one of the tabulated prior (warp 3). Its
/// view is normalized by the driver's `normalize`, a few ulps from glam's, which the
/// table interpolation carries through: within 1e-5.
#[test]
fn shader_readme_example_gives_the_runtime_samples() {
    let Some(kernel) = kernel() else { return };
    let source = [
        nuld_runtime::shader::WGSL,
        include_str!("../examples/shader_sample.wgsl"),
    ]
    .concat();
    let pipeline = kernel.gpu.pipeline(&source, "main");
    let conditional = nuld_runtime::doc_example_conditional_blob();
    let table_prior = nuld_runtime::doc_example_brdf_blob();
    for (label, bytes) in [
        ("equal-area", &conditional.0[..]),
        ("tabulated prior", &table_prior.0[..]),
    ] {
        let brdf = Blob::parse(bytes).unwrap().brdf().unwrap();
        let count = 5 * brdf.len();
        let (out, _) = kernel.gpu.run(
            &pipeline,
            bytes,
            None,
            count as u64,
            [count.div_ceil(64), 1, 1],
            1,
        );
        let wo = Vec3::new(0.3, 0.4, 0.866).normalize();
        let mut worst = 0.0f32;
        for (e, got) in out.iter().enumerate() {
            let (pixel, i) = (e as u32 / brdf.len(), e as u32 % brdf.len());
            // The README's shader writes direction and weight only.
            let g = gap(&(*got, [0.0; 4]), brdf.sample(wo, 0.4, 0.0, pixel, i));
            worst = worst.max(g.direction).max(g.weight);
        }
        println!("shader README example, {label}: max |gpu - cpu| {worst:.2e} (tolerance 1e-5)");
        assert!(worst <= 1e-5, "{label}: {worst}");
    }
}
