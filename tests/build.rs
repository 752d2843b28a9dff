//! Passes the target and host triples to `nuld_tests::capi`, which drives the
//! `cc` crate (the system C and C++ compilers) at test time, outside a build
//! script, where cargo does not set them.
fn main() {
    for var in ["TARGET", "HOST"] {
        let value = std::env::var(var).unwrap_or_default();
        println!("cargo:rustc-env=NULD_TESTS_{var}={value}");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
