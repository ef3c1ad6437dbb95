//! The VR pipeline as a kernel model (paper 001).
//!
//! `naive`: one loop — read the newest tracker sample, simulate, render,
//! wait for the swap lock (the next stereo-pair boundary of the
//! field-sequential display), swap; the next loop starts at the swap.
//!
//! `warp`: three loops. The simulation steps free-running and publishes
//! object transforms; the application renderer renders full frames (20 Hz)
//! from the newest published state; the warping renderer starts at every
//! stereo-pair boundary (60 Hz), reads the newest camera pose from the
//! tracker and the newest object transforms from the simulation, re-projects
//! the newest application frame and swaps at the next boundary.
//!
//! Tracker sample `k` is taken at `k * P` and available at `k * P + L`; a
//! motion at `t` is captured by the first sample at or after `t`.

use rand::Rng;

use crate::engine::{
    Control, Duration, EngineError, EventKind, Model, RngStreams, Scheduler, StreamRng, Time, TimeError,
};

use super::config::{Scheme, VrConfig};

/// Errors of a VR run.
#[derive(Debug, thiserror::Error)]
pub enum VrError {
    /// Kernel error.
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// A model value the simulator cannot use.
    #[error("{key}: {message}")]
    Invalid {
        /// Dotted key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The run ended before every motion was visible.
    #[error("the run stopped at {at} before every motion event was visible ({state})")]
    Unfinished {
        /// When.
        at: Time,
        /// What was missing.
        state: String,
    },
}

impl From<TimeError> for VrError {
    fn from(e: TimeError) -> Self {
        VrError::Engine(EngineError::Time(e))
    }
}

/// The events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ev {
    /// A head/object motion happens.
    Input,
    /// Naive loop: frame start (tracker read).
    LoopStart,
    /// Naive loop: simulation done.
    LoopSimEnd,
    /// Naive loop: rendering done (swap lock entered).
    LoopRenderEnd,
    /// Naive loop: buffers swapped.
    LoopSwap,
    /// Warp: simulation step starts.
    SimStart,
    /// Warp: simulation step published.
    SimEnd,
    /// Warp: application frame starts.
    AppStart,
    /// Warp: application frame done.
    AppEnd,
    /// Warp: warping frame starts (pair boundary).
    WarpStart,
    /// Warp: warping done.
    WarpEnd,
    /// Warp: warped frame swapped (next pair boundary).
    WarpSwap,
}

impl EventKind for Ev {
    const NAMES: &'static [&'static str] = &[
        "input",
        "loop_start",
        "loop_sim_end",
        "loop_render_end",
        "loop_swap",
        "sim_start",
        "sim_end",
        "app_start",
        "app_end",
        "warp_start",
        "warp_end",
        "warp_swap",
    ];
    fn kind(&self) -> usize {
        *self as usize
    }
}

/// A frame of the naive loop.
#[derive(Debug, Clone, Copy)]
pub struct LoopFrame {
    /// Start (tracker read).
    pub start: Time,
    /// Newest tracker sample at start.
    pub sample: Option<u64>,
    /// Simulation end.
    pub sim_end: Time,
    /// Render end.
    pub render_end: Time,
    /// Swap.
    pub swap: Time,
}

/// A simulation step (warp scheme).
#[derive(Debug, Clone, Copy)]
pub struct SimStep {
    /// Start (tracker read).
    pub start: Time,
    /// Newest tracker sample at start.
    pub sample: Option<u64>,
    /// Publication.
    pub end: Time,
}

/// An application frame (warp scheme).
#[derive(Debug, Clone, Copy)]
pub struct AppFrame {
    /// Start.
    pub start: Time,
    /// Simulation step it rendered.
    pub sim: Option<usize>,
    /// End.
    pub end: Time,
}

/// A warped frame.
#[derive(Debug, Clone, Copy)]
pub struct WarpFrame {
    /// Start (pair boundary).
    pub start: Time,
    /// Camera pose: newest tracker sample at start.
    pub camera: Option<u64>,
    /// Object transforms: newest published simulation step.
    pub sim: Option<usize>,
    /// Application frame re-projected.
    pub app: Option<usize>,
    /// Warp end.
    pub render_end: Time,
    /// Swap.
    pub swap: Time,
}

/// All state of a run.
#[derive(Debug)]
pub struct Vr {
    /// The model.
    pub cfg: VrConfig,
    events_left: u64,
    mean_interval: f64,
    arrivals: StreamRng,
    phases: [Duration; 3],
    /// Motion times.
    pub inputs: Vec<Time>,
    /// Naive loop frames.
    pub frames: Vec<LoopFrame>,
    /// Simulation steps.
    pub sims: Vec<SimStep>,
    /// Application frames.
    pub apps: Vec<AppFrame>,
    /// Warped frames.
    pub warps: Vec<WarpFrame>,
    /// Frames (naive or warped) that have swapped.
    pub swapped: usize,
    sims_done: usize,
    apps_done: usize,
    /// Most bytes the motion and frame records may take (`run.max_memory`);
    /// the run fails with an error naming that key beyond it.
    pub max_memory: u64,
}

impl Vr {
    /// A model ready to start.
    pub fn new(cfg: VrConfig) -> Self {
        let rng = RngStreams::new(cfg.run.seed);
        let phase = |name: &str, span: Duration| {
            let mut r = rng.stream(name);
            Duration::from_ps_f64(span.0 as f64 * r.random::<f64>())
        };
        let phases = [
            phase("phase.loop", cfg.pair()),
            phase("phase.simulation", cfg.simulation.step),
            phase("phase.app_renderer", cfg.renderer.render),
        ];
        Vr {
            events_left: cfg.run.events,
            mean_interval: cfg.input.mean_interval.0 as f64,
            arrivals: rng.stream("input.arrivals"),
            phases,
            inputs: Vec::new(),
            frames: Vec::new(),
            sims: Vec::new(),
            apps: Vec::new(),
            warps: Vec::new(),
            swapped: 0,
            sims_done: 0,
            apps_done: 0,
            max_memory: u64::MAX,
            cfg,
        }
    }

    /// Bytes the motion and frame records take now.
    pub fn record_bytes(&self) -> u64 {
        use std::mem::size_of;
        (self.inputs.len() * size_of::<Time>()
            + self.frames.len() * size_of::<LoopFrame>()
            + self.sims.len() * size_of::<SimStep>()
            + self.apps.len() * size_of::<AppFrame>()
            + self.warps.len() * size_of::<WarpFrame>()) as u64
    }

    /// Fails once the records outgrow `run.max_memory`.
    fn check_growth(&self, now: Time) -> Result<(), VrError> {
        let used = self.record_bytes();
        if used > self.max_memory {
            return Err(VrError::Invalid {
                key: "run.max_memory".into(),
                message: crate::limits::over_memory_message(
                    used,
                    &format!(
                        "records of {} motions, {} loop frames, {} simulation steps, {} application and {} warped frames after {now} of simulated time",
                        self.inputs.len(),
                        self.frames.len(),
                        self.sims.len(),
                        self.apps.len(),
                        self.warps.len()
                    ),
                    self.max_memory,
                ),
            });
        }
        Ok(())
    }

    /// Schedules the first events.
    pub fn start(&mut self, sched: &mut Scheduler<Ev>) -> Result<(), VrError> {
        match self.cfg.scheme {
            Scheme::Naive => sched.at(Time::ZERO.add(self.phases[0], "loop phase")?, Ev::LoopStart),
            Scheme::Warp => {
                sched.at(Time::ZERO.add(self.phases[1], "simulation phase")?, Ev::SimStart);
                sched.at(
                    Time::ZERO.add(self.phases[2], "application renderer phase")?,
                    Ev::AppStart,
                );
                sched.at(Time::ZERO, Ev::WarpStart);
            }
        }
        let first = Time::ZERO
            .add(self.cfg.run.warmup, "run.warmup")?
            .add(self.gap(), "first motion")?;
        sched.at(first, Ev::Input);
        Ok(())
    }

    fn gap(&mut self) -> Duration {
        Duration::from_ps_f64(-self.mean_interval * (1.0 - self.arrivals.random::<f64>()).ln())
    }

    /// Newest tracker sample available at `now`.
    pub fn delivered_sample(&self, now: Time) -> Option<u64> {
        now.0
            .checked_sub(self.cfg.tracker.latency.0)
            .map(|x| x / self.cfg.tracker.period.0.max(1))
    }

    /// The sample that captures a motion at `t`.
    pub fn capturing_sample(&self, t: Time) -> u64 {
        t.0.div_ceil(self.cfg.tracker.period.0.max(1))
    }

    /// When sample `k` is taken.
    pub fn sample_time(&self, k: u64) -> Time {
        Time(k.saturating_mul(self.cfg.tracker.period.0))
    }

    /// The first swap opportunity at or after `t`.
    pub fn next_boundary(&self, t: Time) -> Time {
        let p = self.cfg.pair().0.max(1);
        Time(t.0.div_ceil(p).saturating_mul(p))
    }

    /// Whether every motion is visible as head and as object motion.
    pub fn done(&self) -> bool {
        if self.events_left > 0 {
            return false;
        }
        let Some(last) = self.inputs.last() else {
            return true;
        };
        let j = Some(self.capturing_sample(*last));
        let Some(i) = self.swapped.checked_sub(1) else {
            return false;
        };
        match self.cfg.scheme {
            Scheme::Naive => self.frames[i].sample >= j,
            Scheme::Warp => {
                let w = &self.warps[i];
                w.camera >= j && w.sim.and_then(|s| self.sims[s].sample) >= j
            }
        }
    }

    /// What exists so far (for errors).
    pub fn describe(&self) -> String {
        format!(
            "{} motions issued, {} left; {} loop frames, {} simulation steps, {} application frames, {} warped frames",
            self.inputs.len(),
            self.events_left,
            self.frames.len(),
            self.sims.len(),
            self.apps.len(),
            self.warps.len()
        )
    }

    fn swapped_now(&mut self, count: usize) -> Control {
        self.swapped = count;
        if self.done() { Control::Stop } else { Control::Continue }
    }
}

impl Model for Vr {
    type Event = Ev;
    type Error = VrError;

    fn handle(&mut self, now: Time, ev: Ev, sched: &mut Scheduler<Ev>) -> Result<Control, VrError> {
        let c = &self.cfg;
        let (step, render, warp, pair) = (c.simulation.step, c.renderer.render, c.warp.render, c.pair());
        if matches!(
            ev,
            Ev::Input | Ev::LoopStart | Ev::SimStart | Ev::AppStart | Ev::WarpStart
        ) {
            self.check_growth(now)?;
        }
        match ev {
            Ev::Input => {
                self.inputs.push(now);
                self.events_left -= 1;
                if self.events_left > 0 {
                    let g = self.gap();
                    sched.after(g, Ev::Input, "next motion")?;
                }
            }
            Ev::LoopStart => {
                self.frames.push(LoopFrame {
                    start: now,
                    sample: self.delivered_sample(now),
                    sim_end: now,
                    render_end: now,
                    swap: now,
                });
                sched.after(step, Ev::LoopSimEnd, "simulation step")?;
            }
            Ev::LoopSimEnd => {
                if let Some(f) = self.frames.last_mut() {
                    f.sim_end = now;
                }
                sched.after(render, Ev::LoopRenderEnd, "render")?;
            }
            Ev::LoopRenderEnd => {
                if let Some(f) = self.frames.last_mut() {
                    f.render_end = now;
                }
                // The swap lock: wait for the next stereo-pair boundary.
                sched.at(self.next_boundary(now), Ev::LoopSwap);
            }
            Ev::LoopSwap => {
                if let Some(f) = self.frames.last_mut() {
                    f.swap = now;
                }
                let n = self.frames.len();
                if self.swapped_now(n) == Control::Stop {
                    return Ok(Control::Stop);
                }
                sched.at(now, Ev::LoopStart);
            }
            Ev::SimStart => {
                self.sims.push(SimStep {
                    start: now,
                    sample: self.delivered_sample(now),
                    end: now,
                });
                sched.after(step, Ev::SimEnd, "simulation step")?;
            }
            Ev::SimEnd => {
                if let Some(s) = self.sims.last_mut() {
                    s.end = now;
                }
                self.sims_done = self.sims.len();
                sched.at(now, Ev::SimStart);
            }
            Ev::AppStart => {
                self.apps.push(AppFrame {
                    start: now,
                    sim: self.sims_done.checked_sub(1),
                    end: now,
                });
                sched.after(render, Ev::AppEnd, "application frame")?;
            }
            Ev::AppEnd => {
                if let Some(a) = self.apps.last_mut() {
                    a.end = now;
                }
                self.apps_done = self.apps.len();
                sched.at(now, Ev::AppStart);
            }
            Ev::WarpStart => {
                self.warps.push(WarpFrame {
                    start: now,
                    camera: self.delivered_sample(now),
                    sim: self.sims_done.checked_sub(1),
                    app: self.apps_done.checked_sub(1),
                    render_end: now,
                    swap: now,
                });
                sched.after(warp, Ev::WarpEnd, "warp")?;
                sched.after(pair, Ev::WarpSwap, "warp swap")?;
            }
            Ev::WarpEnd => {
                // The warp fits in one pair, so it ends before the next warp starts.
                if let Some(w) = self.warps.last_mut() {
                    w.render_end = now;
                }
            }
            Ev::WarpSwap => {
                let i = self.swapped;
                self.warps[i].swap = now;
                if self.swapped_now(i + 1) == Control::Stop {
                    return Ok(Control::Stop);
                }
                // The next warp frame starts at this boundary.
                sched.at(now, Ev::WarpStart);
            }
        }
        Ok(Control::Continue)
    }
}
