//! `build-tool eval conditional` end to end: `--quick --calibrate` writes its JSON,
//! CSV and pictures, per metallic, with the calibration figures in range; a run
//! without a sampler, or with an unreadable blob, fails with one line and writes
//! nothing.

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
    // 3 (roughness, theta_o) at each default metallic, metallic-major.
    assert_eq!(conditions.len(), 9);
    let metallic: Vec<f64> = conditions
        .iter()
        .map(|c| c["metallic"].as_f64().unwrap())
        .collect();
    assert_eq!(metallic, [0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0]);
    let by: Vec<f64> = json["by_metallic"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["metallic"].as_f64().unwrap())
        .collect();
    assert_eq!(by, [0.0, 0.5, 1.0]);
    // The calibration sampler is Owen-Sobol through the mixture warp with its own
    // scrambles: against the mixture reference its ratio is near 1, and its
    // instances are as far apart as independent scrambles.
    let s = &json["summary"][0];
    assert_eq!(s["sampler"], "calibration");
    let mix = s["mean_ratio_mixture"].as_f64().unwrap();
    assert!((0.8..1.25).contains(&mix), "{mix}");
    let nn = s["mean_nn_ratio"].as_f64().unwrap();
    assert!((nn - 0.65).abs() < 0.1, "{nn}");
    // Direct optimization at the sharpest condition of the dielectric and the
    // metal, not of the blend.
    for (i, direct) in [(0, true), (3, false), (6, true)] {
        assert_eq!(conditions[i]["direct"].is_object(), direct, "condition {i}");
    }
    assert!(conditions[6]["direct"]["cap_l2"].as_f64().unwrap() > 0.0);
    let csv = std::fs::read_to_string(out.join("conditional.csv")).unwrap();
    // Header + per condition: calibration, exact, mixture (+ direct at two).
    assert_eq!(csv.lines().count(), 1 + 9 * 3 + 2, "{csv}");
    assert!(
        csv.starts_with("roughness,theta_o_deg,metallic,method,"),
        "{csv}"
    );
    assert!(stdout.contains("| 0.5 | calibration |"), "{stdout}");
    for f in [
        "conditional-calibration-ratio-m0.png",
        "conditional-calibration-ratio-m0.5.png",
        "conditional-calibration-union-m1.png",
        "conditional-sets-calibration-r0.13-t85-m0.png",
        "conditional-sets-owen-sobol-exact-r0.13-t85-m1.png",
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
