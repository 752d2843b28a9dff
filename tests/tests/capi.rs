//! The C ABI (`runtime/capi`) from C and C++: the freestanding libraries built as
//! the README says, `tests/c/capi_test.c` compiled against the static one by the
//! system C compiler, and the C++ example against both.
//!
//! * Through C, every sample of blobs the build tool wrote (2D, sphere and
//!   hemisphere sets; BRDF and environment samplers in table, network, decoded
//!   network and unbiased modes) prints exactly what `build-tool sample` and
//!   `build-tool export` print for the same blob, byte for byte.
//! * Hostile bytes through C: corruptions, cuts, extensions and misaligned copies
//!   are all refused, re-checksummed ones either refused or sound, no crash;
//!   null, misaligned, unparsed and mismatched arguments each get their code.
//! * The checked-in header is what cbindgen generates from the crate.

use nuld_build_tool::cli::sample::{At, Condition, Normal, SampleMode};
use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::blob::Domain;
use nuld_core::conditional::PointWarp;
use nuld_core::network::Activation;
use nuld_tests::capi::{compile, workspace_root, Link};
use nuld_tests::{
    as_envmap, conditional_parts, shape, small_brdf_prior, sobol_blob, with_brdf_prior, META,
};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The C test program, compiled once per test binary.
fn program() -> &'static Path {
    static PROGRAM: OnceLock<PathBuf> = OnceLock::new();
    PROGRAM.get_or_init(|| {
        let source = workspace_root().join("tests/c/capi_test.c");
        compile(&source, Link::Static, "capi_test")
    })
}

/// Runs `exe` with `args` and returns its standard output; panics with its
/// standard error if it fails or is killed (a crash is a signal, no exit code).
/// Without cargo's `LD_LIBRARY_PATH`, which names `<target>/release`, where the
/// workspace's own (std) `libnuld_capi.so` lies: the dynamic loader would prefer
/// it to the freestanding one of the program's run path.
fn run(exe: &Path, args: &[&str]) -> String {
    let out = Command::new(exe)
        .args(args)
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .expect("the program runs");
    assert!(
        out.status.success(),
        "{} {args:?}: {}\n{}",
        exe.display(),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// A temporary directory of blob files, removed when dropped.
struct Files(PathBuf);

impl Files {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("nuld-capi-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        Self(dir)
    }

    /// Writes `blob` as `NAME.nuld` and returns its path as a string.
    fn write(&self, name: &str, blob: &AlignedBytes) -> String {
        let path = self.0.join(format!("{name}.nuld"));
        std::fs::write(&path, blob.as_slice()).expect("a blob file");
        path.to_str().expect("a UTF-8 path").to_string()
    }
}

impl Drop for Files {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A BRDF sampler of the runtime benchmark's shape (n 64, hidden [32, 32], the
/// BRDF mixture warp, the default bake's 64 instance slots, 16 instances on a
/// 10 x 9 grid), with random contents.
fn brdf_blob(act: Activation, warp: PointWarp, slots: u32, seed: u64) -> AlignedBytes {
    conditional_parts(shape(64, &[32, 32], act, warp, slots), 16, [10, 9], seed)
        .to_blob(&META)
        .expect("a valid blob")
}

/// [`brdf_blob`]'s shape on the tabulated BRDF prior, made small
/// ([`small_brdf_prior`]) so that the file the C program reads stays small.
fn brdf_table_blob(act: Activation, slots: u32, seed: u64) -> AlignedBytes {
    let shape = shape(64, &[32, 32], act, PointWarp::BrdfTable, slots);
    with_brdf_prior(
        conditional_parts(shape, 16, [10, 9], seed),
        small_brdf_prior(),
    )
    .to_blob(&META)
    .expect("a valid blob")
}

/// An environment sampler of the same shape on the fixture prior.
fn envmap_blob(seed: u64) -> AlignedBytes {
    let parts = conditional_parts(
        shape(64, &[32, 32], Activation::Silu, PointWarp::EnvmapTree, 64),
        16,
        [10, 9],
        seed,
    );
    as_envmap(parts).to_blob(&META).expect("a valid blob")
}

/// What `build-tool sample` prints for these arguments (its library function).
fn tool_sample(blob: &AlignedBytes, args: &SampleArgs) -> String {
    let mut out = Vec::new();
    nuld_build_tool::cli::sample::write_csv(
        blob.as_slice(),
        args.at,
        args.instance,
        (args.mode, args.randomize),
        &mut out,
    )
    .expect("build-tool sample succeeds");
    String::from_utf8(out).expect("UTF-8 CSV")
}

/// One `sample` invocation, for both sides.
struct SampleArgs {
    at: At,
    /// `--cond A,B` or `--normal X,Y,Z`, as typed.
    at_flag: [String; 2],
    instance: u32,
    mode: SampleMode,
    randomize: Option<u32>,
}

impl SampleArgs {
    fn new(text: &str, instance: u32, mode: SampleMode, randomize: Option<u32>) -> Self {
        // Both sides read the same decimal text: Rust's `parse` and C's `strtof`
        // both round it correctly.
        let v: Vec<f32> = text
            .trim_start_matches("n:")
            .split(',')
            .map(|x| x.parse().unwrap())
            .collect();
        // `--cond A,B[,M]` for a conditional, `--normal X,Y,Z` (a `n:` prefix).
        let (flag, at) = match (text.strip_prefix("n:"), &v[..]) {
            (None, [a, b]) => ("--cond", At::Condition(Condition([*a, *b, 0.0]))),
            (None, [a, b, m]) => ("--cond", At::Condition(Condition([*a, *b, *m]))),
            (Some(_), [x, y, z]) => ("--normal", At::Normal(Normal([*x, *y, *z]))),
            _ => panic!("{text}"),
        };
        let text = text.trim_start_matches("n:");
        Self {
            at,
            at_flag: [flag.to_string(), text.to_string()],
            instance,
            mode,
            randomize,
        }
    }

    /// The C program's arguments, `--decoded` if `decoded`.
    fn c_args(&self, file: &str, decoded: bool) -> Vec<String> {
        let mut a = vec!["sample".to_string(), file.to_string()];
        a.extend(self.at_flag.iter().cloned());
        a.extend(["--instance".into(), self.instance.to_string()]);
        let mode = match self.mode {
            SampleMode::Table => "table",
            SampleMode::Network => "network",
        };
        a.extend(["--mode".into(), mode.into()]);
        if let Some(r) = self.randomize {
            a.extend(["--randomize".into(), r.to_string()]);
        }
        if decoded {
            a.push("--decoded".into());
        }
        a
    }
}

#[test]
fn samples_through_c_equal_build_tool_sample_byte_for_byte() {
    let files = Files::new("sample");
    let brdf = [
        brdf_blob(Activation::Relu, PointWarp::BrdfMixture, 64, 3),
        brdf_blob(Activation::Silu, PointWarp::EqualArea, 7, 4),
        brdf_table_blob(Activation::Relu, 64, 6),
    ];
    let env = envmap_blob(5);
    // Inside and outside the BRDF's range (clamped), every corner of a grid cell;
    // metallic inside and outside [0, 1] on the tabulated prior.
    let brdf_at = ["0.3,60", "0.05,-5", "1,89", "0.55,33.3"];
    let metal_at = ["0.3,60,1", "0.05,-5,0.5", "1,89,7", "0.55,33.3,0"];
    let env_at = ["n:0.2,0.9,-0.3", "n:0,0,1", "n:-1e-3,0.5,-7", "0.25,0.75"];
    let mut rows = 0;
    for (blob, places) in [
        (&brdf[0], &brdf_at[..]),
        (&brdf[1], &brdf_at[..]),
        (&brdf[2], &metal_at[..]),
        (&env, &env_at[..]),
    ] {
        let file = files.write(&format!("conditional-{rows}"), blob);
        for at in places {
            for (instance, mode, randomize) in [
                (0, SampleMode::Table, None),
                (5, SampleMode::Table, Some(7)),
                (4_000_000_000, SampleMode::Table, None),
                (0, SampleMode::Network, None),
                (9, SampleMode::Network, Some(123_456)),
                (4_000_000_000, SampleMode::Network, None),
            ] {
                let args = SampleArgs::new(at, instance, mode, randomize);
                let want = tool_sample(blob, &args);
                // Network mode also on weights decoded by `nuld_decode_network`.
                let decoded: &[bool] = match mode {
                    SampleMode::Table => &[false],
                    SampleMode::Network => &[false, true],
                };
                for &d in decoded {
                    let c_args = args.c_args(&file, d);
                    let c_args: Vec<&str> = c_args.iter().map(String::as_str).collect();
                    let got = run(program(), &c_args);
                    assert_eq!(got, want, "{c_args:?}");
                    rows += got.lines().count() - 1;
                }
            }
        }
    }
    println!("{rows} sample rows through C equal build-tool sample's");
}

#[test]
fn point_and_direction_sets_through_c_equal_build_tool_export() {
    let files = Files::new("export");
    let fixture = workspace_root().join("tests/fixtures/sobol_sphere_64x2.nuld");
    let blobs = [
        sobol_blob(Domain::Square, 200, 3, 4).1,
        sobol_blob(Domain::Sphere, 333, 2, 5).1,
        sobol_blob(Domain::Hemisphere, 64, 2, 6).1,
        AlignedBytes::read(&fixture).expect("the repository's fixture"),
    ];
    for (k, blob) in blobs.iter().enumerate() {
        let file = files.write(&format!("set-{k}"), blob);
        let mut want = Vec::new();
        nuld_build_tool::cli::export::write_csv(blob.as_slice(), &mut want).unwrap();
        let got = run(program(), &["export", &file]);
        assert_eq!(got, String::from_utf8(want).unwrap(), "{file}");
    }
}

/// The C program writes `f32`s as Rust's `{}` does (the shortest decimal that
/// reads back, no exponent), which the byte-for-byte comparisons rely on: here on
/// special values, powers of two (where the rounding interval is asymmetric),
/// values around 1 and random bit patterns.
#[test]
fn c_writes_floats_as_rust_does() {
    let out = run(program(), &["floats", "11", "200000"]);
    let mut count = 0;
    for line in out.lines() {
        let (bits, text) = line.split_once(',').unwrap();
        let x = f32::from_bits(u32::from_str_radix(bits, 16).unwrap());
        assert_eq!(text, format!("{x}"), "bits {bits}");
        count += 1;
    }
    assert_eq!(count, 200_020);
}

/// `key value` pairs of a line of the hostile run's summary.
fn counts(line: &str) -> Vec<(String, i64)> {
    let words: Vec<&str> = line.split_whitespace().collect();
    words
        .chunks(2)
        .map(|kv| (kv[0].to_string(), kv[1].parse().unwrap()))
        .collect()
}

#[test]
fn hostile_bytes_through_c_are_refused_without_a_crash() {
    let files = Files::new("hostile");
    // Small blobs (the checksum reads every byte of each of 20,000 mutations), of
    // every kind: the hostile-input tests' shapes.
    let small_brdf = conditional_parts(
        shape(4, &[3, 2], Activation::Silu, PointWarp::BrdfMixture, 3),
        2,
        [3, 2],
        5,
    );
    let small_env = conditional_parts(
        shape(4, &[3, 2], Activation::Relu, PointWarp::EnvmapTree, 0),
        2,
        [3, 2],
        6,
    );
    let small_table = with_brdf_prior(
        conditional_parts(
            shape(4, &[3, 2], Activation::Relu, PointWarp::BrdfTable, 2),
            2,
            [3, 2],
            7,
        ),
        small_brdf_prior(),
    );
    let blobs = [
        sobol_blob(Domain::Square, 5, 2, 1).1,
        sobol_blob(Domain::Sphere, 16, 1, 2).1,
        sobol_blob(Domain::Hemisphere, 3, 3, 3).1,
        sobol_blob(Domain::Square, 200, 1, 4).1,
        small_brdf.to_blob(&META).unwrap(),
        as_envmap(small_env).to_blob(&META).unwrap(),
        small_table.to_blob(&META).unwrap(),
    ];
    let (mut mutations, mut rechecksummed, mut accepted) = (0, 0, 0);
    for (k, blob) in blobs.iter().enumerate() {
        let file = files.write(&format!("valid-{k}"), blob);
        let seed = (100 + k).to_string();
        let out = run(program(), &["hostile", &file, &seed, "20000"]);
        let lines: Vec<Vec<(String, i64)>> = out.lines().map(counts).collect();
        let get = |line: usize, key: &str| {
            lines[line]
                .iter()
                .find(|(k, _)| k == key)
                .map(|kv| kv.1)
                .unwrap_or_else(|| panic!("{key} in {out}"))
        };
        assert_eq!(get(0, "mutations"), 20_000, "{out}");
        assert_eq!(get(0, "accepted_corrupt"), 0, "{file}: {out}");
        assert_eq!(get(0, "unusable_violations"), 0, "{file}: {out}");
        assert_eq!(
            get(0, "rejected") + get(0, "unchanged"),
            20_000,
            "{file}: {out}"
        );
        assert_eq!(get(2, "refused"), 15, "{file}: misaligned copies: {out}");
        assert_eq!(get(3, "bad_outputs"), 0, "{file}: {out}");
        // Most damage to sizes, offsets and codes is caught by the bounds checks.
        assert!(get(1, "rejected") * 2 > get(1, "rechecksummed"), "{out}");
        mutations += get(0, "mutations");
        rechecksummed += get(1, "rechecksummed");
        accepted += get(1, "accepted");
    }
    println!(
        "through C: {mutations} mutations, 0 crashes, 0 corrupted blobs accepted; \
         {rechecksummed} re-checksummed corruptions, {accepted} parsed and served sound samples"
    );
}

#[test]
fn each_bad_argument_through_c_gets_its_code() {
    let files = Files::new("errors");
    let paths = [
        files.write("2d", &sobol_blob(Domain::Square, 8, 2, 1).1),
        files.write("sphere", &sobol_blob(Domain::Sphere, 8, 2, 2).1),
        files.write(
            "brdf",
            &brdf_blob(Activation::Relu, PointWarp::BrdfMixture, 64, 3),
        ),
        files.write("env", &envmap_blob(4)),
    ];
    let mut args = vec!["errors"];
    args.extend(paths.iter().map(String::as_str));
    let out = run(program(), &args);
    let last = out.lines().last().unwrap_or_default();
    let failures: Vec<&str> = out.lines().filter(|l| l.starts_with("FAIL")).collect();
    assert!(
        last.starts_with("checks ") && last.ends_with(" failed 0"),
        "{failures:#?}\n{out}"
    );
    println!("{last}");
}

/// The C++ example, linked with the static and with the dynamic library, on an
/// environment sampler and a BRDF sampler on the tabulated prior (a metal): its
/// PDF agrees with each sample's pdf.
#[test]
fn the_cpp_example_builds_and_samples_both_targets() {
    let files = Files::new("cpp");
    let source = workspace_root().join("runtime/capi/examples/sampler.cpp");
    let env = files.write("env", &envmap_blob(6));
    let brdf = files.write("brdf", &brdf_table_blob(Activation::Relu, 64, 7));
    for (link, name) in [(Link::Static, "sampler"), (Link::Dynamic, "sampler_so")] {
        let exe = compile(&source, link, name);
        let out = run(&exe, &[&env]);
        println!("{name} on an environment sampler:\n{out}");
        let last = out.lines().last().unwrap();
        let error: f64 = last.rsplit(' ').next().unwrap().parse().unwrap();
        assert!(error < 1e-4, "{out}");
        assert!(out.contains("Sample(2): wi ("), "{out}");
        let out = run(&exe, &[&brdf]);
        println!("{name} on a BRDF sampler:\n{out}");
        assert!(
            out.contains("metal BRDF, N = 64: reflected radiance"),
            "{out}"
        );
        let last = out.lines().last().unwrap();
        let error: f64 = last.rsplit(' ').next().unwrap().parse().unwrap();
        assert!(error < 1e-3, "{out}");
        let point_set = files.write("set", &sobol_blob(Domain::Square, 4, 1, 1).1);
        let refused = Command::new(&exe)
            .arg(&point_set)
            .env_remove("LD_LIBRARY_PATH")
            .output()
            .unwrap();
        assert_eq!(refused.status.code(), Some(1));
    }
}

/// The checked-in header is cbindgen's output for the crate as it is. After
/// changing the ABI, rewrite it with
/// `NULD_WRITE_HEADER=1 cargo test --release -p nuld-tests --test capi header`.
#[test]
fn the_checked_in_header_is_generated_from_the_crate() {
    let capi = workspace_root().join("runtime/capi");
    let config = cbindgen::Config::from_file(capi.join("cbindgen.toml")).expect("cbindgen.toml");
    let header = cbindgen::Builder::new()
        .with_config(config)
        .with_src(capi.join("src/lib.rs"))
        .generate()
        .expect("cbindgen reads the crate");
    let mut fresh = Vec::new();
    header.write(&mut fresh);
    let path = capi.join("include/nuld.h");
    if std::env::var("NULD_WRITE_HEADER").is_ok_and(|v| v == "1") {
        std::fs::write(&path, &fresh).expect("the header is writable");
    }
    let checked_in = std::fs::read(&path).unwrap_or_default();
    assert!(
        checked_in == fresh,
        "{} differs from cbindgen's output; rewrite it with NULD_WRITE_HEADER=1 \
         cargo test --release -p nuld-tests --test capi header",
        path.display()
    );
}
