//! The frame-pipeline system as a kernel [`Model`]: a CPU thread feeds a
//! bounded command FIFO; the GPU's front end, geometry stage, triangle FIFO
//! and fragment stage execute it; a swap chain and display show the frames;
//! system tasks preempt the CPU thread or the GPU's command processing.
//!
//! Follows paper 000 §3-4 and Figure 4 (CPU and GPU working in parallel
//! through the command buffer; idle time when it is full or empty) and paper
//! 004 §4.2 (vsync and double buffering). Each unit is a struct of its own
//! that owns its state and the transitions that change it: the CPU thread
//! (`cpu_thread/`), the front end (`front_end.rs`), the geometry and
//! fragment stages (`geometry_stage.rs`, `fragment_stage.rs`) and the
//! display (`display.rs`, which owns the swap chain); each holds its spec
//! (`unit_specs.rs`). The FIFOs, the shader pool and the bus between them
//! are the `Links` (`links.rs`), passed to the units' methods; the events
//! they schedule are [`Ev`] (`events.rs`). [`FramePipeline`] holds the
//! units, dispatches each event to the unit it concerns, then lets the
//! units take their steps in the order the data flows
//! (`FramePipeline::settle_units`: CPU -> command FIFO -> front end ->
//! geometry | swap chain and display, the front end's requests carried out
//! by `FramePipeline::downstream`) and has the instant accounted
//! (`accounting.rs`, which reads the units through an immutable view; the
//! critical path takes the display's news after the step that made it).

use crate::components::fifo::BoundedFifo;
use crate::components::noise::{NoiseSource, NoiseTarget};
use crate::components::shader_pool::{ShaderPool, Stream};
use crate::components::shared_bus::SharedBus;
use crate::components::swap_chain::PresentMode;
use crate::engine::{Control, Model, RngStreams, Scheduler, Time};
use crate::systems::error::SystemError;

use super::accounting::{Accounting, Units, units_of};
use super::config::{Fidelity, FramePipelineConfig, WorkloadConfig};
use super::cpu_thread::{Alone, CpuThread};
use super::display::Display;
use super::fragment_stage::FragmentStage;
use super::front_end::{Downstream, FrontEnd, FrontOut, FrontStep};
use super::geometry_stage::{GeometryStage, Handoff};
use super::links::{Env, Links};
use super::plan::{PipelinePlan, PlannedWork};

pub use super::events::Ev;
pub use super::front_end::FrontPhase;

/// The frame pipeline: its units, the links between them, the noise
/// sources, the per-frame records and the accounting.
pub struct FramePipeline {
    /// The model, the scene, the links, the records and the trace flag that
    /// the units' transitions get.
    pub(super) env: Env,
    /// The checked model, kept to summarise the run and write `model.toml`
    /// (the units hold their specs).
    pub(super) cfg: FramePipelineConfig,
    pub(super) frames_total: u64,
    pub(super) cpu: CpuThread,
    pub(super) front: FrontEnd,
    pub(super) geom: GeometryStage,
    pub(super) frag: FragmentStage,
    pub(super) display: Display,
    noise: Vec<NoiseSource>,
    pub(super) acct: Accounting,
}

/// The units downstream of the front end in `$p` (a [`FramePipeline`]).
macro_rules! downstream {
    ($p:ident) => {
        Downstream {
            geom: &$p.geom,
            frag: &$p.frag,
            display: &$p.display,
        }
    };
}

impl FramePipeline {
    /// Builds the units from a plan (which cannot fail: [`PipelinePlan::new`]
    /// refused every model they could not run).
    pub fn new(plan: PipelinePlan, trace: Option<crate::output::trace::TraceWriter>) -> Self {
        let (cfg, work, noise, display, units) = plan.into_parts();
        let streams = RngStreams::new(cfg.run.seed);
        let (fixed, scene) = match work {
            PlannedWork::Fixed(f) => (Some(f), None),
            PlannedWork::Scene(s) => (None, Some(s)),
        };
        // Only a trace of the units' states needs the events' traced paths
        // (a `frame`-detail trace is written from the records at the end).
        let traced = trace
            .as_ref()
            .is_some_and(|t| t.detail() != crate::output::trace::TraceDetail::Frame);
        let frames_total = cfg.run.frames;
        let body = match &scene {
            None => (1, false),
            Some(s) => (s.draws.len() as u32, true),
        };
        let zero_time_after = u64::from(cfg.cpu.max_frames_ahead) + u64::from(cfg.display.buffers) + 1;
        let cpu_rngs = [streams.stream("cpu.non_render"), streams.stream("variation.cpu")];
        let pixel_rng_start = match &cfg.workload {
            WorkloadConfig::Scene(sc) if sc.view == crate::scene::config::View::Static => {
                Some(streams.stream("fragment.pixels"))
            }
            _ => None,
        };
        let links = Links {
            commands: BoundedFifo::new(cfg.command_fifo.capacity),
            // Binning: the FIFO is the draw's bins and holds all of it.
            triangles: BoundedFifo::new(if cfg.gpu.fragment.binned() {
                u64::MAX
            } else {
                cfg.gpu.fragment.fifo_depth as u64
            }),
            shaders: match cfg.fidelity {
                Fidelity::Triangle => cfg.gpu.pool().map(|(n, p)| ShaderPool::new(n, p)),
                Fidelity::Draw => None,
            },
            frames_completed: 0,
            bus: SharedBus::new(cfg.bus.bandwidth.bytes_per_ps()),
            held_triangle: None,
            bus_changed: false,
        };
        FramePipeline {
            cpu: CpuThread::new(units.cpu, frames_total, body, cpu_rngs, fixed, zero_time_after),
            front: FrontEnd::new(units.front, streams.stream("variation.gpu")),
            geom: GeometryStage::new(units.geometry, streams.stream("fragment.pixels"), pixel_rng_start),
            frag: FragmentStage::default(),
            display: Display::new(&display),
            frames_total,
            noise,
            acct: Accounting::new(
                trace,
                (display.mode != PresentMode::Immediate).then_some(display.refresh),
            ),
            env: Env {
                links,
                scene,
                records: Vec::with_capacity(frames_total.min(1 << 16) as usize),
                traced,
            },
            cfg,
        }
    }

    /// Schedules the first events. Call once before running.
    pub fn start(&mut self, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if self.frames_total == 0 {
            return Ok(());
        }
        if self.display.fixed_vblanks() {
            s.at(self.display.first_latch(), Ev::Vblank { tag: 0 });
        }
        for i in 0..self.noise.len() {
            let t = self.noise[i].next_arrival(Time::ZERO)?;
            s.at(t, Ev::NoiseArrive { source: i as u16 });
        }
        self.step(Time::ZERO, s)?;
        Ok(())
    }

    /// The fidelity.
    pub fn fidelity(&self) -> Fidelity {
        self.cfg.fidelity
    }

    /// Commands pushed by the CPU and commands executed by the GPU.
    pub fn command_counts(&self) -> (u64, u64) {
        (self.cpu.issued(), self.front.executed())
    }

    /// Frames displayed or dropped so far.
    pub fn resolved(&self) -> u64 {
        self.display.resolved()
    }

    /// Drops the records of frames not yet displayed or dropped (after a run
    /// stopped by a time or event limit): the leading completed frames stay.
    pub fn keep_completed_frames(&mut self) {
        let done = self
            .env
            .records
            .iter()
            .take_while(|r| r.displayed.is_some() || r.dropped)
            .count();
        self.env.records.truncate(done);
    }

    /// Whether all asked-for frames are done.
    #[inline]
    pub fn done(&self) -> bool {
        self.display.done()
    }

    /// A one-line description of the units' states (for stall reports).
    pub fn describe(&self) -> String {
        format!(
            "cpu {}, command fifo {}/{}, front end {}, geometry {:?} busy={} held={}, fragment busy={}, frames completed {}, queued for display {}",
            self.cpu.describe(),
            self.env.links.commands.used(),
            self.env.links.commands.capacity(),
            self.front.describe(),
            self.geom.draw(),
            self.geom.busy(),
            self.env.links.held_triangle.is_some(),
            self.frag.busy(),
            self.env.links.frames_completed,
            self.display.queued()
        )
    }

    /// What follows every event but those a short cut took whole: the
    /// units take every step they can now ([`FramePipeline::settle`]), the
    /// shader pool's completions that moved are scheduled, and the instant
    /// is accounted.
    #[inline]
    fn step(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        self.settle(now, s)?;
        self.env.links.settle_shaders(now, s)?;
        self.account(now);
        Ok(())
    }

    /// Lets the units make every step they can now, in the order the data
    /// of a frame flows: the CPU thread pushes its commands into the command
    /// FIFO; the front end takes them, waits for swap-chain images, hands
    /// draws to the geometry stage (which feeds the fragment stage through
    /// the triangle FIFO), and presents finished frames to the display.
    ///
    /// Each step runs its unit until it cannot go on, and a step that finds
    /// nothing to do changes nothing; the CPU's progress depends only on what
    /// the front end changes (FIFO space, completed frames). So once the front
    /// end made no progress after a CPU step, another round would change
    /// nothing: the loop ends there.
    pub(super) fn settle(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        self.settle_units(now, s)?;
        self.settle_bus(now, s)
    }

    /// When the GPU's vertex fetch from AGP memory began or ended a draw
    /// (the bus's shares moved), the CPU's running copy takes its new rate
    /// ([`CpuThread::bus_changed`]). Nothing to do otherwise (no call).
    #[inline(always)]
    pub(super) fn settle_bus(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if !self.env.links.bus_changed {
            return Ok(());
        }
        self.env.links.bus_changed = false;
        self.cpu.bus_changed(now, &mut self.env, s)
    }

    /// [`FramePipeline::settle`]'s steps of the units, in the order of a
    /// frame's data flow: the CPU thread pushes into the command FIFO; the
    /// front end takes from it and asks the units downstream of it
    /// ([`FramePipeline::downstream`]) to take an image, a draw or a frame.
    fn settle_units(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        loop {
            // CPU thread -> command FIFO.
            self.cpu.step(now, &mut self.env, s)?;
            // A front end at rest takes no step (most events find it so).
            if self.front.at_rest(&self.geom) {
                return Ok(());
            }
            // Command FIFO -> front end -> geometry | swap chain and display.
            let mut progressed = false;
            loop {
                match self.front.step(now, &mut self.env, &downstream!(self), s)? {
                    FrontStep::Rest(p) => {
                        progressed |= p;
                        break;
                    }
                    FrontStep::Out(out) => {
                        progressed = true;
                        self.downstream(now, out, s)?;
                    }
                }
            }
            if !progressed {
                return Ok(());
            }
        }
    }

    /// What the front end asked of the units downstream of it, done in the
    /// order of the data flow: a swap-chain image taken for the frame it
    /// clears, the frame begun in the geometry stage, a draw handed to the
    /// geometry stage (which feeds the fragment stage), a finished frame
    /// presented to the display (whose news the critical path takes).
    #[inline(always)]
    fn downstream(&mut self, now: Time, out: FrontOut, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if out.acquire {
            let took = self.display.acquire();
            debug_assert!(took, "the front end saw a free image");
        }
        if out.new_frame {
            self.geom.new_frame();
        }
        if let Some(draw) = out.draw
            && self.geom.start_draw(now, draw, &mut self.env, s)?
        {
            self.frag.set_closed_busy(true);
        }
        if let Some(frame) = out.present {
            self.display.present_rendered(now, frame, &mut self.env.records, s)?;
            self.observe_display();
        }
        Ok(())
    }

    /// Accounts the instant `now` in full: every unit's state, read through
    /// an immutable view.
    pub(super) fn account(&mut self, now: Time) {
        self.acct.account(now, units_of!(self), &mut self.env.records);
    }

    /// The critical path takes what the display did (the frames presented,
    /// the frame shown), right after each step that can present or show:
    /// it observes the display's results; the display does not write it.
    #[inline(always)]
    fn observe_display(&mut self) {
        if self.display.has_news() {
            self.take_display_news();
        }
    }

    /// [`FramePipeline::observe_display`] with news.
    #[cold]
    #[inline(never)]
    fn take_display_news(&mut self) {
        let news = self.display.news_mut();
        for f in news.presented.drain(..) {
            self.acct.path.presented(f);
        }
        if let Some(f) = news.shown.take() {
            self.acct.path.shown(f);
        }
    }

    /// The CPU thread's operation finished (its event, not stale): the
    /// thread takes its next steps. Returns true when the thread's short
    /// cuts took the whole event (the rest of `handle` is skipped): when
    /// nothing downstream waits for the CPU (the front end is not idle) and
    /// no trace is written, a draw batch's end is [`CpuThread::draw_done_fast`],
    /// any other operation's [`CpuThread::step_alone`].
    #[inline(always)]
    fn cpu_done(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        // A shared bus: a draw's copy is a step of its own (its start ends
        // the event's work here; its end goes on as any operation's).
        if self.env.scene.as_ref().is_some_and(|sc| sc.bus_shared) && self.cpu.copy_turn(now, &mut self.env, s)? {
            return Ok(false);
        }
        let alone = !self.env.traced && self.front.phase() != FrontPhase::Idle;
        if alone && let Some(a) = self.cpu.draw_done_fast(now, &mut self.env, s)? {
            self.account_cpu_alone(now, a);
            return Ok(true);
        }
        self.cpu.op_done(now, &mut self.env);
        if alone && let Some(a) = self.cpu.step_alone(now, &mut self.env, s)? {
            self.account_cpu_alone(now, a);
            return Ok(true);
        }
        Ok(false)
    }

    /// The accounting an instant that only the CPU thread moved leaves.
    #[inline(always)]
    fn account_cpu_alone(&mut self, now: Time, a: Alone) {
        debug_assert!(
            !self.display.has_news(),
            "a CPU-only instant presented or showed a frame"
        );
        if a == Alone::Blocked {
            self.acct.account_cpu_alone(now, &self.cpu, &mut self.env.records);
        }
    }

    fn noise_arrive(&mut self, now: Time, source: u16, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let src = &mut self.noise[source as usize];
        let d = src.draw_duration();
        let target = src.target;
        let next = src.next_arrival(now)?;
        s.at(next, Ev::NoiseArrive { source });
        let end = match target {
            NoiseTarget::Cpu => self.cpu.task_arrives(now, d)?,
            NoiseTarget::Gpu => self.front.task_arrives(now, d)?,
        };
        if let Some(end) = end {
            s.at(end, Ev::NoiseEnd { target });
        }
        Ok(())
    }

    fn noise_end(&mut self, now: Time, target: NoiseTarget, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let (next, wake) = match target {
            NoiseTarget::Cpu => self.cpu.task_ends(now)?,
            NoiseTarget::Gpu => self.front.task_ends(now)?,
        };
        if let Some(end) = next {
            s.at(end, Ev::NoiseEnd { target });
        }
        match target {
            NoiseTarget::Cpu => CpuThread::schedule_wake(s, wake),
            NoiseTarget::Gpu => FrontEnd::schedule_wake(s, wake),
        }
        Ok(())
    }
}

impl FramePipeline {
    /// A unit's timed wait ends (a zero-time frame's turn, pacing, a
    /// replayed frame's present call or GPU end, a frame held back by frame
    /// generation). Rare beside the units'
    /// work, so kept out of `handle`, whose inlining of the stages' events
    /// it would otherwise crowd out.
    #[cold]
    #[inline(never)]
    fn wait_ends(&mut self, now: Time, ev: Ev, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        match ev {
            Ev::ZeroTimeFrame => self.cpu.zero_time_frame(),
            Ev::PaceWake => self.cpu.pace_wake(),
            Ev::PresentReturn => self.cpu.present_returned(),
            Ev::GpuHoldEnd => self.front.hold_ends(),
            Ev::HeldPresent { tag } => {
                self.display.held_present(now, tag, &mut self.env.records, s)?;
                self.observe_display();
            }
            _ => unreachable!("not a wait's end: {ev:?}"),
        }
        Ok(())
    }
}

impl Model for FramePipeline {
    type Event = Ev;
    type Error = SystemError;

    fn handle(&mut self, now: Time, ev: Ev, s: &mut Scheduler<Ev>) -> Result<Control, SystemError> {
        self.catch_up(s)?;
        match ev {
            Ev::CpuDone { tag } => {
                if self.cpu.complete(tag) && self.cpu_done(now, s)? {
                    return Ok(Control::Continue);
                }
            }
            Ev::FrontDone { tag } => {
                if self.front.complete(tag) {
                    let out = self.front.command_done(now, &mut self.env);
                    self.downstream(now, out, s)?;
                }
            }
            Ev::GeomTriangle { tag } => {
                if self.env.links.shader_completes(now, Stream::Vertex, tag) {
                    // A finished triangle goes to the fragment stage, the
                    // triangle FIFO or the link's slot past it.
                    match self.geom.triangle_done(&mut self.env, self.frag.busy())? {
                        Handoff::Fragment(f) => {
                            self.frag.start(now, f, &mut self.env.links.shaders, s)?;
                            self.geom.next_triangle(now, &mut self.env, s)?;
                        }
                        Handoff::Queued => self.geom.next_triangle(now, &mut self.env, s)?,
                        Handoff::Held | Handoff::NoDraw => {}
                    }
                }
            }
            Ev::FragTriangle { tag } => {
                if self.env.links.shader_completes(now, Stream::Fragment, tag) {
                    // A held triangle freed into the FIFO: geometry goes on.
                    if self.frag.triangle_done(now, &mut self.env, s)? {
                        self.geom.next_triangle(now, &mut self.env, s)?;
                    }
                }
            }
            Ev::DrawGeometry => self.geom.closed_geometry_done(),
            Ev::DrawFragmentStart => self.frag.set_closed_busy(true),
            Ev::DrawDone => {
                self.frag.set_closed_busy(false);
                if let Some(split) = self.geom.draw_done() {
                    self.acct.credit_draw_split(split);
                }
                // The draw's vertex fetch from AGP memory (if any) ends.
                self.env.links.bus_changed |= self.env.links.bus.set_fetch(0.0);
                self.settle_bus(now, s)?;
                if self.draw_done_alone(now, s)? {
                    return Ok(if self.done() { Control::Stop } else { Control::Continue });
                }
            }
            Ev::Vblank { tag } => {
                self.display.vblank(now, tag, &mut self.env.records, s)?;
                self.observe_display();
            }
            Ev::NoiseArrive { source } => self.noise_arrive(now, source, s)?,
            Ev::NoiseEnd { target } => self.noise_end(now, target, s)?,
            Ev::ZeroTimeFrame | Ev::PaceWake | Ev::PresentReturn | Ev::GpuHoldEnd | Ev::HeldPresent { .. } => {
                self.wait_ends(now, ev, s)?
            }
        }
        self.step(now, s)?;
        Ok(if self.done() { Control::Stop } else { Control::Continue })
    }
}
