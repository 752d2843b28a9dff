//! The WGSL sampler (`nuld_runtime::shader`) run by a real Vulkan driver through
//! wgpu, against `nuld-runtime` on the CPU, over grids of (condition, instance,
//! index): point and direction sets, a briefly trained and distilled BRDF sampler,
//! and a random-content sampler with the shapes training does not use (SiLU, three
//! layers, a lattice generator whose products overflow 32 bits).
//!
//! On a machine without an adapter the tests print why (on stderr, shown with
//! `--nocapture`) and pass, except under CI (the `CI` environment variable set),
//! where they fail: CI installs lavapipe, the CPU Vulkan driver
//! (`apt-get install mesa-vulkan-drivers libvulkan1`).
//!
//! Tolerances, in absolute terms on unit-vector components and weights:
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
//!   printed too.
//!
//! Each test prints the largest difference it measured.

#[path = "../examples/shader_sample.rs"]
mod shader_sample;

use nuld_core::blob::Domain;
use nuld_core::conditional::PointWarp;
use nuld_core::conditional::{randomization_shift, torus_shift};
use nuld_core::network::Activation;
use nuld_runtime::glam::{DVec3, Vec2, Vec3};
use nuld_runtime::shader::SAMPLE_STRIDE;
use nuld_runtime::shader::{kernel_wgsl, KernelMode, KernelParams, KERNEL_ENTRY_POINT};
use nuld_runtime::{Blob, BrdfSampler, ConditionalSampler, Sample};
use nuld_tests::{
    as_envmap, conditional_parts, distilled_parts, fixture_tree, shape, sobol_blob, META,
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

/// Largest absolute difference of direction components and weight.
/// The largest difference of direction components and weight, and the pdf's
/// relative difference.
fn gap(gpu: &GpuSample, cpu: Sample) -> f32 {
    let (g, more) = gpu;
    let d = Vec3::new(g[0], g[1], g[2]) - cpu.direction;
    let pdf = (more[0] - cpu.pdf).abs() / cpu.pdf.max(f32::MIN_POSITIVE);
    d.abs()
        .max_element()
        .max((g[3] - cpu.weight).abs())
        .max(pdf)
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
                worst = worst.max(gap(got, want));
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
/// `f32` result is as far from the exact direction).
fn warp_gain(cs: &ConditionalSampler, cond: Vec2, p: Vec2) -> f32 {
    let info = cs.info();
    let warp = info.point_warp().expect("a parsed blob's warp");
    if warp == PointWarp::EqualArea {
        return 1.0;
    }
    // The clamped condition, as the runtime's tables and warp see it.
    let c = info.denormalize(info.normalize(cond.to_array()));
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
    1.0 + j as f32
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

/// The largest `|gpu - cpu| / gain` and the largest `|gpu - cpu|` of samples.
#[derive(Default)]
struct Worst {
    scaled: f32,
    raw: f32,
}

impl Worst {
    fn add(&mut self, gap: f32, gain: f32) {
        self.scaled = self.scaled.max(gap / gain);
        self.raw = self.raw.max(gap);
    }

    fn merge(&mut self, other: Worst) {
        self.scaled = self.scaled.max(other.scaled);
        self.raw = self.raw.max(other.raw);
    }
}

/// The runtime's sample `(c, k, i)` of `p` in its mode (the BRDF modes at the view
/// `p.view`, roughness `c.x`) and the warp's gain there ([`warp_gain`]). The BRDF
/// modes' rotation to the view's azimuth keeps lengths: their gain is the set's at
/// (roughness, theta_o).
fn runtime_sample(cs: &ConditionalSampler, p: &KernelParams, e: u32) -> (Sample, f32) {
    let (c, k, i) = sample_of(p, e);
    let wo = Vec3::new(p.view[0], p.view[1], p.view[2]);
    let brdf_cond = || Vec2::new(c.x, view_theta_deg(wo) as f32);
    let mode = [
        KernelMode::Table,
        KernelMode::Network,
        KernelMode::BrdfTable,
        KernelMode::BrdfNetwork,
        KernelMode::TableRandomized,
        KernelMode::NetworkRandomized,
        KernelMode::Pdf,
    ]
    .into_iter()
    .find(|&m| m as u32 == p.mode)
    .expect("a kernel mode");
    let shifted = |q: Vec2| Vec2::from(torus_shift(q.to_array(), randomization_shift(e)));
    let (want, cond, point) = match mode {
        KernelMode::Table => (cs.sample(c, k, i), c, cs.square_point(c, k, i)),
        KernelMode::Network => (
            cs.network().sample(c, k, i),
            c,
            cs.network().square_point(c, k, i),
        ),
        KernelMode::TableRandomized => (
            cs.sample_randomized(c, k, i, e),
            c,
            shifted(cs.square_point(c, k, i)),
        ),
        KernelMode::NetworkRandomized => (
            cs.network().sample_randomized(c, k, i, e),
            c,
            shifted(cs.network().square_point(c, k, i)),
        ),
        KernelMode::Pdf => {
            let s = cs.sample(c, k, i);
            let s = Sample {
                pdf: cs.pdf(c, s.direction),
                ..s
            };
            (s, c, cs.square_point(c, k, i))
        }
        KernelMode::BrdfTable => {
            let cond = brdf_cond();
            (
                BrdfSampler::try_from(*cs)
                    .unwrap()
                    .sample(wo, c.x, 0.0, k, i),
                cond,
                cs.square_point(cond, k, i),
            )
        }
        KernelMode::BrdfNetwork => {
            let cond = brdf_cond();
            (
                BrdfSampler::try_from(*cs)
                    .unwrap()
                    .network()
                    .sample(wo, c.x, 0.0, k, i),
                cond,
                cs.network().square_point(cond, k, i),
            )
        }
    };
    (want, warp_gain(cs, cond, point))
}

/// The kernel's samples of `p` over `bytes` against the runtime's
/// ([`runtime_sample`]).
fn compare(kernel: &Kernel, bytes: &[u8], cs: &ConditionalSampler, p: &KernelParams) -> Worst {
    let mut worst = Worst::default();
    for (e, got) in kernel.run(bytes, p).iter().enumerate() {
        let (want, gain) = runtime_sample(cs, p, e as u32);
        worst.add(gap(got, want), gain);
    }
    worst
}

/// Compares the kernel with the runtime in table and network mode on a grid of
/// conditions that runs past the blob's range on every side (clamping), instances
/// and indices past the stored counts (wrapping), and on views for `BrdfSampler::sample`.
/// Each difference is divided by the warp's gain at the sample ([`warp_gain`]; 1
/// for the equal-area maps) before it is held to the tolerance.
fn check_conditional(kernel: &Kernel, bytes: &[u8], label: &str) {
    let cs: ConditionalSampler = Blob::parse(bytes).unwrap().conditional().unwrap();
    let info = *cs.info();
    // Roughness 0 to 1.0625 by 1/16, theta_o -6 to 90 by 6 degrees.
    let grid = |mode| {
        KernelParams::new(
            mode,
            [0.0, -6.0],
            [0.0625, 6.0],
            [18, 17],
            0..cs.instances() + 2,
            0..cs.len() + 3,
        )
    };
    let mut worst_table = compare(kernel, bytes, &cs, &grid(KernelMode::Table));
    let mut worst_network = compare(kernel, bytes, &cs, &grid(KernelMode::Network));
    // The unbiased mode and the pdf of any direction: environment samplers'.
    let env = cs.target() == nuld_core::conditional::ConditionalTarget::EnvmapNormal;
    if env {
        worst_table.merge(compare(
            kernel,
            bytes,
            &cs,
            &grid(KernelMode::TableRandomized),
        ));
        worst_table.merge(compare(kernel, bytes, &cs, &grid(KernelMode::Pdf)));
        worst_network.merge(compare(
            kernel,
            bytes,
            &cs,
            &grid(KernelMode::NetworkRandomized),
        ));
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
    for wo in views.into_iter().filter(|_| brdf) {
        for (mode, worst) in [
            (KernelMode::BrdfTable, &mut worst_view),
            (KernelMode::BrdfNetwork, &mut worst_view_network),
        ] {
            let mut p = KernelParams::new(
                mode,
                [0.0, 0.0],
                [0.0625, 0.0],
                [18, 1],
                0..cs.instances() + 1,
                0..cs.len(),
            );
            p.view = [wo.x, wo.y, wo.z, 0.0];
            worst.merge(compare(kernel, bytes, &cs, &p));
        }
    }
    // What is held to the tolerance is the difference over the warp's gain; the
    // unscaled difference follows for reference (a mixture warp magnifies f32
    // rounding of the square point by its gain, so it may exceed the tolerance).
    let views_line = if brdf {
        format!(
            ", brdf views table {:.2e}, network {:.2e}",
            worst_view.scaled, worst_view_network.scaled
        )
    } else {
        String::from(", no brdf views (an environment sampler)")
    };
    println!(
        "shader {label} (n {}, hidden {:?}, activation {}, warp {}): max |gpu - cpu| / warp gain: \
         table {:.2e} (tolerance {TABLE_TOLERANCE:.2e}), network {:.2e} (tolerance \
         {NETWORK_TOLERANCE:.0e}){views_line}; unscaled max: table {:.2e}, network {:.2e}",
        info.n,
        info.hidden,
        info.activation,
        info.warp,
        worst_table.scaled,
        worst_network.scaled,
        worst_table.raw,
        worst_network.raw,
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
        for warp in [PointWarp::EqualArea, PointWarp::BrdfMixture] {
            let shape = shape(n, hidden, act, warp, slots);
            let mut parts = conditional_parts(shape, 2, [4, 3], s as u64);
            // A generator whose products `i g` overflow 32 bits: the shader's
            // 64-bit-free `(i g) mod n`.
            parts.info.lattice_generator = g;
            let mut label = format!("random {s} {warp:?}");
            if s == 2 && warp == PointWarp::BrdfMixture {
                // An environment sampler on its tree: the sphere, the tree's warp.
                parts = as_envmap(parts);
                label = format!("random {s} {:?}", PointWarp::EnvmapTree);
            }
            let bytes = parts.to_blob(&META).unwrap();
            check_conditional(kernel, bytes.as_slice(), &label);
        }
    }
}

/// The README's shader (tests/examples/shader_sample.wgsl, run by the host code of
/// tests/examples/shader_sample.rs) gives the runtime's `BrdfSampler::sample` samples. Its
/// view is normalized by the driver's `normalize`, a few ulps from glam's, which the
/// table interpolation carries through: within 1e-5.
#[test]
fn shader_readme_example_gives_the_runtime_samples() {
    let Some(kernel) = kernel() else { return };
    let bytes = nuld_runtime::doc_example_conditional_blob();
    let cs = Blob::parse(&bytes.0).unwrap().conditional().unwrap();
    let source = [
        nuld_runtime::shader::WGSL,
        include_str!("../examples/shader_sample.wgsl"),
    ]
    .concat();
    let pipeline = kernel.gpu.pipeline(&source, "main");
    let count = 5 * cs.len();
    let (out, _) = kernel.gpu.run(
        &pipeline,
        &bytes.0,
        None,
        count as u64,
        [count.div_ceil(64), 1, 1],
        1,
    );
    let wo = Vec3::new(0.3, 0.4, 0.866).normalize();
    let mut worst = 0.0f32;
    for (e, got) in out.iter().enumerate() {
        let (pixel, i) = (e as u32 / cs.len(), e as u32 % cs.len());
        // The README's shader writes direction and weight only: a zero pdf, as
        // the BRDF sampler's.
        worst = worst.max(gap(
            &(*got, [0.0; 4]),
            BrdfSampler::try_from(cs)
                .unwrap()
                .sample(wo, 0.4, 0.0, pixel, i),
        ));
    }
    println!("shader README example: max |gpu - cpu| {worst:.2e} (tolerance 1e-5)");
    assert!(worst <= 1e-5, "{worst}");
}
