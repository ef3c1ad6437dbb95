//! The GPU's front end (paper 000 §4.5, with §3-4's command buffer): it
//! takes the commands from the command FIFO in order and processes each
//! (command cost, state changes): a clear waits for a free swap-chain image
//! (paper 004 §4.2), a draw is handed to the geometry stage once that stage
//! is free, and a swap waits for the pipeline to drain, then presents the
//! frame to the display. A system task can preempt its command processing.
//!
//! [`FrontEnd`] owns the front end's state (its phase, the command it
//! holds, the frame it is on, its quiet completion, its random stream) and
//! its transitions; the FIFOs come in an [`Env`]. It reads the units
//! downstream of it (geometry, fragment, display) through a read-only
//! [`Downstream`] and changes none of them: what it asks of them (an
//! image, a draw taken, a frame presented) is a [`FrontOut`] that the
//! pipeline's step carries out (`FramePipeline::downstream`). Only the
//! `draw`-fidelity short cut [`FrontEnd::handoff_fast`] still starts the
//! geometry stage's draw itself.

use crate::components::preemptible::{Preemptible, Wake};
use crate::engine::{Duration, Scheduler, Slot, StreamRng, Time};
use crate::systems::error::SystemError;

use super::display::Display;
use super::events::Ev;
use super::fragment_stage::FragmentStage;
use super::geometry_stage::GeometryStage;
use super::links::{Command, Env, command_count};
use super::unit_specs::FrontSpec;

/// What the GPU front end is doing (its command is its own, see
/// `FrontEnd::describe`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontPhase {
    /// Waiting for commands (starved when at rest).
    Idle,
    /// A clear waits for a free swap-chain image.
    WaitImage,
    /// A swap waits for the pipeline to drain.
    WaitDrain,
    /// Processing its command (possibly preempted).
    Running,
    /// A draw waits for the geometry stage to take it.
    Handoff,
    /// A replayed frame's swap waits for the frame's measured GPU end
    /// (`workload.gpu_end`); [`Ev::GpuHoldEnd`] ends it.
    HoldFrame,
}

/// What a front-end step reads of the units downstream of it: whether the
/// geometry stage takes a draw and when its draw ends, whether the
/// pipeline drained, whether a swap-chain image is free. It changes none of
/// them: what it asks of them is a [`FrontOut`].
pub(super) struct Downstream<'a> {
    pub(super) geom: &'a GeometryStage,
    pub(super) frag: &'a FragmentStage,
    pub(super) display: &'a Display,
}

/// What a front-end transition asks of the units downstream of it, in the
/// order the pipeline's step applies it before the front end goes on: take
/// a swap-chain image, start a frame in the geometry stage, hand it a draw,
/// present a finished frame to the display.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct FrontOut {
    /// A swap-chain image for the frame it clears (one is free).
    pub(super) acquire: bool,
    /// A frame begins (the geometry stage restarts a static view's sizes).
    pub(super) new_frame: bool,
    /// A draw for the geometry stage, which is free to take it.
    pub(super) draw: Option<u32>,
    /// A finished frame to present.
    pub(super) present: Option<u64>,
}

/// How a [`FrontEnd::step`] ended.
pub(super) enum FrontStep {
    /// It cannot go on now; whether it changed anything.
    Rest(bool),
    /// It asks something of the units downstream; it goes on once that is done.
    Out(FrontOut),
}

/// The GPU front end.
#[derive(Debug)]
pub struct FrontEnd {
    work: Preemptible,
    phase: FrontPhase,
    /// The command of every [`FrontPhase`] but `Idle`.
    cmd: Command,
    /// The frame it is on (from its clear to its swap).
    frame: Option<u64>,
    /// Its draw command completing quietly: its slot in the event order and
    /// the job's tag ([`super::quiet`]).
    quiet: Option<(Slot, u32)>,
    /// The per-frame variation stream (`variation.gpu`).
    variation_rng: StreamRng,
    /// Commands executed.
    executed: u64,
    /// Whether the held draw's stalling state setup has run
    /// (`gpu.state_change_stalls`).
    set_up: bool,
    /// What it reads of the model.
    spec: FrontSpec,
    /// What its last transitions ask of the units downstream (`has_out`:
    /// anything), taken by the step.
    out: FrontOut,
    has_out: bool,
}

#[inline(always)]
fn schedule(s: &mut Scheduler<Ev>, w: Wake) {
    if let Wake::JobAt(t, tag) = w {
        s.at(t, Ev::FrontDone { tag });
    }
}

impl FrontEnd {
    /// An idle front end of `spec`; `variation_rng`: the `variation.gpu` stream.
    pub(super) fn new(spec: FrontSpec, variation_rng: StreamRng) -> Self {
        FrontEnd {
            spec,
            out: FrontOut::default(),
            has_out: false,
            work: Preemptible::new(),
            phase: FrontPhase::Idle,
            cmd: Command::Clear { frame: 0 },
            frame: None,
            quiet: None,
            variation_rng,
            executed: 0,
            set_up: false,
        }
    }

    /// Whether the fragments are binned (sort-middle).
    #[inline(always)]
    pub(super) fn binned(&self) -> bool {
        self.spec.binned
    }

    /// The phase.
    #[inline(always)]
    pub(super) fn phase(&self) -> FrontPhase {
        self.phase
    }

    /// Whether a [`FrontEnd::step`] now would find nothing to do, whatever
    /// the links hold: it runs a command, or it holds a draw that the
    /// geometry stage, busy with the one before, has not taken. Most events
    /// find it so at `triangle` fidelity.
    #[inline(always)]
    pub(super) fn at_rest(&self, geom: &GeometryStage) -> bool {
        match self.phase {
            FrontPhase::Running | FrontPhase::HoldFrame => true,
            FrontPhase::Handoff => geom.has_draw(),
            _ => false,
        }
    }

    /// The frame it is on (from its clear to its swap).
    #[inline(always)]
    pub(super) fn frame(&self) -> Option<u64> {
        self.frame
    }

    /// Whether a system task holds it.
    #[inline(always)]
    pub(super) fn in_system(&self) -> bool {
        self.work.in_system()
    }

    /// Commands executed so far.
    pub(super) fn executed(&self) -> u64 {
        self.executed
    }

    /// For stall reports: the phase with the command it holds.
    pub(super) fn describe(&self) -> String {
        match self.phase {
            FrontPhase::Idle => "Idle".to_string(),
            p => format!("{p:?}({:?})", self.cmd),
        }
    }

    /// The running command's job with `tag` completed (false: a stale tag).
    #[inline(always)]
    pub(super) fn complete(&mut self, tag: u32) -> bool {
        self.work.complete(tag)
    }

    /// A system task of `d` arrives; returns when it ends, if it runs now.
    pub(super) fn task_arrives(&mut self, now: Time, d: Duration) -> Result<Option<Time>, SystemError> {
        Ok(self.work.task_arrives(now, d)?)
    }

    /// The running system task ends: returns when the next one ends, if one
    /// runs, and the wake of the job it held ([`FrontEnd::schedule_wake`]).
    pub(super) fn task_ends(&mut self, now: Time) -> Result<(Option<Time>, Wake), SystemError> {
        Ok(self.work.task_ends(now)?)
    }

    /// Schedules the completion of a job the front end started or resumed.
    #[inline(always)]
    pub(super) fn schedule_wake(s: &mut Scheduler<Ev>, w: Wake) {
        schedule(s, w);
    }

    /// Advances the front end as far as it can go now, or until a
    /// transition asks something of the units downstream
    /// ([`FrontStep::Out`]: the pipeline's step does it and steps the front
    /// end again).
    pub(super) fn step(
        &mut self,
        now: Time,
        env: &mut Env,
        down: &Downstream<'_>,
        s: &mut Scheduler<Ev>,
    ) -> Result<FrontStep, SystemError> {
        let mut progressed = false;
        loop {
            if self.has_out {
                return Ok(FrontStep::Out(self.take_out()));
            }
            match self.phase {
                FrontPhase::Idle => {
                    let Some(c) = env.links.commands.pop() else {
                        return Ok(FrontStep::Rest(progressed));
                    };
                    self.executed += command_count(&env.scene, &c);
                    self.cmd = c;
                    self.phase = self.begin(now, c, env, down, s)?;
                }
                FrontPhase::WaitImage => {
                    if !down.display.can_acquire() {
                        return Ok(FrontStep::Rest(progressed));
                    }
                    self.emit().acquire = true;
                    self.phase = self.start_clear(now, self.cmd, env, down, s)?;
                }
                FrontPhase::WaitDrain => {
                    // No triangle anywhere between the front end and the fragment output.
                    if !(down.geom.drained()
                        && env.links.held_triangle.is_none()
                        && env.links.triangles.is_empty()
                        && !down.frag.busy())
                    {
                        return Ok(FrontStep::Rest(progressed));
                    }
                    // With frame generation, the interpolation before the
                    // frame's present is GPU work of its swap.
                    let generate = match self.cmd {
                        Command::Swap { frame } => down.display.generation_cost(frame),
                        _ => Duration::ZERO,
                    };
                    let work = self
                        .spec
                        .swap
                        .saturating_add(self.spec.command)
                        .saturating_add(generate);
                    if let Some(t) = self.held_until(env, work)
                        && t > now
                    {
                        s.at(t, Ev::GpuHoldEnd);
                        self.phase = FrontPhase::HoldFrame;
                        return Ok(FrontStep::Rest(true));
                    }
                    self.phase = self.job(now, self.cmd, work, env, down, s)?;
                }
                FrontPhase::Handoff => {
                    // Binning: the next draw's geometry waits for the bins to drain.
                    let bins_busy = self.spec.binned && (down.frag.busy() || !env.links.triangles.is_empty());
                    if down.geom.has_draw() || bins_busy {
                        return Ok(FrontStep::Rest(progressed));
                    }
                    if let Command::Draw { draw, .. } = self.cmd {
                        // A stalling state setup runs now that the stage is free.
                        let setup = env
                            .scene
                            .as_ref()
                            .map_or(Duration::ZERO, |sc| sc.draws[draw as usize].setup);
                        if setup.0 > 0 && !self.set_up {
                            self.set_up = true;
                            self.phase = self.job(now, self.cmd, setup, env, down, s)?;
                            progressed = true;
                            continue;
                        }
                        self.set_up = false;
                        // The geometry stage takes the draw (the step hands it on).
                        self.emit().draw = Some(draw);
                    }
                    self.phase = FrontPhase::Idle;
                }
                FrontPhase::Running | FrontPhase::HoldFrame => return Ok(FrontStep::Rest(progressed)),
            }
            progressed = true;
        }
    }

    /// When the swap (of `work`) may start so that a replayed frame ends no
    /// earlier than its measured GPU end (`workload.gpu_end`, after the
    /// frame began); `None` for every other workload.
    #[inline(never)]
    fn held_until(&self, env: &Env, work: Duration) -> Option<Time> {
        let f = self.frame? as usize;
        let end = self.spec.gpu_end.get(f)?;
        Some(Time(
            env.records[f].begun.0.saturating_add(end.0).saturating_sub(work.0),
        ))
    }

    /// The [`Ev::GpuHoldEnd`] event: the held swap may start.
    pub(super) fn hold_ends(&mut self) {
        if self.phase == FrontPhase::HoldFrame {
            self.phase = FrontPhase::WaitDrain;
        }
    }

    fn begin(
        &mut self,
        now: Time,
        c: Command,
        env: &mut Env,
        down: &Downstream<'_>,
        s: &mut Scheduler<Ev>,
    ) -> Result<FrontPhase, SystemError> {
        let cmd_cost = self.spec.command;
        match c {
            Command::Clear { .. } => {
                if down.display.can_acquire() {
                    self.emit().acquire = true;
                    self.start_clear(now, c, env, down, s)
                } else {
                    Ok(FrontPhase::WaitImage)
                }
            }
            Command::Fixed { gpu, .. } => {
                let work = gpu.saturating_add(cmd_cost);
                self.job(now, c, work, env, down, s)
            }
            Command::Draw { draw, .. } => {
                let work = match &env.scene {
                    Some(sc) => sc.draws[draw as usize].front,
                    None => Duration::ZERO,
                };
                self.job(now, c, work, env, down, s)
            }
            Command::Swap { .. } => Ok(FrontPhase::WaitDrain),
        }
    }

    fn start_clear(
        &mut self,
        now: Time,
        c: Command,
        env: &mut Env,
        down: &Downstream<'_>,
        s: &mut Scheduler<Ev>,
    ) -> Result<FrontPhase, SystemError> {
        if let Command::Clear { frame } = c {
            self.frame = Some(frame);
            self.emit().new_frame = true;
            env.records[frame as usize].gpu_start = Some(now);
        }
        let mut work = self.spec.clear.saturating_add(self.spec.command);
        // Per-frame variation (config `variation.gpu`), drawn only when given.
        if let (Command::Clear { .. }, Some(v)) = (c, &self.spec.variation) {
            work = work.saturating_add(Duration::from_ps_f64(v.sample(&mut self.variation_rng)));
        }
        self.job(now, c, work, env, down, s)
    }

    /// Runs `work` for command `c` on the (preemptible) front end; zero work
    /// completes at once.
    fn job(
        &mut self,
        now: Time,
        c: Command,
        work: Duration,
        env: &mut Env,
        down: &Downstream<'_>,
        s: &mut Scheduler<Ev>,
    ) -> Result<FrontPhase, SystemError> {
        if work.0 > 0 || self.work.in_system() {
            self.start_job(now, c, work, down.geom.done_at(), s)?;
            return Ok(FrontPhase::Running);
        }
        Ok(self.after(now, c, env))
    }

    /// Starts the job of `work` for `c`; its completion is an event, or
    /// quiet when it only starts a hand-off ([`super::quiet`]):
    /// `geometry_done_at` is when the geometry stage's draw ends.
    #[inline(always)]
    fn start_job(
        &mut self,
        now: Time,
        c: Command,
        work: Duration,
        geometry_done_at: Option<Time>,
        s: &mut Scheduler<Ev>,
    ) -> Result<(), SystemError> {
        match self.work.start_job(now, work)? {
            Wake::JobAt(end, tag) if quiet_completion(c, end, geometry_done_at) => {
                self.quiet = Some((s.reserve(end), tag));
            }
            w => schedule(s, w),
        }
        Ok(())
    }

    /// The running command's work finished (its event).
    /// What it asks of the units downstream is returned (a frame to
    /// present, after a swap).
    pub(super) fn command_done(&mut self, now: Time, env: &mut Env) -> FrontOut {
        if let FrontPhase::Running = self.phase {
            self.phase = self.after(now, self.cmd, env);
        }
        self.take_out()
    }

    /// A transition's requests of the units downstream, to be filled in.
    #[inline(always)]
    fn emit(&mut self) -> &mut FrontOut {
        self.has_out = true;
        &mut self.out
    }

    /// The requests made since the last time, taken.
    #[inline(always)]
    fn take_out(&mut self) -> FrontOut {
        self.has_out = false;
        std::mem::take(&mut self.out)
    }

    fn after(&mut self, now: Time, c: Command, env: &mut Env) -> FrontPhase {
        match c {
            Command::Draw { .. } => FrontPhase::Handoff,
            Command::Swap { frame } => {
                // The frame is complete: present it.
                env.links.frames_completed += 1;
                env.records[frame as usize].gpu_end = Some(now);
                self.frame = None;
                self.emit().present = Some(frame);
                FrontPhase::Idle
            }
            Command::Clear { .. } | Command::Fixed { .. } => FrontPhase::Idle,
        }
    }

    /// The quiet completion whose turn came before the event being handled
    /// (after a run: before its end), taken off: its instant and job tag.
    #[inline(always)]
    pub(super) fn passed_quiet(&mut self, s: &Scheduler<Ev>) -> Option<(Time, u32)> {
        if let Some((slot, tag)) = self.quiet
            && s.passed(slot)
        {
            self.quiet = None;
            return Some((slot.time(), tag));
        }
        None
    }

    /// The quiet completion of the draw command's job `tag`: the hand-off
    /// begins, as [`FrontEnd::command_done`] does for a draw command.
    /// Returns false, having changed nothing, when a system task that
    /// preempted the job made the tag stale (the resumed job's completion
    /// is an event of its own).
    #[inline(always)]
    pub(super) fn quiet_done(&mut self, tag: u32) -> bool {
        if !self.work.complete(tag) {
            return false;
        }
        debug_assert!(matches!(self.cmd, Command::Draw { .. }));
        // (Calling `command_done` here costs 1.4% of the hour's
        // instructions: its result goes through memory.)
        if self.phase == FrontPhase::Running {
            self.phase = FrontPhase::Handoff;
        }
        debug_assert_eq!(self.phase, FrontPhase::Handoff);
        true
    }

    /// The front end's first steps of `settle` at a draw's end
    /// ([`super::quiet`]'s `draw_done_alone`) in their common case, taken
    /// without the general step's dispatch: the held draw goes to the
    /// geometry stage (its closed form, its [`Ev::DrawDone`]), and the front
    /// end takes the next command when it is a draw with front-end work
    /// (its job, quiet when it ends before the new draw, as in
    /// [`FrontEnd::job`]), or starts waiting for commands when the FIFO is
    /// empty. Any other next command, a draw without its closed form, and
    /// a draw with a stalling state setup (it runs first, now that the
    /// stage is free), leave everything to `settle`. The CPU's step that `settle` takes
    /// first does nothing at this instant (a draw's end frees no FIFO space
    /// and completes no frame), so taking the front end's steps before it
    /// changes no order; `settle` runs next and takes every step left.
    /// Returns whether the front end is running the next command's job.
    #[inline]
    pub(super) fn handoff_fast(
        &mut self,
        now: Time,
        env: &mut Env,
        geom: &mut GeometryStage,
        frag: &mut FragmentStage,
        s: &mut Scheduler<Ev>,
    ) -> Result<bool, SystemError> {
        let (Command::Draw { draw, .. }, Some(sc)) = (self.cmd, &env.scene) else {
            return Ok(false);
        };
        let d = &sc.draws[draw as usize];
        let Some(t) = d.closed else {
            return Ok(false);
        };
        if d.setup.0 > 0 {
            return Ok(false);
        }
        let triangles = sc.meshes[d.mesh as usize].triangles;
        let next = match env.links.commands.front() {
            None => None,
            Some(&Command::Draw { draw: n, .. }) => {
                let n = &sc.draws[n as usize];
                if n.front.0 == 0 {
                    return Ok(false);
                }
                Some((n.front, u64::from(n.commands)))
            }
            Some(_) => return Ok(false),
        };
        // The geometry stage takes the held draw (`GeometryStage::start_draw`).
        if geom.start_closed_draw(draw, triangles, t, env.traced, s)? {
            frag.set_closed_busy(true);
        }
        self.phase = FrontPhase::Idle;
        // The front end takes the next draw command (`begin`, `job`).
        if let Some((work, commands)) = next
            && let Some(c) = env.links.commands.pop()
        {
            self.executed += commands;
            self.cmd = c;
            self.start_job(now, c, work, geom.done_at(), s)?;
            self.phase = FrontPhase::Running;
            return Ok(true);
        }
        Ok(false)
    }
}

/// Whether the front end's job for `c`, ending at `end`, would only start a
/// hand-off: a draw command finished while the geometry stage's draw ends
/// later, at `geometry_done_at` (one ending at the same instant runs first,
/// since it was scheduled first, and frees the stage).
#[inline(always)]
fn quiet_completion(c: Command, end: Time, geometry_done_at: Option<Time>) -> bool {
    matches!(c, Command::Draw { .. }) && geometry_done_at.is_some_and(|d| d > end)
}
