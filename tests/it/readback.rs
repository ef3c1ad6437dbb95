//! Issue 29, "files read back are validated like user input": measurement
//! CSVs read by `calibrate`, the profiles it writes and `predict` reads,
//! LOD instances and mesh files. Every bad value ends in exit 2 and one
//! `error:` line naming the file, the line and the column or key; nothing
//! already written is lost. The bad files are `tests/fixtures/readback/`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/readback")
        .join(name)
}

fn h200(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/measurements/nvidia-h200")
        .join(name)
}

/// Runs rendersim in `dir`; the exit status must be 2 with an `error:`
/// line and no panic. Returns that line.
fn refused(dir: &Path, args: &[&str]) -> String {
    let o: Output = bin().args(args).current_dir(dir).output().unwrap();
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(!e.contains("panicked") && !e.contains("memory allocation"), "{e}");
    e.lines()
        .find(|l| l.starts_with("error: "))
        .unwrap_or_else(|| panic!("no error line: {e}"))
        .to_string()
}

#[test]
fn calibrate_refuses_times_that_are_not_finite_and_positive() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("profile.toml");
    std::fs::write(&out, "kept").unwrap();
    let text = std::fs::read_to_string(h200("load-grid.csv")).unwrap();
    for bad in ["nan", "NaN", "inf", "-inf", "-5", "0", "-0.0", "1e400"] {
        let csv = d.path().join("rows.csv");
        let lines: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| {
                if i == 2 {
                    let (head, _) = l.rsplit_once(',').unwrap();
                    format!("{head},{bad}")
                } else {
                    l.to_string()
                }
            })
            .collect();
        std::fs::write(&csv, lines.join("\n")).unwrap();
        let e = refused(
            d.path(),
            &["calibrate", csv.to_str().unwrap(), "--out", out.to_str().unwrap()],
        );
        assert!(
            e.contains(&format!("{}: line 3, column 8 (pass_time_ns): ", csv.display())),
            "{bad}: {e}"
        );
        assert!(e.contains("finite number of nanoseconds above 0"), "{bad}: {e}");
        // The profile already there is left as it was.
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "kept");
    }
    let f = fixture("negative-time.csv");
    let e = refused(d.path(), &["calibrate", f.to_str().unwrap(), "--out", "p.toml"]);
    assert!(
        e.contains("negative-time.csv: line 5, column 8 (pass_time_ns): -inf"),
        "{e}"
    );
    assert!(!d.path().join("p.toml").exists());
}

#[test]
fn a_bad_mesh_cell_names_file_line_and_column() {
    let d = tempfile::tempdir().unwrap();
    let f = fixture("bad-mesh.csv");
    let e = refused(d.path(), &["calibrate", f.to_str().unwrap(), "--out", "p.toml"]);
    assert!(
        e.contains(&format!("{}: line 3, column 1 (mesh): \"grid:axb\"", f.display())),
        "{e}"
    );
    // A mesh file that is not there: found while building, still named by
    // the first row that gives it.
    let f = fixture("missing-mesh.csv");
    let e = refused(d.path(), &["calibrate", f.to_str().unwrap(), "--out", "p.toml"]);
    assert!(
        e.contains(&format!("{}: line 4, column 1 (mesh): ", f.display())) && e.contains("missing-mesh.idx"),
        "{e}"
    );
    assert!(!d.path().join("p.toml").exists());
}

/// The profile `calibrate` writes for a name with a newline, quotes,
/// backslashes and unicode reads back (`predict` uses it, the name is the
/// same).
#[test]
fn calibrate_writes_odd_names_that_predict_reads_back() {
    use rendersim::measure::device_profile::DeviceProfile;
    let d = tempfile::tempdir().unwrap();
    for (i, name) in [
        "x\n[device]",
        "a \"quoted\" name with \\ and ''' and \"\"\"",
        "ünïcødé 🎮\t\r\u{7f}",
        "",
    ]
    .into_iter()
    .enumerate()
    {
        let out = d.path().join(format!("p{i}.toml"));
        let o = bin()
            .args(["calibrate", h200("load-grid.csv").to_str().unwrap(), "--out"])
            .arg(&out)
            .args(["--name", name])
            .output()
            .unwrap();
        assert!(o.status.success(), "{name:?}: {}", String::from_utf8_lossy(&o.stderr));
        let p = DeviceProfile::read(&out).unwrap_or_else(|e| panic!("{name:?}: {e}"));
        assert_eq!(p.device.name, name);
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(text.lines().take(4).all(|l| l.starts_with("# ")), "{text}");
        let o = bin()
            .args(["predict", "grid:8x8", "--device"])
            .arg(&out)
            .arg("--json")
            .output()
            .unwrap();
        assert!(o.status.success(), "{name:?}: {}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["device_name"], name);
        assert!(v["predicted"]["pass_time_ns"].as_f64().unwrap() > 0.0, "{v}");
    }
}

#[test]
fn predict_refuses_profiles_calibrate_would_not_write() {
    let d = tempfile::tempdir().unwrap();
    let f = fixture("nan-worst.toml");
    let line = std::fs::read_to_string(&f)
        .unwrap()
        .lines()
        .position(|l| l.starts_with("worst_pct"))
        .unwrap()
        + 1;
    let e = refused(d.path(), &["predict", "grid:8x8", "--device", f.to_str().unwrap()]);
    assert!(
        e.contains(&format!("{}:{line}: key `fit.worst_pct`: NaN", f.display())),
        "{e}"
    );
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/devices/llvmpipe.toml");
    let text = std::fs::read_to_string(shipped).unwrap();
    for (from, to, key) in [
        ("shader_cores = 132", "shader_cores = 0", "device.shader_cores"),
        ("rows = 135", "rows = 3", "fit.rows"),
        (
            "[uncertainty]\n",
            "[uncertainty]\nbogus_ns = 1.0\n",
            "uncertainty.bogus_ns",
        ),
        (
            "fragment_ns = 0.5549780826227038",
            "fragment_ns = inf",
            "costs.fragment_ns",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let bad = d.path().join("bad.toml");
        std::fs::write(&bad, text.replacen(from, to, 1)).unwrap();
        let e = refused(d.path(), &["predict", "grid:8x8", "--device", bad.to_str().unwrap()]);
        assert!(
            e.contains("bad.toml:") && e.contains(&format!("key `{key}`")),
            "{to}: {e}"
        );
    }
}

#[test]
fn lod_instances_name_file_line_and_key() {
    let d = tempfile::tempdir().unwrap();
    let f = fixture("negative-benefit.toml");
    let e = refused(d.path(), &["lod-select", f.to_str().unwrap(), "--json"]);
    assert!(
        e.contains(&format!("{}:6: key `objects.0.levels.1.benefit`: ", f.display())) && e.contains("negative"),
        "{e}"
    );
    let f = fixture("huge-benefits.toml");
    let e = refused(d.path(), &["lod-select", f.to_str().unwrap(), "--json"]);
    assert!(
        e.contains(&format!("{}:7: key `objects.1.levels.0.benefit`: ", f.display()))
            && e.contains("benefit 1.2e308 makes the sum")
            && e.contains("infinite"),
        "{e}"
    );
}

#[test]
fn mesh_files_with_billions_of_vertices_or_nan_positions_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let f = fixture("huge-index.idx");
    let dev = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/devices/llvmpipe.toml");
    let e = refused(
        d.path(),
        &["predict", f.to_str().unwrap(), "--device", dev.to_str().unwrap()],
    );
    assert!(e.contains("huge-index.idx") && e.contains("4294967295 vertices"), "{e}");
    let e = refused(
        d.path(),
        &["predict", "random:1:4294967295:1", "--device", dev.to_str().unwrap()],
    );
    assert!(
        e.contains("random:1:4294967295:1") && e.contains("limit of 268435456"),
        "{e}"
    );
    let e = refused(d.path(), &["vcache", f.to_str().unwrap(), "--policy", "fifo:24"]);
    assert!(e.contains("huge-index.idx"), "{e}");
    // An OBJ position that is not a number.
    let f = fixture("nan-position.obj");
    let e = refused(d.path(), &["vcache", f.to_str().unwrap(), "--policy", "fifo:8"]);
    assert!(
        e.contains("nan-position.obj` at line 3") && e.contains("`nan` is not a finite number"),
        "{e}"
    );
}
