//! Samples per second of the WGSL sampling kernel (`nuld_runtime::shader`) in table
//! and network mode, on whatever adapter wgpu finds. On this project's machines that
//! is lavapipe, Mesa's CPU Vulkan driver: the figures are a CPU software driver's
//! (LLVM-compiled SIMD on the machine's cores), not a GPU's.
//!
//! `cargo run --release -p nuld-tests --example shader_bench`
//!
//! The blobs have random contents and the shapes `build-tool bench --only runtime`
//! times on the CPU (n 64, 16 instances, a 10 x 9 point grid; networks [32, 32]
//! ReLU, the default bake's, and [64, 64] SiLU): speed does not depend on the
//! values. Each figure is the best of 3 dispatches, from submission to completion,
//! of one range of (condition, instance, index) filling an output buffer.

#[path = "shader_sample.rs"]
mod shader_sample;

use nuld_core::conditional::PointWarp;
use nuld_core::network::Activation;
use nuld_runtime::shader::{
    kernel_wgsl, KernelMode, KernelParams, KERNEL_ENTRY_POINT, SAMPLE_STRIDE,
};
use nuld_tests::{as_envmap, conditional_parts, shape, META};
use shader_sample::Gpu;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let gpu = Gpu::new().ok_or("no GPU adapter (on Linux, install mesa-vulkan-drivers)")?;
    let pipeline = gpu.pipeline(kernel_wgsl(), KERNEL_ENTRY_POINT);
    println!(
        "adapter: {} (lavapipe/llvmpipe is a CPU software driver)",
        gpu.adapter
    );
    println!(
        "{:<44} {:>10} {:>12} {:>12}",
        "mode", "samples", "seconds", "samples/s"
    );
    // The table modes read no network: they run on the [32, 32] blob.
    let parts = |hidden: &[u32], act| {
        conditional_parts(
            shape(64, hidden, act, PointWarp::BrdfMixture, 64),
            16,
            [10, 9],
            2,
        )
    };
    let relu = parts(&[32, 32], Activation::Relu).to_blob(&META)?;
    let silu = parts(&[64, 64], Activation::Silu).to_blob(&META)?;
    // An environment sampler on the tests' small tree (the sphere, the tree's warp
    // with its pdf): the sampler that reads the most sections.
    let envmap = as_envmap(parts(&[32, 32], Activation::Relu)).to_blob(&META)?;
    // 16 x 16 conditions over a blob's range from `first` by `step`: the BRDF's
    // roughness and view angle, or the normal's square point.
    let brdf = ([0.1, 0.0], [0.06, 5.9]);
    let normals = ([0.02, 0.02], [0.06, 0.06]);
    let cases = [
        ("table: nuld_sample", &relu, brdf, KernelMode::Table, 1 << 8),
        (
            "table: nuld_sample, environment tree",
            &envmap,
            normals,
            KernelMode::Table,
            1 << 8,
        ),
        (
            "table: nuld_sample_brdf",
            &relu,
            brdf,
            KernelMode::BrdfTable,
            1 << 8,
        ),
        (
            "network [32,32] relu: nuld_sample_network",
            &relu,
            brdf,
            KernelMode::Network,
            1 << 4,
        ),
        (
            "network [64,64] silu: nuld_sample_network",
            &silu,
            brdf,
            KernelMode::Network,
            1 << 2,
        ),
    ];
    for (label, bytes, (first, step), mode, instances) in cases {
        // 16 x 16 conditions, `instances` instances, 64 indices.
        let mut p = KernelParams::new(mode, first, step, [16, 16], 0..instances, 0..64);
        p.view = [0.3, 0.4, 0.866, 0.0];
        let count = p.sample_count().ok_or("range too large")?;
        // A sample is `SAMPLE_STRIDE / 16` vec4 slots of the buffer.
        let slots = SAMPLE_STRIDE / 16;
        let (out, seconds) = gpu.run(
            &pipeline,
            bytes.as_slice(),
            Some(bytemuck::bytes_of(&p)),
            slots * count as u64,
            p.workgroups(),
            3,
        );
        // Every sample written: a unit direction in its first slot (guards
        // against timing a no-op).
        let bad = out
            .iter()
            .step_by(slots as usize)
            .filter(|s| ((s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt() - 1.0).abs() > 1e-4)
            .count();
        if bad > 0 {
            return Err(format!("{label}: {bad} samples are not unit directions").into());
        }
        println!(
            "{label:<44} {count:>10} {seconds:>12.4} {:>12.3e}",
            count as f64 / seconds
        );
    }
    Ok(())
}
