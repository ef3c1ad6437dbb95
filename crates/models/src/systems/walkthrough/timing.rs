//! How the preprocess's renders are timed (paper 000 §6.1-6.2, §7.1): the
//! single-object renders the heuristics' constants are fitted to, the
//! renders that fill the per-object sampling (pos) tables and the sample
//! views of view-cell sampling.
//!
//! - `timestamps`: the exact GPU time of the render, as the time-stamping
//!   extension of §6.2 would give it (a time stamp at the end of the
//!   pipeline before and after the object).
//! - `cpu_clock`: the CPU reads its clock before and after the render, the
//!   pipeline synchronised by a finish (glFinish) at both ends, as the
//!   paper's measurements were taken (§7.1). The reading is the exact time
//!   plus the finish's round trip (`estimation.clock_overhead`: the
//!   command reaching the GPU, the GPU's completion reported back, the
//!   thread woken) plus a jitter, zero-mean normal with standard deviation
//!   `estimation.clock_noise`, drawn from a named RNG stream per use
//!   (`estimation.clock.fit`, `estimation.clock.pos`,
//!   `estimation.clock.vcs`); a reading below zero is read as zero. The
//!   overhead is not subtracted (the paper only amortised it by drawing the
//!   object several times between the readings, `estimation.repeats`), so
//!   per-object times are biased up by overhead / repeats, once per object
//!   summed: the bias grows with the number of objects in a frame, which
//!   is why it hurts the city's many small objects more than the forest's
//!   few large ones (§7.2, §7.5).
//!
//! With zero overhead and zero noise a `cpu_clock` reading equals the
//! `timestamps` one exactly (no random number is drawn).

use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::engine::{Duration, RngStreams, StreamRng};
use crate::systems::error::{SystemError, invalid};

/// Largest overhead or jitter accepted (one second).
pub const MAX_CLOCK: Duration = Duration(1_000_000_000_000);

/// How preprocess renders are timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TimingMode {
    /// Exact GPU time (time stamps, §6.2).
    #[default]
    Timestamps,
    /// A CPU clock around a synchronising finish (§6.1, §7.1).
    CpuClock,
}

impl TimingMode {
    /// The mode's name in the model file.
    pub fn name(self) -> &'static str {
        match self {
            TimingMode::Timestamps => "timestamps",
            TimingMode::CpuClock => "cpu_clock",
        }
    }
}

/// Checks the clock keys.
pub fn validate(overhead: Duration, noise: Duration) -> Result<(), SystemError> {
    for (key, v) in [
        ("estimation.clock_overhead", overhead),
        ("estimation.clock_noise", noise),
    ] {
        if v > MAX_CLOCK {
            return Err(invalid(key, format!("must be at most 1s, got {v}")));
        }
    }
    Ok(())
}

/// A clock that reads render times, with its own RNG stream.
#[derive(Debug)]
pub struct Clock {
    mode: TimingMode,
    overhead: f64,
    noise: f64,
    rng: StreamRng,
    readings: u64,
}

impl Clock {
    /// The clock for one use (`stream` names its jitter's RNG stream).
    pub fn new(mode: TimingMode, overhead: Duration, noise: Duration, seed: u64, stream: &str) -> Clock {
        Clock {
            mode,
            overhead: overhead.0 as f64,
            noise: noise.0 as f64,
            rng: RngStreams::new(seed).stream(stream),
            readings: 0,
        }
    }

    /// The reading for a render whose exact time is `exact` picoseconds.
    pub fn read(&mut self, exact: f64) -> f64 {
        self.readings += 1;
        match self.mode {
            TimingMode::Timestamps => exact,
            TimingMode::CpuClock => {
                let jitter = if self.noise > 0.0 {
                    let z: f64 = StandardNormal.sample(&mut self.rng);
                    self.noise * z
                } else {
                    0.0
                };
                (exact + self.overhead + jitter).max(0.0)
            }
        }
    }

    /// Readings taken.
    pub fn readings(&self) -> u64 {
        self.readings
    }
}

/// `metrics.estimation.timing` of a `cpu_clock` run (absent with time
/// stamps).
#[derive(Debug, Clone, Serialize)]
pub struct TimingSummary {
    /// `"cpu_clock"`.
    pub mode: &'static str,
    /// The finish's overhead added to each reading, ms.
    pub overhead_ms: f64,
    /// Standard deviation of each reading's jitter, ms.
    pub noise_ms: f64,
    /// Readings taken (fit samples, pos renders, vcs sample views).
    pub readings: u64,
    /// The bias each per-object time carries: overhead / repeats, ms.
    pub per_object_bias_ms: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_overhead_and_noise_read_exactly() {
        let mut a = Clock::new(TimingMode::CpuClock, Duration(0), Duration(0), 7, "x");
        let mut b = Clock::new(TimingMode::Timestamps, Duration(5), Duration(5), 7, "x");
        for v in [0.0, 1.5, 1e9, 123456.789] {
            assert_eq!(a.read(v).to_bits(), b.read(v).to_bits());
        }
    }

    #[test]
    fn overhead_is_added_and_noise_averages_out() {
        let mut c = Clock::new(TimingMode::CpuClock, Duration(1000), Duration(100), 7, "x");
        let n = 20_000;
        let mean = (0..n).map(|_| c.read(1e6)).sum::<f64>() / n as f64;
        assert!((mean - 1e6 - 1000.0).abs() < 5.0, "{mean}");
        assert_eq!(c.readings(), n);
    }
}
