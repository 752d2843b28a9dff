//! Nanoseconds per sample through the C ABI against the same Rust call, in one
//! run: `tests/c/capi_test.c bench`, compiled against the freestanding
//! `libnuld_capi.a` (`-O2`), times each entry point from C; this program times
//! the runtime's function it calls, inlined into a Rust loop as a Rust renderer
//! would have it.
//!
//! `cargo run --release -p nuld-tests --example capi_bench`
//!
//! The blobs have random contents and the runtime benchmark's shape (n 64, 16
//! instances, a 10 x 9 point grid, network [32, 32] ReLU with the default bake's
//! 64 instance slots; the environment sampler on the tests' fixture prior, a
//! tree of 4 levels): speed does not depend on the values. Both sides cycle
//! through the same 64 conditions, instance `s / 64` and index `s mod 64` for
//! sample `s`, and keep the best of 3 passes.

use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::conditional::PointWarp;
use nuld_core::network::Activation;
use nuld_runtime::glam::Vec3;
use nuld_runtime::{Blob, BrdfSampler, EnvmapSampler, Sample};
use nuld_tests::capi::{compile, workspace_root, Link};
use nuld_tests::{as_envmap, conditional_parts, shape, META};
use std::hint::black_box;
use std::time::Instant;

/// Samples per table-mode method (a tenth in network mode), as `build-tool
/// bench --only runtime`.
const SAMPLES: u32 = 2_000_000;

/// Conditions cycled through, made as `bench_conditions` in capi_test.c makes
/// them: views and normals spread over their domains, roughness over (0.1, 1).
const CONDITIONS: usize = 64;

struct Conditions {
    views: Vec<Vec3>,
    normals: Vec<Vec3>,
    roughness: Vec<f32>,
}

fn conditions() -> Conditions {
    let n = CONDITIONS as f32;
    let (mut views, mut normals, mut roughness) = (Vec::new(), Vec::new(), Vec::new());
    for c in 0..CONDITIONS {
        let u = (((c * 37) % CONDITIONS) as f32 + 0.5) / n;
        // PI and TAU are the f32s of the C side's literals 3.14159265f, 6.28318531f.
        let theta = 89.0 * u * std::f32::consts::PI / 180.0;
        let phi = std::f32::consts::TAU * (c as f64 * 0.618034).rem_euclid(1.0) as f32;
        views.push(Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ));
        let z = 1.0 - 2.0 * (c as f32 + 0.5) / n;
        let r = (1.0 - z * z).sqrt();
        normals.push(Vec3::new(r * phi.cos(), r * phi.sin(), z));
        roughness.push(0.1 + 0.9 * (((c * 23) % CONDITIONS) as f32 + 0.5) / n);
    }
    Conditions {
        views,
        normals,
        roughness,
    }
}

/// Best-of-3 nanoseconds per call of `f(condition, instance, index)` over
/// `count` calls, the first output component summed as the C side does.
fn time(count: u32, n: u32, mut f: impl FnMut(usize, u32, u32) -> Sample) -> f64 {
    let mut best = f64::INFINITY;
    let mut sink = 0.0f32;
    for _ in 0..3 {
        let t = Instant::now();
        for s in 0..count {
            let s = black_box(s);
            let (c, k, i) = ((s / n) as usize % CONDITIONS, s / n, s % n);
            sink += f(c, k, i).direction.x;
        }
        best = best.min(t.elapsed().as_secs_f64() * 1e9 / count as f64);
    }
    black_box(sink);
    best
}

fn blob(bytes: &AlignedBytes) -> Blob<'_> {
    Blob::parse(bytes.as_slice()).expect("a valid blob")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let shape_of = |warp| shape(64, &[32, 32], Activation::Relu, warp, 64);
    let brdf_bytes =
        conditional_parts(shape_of(PointWarp::BrdfTable), 16, [10, 9], 2).to_blob(&META)?;
    let env_bytes = as_envmap(conditional_parts(
        shape_of(PointWarp::EnvmapTree),
        16,
        [10, 9],
        3,
    ))
    .to_blob(&META)?;
    let dir = std::env::temp_dir().join(format!("nuld-capi-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let (brdf_file, env_file) = (dir.join("brdf.nuld"), dir.join("env.nuld"));
    std::fs::write(&brdf_file, brdf_bytes.as_slice())?;
    std::fs::write(&env_file, env_bytes.as_slice())?;

    // C first, then Rust: each side alone on the machine.
    let program = compile(
        &workspace_root().join("tests/c/capi_test.c"),
        Link::Static,
        "capi_test",
    );
    let out = std::process::Command::new(program)
        .arg("bench")
        .args([&brdf_file, &env_file])
        .arg(SAMPLES.to_string())
        .output()?;
    std::fs::remove_dir_all(&dir)?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).into_owned().into());
    }
    let c_times: Vec<(String, f64)> = String::from_utf8(out.stdout)?
        .lines()
        .filter_map(|l| {
            let (name, ns) = l.rsplit_once(' ')?;
            Some((name.to_string(), ns.parse().ok()?))
        })
        .collect();

    let at = conditions();
    let (brdf, env): (BrdfSampler, EnvmapSampler) =
        (blob(&brdf_bytes).brdf()?, blob(&env_bytes).envmap()?);
    let n = brdf.len();
    let mut brdf_buf = vec![0.0; brdf.decoded_network_len()];
    let brdf_fast = brdf.decode_network(&mut brdf_buf).ok_or("decoding")?;
    let mut env_buf = vec![0.0; env.decoded_network_len()];
    let env_fast = env.decode_network(&mut env_buf).ok_or("decoding")?;
    let net = SAMPLES / 10;
    let rust: [f64; 7] = [
        time(SAMPLES, n, |c, k, i| {
            brdf.sample(at.views[c], at.roughness[c], 0.0, k, i)
        }),
        time(net, n, |c, k, i| {
            brdf.network()
                .sample(at.views[c], at.roughness[c], 0.0, k, i)
        }),
        time(net, n, |c, k, i| {
            brdf_fast.sample(at.views[c], at.roughness[c], 0.0, k, i)
        }),
        time(SAMPLES, n, |c, k, i| env.sample(at.normals[c], k, i)),
        time(SAMPLES, n, |c, k, i| {
            env.sample_randomized(at.normals[c], k, i, k)
        }),
        time(net, n, |c, k, i| env_fast.sample(at.normals[c], k, i)),
        time(SAMPLES, n, |c, _, _| {
            let pdf = env.pdf(at.normals[c], at.views[c]);
            Sample {
                direction: Vec3::splat(pdf),
                weight: 0.0,
                pdf,
            }
        }),
    ];
    if c_times.len() != rust.len() {
        return Err(format!("C printed {c_times:?}").into());
    }
    println!(
        "ns per sample, one thread, n = {n} (best of 3); C: capi_test.c -O2 against libnuld_capi.a"
    );
    println!(
        "{:<26} {:>10} {:>10} {:>9}",
        "method", "Rust", "C", "C / Rust"
    );
    for ((name, c), r) in c_times.iter().zip(rust) {
        println!("{name:<26} {r:>10.1} {c:>10.1} {:>8.2}x", c / r);
    }
    Ok(())
}
