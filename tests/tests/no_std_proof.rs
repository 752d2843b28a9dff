//! Proof that the runtime links without `std` and without an allocator
//! (README.md, "no_std proof"): build the `nuld-no-std-check` staticlib, which has its own
//! `#[panic_handler]`, under the panic=abort `nostd-check` profile, and show that
//! the same build fails when a leak is planted on purpose; and the same for the C
//! ABI's freestanding libraries (`nuld-capi`).

use std::path::PathBuf;
use std::process::{Command, Output};

fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `cargo build --profile nostd-check [--features F]` of the proof crate, which is a
/// workspace of its own (so the std tool's features are never unified in), into a
/// target directory of its own so it does not wait on the lock of the running test
/// build.
fn build_proof(feature: Option<&str>) -> Output {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(workspace_root())
        .args(["build", "--profile", "nostd-check", "--manifest-path"])
        .arg(workspace_root().join("tests/no-std-check/Cargo.toml"))
        .env(
            "CARGO_TARGET_DIR",
            workspace_root().join("target/nostd-check"),
        )
        .env_remove("RUSTFLAGS");
    if let Some(f) = feature {
        cmd.args(["--features", f]);
    }
    cmd.output().expect("cargo runs")
}

#[test]
fn runtime_links_without_std_or_alloc_and_leaks_are_caught() {
    let ok = build_proof(None);
    let stderr = String::from_utf8_lossy(&ok.stderr);
    assert!(
        ok.status.success(),
        "the no_std proof crate failed to build:\n{stderr}"
    );

    let leak = build_proof(Some("leak-std"));
    let stderr = String::from_utf8_lossy(&leak.stderr);
    assert!(!leak.status.success(), "a std leak went unnoticed");
    assert!(
        stderr.contains("E0152") && stderr.contains("panic_impl"),
        "unexpected failure for the std leak:\n{stderr}"
    );

    let leak = build_proof(Some("leak-alloc"));
    let stderr = String::from_utf8_lossy(&leak.stderr);
    assert!(!leak.status.success(), "an alloc leak went unnoticed");
    assert!(
        stderr.contains("no global memory allocator"),
        "unexpected failure for the alloc leak:\n{stderr}"
    );
}

/// The same proof for the C ABI's freestanding libraries (`nuld-capi` built
/// `--no-default-features` under the panic=abort `capi` profile, as the README
/// builds them): the crate is a `no_std` staticlib and cdylib with its own panic
/// handler, so a std in its graph fails with E0152 and an allocator need with
/// "no global memory allocator". The leaks are planted through the runtime's
/// own features.
#[test]
fn c_libraries_link_without_std_or_alloc_and_leaks_are_caught() {
    use nuld_tests::capi::build_libraries;
    let ok = build_libraries(None);
    let stderr = String::from_utf8_lossy(&ok.stderr);
    assert!(
        ok.status.success(),
        "the freestanding C libraries failed to build:\n{stderr}"
    );

    let leak = build_libraries(Some("nuld-runtime/std"));
    let stderr = String::from_utf8_lossy(&leak.stderr);
    assert!(!leak.status.success(), "a std leak went unnoticed");
    assert!(
        stderr.contains("E0152") && stderr.contains("panic_impl"),
        "unexpected failure for the std leak:\n{stderr}"
    );

    let leak = build_libraries(Some("nuld-runtime/alloc"));
    let stderr = String::from_utf8_lossy(&leak.stderr);
    assert!(!leak.status.success(), "an alloc leak went unnoticed");
    assert!(
        stderr.contains("no global memory allocator"),
        "unexpected failure for the alloc leak:\n{stderr}"
    );
}
