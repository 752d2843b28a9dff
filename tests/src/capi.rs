//! The C ABI's libraries and programs, for tests/tests/capi.rs, the no_std proof
//! and tests/examples/capi_bench.rs: the freestanding `libnuld_capi.a` and
//! `libnuld_capi.so` built as the README says, and C and C++ programs compiled
//! against them by the system compiler (the `cc` crate's choice: `CC` and `CXX`
//! if set, else `cc` and `c++`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The repository's root.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Where the header `nuld.h` is.
pub fn include_dir() -> PathBuf {
    workspace_root().join("runtime/capi/include")
}

/// `<target>/capi-c`: the nested builds' target directory and the compiled
/// programs, beside the running test or example binary's own
/// (`<target>/<profile>/{deps,examples}/NAME`).
pub fn build_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the running binary's path");
    let target = exe
        .ancestors()
        .nth(3)
        .expect("the binary lies in <target>/<profile>/<dir>");
    target.join("capi-c")
}

/// `cargo build -p nuld-capi --profile capi --no-default-features [--features
/// F]` into [`build_dir`], a target directory of its own so that it does not wait
/// on the lock of the running build: the freestanding libraries, as the README
/// builds them (`F` plants a leak for the no_std proof).
pub fn build_libraries(features: Option<&str>) -> Output {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(workspace_root())
        .args(["build", "--locked", "-p", "nuld-capi", "--profile", "capi"])
        .args(["--no-default-features", "--target-dir"])
        .arg(build_dir())
        .env_remove("RUSTFLAGS");
    if let Some(f) = features {
        cmd.args(["--features", f]);
    }
    cmd.output().expect("cargo runs")
}

/// The directory of the freestanding `libnuld_capi.a` and `libnuld_capi.so`,
/// built once per process. Panics with cargo's output if the build fails.
pub fn libraries() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let out = build_libraries(None);
        assert!(
            out.status.success(),
            "building the C libraries failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        build_dir().join("capi")
    })
}

/// How a program links the library.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// `libnuld_capi.a`, into the executable.
    Static,
    /// `libnuld_capi.so`, found at run time through the executable's rpath.
    Dynamic,
}

/// Compiles the C (`.c`, C11) or C++ (`.cpp`, C++17) program `source` with
/// warnings as errors and `-O2`, against the header and the freestanding
/// library linked as `link`, into `build_dir()/bin/NAME`, and returns its path.
/// Panics with the compiler's output if it fails.
pub fn compile(source: &Path, link: Link, name: &str) -> PathBuf {
    let cpp = source.extension().is_some_and(|e| e == "cpp");
    let lib = libraries();
    let bin = build_dir().join("bin");
    std::fs::create_dir_all(&bin).expect("a directory for the programs");
    let compiler = cc::Build::new()
        .cpp(cpp)
        .target(env!("NULD_TESTS_TARGET"))
        .host(env!("NULD_TESTS_HOST"))
        .opt_level(2)
        .debug(false)
        .cargo_metadata(false)
        .warnings(true)
        .extra_warnings(true)
        .warnings_into_errors(true)
        .flag(if cpp { "-std=c++17" } else { "-std=c11" })
        .flag("-pedantic")
        .try_get_compiler()
        .expect("a C and C++ compiler (CI installs gcc and g++)");
    let out = bin.join(name);
    let mut cmd = compiler.to_command();
    cmd.arg("-I").arg(include_dir()).arg(source);
    match link {
        Link::Static => {
            cmd.arg(lib.join("libnuld_capi.a"));
        }
        Link::Dynamic => {
            cmd.arg("-L").arg(lib).arg("-lnuld_capi");
            cmd.arg(format!("-Wl,-rpath,{}", lib.display()));
        }
    }
    // libm: the test program's `sinf` and `cosf` (the library itself needs only
    // the C library's `abort`, `memcpy` and `memset`).
    cmd.arg("-lm").arg("-o").arg(&out);
    let result = cmd.output().expect("the compiler runs");
    let args: Vec<_> = cmd.get_args().map(|a| a.to_string_lossy()).collect();
    assert!(
        result.status.success(),
        "compiling {} failed:\n{} {}\n{}",
        source.display(),
        cmd.get_program().to_string_lossy(),
        args.join(" "),
        String::from_utf8_lossy(&result.stderr)
    );
    out
}
