//! System-task noise (paper 000 §4.2): work of the operating system or the
//! driver that preempts the rendering thread or the GPU's command processing.
//! Periodic tasks (period, phase, jitter; e.g. the scheduler tick the paper
//! suspects: about 0.5 ms every 2-3 frames) and random tasks (Poisson
//! arrivals at a rate) with durations from any [`Dist`].

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::components::distribution::{Dist, DistError};
use crate::engine::{Duration, StreamRng, Time, TimeError};

/// Which unit a task preempts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseTarget {
    /// The application's rendering thread on the CPU.
    Cpu,
    /// The GPU driver's command processing (stalls the GPU front end).
    Gpu,
}

/// When a task arrives.
#[derive(Debug, Clone, PartialEq)]
pub enum Arrivals {
    /// At `phase + k * period + U[0, jitter)`.
    Periodic {
        /// Period.
        period: Duration,
        /// Offset of the first arrival.
        phase: Duration,
        /// Uniform random delay added to each arrival.
        jitter: Duration,
    },
    /// Poisson process with mean inter-arrival `mean_gap`.
    Poisson {
        /// Mean time between arrivals (1 / rate).
        mean_gap: Duration,
    },
}

/// One source of system tasks, with its own RNG stream.
///
/// The scheduler tick of paper 000 §4.2 as a periodic source: a 0.5 ms task
/// every 35 ms from 5 ms on (no jitter), so its arrivals are 5, 40, 75 ms.
///
/// ```
/// use rendersim_models::components::distribution::Dist;
/// use rendersim_models::components::noise::{Arrivals, NoiseSource, NoiseTarget};
/// use rendersim_engine::{Duration, RngStreams, Time};
///
/// let arrivals = Arrivals::Periodic { period: Duration::ms(35), phase: Duration::ms(5), jitter: Duration::ZERO };
/// let duration = Dist::constant(Duration::us(500));
/// let rng = RngStreams::new(1).stream("scheduler");
/// let mut tick = NoiseSource::new("scheduler".into(), NoiseTarget::Cpu, arrivals, duration, rng).unwrap();
/// let mut t = Time::ZERO;
/// let mut at_ms = Vec::new();
/// for _ in 0..3 {
///     t = tick.next_arrival(t).unwrap();
///     at_ms.push(t.as_ms_f64());
/// }
/// assert_eq!(at_ms, [5.0, 40.0, 75.0]);
/// assert_eq!(tick.draw_duration(), Duration::us(500));
///
/// // A task longer than its period would never let the unit run: refused.
/// let busy = Arrivals::Periodic { period: Duration::ms(1), phase: Duration::ZERO, jitter: Duration::ZERO };
/// let rng = RngStreams::new(1).stream("busy");
/// assert!(NoiseSource::new("busy".into(), NoiseTarget::Gpu, busy, Dist::constant(Duration::ms(2)), rng).is_err());
/// ```
#[derive(Debug, Clone)]
pub struct NoiseSource {
    /// Name (also names its RNG stream).
    pub name: String,
    /// What it preempts.
    pub target: NoiseTarget,
    /// Arrival process.
    pub arrivals: Arrivals,
    /// Task duration.
    pub duration: Dist<Duration>,
    rng: StreamRng,
    k: u64,
}

/// Errors of a noise source's parameters.
#[derive(Debug, thiserror::Error)]
pub enum NoiseError {
    /// Period or mean gap of zero would schedule infinitely many tasks.
    #[error("system task {name:?}: {what} must be greater than zero")]
    Zero {
        /// Source name.
        name: String,
        /// Which parameter.
        what: &'static str,
    },
    /// Tasks that take on average at least the time between them: the
    /// unit would never catch up and their backlog would grow without bound.
    #[error(
        "system task {name:?}: its duration (mean {duration_ms} ms) is not less than the {what} ({gap_ms} ms): the unit would never catch up and the waiting tasks would grow without bound"
    )]
    Overloaded {
        /// Source name.
        name: String,
        /// Which parameter spaces the tasks.
        what: &'static str,
        /// Mean duration, ms.
        duration_ms: f64,
        /// Mean time between arrivals, ms.
        gap_ms: f64,
    },
    /// The duration distribution is invalid.
    #[error("system task {name:?}: duration: {source}")]
    Duration {
        /// Source name.
        name: String,
        /// Why.
        source: DistError,
    },
}

impl NoiseSource {
    /// A validated source drawing from `rng`.
    pub fn new(
        name: String,
        target: NoiseTarget,
        arrivals: Arrivals,
        duration: Dist<Duration>,
        rng: StreamRng,
    ) -> Result<Self, NoiseError> {
        match &arrivals {
            Arrivals::Periodic { period, .. } if period.0 == 0 => {
                return Err(NoiseError::Zero { name, what: "period" });
            }
            Arrivals::Poisson { mean_gap } if mean_gap.0 == 0 => {
                return Err(NoiseError::Zero { name, what: "1/rate" });
            }
            _ => {}
        }
        duration.validate().map_err(|source| NoiseError::Duration {
            name: name.clone(),
            source,
        })?;
        let (what, gap) = match &arrivals {
            Arrivals::Periodic { period, .. } => ("period", period.0 as f64),
            Arrivals::Poisson { mean_gap } => ("mean time between tasks (1/rate)", mean_gap.0 as f64),
        };
        let mean = duration.mean();
        // Written so that a NaN mean is refused too.
        if mean.partial_cmp(&gap) != Some(std::cmp::Ordering::Less) {
            return Err(NoiseError::Overloaded {
                name,
                what,
                duration_ms: mean / 1e9,
                gap_ms: gap / 1e9,
            });
        }
        Ok(NoiseSource {
            name,
            target,
            arrivals,
            duration,
            rng,
            k: 0,
        })
    }

    /// The next arrival after the previous one (the first call gives the first).
    pub fn next_arrival(&mut self, prev: Time) -> Result<Time, TimeError> {
        let k = self.k;
        self.k += 1;
        match self.arrivals {
            Arrivals::Periodic { period, phase, jitter } => {
                let base = period
                    .checked_mul(k)
                    .and_then(|d| d.checked_add(phase))
                    .ok_or_else(|| TimeError::Overflow {
                        context: format!("scheduling system task {:?}", self.name),
                        at: Time::ZERO,
                        by: period,
                    })?;
                let j = if jitter.0 > 0 {
                    self.rng.random_range(0..jitter.0)
                } else {
                    0
                };
                // Arrivals never go back before the previous one.
                let t = Time::ZERO
                    .add(base, "scheduling a system task")?
                    .add(Duration(j), "jitter")?;
                Ok(t.max(prev))
            }
            Arrivals::Poisson { mean_gap } => {
                let u: f64 = self.rng.random::<f64>();
                let gap = -(1.0 - u).ln() * mean_gap.0 as f64;
                prev.add(Duration::from_ps_f64(gap), "scheduling a random system task")
            }
        }
    }

    /// Draws a task duration.
    pub fn draw_duration(&mut self) -> Duration {
        Duration::from_ps_f64(self.duration.sample(&mut self.rng))
    }
}
