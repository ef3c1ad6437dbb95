//! Multi-frame-rate latency (paper 003 §3.2): the paper's closed forms as
//! oracles, the event simulation bracketed by the bounds over all phases,
//! determinism, and clear errors for bad input.

use std::process::Command;

use rendersim::config::{ModelSource, Overrides, prepare};

use crate::common::{check_within_phase_bounds, num, summary_of as summary, try_run_any as try_run};
use serde_json::Value;

const CLUSTER: &str = include_str!("../../models/mfr-cluster.toml");
const MULTIGPU: &str = include_str!("../../models/mfr-multigpu.toml");

fn assert_within(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got}, paper {want} (tolerance {tol})"
    );
}

#[test]
fn cluster_reproduces_the_papers_hand_analysis() {
    let s = summary(CLUSTER, &["run.events=200"]);
    let a = "metrics.analytic_latency_ms";
    assert_within(num(&s, &format!("{a}.conventional.best")), 206.0, 1e-9, "conventional");
    assert_within(num(&s, &format!("{a}.fast.best")), 73.0, 1e-9, "fast client");
    // 40 + 166 + 20 + 111.1 (10 MiB at 90 MiB/s)
    assert_within(num(&s, &format!("{a}.slow.best")), 337.0, 0.2, "cluster slow client");
    assert_within(
        num(&s, &format!("{a}.slow.worst")),
        390.0,
        0.2,
        "cluster slow client, at most",
    );
    assert_within(num(&s, "metrics.terms_ms.transfer"), 111.0, 0.2, "network transfer");
    assert_within(num(&s, "metrics.rates_hz.fast_client"), 30.0, 0.4, "FC rate");
    assert_within(
        num(&s, "metrics.rates_hz.slow_client"),
        5.4,
        0.1,
        "SC rate (paper: about 6 Hz)",
    );
}

#[test]
fn multi_gpu_reproduces_the_papers_hand_analysis() {
    let s = summary(MULTIGPU, &["run.events=200"]);
    let a = "metrics.analytic_latency_ms";
    assert_within(num(&s, &format!("{a}.fast.best")), 73.0, 1e-9, "fast client");
    // The lock's 0.1 ms is the only transfer term.
    assert_within(
        num(&s, &format!("{a}.slow.best")),
        226.0,
        0.1 + 1e-9,
        "multi-GPU slow client",
    );
    assert_within(
        num(&s, &format!("{a}.slow.worst")),
        279.0,
        0.1 + 1e-9,
        "multi-GPU slow client, at most",
    );
}

#[test]
fn table2_network_transfer_times_by_resolution() {
    // Table 2: 6 / 10 / 15 MB in 66 / 111 / 166 ms. 1600x1200x8 B is
    // 14.65 MiB, which the paper rounds up to 15 MB, so 162.8 ms here.
    for (res, paper, tol) in [
        ("[1024, 768]", 66.0, 1.0),
        ("[1280, 1024]", 111.0, 0.2),
        ("[1600, 1200]", 166.0, 4.0),
    ] {
        let s = summary(CLUSTER, &["run.events=20", &format!("resolution={res}")]);
        assert_within(num(&s, "metrics.terms_ms.transfer"), paper, tol, res);
    }
}

/// The simulated distribution lies inside the bounds over all phases and
/// its mean matches the closed-form mean over independent uniform phases;
/// with thousands of events the extremes come close to the bounds.
fn check_brackets(s: &Value, path: &str) {
    check_within_phase_bounds(
        s,
        &format!("metrics.event_latency_ms.{path}"),
        &format!("metrics.analytic_latency_ms.{path}"),
        0.05,
        0.02,
    );
}

#[test]
fn simulated_distributions_stay_within_the_phase_bounds() {
    for model in [CLUSTER, MULTIGPU] {
        let s = summary(model, &["run.events=4000"]);
        for path in ["fast", "slow", "conventional"] {
            check_brackets(&s, path);
        }
        // The paper's best case is reachable only on the fast and
        // conventional paths; the slow path always adds FC's frame.
        let e = "metrics.event_latency_ms";
        let a = "metrics.analytic_latency_ms";
        assert!(num(&s, &format!("{e}.fast.min")) >= num(&s, &format!("{a}.fast.best")));
        assert!(num(&s, &format!("{e}.slow.min")) >= num(&s, &format!("{a}.slow.best")) + 33.0 - 1e-6);
        // Waiting for SC's next frame start (up to 186 ms) takes the slow
        // path beyond the paper's worst case, which assumes none.
        assert!(num(&s, &format!("{e}.slow.max")) > num(&s, &format!("{a}.slow.worst")) + 100.0);
        assert!(num(&s, &format!("{e}.slow.p99")) > num(&s, &format!("{a}.slow.worst")));
    }
}

#[test]
fn stage_breakdown_adds_up_to_the_mean_latency() {
    let s = summary(CLUSTER, &["run.events=500", "display.latency=\"5ms\""]);
    for path in ["fast", "slow", "conventional"] {
        let b = &s["metrics"]["latency_breakdown_ms"][path];
        let sum: f64 = b.as_object().unwrap().values().map(|v| v.as_f64().unwrap()).sum();
        let mean = num(&s, &format!("metrics.event_latency_ms.{path}.mean"));
        assert!((sum - mean).abs() < 1e-6, "{path}: stages {sum} vs mean {mean}");
        assert_within(num(b, "sensor_transport"), 40.0, 1e-9, "sensor transport");
        assert_within(num(b, "display"), 5.0, 1e-9, "display");
    }
    let slow = &s["metrics"]["latency_breakdown_ms"]["slow"];
    assert_within(num(slow, "render"), 166.0, 1e-9, "SC render");
    assert_within(num(slow, "readback"), 20.0, 1e-9, "SC read-back");
    assert_within(num(slow, "transfer"), 111.1, 0.1, "network transfer");
    assert_within(num(slow, "render_submission"), 10.0, 1e-9, "FC upload");
}

#[test]
fn same_seed_same_numbers_other_seed_other_numbers() {
    let strip = |mut v: Value| {
        for k in ["wall_seconds", "simulate_seconds", "events_per_second"] {
            v[k] = Value::Null;
        }
        v
    };
    let a = strip(summary(CLUSTER, &["run.events=300"]));
    let b = strip(summary(CLUSTER, &["run.events=300"]));
    let c = strip(summary(CLUSTER, &["run.events=300", "run.seed=2"]));
    assert_eq!(a, b);
    assert_ne!(a["metrics"]["event_latency_ms"], c["metrics"]["event_latency_ms"]);
}

#[test]
fn a_link_slower_than_the_slow_client_replaces_buffers_and_still_finishes() {
    // Stereo 1600x1200 over Gigabit Ethernet: 29.3 MiB in 325 ms per frame,
    // longer than SC's frame, so read-back buffers wait and get replaced.
    let s = summary(CLUSTER, &["run.events=300", "resolution=[1600, 1200]", "stereo=true"]);
    assert_eq!(s["metrics"]["link_keeps_up"], Value::Bool(false));
    assert!(s["metrics"]["buffers"]["replaced_before_sending"].as_u64().unwrap() > 0);
    assert_within(
        num(&s, "metrics.terms_ms.transfer"),
        2.0 * 162.76,
        0.1,
        "stereo transfer",
    );
    assert_eq!(num(&s, "metrics.event_latency_ms.slow.count"), 300.0);
}

#[test]
fn faster_paths_shorten_only_the_slow_path() {
    let net = summary(CLUSTER, &["run.events=2000"]);
    let fast_net = summary(CLUSTER, &["run.events=2000", "network.bandwidth=\"180MiB/s\""]);
    assert_within(
        num(&fast_net, "metrics.terms_ms.transfer"),
        55.56,
        0.01,
        "doubled bandwidth",
    );
    for path in ["loopback", "shared_copy", "zero_copy"] {
        let s = summary(CLUSTER, &["run.events=2000", &format!("transfer.path=\"{path}\"")]);
        let (n, p) = (
            num(&net, "metrics.event_latency_ms.slow.mean"),
            num(&s, "metrics.event_latency_ms.slow.mean"),
        );
        let saved = num(&net, "metrics.terms_ms.transfer") - num(&s, "metrics.terms_ms.transfer");
        assert!(
            (n - p - saved).abs() < 0.03 * n,
            "{path}: {n} -> {p}, transfer saved {saved}"
        );
        assert_eq!(
            net["metrics"]["event_latency_ms"]["fast"], s["metrics"]["event_latency_ms"]["fast"],
            "{path}: the fast path does not use the link"
        );
    }
}

#[test]
fn bad_input_gives_clear_errors() {
    for (sets, needle) in [
        (vec!["resolution=[0, 1024]"], "resolution"),
        (vec!["transfer.path=\"pigeon\""], "transfer.path"),
        (vec!["network.bandwidth=\"90MB\""], "network.bandwidth"),
        (vec!["tracker.period=\"0ms\""], "tracker.period"),
        (vec!["fast_client.rendr=\"23ms\""], "rendr"),
        (vec!["run.events=0"], "run.events"),
    ] {
        let e = try_run(CLUSTER, &sets)
            .err()
            .unwrap_or_else(|| panic!("{sets:?} should fail"));
        assert!(e.contains(needle), "{sets:?}: {e}");
    }
}

#[test]
fn cli_writes_json_csv_and_trace() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    let trace = dir.join("trace.json");
    let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args([
            "run",
            "models/mfr-cluster.toml",
            "--set",
            "run.events=50",
            "--json",
            "--out",
        ])
        .arg(&dir)
        .arg("--trace")
        .arg(&trace)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    for path in ["fast", "slow"] {
        for k in ["min", "mean", "p99", "max"] {
            num(&v, &format!("metrics.event_latency_ms.{path}.{k}"));
        }
        for k in ["best", "worst"] {
            num(&v, &format!("metrics.analytic_latency_ms.{path}.{k}"));
        }
    }
    let csv = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    assert_eq!(csv.lines().count(), 51);
    assert!(csv.starts_with("event,input_ms,tracker_sample,fast_latency_ms"));
    // The resolved model runs again to the same numbers.
    let again = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["run", "--json"])
        .arg(dir.join("model.toml"))
        .output()
        .unwrap();
    assert!(again.status.success(), "{}", String::from_utf8_lossy(&again.stderr));
    let w: Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(v["metrics"]["event_latency_ms"], w["metrics"]["event_latency_ms"]);
    // One track per client; spans on a track never overlap.
    let t: Value = serde_json::from_str(&std::fs::read_to_string(&trace).unwrap()).unwrap();
    let mut by_tid: std::collections::BTreeMap<u64, Vec<(f64, f64)>> = Default::default();
    for e in t["traceEvents"].as_array().unwrap() {
        if e["ph"] == "X" {
            let ts = e["ts"].as_f64().unwrap();
            by_tid
                .entry(e["tid"].as_u64().unwrap())
                .or_default()
                .push((ts, ts + e["dur"].as_f64().unwrap()));
        }
    }
    assert_eq!(by_tid.keys().copied().collect::<Vec<_>>(), vec![2, 3, 4, 5]);
    for (tid, mut spans) in by_tid {
        spans.sort_by(|a, b| a.0.total_cmp(&b.0));
        for w in spans.windows(2) {
            assert!(w[1].0 >= w[0].1 - 1e-6, "track {tid}: {w:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn latency_experiments_pass_their_paper_checks() {
    for exp in ["mfr-latency", "transfer-paths", "vr-warping", "migration-artifacts"] {
        let dir = std::env::temp_dir().join(format!("rendersim-exp-{exp}-{}", std::process::id()));
        let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(["experiment", &format!("experiments/{exp}.toml"), "--quiet", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{exp}: {}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
        // Every experiment reports its error against the paper's numbers and its run time.
        assert!(report.contains("| error |"), "{exp}: no error column");
        assert!(report.contains("## Claims"), "{exp}: no verdicts against the paper");
        assert!(
            report.contains("wall_seconds") || report.contains("run time"),
            "{exp}: no run time"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn issue5_experiments_plot_with_labelled_axes() {
    for (exp, plot, labels) in [
        (
            "transfer-paths",
            "slow-latency",
            vec!["1024x768", "1280x1024", "1600x1200"],
        ),
        (
            "migration-artifacts",
            "artifacts",
            vec!["hover 600 ms before select", "hover 50 ms before select"],
        ),
    ] {
        let dir = std::env::temp_dir().join(format!("rendersim-plot-{exp}-{}", std::process::id()));
        let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(["experiment", &format!("experiments/{exp}.toml"), "--quiet", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{exp}: {}", String::from_utf8_lossy(&o.stderr));
        let svg = std::fs::read_to_string(dir.join(format!("{plot}.svg"))).unwrap();
        assert!(dir.join(format!("{plot}.png")).exists());
        for l in labels {
            assert!(svg.contains(l), "{exp}: axis label {l} missing");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn a_rate_cap_makes_the_client_wait_for_its_next_tick() {
    let free = summary(CLUSTER, &["run.events=4000"]);
    let s = summary(CLUSTER, &["run.events=4000", "fast_client.rate=\"20Hz\""]);
    assert_within(num(&s, "metrics.rates_hz.fast_client"), 20.0, 1e-9, "FC capped rate");
    assert_within(num(&s, "metrics.analytic_latency_ms.fast.best"), 73.0, 1e-9, "FC best");
    // Waiting for the next 50 ms tick instead of the next 33 ms frame: 8.5 ms more on average.
    let a = "metrics.analytic_latency_ms.fast";
    assert_within(
        num(&s, &format!("{a}.phase_mean")) - num(&free, &format!("{a}.phase_mean")),
        8.5,
        1e-6,
        "FC mean growth",
    );
    // Inside the bounds over all phases. (20 Hz and the 50 Hz tracker are
    // commensurate, so the waits take few values: the mean is compared loosely.)
    let within = |s: &Value, path: &str| {
        let e = format!("metrics.event_latency_ms.{path}");
        let a = format!("metrics.analytic_latency_ms.{path}");
        let (min, mean, max) = (
            num(s, &format!("{e}.min")),
            num(s, &format!("{e}.mean")),
            num(s, &format!("{e}.max")),
        );
        assert!(min >= num(s, &format!("{a}.phase_min")) - 1e-6, "{path}: min {min}");
        assert!(max <= num(s, &format!("{a}.phase_max")) + 1e-6, "{path}: max {max}");
        let mu = num(s, &format!("{a}.phase_mean"));
        assert!((mean - mu).abs() < 0.06 * mu, "{path}: mean {mean} vs {mu}");
    };
    within(&s, "fast");
    within(&s, "slow");
    assert!(num(&s, "metrics.event_latency_ms.fast.mean") > num(&free, "metrics.event_latency_ms.fast.mean") + 5.0);
    // FC frames: one per 50 ms (the run covers the same simulated time).
    let frames = num(&s, "metrics.frames.fast_client");
    let free_frames = num(&free, "metrics.frames.fast_client");
    assert_within(frames / free_frames, 33.0 / 50.0, 0.05, "FC frames, capped vs free");
    // A slow-client cap: 186 ms frames on a 200 ms grid.
    let sc = summary(CLUSTER, &["run.events=500", "slow_client.rate=\"200ms\""]);
    assert_within(num(&sc, "metrics.rates_hz.slow_client"), 5.0, 1e-9, "SC capped rate");
    within(&sc, "slow");
    // Unset rates keep the paper's numbers (checked above); a bad rate is a clear error.
    let e = try_run(CLUSTER, &["fast_client.rate=\"fast\""]).unwrap_err();
    assert!(e.contains("fast_client.rate"), "{e}");
}

#[test]
fn network_bandwidth_units_pin_the_papers_mebibytes() {
    // The paper's "90 MB/s" are 2^20-byte MB: 10 MiB in 111 ms is written "90MiB/s".
    let mib = summary(CLUSTER, &["run.events=50", "network.bandwidth=\"90MiB/s\""]);
    assert_within(num(&mib, "metrics.terms_ms.transfer"), 111.111, 0.001, "90MiB/s");
    // The unit parser is SI: "90MB/s" is 90e6 B/s, and 10 MiB takes 116.5 ms.
    let si = summary(CLUSTER, &["run.events=50", "network.bandwidth=\"90MB/s\""]);
    assert_within(num(&si, "metrics.terms_ms.transfer"), 116.508, 0.001, "90MB/s");
}

#[test]
fn deferred_shading_moves_bytes_and_shading_to_the_fast_client() {
    let plain = summary(CLUSTER, &["run.events=500"]);
    let s = summary(CLUSTER, &["run.events=500", "deferred.enabled=true"]);
    // 144 bits instead of 64 per pixel: 2.25 times the bytes on every buffer term.
    assert_eq!(s["frame_bytes"].as_u64().unwrap(), 1280 * 1024 * 18);
    assert_within(
        num(&s, "metrics.terms_ms.transfer"),
        2.25 * num(&plain, "metrics.terms_ms.transfer"),
        0.01,
        "transfer",
    );
    // FC shades 4 lights x 1.31 Mpixel at 0.39 ns.
    assert_within(
        num(&s, "deferred_shading_ms"),
        4.0 * 1280.0 * 1024.0 * 0.39e-6,
        1e-6,
        "shading",
    );
    // 22.5 MiB over Gigabit Ethernet (250 ms) no longer keeps up with SC (211 ms).
    assert_eq!(s["metrics"]["link_keeps_up"], Value::Bool(false));
    let z = summary(MULTIGPU, &["run.events=500", "deferred.enabled=true"]);
    assert_eq!(z["metrics"]["link_keeps_up"], Value::Bool(true));
    assert!(try_run(CLUSTER, &["deferred.enabled=true", "deferred.normal_bits=50"]).is_err());
}

const MIGRATION: &str = include_str!("../../models/mfr-migration.toml");

#[test]
fn bookkeeping_removes_the_release_artifact_and_over_prediction_the_selection_artifact() {
    let s = summary(MIGRATION, &[]);
    let m = &s["metrics"]["migration"];
    let n = |p: &str, k: &str| m[p][k].as_u64().unwrap();
    // Original system: dragging right after selecting shows the object
    // twice until SC's image drops it; after release it is missing until
    // SC's image holds it again.
    assert!(
        n("plain", "doubled_frames") > 0 && n("plain", "missing_frames") > 0,
        "{m}"
    );
    // About one slow-path latency of FC frames (33 ms each) after release.
    let frames = n("plain", "missing_frames") as f64 * 33.0;
    let (lo, hi) = (
        num(&s, "metrics.analytic_latency_ms.slow.phase_min") - 2.0 * 33.0,
        num(&s, "metrics.analytic_latency_ms.slow.phase_max"),
    );
    assert!(
        frames >= lo && frames <= hi,
        "{frames} ms of missing frames vs [{lo}, {hi}]"
    );
    // Over-prediction (600 ms of hovering) and Table 3: no artifact.
    assert_eq!(
        (n("bookkeeping", "doubled_frames"), n("bookkeeping", "missing_frames")),
        (0, 0),
        "{m}"
    );
    // Selecting 50 ms after hovering leaves SC no time: the object shows twice
    // (the paper's shadow-object case), but never goes missing.
    let quick = summary(
        MIGRATION,
        &[
            "migration.script=[{at=\"2s\",action=\"hover\"},{at=\"2.05s\",action=\"select\"},{at=\"2.06s\",action=\"drag\"},{at=\"4s\",action=\"release\"},{at=\"4.01s\",action=\"leave\"}]",
        ],
    );
    let q = &quick["metrics"]["migration"]["bookkeeping"];
    assert!(q["doubled_frames"].as_u64().unwrap() > 0, "{q}");
    assert_eq!(q["missing_frames"].as_u64().unwrap(), 0, "{q}");
    // Scripts out of order are refused with the key.
    let e = try_run(
        MIGRATION,
        &["migration.script=[{at=\"3s\",action=\"hover\"},{at=\"2s\",action=\"select\"}]"],
    )
    .err()
    .unwrap();
    assert!(e.contains("migration.script.1.at"), "{e}");
}

#[test]
fn records_past_run_max_memory_end_the_run_with_an_error_naming_the_key() {
    use rendersim::engine::{Limits, Scheduler, run};
    use rendersim::systems::SystemError;
    use rendersim::systems::multi_rate::{MultiRate, MultiRateConfig};
    let cfg: MultiRateConfig = toml::from_str(CLUSTER).unwrap();
    let mut m = MultiRate::new(&rendersim::systems::checked::Checked::new(cfg).unwrap());
    // The input records grow with the input events; 4 KiB is too little for
    // the model's 5000 (the run itself refuses this up front; the model
    // checks as it goes too).
    m.max_memory = 4096;
    let mut s = Scheduler::new();
    m.start(&mut s).unwrap();
    let e = run(&mut m, &mut s, Limits::default()).unwrap_err();
    match e {
        SystemError::Invalid { key, message } => {
            assert_eq!(key, "run.max_memory");
            assert!(
                message.contains("4 KiB") && message.contains("input events"),
                "{message}"
            );
        }
        other => panic!("{other}"),
    }
}

#[test]
fn memory_is_bounded_by_the_input_events_not_the_simulated_span() {
    use rendersim::systems::multi_rate::run::estimate_memory;
    let est = |sets: &[&str]| {
        let m = prepare(ModelSource::from_text("m.toml", CLUSTER), &Overrides::with_sets(sets)).unwrap();
        estimate_memory(&toml::Value::Table(m.table).try_into().unwrap()).0
    };
    // The same events over a thousand times the span: the same estimate.
    assert_eq!(est(&[]), est(&["input.mean_interval=\"300s\""]));
    assert!(est(&["run.events=10000"]) > est(&["run.events=100"]));
    let e = try_run(CLUSTER, &["run.max_memory=\"64KiB\""]).unwrap_err();
    assert!(
        e.contains("run.max_memory") && e.contains("64 KiB") && e.contains("5000 input events"),
        "{e}"
    );
    // 20 inputs 100 s apart: over 2000 s simulated (about 10^5 frames of each
    // client) within 64 KiB of records; every input is followed on every path.
    let s = try_run(
        CLUSTER,
        &[
            "run.events=20",
            "input.mean_interval=\"100s\"",
            "run.max_memory=\"64KiB\"",
        ],
    )
    .unwrap()
    .summary()
    .clone();
    assert!(s["simulated_seconds"].as_f64().unwrap() > 1000.0, "{s}");
    assert!(s["metrics"]["frames"]["fast_client"].as_u64().unwrap() > 50_000, "{s}");
    for path in ["fast", "slow", "conventional"] {
        assert_eq!(s["metrics"]["event_latency_ms"][path]["count"], 20, "{path}");
    }
    // The shipped model runs unchanged under the default.
    assert!(try_run(CLUSTER, &["run.events=200"]).is_ok());
}

/// Issue 13 item 5: with stereo on, the link (222 ms per 20 MiB image) is
/// slower than SC (206 ms), the slow path's closed forms assume it is not,
/// and the summary and the report say so next to the numbers, with the
/// bound that holds (`phase_max + T_send`) — which the simulation respects.
#[test]
fn closed_forms_say_where_they_hold_with_stereo_on() {
    for (sets, events) in [
        (vec!["stereo=true"], 3000),
        (vec!["stereo=true", "resolution=[1600, 1200]"], 1500),
        (vec!["stereo=true", "run.seed=7"], 1500),
    ] {
        let events_set = format!("run.events={events}");
        let mut all = sets.clone();
        all.push(&events_set);
        let s = summary(CLUSTER, &all);
        let a = "metrics.analytic_latency_ms.slow";
        assert_eq!(s["metrics"]["analytic_latency_ms"]["slow"]["holds"], Value::Bool(false));
        assert_eq!(s["metrics"]["analytic_latency_ms"]["fast"]["holds"], Value::Bool(true));
        let (max, phase_max, bound) = (
            num(&s, "metrics.event_latency_ms.slow.max"),
            num(&s, &format!("{a}.phase_max")),
            num(&s, &format!("{a}.bound_max")),
        );
        let x = num(&s, "metrics.terms_ms.transfer");
        assert!((bound - (phase_max + x)).abs() < 1e-6, "{bound} vs {phase_max} + {x}");
        assert!(
            max <= bound + 1e-6,
            "{sets:?}: simulated max {max} over the bound that holds {bound}"
        );
        let caveats = s["metrics"]["closed_form_caveats"].as_array().unwrap();
        assert_eq!(caveats.len(), 1, "{caveats:?}");
        assert!(caveats[0].as_str().unwrap().contains("does not keep up"));
        if sets.len() == 1 {
            // The issue's numbers: 985.9 ms simulated against 780.2 ms.
            assert!(max > phase_max, "{max} vs {phase_max}: the failing bound fails here");
            assert_within(phase_max, 780.2, 0.1, "keeps-up bound");
            assert_within(bound, 1002.4, 0.1, "bound that holds");
        }
    }
    // Mono: everything holds and no caveat is given.
    let s = summary(CLUSTER, &["run.events=200"]);
    assert_eq!(s["metrics"]["analytic_latency_ms"]["slow"]["holds"], Value::Bool(true));
    assert_eq!(s["metrics"]["closed_form_caveats"], Value::Array(Vec::new()));
    // The report says it next to the slow row.
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("mfr.toml");
    std::fs::write(&model, CLUSTER).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--set",
            "stereo=true",
            "--set",
            "run.events=300",
        ])
        .output()
        .unwrap();
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let slow = lines.iter().position(|l| l.trim_start().starts_with("slow")).unwrap();
    assert!(
        lines[slow + 1].contains("closed forms do not hold") && lines[slow + 1].contains("1002.4"),
        "{text}"
    );
    assert!(text.contains("note: slow path: the link does not keep up"), "{text}");
}
