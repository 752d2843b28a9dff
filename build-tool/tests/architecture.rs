//! The crate's boundaries, read from its sources: the product never imports the lab
//! (nor the CLI), not even in its tests; no two top-level modules import each other,
//! directly or around a circle; no source file but a test module is over 800 lines.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level modules that judge or drive the product; everything else is product.
const LAB: &[&str] = &["lab", "cli"];

/// Longest source file allowed, in lines (test modules apart).
const MAX_LINES: usize = 800;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file under `src/` belongs to (`lib.rs` and `main.rs`: none).
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel.components().next()?.as_os_str().to_str()?.to_string();
    let name = first.strip_suffix(".rs").unwrap_or(&first).to_string();
    (name != "lib" && name != "main").then_some(name)
}

/// A line of code without its comment and with string literals emptied, so that a
/// module named in documentation or in a message is not an import.
fn code_of(line: &str) -> String {
    // A quote as a char literal opens no string.
    let line = line.replace("'\\\"'", "' '").replace("'\"'", "' '");
    let mut out = String::new();
    let mut in_string = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        if in_string {
            if c == '\\' {
                chars.next();
            } else if c == '"' {
                in_string = false;
                out.push('"');
            }
            continue;
        }
        if c == '/' && chars.peek() == Some(&'/') {
            break;
        }
        if c == '"' {
            in_string = true;
        }
        out.push(c);
    }
    out
}

fn identifier_at(s: &str) -> String {
    s.chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect()
}

/// The top-level modules that `code` names through `crate::` paths, including the
/// first names of a `use crate::{a, b::c}` group.
fn crate_references(code: &str) -> Vec<String> {
    let mut names = Vec::new();
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let group = group.split('}').next().unwrap_or("");
            for item in group.split(',') {
                let name = identifier_at(item.trim());
                if !name.is_empty() {
                    names.push(name);
                }
            }
        } else {
            let name = identifier_at(rest);
            if !name.is_empty() {
                names.push(name);
            }
        }
    }
    names
}

/// Every import edge between top-level modules, with one place that makes it.
fn module_edges() -> BTreeMap<(String, String), String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut edges = BTreeMap::new();
    for file in &files {
        let Some(from) = top_module(&src, file) else {
            continue;
        };
        let text = std::fs::read_to_string(file).unwrap();
        // A `use crate::{...}` group may span lines: read the file as one line of
        // code per source line, then join.
        let code: Vec<String> = text.lines().map(code_of).collect();
        let joined = code.join(" ");
        for to in crate_references(&joined) {
            if to != from {
                let at = format!("{}", file.strip_prefix(&src).unwrap().display());
                edges.entry((from.clone(), to)).or_insert(at);
            }
        }
    }
    edges
}

#[test]
fn the_product_never_imports_the_lab() {
    let edges = module_edges();
    // The reader sees the imports (a reader that saw none would pass anything).
    for known in [
        ("optimize", "descent"),
        ("train", "network"),
        ("lab", "train"),
    ] {
        assert!(
            edges.contains_key(&(known.0.to_string(), known.1.to_string())),
            "the source reader missed {known:?}"
        );
    }
    let crossings: Vec<String> = edges
        .iter()
        .filter(|((from, to), _)| !LAB.contains(&from.as_str()) && LAB.contains(&to.as_str()))
        .map(|((from, to), at)| format!("{from} -> {to} ({at})"))
        .collect();
    assert!(
        crossings.is_empty(),
        "product imports the lab: {crossings:#?}"
    );
}

#[test]
fn no_import_circle_between_top_level_modules() {
    let edges = module_edges();
    let mut graph: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    for (from, to) in edges.keys() {
        graph.entry(from).or_default().insert(to);
    }
    // A circle exists iff a depth-first search meets a module still on its path.
    fn visit<'a>(
        m: &'a str,
        graph: &BTreeMap<&'a str, BTreeSet<&'a str>>,
        path: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
    ) -> Option<Vec<&'a str>> {
        if let Some(start) = path.iter().position(|&p| p == m) {
            let mut circle = path[start..].to_vec();
            circle.push(m);
            return Some(circle);
        }
        if done.contains(m) {
            return None;
        }
        path.push(m);
        for &next in graph.get(m).into_iter().flatten() {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(m);
        None
    }
    let mut done = BTreeSet::new();
    for &m in graph.keys() {
        if let Some(circle) = visit(m, &graph, &mut Vec::new(), &mut done) {
            let places: Vec<String> = circle
                .windows(2)
                .map(|w| {
                    let at = &edges[&(w[0].to_string(), w[1].to_string())];
                    format!("{} -> {} ({at})", w[0], w[1])
                })
                .collect();
            panic!("import circle: {places:#?}");
        }
    }
}

#[test]
fn no_source_file_but_a_test_module_is_over_800_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let mut files = Vec::new();
    for krate in ["core", "runtime", "build-tool"] {
        rust_files(&root.join(krate).join("src"), &mut files);
    }
    assert!(files.len() > 50, "found only {} files", files.len());
    let long: Vec<String> = files
        .iter()
        .filter(|f| f.file_name().is_some_and(|n| n != "tests.rs"))
        .filter_map(|f| {
            let lines = std::fs::read_to_string(f).unwrap().lines().count();
            (lines > MAX_LINES).then(|| format!("{} ({lines} lines)", f.display()))
        })
        .collect();
    assert!(long.is_empty(), "files over {MAX_LINES} lines: {long:#?}");
}
