//! Display and latency oracles: vsync quantization with double and triple
//! buffering (paper 004 §4.2), mailbox, FIFO latest ready, immediate, and
//! render-ahead latency.

use crate::common;
use common::{FIXED, metric, run};

const REFRESH_MS: f64 = 1000.0 / 60.0;

#[test]
fn double_buffered_fifo_shows_a_17ms_frame_every_two_refreshes() {
    let r = run(FIXED, &["display.buffers=2"]);
    let iv = metric(&r, "metrics.display_interval_ms.mean");
    assert!((iv - 2.0 * REFRESH_MS).abs() < 1e-6, "{iv}");
    assert_eq!(
        metric(&r, "metrics.display_interval_ms.max"),
        metric(&r, "metrics.display_interval_ms.p50")
    );
    let rep = metric(&r, "metrics.repeated_refresh_fraction");
    assert!((rep - 0.5).abs() < 0.01, "{rep}");
}

#[test]
fn triple_buffering_tracks_the_gpu_and_repeats_one_refresh_in_fifty() {
    for mode in ["fifo", "mailbox"] {
        let r = run(
            FIXED,
            &[
                "display.buffers=3",
                &format!("display.present_mode=\"{mode}\""),
                "run.frames=1200",
            ],
        );
        let iv = metric(&r, "metrics.display_interval_ms.mean");
        assert!((iv - 17.0).abs() < 0.05, "{mode}: {iv}");
        let rep = metric(&r, "metrics.repeated_refresh_fraction");
        let expect = 1.0 - REFRESH_MS / 17.0;
        assert!((rep - expect).abs() < 0.002, "{mode}: {rep} vs {expect}");
        assert_eq!(metric(&r, "metrics.dropped_frames"), 0.0);
    }
}

#[test]
fn mailbox_drops_frames_produced_faster_than_refresh() {
    let r = run(
        FIXED,
        &[
            "display.buffers=3",
            "display.present_mode=\"mailbox\"",
            "workload.gpu=\"5ms\"",
            "workload.cpu=\"1ms\"",
        ],
    );
    assert!((metric(&r, "metrics.display_interval_ms.mean") - REFRESH_MS).abs() < 1e-6);
    let dropped = metric(&r, "metrics.dropped_frames");
    // Counted after warm-up, like every frame metric.
    let frames = metric(&r, "frames") - metric(&r, "warmup_frames");
    // About 3.33 frames per refresh: roughly 70% of them never shown.
    assert!((dropped / frames - (1.0 - 5.0 / REFRESH_MS)).abs() < 0.03, "{dropped}");
    // FIFO with the same load never drops and runs at refresh rate.
    let f = run(
        FIXED,
        &["display.buffers=3", "workload.gpu=\"5ms\"", "workload.cpu=\"1ms\""],
    );
    assert_eq!(metric(&f, "metrics.dropped_frames"), 0.0);
    assert!((metric(&f, "metrics.frame_time_ms.mean") - REFRESH_MS).abs() < 0.01);
}

/// Vulkan's `fifo_latest_ready` (VK_KHR_present_mode_fifo_latest_ready):
/// frames queue as in FIFO and each vertical blank shows the newest one
/// ready, releasing the older ones. With two images only one frame can
/// queue, so it is FIFO exactly; with four and a GPU three times faster than
/// the refresh, every vertical blank shows the newest frame finished before
/// it, every dropped frame was overtaken before its vertical blank, and the
/// GPU waits for images that mailbox would have freed at once.
#[test]
fn fifo_latest_ready_shows_the_newest_ready_frame_at_each_vertical_blank() {
    let latest = "display.present_mode=\"fifo_latest_ready\"";
    let timeline = |r: &rendersim::systems::frame_pipeline::PipelineRun| {
        r.records
            .iter()
            .map(|f| (f.gpu_end, f.displayed, f.dropped))
            .collect::<Vec<_>>()
    };
    let two = ["display.buffers=2", "workload.gpu=\"5ms\"", "workload.cpu=\"1ms\""];
    assert_eq!(
        timeline(&run(FIXED, &[&two[..], &[latest]].concat())),
        timeline(&run(FIXED, &two)),
        "two images: fifo_latest_ready is fifo"
    );

    let four = [
        "display.buffers=4",
        "workload.gpu=\"5ms\"",
        "workload.cpu=\"1ms\"",
        latest,
    ];
    let r = run(FIXED, &four);
    let shown: Vec<(u64, u64)> = r
        .records
        .iter()
        .filter_map(|f| f.displayed.map(|t| (t.0, f.index)))
        .collect();
    assert!(shown.len() > 100, "{}", shown.len());
    let done = |i: u64| r.records[i as usize].gpu_end.expect("every frame finished").0;
    for &(t, f) in &shown {
        assert!(done(f) <= t, "frame {f} shown before it was done");
        // No later frame was ready at this vertical blank.
        if let Some(next) = r.records.get(f as usize + 1) {
            assert!(
                next.gpu_end.unwrap().0 >= t,
                "frame {} was newer than {f} at {t}",
                f + 1
            );
        }
    }
    let mut dropped = 0;
    for d in r.records.iter().filter(|f| f.dropped) {
        dropped += 1;
        let end = d.gpu_end.unwrap().0;
        let (_, f) = shown
            .iter()
            .find(|&&(t, _)| t >= end)
            .expect("a vertical blank after it");
        assert!(*f > d.index, "frame {} dropped but nothing newer was shown", d.index);
    }
    assert!(dropped > 100, "{dropped}");
    // Every refresh shows a new frame; the display never repeats one.
    assert_eq!(metric(&r, "metrics.repeated_refreshes"), 0.0);
    // Mailbox frees a replaced frame's image at once, so its GPU never
    // waits (5 ms a frame); here the images come back only at a vertical
    // blank, and the GPU waits for them.
    let mailbox = run(FIXED, &[&four[..3], &["display.present_mode=\"mailbox\""]].concat());
    let (ft_latest, ft_mailbox) = (
        metric(&r, "metrics.frame_time_ms.mean"),
        metric(&mailbox, "metrics.frame_time_ms.mean"),
    );
    assert!((ft_mailbox - 5.0).abs() < 0.01, "{ft_mailbox}");
    assert!(ft_latest > ft_mailbox + 0.2, "{ft_latest} vs {ft_mailbox}");
}

#[test]
fn immediate_present_shows_frames_as_they_complete() {
    let r = run(FIXED, &["display.vsync=false"]);
    assert!((metric(&r, "metrics.display_interval_ms.mean") - 17.0).abs() < 1e-9);
    assert_eq!(
        r.stats.by_kind[r.stats.kind_names.iter().position(|k| *k == "vblank").unwrap()],
        0,
        "no vblank events when nothing waits for them"
    );
}

#[test]
fn render_ahead_adds_one_gpu_frame_of_latency_per_frame_in_flight() {
    let lat: Vec<f64> = (1..=5)
        .map(|n| {
            metric(
                &run(FIXED, &["display.vsync=false", &format!("cpu.max_frames_ahead={n}")]),
                "metrics.display_latency_ms.mean",
            )
        })
        .collect();
    // One frame in flight: CPU and GPU run one after the other.
    assert!((lat[0] - 22.0).abs() < 1e-9, "{lat:?}");
    for w in lat[1..].windows(2) {
        assert!((w[1] - w[0] - 17.0).abs() < 1e-9, "{lat:?}");
    }
}

#[test]
fn refresh_extremes_one_hertz_and_one_kilohertz() {
    let slow = run(
        FIXED,
        &["display.refresh=\"1Hz\"", "run.frames=12", "run.warmup_frames=2"],
    );
    assert!((metric(&slow, "metrics.display_interval_ms.mean") - 1000.0).abs() < 1e-9);
    // Every frame appears exactly on a 1 s boundary.
    assert!(
        slow.records
            .iter()
            .filter_map(|r| r.displayed)
            .all(|t| t.0 % 1_000_000_000_000 == 0)
    );
    let fast = run(FIXED, &["display.refresh=\"1000Hz\""]);
    let iv = metric(&fast, "metrics.display_interval_ms.mean");
    assert!((17.0..=18.0).contains(&iv), "{iv}");
}

#[test]
fn a_composed_flip_shows_every_frame_one_refresh_later() {
    // The compositor takes each flipped frame at its vertical blank and
    // shows it at the next one: the same frames, the same intervals, every
    // display time exactly one refresh later (`display.composition`).
    let refresh_ps = (1e12f64 / 60.0).round() as u64; // 60 Hz, to the nearest ps
    for mode in ["fifo", "mailbox"] {
        for buffers in ["2", "3"] {
            let base = [
                format!("display.present_mode=\"{mode}\""),
                format!("display.buffers={buffers}"),
                "run.frames=240".to_string(),
            ];
            let sets: Vec<&str> = base.iter().map(String::as_str).collect();
            let flip = run(FIXED, &sets);
            let mut composed_sets = sets.clone();
            composed_sets.push("display.composition=\"composed\"");
            let composed = run(FIXED, &composed_sets);
            assert_eq!(flip.records.len(), composed.records.len());
            for (a, b) in flip.records.iter().zip(&composed.records) {
                assert_eq!(a.dropped, b.dropped, "{mode} x{buffers}: frame {}", a.index);
                assert_eq!(a.gpu_end, b.gpu_end, "{mode} x{buffers}: frame {}", a.index);
                match (a.displayed, b.displayed) {
                    (Some(x), Some(y)) => assert_eq!(y.0 - x.0, refresh_ps, "{mode} x{buffers}: frame {}", a.index),
                    (x, y) => assert_eq!(x.is_some(), y.is_some()),
                }
            }
            let lat = |r| metric(r, "metrics.display_latency_ms.mean");
            assert!((lat(&composed) - lat(&flip) - refresh_ps as f64 * 1e-9).abs() < 1e-9);
            assert_eq!(
                metric(&flip, "metrics.display_interval_ms.mean"),
                metric(&composed, "metrics.display_interval_ms.mean")
            );
        }
    }
}

#[test]
fn a_composed_display_needs_a_vertical_blank() {
    let e = common::try_run(FIXED, &["display.composition=\"composed\"", "display.vsync=false"])
        .expect_err("composed without vsync is refused");
    assert!(e.contains("display.composition") && e.contains("vsync"), "{e}");
}

#[test]
fn the_compositor_takes_the_newest_ready_frame_at_its_wake_and_shows_it_refreshes_later() {
    // `[display.compositor]`: frames are taken at the compositor's wake, a
    // set time after each vertical blank, and seen `refreshes` blanks after
    // the blank before that wake. An independent replay of that rule over
    // the run's own GPU ends must give every frame's fate and screen time:
    // `fifo` takes the oldest queued frame at each wake, `mailbox` and
    // `fifo_latest_ready` the newest (the older ones are dropped).
    let t = (1e12f64 / 60.0).round() as u64;
    let wake = 3_300_000_000u64; // 3.3 ms
    for mode in ["fifo", "mailbox", "fifo_latest_ready"] {
        let r = run(
            FIXED,
            &[
                "workload.gpu=\"6.1ms\"",
                "workload.cpu=\"2ms\"",
                "display.buffers=3",
                &format!("display.present_mode=\"{mode}\""),
                "display.composition=\"composed\"",
                "display.compositor.wake=\"3.3ms\"",
                "display.compositor.refreshes=2",
                "run.frames=300",
            ],
        );
        let ends: Vec<u64> = r.records.iter().map(|f| f.gpu_end.expect("rendered").0).collect();
        assert!(ends.windows(2).all(|w| w[0] < w[1]));
        let mut expected: Vec<Option<u64>> = vec![None; ends.len()];
        let (mut next, mut k) = (0usize, 0u64);
        while next < ends.len() {
            let w = k * t + wake;
            let ready = ends[next..].iter().take_while(|&&e| e <= w).count();
            if ready > 0 {
                let take = if mode == "fifo" { next } else { next + ready - 1 };
                expected[take] = Some((k + 2) * t);
                next = take + 1;
            }
            k += 1;
        }
        let mut dropped = 0;
        for (f, e) in r.records.iter().zip(&expected) {
            assert_eq!(f.displayed.map(|d| d.0), *e, "{mode}: frame {}", f.index);
            assert_eq!(f.dropped, e.is_none(), "{mode}: frame {}", f.index);
            dropped += usize::from(f.dropped);
        }
        if mode == "fifo" {
            assert_eq!(dropped, 0);
        } else {
            assert!(
                dropped > 50,
                "{mode}: a 6.1 ms frame on a 60 Hz compositor drops most: {dropped}"
            );
        }
    }
}

#[test]
fn the_compositor_s_default_timing_is_a_wake_at_the_blank_and_one_refresh() {
    // Left out, `[display.compositor]` is `wake = 0`, `refreshes = 1`; one
    // refresh more moves every screen time by one refresh and nothing else.
    let base = [
        "display.composition=\"composed\"",
        "display.buffers=3",
        "run.frames=240",
    ];
    let plain = run(FIXED, &base);
    let mut given = base.to_vec();
    given.extend(["display.compositor.wake=\"0ms\"", "display.compositor.refreshes=1"]);
    assert_eq!(run(FIXED, &given).records, plain.records);
    let mut later = base.to_vec();
    later.push("display.compositor.refreshes=3");
    let later = run(FIXED, &later);
    let t = (1e12f64 / 60.0).round() as u64;
    for (a, b) in plain.records.iter().zip(&later.records) {
        assert_eq!(a.gpu_end, b.gpu_end);
        assert_eq!(b.displayed.map(|d| d.0), a.displayed.map(|d| d.0 + 2 * t));
    }
}

#[test]
fn a_compositor_s_timing_is_checked() {
    for (sets, says) in [
        (&["display.compositor.wake=\"1ms\""][..], "display.compositor"),
        (
            &["display.composition=\"composed\"", "display.compositor.wake=\"17ms\""][..],
            "must be below one refresh",
        ),
        (
            &["display.composition=\"composed\"", "display.compositor.refreshes=0"][..],
            "must be 1 to 16",
        ),
        (
            &["display.composition=\"composed\"", "display.compositor.delay=2"][..],
            "delay",
        ),
    ] {
        let e = common::try_run(FIXED, sets).expect_err("refused");
        assert!(e.contains(says), "{sets:?}: {e}");
    }
}
