//! Experiments over several model files (`[[sweep]] key = "model"`) and the
//! per-device prediction report as a system an experiment runs (issue 10
//! items 3 and 7): each point runs on its own file, errors name the entry,
//! and the `device_predictions` run gives the same leave-one-out errors as
//! the library's calibration.

use std::path::Path;
use std::process::Command;

use rendersim::measure::calibrate::{Invocations, LoadCache, read_rows, row_load};
use rendersim::measure::cross_validation::{error_summary, leave_one_out, linear_baseline_loo};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn fixed_model(gpu_ms: f64) -> String {
    format!(
        "system = \"frame_pipeline\"\n[run]\nframes = 20\nwarmup_frames = 2\n[noise]\nenabled = false\n\
         [display]\nvsync = false\n[workload]\nkind = \"fixed\"\ncpu = \"1ms\"\ngpu = \"{gpu_ms}ms\"\n"
    )
}

/// Writes `files` into a temp folder and runs `rendersim experiment` on
/// `exp.toml` there: (success, stdout, stderr, folder).
fn experiment(files: &[(&str, &str)]) -> (bool, String, String, tempfile::TempDir) {
    let d = tempfile::tempdir().unwrap();
    for (name, text) in files {
        let p = d.path().join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    let o = bin()
        .arg("experiment")
        .arg(d.path().join("exp.toml"))
        .arg("--out")
        .arg(d.path().join("out"))
        .arg("--quiet")
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        d,
    )
}

const SWEEP: &str = r#"name = "two-models"
[set]
"run.frames" = 12
[[sweep]]
key = "model"
values = ["models/a.toml", "models/b.toml"]
labels = ["a", "b"]
[[sweep]]
key = "display.buffers"
values = [2, 3]
[[metric]]
path = "metrics.gpu_time_ms.mean"
[[check]]
path = "metrics.gpu_time_ms.mean"
where = { model = "models/a.toml" }
expect = 3.0
rel_tolerance = 1e-9
[[check]]
path = "metrics.gpu_time_ms.mean"
where = { model = "models/b.toml" }
expect = 7.0
rel_tolerance = 1e-9
"#;

#[test]
fn each_point_runs_on_the_model_file_its_sweep_names() {
    let (a, b) = (fixed_model(3.0), fixed_model(7.0));
    let (ok, out, err, d) = experiment(&[("exp.toml", SWEEP), ("models/a.toml", &a), ("models/b.toml", &b)]);
    assert!(ok, "{out}{err}");
    assert!(out.contains("checks 4 passed 0 failed"), "{out}");
    // `[set]` applies to every model: 12 frames, 2 of them warm-up.
    let points = std::fs::read_to_string(d.path().join("out/points.csv")).unwrap();
    assert!(
        points
            .lines()
            .next()
            .unwrap()
            .starts_with("point,model,display.buffers"),
        "{points}"
    );
    assert_eq!(points.lines().count(), 5, "{points}");
    let runs = std::fs::read_to_string(d.path().join("out/runs.csv")).unwrap();
    assert!(
        runs.contains("models/a.toml") && runs.contains("models/b.toml"),
        "{runs}"
    );
}

#[test]
fn a_bad_model_sweep_is_an_error_naming_the_entry() {
    let a = fixed_model(3.0);
    let cases: [(&str, &str); 4] = [
        (
            "values = [\"models/a.toml\", \"models/b.toml\"]",
            "model file \"models/b.toml\" not found",
        ),
        ("values = [\"models/a.toml\", 3]", "takes model file paths"),
        (
            "values = [\"models/a.toml\"]\n[[search]]\nname = \"s\"\nvary = \"workload.gpu\"\nfrom = 1.0\nto = 2.0\n\
             format = \"{}ms\"\npath = \"metrics.gpu_time_ms.mean\"\ntarget = 1.5",
            "cannot have them",
        ),
        ("values = [\"models/a.toml\"]\n", "leave out the top-level `model`"),
    ];
    for (i, (values, want)) in cases.iter().enumerate() {
        let head = if i == 3 { "model = \"models/a.toml\"\n" } else { "" };
        let exp = format!(
            "name = \"bad\"\n{head}[[metric]]\npath = \"metrics.gpu_time_ms.mean\"\n[[sweep]]\nkey = \"model\"\n{values}\n"
        );
        let (ok, out, err, _d) = experiment(&[("exp.toml", &exp), ("models/a.toml", &a)]);
        assert!(!ok, "case {i} ran: {out}");
        assert!(err.contains(want), "case {i}: {err}");
        assert!(!err.contains("panicked"), "case {i}: {err}");
    }
}

#[test]
fn a_missing_model_file_is_an_error_naming_the_experiment_and_its_line() {
    let exp = "name = \"bad\"\nmodel = \"models/none.toml\"\n[[metric]]\npath = \"metrics.gpu_time_ms.mean\"\n";
    let (ok, out, err, _d) = experiment(&[("exp.toml", exp)]);
    assert!(!ok, "ran: {out}");
    assert!(
        err.contains("exp.toml:2: key `model`: model file \"models/none.toml\" not found"),
        "{err}"
    );
}

#[test]
fn device_predictions_report_the_leave_one_out_errors_of_the_calibration() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let model = root.join("experiments/device-predictions/nvidia-h200.toml");
    let o = bin().arg("run").arg(&model).arg("--json").output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let m = &v["metrics"];
    assert_eq!(m["rows"], 95);
    // The oracle: the library's leave-one-out on the same rows.
    let dir = root.join("docs/measurements/nvidia-h200");
    let mut rows = read_rows(&dir.join("load-grid.csv")).unwrap();
    rows.extend(read_rows(&dir.join("load-sweep.csv")).unwrap());
    let policy = "nvidia".parse().unwrap();
    let mut cache = LoadCache::default();
    let mut load = |inv| -> Vec<_> {
        rows.iter()
            .map(|r| row_load(r, &mut cache, &policy, inv).unwrap())
            .collect()
    };
    let (fit_loads, pred_loads) = (load(Invocations::Measured), load(Invocations::Predicted));
    let y: Vec<f64> = rows.iter().map(|r| r.pass_time_ns).collect();
    let (med, p90, worst) = error_summary(&leave_one_out(&fit_loads, &pred_loads, &y).unwrap());
    let (bm, _, _) = error_summary(&linear_baseline_loo(&pred_loads, &y));
    let got = |k: &str| m["loo_error_pct"][k].as_f64().unwrap();
    assert!(
        (got("median") - med).abs() < 1e-9 && (got("p90") - p90).abs() < 1e-9 && (got("worst") - worst).abs() < 1e-9
    );
    assert!((m["linear_baseline_loo_pct"]["median"].as_f64().unwrap() - bm).abs() < 1e-9);
    // Study H2's ratio: the load grid's four cells measured (0.931), the
    // profile's prediction and that of a fit without H2's mesh (0.935), as
    // tests/it/devices.rs computes them through the library.
    let h2 = &m["sum_vs_max"];
    let f = |k: &str| h2[k].as_f64().unwrap_or(f64::NAN);
    assert!(
        (f("measured_rows") - (40.336128 - 22.84464) / (18.8376 - 0.0552)).abs() < 1e-6,
        "{h2}"
    );
    assert_eq!(f("measured_study"), 0.94, "{h2}");
    assert!(
        (f("predicted") - 0.931).abs() < 0.002 && (f("predicted_without_mesh") - 0.935).abs() < 0.002,
        "{h2}"
    );
    // Measuring: 7 passes per row.
    let measuring: f64 = y.iter().map(|t| 7.0 * t * 1e-9).sum();
    assert!((m["measuring_seconds"].as_f64().unwrap() - measuring).abs() < 1e-9 * measuring);
    // The human report is the markdown table, one line per row.
    let o = bin().arg("run").arg(&model).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.starts_with("# Predicted against measured: nvidia-h200"), "{text}");
    assert_eq!(
        text.lines()
            .filter(|l| l.starts_with("| grid") || l.starts_with("| random") || l.starts_with("| strip"))
            .count(),
        95
    );
}

#[test]
fn a_bad_device_predictions_model_is_an_error_naming_the_key() {
    let d = tempfile::tempdir().unwrap();
    let write = |text: &str| {
        let p = d.path().join("device.toml");
        std::fs::write(&p, text).unwrap();
        p
    };
    let head = "system = \"device_predictions\"\ndevice = \"x\"\n";
    for (body, want) in [
        ("files = [\"missing.csv\"]\nvertex_cache = \"nvidia\"\n", "files[0]"),
        ("files = []\nvertex_cache = \"nvidia\"\n", "files"),
        ("files = [\"missing.csv\"]\nvertex_cache = \"bogus\"\n", "vertex_cache"),
        (
            "files = [\"missing.csv\"]\nvertex_cache = \"nvidia\"\ncolour = 1\n",
            "colour",
        ),
    ] {
        let p = write(&format!("{head}{body}"));
        let o = bin().arg("run").arg(&p).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{body}");
        assert!(err.contains(want) && !err.contains("panicked"), "{body}: {err}");
    }
    // `[sum_vs_max]` (study H2's cells) on real rows: each bad value named.
    let grid = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/measurements/nvidia-h200/load-grid.csv");
    let files = format!(
        "files = [{:?}]\nvertex_cache = \"nvidia\"\n",
        grid.display().to_string()
    );
    let cells = "mesh = \"grid:96x96:optimized\"\nsize = \"384x384\"\nvs_loops = 67390\nfs_loops = 7681\n";
    for (table, want) in [
        (cells.replace("384x384", "384"), "sum_vs_max.size"),
        (cells.replace("67390", "0"), "`sum_vs_max`: vs_loops = 0"),
        (cells.replace("grid:96x96:optimized", "grid:oops"), "grid:oops"),
        (format!("{cells}measured = nan\n"), "sum_vs_max.measured"),
        (format!("{cells}colour = 1\n"), "colour"),
    ] {
        let body = format!("{files}[sum_vs_max]\n{table}");
        let p = write(&format!("{head}{body}"));
        let o = bin().arg("run").arg(&p).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{body}");
        assert!(err.contains(want) && !err.contains("panicked"), "{body}: {err}");
    }
}
