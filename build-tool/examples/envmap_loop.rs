//! The environment sampler's table mode and `pdf` in a loop of their own, each
//! the only caller of the runtime's sampler, so that the compiler inlines the
//! whole sample into the loop as a renderer's build of one call site would:
//! `cargo run --release -p nuld-build-tool --example envmap_loop -- [BLOB |
//! lattice] [NORMALS]`.
//!
//! Without `BLOB` (or with `lattice`, the same), the blob of `build-tool bench
//! --only envmap-prior`: the default bake's shapes on courtyard's tree, random
//! network weights and each instance's shifted rank-1 lattice at every node of
//! the table (an untrained bake's points, whose interpolation between nodes
//! keeps them where a trained table's would be; the bench's random codes
//! before, interpolated towards the square's middle, timed 3 to 5 % faster
//! here). Sample `s` has normal
//! `s / 64 mod NORMALS` (default 4096, as the bench: with 64, each normal meets
//! one stored instance only, which the caches learn) of a fixed pseudo-random set, instance `s
//! / 64` and index `s mod 64`; `pdf` is asked for pseudo-random directions.
//! Prints ns per sample, the best of three runs of 4·10^6 samples each, one
//! thread. (`bench` times every method through one harness, where the sampler
//! has several callers and is compiled apart from them.)
use nuld_build_tool::lab::bench::envmap_prior::{sampler_blob, sampler_parts};
use nuld_build_tool::pointset::AlignedBytes;
use nuld_build_tool::sphere::envmap_tree::{prior_levels, PRIOR_GRID};
use nuld_build_tool::sphere::{EnvmapDensity, EnvmapTree};
use nuld_core::blob::Domain;
use nuld_runtime::glam::Vec3;
use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

const SAMPLES: u32 = 4_000_000;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bytes = match args.get(1) {
        Some(path) if path != "lattice" => AlignedBytes::read(std::path::Path::new(path)).unwrap(),
        _ => bench_blob(),
    };
    let count: usize = args.get(2).map_or(4096, |a| a.parse().unwrap());
    let env = nuld_runtime::Blob::parse(bytes.as_slice())
        .unwrap()
        .envmap()
        .unwrap();
    let mut h = 7u64;
    let mut r = || {
        h = h
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (h >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    let normals: Vec<Vec3> = (0..count)
        .map(|_| Vec3::new(r(), r(), r()).normalize())
        .collect();
    let directions: Vec<Vec3> = (0..4096)
        .map(|_| Vec3::new(r(), r(), r()).normalize())
        .collect();
    let best = |f: &dyn Fn(u32)| {
        (0..3)
            .map(|_| {
                let t = Instant::now();
                (0..SAMPLES).for_each(f);
                t.elapsed().as_nanos() as f64 / SAMPLES as f64
            })
            .fold(f64::INFINITY, f64::min)
    };
    let n = |s: u32| normals[(s / 64) as usize % count];
    let table = best(&|s| {
        black_box(env.sample(n(s), s / 64, s % 64));
    });
    let pdf = best(&|s| {
        black_box(env.pdf(n(s), directions[s as usize % 4096]));
    });
    println!("table mode {table:.1} ns, pdf {pdf:.1} ns per sample ({count} normals)");
}

/// The blob `bench --only envmap-prior` times, on courtyard.
fn bench_blob() -> AlignedBytes {
    let path = std::path::Path::new("../shared/data/envmaps/courtyard.hdr");
    let map = EnvmapDensity::from_file_filtered(path, Domain::Sphere).unwrap();
    let tree = EnvmapTree::new(&map, prior_levels(&map), PRIOR_GRID).unwrap();
    sampler_blob(sampler_parts(Arc::new(tree)).unwrap()).unwrap()
}
