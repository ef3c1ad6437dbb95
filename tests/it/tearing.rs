//! Tearing (`immediate`, crates/models/src/components/tearing.rs and
//! systems/frame_pipeline/display.rs) against closed forms on the fixed
//! teaching model with vsync off: 2 ms of CPU then 8 ms of GPU per frame on
//! a 62.5 Hz display (16 ms refreshes), so the GPU flips at 10 + 8k ms, at
//! phases 10 ms and 2 ms of the refresh in turn. With the default blanking
//! (4%, 0.64 ms) both tear, at (10 - 0.64) / 15.36 and (2 - 0.64) / 15.36
//! of the height: 125 torn frames a second. With 15% blanking (2.4 ms) the
//! flip at 2 ms lands in the blanking and shows whole: 62.5 a second.

use crate::common::{FIXED, metric, run, try_run, try_run_any};

const SETS: [&str; 4] = [
    "display.vsync=false",
    "display.refresh=\"62.5Hz\"",
    "workload.cpu=\"2ms\"",
    "workload.gpu=\"8ms\"",
];

fn tearing(extra: &[&str]) -> rendersim::systems::frame_pipeline::PipelineRun {
    let mut sets = SETS.to_vec();
    sets.extend_from_slice(extra);
    run(FIXED, &sets)
}

/// The expected tear line of a flip at `t` ms on 16 ms refreshes whose first
/// `b` share is blanking.
fn expected(t_ms: f64, b: f64) -> Option<f64> {
    let phase = t_ms % 16.0;
    let blank = 16.0 * b;
    (phase >= blank).then(|| (phase - blank) / (16.0 - blank))
}

#[test]
fn every_flip_off_the_vertical_blank_tears_where_the_scan_is() {
    let r = tearing(&[]);
    for f in r.records.iter().skip(60) {
        let t = f.displayed.unwrap().as_ms_f64();
        let (want, got) = (expected(t, 0.04).unwrap(), f.tear_line.unwrap());
        assert!(
            (want - got).abs() < 1e-9,
            "frame {} at {t} ms: {got} against {want}",
            f.index
        );
    }
    assert_eq!(metric(&r, "metrics.tearing.torn_frames"), 540.0);
    let per_s = metric(&r, "metrics.tearing.torn_per_second");
    assert!((per_s - 125.0).abs() < 0.5, "{per_s}");
    // Two lines, in turn: the median lies between them.
    let lo = (2.0 - 0.64) / 15.36;
    let hi = (10.0 - 0.64) / 15.36;
    let p50 = metric(&r, "metrics.tearing.tear_line.p50");
    assert!((lo..=hi).contains(&p50), "{p50}");
}

#[test]
fn a_flip_in_the_blanking_interval_shows_whole() {
    let r = tearing(&["display.blanking=0.15"]);
    let mut torn = 0;
    for f in r.records.iter().skip(60) {
        let t = f.displayed.unwrap().as_ms_f64();
        match (expected(t, 0.15), f.tear_line) {
            (None, None) => {}
            (Some(w), Some(g)) => {
                torn += 1;
                assert!((w - g).abs() < 1e-9, "frame {} at {t} ms", f.index);
            }
            (w, g) => panic!("frame {} at {t} ms: {g:?} against {w:?}", f.index),
        }
    }
    assert_eq!(torn, 270);
    assert_eq!(metric(&r, "metrics.tearing.torn_frames"), 270.0);
    let per_s = metric(&r, "metrics.tearing.torn_per_second");
    assert!((per_s - 62.5).abs() < 0.5, "{per_s}");
    // The frames table says where, and NA for a whole frame.
    let mut csv = Vec::new();
    r.write_frames_csv(&mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    let col = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == "TearLine")
        .unwrap();
    let cells: Vec<&str> = text.lines().skip(61).map(|l| l.split(',').nth(col).unwrap()).collect();
    assert!(
        cells.contains(&"NA") && cells.iter().any(|c| c.starts_with("0.558")),
        "{cells:?}"
    );
}

#[test]
fn vsync_leaves_no_tear_and_bad_blanking_names_the_key() {
    let r = run(FIXED, &[]);
    assert!(r.summary()["metrics"].get("tearing").is_none());
    assert!(r.records.iter().all(|f| f.tear_line.is_none()));
    for bad in ["1.0", "-0.1", "nan"] {
        let e = try_run(FIXED, &["display.vsync=false", &format!("display.blanking={bad}")]).unwrap_err();
        assert!(e.contains("display.blanking") && e.contains("below 1"), "{bad}: {e}");
    }
    // The present system has no tear line: it refuses the key.
    let present = include_str!("../../models/present.toml");
    let e = try_run_any(present, &["display.blanking=0.1"]).unwrap_err();
    assert!(e.contains("display.blanking"), "{e}");
}
