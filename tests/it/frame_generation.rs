//! Frame generation (`[frame_generation]`,
//! crates/models/src/components/frame_generation.rs and
//! systems/frame_pipeline/display.rs) against closed forms on the fixed
//! teaching model (5 ms of CPU, 17 ms of GPU, two frames in flight) with
//! vsync off and three swap-chain images: with 1 ms of interpolation the
//! GPU finishes a rendered frame every T = 18 ms; the generated frame goes
//! out at once and the rendered one T/2 = 9 ms later, so the screen changes
//! exactly every 9 ms (twice the rendered rate), each rendered frame is
//! held back 9 ms, and its latency is 2.5 T = 45 ms against 2 T = 36 ms
//! for the same GPU time without generation: the cost is the hold-back.

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
    for w in shown.windows(2).skip(20) {
        assert_eq!(w[1] - w[0], 9 * MS, "{w:?}");
    }
    for f in r.records.iter().skip(20) {
        // Rendered every 18 ms; shown 9 ms after its GPU end; 45 ms from its input.
        let (end, shown) = (f.gpu_end.unwrap().0, f.displayed.unwrap().0);
        assert_eq!(shown - end, 9 * MS, "frame {}", f.index);
        assert_eq!(shown - f.input.0, 45 * MS, "frame {}", f.index);
    }
    assert_eq!(metric(&r, "metrics.frame_generation.hold_back_ms.mean"), 9.0);
    assert_eq!(metric(&r, "metrics.frame_generation.generated_shown"), 540.0);
    assert_eq!(metric(&r, "metrics.frame_generation.skipped"), 0.0);
    let (all, rendered) = (
        metric(&r, "metrics.frame_generation.displayed_fps"),
        metric(&r, "metrics.frame_generation.rendered_fps"),
    );
    assert!(
        (all - 1000.0 / 9.0).abs() < 0.5 && (rendered - 1000.0 / 18.0).abs() < 0.3,
        "{all} {rendered}"
    );
    assert_eq!(metric(&r, "metrics.display_latency_ms.mean"), 45.0);

    // The same GPU time per frame without generation: 2 T = 36 ms.
    let plain = fixed(&["workload.gpu=\"18ms\""]);
    assert_eq!(metric(&plain, "metrics.display_latency_ms.mean"), 36.0);
    assert!(plain.summary["metrics"].get("frame_generation").is_none());
}

#[test]
fn a_generated_frame_needs_a_free_image() {
    // Two images: the held rendered frame and the one on screen take both,
    // so every generated frame is discarded and counted.
    let r = run(FIXED, &["display.vsync=false", "frame_generation.enabled=true"]);
    assert!(r.generated.is_empty());
    assert_eq!(metric(&r, "metrics.frame_generation.skipped"), 540.0);
    assert_eq!(metric(&r, "metrics.frame_generation.generated_frames"), 0.0);
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
