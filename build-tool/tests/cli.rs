//! The `build-tool` binary end to end: write a blob, export it, and check the CSV
//! against what the runtime reads from the same file.

use nuld_build_tool::pointset::AlignedBytes;
use nuld_runtime::Blob;
use std::path::{Path, PathBuf};
use std::process::Command;

fn build_tool() -> Command {
    Command::new(env!("CARGO_BIN_EXE_build-tool"))
}

/// Runs `build-tool ARGS --out OUT`, which must fail; returns its stderr.
fn failure(args: &[&str], out: &Path) -> String {
    let o = build_tool()
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(!o.status.success(), "{args:?}");
    String::from_utf8(o.stderr).unwrap()
}

/// Runs `cmd`, which must succeed (its stderr shown if not); returns its stdout.
fn stdout_of(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nuld-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn sobol_then_export_prints_what_the_runtime_reads() {
    let dir = scratch("export");
    for (domain, header) in [
        ("square", "set,index,x,y"),
        ("sphere", "set,index,x,y,z"),
        ("hemisphere", "set,index,x,y,z"),
    ] {
        let file = dir.join(format!("{domain}.nuld"));
        let st = build_tool()
            .args([
                "sobol", "--domain", domain, "--n", "37", "--sets", "2", "--seed", "11",
            ])
            .arg("--out")
            .arg(&file)
            .status()
            .unwrap();
        assert!(st.success());
        let out = build_tool().arg("export").arg(&file).output().unwrap();
        assert!(out.status.success());
        let csv = String::from_utf8(out.stdout).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some(header));
        let rows: Vec<Vec<f32>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 2 * 37);

        let bytes = AlignedBytes::read(&file).unwrap();
        let blob = Blob::parse(bytes.as_slice()).unwrap();
        for row in &rows {
            let (s, i) = (row[0] as usize, row[1] as usize);
            let want: Vec<f32> = if domain == "square" {
                blob.point_set_2d().unwrap().point(s, i).to_array().to_vec()
            } else {
                blob.direction_set()
                    .unwrap()
                    .direction(s, i)
                    .to_array()
                    .to_vec()
            };
            assert_eq!(&row[2..], &want[..], "{domain} row {s},{i}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_gives_one_line_errors_and_writes_nothing() {
    let dir = scratch("errors");
    let missing = dir.join("nope.nuld");
    let out = build_tool().arg("export").arg(&missing).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("nope.nuld"), "{err}");

    let junk = dir.join("junk.nuld");
    std::fs::write(
        &junk,
        b"definitely not a blob: a text file that is long enough to hold a header.",
    )
    .unwrap();
    let out = build_tool().arg("export").arg(&junk).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("bad magic"), "{err}");

    let target = dir.join("zero.nuld");
    let out = build_tool()
        .args(["sobol", "--n", "0", "--out"])
        .arg(&target)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8(out.stderr).unwrap().contains("--n"));
    assert!(!target.exists());
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "only the junk input remains");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn optimize_writes_blob_report_and_picture() {
    let dir = scratch("optimize");
    let out = dir.join("run");
    let st = build_tool()
        .args([
            "optimize",
            "--density",
            "quarter-disc",
            "--n",
            "64",
            "--sets",
            "2",
        ])
        .args([
            "--epochs",
            "200",
            "--seed",
            "5",
            "--baseline-sets",
            "4",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    // stderr is a pipe here, not a terminal: plain progress lines for both phases
    // (2 sets x 200 epochs; 2 optimized + 2 starting + 4 baseline sets measured).
    let log = String::from_utf8_lossy(&st.stderr);
    for needle in [
        "optimize: epoch 0/400 (0%)",
        "optimize: done, 400 epochs in ",
        "report: set 0/8 (0%)",
        "report: done, 8 sets in ",
    ] {
        assert!(log.contains(needle), "no `{needle}` in\n{log}");
    }
    let bytes = AlignedBytes::read(&out.join("set.nuld")).unwrap();
    let blob = Blob::parse(bytes.as_slice()).unwrap();
    let pts = blob.point_set_2d().unwrap();
    assert_eq!((pts.len(), pts.set_count()), (64, 2));
    assert_eq!(blob.metadata().target, "quarter-disc");
    // Optimized through the inverse CDF: every point inside the quarter disc.
    let r2 = 2.0 / std::f32::consts::PI;
    for s in 0..2 {
        for i in 0..64 {
            let p = pts.point(s, i);
            assert!(p.x * p.x + p.y * p.y < r2 * 1.0001, "{p:?}");
        }
    }
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["n"], 64);
    assert_eq!(report["per_set"].as_array().unwrap().len(), 2);
    for key in ["asd", "l2_star", "star"] {
        let v = report["optimized_mean"][key].as_f64().unwrap();
        let b = report["baseline_warped_owen_sobol_mean"][key]
            .as_f64()
            .unwrap();
        assert!(v > 0.0 && b > 0.0, "{key}");
    }
    let png = image::open(out.join("set.png")).unwrap();
    assert!(png.width() >= 800 && png.height() >= 800);
    // Exactly the three outputs, no temporaries.
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["report.json", "set.nuld", "set.png"]);

    // `metrics` measures against the target recorded in the blob and prints the
    // report's numbers exactly: both measure the points as stored.
    assert_metrics_match_report(&out);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs `metrics` on `out/set.nuld` without `--density` and checks that it used
/// the recorded target and that every per-set value equals the report's `after`.
fn assert_metrics_match_report(out: &std::path::Path) {
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let m = build_tool()
        .arg("metrics")
        .arg(out.join("set.nuld"))
        .arg("--json")
        .output()
        .unwrap();
    assert!(m.status.success(), "{}", String::from_utf8_lossy(&m.stderr));
    let m: serde_json::Value = serde_json::from_slice(&m.stdout).unwrap();
    assert_eq!(m["density"], report["density"]);
    assert_eq!(m["density_source"], "recorded in the blob");
    let sets = report["per_set"].as_array().unwrap();
    assert_eq!(m["per_set"].as_array().unwrap().len(), sets.len());
    for (s, set) in sets.iter().enumerate() {
        let after = set["after"].as_object().unwrap();
        for (key, value) in after {
            if key.ends_with("stderr") {
                continue;
            }
            assert_eq!(m["per_set"][s][key], *value, "set {s} {key}");
        }
    }
    assert_eq!(m["mean"], report["optimized_mean"]);

    // The table says which target it used; `--density` overrides it.
    let table = build_tool()
        .arg("metrics")
        .arg(out.join("set.nuld"))
        .output()
        .unwrap();
    let text = String::from_utf8(table.stdout).unwrap();
    let density = report["density"].as_str().unwrap();
    assert_eq!(
        text.lines().next(),
        Some(format!("target: {density} (recorded in the blob)").as_str()),
        "{text}"
    );
    let other = build_tool()
        .arg("metrics")
        .arg(out.join("set.nuld"))
        .args(["--density", "uniform", "--json"])
        .output()
        .unwrap();
    let other: serde_json::Value = serde_json::from_slice(&other.stdout).unwrap();
    assert_eq!(
        (&other["density"], &other["density_source"]),
        (&"uniform".into(), &"--density".into())
    );
}

#[test]
fn optimize_rejects_bad_input_with_one_line_and_writes_nothing() {
    let dir = scratch("optimize-bad");
    for (args, needle) in [
        (vec!["--density", "nonsense:1"], "nonsense"),
        (vec!["--density", "gaussian:0.5,0.5"], "gaussian"),
        (
            vec!["--density", "image:/definitely/missing.png"],
            "missing.png",
        ),
        (vec!["--density", "uniform", "--n", "0"], "--n"),
        (vec!["--density", "bilinear:0,0,0,0"], "bilinear"),
        (
            vec!["--domain", "sphere", "--density", "gaussian:0.5,0.5,0.1"],
            "gaussian",
        ),
        (
            vec!["--domain", "hemisphere", "--density", "brdf:2,45"],
            "brdf",
        ),
        (
            vec!["--domain", "sphere", "--density", "envmap:/nope.hdr"],
            "nope.hdr",
        ),
    ] {
        let out = dir.join("never");
        let err = failure(&[&["optimize"], &args[..]].concat(), &out);
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.to_lowercase().contains(&needle.to_lowercase()),
            "{args:?}: {err}"
        );
        assert!(!out.exists(), "{args:?} left {out:?} behind");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn optimize_directions_writes_a_direction_blob() {
    let dir = scratch("optimize-dirs");
    for (domain, density) in [("sphere", "uniform"), ("hemisphere", "cosine")] {
        let out = dir.join(domain);
        let st = build_tool()
            .args([
                "optimize",
                "--domain",
                domain,
                "--density",
                density,
                "--n",
                "48",
            ])
            .args(["--epochs", "150", "--baseline-sets", "2", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        let bytes = AlignedBytes::read(&out.join("set.nuld")).unwrap();
        let blob = Blob::parse(bytes.as_slice()).unwrap();
        let dirs = blob.direction_set().unwrap();
        assert_eq!(dirs.len(), 48);
        for i in 0..48 {
            let d = dirs.direction(0, i);
            assert!((d.length() - 1.0).abs() < 1e-5);
            if domain == "hemisphere" {
                assert!(d.z >= 0.0);
            }
        }
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        assert_eq!(report["domain"], domain);
        for key in ["cap_l2", "cap_l2_theta", "cap_star_lower_bound"] {
            assert!(
                report["optimized_mean"][key].as_f64().unwrap() > 0.0,
                "{key}"
            );
        }
        let png = image::open(out.join("set.png")).unwrap();
        assert!(
            png.width() >= 3 * png.height() / 2,
            "three panels side by side"
        );
        assert_metrics_match_report(&out);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_baselines_times_every_generator_at_every_size() {
    let text = stdout_of(build_tool().args(["bench", "--only", "baselines", "--sizes", "16,32"]));
    let names = [
        "random",
        "owen-sobol",
        "sobol-cp",
        "halton",
        "poisson-disk",
        "sot",
        "gbn",
    ];
    for name in names {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no row for {name}:\n{text}"));
        let ms: Vec<f64> = line
            .split_whitespace()
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(ms.len(), 2, "{line}");
        assert!(ms.iter().all(|m| m.is_finite() && *m >= 0.0), "{line}");
    }
}

#[test]
fn export_into_a_reader_that_stops_early_ends_quietly() {
    use std::io::Read;
    use std::process::Stdio;
    let dir = scratch("pipe");
    let file = dir.join("big.nuld");
    // 4 sets of 4096 points: about 450 kB of CSV, far more than a pipe buffers, so
    // the export is still writing when the reader goes away.
    let st = build_tool()
        .args(["sobol", "--n", "4096", "--sets", "4", "--out"])
        .arg(&file)
        .status()
        .unwrap();
    assert!(st.success());
    let mut child = build_tool()
        .arg("export")
        .arg(&file)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut head = [0u8; 14];
    stdout.read_exact(&mut head).unwrap();
    assert_eq!(&head, b"set,index,x,y\n");
    drop(stdout); // what `| head` does after its lines
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {err}", out.status);
    assert!(err.is_empty(), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn negative_numbers_get_a_message_about_the_value() {
    let dir = scratch("negative");
    let out = dir.join("never");
    for (args, needle) in [
        (vec!["optimize", "--n", "-5"], "-5 is negative"),
        (vec!["optimize", "--sets", "-1"], "-1 is negative"),
        (vec!["optimize", "--epochs", "-3"], "-3 is negative"),
        (vec!["sobol", "--n", "-5"], "-5 is negative"),
        (
            vec!["optimize", "--lr", "-0.5"],
            "--lr must be positive, got -0.5",
        ),
    ] {
        let err = failure(&args, &out);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} left {out:?} behind");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unrecognized_image_names_its_extension_plainly() {
    let dir = scratch("image-ext");
    let text = dir.join("notes.txt");
    std::fs::write(
        &text,
        "not an image, and long enough to be sniffed as one\n",
    )
    .unwrap();
    let out = dir.join("never");
    let spec = format!("image:{}", text.display());
    let err = failure(&["optimize", "--density", &spec], &out);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("notes.txt"), "{err}");
    assert!(err.contains("extension `.txt`"), "{err}");
    assert!(!err.contains("\"txt\""), "{err}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small conditional blob (n 6, hidden [5], 3 instances, 3 x 4 grid) with
/// deterministic contents, written with the tool's writer.
fn conditional_blob(path: &Path) {
    use nuld_build_tool::conditional::blob::ConditionalParts;
    use nuld_core::conditional::ConditionalInfo;
    use nuld_core::quantize::f16_encode;
    let info = ConditionalInfo {
        n: 6,
        instances: 3,
        domain: 2,
        target: 1,
        grid: [3, 4],
        weight_grid: [2, 3],
        cond_min: [0.1, 0.0],
        cond_max: [1.0, 89.0],
        hidden: [5, 0, 0],
        activation: 1,
        lattice_generator: 5,
        warp: 0,
        instance_slots: 0,
        offset_hash: 1,
    };
    let params = (0..info.shape().unwrap().param_len())
        .map(|j| f16_encode(((j * 37 % 101) as f32 - 50.0) / 60.0))
        .collect();
    let table = (0..info.point_table_len().unwrap() as u32)
        .map(|e| e.wrapping_mul(0x9e37_79b9))
        .collect();
    let weights = vec![1.0, 0.9, 1.1, 0.95, 1.3, 1.05];
    let parts = ConditionalParts {
        info,
        params,
        table,
        weights,
        prior: None,
        metal: None,
        metallic_nodes: Vec::new(),
    };
    let meta = nuld_core::blob::Metadata {
        generator: "cli-test",
        target: "brdf",
        seed: 0,
    };
    parts.write_blob(path, &meta).unwrap();
}

#[test]
fn sample_prints_what_the_runtime_serves_and_rejects_bad_input() {
    use nuld_runtime::glam::Vec2;
    let dir = scratch("sample");
    let file = dir.join("brdf.nuld");
    conditional_blob(&file);
    let bytes = AlignedBytes::read(&file).unwrap();
    let cs = Blob::parse(bytes.as_slice())
        .unwrap()
        .conditional()
        .unwrap();
    for (mode, instance) in [("table", "4"), ("network", "123456")] {
        let csv = stdout_of(build_tool().arg("sample").arg(&file).args([
            "--cond",
            "0.35,47.5",
            "--instance",
            instance,
            "--mode",
            mode,
        ]));
        let mut lines = csv.lines();
        let header = lines.next().unwrap();
        assert_eq!(header, "index,x,y,z,weight,pdf");
        // The command list of `build-tool --help` names the same columns.
        let help = stdout_of(build_tool().arg("--help"));
        let line = help.lines().find(|l| l.trim_start().starts_with("sample"));
        assert!(line.unwrap().contains(&format!("`{header}`")), "{help}");
        let rows: Vec<Vec<f32>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 6);
        let c = Vec2::new(0.35, 47.5);
        let k: u32 = instance.parse().unwrap();
        for (i, row) in rows.iter().enumerate() {
            let s = match mode {
                "table" => cs.sample(c, k, i as u32),
                _ => cs.network().sample(c, k, i as u32),
            };
            let want = [
                i as f32,
                s.direction.x,
                s.direction.y,
                s.direction.z,
                s.weight,
                s.pdf,
            ];
            assert_eq!(row.as_slice(), want.as_slice(), "{mode} {i}");
        }
    }
    // The default mode is table mode, the default instance 0.
    let first = stdout_of(
        build_tool()
            .arg("sample")
            .arg(&file)
            .args(["--cond", "2,-10"]),
    )
    .lines()
    .nth(1)
    .unwrap()
    .to_string();
    let s = cs.sample(Vec2::new(1.0, 0.0), 0, 0);
    let d = s.direction;
    assert_eq!(
        first,
        format!("0,{},{},{},{},{}", d.x, d.y, d.z, s.weight, s.pdf)
    );
    // A condition outside the blob's range is clamped, and stderr says so in one
    // line; one inside the range prints nothing there.
    for (cond, warned) in [
        ("2,-10", true),
        ("0.35,47.5", false),
        ("0.35,47.5,1", false),
        // Metallic outside [0, 1] clamps too.
        ("0.35,47.5,1.5", true),
    ] {
        let out = build_tool()
            .arg("sample")
            .arg(&file)
            .args(["--cond", cond])
            .output()
            .unwrap();
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(out.status.success(), "{err}");
        assert_eq!(err.lines().count(), usize::from(warned), "{cond}: {err}");
        assert_eq!(err.contains("outside the blob's range"), warned, "{err}");
        if cond.ends_with("1.5") {
            assert!(
                err.contains("sampling at the clamped 0.35,47.5,1\n"),
                "{err}"
            );
        }
    }

    let sobol = dir.join("sobol.nuld");
    let st = build_tool()
        .args(["sobol", "--n", "8", "--out"])
        .arg(&sobol)
        .status()
        .unwrap();
    assert!(st.success());
    for (target, cond) in [
        (&sobol, "0.5,30"),
        (&file, "0.5"),
        (&file, "abc,30"),
        (&file, "0.5,inf"),
        (&file, "0.5,30,0,1"),
    ] {
        let out = build_tool()
            .arg("sample")
            .arg(target)
            .args(["--cond", cond])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{cond}");
        assert!(out.stdout.is_empty(), "{cond}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(!err.trim().is_empty(), "{cond}");
        if cond == "0.5,30" {
            assert_eq!(err.trim().lines().count(), 1, "{err}");
            assert!(err.contains("not Conditional"), "{err}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `bake` and `sample` on environment samplers: one-line errors for a missing or
/// undecodable map, an unusable `--out`, two targets at once, a normal given to a
/// BRDF blob, or both `--cond` and `--normal`; nothing written.
#[test]
fn envmap_bake_and_sample_reject_bad_input_with_one_line() {
    let dir = scratch("envmap-bad");
    let out = dir.join("never");
    let missing = dir.join("missing.hdr");
    let e = failure(&["bake", "--envmap", missing.to_str().unwrap()], &out);
    assert!(
        e.contains("cannot read environment map") && e.contains("missing.hdr"),
        "{e}"
    );
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    let e = failure(&["bake", "--brdf", "--envmap", "x.hdr"], &out);
    assert!(e.contains("cannot be used with"), "{e}");
    let e = failure(&["bake"], &out);
    assert!(e.contains("--brdf or --envmap MAP"), "{e}");
    // Slots whose embedding (M n h1 numbers) would not fit in a u32, a negative
    // slot count, a union weight that is no number: one line, nothing written.
    let e = failure(
        &[
            "bake",
            "--brdf",
            "--n",
            "65536",
            "--hidden",
            "128",
            "--instance-slots",
            "512",
        ],
        &out,
    );
    assert!(e.contains("max(instance slots, 1) x n"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    let e = failure(&["bake", "--brdf", "--instance-slots", "-1"], &out);
    assert!(e.contains("negative"), "{e}");
    let e = failure(&["bake", "--brdf", "--union-weight", "nan"], &out);
    assert!(e.contains("--union-weight must be finite"), "{e}");
    let e = failure(&["bake", "--brdf", "--alpha-end", "0"], &out);
    assert!(e.contains("--alpha-end must be finite and > 0"), "{e}");
    let e = failure(&["bake", "--brdf", "--pool-conditions", "0"], &out);
    assert!(
        e.contains("--pool-conditions must be in 1..=65536, got 0"),
        "{e}"
    );
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    // Metallic nodes out of order, out of [0, 1], too few, not numbers.
    for nodes in ["0.5,0.2", "0,1.5", "0.5", "0,x"] {
        let e = failure(&["bake", "--brdf", "--metallic-nodes", nodes], &out);
        assert!(e.contains("--metallic-nodes"), "{nodes}: {e}");
    }
    assert!(!out.exists());
    // A map that exists but does not decode fails in the pool, after the output
    // directory was made: it goes again.
    let junk = dir.join("junk.hdr");
    std::fs::write(&junk, b"not an image").unwrap();
    let e = failure(&["bake", "--envmap", junk.to_str().unwrap()], &out);
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert!(!out.exists());
    // The same from N = 256, where the bake trains nothing and builds no pool:
    // the map fails as it loads, and the directory goes again.
    let e = failure(
        &["bake", "--envmap", junk.to_str().unwrap(), "--n", "256"],
        &out,
    );
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert!(!out.exists());
    // No training steps leave nothing to resume.
    let e = failure(&["bake", "--brdf", "--steps", "0", "--resume"], &out);
    assert!(e.contains("--resume continues a training run"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    // An --out that cannot be a directory fails before the pool: its error comes
    // first, not the map's.
    let e = failure(
        &["bake", "--envmap", junk.to_str().unwrap()],
        &junk.join("out"),
    );
    assert!(e.contains("cannot create directory"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert_eq!(std::fs::read(&junk).unwrap(), b"not an image");
    // A map that is not 2:1 is read all the same, with a warning first.
    let square = dir.join("square.png");
    image::GrayImage::from_pixel(16, 16, image::Luma([200]))
        .save(&square)
        .unwrap();
    let e = failure(
        &["bake", "--envmap", square.to_str().unwrap()],
        &junk.join("out"),
    );
    let lines: Vec<&str> = e.trim().lines().collect();
    assert_eq!(lines.len(), 2, "{e}");
    assert!(
        lines[0].starts_with("warning:") && lines[0].contains("16 x 16 pixels, not 2:1"),
        "{e}"
    );
    assert!(lines[1].contains("cannot create directory"), "{e}");
    let file = dir.join("brdf.nuld");
    conditional_blob(&file);
    for args in [
        vec!["--normal", "0,0,1"],
        vec!["--normal", "0,0,0"],
        vec!["--cond", "0.5,30", "--normal", "0,0,1"],
        vec![],
    ] {
        let o = build_tool()
            .arg("sample")
            .arg(&file)
            .args(&args)
            .output()
            .unwrap();
        assert!(!o.status.success(), "{args:?}");
        assert!(o.stdout.is_empty(), "{args:?}");
        let err = String::from_utf8(o.stderr).unwrap();
        assert!(!err.trim().is_empty(), "{args:?}");
        if args == ["--normal", "0,0,1"] {
            assert_eq!(err.trim().lines().count(), 1, "{err}");
            assert!(
                err.contains("--normal needs an environment sampler"),
                "{err}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `build-tool shader` writes each language's kernel to `--out` (the same bytes
/// the library translates), prints it to stdout without `--out`, and fails with one
/// line and no file for an unwritable path or an unknown language.
#[test]
fn shader_writes_each_language_or_fails_cleanly() {
    use nuld_build_tool::shader::{translate, Lang};
    let dir = scratch("shader");
    for lang in Lang::ALL {
        let path = dir.join(format!("kernel.{}", lang.name()));
        let o = build_tool()
            .args(["shader", "--lang", lang.name(), "--out"])
            .arg(&path)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let written = std::fs::read(&path).unwrap();
        assert_eq!(written, translate(lang).unwrap().bytes, "{}", lang.name());
    }
    let o = build_tool()
        .args(["shader", "--lang", "glsl"])
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(o.stdout.starts_with(b"#version 450"));
    let missing = dir.join("no/such/dir/kernel.wgsl");
    let err = failure(&["shader", "--lang", "wgsl"], &missing);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!missing.exists());
    let o = build_tool()
        .args(["shader", "--lang", "cuda"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), Lang::ALL.len(), "{names:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `eval brdf-prior --sets K` judges a blob's instances 0 to K-1: a K beyond
/// the instances the blob stores (3 here) is refused in one line before
/// anything is written.
#[test]
fn eval_brdf_prior_refuses_more_sets_than_the_blob_stores() {
    let dir = scratch("eval-prior-sets");
    let file = dir.join("brdf.nuld");
    conditional_blob(&file);
    let out = dir.join("eval");
    let blob = file.to_str().unwrap();
    let err = failure(&["eval", "brdf-prior", "--sets", "4", "--blob", blob], &out);
    assert!(
        err.contains("--sets 4 exceeds the 3 instances the blob stores"),
        "{err}"
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `eval conditional --blob` reads a blob file (16-byte aligned, as `Blob::parse`
/// demands) and judges its table and network modes through the runtime: the
/// report's first rows are those two samplers, with finite ratios.
#[test]
fn eval_conditional_judges_a_blob_file() {
    let dir = scratch("eval-blob");
    let file = dir.join("brdf.nuld");
    conditional_blob(&file);
    let out = dir.join("eval");
    let table = stdout_of(
        build_tool()
            .args(["eval", "conditional", "--quick", "--blob"])
            .arg(&file)
            .arg("--out")
            .arg(&out),
    );
    assert!(
        table.contains("| table |") && table.contains("| network |"),
        "{table}"
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("conditional.json")).unwrap()).unwrap();
    assert_eq!(json["n"], 6);
    for (row, name) in ["table", "network"].iter().enumerate() {
        let s = &json["summary"][row];
        assert_eq!(s["sampler"], *name);
        let r = s["mean_ratio_exact"].as_f64().unwrap();
        assert!(r.is_finite() && r > 0.0, "{name}: {r}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
