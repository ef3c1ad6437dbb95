//! The present system (swap chain and display alone, paper 004 §4.2):
//! closed forms as oracles for constant and random render times, every
//! present mode, extremes (no frames, a picosecond frame against a
//! one-second refresh, zero-time frames), determinism, a trace, and errors
//! that name the key.

use std::process::Command;

use serde_json::Value;

use crate::common::{num, summary_of, try_run_any};

const MS_PER_REFRESH: f64 = 1000.0 / 60.0;

/// A present model of `frames` frames with render times `time` (a
/// distribution as TOML) and the display keys `display`.
fn model(frames: u64, time: &str, display: &str) -> String {
    format!(
        "system = \"present\"\n[run]\nframes = {frames}\nseed = 7\n[render]\ntime = {time}\n\
         [display]\nrefresh = \"60Hz\"\n{display}\n"
    )
}

fn interval(s: &Value, stat: &str) -> f64 {
    num(s, &format!("metrics.display_interval_ms.{stat}"))
}

#[test]
fn double_buffered_vsync_snaps_constant_frames_to_whole_refreshes() {
    for (t, refreshes) in [(5.0, 1.0), (16.0, 1.0), (20.0, 2.0), (40.0, 3.0)] {
        let s = summary_of(&model(120, &format!("\"{t}ms\""), "buffers = 2"), &[]);
        let want = refreshes * MS_PER_REFRESH;
        for stat in ["min", "mean", "max"] {
            assert!(
                (interval(&s, stat) - want).abs() < 1e-6,
                "{t} ms: {stat} {}",
                interval(&s, stat)
            );
        }
        // A frame starts at a vertical blank and is shown at the first one
        // after it is done: its latency is its interval.
        assert!((num(&s, "metrics.latency_ms.mean") - want).abs() < 1e-6);
        assert!((num(&s, "metrics.analytic_interval_ms") - want).abs() < 1e-6);
        assert_eq!(num(&s, "metrics.dropped_frames"), 0.0);
    }
}

#[test]
fn a_third_image_lets_the_renderer_run_at_its_own_rate() {
    // 20 ms frames: double buffering shows one every 33.3 ms, triple
    // buffering one every 20 ms on average (each at a vertical blank).
    let s = summary_of(&model(600, "\"20ms\"", "buffers = 3"), &[]);
    let n = num(&s, "metrics.displayed_frames");
    assert!(
        (interval(&s, "mean") - 20.0).abs() < MS_PER_REFRESH / (n - 1.0),
        "{}",
        interval(&s, "mean")
    );
    assert!((interval(&s, "min") - MS_PER_REFRESH).abs() < 1e-6);
    assert!((interval(&s, "max") - 2.0 * MS_PER_REFRESH).abs() < 1e-6);
    assert_eq!(num(&s, "metrics.analytic_interval_ms"), 20.0);
}

#[test]
fn mailbox_drops_frames_a_faster_renderer_replaces() {
    // 5 ms frames, three images, mailbox: the display shows the newest
    // frame at every refresh and the ones it replaced are dropped.
    let s = summary_of(&model(600, "\"5ms\"", "buffers = 3\npresent_mode = \"mailbox\""), &[]);
    assert!((interval(&s, "mean") - MS_PER_REFRESH).abs() < 1e-6);
    assert!((interval(&s, "max") - MS_PER_REFRESH).abs() < 1e-6);
    let (shown, dropped) = (num(&s, "metrics.displayed_frames"), num(&s, "metrics.dropped_frames"));
    assert!(dropped > shown, "{shown} shown, {dropped} dropped");
    // The frame shown was finished less than a refresh ago.
    assert!(num(&s, "metrics.present_to_display_ms.max") <= MS_PER_REFRESH + 1e-6);
    // fifo with the same frames drops none.
    let f = summary_of(&model(600, "\"5ms\"", "buffers = 3"), &[]);
    assert_eq!(num(&f, "metrics.dropped_frames"), 0.0);
}

#[test]
fn immediate_and_vsync_off_show_each_frame_when_it_is_done() {
    for display in ["present_mode = \"immediate\"", "vsync = false"] {
        let s = summary_of(&model(100, "\"7ms\"", display), &[]);
        assert!((interval(&s, "mean") - 7.0).abs() < 1e-6, "{display}");
        assert!((num(&s, "metrics.latency_ms.max") - 7.0).abs() < 1e-6, "{display}");
        assert_eq!(num(&s, "metrics.vblanks"), 0.0, "{display}");
    }
}

#[test]
fn random_render_times_match_the_closed_form_expectation() {
    // Uniform 12-22 ms at 60 Hz, double buffered: a frame takes two
    // refreshes when it is longer than one, P = (22 - 16.67) / 10, so the
    // mean interval is 16.67 (1 + 0.533) = 25.56 ms.
    let s = summary_of(
        &model(
            20_000,
            "{ kind = \"uniform\", min = \"12ms\", max = \"22ms\" }",
            "buffers = 2",
        ),
        &[],
    );
    let want = MS_PER_REFRESH * (1.0 + (22.0 - MS_PER_REFRESH) / 10.0);
    assert!((num(&s, "metrics.analytic_interval_ms") - want).abs() < 1e-6);
    let n = num(&s, "metrics.display_interval_ms.count");
    let se = interval(&s, "std") / n.sqrt();
    assert!(
        (interval(&s, "mean") - want).abs() < 4.0 * se,
        "{} vs {want} (se {se})",
        interval(&s, "mean")
    );
    // Lognormal frames with a tail past three refreshes: the closed form
    // sums the survival function over every refresh.
    let s = summary_of(
        &model(
            20_000,
            "{ kind = \"lognormal\", median = \"15ms\", sigma = 0.6 }",
            "buffers = 2",
        ),
        &[],
    );
    let se = interval(&s, "std") / num(&s, "metrics.display_interval_ms.count").sqrt();
    let want = num(&s, "metrics.analytic_interval_ms");
    assert!(interval(&s, "max") > 3.0 * MS_PER_REFRESH);
    assert!(
        (interval(&s, "mean") - want).abs() < 4.0 * se,
        "{} vs {want} (se {se})",
        interval(&s, "mean")
    );
}

#[test]
fn extremes_no_frames_one_frame_zero_time_and_a_picosecond_against_a_second() {
    // No frames: nothing to show, every statistic null.
    let s = summary_of(&model(0, "\"5ms\"", ""), &[]);
    assert_eq!(num(&s, "metrics.frames"), 0.0);
    assert!(s["metrics"]["display_interval_ms"]["mean"].is_null());
    assert!(s["metrics"]["latency_ms"]["mean"].is_null());
    // One frame: shown at the first vertical blank, no interval.
    let s = summary_of(&model(1, "\"5ms\"", ""), &[]);
    assert_eq!(num(&s, "metrics.displayed_frames"), 1.0);
    assert!((num(&s, "metrics.latency_ms.mean") - MS_PER_REFRESH).abs() < 1e-6);
    assert!(s["metrics"]["display_interval_ms"]["mean"].is_null());
    // Frames that take no time still wait a refresh each.
    let s = summary_of(&model(50, "\"0ms\"", ""), &[]);
    assert!((interval(&s, "mean") - MS_PER_REFRESH).abs() < 1e-6);
    // A picosecond of work against a one-second refresh: stiff, exact.
    let text = model(5, "\"1ps\"", "").replace("\"60Hz\"", "\"1Hz\"");
    let s = summary_of(&text, &[]);
    assert_eq!(interval(&s, "mean"), 1000.0);
    assert_eq!(num(&s, "metrics.render_ms.max"), 1e-9);
}

#[test]
fn same_seed_same_bytes_other_seed_other_frames() {
    let text = model(300, "{ kind = \"exponential\", mean = \"10ms\" }", "buffers = 3");
    let csv = |sets: &[&str]| {
        let mut out = Vec::new();
        try_run_any(&text, sets).unwrap().write_frames_csv(&mut out).unwrap();
        out
    };
    assert_eq!(csv(&[]), csv(&[]));
    assert_ne!(csv(&[]), csv(&["run.seed=8"]));
}

#[test]
fn bad_values_name_their_key() {
    for (sets, key) in [
        (vec!["display.buffers=1"], "display.buffers"),
        (vec!["display.refresh=\"2MHz\""], "display.refresh"),
        (vec!["run.warmup_frames=500"], "run.warmup_frames"),
        (
            vec!["render.time={ kind = \"uniform\", min = \"5ms\", max = \"1ms\" }"],
            "render.time",
        ),
        (vec!["render.time=\"-1ms\""], "render.time"),
        (vec!["run.frames=100000000000000"], "run.frames"),
        (vec!["render.colour=1"], "colour"),
    ] {
        let e = try_run_any(&model(100, "\"5ms\"", ""), &sets).unwrap_err();
        assert!(e.contains(key), "{sets:?}: {e}");
    }
}

#[test]
fn the_cli_runs_the_shipped_model_with_a_trace_and_refuses_a_bad_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["run", "models/present.toml", "--out"])
        .arg(dir.path().join("o"))
        .arg("--trace")
        .arg(dir.path().join("t.json"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let trace = std::fs::read_to_string(dir.path().join("t.json")).unwrap();
    assert!(trace.contains("\"renderer\"") && trace.contains("\"screen\""));
    let csv = std::fs::read_to_string(dir.path().join("o/frames.csv")).unwrap();
    assert!(csv.starts_with("Frame,StartMs,RenderMs,PresentMs,ShownMs,LatencyMs\n"));
    assert_eq!(csv.lines().count(), 601);
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "system = \"present\"\n[display]\nbuffers = 1\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .arg("run")
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("bad.toml") && e.contains(":3") && e.contains("display.buffers"),
        "{e}"
    );
}

#[test]
fn a_composed_display_is_refused_with_the_key_and_where_it_is_modelled() {
    let text = model(10, "\"5ms\"", "composition = \"composed\"");
    let e = try_run_any(&text, &[]).expect_err("composition is the frame pipeline's");
    assert!(e.contains("display.composition") && e.contains("frame_pipeline"), "{e}");
}
