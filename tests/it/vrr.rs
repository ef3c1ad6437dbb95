//! Variable refresh (`display.vrr`, crates/models/src/components/swap_chain.rs
//! and systems/frame_pipeline/display.rs) against closed forms on the fixed
//! teaching model (5 ms of CPU, then the GPU's time per frame) on a 48-144 Hz
//! panel: a frame inside the window is shown the moment the GPU finishes it,
//! above the window the panel's fastest rate holds it, below the window the
//! panel repeats the old image at the slowest rate's deadline; and errors
//! that name the key.

use crate::common::{FIXED, metric, run, try_run, try_run_any};

/// 144 Hz and 48 Hz, in picoseconds (rounded as `Rate` rounds them).
const SHORTEST: u64 = 6_944_444_444;
const LONGEST: u64 = 20_833_333_333;

fn vrr(gpu: &str, extra: &[&str]) -> rendersim::systems::frame_pipeline::PipelineRun {
    let gpu = format!("workload.gpu=\"{gpu}\"");
    let mut sets = vec![
        "display.refresh=\"144Hz\"",
        "display.vrr.min_refresh=\"48Hz\"",
        gpu.as_str(),
    ];
    sets.extend_from_slice(extra);
    run(FIXED, &sets)
}

/// (displayed - GPU end, display interval) of every shown frame after the
/// first ten, in picoseconds.
fn shown(r: &rendersim::systems::frame_pipeline::PipelineRun) -> Vec<(u64, u64)> {
    let frames: Vec<_> = r.records.iter().filter(|f| f.displayed.is_some()).collect();
    frames
        .windows(2)
        .skip(10)
        .map(|w| {
            let d = w[1].displayed.unwrap().0;
            (d - w[1].gpu_end.unwrap().0, d - w[0].displayed.unwrap().0)
        })
        .collect()
}

#[test]
fn inside_the_window_a_frame_is_shown_when_the_gpu_finishes_it() {
    // 10 ms frames (100 Hz, inside 48-144 Hz): no wait for a vertical blank,
    // every interval exactly 10 ms, no refresh repeated.
    let r = vrr("10ms", &[]);
    let s = shown(&r);
    assert!(s.len() > 500);
    assert!(
        s.iter().all(|&(wait, iv)| wait == 0 && iv == 10_000_000_000),
        "{:?}",
        &s[..3]
    );
    assert_eq!(metric(&r, "metrics.repeated_refreshes"), 0.0);
    // A fixed 144 Hz display shows the same frames at its vertical blanks:
    // intervals of one or two refreshes, and a wait for each.
    let fixed = run(FIXED, &["display.refresh=\"144Hz\"", "workload.gpu=\"10ms\""]);
    let f = shown(&fixed);
    assert!(f.iter().any(|&(wait, _)| wait > 0));
    assert!(
        f.iter()
            .all(|&(_, iv)| iv == SHORTEST || iv == 2 * SHORTEST || iv == 2 * SHORTEST + 1)
    );
    assert!(metric(&fixed, "metrics.display_latency_ms.mean") > metric(&r, "metrics.display_latency_ms.mean"));
}

#[test]
fn above_the_window_the_fastest_refresh_holds_the_frame_rate() {
    // 4 ms frames (250 Hz): fifo waits for each scan-out to end, so every
    // interval is one 144 Hz period.
    let r = vrr("4ms", &[]);
    let s = shown(&r);
    assert!(s.iter().all(|&(_, iv)| iv == SHORTEST), "{:?}", &s[..3]);
    // Mailbox with three images shows the newest at each scan-out and drops
    // the rest: the same rate, frames dropped, none repeated.
    let m = vrr("4ms", &["display.present_mode=\"mailbox\"", "display.buffers=3"]);
    assert!(shown(&m).iter().all(|&(_, iv)| iv == SHORTEST));
    assert!(metric(&m, "metrics.dropped_frames") > 0.0);
    assert_eq!(metric(&m, "metrics.repeated_refreshes"), 0.0);
}

#[test]
fn below_the_window_the_panel_repeats_the_image_at_the_slowest_deadline() {
    // 30 ms frames (33 Hz): the panel repeats the image 20.83 ms after each
    // scan-out began, the repeat ends at 27.78 ms, and the next frame (at
    // 30 ms) is shown at once: one repeated refresh per frame.
    let r = vrr("30ms", &[]);
    let s = shown(&r);
    assert!(
        s.iter().all(|&(wait, iv)| wait == 0 && iv == 30_000_000_000),
        "{:?}",
        &s[..3]
    );
    let frac = metric(&r, "metrics.repeated_refresh_fraction");
    assert!((frac - 0.5).abs() < 0.01, "{frac}");
    // 25 ms frames arrive during the repeat's scan-out (20.83 to 27.78 ms)
    // and wait for its end. With two images the GPU waits too: every frame
    // is shown 20.83 + 6.94 = 27.78 ms after the one before, 2.78 ms after
    // the GPU finished it.
    let d = vrr("25ms", &[]);
    let s = shown(&d);
    assert!(
        s.iter()
            .all(|&(wait, iv)| iv == LONGEST + SHORTEST && wait == LONGEST + SHORTEST - 25_000_000_000),
        "{:?}",
        &s[..3]
    );
    // A third image keeps the GPU at 25 ms a frame: only some frames wait.
    let t = vrr("25ms", &["display.buffers=3", "run.frames=1200"]);
    let iv = metric(&t, "metrics.display_interval_ms.mean");
    assert!((iv - 25.0).abs() < 0.05, "{iv}");
    let waits = shown(&t).iter().filter(|s| s.0 > 0).count();
    assert!(waits > 0 && waits < shown(&t).len(), "{waits}");
}

#[test]
fn max_refresh_overrides_the_refresh_and_runs_stay_deterministic() {
    let a = run(
        FIXED,
        &[
            "display.vrr.min_refresh=\"48Hz\"",
            "display.vrr.max_refresh=\"144Hz\"",
            "workload.gpu=\"4ms\"",
        ],
    );
    assert!(shown(&a).iter().all(|&(_, iv)| iv == SHORTEST));
    let b = vrr("4ms", &[]);
    assert_eq!(
        a.records.iter().map(|f| f.displayed).collect::<Vec<_>>(),
        b.records.iter().map(|f| f.displayed).collect::<Vec<_>>()
    );
}

#[test]
fn bad_windows_and_unsupported_combinations_name_the_key() {
    let err = |sets: &[&str]| try_run(FIXED, sets).expect_err("refused");
    let e = err(&["display.vrr.min_refresh=\"60Hz\""]);
    assert!(e.contains("display.vrr.min_refresh") && e.contains("slower"), "{e}");
    let e = err(&["display.vrr.min_refresh=\"48Hz\"", "display.vrr.max_refresh=\"40Hz\""]);
    assert!(
        e.contains("display.vrr.min_refresh") && e.contains("max_refresh"),
        "{e}"
    );
    let e = err(&["display.vrr.min_refresh=\"48Hz\"", "display.vrr.max_refresh=\"2MHz\""]);
    assert!(e.contains("display.vrr.max_refresh") && e.contains("1us"), "{e}");
    let e = err(&["display.vrr.min_refresh=\"30Hz\"", "display.vsync=false"]);
    assert!(e.contains("display.vrr") && e.contains("vsync"), "{e}");
    let e = err(&["display.vrr.min_refresh=\"30Hz\"", "display.composition=\"composed\""]);
    assert!(e.contains("display.vrr") && e.contains("independent"), "{e}");
    let e = err(&["display.vrr.min_refrsh=\"30Hz\""]);
    assert!(e.contains("did you mean `min_refresh`"), "{e}");
    let e = err(&["display.vrr.max_refresh=\"144Hz\""]);
    assert!(e.contains("min_refresh"), "{e}");
    // The present system has no variable refresh.
    let present = "system = \"present\"\n[run]\nframes = 10\n[render]\ntime = \"5ms\"\n\
                   [display]\nrefresh = \"60Hz\"\nvrr = { min_refresh = \"30Hz\" }\n";
    let e = try_run_any(present, &[]).expect_err("the present system refuses vrr");
    assert!(e.contains("display.vrr") && e.contains("frame_pipeline"), "{e}");
}
