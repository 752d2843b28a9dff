//! `build-tool eval` end to end in `--quick` mode: the CSV, JSON and PNG outputs
//! exist and parse, metrics are positive, and a rerun is served from the cache with
//! byte-identical output.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

fn build_tool() -> Command {
    Command::new(env!("CARGO_BIN_EXE_build-tool"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nuld-eval-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// `../shared/data` beside the checkout (CI layout); may be missing.
fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data")
}

/// Runs `eval FIG --quick --max-n 32`; returns (seconds, stderr).
fn eval(fig: &str, out: &Path) -> (f64, String) {
    let started = Instant::now();
    let o = build_tool()
        .args(["eval", fig, "--quick", "--max-n", "32", "--out"])
        .arg(out)
        .arg("--data")
        .arg(data_dir())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "eval {fig} failed: {stderr}");
    (started.elapsed().as_secs_f64(), stderr)
}

/// All output files of a figure (CSV, JSON, PNGs), sorted, with their bytes.
fn outputs(out: &Path, fig: &str) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .filter_map(|p| {
            let name = p.file_name()?.to_string_lossy().into_owned();
            name.starts_with(fig)
                .then(|| (name, std::fs::read(&p).unwrap()))
        })
        .collect();
    v.sort();
    v
}

/// Checks a figure's CSV, JSON and plots; returns the number of CSV rows.
fn check_outputs(out: &Path, fig: &str, metrics: &[&str]) -> usize {
    let csv = std::fs::read_to_string(out.join(format!("{fig}.csv"))).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("target,metric,method,n,mean,stderr,realizations")
    );
    let mut rows = 0;
    let mut targets = std::collections::BTreeSet::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 7, "{line}");
        assert!(metrics.contains(&f[1]), "{line}");
        let n: usize = f[3].parse().unwrap();
        assert!([4, 8, 16, 32].contains(&n), "{line}");
        let mean: f64 = f[4].parse().unwrap();
        let se: f64 = f[5].parse().unwrap();
        let r: usize = f[6].parse().unwrap();
        assert!(mean.is_finite() && mean > 0.0, "{line}");
        assert!(se.is_finite() && se >= 0.0, "{line}");
        assert_eq!(r, if f[2] == "ours" { 2 } else { 8 }, "{line}");
        targets.insert(f[0].to_string());
        rows += 1;
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join(format!("{fig}.json"))).unwrap())
            .unwrap();
    assert_eq!(json["figure"], fig);
    assert_eq!(json["settings"]["quick"], true);
    assert_eq!(json["rows"].as_array().unwrap().len(), rows);
    let panels = json["panels"].as_array().unwrap();
    assert_eq!(panels.len(), targets.len());
    for p in panels {
        assert!(!p["notes"].as_array().unwrap().is_empty());
        for plot in p["plots"].as_array().unwrap() {
            let img = image::open(out.join(plot.as_str().unwrap())).unwrap();
            assert_eq!((img.width(), img.height()), (1000, 700));
        }
        for m in metrics {
            let name = format!("{fig}-{}-{m}.png", p["target"].as_str().unwrap());
            assert!(out.join(&name).is_file(), "{name}");
        }
    }
    // One summary line per (target, metric), each naming ours' value and a ratio.
    let summary = std::fs::read_to_string(out.join(format!("{fig}-summary.md"))).unwrap();
    let lines: Vec<&str> = summary.lines().skip(2).collect();
    assert_eq!(lines.len(), targets.len() * metrics.len(), "{summary}");
    for l in lines {
        assert!(
            l.starts_with(&format!("| {fig} | ")) && l.ends_with("/4 |"),
            "{l}"
        );
    }
    rows
}

#[test]
fn quick_figures_write_parseable_outputs_and_reruns_hit_the_cache() {
    let out = scratch("quick");
    let figs: [(&str, &[&str]); 2] = [
        ("fig2", &["l2-star", "star"]),
        ("fig5", &["asd", "l2-star", "star"]),
    ];
    for (fig, metrics) in figs {
        let (first, log) = eval(fig, &out);
        assert!(log.contains("(0 from the cache)"), "{log}");
        let rows = check_outputs(&out, fig, metrics);
        let panels = if fig == "fig2" {
            1
        } else if data_dir().join("images/camera.png").is_file() {
            4
        } else {
            assert!(log.contains("skipping camera"), "{log}");
            3
        };
        let methods = if fig == "fig2" { 8 } else { 5 };
        assert_eq!(rows, panels * metrics.len() * methods * 4, "{fig}");
        let before = outputs(&out, fig);

        let (second, log) = eval(fig, &out);
        for line in log.lines().filter(|l| l.contains("realizations (")) {
            // "figN target: T realizations (T from the cache) in ..."
            let total = line.split(": ").nth(1).unwrap().split(' ').next().unwrap();
            assert!(
                line.contains(&format!("({total} from the cache)")),
                "{line}"
            );
        }
        assert_eq!(
            outputs(&out, fig),
            before,
            "{fig}: rerun changed the output"
        );
        assert!(
            second < first,
            "{fig}: cached rerun {second:.1} s vs {first:.1} s"
        );
        eprintln!("{fig}: first run {first:.1} s, cached rerun {second:.1} s");
    }
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn bad_arguments_give_one_line_errors() {
    let out = scratch("bad");
    for args in [
        vec!["eval", "fig2", "--quick", "--max-n", "2"],
        vec!["eval", "fig2", "--quick", "--realizations-ours", "0"],
    ] {
        let o = build_tool()
            .args(&args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(!o.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    }
    let o = build_tool()
        .args(["eval", "fig4", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let _ = std::fs::remove_dir_all(&out);
}
