//! Issue 29's runs that cannot finish, refused up front with their estimate,
//! and its errors that pointed at the wrong thing: each case the audit
//! found, through the command line (exit 2, one `error:` line naming the
//! key or option) or the library.

use std::path::Path;
use std::process::Command;

use crate::common::{num, summary_of, try_run_any};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rendersim"))
}

fn root(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel).display().to_string()
}

/// Runs and expects exit 2 with an `error:` line holding every `needle`;
/// returns stderr.
fn refused(args: &[&str], needles: &[&str]) -> String {
    let o = bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{args:?}: expected exit 2, stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.lines().filter(|l| l.starts_with("error:")).count(), 1, "{err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: {n:?} not in {err}");
    }
    err
}

#[test]
fn system_tasks_that_leave_no_cpu_are_refused() {
    // 34.99 ms every 35 ms beside the 2 Hz background task: more than the
    // whole CPU (it ran at 1 frame per 7,148 simulated seconds).
    refused(
        &[
            "run",
            "--set",
            "noise.periodic.0.duration=\"34.99ms\"",
            "--set",
            "run.frames=30",
            "--json",
        ],
        &["noise.periodic.0.duration", "CPU thread", "5%", "34.99 ms every 35 ms"],
    );
    // On the GPU front end as well.
    refused(
        &[
            "run",
            "--set",
            "noise.periodic.0.target=\"gpu\"",
            "--set",
            "noise.periodic.0.duration=\"34ms\"",
            "--set",
            "run.frames=30",
        ],
        &["noise.periodic.0.duration", "GPU front end"],
    );
}

#[test]
fn a_frame_pipeline_run_past_the_event_bound_is_refused_unless_bounded() {
    // A 1 MHz display under 100 s frames: 2e11 refreshes.
    let fixed = root("models/fixed.toml");
    let sets = [
        "--set",
        "display.refresh=\"1us\"",
        "--set",
        "workload.cpu=\"100s\"",
        "--set",
        "run.frames=2000",
    ];
    let mut args = vec!["run", fixed.as_str()];
    args.extend(sets);
    refused(&args, &["display refreshes", "1e11 events", "run.max_events"]);
    // Bounded by run.max_events, it runs and stops there.
    args.extend(["--set", "run.max_events=1000", "--json"]);
    let o = bin().args(&args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["stopped_by"], "event_limit");
}

#[test]
fn a_one_picosecond_step_is_refused_with_its_estimate() {
    for (model, key) in [
        ("models/vr-warp.toml", "renderer.render"),
        ("models/vr-warp.toml", "simulation.step"),
        ("models/vr-naive.toml", "simulation.step"),
        ("models/mfr-cluster.toml", "slow_client.render"),
        ("models/mfr-multigpu.toml", "conventional.frame"),
    ] {
        let m = root(model);
        let set = format!("{key}=\"1ps\"");
        let mut args = vec!["run", m.as_str(), "--set", &set];
        if model.contains("naive") {
            // The naive loop also waits for a stereo pair: make it short too.
            args.extend([
                "--set",
                "renderer.render=\"1ps\"",
                "--set",
                "display.field_rate=\"1ps\"",
            ]);
        }
        refused(&args, &[key, "events", "1e11 events"]);
    }
    // Against an explicit run.max_events (the run would end unfinished there).
    let m = root("models/mfr-cluster.toml");
    refused(
        &[
            "run",
            &m,
            "--set",
            "conventional.frame=\"1ms\"",
            "--set",
            "run.events=40",
            "--set",
            "run.max_events=1000",
        ],
        &["conventional.frame", "run.max_events = 1000"],
    );
}

#[test]
fn the_latency_estimate_is_a_lower_bound_of_real_runs() {
    // With run.max_events at exactly the events a run took, it is still
    // accepted (the estimate never exceeds them) and gives the same result.
    for (model, extra) in [
        ("models/vr-warp.toml", vec![]),
        ("models/vr-naive.toml", vec![]),
        ("models/mfr-cluster.toml", vec![]),
        ("models/mfr-multigpu.toml", vec![]),
        ("models/mfr-migration.toml", vec![]),
        ("models/mfr-cluster.toml", vec!["fast_client.rate=\"20Hz\""]),
        ("models/vr-warp.toml", vec!["run.warmup=\"0ms\"", "run.events=3"]),
    ] {
        let text = std::fs::read_to_string(root(model)).unwrap();
        let mut sets = vec!["run.events=300"];
        sets.extend(extra.iter().copied());
        let s = summary_of(&text, &sets);
        let events = num(&s, "events.total") as u64;
        let cap = format!("run.max_events={events}");
        sets.push(&cap);
        let again = try_run_any(&text, &sets).unwrap_or_else(|e| panic!("{model} {extra:?}: {e}"));
        assert_eq!(num(&again.summary(), "events.total") as u64, events, "{model}");
    }
}

#[test]
fn predict_layers_have_a_limit() {
    let device = root("models/devices/nvidia-h200.toml");
    refused(
        &["predict", "grid:8x8", "--device", &device, "--layers", "4294967295"],
        &["--layers 4294967295", "1024"],
    );
    refused(
        &["predict", "grid:512x512", "--device", &device, "--layers", "1000"],
        &["--layers 1000", "524288000 triangles", "134217728"],
    );
    let o = bin()
        .args(["predict", "grid:8x8", "--device", &device, "--layers", "1024", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_bad_calibrate_vertex_cache_names_that_option() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.toml").display().to_string();
    let csv = root("docs/measurements/nvidia-h200/load-grid.csv");
    for bad in ["bogus", "fifo:0", "direct:4294967295,1", "meshopt:1,2"] {
        let e = refused(
            &["calibrate", &csv, "--out", &out, "--vertex-cache", bad],
            &["--vertex-cache"],
        );
        assert!(!e.contains("--policy"), "{e}");
    }
}

#[test]
fn sortbuf_scene_without_a_model_file_names_the_argument() {
    let e = refused(
        &["sortbuf", "scene::state", "--buffer", "4", "--strategy", "lru"],
        &["scene::state", "names no model file", "scene:MODEL.toml"],
    );
    assert!(!e.contains("Is a directory"), "{e}");
    let models = root("models");
    refused(
        &[
            "sortbuf",
            &format!("scene:{models}"),
            "--buffer",
            "4",
            "--strategy",
            "lru",
        ],
        &["is a folder, not a model file"],
    );
}

#[test]
fn a_zero_time_transfer_is_refused_not_reported_as_null() {
    let m = root("models/mfr-multigpu.toml");
    refused(
        &["run", &m, "--set", "zero_copy.lock=\"0ms\"", "--json"],
        &["zero_copy.lock", "rates_hz.transfer", "infinite"],
    );
    // The shipped lock reports a number.
    let text = std::fs::read_to_string(&m).unwrap();
    let s = summary_of(&text, &["run.events=20"]);
    assert!(num(&s, "metrics.rates_hz.transfer") > 0.0);
}

#[test]
fn a_trace_of_a_system_without_trace_events_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (model, system) in [
        ("models/walkthrough-city.toml", "walkthrough"),
        ("experiments/state-sorting/lru-worst.toml", "state_sorting"),
    ] {
        let trace = dir.path().join(format!("{system}.json"));
        let t = trace.display().to_string();
        refused(
            &["run", &root(model), "--trace", &t, "--json"],
            &["--trace", &format!("system \"{system}\" writes no trace events")],
        );
        assert!(!trace.exists(), "{system}: an empty trace was written");
    }
}

/// A trace into a FIFO whose reader reads a little and closes it: one
/// error line and exit 2 (the process was killed by SIGPIPE, silently).
#[cfg(unix)]
#[test]
fn a_trace_fifo_closed_by_its_reader_ends_with_an_error() {
    use std::io::Read;
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("trace.fifo");
    let c = std::ffi::CString::new(fifo.as_os_str().as_bytes()).unwrap();
    // SAFETY: mkfifo on a NUL-terminated path inside the temp folder.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let reader_path = fifo.clone();
    let reader = std::thread::spawn(move || {
        // Opening waits for the writer; read a little, then close.
        let mut f = std::fs::File::open(&reader_path).unwrap();
        let mut buf = [0u8; 100];
        let _ = f.read(&mut buf);
    });
    let o = bin()
        .args([
            "run",
            "--set",
            "run.frames=40",
            "--trace",
            &fifo.display().to_string(),
            "--json",
        ])
        .output()
        .unwrap();
    // A reader still waiting (the run failed before opening the FIFO) is
    // let go by opening the other end without blocking.
    {
        use std::os::unix::fs::OpenOptionsExt;
        let _ = std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(&fifo);
    }
    reader.join().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "status {:?}, stderr: {err}", o.status);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].starts_with("error: writing trace")
            && lines[0].contains("trace.fifo")
            && lines[0].contains("reader closed the pipe"),
        "{err}"
    );
}

#[test]
fn a_walkthrough_whose_runs_cannot_finish_is_refused_before_its_preprocess() {
    // Issue 60 item 6: every frame and preprocess render is a pipeline run of
    // its own, so a swap of 10^6 s is about 6e7 vertical blanks per run over
    // 10,000 fit renders (it ran for hours).
    let model = root("models/walkthrough-city.toml");
    refused(
        &[
            "run",
            &model,
            "--set",
            "gpu.swap=\"1000000s\"",
            "--set",
            "run.frames=5",
            "--json",
        ],
        &[
            "key `gpu.swap`",
            "e11 events",
            "11377 preprocess renders",
            "1000000s",
            "for a walkthrough",
        ],
    );
    // With pos alone (no fit), the pos tables' least renders count: a
    // longer swap is refused the same way.
    refused(
        &[
            "run",
            &model,
            "--set",
            "gpu.swap=\"10000000s\"",
            "--set",
            "estimation.estimators=[\"pos\"]",
            "--set",
            "run.frames=5",
            "--json",
        ],
        &["key `gpu.swap`", "pos"],
    );
}
