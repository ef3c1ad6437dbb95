//! The command line: outputs, reproducibility from the output folder, and
//! clear errors (file, key, line, suggestion; non-zero exit; no panic; no
//! earlier results lost).

use std::path::Path;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn run_ok(args: &[&str]) -> String {
    let o = bin().args(args).output().unwrap();
    assert!(
        o.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// Runs and expects failure with exit code 2 (not a panic's 101); returns stderr.
fn run_err(args: &[&str]) -> String {
    let o = bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{args:?}: expected exit 2, stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

const SMALL: &str = r#"
[run]
frames = 20
[noise]
enabled = false
[workload]
kind = "fixed"
cpu = "2ms"
gpu = "9ms"
"#;

#[test]
fn json_summary_has_the_documented_keys() {
    let out = run_ok(&["run", "--frames", "12", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for k in ["system", "seed", "frames", "wall_seconds"] {
        assert!(!v[k].is_null(), "{k}");
    }
    assert!(v["events"]["total"].as_u64().unwrap() > 0);
    assert!(v["events"]["by_kind"].is_object());
    let m = &v["metrics"];
    for k in ["frame_time_ms", "display_interval_ms", "display_latency_ms"] {
        for s in ["mean", "p50", "p99", "max"] {
            assert!(m[k][s].is_number(), "{k}.{s}");
        }
    }
    for k in [
        "cpu_busy_fraction",
        "gpu_busy_fraction",
        "repeated_refreshes",
        "dropped_frames",
    ] {
        assert!(m[k].is_number(), "{k}");
    }
    let shares: f64 = m["bottleneck"]
        .as_object()
        .unwrap()
        .values()
        .map(|x| x.as_f64().unwrap())
        .sum();
    assert!((shares - 1.0).abs() < 1e-9, "{shares}");
}

#[test]
fn out_dir_reruns_to_the_same_frames_and_trace_is_valid() {
    let d = tempfile::tempdir().unwrap();
    let a = d.path().join("a");
    let b = d.path().join("b");
    let trace = d.path().join("t.json");
    run_ok(&[
        "run",
        "--frames",
        "15",
        "--seed",
        "5",
        "--set",
        "display.buffers=3",
        "--set",
        "fidelity=\"triangle\"",
        "--out",
        a.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
        "--trace-detail",
        "triangle",
    ]);
    for f in ["summary.json", "frames.csv", "model.toml"] {
        assert!(a.join(f).exists(), "{f}");
    }
    let csv = std::fs::read_to_string(a.join("frames.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    for col in [
        "FrameTime",
        "MsCPUBusy",
        "MsCPUWait",
        "MsGPULatency",
        "MsGPUTime",
        "MsGPUBusy",
        "MsGPUWait",
        "MsUntilDisplayed",
        "DisplayLatency",
        "MsBetweenDisplayChange",
        "Dropped",
    ] {
        assert!(header.split(',').any(|c| c == col), "{col} missing in {header}");
    }
    // The resolved model alone reproduces the run.
    run_ok(&[
        "run",
        a.join("model.toml").to_str().unwrap(),
        "--out",
        b.to_str().unwrap(),
    ]);
    assert_eq!(csv, std::fs::read_to_string(b.join("frames.csv")).unwrap());
    // Trace: valid JSON; spans on one track never overlap.
    let t: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&trace).unwrap()).unwrap();
    let ev = t["traceEvents"].as_array().unwrap();
    let mut by_tid: std::collections::BTreeMap<i64, Vec<(f64, f64)>> = Default::default();
    for e in ev.iter().filter(|e| e["ph"] == "X") {
        let ts = e["ts"].as_f64().unwrap();
        by_tid
            .entry(e["tid"].as_i64().unwrap())
            .or_default()
            .push((ts, ts + e["dur"].as_f64().unwrap()));
    }
    // One named track per unit, each with spans (triangle fidelity: the
    // geometry and fragment stages have per-triangle spans).
    let track_names: std::collections::BTreeMap<i64, &str> = ev
        .iter()
        .filter(|e| e["ph"] == "M" && e["name"] == "thread_name")
        .map(|e| (e["tid"].as_i64().unwrap(), e["args"]["name"].as_str().unwrap()))
        .collect();
    for unit in ["CPU thread", "GPU front end", "GPU geometry", "GPU fragment", "Display"] {
        let tid = track_names
            .iter()
            .find(|(_, n)| **n == unit)
            .map(|(t, _)| *t)
            .unwrap_or_else(|| panic!("no track named {unit:?}: {track_names:?}"));
        assert!(
            by_tid.get(&tid).is_some_and(|s| !s.is_empty()),
            "track {unit:?} has no spans"
        );
    }
    for (tid, mut spans) in by_tid {
        spans.sort_by(|x, y| x.0.total_cmp(&y.0));
        for w in spans.windows(2) {
            assert!(w[1].0 >= w[0].1 - 1e-6, "overlap on track {tid}: {w:?}");
        }
    }
    // Counter tracks for both FIFOs.
    for counter in ["command FIFO", "triangle FIFO"] {
        assert!(
            ev.iter().any(|e| e["ph"] == "C" && e["name"] == counter),
            "no {counter:?} counter"
        );
    }
}

#[test]
fn unknown_key_names_file_line_and_suggestion() {
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "m.toml", &format!("{SMALL}\n[display]\nrefesh = \"60Hz\"\n"));
    let e = run_err(&["run", &m]);
    assert!(
        e.contains("m.toml:") && e.contains("display.refesh") && e.contains("did you mean `refresh`"),
        "{e}"
    );
    let line = SMALL.lines().count() + 3;
    assert!(e.contains(&format!(":{line}:")), "expected line {line}: {e}");
    let e = run_err(&["run", &m.replace("m.toml", "none.toml")]);
    assert!(e.contains("none.toml"), "{e}");
    let e = run_err(&["run", "--set", "display.refesh=60Hz"]);
    assert!(e.contains("did you mean `refresh`"), "{e}");
}

#[test]
fn bad_values_are_named() {
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "m.toml", SMALL);
    for (set, needle) in [
        ("workload.gpu=\"9 parsecs\"", "workload.gpu"),
        ("workload.gpu=\"-3ms\"", "negative"),
        ("workload.gpu=\"NaNms\"", "NaN"),
        ("workload.gpu=17", "needs a unit"),
        ("display.refresh=\"0Hz\"", "display.refresh"),
        ("display.buffers=1", "display.buffers"),
        ("cpu.max_frames_ahead=0", "cpu.max_frames_ahead"),
        ("command_fifo.unit=\"lines\"", "command_fifo.unit"),
        ("gpu.geometry.vertex_cache=\"fifo:0\"", "vertex_cache"),
        ("system=\"warp\"", "unknown system"),
    ] {
        let e = run_err(&["run", &m, "--set", set]);
        assert!(e.contains(needle), "{set}: {e}");
    }
}

#[test]
fn malformed_files_are_reported_with_their_names() {
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "bad.toml", "[run\nframes = 3\n");
    let e = run_err(&["run", &m]);
    assert!(e.contains("bad.toml") && e.contains("line 1"), "{e}");
    write(d.path(), "broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 x\n");
    let scene = format!(
        "{}\n[workload]\nkind = \"scene\"\n[[workload.groups]]\nname = \"o\"\nmesh = \"broken.obj\"\ntriangle_pixels = 1.0\n",
        "[run]\nframes = 2"
    );
    let m = write(d.path(), "scene.toml", &scene);
    let e = run_err(&["run", &m]);
    assert!(e.contains("broken.obj") && e.contains("workload.groups.0.mesh"), "{e}");
    let e = run_err(&["run", &m, "--set", "workload.groups.0.mesh=\"missing.obj\""]);
    assert!(e.contains("missing.obj"), "{e}");
}

/// Input files are read only when regular and only up to their size limit
/// (issue 60 item 1): `/dev/zero` as a model, as a model's hardware file
/// and behind an `.obj` name, a FIFO that would block, and a model over a
/// limit set by the option and by the environment, each exit 2 at once
/// with the file and the reason.
#[cfg(unix)]
#[test]
fn inputs_that_are_endless_blocking_or_too_large_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let err = run_err(&["run", "/dev/zero"]);
    assert!(err.contains("/dev/zero") && err.contains("not a regular file"), "{err}");
    let hw = write(
        d.path(),
        "hw.toml",
        "system = \"frame_pipeline\"\nhardware = \"/dev/zero\"\n[workload]\nkind = \"fixed\"\n",
    );
    let err = run_err(&["run", &hw]);
    assert!(
        err.contains("key `hardware`") && err.contains("not a regular file"),
        "{err}"
    );
    let obj = d.path().join("zero.obj");
    std::os::unix::fs::symlink("/dev/zero", &obj).unwrap();
    let err = run_err(&["vcache", "--policy", "fifo:16", obj.to_str().unwrap()]);
    assert!(err.contains("zero.obj") && err.contains("not a regular file"), "{err}");
    let fifo = d.path().join("fifo.toml");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success(),
        "mkfifo"
    );
    let err = run_err(&["run", fifo.to_str().unwrap()]);
    assert!(err.contains("fifo.toml") && err.contains("not a regular file"), "{err}");
    let m = write(d.path(), "m.toml", SMALL);
    let err = run_err(&["run", &m, "--max-input-bytes", "10"]);
    assert!(
        err.contains("m.toml") && err.contains("more than the 10 bytes"),
        "{err}"
    );
    let o = bin()
        .args(["run", &m])
        .env("RENDERSIM_MAX_INPUT_BYTES", "20")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("more than the 20 bytes"), "{err}");
    // Raised by the option above the environment's limit, the model runs.
    let o = bin()
        .args(["run", &m, "--max-input-bytes", "1000000"])
        .env("RENDERSIM_MAX_INPUT_BYTES", "20")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Errors that blamed the wrong thing (issue 60 item 9): an empty sortbuf
/// sequence said "` is a folder`"; a uniform distribution's bounds were
/// raw picoseconds; a wrong `--set run.frames` was dropped unchecked when
/// `--frames` replaced it.
#[test]
fn errors_name_what_the_user_wrote() {
    let err = run_err(&["sortbuf", "", "--buffer", "4"]);
    assert!(err.contains("the sequence is empty"), "{err}");
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "m.toml", SMALL);
    let err = run_err(&[
        "run",
        &m,
        "--set",
        "workload.cpu={kind=\"uniform\", min=\"30ms\", max=\"22ms\"}",
    ]);
    assert!(err.contains("`min` (30ms) must not exceed `max` (22ms)"), "{err}");
    let err = run_err(&["run", &m, "--set", "run.frames=\"abc\"", "--frames", "5"]);
    assert!(
        err.contains("--set run.frames=\"abc\"") && err.contains("whole number"),
        "{err}"
    );
}

#[test]
fn a_failed_run_keeps_earlier_results() {
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "m.toml", SMALL);
    let out = d.path().join("out");
    run_ok(&["run", &m, "--out", out.to_str().unwrap()]);
    let before = std::fs::read_to_string(out.join("summary.json")).unwrap();
    run_err(&[
        "run",
        &m,
        "--set",
        "workload.gpu=\"-1ms\"",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(before, std::fs::read_to_string(out.join("summary.json")).unwrap());
    // summary.json, frames.csv, model.toml and the result-set marker.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 4, "no stray files");
    assert!(
        std::fs::read_dir(d.path())
            .unwrap()
            .all(|e| !e.unwrap().file_name().to_string_lossy().starts_with(".out."))
    );
}

#[test]
fn isolate_finds_the_limiting_subsystem() {
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "m.toml", SMALL);
    let out = run_ok(&["isolate", &m, "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["bottleneck"], "gpu", "{v}");
    let out = run_ok(&["isolate", &m, "--json", "--set", "workload.cpu=\"20ms\""]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["bottleneck"], "cpu", "{v}");
    let out = run_ok(&[
        "isolate",
        "--json",
        "--set",
        "fidelity=\"draw\"",
        "--set",
        "run.frames=30",
        "--set",
        "cpu.non_render=\"0ms\"",
        "--set",
        "gpu.fragment.per_fragment=\"20ns\"",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["bottleneck"], "raster", "{v}");
    run_err(&["isolate", &m, "--factor", "1.5"]);
}

/// A scene model, vsync off, no noise, 10 frames at `draw` fidelity, with `extra` keys.
fn isolate_scene(group: &str, extra: &str) -> String {
    format!(
        "fidelity = \"draw\"\n[run]\nframes = 10\n[display]\nvsync = false\n[noise]\nenabled = false\n{extra}\n\
         [workload]\nkind = \"scene\"\n[[workload.groups]]\nname = \"g\"\n{group}\n"
    )
}

#[test]
fn isolate_reports_geometry_and_front_end_bound_models() {
    let d = tempfile::tempdir().unwrap();
    let iso = |name: &str, text: &str| -> serde_json::Value {
        let m = write(d.path(), name, text);
        serde_json::from_str(&run_ok(&["isolate", &m, "--json"])).unwrap()
    };
    let change = |v: &serde_json::Value, name: &str| {
        v["variants"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == name)
            .unwrap_or_else(|| panic!("no variant {name}: {v}"))["change"]
            .as_f64()
            .unwrap()
    };
    // Geometry-bound: 100,000 triangles x 100 ns of vertex shading = 10 ms; fragments 0.01 ms.
    let v = iso(
        "geometry.toml",
        &isolate_scene(
            "mesh = { triangles = 100000, acmr = 1.0 }\ntriangle_pixels = 0.1",
            "[gpu.geometry]\nvertex_shader = \"100ns\"\n[gpu.fragment]\nper_fragment = \"1ns\"",
        ),
    );
    assert_eq!(v["bottleneck"], "geometry", "{v}");
    assert!((change(&v, "geometry") + 0.5).abs() < 0.01, "{v}");
    // Front-end-bound: 100 draws, each batch 2 commands (matrix + draw) at
    // 50 us of command processing, plus clear and swap: about 10 ms on the
    // GPU front end, next to nothing on the CPU, geometry or fragments.
    let v = iso(
        "front.toml",
        &isolate_scene(
            "count = 100\nmesh = \"grid:1x1\"\ntriangle_pixels = 1.0",
            "[gpu]\ncommand = \"50us\"\n[gpu.geometry]\nvertex_shader = \"1ns\"\n[gpu.fragment]\nper_fragment = \"1ns\"",
        ),
    );
    assert_eq!(v["bottleneck"], "front_end", "{v}");
    assert!((change(&v, "front_end") + 0.5).abs() < 0.01, "{v}");
    for other in ["cpu", "geometry", "raster"] {
        assert!(change(&v, other).abs() < 0.01, "{other}: {v}");
    }
}

#[test]
fn vcache_reports_the_figure_keys() {
    let out = run_ok(&["vcache", "grid:4x3", "--policy", "fifo:9", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["triangles"], 24);
    assert_eq!(v["transformed"], 20);
    for k in ["policy", "indices", "unique_vertices", "acmr", "atvr"] {
        assert!(!v[k].is_null(), "{k}");
    }
    let e = run_err(&["vcache", "grid:4x3", "--policy", "lfu:3"]);
    assert!(e.contains("lfu"), "{e}");
}

#[test]
fn vcache_nvidia_on_an_icosphere_measured_on_the_h200() {
    // docs/measurements/nvidia-h200/vertex-reuse.csv: 72,960 invocations.
    let path = format!(
        "{}/docs/measurements/nvidia-h200/corpus/ico6-ordered.idx",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = run_ok(&["vcache", &path, "--policy", "nvidia", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["policy"], "nvidia");
    assert_eq!(v["transformed"], 72_960);
    assert_eq!(v["unique_vertices"], 40_962);
}

/// Paths of JSON nulls (NaN is written as null) in `v`.
fn nulls(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Null => out.push(path.to_string()),
        serde_json::Value::Object(m) => m.iter().for_each(|(k, x)| nulls(x, &format!("{path}.{k}"), out)),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| nulls(x, &format!("{path}[{i}]"), out)),
        _ => {}
    }
}

#[test]
fn run_until_stops_at_that_simulated_time() {
    // The default model asks for 300 frames at 60 Hz (5 s); run.until cuts it at 100 ms.
    let json = |extra: &[&str]| -> serde_json::Value {
        let mut args = vec!["run", "--json", "--set", "run.until=\"100ms\""];
        args.extend_from_slice(extra);
        serde_json::from_str(&run_ok(&args)).unwrap()
    };
    let v = json(&["--set", "run.warmup_frames=0"]);
    assert_eq!(v["stopped_by"], "time_limit", "{v}");
    assert_eq!(
        v["simulated_seconds"].as_f64().unwrap(),
        0.1,
        "{}",
        v["simulated_seconds"]
    );
    // Double-buffered 60 Hz vsync: a frame is shown every 16.7 ms at best, so
    // at most 6 frames complete by 100 ms; the frames still in flight are not reported.
    let done = v["frames_simulated"].as_u64().unwrap();
    assert!((3..=6).contains(&done), "{done} frames");
    assert_eq!(v["metrics"]["frame_time_ms"]["count"].as_u64().unwrap(), done);
    let displayed =
        v["metrics"]["displayed_frames"].as_u64().unwrap() + v["metrics"]["dropped_frames"].as_u64().unwrap();
    assert_eq!(displayed, done);
    let mut n = vec![];
    nulls(&v, "", &mut n);
    assert!(n.is_empty(), "NaN in the summary: {n:?}");
    // Fewer frames completed than the warm-up leaves out: empty metrics, no
    // NaN; the statistics of an empty distribution are null (not a measured
    // 0) beside `count: 0`, and nothing else is null.
    let v = json(&[]);
    assert_eq!(v["stopped_by"], "time_limit");
    let mut n = vec![];
    nulls(&v, "", &mut n);
    assert!(!n.is_empty());
    for path in &n {
        let (dist, stat) = path.rsplit_once('.').unwrap();
        assert!(
            ["mean", "p50", "p99", "min", "max", "std"].contains(&stat),
            "null that is not a statistic: {path}"
        );
        let pointer = format!("{}/count", dist.replace('.', "/"));
        assert_eq!(v.pointer(&pointer), Some(&serde_json::json!(0)), "{path}");
    }
    // A limit beyond the run's end changes nothing.
    let v = json(&["--set", "run.until=\"1000s\"", "--frames", "10"]);
    assert_eq!(v["stopped_by"], "model");
    assert_eq!(v["frames_simulated"], 10);
}

#[test]
fn a_missing_model_file_reports_the_os_error_once() {
    let d = tempfile::tempdir().unwrap();
    let missing = d.path().join("none.toml");
    let e = run_err(&["run", missing.to_str().unwrap()]);
    assert!(e.contains("none.toml"), "{e}");
    let os = std::fs::read_to_string(&missing).unwrap_err().to_string();
    assert_eq!(e.matches(&os).count(), 1, "OS error not exactly once: {e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    // The same for an experiment file.
    let e = run_err(&["experiment", missing.to_str().unwrap()]);
    assert_eq!(e.matches(&os).count(), 1, "OS error not exactly once: {e}");
}

#[test]
fn a_bad_enum_value_names_its_key_and_the_valid_values() {
    let e = run_err(&["run", "--set", "display.present_mode=mailbx"]);
    assert!(e.contains("`display.present_mode`"), "{e}");
    assert!(!e.contains("present_mode.mailbx"), "{e}");
    for v in ["`fifo`", "`mailbox`", "`immediate`"] {
        assert!(e.contains(v), "{v} not listed: {e}");
    }
    assert!(e.contains("did you mean `mailbox`"), "{e}");
    // In a file: the key's line.
    let d = tempfile::tempdir().unwrap();
    let m = write(
        d.path(),
        "m.toml",
        &format!("{SMALL}\n[command_fifo]\nunit = \"lines\"\n"),
    );
    let e = run_err(&["run", &m]);
    let line = SMALL.lines().count() + 3;
    assert!(e.contains(&format!("m.toml:{line}: key `command_fifo.unit`:")), "{e}");
    assert!(e.contains("`entries`") && e.contains("`bytes`"), "{e}");
}

#[test]
fn a_bad_set_value_is_reported_as_coming_from_the_option() {
    // cpu.per_draw stands on a line of the embedded model, but the bad value came from --set.
    let e = run_err(&["run", "--set", "cpu.per_draw=17"]);
    assert!(e.contains("`--set cpu.per_draw=17`"), "{e}");
    assert!(e.contains("key `cpu.per_draw`") && e.contains("needs a unit"), "{e}");
    assert!(
        !e.contains("<embedded default model>:"),
        "reported at a line of the model: {e}"
    );
    // The same for a file, and for values the simulator rejects after parsing.
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "m.toml", &format!("{SMALL}\n[display]\nbuffers = 2\n"));
    let e = run_err(&["run", &m, "--set", "display.buffers=1"]);
    assert!(
        e.contains("`--set display.buffers=1`") && e.contains("display.buffers"),
        "{e}"
    );
    assert!(!e.contains("m.toml:"), "{e}");
    // A bad value in the file itself still names its line.
    let m = write(d.path(), "bad.toml", &format!("{SMALL}\n[display]\nbuffers = 1\n"));
    let e = run_err(&["run", &m, "--set", "cpu.per_draw=\"1us\""]);
    assert!(e.contains(&format!("bad.toml:{}", SMALL.lines().count() + 3)), "{e}");
}

/// Whether `text` shows a negative zero such as "-0.000" or "-0.0".
fn has_negative_zero(text: &str) -> bool {
    text.match_indices("-0").any(|(i, _)| {
        if text[..i].chars().next_back().is_some_and(|c| c.is_ascii_alphanumeric()) {
            return false; // 10-0, 1e-05: not a signed number
        }
        let rest = &text[i + 1..];
        let num: String = rest.chars().take_while(|c| c.is_ascii_digit() || *c == '.').collect();
        !num.is_empty() && num.chars().all(|c| c == '0' || c == '.')
    })
}

#[test]
fn an_empty_scene_prints_no_negative_zeros() {
    assert!(has_negative_zero("geometry -0.000 ms") && has_negative_zero("\"x\": -0.0,"));
    assert!(!has_negative_zero("-0.25 ms, 10-0 and -1.000"));
    let d = tempfile::tempdir().unwrap();
    let m = write(
        d.path(),
        "empty.toml",
        "[run]\nframes = 10\n[display]\nvsync = false\n[noise]\nenabled = false\n[workload]\nkind = \"scene\"\n\
         [[workload.groups]]\nname = \"g\"\ncount = 0\nmesh = \"grid:1x1\"\ntriangle_pixels = 1.0\n",
    );
    let out = d.path().join("out");
    let human = run_ok(&["run", &m, "--out", out.to_str().unwrap()]);
    assert!(!has_negative_zero(&human), "{human}");
    assert!(human.contains("geometry 0.000 ms"), "{human}");
    let json = run_ok(&["run", &m, "--json"]);
    assert!(!has_negative_zero(&json), "{json}");
    for f in ["summary.json", "frames.csv"] {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        assert!(!has_negative_zero(&text), "{f}: {text}");
    }
    let iso = run_ok(&["isolate", &m]);
    assert!(!has_negative_zero(&iso), "{iso}");
}

#[test]
fn a_run_stopped_by_max_events_reports_the_frames_it_completed() {
    let args = ["run", "--set", "run.max_events=1000000", "--set", "run.warmup_frames=0"];
    let mut json_args = args.to_vec();
    json_args.push("--json");
    let v: serde_json::Value = serde_json::from_str(&run_ok(&json_args)).unwrap();
    assert_eq!(v["stopped_by"], "event_limit", "{v}");
    assert_eq!(v["events"]["total"], 1_000_000);
    assert_eq!(v["frames_requested"], 300);
    let done = v["frames"].as_u64().unwrap();
    assert!(done > 0 && done < 300, "{done}");
    assert_eq!(v["frames_simulated"], done);
    let m = &v["metrics"];
    assert_eq!(
        m["displayed_frames"].as_u64().unwrap() + m["dropped_frames"].as_u64().unwrap(),
        done
    );
    assert_eq!(m["frame_time_ms"]["count"], done);
    let human = run_ok(&args);
    assert!(
        human.contains(&format!(
            "{done} of 300 frames completed (stopped early: run.max_events reached"
        )),
        "{human}"
    );
    // A complete run says just how many frames it simulated.
    let human = run_ok(&["run", "--frames", "5"]);
    assert!(
        human.contains(", 5 frames, seed 1") && !human.contains("stopped early"),
        "{human}"
    );
}

#[test]
fn system_noise_experiment_prints_the_paper_constant_at_the_end() {
    let d = tempfile::tempdir().unwrap();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/figure3-system-noise.toml");
    let out = run_ok(&[
        "experiment",
        file.to_str().unwrap(),
        "--out",
        d.path().to_str().unwrap(),
    ]);
    // The last lines: derived values per point, the check tally, the
    // claims' verdicts, the wall time.
    let tail: Vec<&str> = out.lines().skip_while(|l| !l.starts_with("derived values:")).collect();
    let line = tail
        .iter()
        .find(|l| l.contains("noise.enabled=true, variation.enabled=false") && l.contains("c99_from_min = "))
        .unwrap_or_else(|| panic!("no c99 in the last lines:\n{out}"));
    let c99: f64 = line
        .split("c99_from_min = ")
        .nth(1)
        .and_then(|r| r.split(';').next())
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    // The experiment's own check: the 99% width lies in 0.5 .. 1.5 ms (seed 1: 1.267 ms).
    assert!((0.5..=1.5).contains(&c99), "{c99}");
    assert!(
        tail.iter()
            .any(|l| l.contains("noise.enabled=false, variation.enabled=false") && l.contains("c99_from_min = 0;")),
        "{out}"
    );
    assert!(tail.len() <= 16, "{out}");
}
// Sizes read from input are checked against stated limits (crates/models/src/limits.rs,
// docs/models.md "Limits") before anything is allocated: a clear error that
// names the key, the value and the limit, exit 2, never an allocation
// failure or a panic.

/// Runs, expects exit 2 and an error containing every one of `needles`,
/// with no panic and no allocation failure.
fn limit_err(args: &[&str], needles: &[&str]) {
    let e = run_err(args);
    assert!(!e.contains("memory allocation"), "{e}");
    for n in needles {
        assert!(e.contains(n), "{args:?}: expected {n:?} in: {e}");
    }
}

fn model(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn a_huge_direct_vertex_cache_is_refused_with_its_limit() {
    limit_err(
        &["vcache", "grid:8x8", "--policy", "direct:4294967295,1"],
        &["--policy", "4294967295", "limit of 1048576"],
    );
}

#[test]
fn huge_generated_meshes_are_refused_with_their_limit() {
    limit_err(
        &["vcache", "grid:40000x40000", "--policy", "fifo:32"],
        &["grid:40000x40000", "9600000000 indices", "limit of 268435456"],
    );
    limit_err(
        &["vcache", "random:700000000:1000:1", "--policy", "fifo:32"],
        &["2100000000 indices", "limit of 268435456"],
    );
    limit_err(
        &[
            "run",
            &model("one-mesh.toml"),
            "--set",
            "workload.groups.0.mesh=\"grid:100000x100000\"",
        ],
        &["workload.groups.0.mesh", "limit of 268435456"],
    );
}

#[test]
fn a_huge_replication_count_is_refused_with_its_limit() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "e.toml",
        "name = \"x\"\nmodel = \"default\"\nreplications = 100000000\n[[sweep]]\nkey = \"run.seed\"\nvalues = [1]\n",
    );
    limit_err(&["experiment", &f], &["replications", "100000000", "limit of 100000"]);
    // Points x replications: three sweeps of 10^5 steps.
    let mut text = String::from("name = \"x\"\nmodel = \"default\"\n");
    for k in ["cpu.per_draw", "cpu.per_object", "cpu.clear"] {
        text += &format!(
            "[[sweep]]\nkey = \"{k}\"\nrange = {{ from = 1, to = 100000, steps = 100000, format = \"{{}}ns\" }}\n"
        );
    }
    let f = write(d.path(), "s.toml", &text);
    limit_err(
        &["experiment", &f],
        &["sweep", "100000 x 100000 x 100000", "limit of 1000000"],
    );
}

#[test]
fn huge_pixelflow_sizes_are_refused_with_their_limit() {
    let m = model("pixelflow-20.toml");
    limit_err(
        &["run", &m, "--set", "nodes=4294967295"],
        &["key `nodes`", "4294967295", "limit of 4096"],
    );
    limit_err(
        &["run", &m, "--set", "frames=10000", "--set", "region={width=1,height=1}"],
        &["key `frames`", "3276800000 region records", "limit of 16777216"],
    );
}

#[test]
fn huge_scenes_are_refused_with_their_limit() {
    limit_err(
        &[
            "run",
            &model("one-mesh.toml"),
            "--set",
            "workload.groups.0.count=9223372036854775807",
        ],
        &["workload.groups.0.count", "9223372036854775807", "limit of 16777216"],
    );
    limit_err(
        &["run", &model("city.toml"), "--set", "workload.scale=1e308"],
        &["workload.scale", "1e308", "limit of 1000"],
    );
}

#[test]
fn a_run_over_max_memory_is_refused_before_it_starts() {
    // 10^9 frames of records: about 268 GiB, over the 8 GiB default.
    limit_err(
        &["run", &model("fixed.toml"), "--set", "run.frames=1000000000"],
        &[
            "run.max_memory",
            "1000000000 frames",
            "GiB",
            "8 GiB",
            "--set run.max_memory=",
        ],
    );
    // A lower limit of the user's own.
    limit_err(
        &[
            "run",
            &model("fixed.toml"),
            "--set",
            "run.frames=100000",
            "--set",
            "run.max_memory=\"1MiB\"",
        ],
        &["run.max_memory", "1 MiB"],
    );
    // Raised, the same run goes.
    run_ok(&[
        "run",
        &model("fixed.toml"),
        "--set",
        "run.frames=100",
        "--set",
        "run.max_memory=\"16GiB\"",
    ]);
    limit_err(
        &["run", &model("fixed.toml"), "--set", "run.max_memory=\"lots\""],
        &["run.max_memory"],
    );
}

#[test]
fn a_trace_streams_to_its_file_and_takes_no_memory_budget() {
    // One-mesh at triangle fidelity: 18,432 triangles a frame. Held in memory
    // the timeline would need far more than 4 MiB; streamed, it needs none.
    let d = tempfile::tempdir().unwrap();
    let t = d.path().join("t.json");
    run_ok(&[
        "run",
        &model("one-mesh.toml"),
        "--frames",
        "3",
        "--set",
        "run.max_memory=\"4MiB\"",
        "--trace",
        t.to_str().unwrap(),
        "--trace-detail",
        "triangle",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&t).unwrap()).unwrap();
    assert!(v["traceEvents"].as_array().unwrap().len() > 50_000);
}

#[test]
fn latency_systems_over_a_long_simulated_span_run_in_bounded_memory() {
    for m in ["mfr-cluster.toml", "vr-naive.toml", "vr-warp.toml"] {
        // 10 inputs 100 s apart: over 1000 s simulated in 64 KiB of records
        // (the frames are folded into the inputs they show and not kept).
        run_ok(&[
            "run",
            &model(m),
            "--set",
            "run.events=10",
            "--set",
            "input.mean_interval=\"100s\"",
            "--set",
            "run.max_memory=\"64KiB\"",
        ]);
    }
}

#[test]
fn a_huge_input_event_count_is_refused_with_its_limit() {
    for m in ["mfr-cluster.toml", "vr-naive.toml"] {
        limit_err(
            &["run", &model(m), "--set", "run.events=1000000000000"],
            &["run.events", "1000000000000", "limit of 100000000"],
        );
    }
}

#[test]
fn zero_time_frames_stop_at_max_events() {
    let out = run_ok(&[
        "run",
        &model("fixed.toml"),
        "--json",
        "--set",
        "workload.cpu=\"0ms\"",
        "--set",
        "workload.gpu=\"0ms\"",
        "--set",
        "display.vsync=false",
        "--set",
        "run.frames=10000000",
        "--set",
        "run.max_events=1000",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["stopped_by"], "event_limit");
    assert_eq!(v["events"]["total"], 1000);
    assert!(v["frames"].as_u64().unwrap() < 1100, "{}", v["frames"]);
}

/// A scene model whose second `[[workload.groups]]` entry stands at a known line.
const GROUPS: &str = r#"[run]
frames = 10
[noise]
enabled = false
[workload]
kind = "scene"

[[workload.groups]]
name = "a"
count = 2
mesh = { triangles = 40, acmr = 0.9 }
triangle_pixels = 4.0

[[workload.groups]]
name = "b"
count = COUNT
mesh = { triangles = 40, acmr = 0.9 }
triangle_pixels = 4.0
"#;

#[test]
fn keys_inside_arrays_of_tables_name_their_line() {
    let d = tempfile::tempdir().unwrap();
    let line = GROUPS.lines().position(|l| l == "count = COUNT").unwrap() + 1;
    let m = write(d.path(), "g.toml", &GROUPS.replace("COUNT", "-3"));
    let e = run_err(&["run", &m]);
    assert!(
        e.contains(&format!("g.toml:{line}: key `workload.groups.1.count`")),
        "expected line {line}: {e}"
    );
    let m = write(
        d.path(),
        "h.toml",
        &GROUPS.replace("count = COUNT", "count = 1\ntexturs = 3"),
    );
    let e = run_err(&["run", &m]);
    assert!(
        e.contains(&format!("h.toml:{}: key `workload.groups.1.texturs`", line + 1))
            && e.contains("did you mean `textures`"),
        "{e}"
    );
}

#[test]
fn a_set_on_an_array_element_is_blamed_on_the_option() {
    let d = tempfile::tempdir().unwrap();
    let m = write(d.path(), "g.toml", &GROUPS.replace("COUNT", "1"));
    let e = run_err(&["run", &m, "--set", "workload.groups.1.count=-1"]);
    assert!(
        e.contains("`--set workload.groups.1.count=-1`") && e.contains("key `workload.groups.1.count`"),
        "{e}"
    );
    assert!(!e.contains("g.toml:"), "blamed on a line of the model: {e}");
    // The embedded default model too.
    let e = run_err(&["run", "--set", "workload.groups.0.count=-1"]);
    assert!(e.contains("`--set workload.groups.0.count=-1`"), "{e}");
    assert!(!e.contains("<embedded default model>:"), "{e}");
}

const FIXED_EXPERIMENT: &str = r#"name = "e"
model = "MODEL"

[set]
"run.frames" = 30
"run.warmup_frames" = 3
"workload.gpu" = "GPU"

[[sweep]]
key = "display.buffers"
values = [2, BUFFERS]

[[metric]]
path = "metrics.frame_time_ms.mean"
"#;

fn experiment_file(dir: &Path, name: &str, gpu: &str, buffers: &str, extra: &str) -> String {
    let model = write(dir, "m.toml", SMALL);
    let text = FIXED_EXPERIMENT
        .replace("MODEL", &model)
        .replace("GPU", gpu)
        .replace("BUFFERS", buffers);
    write(dir, name, &format!("{text}{extra}"))
}

#[test]
fn experiment_values_are_blamed_on_the_experiment_file() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    let out = out.to_str().unwrap();
    // A bad [set] value: the experiment file and the line of the key.
    let e = experiment_file(d.path(), "e.toml", "-5ms", "3", "");
    let err = run_err(&["experiment", &e, "--quiet", "--out", out]);
    assert!(
        err.contains("[set] workload.gpu in ") && err.contains("e.toml:7"),
        "{err}"
    );
    assert!(!err.contains("m.toml:"), "blamed on the model file: {err}");
    // A bad sweep value: the experiment file and the line of its [[sweep]].
    let e = experiment_file(d.path(), "f.toml", "5ms", "30", "");
    let err = run_err(&["experiment", &e, "--quiet", "--out", out]);
    assert!(
        err.contains("[[sweep]] of display.buffers in ") && err.contains("f.toml:10"),
        "{err}"
    );
    assert!(
        err.contains("key `display.buffers`") && !err.contains("m.toml:"),
        "{err}"
    );
}

#[test]
fn experiment_check_entries_name_their_line() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    let check = "\n[[check]]\npath = \"metrics.frame_time_ms.mean\"\nexpect = 9.0\ntolerance = 0.5\n\n[[check]]\npath = \"metrics.frame_time_ms.mean\"\nexpect = 9.0\n";
    let e = experiment_file(d.path(), "e.toml", "9ms", "3", check);
    let line = std::fs::read_to_string(&e)
        .unwrap()
        .lines()
        .enumerate()
        .filter(|(_, l)| *l == "[[check]]")
        .nth(1)
        .unwrap()
        .0
        + 1;
    let err = run_err(&["experiment", &e, "--quiet", "--out", out.to_str().unwrap()]);
    assert!(
        err.contains(&format!("e.toml:{line}: key `check[1]")),
        "expected line {line}: {err}"
    );
}

#[test]
fn failed_checks_exit_1_and_errors_exit_2() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    let out = out.to_str().unwrap();
    let check = "\n[[check]]\npath = \"metrics.frame_time_ms.mean\"\nat_most = 1.0\ntolerance = 0.0\n";
    let e = experiment_file(d.path(), "e.toml", "9ms", "3", check);
    let o = bin()
        .args(["experiment", &e, "--quiet", "--out", out])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("reference check(s) failed") && !err.contains("panicked"),
        "{err}"
    );
    assert!(Path::new(out).join("report.md").exists());
    // A passing check exits 0, an invalid experiment exits 2.
    let check = "\n[[check]]\npath = \"metrics.frame_time_ms.mean\"\nat_least = 1.0\ntolerance = 0.0\n";
    let e = experiment_file(d.path(), "e.toml", "9ms", "3", check);
    run_ok(&["experiment", &e, "--quiet", "--out", out]);
    let e = experiment_file(d.path(), "e.toml", "9ms", "3", "\n[[check]]\npath = \"x\"\n");
    run_err(&["experiment", &e, "--quiet", "--out", out]);
}

#[test]
fn a_derived_value_blames_the_key_the_user_gave() {
    let e = run_err(&["run", "models/mfr-cluster.toml", "--set", "slow_client.render=0ms"]);
    assert!(
        e.contains("`--set slow_client.render=0ms`") && e.contains("key `slow_client.render`"),
        "{e}"
    );
    assert!(!e.contains("key `conventional.frame`"), "{e}");
    // A constraint between two keys blames the one the user changed.
    let e = run_err(&["run", "models/fixed.toml", "--set", "run.frames=5"]);
    assert!(
        e.contains("`--set run.frames=5`") && e.contains("key `run.frames`") && e.contains("run.warmup_frames (60)"),
        "{e}"
    );
    let e = run_err(&["run", "models/fixed.toml", "--set", "run.warmup_frames=600"]);
    assert!(e.contains("key `run.warmup_frames`"), "{e}");
}

#[test]
fn policy_errors_name_the_policy_given() {
    let e = run_err(&["vcache", "grid:4x4", "--policy", "lavapipe:3"]);
    assert!(e.contains("`lavapipe` takes no size") && !e.contains("`none`"), "{e}");
    let e = run_err(&["vcache", "grid:4x4", "--policy", "none:3"]);
    assert!(e.contains("`none` takes no size"), "{e}");
}

#[test]
fn isolate_refuses_other_systems_by_name() {
    for (m, system) in [
        ("models/mfr-cluster.toml", "multi_rate"),
        ("models/pixelflow-20.toml", "pixelflow"),
        ("models/vr-warp.toml", "vr"),
    ] {
        let e = run_err(&["isolate", m]);
        assert!(
            e.contains(&format!(
                "isolate applies to the frame pipeline; {m} is a {system} model"
            )),
            "{e}"
        );
        assert!(!e.contains("unknown field"), "{e}");
    }
}

#[test]
fn non_finite_pixelflow_values_are_errors_naming_the_input() {
    for (set, key) in [
        ("region.width=1e+308", "region.width"),
        ("display.height=1e308", "display.height"),
        ("aa_primitive.width=1e300", "aa_primitive.width"),
        ("deferred.t_rast_per_prim=1000000s", "deferred.t_rast_per_prim"),
    ] {
        let e = run_err(&["run", "models/pixelflow-20.toml", "--set", set, "--json"]);
        assert!(
            e.contains(&format!("`--set {set}`")) && e.contains(&format!("key `{key}`")),
            "{set}: {e}"
        );
    }
    // The closed forms alone never overflow a clock: a huge cost is fine there.
    let out = run_ok(&[
        "run",
        "models/pixelflow-20.toml",
        "--set",
        "fidelity=\"analytic\"",
        "--set",
        "deferred.t_rast_per_prim=1000000s",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["metrics"]["analytic_latency_ms"].as_f64().unwrap() > 1e12, "{v}");
}

#[test]
fn empty_statistics_are_null_not_zero() {
    let args = ["run", "models/fixed.toml", "--set", "run.max_events=5"];
    let mut json_args = args.to_vec();
    json_args.push("--json");
    let v: serde_json::Value = serde_json::from_str(&run_ok(&json_args)).unwrap();
    let s = &v["metrics"]["frame_time_ms"];
    assert_eq!(s["count"], 0, "{s}");
    for k in ["mean", "p50", "p99", "min", "max", "std"] {
        assert!(s[k].is_null(), "{k}: {s}");
    }
    let human = run_ok(&args);
    let line = human.lines().find(|l| l.contains("frame time")).unwrap();
    assert!(line.contains("n/a") && !line.contains("0.000"), "{human}");
}

#[test]
fn predictable_clock_overflow_is_reported_before_simulating() {
    // 600 frames of 5,000,000 s each: reported up front, naming the keys.
    let e = run_err(&[
        "run",
        "models/fixed.toml",
        "--set",
        "workload.gpu=\"5000000s\"",
        "--set",
        "display.vsync=true",
    ]);
    assert!(
        e.contains("key `workload.gpu`") && e.contains("run.frames") && e.contains("213 days"),
        "{e}"
    );
    let e = run_err(&["run", "models/fixed.toml", "--set", "display.refresh=\"2000000s\""]);
    assert!(
        e.contains("key `display.refresh`") && e.contains("would overflow"),
        "{e}"
    );
    // (With room for that many frames' records: else run.max_memory says no first.)
    let e = run_err(&[
        "run",
        "models/fixed.toml",
        "--frames",
        "100000000000",
        "--set",
        "run.max_memory=\"1000TiB\"",
    ]);
    assert!(
        e.contains("`--frames 100000000000`") && e.contains("key `run.frames`"),
        "{e}"
    );
    // Within run.events' own limit (1e8), but 1e8 inputs a second apart
    // outrun the clock.
    let e = run_err(&[
        "run",
        "models/mfr-cluster.toml",
        "--set",
        "run.events=100000000",
        "--set",
        "input.mean_interval=\"1s\"",
    ]);
    assert!(
        e.contains("key `input.mean_interval`") && e.contains("run.events") && e.contains("213 days"),
        "{e}"
    );
    let e = run_err(&[
        "run",
        "models/vr-warp.toml",
        "--set",
        "input.mean_interval=\"1000000s\"",
    ]);
    assert!(
        e.contains("key `input.mean_interval`") && e.contains("run.events"),
        "{e}"
    );
}

#[test]
fn an_infinite_expected_cost_is_an_error_naming_the_distribution() {
    // exp(sigma^2 / 2) overflows: the fragment term would be written as null.
    let e = run_err(&[
        "run",
        "--frames",
        "20",
        "--set",
        "run.until=\"1ms\"",
        "--set",
        "workload.groups.2.triangle_pixels.sigma=100",
    ]);
    assert!(
        e.contains("`--set workload.groups.2.triangle_pixels.sigma=100`")
            && e.contains("key `workload.groups.2.triangle_pixels`")
            && e.contains("not a finite number"),
        "{e}"
    );
    let e = run_err(&[
        "run",
        "models/fixed.toml",
        "--set",
        "workload.gpu={kind=\"pareto\", scale=\"1ms\", shape=0.5}",
    ]);
    assert!(e.contains("key `workload.gpu`") && e.contains("does not exist"), "{e}");
}

#[test]
fn a_search_value_is_blamed_on_the_search() {
    let d = tempfile::tempdir().unwrap();
    let model = std::fs::canonicalize("models/pixelflow-20.toml").unwrap();
    let text = format!(
        "name = \"s\"\nmodel = {:?}\n[set]\nfidelity = \"analytic\"\n[[metric]]\npath = \"metrics.latency_ms\"\n\
         [[search]]\nname = \"bad\"\nvary = \"deferred.t_trans\"\nfrom = 0.1\nto = 5.0\nformat = \"{{}}us\"\n\
         path = \"metrics.latency_ms\"\ntarget = 30.0\nset = {{ shading_nodes = 100 }}\n",
        model.display().to_string()
    );
    let e = write(d.path(), "s.toml", &text);
    let out = d.path().join("out");
    let err = run_err(&["experiment", &e, "--quiet", "--out", out.to_str().unwrap()]);
    assert!(
        err.contains("search \"bad\" failed") && err.contains("[[search]] \"bad\", which sets shading_nodes"),
        "{err}"
    );
    assert!(
        err.contains("key `shading_nodes`") && !err.contains("pixelflow-20.toml:"),
        "{err}"
    );
}

#[test]
fn every_system_near_the_end_of_the_clock_gives_a_clear_error_not_a_wrap() {
    // 2^64 - 1 picoseconds: any sum or product with it overflows u64; each
    // system must say so (or refuse the run's size), never wrap silently.
    let max = "\"18446744073709551615ps\"";
    for (model, key, extra) in [
        ("one-mesh.toml", "gpu.geometry.vertex_shader", "run.warmup_frames=0"),
        ("one-mesh.toml", "gpu.fragment.per_fragment", "run.warmup_frames=0"),
        ("fixed.toml", "workload.gpu", "run.max_events=100"),
        ("fixed.toml", "cpu.swap", "run.warmup_frames=0"),
        ("mfr-cluster.toml", "tracker.latency", "run.events=20"),
        ("mfr-cluster.toml", "slow_client.render", "run.events=20"),
        ("vr-warp.toml", "tracker.latency", "run.events=20"),
        ("vr-naive.toml", "renderer.render", "run.events=20"),
        ("pixelflow-20.toml", "deferred.t_load", "primitives=1000"),
    ] {
        let e = run_err(&[
            "run",
            &model_path(model),
            "--set",
            &format!("{key}={max}"),
            "--set",
            extra,
        ]);
        assert!(
            ["213 days", "overflow", "run.max_memory", "picosecond range"]
                .iter()
                .any(|w| e.contains(w)),
            "{model} {key}: {e}"
        );
    }
}

fn model_path(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn an_output_folder_of_one_command_is_not_replaced_by_another_unless_forced() {
    // An experiment's results are not lost to `run --out` (or `replay
    // --out`) into the same folder; --force replaces them.
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("results");
    let out_s = out.to_str().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exp = root.join("experiments/vsync-quantization.toml");
    run_ok(&["experiment", exp.to_str().unwrap(), "--out", out_s, "--quiet"]);
    let fixed = root.join("models/fixed.toml");
    let err = run_err(&["run", fixed.to_str().unwrap(), "--out", out_s]);
    assert!(
        err.contains("holds the results of `rendersim experiment`")
            && err.contains("`rendersim run`")
            && err.contains("--force"),
        "{err}"
    );
    assert!(out.join("report.md").is_file(), "the experiment's results are kept");
    let capture = root.join("tests/fixtures/presentmon/test_case_1.csv");
    let err = run_err(&["replay", capture.to_str().unwrap(), "--out", out_s]);
    assert!(err.contains("`rendersim replay`"), "{err}");
    // The same command replaces its own; --force replaces another's.
    run_ok(&["experiment", exp.to_str().unwrap(), "--out", out_s, "--quiet"]);
    run_ok(&["run", fixed.to_str().unwrap(), "--out", out_s, "--force"]);
    assert!(out.join("summary.json").is_file() && !out.join("report.md").exists());
    let err = run_err(&["experiment", exp.to_str().unwrap(), "--out", out_s, "--quiet"]);
    assert!(err.contains("holds the results of `rendersim run`"), "{err}");
}

/// `rendersim ARGS` in a pseudo-terminal (util-linux `script`), its screen
/// output; `None` where `script` is missing.
fn on_a_terminal(args: &str, after_ms: &str) -> Option<String> {
    let line = format!("{} {args}", env!("CARGO_BIN_EXE_rendersim"));
    // `script` keeps a copy of the session in a file: one in a temp folder.
    let d = tempfile::tempdir().unwrap();
    let typescript = d.path().join("typescript");
    let o = Command::new("script")
        .args(["-qec", &line, typescript.to_str().unwrap()])
        .env("RENDERSIM_PROGRESS_AFTER_MS", after_ms)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()?;
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    Some(String::from_utf8_lossy(&o.stdout).to_string())
}

#[test]
fn long_commands_show_a_spinner_on_a_terminal_only() {
    // On a terminal, once the delay has passed: the command line and the
    // time so far, cleared at the end, the printed lines intact.
    // (A run of about 0.4 s, so that the spinner is drawn before the end.)
    let Some(screen) = on_a_terminal("run --set run.frames=30", "0") else {
        eprintln!("SKIPPED: no `script` to make a terminal");
        return;
    };
    assert!(screen.contains("rendersim run --set run.frames=30 [0s]"), "{screen:?}");
    assert!(
        screen.ends_with("\r\x1b[2K"),
        "the spinner is cleared at the end: {screen:?}"
    );
    let report = "<embedded default model> (triangle), 30 frames, seed 1\r\n";
    assert!(
        screen.contains(&format!("\x1b[2K{report}")),
        "{report:?} whole in {screen:?}"
    );
    let iso = on_a_terminal("isolate --fidelity triangle --set run.frames=70", "0").unwrap();
    assert!(
        iso.contains("rendersim isolate --fidelity triangle --set run.frames=70 ["),
        "{iso:?}"
    );
    for line in [
        "bottleneck isolation (load x0.5, vsync off, triangle fidelity):",
        "  => bottleneck: ",
    ] {
        assert!(
            !iso.contains(&format!("]{line}")),
            "{line:?} not after the spinner in {iso:?}"
        );
        assert!(iso.contains(line), "{line:?} in {iso:?}");
    }
    // Work shorter than the delay draws nothing.
    let quick = on_a_terminal("isolate models/fixed.toml", "60000").unwrap();
    assert!(!quick.contains("[0s]") && !quick.contains('\x1b'), "{quick:?}");
    // Not on a terminal: no spinner, even at once.
    let o = bin()
        .args(["isolate", "models/fixed.toml"])
        .env("RENDERSIM_PROGRESS_AFTER_MS", "0")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(o.stderr.is_empty(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!String::from_utf8_lossy(&o.stdout).contains('\x1b'));
}

/// `run --trace` at each detail of the default model: the frame number on
/// every slice, one flow a shown frame from its CPU slice through its GPU
/// slice to its display slice, each point inside its slice; the sizes in
/// the order of the details; a warning with the estimate before a trace
/// over 100 MB, none below.
#[test]
fn traces_at_three_details_with_frames_flows_and_a_size_warning() {
    let d = tempfile::tempdir().unwrap();
    let mut sizes = Vec::new();
    for detail in ["frame", "draw", "triangle"] {
        let t = d.path().join(format!("{detail}.json"));
        let o = bin()
            .args([
                "run",
                "--frames",
                "8",
                "--trace",
                t.to_str().unwrap(),
                "--trace-detail",
                detail,
            ])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("warning"), "{detail}: {err}");
        let bytes = std::fs::read(&t).unwrap();
        sizes.push(bytes.len());
        let v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        let ev = v["traceEvents"].as_array().unwrap();
        let slices: Vec<&serde_json::Value> = ev.iter().filter(|e| e["ph"] == "X").collect();
        for e in &slices {
            assert!(e["args"]["frame"].is_u64(), "{detail}: a slice without its frame: {e}");
        }
        let tids: std::collections::BTreeSet<i64> = slices.iter().map(|e| e["tid"].as_i64().unwrap()).collect();
        if detail == "frame" {
            assert_eq!(
                tids.into_iter().collect::<Vec<_>>(),
                [5, 6, 7],
                "display, CPU frames, GPU frames"
            );
        } else {
            assert!((1..=7).all(|t| tids.contains(&t)), "{detail}: {tids:?}");
        }
        if detail == "draw" {
            // Geometry and fragment work: a slice a draw, with its busy time.
            let geom: Vec<&&serde_json::Value> = slices.iter().filter(|e| e["tid"] == 3).collect();
            assert!(geom.iter().all(|e| e["name"].as_str().unwrap().starts_with("draw")));
            assert!(
                geom.iter()
                    .all(|e| e["args"]["busy_ns"].as_f64().unwrap() <= e["dur"].as_f64().unwrap() * 1000.0 + 1.0)
            );
        }
        // Flows: one id a frame, CPU frames -> GPU frames -> display.
        let mut flows: std::collections::BTreeMap<u64, Vec<&serde_json::Value>> = Default::default();
        for e in ev
            .iter()
            .filter(|e| ["s", "t", "f"].contains(&e["ph"].as_str().unwrap()))
        {
            flows.entry(e["id"].as_u64().unwrap()).or_default().push(e);
        }
        assert!(flows.len() >= 8, "{detail}: {} flows", flows.len());
        for (id, points) in &flows {
            let phases: Vec<&str> = points.iter().map(|e| e["ph"].as_str().unwrap()).collect();
            let tracks: Vec<i64> = points.iter().map(|e| e["tid"].as_i64().unwrap()).collect();
            assert!(
                phases == ["s", "t", "f"] && tracks == [6, 7, 5] || phases == ["s", "f"] && tracks == [6, 7],
                "{phases:?} {tracks:?}"
            );
            for p in points {
                let at = p["ts"].as_f64().unwrap();
                let inside = slices.iter().any(|e| {
                    e["tid"] == p["tid"]
                        && e["args"]["frame"].as_u64() == Some(id - 1)
                        && e["ts"].as_f64().unwrap() <= at
                        && at <= e["ts"].as_f64().unwrap() + e["dur"].as_f64().unwrap()
                });
                assert!(inside, "{detail}: flow point {p} is in no slice of its frame");
            }
        }
    }
    assert!(sizes[0] * 20 < sizes[1] && sizes[1] * 20 < sizes[2], "{sizes:?}");
    // 20 frames at triangle detail: about 150 MB, said before writing.
    let t = d.path().join("big.json");
    let o = bin()
        .args([
            "run",
            "--frames",
            "20",
            "--trace",
            t.to_str().unwrap(),
            "--trace-detail",
            "triangle",
        ])
        .output()
        .unwrap();
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let line = err
        .lines()
        .find(|l| l.starts_with("warning: the trace will be about "))
        .expect(&err);
    assert!(
        line.contains("(20 frames at about") && line.contains("--trace-detail draw or frame"),
        "{line}"
    );
    let mb: f64 = line["warning: the trace will be about ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let real = std::fs::metadata(&t).unwrap().len() as f64 / 1e6;
    assert!((mb / real - 1.0).abs() < 0.2, "estimate {mb} MB, written {real} MB");
    // --trace-detail without --trace is refused.
    let e = run_err(&["run", "--trace-detail", "frame"]);
    assert!(e.contains("--trace <FILE>"), "{e}");
}

/// `isolate` runs at draw fidelity unless asked otherwise, and names it;
/// on a shipped scene model draw and triangle fidelity give the same
/// verdict and changes within 0.005.
#[test]
fn isolate_at_draw_fidelity_agrees_with_triangle() {
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/one-mesh.toml");
    let m = m.to_str().unwrap();
    let get = |fid: &str| -> serde_json::Value {
        serde_json::from_str(&run_ok(&["isolate", m, "--json", "--fidelity", fid])).unwrap()
    };
    let (draw, tri, model) = (get("draw"), get("triangle"), get("model"));
    let default: serde_json::Value = serde_json::from_str(&run_ok(&["isolate", m, "--json"])).unwrap();
    assert_eq!(draw["fidelity"], "draw");
    assert_eq!(default["fidelity"], "draw");
    assert_eq!(tri["fidelity"], "triangle");
    assert_eq!(model["fidelity"], "triangle", "one-mesh.toml runs at triangle fidelity");
    assert_eq!(draw["bottleneck"], tri["bottleneck"]);
    assert_eq!(draw["tied"], tri["tied"]);
    for (a, b) in draw["variants"]
        .as_array()
        .unwrap()
        .iter()
        .zip(tri["variants"].as_array().unwrap())
    {
        assert_eq!(a["name"], b["name"]);
        let (ca, cb) = (a["change"].as_f64().unwrap(), b["change"].as_f64().unwrap());
        assert!((ca - cb).abs() < 0.005, "{}: {ca} against {cb}", a["name"]);
    }
    let e = run_err(&["isolate", m, "--fidelity", "pixel"]);
    assert!(e.contains("pixel") && e.contains("draw"), "{e}");
}

#[test]
fn hardware_files_merge_under_the_model_and_their_errors_name_their_line() {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("hw")).unwrap();
    let model = format!("hardware = \"hw/gpu.toml\"\n{SMALL}");
    let m = write(d.path(), "m.toml", &model);
    // A good hardware file: the model runs, and its model.toml holds the
    // merged keys (it runs without the hardware file).
    write(&d.path().join("hw"), "gpu.toml", "# a device\n[gpu]\nclear = \"1ms\"\n");
    let out = d.path().join("out");
    run_ok(&["run", &m, "--out", out.to_str().unwrap()]);
    let resolved = std::fs::read_to_string(out.join("model.toml")).unwrap();
    assert!(resolved.contains("clear = \"1ms\""), "{resolved}");
    assert!(!resolved.contains("hardware ="), "{resolved}");
    // A bad value in it names the hardware file and its line.
    write(
        &d.path().join("hw"),
        "gpu.toml",
        "# a device\n[gpu]\nclear = \"fast\"\n",
    );
    let err = run_err(&["run", &m]);
    assert!(err.contains("gpu.toml:3: key `gpu.clear`"), "{err}");
    // A section that is not hardware, and a missing file.
    write(&d.path().join("hw"), "gpu.toml", "[workload]\nkind = \"fixed\"\n");
    let err = run_err(&["run", &m]);
    assert!(
        err.contains("gpu.toml:1: key `workload`: is not a hardware section"),
        "{err}"
    );
    std::fs::remove_file(d.path().join("hw/gpu.toml")).unwrap();
    let err = run_err(&["run", &m]);
    assert!(err.contains("m.toml:1: key `hardware`: cannot read"), "{err}");
    // The earlier results are still there.
    assert!(out.join("summary.json").exists());
}

#[test]
fn isolate_lengthens_a_run_too_short_to_judge() {
    // The GPU-bound GeForce3 terrain with one measured frame: the CPU has
    // not yet waited for the GPU, so the verdict would be the CPU. Isolate
    // runs enough frames for the steady state, and says so.
    let m = concat!(env!("CARGO_MANIFEST_DIR"), "/models/terrain-geforce3.toml");
    let o = bin()
        .args(["isolate", m, "--set", "run.frames=2", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["bottleneck"], "geometry", "{v}");
    assert_eq!(v["frames"], 4);
    assert!(
        v["note"].as_str().unwrap().contains("run.frames raised from 2 to 4"),
        "{v}"
    );
    // As text, the note goes to stderr before the table.
    let o = bin().args(["isolate", m, "--set", "run.frames=2"]).output().unwrap();
    assert!(String::from_utf8_lossy(&o.stderr).contains("note: run.frames raised from 2 to 4"));
    assert!(String::from_utf8_lossy(&o.stdout).contains("=> bottleneck: geometry"));
    // A replay's lists fix its length: it runs as it is, with the warning.
    let r = concat!(env!("CARGO_MANIFEST_DIR"), "/models/replay.toml");
    let v: serde_json::Value = serde_json::from_str(&run_ok(&["isolate", r, "--json"])).unwrap();
    assert_eq!(v["frames"], 2, "{v}");
    assert!(
        v["note"].as_str().unwrap().contains("cannot run longer than its lists"),
        "{v}"
    );
    // A run long enough is left alone, without a note.
    let v: serde_json::Value = serde_json::from_str(&run_ok(&["isolate", m, "--json"])).unwrap();
    assert_eq!((v["frames"].as_u64(), v.get("note")), (Some(4), None), "{v}");
}

#[test]
fn standard_output_that_cannot_be_written_is_an_error_not_a_panic() {
    // issue 60 item 3: a full disk behind standard output.
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // no /dev/full on this system
    };
    for args in [
        &["run", "--json"][..],
        &["run"][..],
        &["replay", "tests/fixtures/presentmon/test_case_1.csv"][..],
        // The help and the version too (clap's own printing dropped them
        // with exit 0).
        &["--help"][..],
        &["run", "--help"][..],
        &["--version"][..],
    ] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(args)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("No space left on device") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn version_names_the_git_revision_it_was_built_from() {
    // issue 58: `--version` gives what the provenance beside results gives.
    let o = bin().arg("--version").output().unwrap();
    assert!(o.status.success());
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(
        out.starts_with(concat!("rendersim ", env!("CARGO_PKG_VERSION"))),
        "{out}"
    );
    if let Some(rev) = option_env!("RENDERSIM_GIT_REVISION") {
        assert!(out.trim_end().ends_with(&format!("({rev})")), "{out}");
    }
}

#[test]
fn completions_and_the_man_page_come_from_the_command_line_itself() {
    // Issue 58 item 2: clap's own generators, so every command is in them.
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(["completions", shell])
            .output()
            .unwrap();
        assert!(o.status.success(), "{shell}");
        let text = String::from_utf8_lossy(&o.stdout);
        for cmd in ["replay", "experiment", "perceived-speed", "compare", "no-timing"] {
            assert!(text.contains(cmd), "{shell}: no {cmd}");
        }
    }
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .arg("man")
        .output()
        .unwrap();
    assert!(o.status.success());
    let page = String::from_utf8_lossy(&o.stdout);
    assert!(page.contains(".TH rendersim 1") && page.contains("replay"), "{page}");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["completions", "tcsh"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("possible values: bash"));
}

#[test]
fn an_experiment_ends_with_its_answer_not_a_line_per_point() {
    // Issue 58 item 3's target: latency-sensitivity (2,048 points) prints at
    // most 30 lines, and they hold the Sobol' indices.
    let d = tempfile::tempdir().unwrap();
    let o = bin()
        .args(["experiment", "experiments/latency-sensitivity.toml", "--out"])
        .arg(d.path().join("ls"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.lines().count() <= 30, "{} lines:\n{text}", text.lines().count());
    assert!(
        text.contains("Sobol' indices of mean display latency (a metric in ms)"),
        "{text}"
    );
    assert!(
        text.contains("cpu.max_frames_ahead: S1 ") && text.contains(", ST "),
        "{text}"
    );
    assert!(
        text.contains("2048 points: each point's means are in points.csv"),
        "{text}"
    );
}

#[test]
fn bench_and_experiment_print_json_when_asked() {
    // Issue 58 item 3: --json on bench and experiment (calibrate had it).
    let o = bin()
        .args(["bench", "pipeline", "--scale", "0.01", "--repeats", "1", "--json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["pipeline"].is_object(), "{v}");
    let d = tempfile::tempdir().unwrap();
    let o = bin()
        .args(["experiment", "experiments/render-ahead.toml", "--json", "--out"])
        .arg(d.path().join("ra"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["experiment"]["name"], "render-ahead");
    assert_eq!(v["experiment"]["points"].as_array().unwrap().len(), 20);
    assert_eq!(v["experiment"]["checks_failed"], 0);
    assert!(v["out"].as_str().unwrap().ends_with("ra"));
    // The report names the model as a reader finds it (issue 58 item 4: it
    // said `experiments/../models/fixed.toml`).
    let report = std::fs::read_to_string(d.path().join("ra/report.md")).unwrap();
    assert!(report.contains("- model: `models/fixed.toml`"), "{report}");
}

#[test]
fn seeds_past_what_a_model_holds_blame_the_experiment_s_base_seed() {
    // Issue 60 item 9: the last seed of base_seed + replications - 1 past
    // i64::MAX (a TOML integer's largest) blamed the model file's line.
    let root = env!("CARGO_MANIFEST_DIR");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let e = run_err(&[
        "experiment",
        &format!("{root}/tests/fuzz-cases/seed-past-i64.toml"),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        e.contains("seed-past-i64.toml") && e.contains("base_seed") && e.contains("9223372036854775808"),
        "{e}"
    );
    assert!(!e.contains("fixed.toml"), "{e}");
    assert!(!out.exists(), "nothing written");
}

/// Issue 60 item 5: a table written as an array was read field by
/// position (`display = ["144Hz"]` set the refresh, `run = [1024]` ran 1024
/// frames, a device profile's `device = [...]` loaded). Every loader now
/// refuses it, naming the key.
#[test]
fn a_table_written_as_an_array_is_refused_naming_the_key() {
    let fixed = concat!(env!("CARGO_MANIFEST_DIR"), "/models/fixed.toml");
    for (set, key) in [
        ("display=[\"144Hz\"]", "display"),
        ("run=[1024]", "run"),
        ("display.vrr=[\"48Hz\"]", "display.vrr"),
        ("noise.periodic=[[\"x\"]]", "noise.periodic"),
    ] {
        let err = run_err(&["run", fixed, "--set", set]);
        assert!(
            err.contains(&format!("key `{key}")) && err.contains("expected a table"),
            "{set}: {err}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let profile = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/models/devices/llvmpipe.toml"))
        .unwrap()
        .replace(
            "[device]\nname = \"llvmpipe\"\nvertex_cache = \"lavapipe\"\nshader_cores = 132\n",
            "device = [\"x\", \"lavapipe\", 4]\n",
        );
    assert!(
        profile.contains("device = ["),
        "the profile's [device] table was not replaced"
    );
    let p = write(dir.path(), "p.toml", &profile);
    let err = run_err(&["predict", "grid:8x8", "--device", &p]);
    assert!(err.contains("device") && err.contains("expected a table"), "{err}");
    let e = write(
        dir.path(),
        "e.toml",
        "name = \"e\"\nmodel = \"../m.toml\"\nreplications = 1\nmetric = [[\"a\", \"b\"]]\n",
    );
    let err = run_err(&["experiment", &e, "--out", &dir.path().join("o").display().to_string()]);
    assert!(
        !err.contains("RawMetric") && err.contains("metric") && err.contains("expected a table"),
        "{err}"
    );
}
