//! Frame generation (`[frame_generation]`,
//! crates/models/src/components/frame_generation.rs and
//! systems/frame_pipeline/display.rs) against closed forms on the fixed
//! teaching model (5 ms of CPU, 17 ms of GPU, two frames in flight) with
//! vsync off and three swap-chain images: with 1 ms of interpolation the
//! GPU finishes a rendered frame every T = 18 ms; the generated frame goes
//! out at once and the rendered one T/2 less the pacing margin (0.1 ms,
//! FSR 3's default) later, so the screen changes 8.9 and 9.1 ms apart
//! (twice the rendered rate), each rendered frame is held back 8.9 ms, and
//! its latency is 2.5 T - 0.1 = 44.9 ms against 2 T = 36 ms for the same
//! GPU time without generation: the cost is the hold-back.

use crate::common::{FIXED, metric, run, try_run};

fn fixed(extra: &[&str]) -> rendersim::systems::frame_pipeline::PipelineRun {
    let mut sets = vec!["display.vsync=false", "display.buffers=3"];
    sets.extend_from_slice(extra);
    run(FIXED, &sets)
}

const MS: u64 = 1_000_000_000;

#[test]
fn a_generated_frame_before_every_rendered_one_doubles_the_frames_shown() {
    let r = fixed(&["frame_generation.enabled=true", "frame_generation.cost=\"1ms\""]);
    // Every frame shown, rendered and generated, in screen order.
    let mut shown: Vec<u64> = r
        .records
        .iter()
        .filter_map(|f| f.displayed)
        .chain(r.generated.iter().filter_map(|g| g.displayed))
        .map(|t| t.0)
        .collect();
    shown.sort_unstable();
    assert_eq!(r.generated.len(), 599, "one before every rendered frame but the first");
    const HOLD: u64 = 9 * MS - MS / 10;
    for w in shown.windows(2).skip(20) {
        assert!(w[1] - w[0] == HOLD || w[1] - w[0] == 18 * MS - HOLD, "{w:?}");
    }
    for f in r.records.iter().skip(20) {
        // Rendered every 18 ms; shown 8.9 ms after its GPU end; 44.9 ms from its input.
        let (end, shown) = (f.gpu_end.unwrap().0, f.displayed.unwrap().0);
        assert_eq!(shown - end, HOLD, "frame {}", f.index);
        assert_eq!(shown - f.input.0, 36 * MS + HOLD, "frame {}", f.index);
    }
    assert!((metric(&r, "metrics.frame_generation.hold_back_ms.mean") - 8.9).abs() < 1e-9);
    assert_eq!(metric(&r, "metrics.frame_generation.generated_shown"), 540.0);
    assert_eq!(metric(&r, "metrics.frame_generation.generated_dropped"), 0.0);
    let (all, rendered) = (
        metric(&r, "metrics.frame_generation.displayed_fps"),
        metric(&r, "metrics.frame_generation.rendered_fps"),
    );
    assert!(
        (all - 1000.0 / 9.0).abs() < 0.5 && (rendered - 1000.0 / 18.0).abs() < 0.3,
        "{all} {rendered}"
    );
    assert!((metric(&r, "metrics.display_latency_ms.mean") - 44.9).abs() < 1e-9);

    // The same GPU time per frame without generation: 2 T = 36 ms.
    let plain = fixed(&["workload.gpu=\"18ms\""]);
    assert_eq!(metric(&plain, "metrics.display_latency_ms.mean"), 36.0);
    assert!(plain.summary()["metrics"].get("frame_generation").is_none());
}

#[test]
fn the_present_thread_waits_for_an_image_so_vsync_halves_the_rendered_rate() {
    // Vsync off: two images suffice (the game renders into the proxy's;
    // a flip frees the old front image at once), every generated frame is
    // shown.
    let r = run(FIXED, &["display.vsync=false", "frame_generation.enabled=true"]);
    assert_eq!(metric(&r, "metrics.frame_generation.generated_shown"), 540.0);
    assert!((metric(&r, "metrics.frame_generation.hold_back_ms.mean") - 8.9).abs() < 1e-9);
    // Vsync on (fifo at 60 Hz), as FSR 3's documentation says: every frame
    // is shown a refresh, so the present thread waits for images and the
    // game behind it renders at half the refresh, however fast its GPU.
    let r = run(FIXED, &["display.buffers=3", "frame_generation.enabled=true"]);
    let (all, rendered) = (
        metric(&r, "metrics.frame_generation.displayed_fps"),
        metric(&r, "metrics.frame_generation.rendered_fps"),
    );
    assert!(
        (all - 60.0).abs() < 0.3 && (rendered - 30.0).abs() < 0.2,
        "{all} {rendered}"
    );
    assert_eq!(metric(&r, "metrics.frame_generation.generated_dropped"), 0.0);
    assert_eq!(metric(&r, "metrics.dropped_frames"), 0.0);
    // Mailbox at 60 Hz: the game is not held back; a newer frame replaces
    // a queued one, generated or rendered, and both are counted.
    let r = run(
        FIXED,
        &[
            "display.buffers=3",
            "display.present_mode=\"mailbox\"",
            "frame_generation.enabled=true",
        ],
    );
    assert!(metric(&r, "metrics.frame_generation.generated_dropped") > 100.0);
    assert!(metric(&r, "metrics.dropped_frames") > 100.0);
    assert!((metric(&r, "metrics.frame_generation.hold_back_ms.mean") - 8.9).abs() < 1e-9);
}

/// The fixed model's CPU and display with a GPU that alternates 9 and
/// 25 ms a frame (so, with 1 ms of interpolation, rendered frames end 10
/// and 26 ms apart), 200 frames.
fn alternating() -> String {
    let n = 200;
    let list = |f: &dyn Fn(usize) -> &'static str| {
        let v: Vec<String> = (0..n).map(|i| format!("\"{}\"", f(i))).collect();
        format!("[{}]", v.join(", "))
    };
    let head = &FIXED[..FIXED.find("[workload]").unwrap()];
    format!(
        "{head}[workload]\nkind = \"frames\"\ncpu = {}\nsubmit = {}\ngpu = {}\npresent = {}\n",
        list(&|_| "2ms"),
        list(&|_| "0ms"),
        list(&|i| if i % 2 == 0 { "9ms" } else { "25ms" }),
        list(&|_| "0ms"),
    )
    .replace("frames = 600", "frames = 200")
}

#[test]
fn the_pacing_averages_the_last_rendered_intervals() {
    let model = alternating();
    let presents = |window: &str| {
        let r = run(
            &model,
            &[
                "display.vsync=false",
                "display.buffers=3",
                "frame_generation.enabled=true",
                "frame_generation.pacing_margin=\"0ms\"",
                "frame_generation.pacing_variance_factor=0",
                window,
            ],
        );
        let mut at: Vec<u64> = r
            .hold_backs
            .iter()
            .map(|(f, d)| r.records[*f as usize].gpu_end.unwrap().0 + d.0)
            .chain(r.generated.iter().map(|g| g.present.0))
            .collect();
        at.sort_unstable();
        // Past the warm-up, before the run's last frames.
        at[..at.len() - 4]
            .windows(2)
            .skip(40)
            .map(|w| (w[1] - w[0]) as f64 / MS as f64)
            .collect::<Vec<f64>>()
    };
    let near = |x: f64, v: &[f64]| v.iter().any(|y| (x - y).abs() < 1e-6);
    // Pacing on the last interval alone: the delta jumps between 5 and
    // 13 ms, and a present waits on the one before, so the screen changes
    // 16, 10, 5 and 5 ms apart.
    let one = presents("frame_generation.pacing_frames=1");
    assert!(one.iter().all(|g| near(*g, &[16.0, 10.0, 5.0])), "{one:?}");
    // FSR 3's seven: the average of four 10s and three 26s, or three and
    // four, halved: 118/14 and 134/14 ms, never further from 9 ms (its
    // margin and variance factor, which would shorten them, set to 0).
    let seven = presents("frame_generation.pacing_frames=7");
    assert!(
        seven.iter().all(|g| near(*g, &[118.0 / 14.0, 134.0 / 14.0])),
        "{seven:?}"
    );
    let e = try_run(FIXED, &["frame_generation.pacing_frames=0"]).unwrap_err();
    assert!(e.contains("frame_generation.pacing_frames"), "{e}");
}

#[test]
fn generated_frames_are_rows_of_frames_csv_and_bad_keys_are_named() {
    let r = fixed(&["frame_generation.enabled=true"]);
    let mut csv = Vec::new();
    r.write_frames_csv(&mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    let kinds: Vec<&str> = text.lines().skip(1).map(|l| l.split(',').nth(8).unwrap()).collect();
    assert_eq!(kinds.len(), 600 + 599);
    assert_eq!(&kinds[..4], ["Application", "Generated", "Application", "Generated"]);
    let e = try_run(FIXED, &["frame_generation.costt=\"1ms\""]).unwrap_err();
    assert!(
        e.contains("frame_generation.costt") && e.contains("did you mean `cost`"),
        "{e}"
    );
    let e = try_run(FIXED, &["frame_generation.cost=\"fast\""]).unwrap_err();
    assert!(e.contains("frame_generation.cost"), "{e}");
}
