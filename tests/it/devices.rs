//! Device profiles (issue 10 item 3): `calibrate` recovers known costs from
//! synthetic passes, beats the plain linear fit on the shared H200 rows when
//! each row is held out, and `predict` prints what it promises; bad inputs
//! give clear errors, never a panic.

use std::path::{Path, PathBuf};
use std::process::Command;

use rendersim::measure::calibrate::{Invocations, LoadCache, PassRow, fit, read_rows, row_load};
use rendersim::measure::cross_validation::{
    error_summary, held_out_half, k_fold_by_mesh, leave_one_out, linear_baseline_loo, mesh_folds,
};
use rendersim::measure::device_profile::{DeviceCosts, DeviceProfile};

fn h200(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/measurements/nvidia-h200")
        .join(file)
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn truth() -> DeviceCosts {
    DeviceCosts {
        pass_overhead_ns: 5_000.0,
        draw_ns: 300.0,
        clear_store_per_pixel_ns: 0.15,
        vertex_ns: 2.0,
        triangle_ns: 0.5,
        covered_triangle_ns: 1.5,
        vertex_loop_latency_ns: 15.0,
        vertex_lane_per_loop_ns: 0.013,
        fragment_ns: 0.05,
        helper_lane_ns: 0.09,
        empty_lane_ns: 0.01,
        fragment_per_loop_ns: 0.0035,
        helper_lane_per_loop_ns: 0.002,
        empty_lane_per_loop_ns: 0.001,
        fragment_loop_latency_ns: 40.0,
        shared_core_overlap: 0.0,
    }
}

/// The meshes of [`synthetic_passes`].
const SYNTHETIC_MESHES: [&str; 4] = ["grid:16x16", "grid:48x48", "grid:32x32:shuffled:3", "strip:24x24"];

/// Passes of four meshes at three sizes under six loads, then each mesh at
/// 64x64 in 0, 4 and 16 draws, timed by `t`; with each row's mesh.
type Synthetic = (
    Vec<rendersim::measure::device_profile::PassLoad>,
    Vec<f64>,
    Vec<&'static str>,
);
fn synthetic_passes(t: &DeviceCosts) -> Synthetic {
    let mut cache = LoadCache::default();
    let policy = "meshopt:32,32,32".parse().unwrap();
    let (mut loads, mut y, mut meshes) = (Vec::new(), Vec::new(), Vec::new());
    let one_draw = [
        (0, 0, false),
        (2000, 0, false),
        (0, 300, false),
        (500, 100, false),
        (0, 0, true),
        (20000, 0, true),
    ];
    let passes = SYNTHETIC_MESHES
        .into_iter()
        .flat_map(|m| [64, 256, 1024].into_iter().map(move |s| (m, s)))
        .flat_map(|(m, s)| one_draw.into_iter().map(move |(v, f, g)| (m, s, v, f, g, 1)))
        .chain(
            SYNTHETIC_MESHES
                .into_iter()
                .flat_map(|m| [0, 4, 16].into_iter().map(move |d| (m, 64, 0, 0, false, d))),
        );
    for (mesh, size, vs, fs, geo, draws) in passes {
        let row = PassRow {
            mesh: mesh.into(),
            size: (size, size).into(),
            vs_loops: vs,
            fs_loops: fs,
            geometry_only: geo,
            vs_invocations: 0,
            fs_invocations: 0,
            pass_time_ns: 1.0,
            draws,
        };
        let l = row_load(&row, &mut cache, &policy, Invocations::Predicted).unwrap();
        y.push(t.cost(&l).pass_ns);
        loads.push(l);
        meshes.push(mesh);
    }
    (loads, y, meshes)
}

#[test]
fn calibrate_recovers_the_shared_core_overlap() {
    // Vertex loop and fragment work overlapping by 12% of Gl R / (Gl + R),
    // about the H200's fitted value: the fit finds it and every cost.
    let t = DeviceCosts {
        shared_core_overlap: 0.12,
        ..truth()
    };
    let (loads, y, _) = synthetic_passes(&t);
    let f = fit(&loads, &y).unwrap();
    for ((k, got), (_, want)) in f.costs.entries().iter().zip(t.entries()) {
        assert!((got - want).abs() <= 0.01 * want, "{k}: fitted {got}, true {want}");
    }
    assert!(f.objective < 1e-10, "{}", f.objective);
}

#[test]
fn calibrate_recovers_known_costs_from_synthetic_passes() {
    let t = truth();
    let (loads, y, meshes) = synthetic_passes(&t);
    // With whole meshes held out, each fold is predicted exactly too.
    let k = k_fold_by_mesh(&loads, &loads, &y, &meshes, 4).unwrap();
    assert_eq!((k.folds, k.meshes, k.errors.len()), (4, 4, y.len()));
    assert!(k.errors.iter().all(|e| e.abs() < 1.0), "{:?}", k.errors);
    // Fitted on half the passes, the other half is predicted exactly too.
    let half = held_out_half(&loads, &loads, &y).unwrap();
    assert!(
        half.len() >= y.len() / 4 && half.len() <= 3 * y.len() / 4,
        "{}",
        half.len()
    );
    assert!(half.iter().all(|e| e.abs() < 1.0), "{half:?}");
    let f = fit(&loads, &y).unwrap();
    for ((k, got), (_, want)) in f.costs.entries().iter().zip(t.entries()) {
        assert!(
            (got - want).abs() <= 0.01 * want + 1e-6,
            "{k}: fitted {got}, true {want}"
        );
    }
    assert!(f.objective < 1e-12, "{}", f.objective);
    assert!(
        f.std_errors.iter().all(|(_, s)| s.is_finite() && *s < 1e-3),
        "{:?}",
        f.std_errors
    );
}

#[test]
fn h200_leave_one_out_meets_the_goal_and_beats_the_linear_baseline() {
    let mut rows = read_rows(&h200("load-grid.csv")).unwrap();
    rows.extend(read_rows(&h200("load-sweep.csv")).unwrap());
    assert_eq!(rows.len(), 95);
    let mut cache = LoadCache::default();
    let policy = "nvidia".parse().unwrap();
    let fit_loads: Vec<_> = rows
        .iter()
        .map(|r| row_load(r, &mut cache, &policy, Invocations::Measured).unwrap())
        .collect();
    let pred_loads: Vec<_> = rows
        .iter()
        .map(|r| row_load(r, &mut cache, &policy, Invocations::Predicted).unwrap())
        .collect();
    let y: Vec<f64> = rows.iter().map(|r| r.pass_time_ns).collect();
    let (m, p90, _) = error_summary(&leave_one_out(&fit_loads, &pred_loads, &y).unwrap());
    let (bm, bp90, _) = error_summary(&linear_baseline_loo(&pred_loads, &y));
    eprintln!("H200 leave-one-out: profile median {m:.1}% p90 {p90:.1}%; linear median {bm:.1}% p90 {bp90:.1}%");
    assert!(m.is_finite() && p90.is_finite());
    assert!(m < bm && p90 < bp90, "profile {m}/{p90} vs linear {bm}/{bp90}");
    // Issue 10's accuracy goal was a median of at most 5% and a 90th
    // percentile of at most 15%, each row predicted without itself. The
    // linear formula met it (4.71% / 13.02%); with the shared-core overlap
    // (issue 30) the median is 5.32% and the 90th percentile 13.14%, while
    // whole meshes held out predict a little better (6-fold: 6.4% / 30.4% /
    // 85.4% against 6.4% / 30.5% / 85.7%). The 90th percentile still meets
    // the goal; the median misses it by 0.3 points, as
    // docs/measurements/README.md says. Both are held here so that a change
    // that loses more fails.
    assert!(m <= 5.4 && p90 <= 15.0, "leave-one-out median {m:.2}% p90 {p90:.2}%");
    // Fitted on every other row, the rest predicted: also below the
    // linear baseline's leave-one-out errors.
    let (hm, hp90, _) = error_summary(&held_out_half(&fit_loads, &pred_loads, &y).unwrap());
    eprintln!("H200 held-out half: median {hm:.1}% p90 {hp90:.1}%");
    // Whole meshes held out (what a new user's pass is): every row gets a
    // prediction, and the meshes' folds are disjoint.
    let meshes: Vec<&str> = rows.iter().map(|r| r.mesh.as_str()).collect();
    let k = k_fold_by_mesh(&fit_loads, &pred_loads, &y, &meshes, 6).unwrap();
    let (km, kp90, kw) = error_summary(&k.errors);
    eprintln!("H200 6-fold by mesh: median {km:.1}% p90 {kp90:.1}% worst {kw:.1}%");
    assert!(k.errors.iter().all(|e| e.is_finite()));
    let (_, fold) = mesh_folds(&meshes, 6);
    for (i, a) in meshes.iter().enumerate() {
        for (j, b) in meshes.iter().enumerate() {
            assert_eq!(a == b, a == b && fold[i] == fold[j], "{a} {b}");
        }
    }
    assert!(
        hm < bm && hp90 < bp90,
        "held-out half {hm}/{hp90} vs linear {bm}/{bp90}"
    );
}

#[test]
fn calibrate_and_predict_through_the_command_line() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("devices/h200.toml");
    let report = d.path().join("h200-predictions.md");
    let o = bin()
        .args([
            "calibrate",
            h200("load-grid.csv").to_str().unwrap(),
            h200("load-sweep.csv").to_str().unwrap(),
            "--kfold",
            "5",
            "--out",
        ])
        .arg(&out)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        stdout.contains("k-fold by mesh (5 folds over 6 meshes, each fold's meshes held out whole) |error|: median"),
        "{stdout}"
    );
    assert!(
        stdout.contains("lane_per_loop_ns") && stdout.contains("median"),
        "{stdout}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("# Device profile h200") && text.contains("Rows: 95"),
        "{text}"
    );
    let profile = DeviceProfile::read(&out).unwrap();
    assert_eq!(profile.fit.rows, 95);
    // Every H200 pass is one draw: the draw's cost cannot be told from the
    // pass's, so the pass overhead holds both.
    assert!(
        profile.costs.draw_ns == 0.0 && profile.costs.pass_overhead_ns > 1000.0,
        "{:?}",
        profile.costs
    );
    assert!(text.contains("# K-fold by mesh (5 folds over 6 meshes"), "{text}");
    let (km, kp) = (
        profile.fit.kfold_median_pct.unwrap(),
        profile.fit.kfold_p90_pct.unwrap(),
    );
    assert!(km.is_finite() && kp >= km, "{km} {kp}");
    // The report: one table row per pass (simulated by `predict`'s model),
    // then the summary with measuring against simulating time.
    let md = std::fs::read_to_string(&report).unwrap();
    assert_eq!(
        md.lines()
            .filter(|l| l.starts_with("| grid") || l.starts_with("| random") || l.starts_with("| strip"))
            .count(),
        95,
        "{md}"
    );
    assert!(
        md.contains("95 rows. Leave-one-out |error|: median") && md.contains("simulating took"),
        "{md}"
    );

    let o = bin()
        .args(["predict", "grid:32x32", "--device"])
        .arg(&out)
        .args(["--size", "128x128", "--fs-loops", "300", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for k in ["pass_time_ns", "vs_invocations", "fs_invocations", "sim_wall_seconds"] {
        assert!(v["predicted"][k].is_number(), "{k} in {v}");
    }
    assert_eq!(v["predicted"]["fs_invocations"], 16384);
    assert!(v["wall_seconds"].is_number());
    let t = v["predicted"]["pass_time_ns"].as_f64().unwrap();
    // Measured 108,032 ns on the H200.
    assert!(t > 50_000.0 && t < 200_000.0, "{t}");

    let err = |args: &[&str]| {
        let o = bin().args(args).output().unwrap();
        assert!(!o.status.success(), "{args:?} succeeded");
        let e = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(!e.contains("panicked"), "{e}");
        e
    };
    let dev = out.to_str().unwrap();
    assert!(err(&["predict", "grid:oops", "--device", dev]).contains("grid:oops"));
    assert!(err(&["predict", "grid:8x8", "--device", dev, "--size", "12"]).contains("--size"));
    assert!(err(&["predict", "grid:8x8", "--device", "/nonexistent/x.toml"]).contains("/nonexistent/x.toml"));
    let bad = d.path().join("bad.toml");
    let mut seen = false;
    let negative: String = text
        .lines()
        .map(|l| {
            if l.starts_with("fragment_ns = ") && !seen {
                seen = true;
                "fragment_ns = -1.0\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    std::fs::write(&bad, negative).unwrap();
    let e = err(&["predict", "grid:8x8", "--device", bad.to_str().unwrap()]);
    assert!(e.contains("bad.toml") && e.contains("costs.fragment_ns"), "{e}");
    std::fs::write(&bad, text.replace("vertex_ns", "vertex_nanos")).unwrap();
    let e = err(&["predict", "grid:8x8", "--device", bad.to_str().unwrap()]);
    assert!(e.contains("bad.toml") && e.contains("vertex_nanos"), "{e}");
    let csv = d.path().join("rows.csv");
    std::fs::write(&csv, "mesh,size\n").unwrap();
    let e = err(&[
        "calibrate",
        csv.to_str().unwrap(),
        "--out",
        d.path().join("x.toml").to_str().unwrap(),
    ]);
    assert!(e.contains("rows.csv: line 1") && e.contains("header"), "{e}");
}

#[test]
fn the_held_out_half_fails_the_command_past_either_bound_and_keeps_the_profile() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("p.toml");
    let run = |bounds: &[&str]| {
        bin()
            .arg("calibrate")
            .arg(h200("load-grid.csv"))
            .arg(h200("load-sweep.csv"))
            .args(["--holdout", "--out"])
            .arg(&out)
            .args(bounds)
            .output()
            .unwrap()
    };
    // Generous bounds pass.
    let o = run(&["--holdout-max-median", "1000", "--holdout-max-p90", "1000"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_file(&out).unwrap();
    // A p90 bound of 0.001% fails alone, naming only itself.
    let o = run(&["--holdout-max-median", "1000", "--holdout-max-p90", "0.001"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("held-out half: 90th percentile |error|") && err.contains("exceeds --holdout-max-p90 0.001%"),
        "{err}"
    );
    assert!(!err.contains("--holdout-max-median"), "{err}");
    assert!(out.exists(), "the profile is still written");
    // Both bounds exceeded: both named.
    let o = run(&["--holdout-max-median", "0.001", "--holdout-max-p90", "0.001"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("median |error|") && err.contains("exceeds --holdout-max-median 0.001%; 90th percentile"),
        "{err}"
    );
    // A bound that is not a finite percentage is refused before fitting:
    // NaN or infinity would pass whatever the errors.
    for (flag, bad) in [
        ("--holdout-max-p90", "nan"),
        ("--holdout-max-median", "inf"),
        ("--holdout-max-p90", "-5"),
    ] {
        let arg = format!("{flag}={bad}");
        let o = run(&[arg.as_str()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {bad}: {err}");
        assert!(
            err.contains(flag) && err.contains("a finite number at least 0"),
            "{err}"
        );
    }
    // The bounds need --holdout.
    let o = bin()
        .arg("calibrate")
        .arg(h200("load-grid.csv"))
        .args(["--holdout-max-p90", "30", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--holdout"));
}

#[test]
fn k_fold_by_mesh_needs_two_meshes_and_a_sensible_k() {
    let d = tempfile::tempdir().unwrap();
    let one_mesh = d.path().join("one.csv");
    let grid = std::fs::read_to_string(h200("load-grid.csv")).unwrap();
    let mut text = String::new();
    for (i, line) in grid.lines().enumerate() {
        if i == 0 || line.starts_with("grid:96x96:optimized,") {
            text.push_str(line);
            text.push('\n');
        }
    }
    std::fs::write(&one_mesh, text).unwrap();
    // `calibrate CSV --kfold K` refused: exit 2, its error line returned.
    let refused = |csv: &Path, k: &str| {
        let o = bin()
            .arg("calibrate")
            .arg(csv)
            .args(["--kfold", k, "--out"])
            .arg(d.path().join("p.toml"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(o.status.code(), Some(2), "{err}");
        err
    };
    let err = refused(&one_mesh, "3");
    assert!(err.contains("at least 2 distinct meshes; these have 1"), "{err}");
    // One mesh holds most of load-grid.csv's rows: without it too few are left.
    let err = refused(&h200("load-grid.csv"), "3");
    assert!(
        err.contains("holding out fold 3 (grid:96x96:optimized) leaves 4 rows to fit"),
        "{err}"
    );
    let err = refused(&h200("load-grid.csv"), "1");
    assert!(err.contains("--kfold"), "{err}");
}

#[test]
fn the_h200_profile_predicts_study_h2() {
    // Study H2 on the H200 (docs/measurements/nvidia-h200/studies.json):
    // grid:96x96:optimized at 384x384, vertex loops 0 / 67390, fragment
    // loops 0 / 7681. The ratio is the extra vertex cost with the heavy
    // fragment shader over the extra with the light one: the H200 measured
    // (40.312 - 22.859) / (18.627 - 0.056) = 0.940 (the same cells in
    // load-grid.csv give 0.931). A pure sum of vertex and fragment terms
    // gives 1.000; the shared-core overlap makes it less.
    // docs/measurements/README.md reports the numbers, and this test keeps
    // them true.
    let profile =
        DeviceProfile::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/devices/nvidia-h200.toml")).unwrap();
    let cell = |vs_loops, fs_loops| {
        let pass = rendersim::measure::device_predict::DevicePass {
            mesh: "grid:96x96:optimized".into(),
            size: (384, 384),
            vs_loops,
            fs_loops,
            geometry_only: false,
            layers: 1,
            order: rendersim::measure::DepthOrder::FrontToBack,
            depth_test: false,
            draws: 1,
        };
        rendersim::measure::device_predict::predict_on_device(&profile, &pass)
            .unwrap()
            .pass_time_ns
    };
    let (ss, sc, cs, cc) = (cell(0, 0), cell(0, 7681), cell(67390, 0), cell(67390, 7681));
    let predicted = (cc - sc) / (cs - ss);
    let measured: f64 = (40.312128 - 22.8592) / (18.627424 - 0.055552);
    eprintln!("H2 on the H200: measured ratio {measured:.3}, the shipped profile predicts {predicted:.3}");
    assert!((measured - 0.940).abs() < 0.001);
    assert!((predicted - 0.931).abs() < 0.002, "{predicted}");

    // The shipped profile was fitted to these very cells (load-grid.csv).
    // Fitted to every row but those of grid:96x96:optimized, the mesh H2
    // draws, the profile predicts the ratio of a mesh it has not seen.
    let mut rows = read_rows(&h200("load-grid.csv")).unwrap();
    rows.extend(read_rows(&h200("load-sweep.csv")).unwrap());
    rows.retain(|r| r.mesh != "grid:96x96:optimized");
    let mut cache = LoadCache::default();
    let policy = "nvidia".parse().unwrap();
    let loads: Vec<_> = rows
        .iter()
        .map(|r| row_load(r, &mut cache, &policy, Invocations::Measured).unwrap())
        .collect();
    let y: Vec<f64> = rows.iter().map(|r| r.pass_time_ns).collect();
    let f = fit(&loads, &y).unwrap();
    let mut cell = |vs_loops, fs_loops| {
        let row = PassRow {
            mesh: "grid:96x96:optimized".into(),
            size: (384, 384).into(),
            vs_loops,
            fs_loops,
            geometry_only: false,
            vs_invocations: 0,
            fs_invocations: 0,
            pass_time_ns: 1.0,
            draws: 1,
        };
        let l = row_load(&row, &mut cache, &policy, Invocations::Predicted).unwrap();
        f.costs.cost(&l).pass_ns
    };
    let (ss, sc, cs, cc) = (cell(0, 0), cell(0, 7681), cell(67390, 0), cell(67390, 7681));
    let held_out = (cc - sc) / (cs - ss);
    eprintln!(
        "H2 predicted by a fit without its mesh: {held_out:.3} (overlap {:.3})",
        f.costs.shared_core_overlap
    );
    assert!((held_out - 0.935).abs() < 0.002, "{held_out}");
    assert!(f.costs.shared_core_overlap > 0.05, "{:?}", f.costs);
}

#[test]
fn calibrate_refuses_repeated_passes_and_names_the_costs_its_passes_cannot_determine() {
    // Issue 60 item 7: twenty copies of one pass (plus one other) passed the
    // 12-row minimum and gave a profile predicting 0 ms, without a word.
    let d = tempfile::tempdir().unwrap();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/measurements/llvmpipe-mesa-22.3.6-profile-passes.csv");
    let text = std::fs::read_to_string(&src).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let rows: Vec<&str> = lines.collect();
    let copies = d.path().join("copies.csv");
    let mut t = format!("{header}\n{}\n", rows[1]);
    for _ in 0..20 {
        t += &format!("{}\n", rows[0]);
    }
    std::fs::write(&copies, t).unwrap();
    let out = d.path().join("p.toml");
    let o = bin()
        .args(["calibrate", copies.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("21 rows hold 2 distinct pass(es)") && e.contains("at least 12"),
        "{e}"
    );
    assert!(!out.exists());
    // Passes without shader loops cannot tell the loop costs: calibrated,
    // with a warning and a line in the profile naming them.
    let header_cols: Vec<&str> = header.split(',').collect();
    let col = |name: &str| header_cols.iter().position(|c| *c == name).unwrap();
    let (vs, fs) = (col("vs_loops"), col("fs_loops"));
    let plain: Vec<&str> = rows
        .iter()
        .filter(|r| {
            let f: Vec<&str> = r.split(',').collect();
            f[vs] == "0" && f[fs] == "0"
        })
        .copied()
        .collect();
    assert!(plain.len() >= 12, "{}", plain.len());
    let no_loops = d.path().join("no-loops.csv");
    std::fs::write(&no_loops, format!("{header}\n{}\n", plain.join("\n"))).unwrap();
    let o = bin()
        .args(["calibrate", no_loops.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("warning: these passes do not determine") && e.contains("fragment_per_loop_ns"),
        "{e}"
    );
    let profile = std::fs::read_to_string(&out).unwrap();
    assert!(profile.contains("# Not determined:") && profile.contains("vertex_lane_per_loop_ns"));
    assert!(!profile.contains("Not determined: these passes do not determine pass_overhead_ns"));
}
