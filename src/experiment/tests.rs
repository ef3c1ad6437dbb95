//! Tests of the experiment runner against a fake simulator.

use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use serde_json::json;

use super::*;

/// A fake simulator: metrics are simple functions of the patched keys plus
/// a little seed noise; fails for `workload.gpu = "13ms"` with seed 2 when
/// `fail` is set.
#[derive(Default)]
struct Fake {
    fail: bool,
    calls: AtomicUsize,
    wanted_frames: AtomicBool,
    seen: Mutex<Vec<(String, u64)>>,
}

fn get<'a>(t: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    let mut parts = key.split('.');
    let mut v = t.get(parts.next()?)?;
    for p in parts {
        v = v.as_table()?.get(p)?;
    }
    Some(v)
}

impl Runner for Fake {
    fn run(&self, model: &toml::Table, seed: u64, want_frames: bool) -> Result<RunOutput, RunError> {
        self.calls.fetch_add(1, Ordering::SeqCst);
        if want_frames {
            self.wanted_frames.store(true, Ordering::SeqCst);
        }
        let gpu = get(model, "workload.gpu").and_then(numeric_coord).unwrap_or(10.0);
        let buffers = get(model, "display.buffers").and_then(|v| v.as_integer()).unwrap_or(2) as f64;
        let fidelity = get(model, "fidelity")
            .and_then(|v| v.as_str())
            .unwrap_or("triangle")
            .to_string();
        let kind = get(model, "workload.kind")
            .and_then(|v| v.as_str())
            .unwrap_or("random")
            .to_string();
        self.seen.lock().unwrap().push((kind.clone(), seed));
        if self.fail && gpu == 13.0 && seed == 2 {
            return Err(RunError::Other("GPU fell over".into()));
        }
        let refresh = 1000.0 / 60.0;
        let interval = (gpu / refresh).ceil() * refresh * if buffers >= 3.0 { 0.9 } else { 1.0 };
        let (bias, wall) = match fidelity.as_str() {
            "triangle" => (0.0, 2.0),
            "tile" => (0.1, 0.5),
            _ => (1.0, 0.1),
        };
        let noise = (seed as f64 - 2.0) * 0.01;
        let summary = json!({
            "system": "fake", "seed": seed, "frames": 100,
            "events": {"total": 1000 + seed},
            "wall_seconds": wall,
            "metrics": {
                "display_interval_ms": {"mean": interval + noise},
                "frame_time_ms": {"mean": gpu + bias + noise, "p99": null},
                "fixed_kind": if kind == "fixed" { 1 } else { 0 },
            }
        });
        let frames = want_frames.then(|| FrameTable {
            columns: vec!["Index".into(), "FrameTime".into()],
            rows: (0..100).map(|i| vec![i as f64, gpu + (i % 10) as f64]).collect(),
        });
        Ok(RunOutput { summary, frames })
    }
}

const BASIC: &str = r#"
name = "vsync-quantization"
description = "Display interval against GPU time."
replications = 3
base_seed = 1
confidence = 0.95
[set]
"workload.kind" = "fixed"
[[sweep]]
key = "workload.gpu"
range = { from = 10, to = 16, steps = 4, format = "{}ms" }
[[sweep]]
key = "display.buffers"
values = [2, 3]
[[metric]]
path = "metrics.display_interval_ms.mean"
label = "display interval (ms)"
[[metric]]
path = "metrics.fixed_kind"
[[plot]]
file = "interval"
kind = "line"
x = "workload.gpu"
y = ["metrics.display_interval_ms.mean"]
title = "Display interval"
[[check]]
path = "metrics.display_interval_ms.mean"
where = { "workload.gpu" = "16ms", "display.buffers" = 2 }
expect = 16.667
tolerance = 0.05
[[check]]
path = "metrics.display_interval_ms.mean"
where = { "workload.gpu" = "12ms", "display.buffers" = 3 }
expect = 16.667
rel_tolerance = 0.01
"#;

fn parse(text: &str) -> Experiment {
    parse_experiment(text, Path::new("experiments/test.toml")).unwrap()
}

fn parse_err(text: &str) -> String {
    parse_experiment(text, Path::new("experiments/bad.toml"))
        .unwrap_err()
        .to_string()
}

fn base_model() -> toml::Table {
    "[display]\nbuffers = 2\n[workload]\ngpu = \"10ms\"\n".parse().unwrap()
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap()
}

#[test]
fn expansion_order_and_counts() {
    let exp = parse(BASIC);
    let pts = expand_points(&exp);
    assert_eq!(pts.len(), 8);
    let labels: Vec<String> = pts.iter().map(|p| p.label()).collect();
    assert_eq!(labels[0], "workload.gpu=10ms, display.buffers=2");
    assert_eq!(labels[1], "workload.gpu=10ms, display.buffers=3");
    assert_eq!(labels[2], "workload.gpu=12ms, display.buffers=2");
    assert_eq!(labels[7], "workload.gpu=16ms, display.buffers=3");
    assert!(pts.iter().enumerate().all(|(i, p)| p.index == i));
    assert_eq!(exp.seeds(), vec![1, 2, 3]);
    // No sweeps: one point.
    let single = parse("name = \"x\"\n");
    let pts = expand_points(&single);
    assert_eq!(pts.len(), 1);
    assert_eq!(pts[0].label(), "(single point)");
}

#[test]
fn range_formatting() {
    let exp = parse(BASIC);
    let vals: Vec<String> = exp.sweeps[0].values.iter().map(value_text).collect();
    assert_eq!(vals, ["10ms", "12ms", "14ms", "16ms"]);
    assert!(exp.sweeps[0].values[0].is_str());
    assert_eq!(exp.sweeps[0].coords, [10.0, 12.0, 14.0, 16.0]);

    let exp = parse(
        "name = \"r\"\n[[sweep]]\nkey = \"a\"\nrange = { from = 0.0, to = 1.0, steps = 3 }\n\
         [[sweep]]\nkey = \"b\"\nrange = { from = 1, to = 4, steps = 4 }\n\
         [[sweep]]\nkey = \"c\"\nrange = { from = 0.1, to = 0.3, steps = 3, format = \"x{}us\" }\n\
         [[sweep]]\nkey = \"d\"\nrange = { from = 5, to = 9, steps = 1 }\n",
    );
    assert_eq!(exp.sweeps[0].values, [0.0, 0.5, 1.0].map(toml::Value::Float));
    assert_eq!(exp.sweeps[1].values, [1, 2, 3, 4].map(toml::Value::Integer));
    let c: Vec<String> = exp.sweeps[2].values.iter().map(value_text).collect();
    assert_eq!(c, ["x0.1us", "x0.2us", "x0.3us"]);
    assert_eq!(exp.sweeps[3].values, [toml::Value::Integer(5)]);
    // Coordinates of plain values: numbers and leading numbers of strings.
    let exp = parse("name = \"v\"\n[[sweep]]\nkey = \"a\"\nvalues = [\"17ms\", \"fast\", 3]\n");
    assert_eq!(exp.sweeps[0].coords, [17.0, 1.0, 3.0]);
}

#[test]
fn bad_experiment_files() {
    let e = parse_err("name = \"x\"\nreplicatons = 3\n");
    assert!(e.contains("experiments/bad.toml") && e.contains("replicatons"), "{e}");
    // The loader of model files reads experiments too: file, line, key and
    // the closest valid key, in a model error's form.
    assert!(
        e.starts_with("experiments/bad.toml:2: key `replicatons`: unknown field")
            && e.ends_with("(did you mean `replications`?)"),
        "{e}"
    );
    let e = parse_err("name = \"x\"\n\n[[sweep]]\nkey = \"a\"\nvalues = [1]\n\n[[sweep]]\nkey = \"b\"\nvaluse = [2]\n");
    assert!(
        e.starts_with("experiments/bad.toml:9: key `sweep[1].valuse`: unknown field")
            && e.contains("did you mean `values`"),
        "{e}"
    );
    let e = parse_err("name = \"x\"\nreplications = \"three\"\n");
    assert!(
        e.starts_with("experiments/bad.toml:2: key `replications`: invalid type"),
        "{e}"
    );
    let e = parse_err("name = \"x\"\nreplications = [\n");
    assert!(
        e.starts_with("experiments/bad.toml: malformed TOML: ") && e.contains("line 2"),
        "{e}"
    );

    let e = parse_err("name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1]\nrange = { from = 1, to = 2, steps = 2 }\n");
    assert!(e.contains("sweep[0]") && e.contains("not both"), "{e}");

    let e = parse_err("name = \"x\"\n[[sweep]]\nkey = \"a\"\n");
    assert!(e.contains("sweep[0]") && e.contains("needs `values` or `range`"), "{e}");

    let e =
        parse_err("name = \"x\"\n[[sweep]]\nkey = \"a\"\nrange = { from = 1, to = 2, steps = 2, format = \"ms\" }\n");
    assert!(e.contains("sweep[0].range") && e.contains("{}"), "{e}");

    let e = parse_err("name = \"x\"\n[[plot]]\nfile = \"p\"\nkind = \"line\"\nx = \"nope\"\ny = \"m\"\n");
    assert!(e.contains("plot[0] (p).x") && e.contains("not a sweep key"), "{e}");

    let e = parse_err("name = \"x\"\n[[plot]]\nfile = \"p\"\nkind = \"pie\"\n");
    assert!(e.contains("unknown kind `pie`"), "{e}");

    let e = parse_err("name = \"x\"\n[[plot]]\nfile = \"../p\"\nkind = \"scatter\"\nx = \"a\"\ny = \"b\"\n");
    assert!(e.contains("plain file name"), "{e}");

    let e = parse_err(
        "name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = [1, 2]\n\
         [[check]]\npath = \"m\"\nwhere = { a = 5 }\nexpect = 1.0\ntolerance = 0.1\n",
    );
    assert!(
        e.contains("check[0] (m).where") && e.contains("not one of the swept values"),
        "{e}"
    );

    let e = parse_err("name = \"x\"\n[[check]]\npath = \"m\"\nexpect = 1.0\n");
    assert!(e.contains("exactly one of `tolerance` and `rel_tolerance`"), "{e}");

    let e = parse_err("name = \"x\"\n[[check]]\npath = \"m\"\nexpect = 1.0\nat_most_path = \"s\"\ntolerance = 0.1\n");
    assert!(e.contains("not both"), "{e}");
    let e = parse_err("name = \"x\"\n[[check]]\npath = \"m\"\ntolerance = 0.1\n");
    assert!(e.contains("needs `expect` or `at_least_path`/`at_most_path`"), "{e}");
    let e = parse_err("name = \"x\"\n[[check]]\npath = \"m\"\nat_least_path = \" \"\ntolerance = 0.1\n");
    assert!(e.contains("check[0] (m).at_least_path"), "{e}");

    let e = parse_err("name = \"x\"\nconfidence = 1.5\n");
    assert!(e.contains("`confidence`"), "{e}");

    let e = parse_err("name = \"x\"\n[[derived]]\nname = \"d\"\nkind = \"interval_width\"\ncolumn = \"FrameTime\"\n");
    assert!(e.contains("needs `level`"), "{e}");
    // The histogram's shape: a bin width is required, finite and positive;
    // the prominence is a share in (0, 1] and only for modes.
    let derived = |rest: &str| {
        parse_err(&format!(
            "name = \"x\"\n[[derived]]\nname = \"d\"\ncolumn = \"FrameTime\"\n{rest}"
        ))
    };
    let e = derived("kind = \"modes\"\n");
    assert!(
        e.contains("derived[0] (d)") && e.contains("kind `modes` needs `bin`"),
        "{e}"
    );
    for bad in ["0.0", "-0.08", "nan", "inf"] {
        let e = derived(&format!("kind = \"largest_bin_share\"\nbin = {bad}\n"));
        assert!(
            e.contains("derived[0] (d).bin") && e.contains("must be finite and > 0"),
            "{bad}: {e}"
        );
    }
    for bad in ["0.0", "1.5", "nan"] {
        let e = derived(&format!("kind = \"modes\"\nbin = 0.08\nprominence = {bad}\n"));
        assert!(
            e.contains("derived[0] (d).prominence") && e.contains("must be in (0, 1]"),
            "{bad}: {e}"
        );
    }
    let e = derived("kind = \"largest_bin_share\"\nbin = 0.08\nprominence = 0.2\n");
    assert!(
        e.contains("derived[0] (d).prominence") && e.contains("only to kind `modes`"),
        "{e}"
    );
    let e = parse_err("name = \"x\"\n[[derived]]\nname = \"d\"\nkind = \"modes\"\nbin = 0.08\n");
    assert!(e.contains("kind `modes` needs `column`"), "{e}");

    let e = parse_err("name = \"x\"\n[[sweep]]\nkey = \"a\"\nvalues = \"oops\"\n");
    assert!(e.contains("experiments/bad.toml") && e.contains("values"), "{e}");

    let missing = Path::new("/nonexistent/dir/exp.toml");
    let e = load_experiment(missing).unwrap_err();
    assert!(matches!(e, ExperimentError::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/dir/exp.toml"), "{e}");
}

#[test]
fn load_from_file_resolves_model_relative_to_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("models")).unwrap();
    std::fs::write(dir.path().join("models/m.toml"), "[display]\nbuffers = 3\n").unwrap();
    let path = dir.path().join("exp.toml");
    std::fs::write(&path, "name = \"f\"\nmodel = \"models/m.toml\"\n").unwrap();
    let exp = load_experiment(&path).unwrap();
    assert_eq!(exp.model, ModelSource::File(dir.path().join("models/m.toml")));
    let model = exp.resolve_model(&toml::Table::new()).unwrap();
    assert_eq!(model["display"]["buffers"].as_integer(), Some(3));
    let default = parse("name = \"d\"\n");
    assert_eq!(default.resolve_model(&base_model()).unwrap(), base_model());
}

#[test]
fn runs_and_writes_csvs_report_and_plots() {
    let exp = parse(BASIC);
    let fake = Fake::default();
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &fake, dir.path(), false).unwrap();
    assert_eq!(fake.calls.load(Ordering::SeqCst), 24);
    assert!(
        !fake.wanted_frames.load(Ordering::SeqCst),
        "no plot or derived value needs frames"
    );
    // [set] reached every run.
    assert!(fake.seen.lock().unwrap().iter().all(|(k, _)| k == "fixed"));
    assert_eq!(res.points.len(), 8);
    assert_eq!(res.runs.len(), 24);

    let runs = read(dir.path(), "runs.csv");
    let lines: Vec<&str> = runs.lines().collect();
    assert_eq!(
        lines[0],
        "point,workload.gpu,display.buffers,seed,metrics.display_interval_ms.mean,metrics.fixed_kind,wall_seconds"
    );
    assert_eq!(lines.len(), 25);
    let interval = 1000.0 / 60.0;
    assert_eq!(lines[1], format!("0,10ms,2,1,{},1,2", interval - 0.01));
    assert!(lines[4].starts_with("1,10ms,3,1,"));

    let points = read(dir.path(), "points.csv");
    let plines: Vec<&str> = points.lines().collect();
    assert_eq!(plines.len(), 9);
    assert!(plines[0].starts_with(
        "point,workload.gpu,display.buffers,metrics.display_interval_ms.mean:mean,\
         metrics.display_interval_ms.mean:ci_low,metrics.display_interval_ms.mean:ci_high,\
         metrics.display_interval_ms.mean:n"
    ));
    // Point 0: values interval - 0.01, interval, interval + 0.01.
    let ci = res.points[0].stat("metrics.display_interval_ms.mean").unwrap();
    assert!((ci.mean - interval).abs() < 1e-9);
    assert!((ci.half_width - 4.302_652_7 * 0.01 / 3f64.sqrt()).abs() < 1e-6);
    assert_eq!(ci.n, 3);

    // Checks: the first passes, the second (12ms, 3 buffers: 15.0) fails by 10%.
    assert_eq!(res.checks.len(), 2);
    assert!(res.checks[0].passed);
    assert!(!res.checks[1].passed);
    assert_eq!(res.checks_failed, 1);
    assert!((res.sim_wall_seconds - 48.0).abs() < 1e-9);

    let report = read(dir.path(), "report.md");
    for needle in [
        "# vsync-quantization",
        "Display interval against GPU time.",
        "| `workload.kind` | \"fixed\" |",
        "| `workload.gpu` | 10ms, 12ms, 14ms, 16ms |",
        "### display interval (ms) (`metrics.display_interval_ms.mean`)",
        "1 of 2 passed",
        "PASS",
        "**FAIL**",
        "summed simulation wall time: 48.000 s over 24 runs",
        "[interval.png](interval.png)",
    ] {
        assert!(report.contains(needle), "report lacks {needle:?}:\n{report}");
    }
    for f in ["interval.svg", "interval.png"] {
        assert!(std::fs::metadata(dir.path().join(f)).unwrap().len() > 0);
    }
    assert!(res.files.iter().any(|f| f == Path::new("report.md")));
    let table = res.table(&exp);
    assert!(
        table.contains("workload.gpu=10ms, display.buffers=2: display interval (ms) = 16.67 ±"),
        "{table}"
    );
}

#[test]
fn results_do_not_depend_on_scheduling() {
    let exp = parse(BASIC);
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    run_experiment(&exp, &base_model(), &Fake::default(), a.path(), false).unwrap();
    // A second run on a one-thread pool must give byte-identical CSVs.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| run_experiment(&exp, &base_model(), &Fake::default(), b.path(), true))
        .unwrap();
    assert_eq!(read(a.path(), "points.csv"), read(b.path(), "points.csv"));
    assert_eq!(read(a.path(), "runs.csv"), read(b.path(), "runs.csv"));
}

#[test]
fn an_observer_sees_every_run_and_can_stop_the_rest() {
    let exp = parse(BASIC);
    let dir = tempfile::tempdir().unwrap();
    let seen = Mutex::new(Vec::new());
    let all = |done: u64, total: u64| {
        seen.lock().unwrap().push((done, total));
        true
    };
    run_experiment(
        &exp,
        &base_model(),
        &Fake::default(),
        dir.path(),
        Progress::Observe(&all),
    )
    .unwrap();
    let mut seen = seen.into_inner().unwrap();
    seen.sort();
    let total = read(dir.path(), "runs.csv").lines().count() as u64 - 1;
    assert_eq!(seen, (1..=total).map(|d| (d, total)).collect::<Vec<_>>());
    // Stopping after the first run: on one thread, the rest never start.
    let stop = |_: u64, _: u64| false;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let other = tempfile::tempdir().unwrap();
    let e = pool
        .install(|| {
            run_experiment(
                &exp,
                &base_model(),
                &Fake::default(),
                other.path(),
                Progress::Observe(&stop),
            )
        })
        .unwrap_err();
    assert!(
        matches!(e, ExperimentError::Stopped { done: 1, total: t } if t == total),
        "{e}"
    );
    assert_eq!(e.to_string(), format!("stopped after 1 of {total} runs, as asked"));
    assert_eq!(
        read(other.path(), "runs.csv").lines().count(),
        2,
        "the one finished run is kept"
    );
}

#[test]
fn run_error_names_point_and_seed_and_keeps_finished_runs() {
    let fake = Fake {
        fail: true,
        ..Default::default()
    };
    // The fake fails only for gpu = 13ms with seed 2.
    let exp = parse(
        "name = \"f\"\nreplications = 3\n[[sweep]]\nkey = \"workload.gpu\"\nvalues = [\"12ms\", \"13ms\"]\n\
         [[metric]]\npath = \"metrics.frame_time_ms.mean\"\n",
    );
    let dir = tempfile::tempdir().unwrap();
    let e = run_experiment(&exp, &base_model(), &fake, dir.path(), false).unwrap_err();
    match &e {
        ExperimentError::Run {
            point,
            label,
            seed,
            message,
        } => {
            assert_eq!((*point, *seed), (1, 2));
            assert_eq!(label, "workload.gpu=13ms");
            assert_eq!(message, "GPU fell over");
        }
        other => panic!("unexpected error {other}"),
    }
    assert!(e.to_string().contains("point 1 (workload.gpu=13ms), seed 2"), "{e}");
    let runs = read(dir.path(), "runs.csv");
    assert_eq!(runs.lines().count(), 1 + 5, "{runs}");
    assert!(!runs.contains("13ms,2,"));
    assert!(!dir.path().join("points.csv").exists());
}

#[test]
fn missing_metric_path_is_a_clear_error() {
    let exp = parse("name = \"m\"\n[[metric]]\npath = \"metrics.frame_time_ms.p50\"\n");
    let dir = tempfile::tempdir().unwrap();
    let e = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("metrics.frame_time_ms.p50") && msg.contains("seed 1"),
        "{msg}"
    );
}

#[test]
fn null_metric_gives_empty_cells_not_nan() {
    let exp = parse("name = \"n\"\nreplications = 2\n[[metric]]\npath = \"metrics.frame_time_ms.p99\"\n");
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap();
    assert_eq!(res.points[0].mean("metrics.frame_time_ms.p99"), None);
    let points = read(dir.path(), "points.csv");
    assert!(!points.contains("NaN"), "{points}");
    assert_eq!(points.lines().nth(1).unwrap(), "0,,,,0");
}

const FIDELITY: &str = r#"
name = "fidelity"
replications = 2
[[sweep]]
key = "fidelity"
values = ["triangle", "tile", "frame"]
[[sweep]]
key = "workload.gpu"
values = ["10ms", "20ms"]
[[metric]]
path = "metrics.frame_time_ms.mean"
[[metric]]
path = "wall_seconds"
[[derived]]
name = "draw_error"
kind = "relative_error"
path = "metrics.frame_time_ms.mean"
reference = { "fidelity" = "triangle" }
[[derived]]
name = "speedup"
kind = "speedup"
reference = { fidelity = "triangle" }
[[derived]]
name = "c99"
kind = "interval_width"
column = "FrameTime"
level = 0.8
[[derived]]
name = "c_from_min"
kind = "quantile_width_from_min"
column = "FrameTime"
level = 0.9
[[plot]]
file = "error_vs_time"
kind = "scatter"
x = "wall_seconds"
y = "draw_error"
log_x = true
[[plot]]
file = "frames"
kind = "histogram"
column = "FrameTime"
bins = 20
where = { fidelity = "triangle" }
[[plot]]
file = "c99"
kind = "line"
x = "workload.gpu"
y = ["c99", "metrics.frame_time_ms.mean"]
[[check]]
path = "speedup"
where = { fidelity = "frame" }
expect = 20.0
rel_tolerance = 0.001
"#;

#[test]
fn derived_values_and_frame_plots() {
    let exp = parse(FIDELITY);
    assert!(exp.needs_frames());
    let fake = Fake::default();
    let dir = tempfile::tempdir().unwrap();
    let res = run_experiment(&exp, &base_model(), &fake, dir.path(), false).unwrap();
    assert!(fake.wanted_frames.load(Ordering::SeqCst));
    // Seed noise averages to -0.005 over seeds 1 and 2.
    // Points: (triangle,10) (triangle,20) (tile,10) (tile,20) (frame,10) (frame,20).
    let p = |i: usize, name: &str| res.points[i].derived_value(name);
    assert_eq!(p(0, "draw_error"), Some(0.0));
    assert!((p(2, "draw_error").unwrap() - 0.1 / 9.995).abs() < 1e-9);
    assert!((p(5, "draw_error").unwrap() - 1.0 / 19.995).abs() < 1e-9);
    assert_eq!(p(0, "speedup"), Some(1.0));
    assert_eq!(p(2, "speedup"), Some(4.0));
    assert_eq!(p(4, "speedup"), Some(20.0));
    // Frames per run: gpu + (i % 10), i < 100, pooled over 2 seeds.
    let frames: Vec<f64> = (0..200).map(|i| 10.0 + (i % 10) as f64).collect();
    assert_eq!(p(0, "c99"), interval_width(&frames, 0.8));
    assert_eq!(p(0, "c_from_min"), quantile_width_from_min(&frames, 0.9));
    // 200 values 10..=19, 20 each: h = 199 * 0.9 = 179.1 -> 18.1; minus 10.
    assert!((p(0, "c_from_min").unwrap() - 8.1).abs() < 1e-9);
    assert_eq!(res.checks.len(), 2);
    assert_eq!(res.checks_failed, 0);
    for f in ["error_vs_time", "frames", "c99"] {
        for ext in ["svg", "png"] {
            let path = dir.path().join(format!("{f}.{ext}"));
            assert!(
                std::fs::metadata(&path).map(|m| m.len() > 0).unwrap_or(false),
                "{path:?}"
            );
        }
    }
    let points = read(dir.path(), "points.csv");
    assert!(
        points
            .lines()
            .next()
            .unwrap()
            .ends_with(",draw_error,speedup,c99,c_from_min")
    );
    let report = read(dir.path(), "report.md");
    assert!(
        report.contains("## Derived values") && report.contains("`c_from_min`"),
        "{report}"
    );
    // The printed table ends with the derived values, one line per point,
    // just before the check tally.
    let table = res.table(&exp);
    let lines: Vec<&str> = table.lines().collect();
    let at = lines.iter().position(|l| *l == "derived values:").expect(&table);
    assert_eq!(lines.len(), at + 1 + 6 + 1, "{table}");
    assert!(lines[at + 1].contains("c_from_min = 8.100"), "{table}");
    assert!(
        lines[at + 1].contains("draw_error = 0;") && lines[at + 1].contains("speedup = 1.000"),
        "{table}"
    );
    assert!(lines.last().unwrap().starts_with("checks:"), "{table}");
}

#[test]
fn frame_column_missing_is_reported() {
    let exp = parse("name = \"h\"\n[[plot]]\nfile = \"h\"\nkind = \"histogram\"\ncolumn = \"Latency\"\n");
    let dir = tempfile::tempdir().unwrap();
    let e = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap_err();
    assert!(
        e.to_string()
            .contains("frame column `Latency` not found (columns: Index, FrameTime)"),
        "{e}"
    );
}

#[test]
fn point_model_applies_set_then_sweep() {
    let exp = parse(
        "name = \"p\"\n[set]\ndisplay.buffers = 4\n\"workload.kind\" = \"fixed\"\n\
         [[sweep]]\nkey = \"display.buffers\"\nvalues = [3]\n",
    );
    assert_eq!(exp.set.len(), 2, "nested [set] tables flatten to dotted keys");
    let pts = expand_points(&exp);
    let m = point_model(&exp, &base_model(), &pts[0]).unwrap();
    assert_eq!(m["display"]["buffers"].as_integer(), Some(3));
    assert_eq!(m["workload"]["kind"].as_str(), Some("fixed"));
    assert_eq!(m["workload"]["gpu"].as_str(), Some("10ms"));
    // A patch that cannot apply names the key.
    let exp = parse("name = \"p\"\n[set]\n\"workload.gpu.mean\" = 1\n");
    let dir = tempfile::tempdir().unwrap();
    let e = run_experiment(&exp, &base_model(), &Fake::default(), dir.path(), false).unwrap_err();
    assert!(e.to_string().contains("cannot set `workload.gpu.mean`"), "{e}");
}

// Checks against bounds and claims: tests/checks.rs; plots: tests/plots.rs;
// sampled experiments ([sample]): tests/sample.rs.
mod checks;
mod plots;
mod sample;

#[test]
fn a_search_aims_at_a_summary_metric_or_a_frame_columns_derived_value_only() {
    let with = |derived: &str, path: &str| {
        format!(
            "{BASIC}\n{derived}\n[[search]]\nname = \"s\"\nvary = \"workload.gpu\"\nfrom = 1\nto = 2\npath = \"{path}\"\ntarget = 1.0\n"
        )
    };
    // A ratio is taken between points: no meaning for one run.
    let e = parse_err(&with(
        "[[derived]]\nname = \"r\"\nkind = \"ratio\"\npath = \"metrics.display_interval_ms.mean\"\nreference = { \"display.buffers\" = 2 }",
        "r",
    ));
    assert!(
        e.contains("search[0].path") && e.contains("`r` is a derived value taken between points"),
        "{e}"
    );
    // A derived value of a frame column is computed from each run's frames.
    let exp = parse(&with(
        "[[derived]]\nname = \"w\"\nkind = \"interval_width\"\ncolumn = \"FrameTime\"\nlevel = 0.9",
        "w",
    ));
    assert!(matches!(
        exp.searches[0].frame_value,
        Some(DerivedKind::IntervalWidth { ref column, .. }) if column == "FrameTime"
    ));
    // Any other path stays a summary path.
    let exp = parse(&with("", "metrics.frame_time_ms.mean"));
    assert_eq!(exp.searches[0].frame_value, None);
}
