//! The `build-tool` binary end to end: write a blob, export it, and check the CSV
//! against what the runtime reads from the same file.

use nuld_build_tool::pointset::AlignedBytes;
use nuld_runtime::Blob;
use std::path::PathBuf;
use std::process::Command;

fn build_tool() -> Command {
    Command::new(env!("CARGO_BIN_EXE_build-tool"))
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
            .args(["sobol", "--domain", domain, "--n", "37", "--sets", "2", "--seed", "11"])
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
                blob.direction_set().unwrap().direction(s, i).to_array().to_vec()
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
    std::fs::write(&junk, b"definitely not a blob: a text file that is long enough to hold a header.").unwrap();
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
