//! The input side shared by the latency systems (multi-frame-rate, paper 003
//! §3; VR, paper 001): input events as a Poisson process, captured by a
//! tracker that samples periodically and delivers each sample a fixed
//! latency later, and a run measured in input events. Each system gives its
//! own defaults (the papers' numbers) through [`Defaults`].

use std::marker::PhantomData;

use serde::{Deserialize, Serialize};

use crate::config::Bytes;
use crate::engine::{Duration, Time};
use crate::limits::{DEFAULT_MAX_MEMORY, over_memory_message};
use crate::systems::error::{SystemError, invalid};

/// A latency system's defaults for the shared tables.
pub trait Defaults {
    /// `run.warmup`, milliseconds.
    const WARMUP_MS: u64;
    /// `tracker.period`, milliseconds.
    const TRACKER_PERIOD_MS: u64;
    /// `tracker.latency`, milliseconds.
    const TRACKER_LATENCY_MS: u64;
}

/// Run length and seed of a latency system: `[run]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default, bound = "")]
pub struct RunConfig<D: Defaults> {
    /// Master seed of all RNG streams.
    pub seed: u64,
    /// Input events to follow through the pipeline (default 5000).
    pub events: u64,
    /// Simulated time before the first input event (every loop running).
    pub warmup: Duration,
    /// Safety cap on handled events.
    pub max_events: Option<u64>,
    /// Most memory the input records may take: estimated from the inputs
    /// before simulating and enforced while it runs (default
    /// [`crate::limits::DEFAULT_MAX_MEMORY`], 8 GiB).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_memory: Option<Bytes>,
    #[serde(skip)]
    defaults: PhantomData<fn() -> D>,
}

impl<D: Defaults> Default for RunConfig<D> {
    fn default() -> Self {
        RunConfig {
            seed: 1,
            events: 5000,
            warmup: Duration::ms(D::WARMUP_MS),
            max_events: None,
            max_memory: None,
            defaults: PhantomData,
        }
    }
}

/// Input events: `[input]`, a Poisson process (exponential gaps drawn from
/// the `input.arrivals` stream), so each event falls at a random phase of
/// every periodic process.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InputConfig {
    /// Mean time between input events (default 97 ms).
    pub mean_interval: Duration,
}

impl Default for InputConfig {
    fn default() -> Self {
        InputConfig {
            mean_interval: Duration::ms(97),
        }
    }
}

/// The tracker: `[tracker]`, samples every `period`; a sample reaches the
/// application `latency` later.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default, bound = "")]
pub struct TrackerConfig<D: Defaults> {
    /// Time between tracker samples.
    pub period: Duration,
    /// Sample-to-application latency.
    pub latency: Duration,
    #[serde(skip)]
    defaults: PhantomData<fn() -> D>,
}

impl<D: Defaults> Default for TrackerConfig<D> {
    fn default() -> Self {
        TrackerConfig {
            period: Duration::ms(D::TRACKER_PERIOD_MS),
            latency: Duration::ms(D::TRACKER_LATENCY_MS),
            defaults: PhantomData,
        }
    }
}

impl<D: Defaults> TrackerConfig<D> {
    /// The sample that captures an input at `t`: the first taken at or
    /// after it (sample `k` is taken at `k * period`).
    pub fn capturing_sample(&self, t: Time) -> u64 {
        t.0.div_ceil(self.period.0.max(1))
    }

    /// The newest sample delivered at `now` (`None` before the first).
    pub fn delivered_sample(&self, now: Time) -> Option<u64> {
        now.0.checked_sub(self.latency.0).map(|x| x / self.period.0.max(1))
    }
}

impl<D: Defaults> RunConfig<D> {
    /// Checks the run's size before anything is allocated: at least one
    /// input event (`noun`, e.g. "input event"), at most
    /// [`crate::limits::MAX_INPUT_EVENTS`], and input events that fit in
    /// the clock's range at `input`'s mean interval.
    pub fn validate(&self, input: &InputConfig, noun: &str) -> Result<(), SystemError> {
        let limit = crate::limits::MAX_INPUT_EVENTS;
        if self.events == 0 {
            return Err(invalid("run.events", format!("must be at least 1 {noun}")));
        }
        if self.events > limit {
            return Err(invalid(
                "run.events",
                format!("{} {noun}s is more than the limit of {limit}", self.events),
            ));
        }
        match crate::limits::input_span_message(self.events, self.warmup.0, input.mean_interval.0) {
            Some(message) => Err(invalid(crate::limits::INPUT_SPAN_KEYS, message)),
            None => Ok(()),
        }
    }

    /// `run.max_memory` in bytes (the default when unset), after checking
    /// the run's estimate `(bytes, what they are)` against it before
    /// simulating.
    pub fn memory_budget(&self, estimate: (u64, String)) -> Result<u64, SystemError> {
        let max = self.max_memory.map_or(DEFAULT_MAX_MEMORY, |b| b.0);
        let (bytes, parts) = estimate;
        if bytes > max {
            return Err(invalid("run.max_memory", over_memory_message(bytes, &parts, max)));
        }
        Ok(max)
    }
}

/// One periodic loop of a latency system, for its event estimate: the key
/// that sets its interval (`a|b` for several), a name, the longest its
/// iterations can take (picoseconds) and the kernel events of each.
#[derive(Debug, Clone)]
pub struct Loop {
    /// The key to blame.
    pub key: String,
    /// What it is ("the warping renderer's frames").
    pub what: &'static str,
    /// The longest an iteration takes, picoseconds.
    pub interval_ps: f64,
    /// Kernel events per iteration.
    pub events: f64,
}

/// When the last of `events` inputs arrives, picoseconds: `warmup` and the
/// same exponential gaps of mean `mean_interval` the models draw (the
/// `input.arrivals` stream of `seed`), added up.
pub fn last_arrival_ps(seed: u64, events: u64, warmup: Duration, mean_interval: Duration) -> f64 {
    use rand::Rng;
    let mut rng = crate::engine::RngStreams::new(seed).stream("input.arrivals");
    let mean = mean_interval.0 as f64;
    let mut t = warmup.0 as f64;
    for _ in 0..events {
        t += Duration::from_ps_f64(-mean * (1.0 - rng.random::<f64>()).ln()).0 as f64;
    }
    t
}

impl<D: Defaults> RunConfig<D> {
    /// Refuses, before simulating, a run whose loops certainly need more
    /// events than `run.max_events` (or [`crate::limits::DEFAULT_MAX_EVENTS`]
    /// without one): the run lasts at least until its last input arrives,
    /// and over that span each loop iterates at least once per its longest
    /// interval (less its first two, for the phase). A render step of 1 ps
    /// would otherwise run for ever. The exact arrival of the last input is
    /// computed (the models' own draws, O(run.events)) only when the
    /// expected span already comes near the bound.
    pub fn check_events(&self, input: &InputConfig, noun: &str, loops: &[Loop]) -> Result<(), SystemError> {
        let limit = self.max_events.unwrap_or(crate::limits::DEFAULT_MAX_EVENTS) as f64;
        let parts = |span: f64| {
            let mut p: Vec<crate::limits::EventPart> =
                vec![("run.events".into(), format!("{noun}s"), self.events as f64)];
            for l in loops {
                let n = (span / l.interval_ps.max(1.0) - 2.0).max(0.0) * l.events;
                p.push((l.key.clone(), l.what.to_string(), n));
            }
            p
        };
        let total = |p: &[crate::limits::EventPart]| p.iter().map(|x| x.2).sum::<f64>();
        let expected = self.warmup.0 as f64 + self.events as f64 * input.mean_interval.0 as f64;
        if total(&parts(expected)) <= limit / 4.0 {
            return Ok(());
        }
        let span = last_arrival_ps(self.seed, self.events, self.warmup, input.mean_interval);
        let advice = format!(
            "the last {noun} arrives only after {:.3e} s of simulated time; lengthen that step or lower run.events, or {}",
            span / 1e12,
            if self.max_events.is_some() {
                "raise run.max_events"
            } else {
                "set run.max_events above the estimate to run anyway"
            }
        );
        match crate::limits::events_check(&parts(span), self.max_events, &advice) {
            Some((key, message)) => Err(invalid(&key, message)),
            None => Ok(()),
        }
    }
}

/// Fails, naming `run.max_memory`, once the input records (`used` bytes,
/// `what` describes them) outgrow `max` while the run goes.
pub fn check_records(used: u64, max: u64, what: impl FnOnce() -> String) -> Result<(), SystemError> {
    if used > max {
        return Err(invalid("run.max_memory", over_memory_message(used, &what(), max)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone)]
    struct D;
    impl Defaults for D {
        const WARMUP_MS: u64 = 500;
        const TRACKER_PERIOD_MS: u64 = 5;
        const TRACKER_LATENCY_MS: u64 = 10;
    }

    #[test]
    fn defaults_come_from_the_system_and_samples_round_up() {
        let r: RunConfig<D> = toml::from_str("seed = 3").unwrap();
        assert_eq!((r.seed, r.events, r.warmup), (3, 5000, Duration::ms(500)));
        assert!(toml::from_str::<RunConfig<D>>("defaults = 1").is_err());
        let t = TrackerConfig::<D>::default();
        assert_eq!(t.capturing_sample(Time(Duration::ms(5).0)), 1);
        assert_eq!(t.capturing_sample(Time(Duration::ms(5).0 + 1)), 2);
        assert_eq!(t.delivered_sample(Time(Duration::ms(9).0)), None);
        assert_eq!(t.delivered_sample(Time(Duration::ms(15).0)), Some(1));
    }
}
