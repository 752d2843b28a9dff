//! `build-tool eval conditional` end to end: `--quick --calibrate` writes its JSON,
//! CSV and pictures with the calibration figures in range; a run without a sampler,
//! or with an unreadable blob, fails with one line and writes nothing.

use std::path::PathBuf;
use std::process::Command;

fn build_tool() -> Command {
    Command::new(env!("CARGO_BIN_EXE_build-tool"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nuld-evalcond-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn quick_calibration_run_writes_its_report() {
    let out = scratch("quick");
    let o = build_tool()
        .args(["eval", "conditional", "--quick", "--calibrate", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("| calibration |"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("conditional.json")).unwrap()).unwrap();
    assert_eq!(json["n"], 64);
    let conditions = json["conditions"].as_array().unwrap();
    assert_eq!(conditions.len(), 3);
    // The calibration sampler is Owen-Sobol through the mixture warp with its own
    // scrambles: against the mixture reference its ratio is near 1, and its
    // instances are as far apart as independent scrambles.
    let s = &json["summary"][0];
    assert_eq!(s["sampler"], "calibration");
    let mix = s["mean_ratio_mixture"].as_f64().unwrap();
    assert!((0.8..1.25).contains(&mix), "{mix}");
    let nn = s["mean_nn_ratio"].as_f64().unwrap();
    assert!((nn - 0.65).abs() < 0.1, "{nn}");
    assert!(conditions[0]["direct"]["cap_l2"].as_f64().unwrap() > 0.0);
    let csv = std::fs::read_to_string(out.join("conditional.csv")).unwrap();
    // Header + per condition: calibration, exact, mixture (+ direct at one).
    assert_eq!(csv.lines().count(), 1 + 3 * 3 + 1, "{csv}");
    for f in [
        "conditional-calibration-ratio.png",
        "conditional-calibration-union.png",
        "conditional-sets-calibration-r0.13-t85.png",
        "conditional-sets-owen-sobol-exact-r0.13-t85.png",
    ] {
        let bytes = std::fs::read(out.join(f)).unwrap_or_else(|_| panic!("{f} missing"));
        assert!(bytes.starts_with(b"\x89PNG"), "{f}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn missing_sampler_or_blob_fails_in_one_line_and_writes_nothing() {
    for (name, extra) in [
        ("none", vec![]),
        ("absent", vec!["--blob", "/nonexistent/brdf.nuld"]),
    ] {
        let out = scratch(name);
        let o = build_tool()
            .args(["eval", "conditional", "--quick", "--out"])
            .arg(&out)
            .args(&extra)
            .output()
            .unwrap();
        assert!(!o.status.success());
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(!out.exists(), "{name}: {} was created", out.display());
    }
}
