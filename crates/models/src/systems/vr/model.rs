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

use crate::engine::{Control, Duration, EventKind, Model, RngStreams, Scheduler, StreamRng, Time};
use crate::systems::checked::Checked;
use crate::systems::error::SystemError;

use crate::output::trace::TraceWriter;

use super::config::{Scheme, VrConfig};
use super::latency::Follower;

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
    /// Object transforms: the newest published simulation step, its number
    /// and a copy of its record (final: it was published).
    pub sim: Option<(usize, SimStep)>,
    /// The newest finished application frame, re-projected: its number and
    /// a copy of its record.
    pub app: Option<(usize, AppFrame)>,
    /// Warp end.
    pub render_end: Time,
    /// Swap.
    pub swap: Time,
}

/// All state of a run. Memory is bounded by the motions, not by the
/// simulated span: a frame is folded into the motions it shows when it
/// swaps ([`Follower`]) and its trace spans are written as it goes, so only
/// the frames in flight are held.
#[derive(Debug)]
pub struct Vr {
    /// The model.
    pub cfg: VrConfig,
    events_left: u64,
    mean_interval: f64,
    arrivals: StreamRng,
    phases: [Duration; 3],
    /// Every motion's fate, filled in as frames swap.
    pub follower: Follower,
    frame: Option<LoopFrame>,
    sim: Option<SimStep>,
    sim_done: Option<(usize, SimStep)>,
    app: Option<AppFrame>,
    app_done: Option<(usize, AppFrame)>,
    warp: Option<WarpFrame>,
    last_swap: Option<(usize, Time)>,
    /// Naive loop frames started.
    pub frames: usize,
    /// Simulation steps started.
    pub sims: usize,
    /// Application frames started.
    pub apps: usize,
    /// Warped frames started.
    pub warps: usize,
    /// Frames (naive or warped) that have swapped.
    pub swapped: usize,
    /// The trace, written as the run goes.
    pub trace: Option<TraceWriter>,
    /// Most bytes the motion records may take (`run.max_memory`); the run
    /// fails with an error naming that key beyond it.
    pub max_memory: u64,
}

impl Vr {
    /// A model ready to start, from a checked config.
    pub fn new(cfg: Checked<VrConfig>) -> Self {
        let cfg = cfg.into_inner();
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
            follower: Follower::new(&cfg),
            frame: None,
            sim: None,
            sim_done: None,
            app: None,
            app_done: None,
            warp: None,
            last_swap: None,
            frames: 0,
            sims: 0,
            apps: 0,
            warps: 0,
            swapped: 0,
            trace: None,
            max_memory: u64::MAX,
            cfg,
        }
    }

    /// Fails once the motion records outgrow `run.max_memory`.
    fn check_growth(&self, now: Time) -> Result<(), SystemError> {
        let records = &self.follower.records;
        crate::systems::tracked_input::check_records(self.follower.record_bytes(), self.max_memory, || {
            format!("records of {} motions after {now} of simulated time", records.len())
        })
    }

    /// Schedules the first events and writes the trace's tracks.
    pub fn start(&mut self, sched: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if let Some(t) = &mut self.trace {
            t.process(1, "VR pipeline");
            for (tid, name) in [
                (1, "tracker (motions)"),
                (2, "simulation"),
                (3, "renderer"),
                (4, "warping renderer"),
                (5, "display"),
            ] {
                t.track(1, tid, name);
            }
        }
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

    /// Writes the last image's span (it stays for two fields) and hands the
    /// trace back.
    pub fn finish_trace(&mut self) -> Option<TraceWriter> {
        let mut t = self.trace.take()?;
        if let Some((i, s)) = self.last_swap {
            // Saturating: a trace's end, not a result.
            let field = self.cfg.display_latency().0;
            t.span(
                1,
                5,
                &format!("image {i}"),
                s,
                Time(s.0.saturating_add(field.saturating_mul(2))),
                None,
            );
        }
        Some(t)
    }

    fn gap(&mut self) -> Duration {
        Duration::from_ps_f64(-self.mean_interval * (1.0 - self.arrivals.random::<f64>()).ln())
    }

    /// Newest tracker sample available at `now`.
    pub fn delivered_sample(&self, now: Time) -> Option<u64> {
        self.cfg.tracker.delivered_sample(now)
    }

    /// The first swap opportunity at or after `t`.
    pub fn next_boundary(&self, t: Time) -> Time {
        let p = self.cfg.pair().0.max(1);
        Time(t.0.div_ceil(p).saturating_mul(p))
    }

    /// Whether every motion is visible as head and as object motion.
    pub fn done(&self) -> bool {
        self.events_left == 0 && self.follower.all_shown()
    }

    /// What exists so far (for errors).
    pub fn describe(&self) -> String {
        format!(
            "{} motions issued, {} left; {} loop frames, {} simulation steps, {} application frames, {} warped frames",
            self.follower.records.len(),
            self.events_left,
            self.frames,
            self.sims,
            self.apps,
            self.warps
        )
    }

    /// A frame swapped at `now`: the display shows a new image.
    fn swapped_now(&mut self, now: Time) -> Control {
        let i = self.swapped;
        if let (Some(t), Some((k, prev))) = (&mut self.trace, self.last_swap) {
            t.span(1, 5, &format!("image {k}"), prev, now, None);
        }
        self.last_swap = Some((i, now));
        self.swapped = i + 1;
        if self.done() { Control::Stop } else { Control::Continue }
    }
}

impl Model for Vr {
    type Event = Ev;
    type Error = SystemError;

    fn handle(&mut self, now: Time, ev: Ev, sched: &mut Scheduler<Ev>) -> Result<Control, SystemError> {
        let c = &self.cfg;
        let (step, render, warp, pair) = (c.simulation.step, c.renderer.render, c.warp.render, c.pair());
        match ev {
            Ev::Input => {
                self.check_growth(now)?;
                if let Some(t) = &mut self.trace {
                    t.instant(1, 1, &format!("motion {}", self.follower.records.len()), now);
                }
                self.follower.input(now);
                self.events_left -= 1;
                if self.events_left > 0 {
                    let g = self.gap();
                    sched.after(g, Ev::Input, "next motion")?;
                }
            }
            Ev::LoopStart => {
                self.frame = Some(LoopFrame {
                    start: now,
                    sample: self.delivered_sample(now),
                    sim_end: now,
                    render_end: now,
                    swap: now,
                });
                self.frames += 1;
                sched.after(step, Ev::LoopSimEnd, "simulation step")?;
            }
            Ev::LoopSimEnd => {
                if let Some(f) = &mut self.frame {
                    f.sim_end = now;
                }
                sched.after(render, Ev::LoopRenderEnd, "render")?;
            }
            Ev::LoopRenderEnd => {
                if let Some(f) = &mut self.frame {
                    f.render_end = now;
                }
                // The swap lock: wait for the next stereo-pair boundary.
                sched.at(self.next_boundary(now), Ev::LoopSwap);
            }
            Ev::LoopSwap => {
                if let Some(mut f) = self.frame.take() {
                    f.swap = now;
                    let i = self.swapped;
                    if let Some(t) = &mut self.trace {
                        t.span(1, 2, &format!("frame {i} simulation"), f.start, f.sim_end, None);
                        t.span(1, 3, &format!("frame {i} render"), f.sim_end, f.render_end, None);
                        t.span(1, 3, &format!("frame {i} swap lock"), f.render_end, f.swap, None);
                    }
                    self.follower.loop_swap(&f);
                }
                if self.swapped_now(now) == Control::Stop {
                    return Ok(Control::Stop);
                }
                sched.at(now, Ev::LoopStart);
            }
            Ev::SimStart => {
                self.sim = Some(SimStep {
                    start: now,
                    sample: self.delivered_sample(now),
                    end: now,
                });
                self.sims += 1;
                sched.after(step, Ev::SimEnd, "simulation step")?;
            }
            Ev::SimEnd => {
                if let Some(mut s) = self.sim.take() {
                    s.end = now;
                    let i = self.sims - 1;
                    if let Some(t) = &mut self.trace {
                        t.span(1, 2, &format!("step {i}"), s.start, s.end, None);
                    }
                    self.sim_done = Some((i, s));
                }
                sched.at(now, Ev::SimStart);
            }
            Ev::AppStart => {
                self.app = Some(AppFrame {
                    start: now,
                    sim: self.sim_done.map(|(i, _)| i),
                    end: now,
                });
                self.apps += 1;
                sched.after(render, Ev::AppEnd, "application frame")?;
            }
            Ev::AppEnd => {
                if let Some(mut a) = self.app.take() {
                    a.end = now;
                    let i = self.apps - 1;
                    if let Some(t) = &mut self.trace {
                        t.span(1, 3, &format!("app frame {i}"), a.start, a.end, None);
                    }
                    self.app_done = Some((i, a));
                }
                sched.at(now, Ev::AppStart);
            }
            Ev::WarpStart => {
                self.warp = Some(WarpFrame {
                    start: now,
                    camera: self.delivered_sample(now),
                    sim: self.sim_done,
                    app: self.app_done,
                    render_end: now,
                    swap: now,
                });
                self.warps += 1;
                sched.after(warp, Ev::WarpEnd, "warp")?;
                sched.after(pair, Ev::WarpSwap, "warp swap")?;
            }
            Ev::WarpEnd => {
                // The warp fits in one pair, so it ends before the next warp starts.
                if let Some(w) = &mut self.warp {
                    w.render_end = now;
                }
            }
            Ev::WarpSwap => {
                if let Some(mut w) = self.warp.take() {
                    w.swap = now;
                    if let Some(t) = &mut self.trace {
                        t.span(1, 4, &format!("warp {}", self.swapped), w.start, w.render_end, None);
                    }
                    self.follower.warp_swap(&w);
                }
                if self.swapped_now(now) == Control::Stop {
                    return Ok(Control::Stop);
                }
                // The next warp frame starts at this boundary.
                sched.at(now, Ev::WarpStart);
            }
        }
        Ok(Control::Continue)
    }
}
