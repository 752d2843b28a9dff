//! The README's Rust and WGSL snippets are examples, verbatim: `cargo test` compiles
//! `runtime/examples/*.rs` and `tests/examples/*.rs` (the WGSL ones are
//! `include_str!`-ed there), and this test fails if the README's copy of one drifts
//! from the file or if a ```rust or ```wgsl block in the README is not such a copy.

use std::path::{Path, PathBuf};

/// The line that precedes each quoted example in the README, naming its file.
const MARKER: &str = "<!-- verbatim: ";

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The fences that open a block that must be a verbatim copy.
const QUOTED_FENCES: [&str; 2] = ["```rust", "```wgsl"];

/// `(file named by the marker, text of the fenced block after it)` for every marker,
/// and the number of ```rust and ```wgsl fences in the text.
fn quoted_examples(readme: &str) -> (Vec<(String, String)>, usize) {
    let lines: Vec<&str> = readme.lines().collect();
    let mut quoted = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        let Some(rest) = line.strip_prefix(MARKER) else {
            continue;
        };
        let file = rest.trim_end_matches("-->").trim().to_string();
        assert!(
            lines.get(k + 1).is_some_and(|l| QUOTED_FENCES.contains(l)),
            "the line after the marker for {file} must open a ```rust or ```wgsl block"
        );
        let body: Vec<&str> = lines[k + 2..]
            .iter()
            .take_while(|l| **l != "```")
            .copied()
            .collect();
        quoted.push((file, body.join("\n") + "\n"));
    }
    let fences = lines
        .iter()
        .filter(|l| QUOTED_FENCES.contains(&l.trim()))
        .count();
    (quoted, fences)
}

#[test]
fn readme_rust_snippets_are_the_examples_verbatim() {
    let readme = std::fs::read_to_string(repo_root().join("README.md")).expect("README.md");
    let (quoted, fences) = quoted_examples(&readme);
    assert!(!quoted.is_empty(), "the README quotes no example");
    assert_eq!(
        quoted.len(),
        fences,
        "every ```rust and ```wgsl block in the README must follow a `{MARKER}FILE -->` line"
    );
    for (file, text) in quoted {
        assert!(
            file.starts_with("runtime/examples/") || file.starts_with("tests/examples/"),
            "{file}: quote files that `cargo test` compiles"
        );
        let on_disk = std::fs::read_to_string(repo_root().join(&file))
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(
            text, on_disk,
            "README's copy of {file} differs from the file"
        );
    }
}

#[test]
fn a_drifted_copy_is_caught() {
    let readme = "x\n<!-- verbatim: runtime/examples/embed.rs -->\n```rust\nfn main() {}\n```\n```rust\n```\n";
    let (quoted, fences) = quoted_examples(readme);
    assert_eq!(fences, 2);
    assert_eq!(
        quoted,
        vec![(
            "runtime/examples/embed.rs".to_string(),
            "fn main() {}\n".to_string()
        )]
    );
    let on_disk = std::fs::read_to_string(repo_root().join("runtime/examples/embed.rs")).unwrap();
    assert_ne!(quoted[0].1, on_disk);
}

#[test]
fn readme_test_command_is_the_one_ci_runs() {
    let readme = std::fs::read_to_string(repo_root().join("README.md")).expect("README.md");
    let ci = std::fs::read_to_string(repo_root().join(".ci/run")).expect(".ci/run");
    let commands: Vec<&str> = readme
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("cargo test"))
        .collect();
    assert_eq!(
        commands.len(),
        1,
        "one test command in the README: {commands:?}"
    );
    assert!(
        ci.lines().any(|l| l.trim() == commands[0]),
        "CI does not run the README's `{}`",
        commands[0]
    );
}
