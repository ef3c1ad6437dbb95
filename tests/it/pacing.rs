//! Frame pacing (`[pacing]`, crates/models/src/components/frame_pacing.rs):
//! the frame limiter and the low-latency pacer against closed forms on the
//! fixed teaching model (5 ms of CPU, then 17 ms of GPU per frame), and
//! errors that name the key.

use crate::common::{FIXED, metric, run, try_run};

const OFF: &str = "display.vsync=false";

fn lat(sets: &[&str]) -> (f64, f64) {
    let r = run(FIXED, sets);
    (
        metric(&r, "metrics.display_latency_ms.mean"),
        metric(&r, "metrics.display_interval_ms.mean"),
    )
}

#[test]
fn the_low_latency_pacer_gives_one_frame_of_latency_at_the_throughput_of_two() {
    // One frame in flight: CPU then GPU, 22 ms a frame and 22 ms of latency.
    assert_eq!(lat(&[OFF, "cpu.max_frames_ahead=1"]), (22.0, 22.0));
    // Two in flight: the GPU never waits (17 ms a frame), but a frame
    // waits a whole GPU frame in the queue (34 ms).
    let two = lat(&[OFF, "cpu.max_frames_ahead=2"]);
    assert!((two.0 - 34.0).abs() < 1e-9 && (two.1 - 17.0).abs() < 1e-9, "{two:?}");
    // The pacer starts each frame 5 ms before the GPU runs dry: 17 ms a
    // frame at 22 ms of latency, whatever the frames ahead allow.
    for ahead in ["2", "3", "8"] {
        let sets = [OFF, "pacing.low_latency=true", &format!("cpu.max_frames_ahead={ahead}")];
        let (l, iv) = lat(&sets);
        assert!(
            (l - 22.0).abs() < 1e-9 && (iv - 17.0).abs() < 1e-9,
            "{ahead} ahead: {l} {iv}"
        );
    }
    // The sleep is between frames: counted as its own CPU state, not as any
    // frame's wait. (Until a GPU frame has closed, frames 2 and 3, the pacer
    // has no history and the frames-in-flight limit holds them.)
    let r = run(FIXED, &[OFF, "pacing.low_latency=true"]);
    assert!(metric(&r, "metrics.states_ms.cpu.wait: pacing before a frame") > 0.0);
    let waits: Vec<(u64, u64)> = r
        .records
        .iter()
        .skip(4)
        .filter(|f| f.cpu_wait > 0)
        .map(|f| (f.index, f.cpu_wait))
        .collect();
    assert!(waits.is_empty(), "{waits:?}");
}

#[test]
fn a_frame_limiter_holds_frames_to_its_interval_and_no_faster() {
    // 50 Hz on a pipeline that could run at 58.8: 20 ms apart, and the GPU
    // idles 3 ms a frame, so no frame queues (22 ms of latency).
    for from in ["start", "present"] {
        let sets = [OFF, "pacing.limit=\"50Hz\"", &format!("pacing.limit_from=\"{from}\"")];
        let r = run(FIXED, &sets);
        let (l, iv) = (
            metric(&r, "metrics.display_latency_ms.mean"),
            metric(&r, "metrics.display_interval_ms.mean"),
        );
        assert!((iv - 20.0).abs() < 1e-9 && (l - 22.0).abs() < 1e-9, "{from}: {l} {iv}");
        let presents: Vec<u64> = r.records.iter().map(|f| f.present.0).collect();
        for w in presents.windows(2).skip(1) {
            assert_eq!(w[1] - w[0], 20_000_000_000, "{from}: presents 20 ms apart");
        }
    }
    // A limit above what the pipeline reaches changes nothing.
    let free = run(FIXED, &[OFF]);
    let limited = run(FIXED, &[OFF, "pacing.limit=\"100Hz\""]);
    assert_eq!(
        metric(&free, "metrics.display_interval_ms.mean"),
        metric(&limited, "metrics.display_interval_ms.mean")
    );
    // With the pacer the later start wins: the limiter's 20 ms.
    assert_eq!(
        lat(&[OFF, "pacing.limit=\"50Hz\"", "pacing.low_latency=true"]),
        (22.0, 20.0)
    );
}

#[test]
fn bad_pacing_keys_name_the_key() {
    for (set, needle) in [
        ("pacing.limit=\"0Hz\"", "pacing.limit"),
        ("pacing.limit=\"fast\"", "pacing.limit"),
        ("pacing.limit_from=\"end\"", "pacing.limit_from"),
        ("pacing.lmit=\"50Hz\"", "did you mean `limit`"),
    ] {
        let e = try_run(FIXED, &[set]).expect_err(set);
        assert!(e.contains(needle), "{set}: {e}");
    }
}

#[test]
fn where_a_limiter_waits_decides_the_latency() {
    // 2 ms of CPU, 5 ms of GPU, a 50 Hz limit, vsync off (a frame is shown
    // when it is presented and its GPU work is done). Every frame after the
    // first, closed form, display latency (input to screen):
    // - the game's limiter before the frame (`start`): CPU + GPU = 7 ms;
    // - in the present call (`present`): the interval, 20 ms (the GPU work
    //   went out before the wait and finished during it);
    // - the GPU driver's (`submit`): the wait holds the frame's GPU work,
    //   so the interval plus the GPU time, 25 ms.
    for (place, expected_ms) in [("start", 7.0), ("present", 20.0), ("submit", 25.0)] {
        let from = format!("pacing.limit_from=\"{place}\"");
        let r = run(
            FIXED,
            &[
                "workload.cpu=\"2ms\"",
                "workload.gpu=\"5ms\"",
                "display.vsync=false",
                "pacing.limit=\"50Hz\"",
                &from,
                "run.frames=40",
                "run.warmup_frames=1",
            ],
        );
        for f in r.records.iter().skip(1) {
            let lat = f.displayed.unwrap().since(f.input).as_ms_f64();
            assert!((lat - expected_ms).abs() < 1e-9, "{place}: frame {}: {lat} ms", f.index);
        }
        for w in r.records[1..].windows(2) {
            let iv = w[1].displayed.unwrap().since(w[0].displayed.unwrap()).as_ms_f64();
            assert!((iv - 20.0).abs() < 1e-9, "{place}: frame {}: {iv} ms apart", w[1].index);
        }
    }
}

/// A limiter in each of its places holds a scene's frames too, at both
/// fidelities: the draw-batch short cut that starts the swap's CPU work
/// once skipped the wait before the present (frames came 7.6 ms apart
/// under a 40 fps limit; found by `rendersim explore`'s lesson).
#[test]
fn a_limiter_holds_a_scene_in_every_place_at_both_fidelities() {
    for fidelity in ["draw", "triangle"] {
        for place in ["start", "present", "submit"] {
            let f = format!("fidelity=\"{fidelity}\"");
            let at = format!("pacing.limit_from=\"{place}\"");
            let sets = [
                f.as_str(),
                OFF,
                "noise.enabled=false",
                "run.frames=60",
                "pacing.limit=\"40Hz\"",
                at.as_str(),
            ];
            let r = run(crate::common::DEFAULT, &sets);
            let interval = metric(&r, "metrics.display_interval_ms.mean");
            assert!((interval - 25.0).abs() < 0.01, "{fidelity}, {place}: {interval} ms");
            // Before the start the input waits too; in the other places the
            // wait lands between input and screen.
            let latency = metric(&r, "metrics.display_latency_ms.p50");
            assert_eq!(latency < 15.0, place == "start", "{fidelity}, {place}: {latency} ms");
        }
    }
}
