//! `rendersim bench replay`: replaying a 20,000-frame capture against
//! reading the same CSV alone (issue 26, "Accuracy and speed": well under a
//! second).
//!
//! The capture is generated (PresentMon 2 columns, `CPUStartTime` in ms):
//! one swap chain, an application at sync interval 1 on a 60 Hz display
//! that starts each frame just after a vertical blank, with CPU busy time
//! varying from 1 to 6 ms and GPU busy time from 2 to 10 ms, each frame
//! shown at the next vertical blank. It is written to memory, not to a file; reading
//! is [`Capture::parse`] of its bytes, the replay is
//! [`replay_capture`] of what was read (set-up, the frame pipeline's run,
//! the comparison), and both are timed in the same run.

use std::fmt::Write;
use std::time::Instant;

use super::BenchError;
use super::spread::{Spread, paired_ratio};
use crate::capture::presentmon::Capture;
use crate::studies::replay::{ReplayOptions, replay_capture};

/// The replay benchmark's measurements over `reps` repetitions.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReplayBench {
    /// Frames in the capture.
    pub frames: usize,
    /// Its size in bytes.
    pub bytes: usize,
    /// Repetitions.
    pub reps: usize,
    /// Seconds to read the CSV alone.
    pub read_s: Spread,
    /// Seconds to replay what was read (set-up, simulation, comparison).
    pub replay_s: Spread,
    /// Of those, the frame pipeline's run.
    pub simulate_s: Spread,
    /// Replaying over reading, repetition by repetition.
    pub ratio: Spread,
    /// Displayed-or-dropped agreement of the replay (a check that the
    /// capture replays as it was generated).
    pub agreement: f64,
}

const REFRESH_MS: f64 = 1000.0 / 60.0;

/// A PresentMon 2 capture of `frames` frames (see the module docs).
pub fn synthetic_capture(frames: usize) -> String {
    let mut s = String::from(
        "Application,ProcessID,SwapChainAddress,PresentRuntime,SyncInterval,AllowsTearing,PresentMode,\
         CPUStartTime,MsCPUBusy,MsCPUWait,MsGPULatency,MsGPUBusy,MsGPUWait,MsRenderPresentLatency,\
         MsUntilDisplayed,MsBetweenDisplayChange\n",
    );
    let mut last_shown = f64::NEG_INFINITY;
    for i in 0..frames {
        // Deterministic variation without a random stream: two incommensurate
        // sawtooths. Each frame starts 0.3 ms after a vertical blank and is
        // done with its GPU work before the next one.
        let u = (i as f64 * 0.618_034).fract();
        let v = (i as f64 * 0.414_214).fract();
        let start = i as f64 * REFRESH_MS + 0.3;
        let busy = 1.0 + 5.0 * u;
        let gpu = 2.0 + 8.0 * v;
        let present = start + busy;
        let gpu_start = start + 0.5 * busy;
        let gpu_end = gpu_start + gpu;
        let shown = (i + 1) as f64 * REFRESH_MS;
        let between = if last_shown.is_finite() {
            format!("{:.4}", shown - last_shown)
        } else {
            "NA".to_string()
        };
        last_shown = shown;
        // The CPU waits in its present until the next frame's start.
        let wait = start + REFRESH_MS - present;
        let _ = writeln!(
            s,
            "Bench.exe,1,0x1,DXGI,1,0,Hardware: Independent Flip,{start:.4},{busy:.4},{wait:.4},{:.4},{gpu:.4},0.0000,{:.4},{:.4},{between}",
            gpu_start - start,
            gpu_end - present,
            shown - present,
        );
    }
    s
}

/// The replay benchmark at `scale`: 20,000 frames at 1 (at least 200),
/// `repeats` repetitions.
pub fn replay_bench(scale: f64, repeats: usize) -> Result<ReplayBench, BenchError> {
    let frames = ((20_000.0 * scale) as usize).max(200);
    let text = synthetic_capture(frames);
    let reps = repeats.max(1);
    let (mut read, mut whole, mut sim) = (Vec::new(), Vec::new(), Vec::new());
    let mut agreement = 0.0;
    for _ in 0..reps {
        let t = Instant::now();
        let capture = Capture::parse("bench.csv", text.as_bytes()).map_err(|e| BenchError::Replay(e.to_string()))?;
        read.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let r =
            replay_capture(&capture, &ReplayOptions::default(), t).map_err(|e| BenchError::Replay(e.to_string()))?;
        whole.push(t.elapsed().as_secs_f64());
        sim.push(r.summary.simulate_seconds);
        agreement = r.summary.agreement.displayed;
    }
    Ok(ReplayBench {
        frames,
        bytes: text.len(),
        reps,
        ratio: paired_ratio(&whole, &read),
        read_s: Spread::of(&read),
        replay_s: Spread::of(&whole),
        simulate_s: Spread::of(&sim),
        agreement,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_synthetic_capture_replays_as_it_was_generated() {
        let b = replay_bench(0.01, 2).unwrap();
        assert_eq!(b.ratio.n, 2);
        assert_eq!(b.frames, 200);
        assert!(b.agreement > 0.99, "{}", b.agreement);
        let capture = Capture::parse("bench.csv", synthetic_capture(200).as_bytes()).unwrap();
        let r = replay_capture(&capture, &ReplayOptions::default(), Instant::now()).unwrap();
        let e = &r.summary.error_ms.until_displayed;
        assert!(e.max.unwrap() < 0.01, "{e:?}");
        assert!((r.summary.refresh_hz - 60.0).abs() < 0.01, "{}", r.summary.refresh_hz);
    }
}
