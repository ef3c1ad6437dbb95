//! The CPU thread (paper 000 §4.3-4.4, Figure 4): per frame it waits until
//! fewer than `max_frames_ahead` frames are in flight, samples input, runs
//! non-rendering work, then issues clear, one batch per object (traversal,
//! driver cost per draw and per state change, uploads over the bus) and the
//! swap, pushing each into the command FIFO. A full FIFO blocks it.
//!
//! [`CpuThread`] owns the thread's state (its phase, frame, operation, the
//! command it must push, its random streams, the fixed workload's CPU and
//! GPU times) and every transition that changes it; the command FIFO, the
//! count of completed frames and the records come in an [`Env`].

use crate::components::preemptible::{Preemptible, Wake};
use crate::engine::{Duration, Scheduler, StreamRng, Time};
use crate::systems::error::SystemError;

mod fixed_work;
mod pacing;

pub use fixed_work::FixedWork;

use super::bus_copy::BusCopy;
use super::events::Ev;
use super::links::{Command, Env, command_count, draw_batch_weight};
use super::records::FrameRecord;
use super::unit_specs::CpuSpec;

/// What the CPU thread is doing. The phases carry no data (the command
/// to push is the thread's own), so a phase is one byte, written and read
/// back whole on the hot path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CpuPhase {
    /// About to start the next frame (transient).
    NextFrame,
    /// Blocked: too many frames in flight.
    WaitFrames,
    /// About to run the current operation (transient).
    Ready,
    /// Running the current operation (possibly preempted).
    Running,
    /// Must push its command; at rest this means the FIFO is full.
    Push,
    /// Pushed into a FIFO beyond its capacity (rendezvous): waits until taken.
    Rendezvous,
    /// Waits for its [`Ev::ZeroTimeFrame`] event before starting a frame
    /// that takes no time.
    ZeroTimeWait,
    /// Held by the frame limiter or the low-latency pacer before starting
    /// a frame (`[pacing]`); [`Ev::PaceWake`] ends it.
    PaceStart,
    /// Held by a present-measured frame limiter before the present
    /// (`pacing.limit_from = "present"`); [`Ev::PaceWake`] ends it.
    PacePresent,
    /// A replayed frame (`kind = "frames"`) waits for the previous frame's
    /// present call to return, as long as the capture timed it;
    /// [`Ev::PresentReturn`] ends it.
    InPresent,
    /// All frames submitted.
    Finished,
    /// Held by a submission-measured frame limiter (the GPU driver's cap,
    /// `pacing.limit_from = "submit"`) before the frame's first GPU
    /// command; [`Ev::PaceWake`] ends it.
    PaceSubmit,
}

/// How a CPU event that only the CPU thread moved ended (the short cuts
/// [`CpuThread::draw_done_fast`] and [`CpuThread::step_alone`]): what is
/// left of the instant's accounting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Alone {
    /// The thread runs its next operation on the same frame: its clock,
    /// frame and critical-path mode are what the last event left.
    Running,
    /// Blocked on a full command FIFO: only its own clock and mode move.
    Blocked,
}

/// One step of the CPU thread's frame.
#[derive(Debug, Clone, Copy)]
enum Op {
    Input,
    NonRender,
    Clear,
    Fixed,
    Draw(u32),
    Swap,
}

/// The CPU thread.
#[derive(Debug)]
pub struct CpuThread {
    work: Preemptible,
    phase: CpuPhase,
    /// The command of [`CpuPhase::Push`].
    cmd: Command,
    /// Its weight in the FIFO's unit (so a push blocked on a full FIFO is
    /// found without a call).
    cmd_weight: u64,
    /// Operations between the clear and the swap: the scene's draws, or the
    /// one fixed GPU command.
    body_ops: u32,
    /// Whether those are a scene's draws (else the fixed command).
    scene_body: bool,
    frame: u64,
    op: u32,
    frames_total: u64,
    non_render_rng: StreamRng,
    /// The per-frame variation stream (`variation.cpu`).
    variation_rng: StreamRng,
    /// A fixed workload (`None`: a scene).
    fixed: Option<FixedWork>,
    /// The instant the thread last started a frame, and how many frames it
    /// started then.
    frames_at_instant: (Time, u64),
    /// Frames started at one instant beyond which a frame is known to take
    /// no time (more than could be in flight); see [`Ev::ZeroTimeFrame`].
    zero_time_after: u64,
    /// The pending [`Ev::ZeroTimeFrame`] was handled: start the frame.
    zero_time_go: bool,
    /// Commands pushed.
    issued: u64,
    /// The pending [`Ev::PaceWake`] was handled: go on without pacing again.
    pace_go: bool,
    /// The phase a [`Ev::PaceWake`] resumes.
    pace_resume: CpuPhase,
    /// Whether the low-latency pacer (not a limiter) set the start wait.
    pace_for_gpu: bool,
    /// When the last frame's first GPU command (its clear) started.
    last_submit: Option<Time>,
    /// Whether the workload is given frame by frame (`kind = "frames"`).
    per_frame: bool,
    /// What it reads of the model.
    spec: CpuSpec,
    /// The current draw's copy over a shared bus, while it runs
    /// ([`super::bus_copy`]).
    copy: Option<BusCopy>,
}

#[inline(always)]
fn schedule(s: &mut Scheduler<Ev>, w: Wake) {
    if let Wake::JobAt(t, tag) = w {
        s.at(t, Ev::CpuDone { tag });
    }
}

impl CpuThread {
    /// A thread at the start of frame 0 of `frames_total`; `body_ops`
    /// operations between clear and swap (`scene_body`: a scene's draws);
    /// `zero_time_after`: see [`Ev::ZeroTimeFrame`].
    pub(super) fn new(
        spec: CpuSpec,
        frames_total: u64,
        (body_ops, scene_body): (u32, bool),
        rngs: [StreamRng; 2],
        fixed: Option<FixedWork>,
        zero_time_after: u64,
    ) -> Self {
        let [non_render_rng, variation_rng] = rngs;
        CpuThread {
            work: Preemptible::new(),
            phase: CpuPhase::NextFrame,
            cmd: Command::Clear { frame: 0 },
            cmd_weight: 1,
            body_ops,
            scene_body,
            frame: 0,
            op: 0,
            frames_total,
            non_render_rng,
            variation_rng,
            per_frame: matches!(fixed, Some(FixedWork::PerFrame(_))),
            fixed,
            frames_at_instant: (Time::ZERO, 0),
            zero_time_after,
            zero_time_go: false,
            issued: 0,
            pace_go: false,
            pace_resume: CpuPhase::NextFrame,
            pace_for_gpu: false,
            last_submit: None,
            copy: None,
            spec,
        }
    }

    /// The phase.
    #[inline(always)]
    pub(super) fn phase(&self) -> CpuPhase {
        self.phase
    }

    /// The frame the thread is on.
    #[inline(always)]
    pub(super) fn frame(&self) -> u64 {
        self.frame
    }

    /// Whether a system task holds the thread.
    #[inline(always)]
    pub(super) fn in_system(&self) -> bool {
        self.work.in_system()
    }

    /// Commands pushed so far.
    pub(super) fn issued(&self) -> u64 {
        self.issued
    }

    /// For stall reports: the phase (with the command it must push), frame
    /// and operation.
    pub(super) fn describe(&self) -> String {
        let phase = match self.phase {
            CpuPhase::Push => format!("Push({:?})", self.cmd),
            p => format!("{p:?}"),
        };
        format!("{phase} (frame {}, op {})", self.frame, self.op)
    }

    /// The running operation's job with `tag` completed (false: a stale tag).
    #[inline(always)]
    pub(super) fn complete(&mut self, tag: u32) -> bool {
        self.work.complete(tag)
    }

    /// A system task of `d` arrives; returns when it ends, if it runs now.
    pub(super) fn task_arrives(&mut self, now: Time, d: Duration) -> Result<Option<Time>, SystemError> {
        Ok(self.work.task_arrives(now, d)?)
    }

    /// The running system task ends: returns when the next one ends, if one
    /// runs, and the wake of the job it held ([`CpuThread::schedule_wake`]).
    pub(super) fn task_ends(&mut self, now: Time) -> Result<(Option<Time>, Wake), SystemError> {
        Ok(self.work.task_ends(now)?)
    }

    /// Schedules the completion of a job the thread started or resumed.
    #[inline(always)]
    pub(super) fn schedule_wake(s: &mut Scheduler<Ev>, w: Wake) {
        schedule(s, w);
    }

    /// The [`Ev::ZeroTimeFrame`] event: the waiting frame may start.
    pub(super) fn zero_time_frame(&mut self) {
        self.zero_time_go = true;
        self.phase = CpuPhase::NextFrame;
    }

    #[inline]
    fn op_at(&self, op: u32) -> Op {
        match op {
            0 => Op::Input,
            1 => Op::NonRender,
            2 => Op::Clear,
            _ => {
                let k = op - 3;
                match (self.scene_body, k < self.body_ops) {
                    (false, true) => Op::Fixed,
                    (true, true) => Op::Draw(k),
                    (_, false) => Op::Swap,
                }
            }
        }
    }

    fn op_work(&mut self, op: Op, env: &Env) -> Duration {
        let c = &self.spec;
        match op {
            Op::Input => c.input_sampling,
            Op::NonRender => {
                let work = Duration::from_ps_f64(c.non_render.sample(&mut self.non_render_rng));
                // Per-frame variation (config `variation.cpu`), drawn only when given.
                let work = match &c.variation {
                    Some(v) => work.saturating_add(Duration::from_ps_f64(v.sample(&mut self.variation_rng))),
                    None => work,
                };
                match &self.fixed {
                    Some(f) => work.saturating_add(f.before_clear(self.frame)),
                    None => work,
                }
            }
            Op::Clear => c.clear,
            Op::Swap => match &self.fixed {
                Some(f) => c.swap.saturating_add(f.after_submit(self.frame)),
                None => c.swap,
            },
            Op::Fixed => match &mut self.fixed {
                Some(f) => f.before_submit(),
                None => Duration::ZERO,
            },
            Op::Draw(k) => match &env.scene {
                Some(sc) => sc.draws[k as usize].cpu,
                None => Duration::ZERO,
            },
        }
    }

    /// The phase after the current operation's work is done.
    fn after_work(&mut self, now: Time, env: &mut Env) -> CpuPhase {
        let frame = self.frame;
        match self.op_at(self.op) {
            Op::Input => {
                env.records[frame as usize].input = now;
                self.advance(now, env)
            }
            Op::NonRender => self.advance(now, env),
            Op::Clear => self.push_phase(Command::Clear { frame }, env),
            Op::Fixed => {
                let gpu = match &mut self.fixed {
                    Some(f) => f.gpu(frame),
                    None => Duration::ZERO,
                };
                self.push_phase(Command::Fixed { frame, gpu }, env)
            }
            Op::Draw(k) => self.push_phase(Command::Draw { frame, draw: k }, env),
            Op::Swap => self.push_phase(Command::Swap { frame }, env),
        }
    }

    /// The phase that pushes `c`.
    #[inline]
    fn push_phase(&mut self, c: Command, env: &Env) -> CpuPhase {
        self.cmd = c;
        self.cmd_weight = self.spec.weights.of(&env.scene, &c);
        CpuPhase::Push
    }

    /// After a completed push or an operation without command: next
    /// operation, or the end of the frame after the swap.
    fn advance(&mut self, now: Time, env: &mut Env) -> CpuPhase {
        if let Op::Swap = self.op_at(self.op) {
            env.records[self.frame as usize].present = now;
            self.frame += 1;
            self.op = 0;
            CpuPhase::NextFrame
        } else {
            self.op += 1;
            CpuPhase::Ready
        }
    }

    /// On a shared bus ([`super::bus_copy`]), the running operation's work
    /// finished: a draw with an upload then copies it (returns true: the
    /// thread runs on, the copy's end is its next event), and a copy's end
    /// is recorded in the frame (returns false: the draw's batch is pushed
    /// as after any work).
    pub(super) fn copy_turn(&mut self, now: Time, env: &mut Env, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        if let Some(c) = self.copy.take() {
            let took = c.end(now, &mut env.links.bus);
            env.records[self.frame as usize].copy += took.0;
            return Ok(false);
        }
        let Some((bytes, alone)) = self.pending_copy(env) else {
            return Ok(false);
        };
        // The rate alone: the bytes over their time into their memory.
        let alone = bytes as f64 / alone.0.max(1) as f64;
        let (copy, t) = BusCopy::begin(now, bytes, alone, &mut env.links.bus);
        self.copy = Some(copy);
        let w = self.work.start_job(now, t)?;
        schedule(s, w);
        Ok(true)
    }

    /// The bytes the current operation still has to copy and their time
    /// alone: a draw with an upload on a shared bus whose copy has not run.
    fn pending_copy(&self, env: &Env) -> Option<(u64, Duration)> {
        let sc = env.scene.as_ref().filter(|sc| sc.bus_shared)?;
        if self.copy.is_some() {
            return None;
        }
        match self.op_at(self.op) {
            Op::Draw(k) => Some(&sc.draws[k as usize])
                .filter(|d| d.upload > 0)
                .map(|d| (d.upload, d.copy)),
            _ => None,
        }
    }

    /// The bus's shares moved: a running copy goes on at its new rate.
    pub(super) fn bus_changed(&mut self, now: Time, env: &mut Env, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if let Some(c) = &mut self.copy
            && let Some(factor) = c.retime(&env.links.bus)
        {
            let w = self.work.rescale(now, factor)?;
            schedule(s, w);
        }
        Ok(())
    }

    /// The running operation's work finished.
    pub(super) fn op_done(&mut self, now: Time, env: &mut Env) {
        debug_assert_eq!(self.phase, CpuPhase::Running);
        self.phase = self.after_work(now, env);
    }

    /// After an operation's work ([`CpuThread::op_done`]), when nothing but
    /// the CPU thread moves: takes the thread's step (push the command,
    /// start the next operation) and returns what is left of the instant's
    /// accounting when that was all the event did, so the pipeline's
    /// `settle` and `account` can be skipped. The caller calls it only when
    /// the front end is not waiting for commands (a push wakes only an idle
    /// front end; no other GPU step depends on the CPU) and no trace is
    /// written (it records the FIFO's level at every event). It holds when
    /// the thread ends up on the same frame either working ([`Alone::Running`])
    /// or blocked on a full command FIFO ([`Alone::Blocked`]; in a
    /// GPU-bound stretch that is about a quarter of the operations). A new
    /// frame or a rendezvous needs the full accounting. Returns `None`
    /// otherwise, with at most the thread's step taken, which `settle` then
    /// repeats as a no-op before the front end's.
    pub(super) fn step_alone(
        &mut self,
        now: Time,
        env: &mut Env,
        s: &mut Scheduler<Ev>,
    ) -> Result<Option<Alone>, SystemError> {
        let frame = self.frame;
        self.step(now, env, s)?;
        if self.frame != frame {
            return Ok(None);
        }
        Ok(match self.phase {
            CpuPhase::Running => Some(Alone::Running),
            CpuPhase::Push => Some(Alone::Blocked),
            _ => None,
        })
    }

    /// A draw batch's CPU work finished (the current operation is a draw of
    /// the scene's body), in the case that is most of a long run's CPU
    /// events: the caller found the front end not waiting for commands and
    /// no trace written, and the batch either fits in the FIFO (pushed, and
    /// the next operation starts, [`CpuThread::push_draw_start_next`]) or
    /// finds it full (the thread waits). That is what
    /// [`CpuThread::op_done`] followed by [`CpuThread::step_alone`] does
    /// then, taken without the general steps' dispatch on the operation and
    /// the phase. Returns `None`, having changed nothing, in every other
    /// case (the general path runs): a fixed workload, the next operation
    /// without work, a FIFO the batch would overfill.
    #[inline(always)]
    pub(super) fn draw_done_fast(
        &mut self,
        now: Time,
        env: &mut Env,
        s: &mut Scheduler<Ev>,
    ) -> Result<Option<Alone>, SystemError> {
        let k = self.op.wrapping_sub(3);
        if k >= self.body_ops || !self.scene_body {
            return Ok(None);
        }
        let Some(sc) = &env.scene else {
            return Ok(None);
        };
        let d = &sc.draws[k as usize];
        let weight = draw_batch_weight(self.spec.weights.unit, d);
        let cmd = Command::Draw {
            frame: self.frame,
            draw: k,
        };
        if !env.links.commands.can_push(weight) {
            // Blocked on a full FIFO: only the thread's clock and mode move.
            self.cmd = cmd;
            self.cmd_weight = weight;
            self.phase = CpuPhase::Push;
            return Ok(Some(Alone::Blocked));
        }
        if !self.push_draw_start_next(now, env, s, cmd, weight)? {
            return Ok(None);
        }
        Ok(Some(Alone::Running))
    }

    /// Pushes the draw batch `cmd` of the current frame (weight `weight`,
    /// which fits in the FIFO) and starts the thread's next operation, a
    /// draw or the swap, as [`CpuThread::step_from_rest`] does from
    /// [`CpuPhase::Push`]; the thread is then [`CpuPhase::Running`]. Returns
    /// false, having changed nothing, when that is not all the step would
    /// do: the batch would fill the FIFO past its capacity (a rendezvous),
    /// the next operation has no work (it ends at once), or it is the swap
    /// and a limiter waits before the present.
    #[inline(always)]
    fn push_draw_start_next(
        &mut self,
        now: Time,
        env: &mut Env,
        s: &mut Scheduler<Ev>,
        cmd: Command,
        weight: u64,
    ) -> Result<bool, SystemError> {
        let (Command::Draw { draw: k, .. }, Some(sc)) = (cmd, &env.scene) else {
            return Ok(false);
        };
        let Some(d) = sc.draws.get(k as usize) else {
            return Ok(false);
        };
        let next = match sc.draws.get(k as usize + 1) {
            Some(n) => n.cpu,
            // The swap: a limiter that waits before the present holds it
            // (`op_wait`, from `CpuPhase::Ready`), so that start is the
            // general path's.
            None if self.spec.pacing.present_limit().is_some() => return Ok(false),
            None => self.spec.swap,
        };
        let fifo = &mut env.links.commands;
        if next.0 == 0 || fifo.used().saturating_add(weight) > fifo.capacity() {
            return Ok(false);
        }
        let count = u64::from(d.commands);
        fifo.push(cmd, weight);
        self.issued += count;
        self.cmd = cmd;
        self.cmd_weight = weight;
        self.op += 1;
        let w = self.work.start_job(now, next)?;
        schedule(s, w);
        self.phase = CpuPhase::Running;
        Ok(true)
    }

    /// Advances the thread as far as it can go now. Returns whether
    /// anything changed.
    #[inline(always)]
    pub(super) fn step(&mut self, now: Time, env: &mut Env, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        // At rest while an operation runs or too many frames are in flight
        // (most events find it so), and for good once finished or waiting
        // for its zero-time frame: no step, and no call.
        match self.phase {
            CpuPhase::Running
            | CpuPhase::ZeroTimeWait
            | CpuPhase::PaceStart
            | CpuPhase::PacePresent
            | CpuPhase::PaceSubmit
            | CpuPhase::InPresent
            | CpuPhase::Finished => return Ok(false),
            CpuPhase::WaitFrames if self.frames_ahead_full(env) => {
                return Ok(false);
            }
            // Blocked on a full FIFO (or a rendezvous not yet taken).
            CpuPhase::Push if !env.links.commands.can_push(self.cmd_weight) => return Ok(false),
            CpuPhase::Rendezvous if env.links.commands.over_capacity() => return Ok(false),
            _ => {}
        }
        self.step_from_rest(now, env, s)
    }

    /// Whether `cpu.max_frames_ahead` frames are in flight (submitted by the
    /// CPU, not yet completed by the GPU): the thread may not start another.
    #[inline(always)]
    fn frames_ahead_full(&self, env: &Env) -> bool {
        self.frame - env.links.frames_completed >= u64::from(self.spec.max_frames_ahead)
    }

    /// [`CpuThread::step`] from a phase that may move.
    #[inline(never)]
    fn step_from_rest(&mut self, now: Time, env: &mut Env, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        // Released from a full FIFO with a draw batch (at a draw's end, in a
        // GPU-bound stretch): push it and start the next operation.
        if self.phase == CpuPhase::Push
            && env.links.commands.can_push(self.cmd_weight)
            && self.push_draw_start_next(now, env, s, self.cmd, self.cmd_weight)?
        {
            return Ok(true);
        }
        let mut progressed = false;
        loop {
            match self.phase {
                CpuPhase::NextFrame | CpuPhase::WaitFrames => {
                    if let Some(done) = self.start_frame(now, env, s) {
                        return Ok(progressed || done);
                    }
                }
                CpuPhase::Ready => {
                    if let Some(t) = self.op_wait(now, env) {
                        s.at(t, Ev::PaceWake);
                        self.pace_resume = CpuPhase::Ready;
                        self.phase = match self.op_at(self.op) {
                            Op::Clear => CpuPhase::PaceSubmit,
                            _ => CpuPhase::PacePresent,
                        };
                        return Ok(true);
                    }
                    if let Op::Clear = self.op_at(self.op) {
                        // The frame's first GPU command starts now (a
                        // submission-measured limiter counts from here).
                        self.last_submit = Some(now);
                    }
                    let work = self.op_work(self.op_at(self.op), env);
                    // A draw with nothing but its copy still runs (for no
                    // time), so its end starts the copy.
                    if work.0 > 0 || self.work.in_system() || self.pending_copy(env).is_some() {
                        let w = self.work.start_job(now, work)?;
                        schedule(s, w);
                        self.phase = CpuPhase::Running;
                        return Ok(true);
                    }
                    self.phase = self.after_work(now, env);
                }
                CpuPhase::Push => {
                    let c = self.cmd;
                    let w = self.cmd_weight;
                    let fifo = &mut env.links.commands;
                    if !fifo.can_push(w) {
                        return Ok(progressed);
                    }
                    fifo.push(c, w);
                    self.issued += command_count(&env.scene, &c);
                    self.phase = if env.links.commands.over_capacity() {
                        CpuPhase::Rendezvous
                    } else {
                        self.advance(now, env)
                    };
                }
                CpuPhase::Rendezvous => {
                    if env.links.commands.over_capacity() {
                        return Ok(progressed);
                    }
                    self.phase = self.advance(now, env);
                }
                CpuPhase::Running
                | CpuPhase::ZeroTimeWait
                | CpuPhase::PaceStart
                | CpuPhase::PacePresent
                | CpuPhase::PaceSubmit
                | CpuPhase::InPresent
                | CpuPhase::Finished => return Ok(progressed),
            }
            progressed = true;
        }
    }

    /// From [`CpuPhase::NextFrame`] or [`CpuPhase::WaitFrames`]: starts the
    /// frame ([`CpuPhase::Ready`], returns `None`: the step goes on), or
    /// returns whether the phase changed when the thread stops here
    /// (finished, too many frames in flight, a zero-time frame's event).
    #[inline(always)]
    fn start_frame(&mut self, now: Time, env: &mut Env, s: &mut Scheduler<Ev>) -> Option<bool> {
        if self.frame >= self.frames_total {
            self.phase = CpuPhase::Finished;
            return Some(true);
        }
        if env.records.len() as u64 == self.frame {
            env.records.push(FrameRecord::new(self.frame, now));
        }
        // A replayed frame begins when the previous present call returns, as
        // the capture timed it; a wait for frames in flight overlaps it.
        if self.per_frame && self.wait_in_present_call(now, env, s) {
            return Some(true);
        }
        if self.frames_ahead_full(env) {
            let changed = self.phase != CpuPhase::WaitFrames;
            self.phase = CpuPhase::WaitFrames;
            return Some(changed);
        }
        // Pacing (`[pacing]`): a limiter or the low-latency pacer holds the
        // frame; it starts, and samples input, when the wait ends.
        if std::mem::take(&mut self.pace_go) {
            let r = &mut env.records[self.frame as usize];
            (r.start, r.input) = (now, now);
        } else if let Some(t) = self.start_wait(now, env) {
            s.at(t, Ev::PaceWake);
            self.pace_resume = CpuPhase::NextFrame;
            self.phase = CpuPhase::PaceStart;
            return Some(true);
        }
        // Frames that take no time would all run at this one instant inside
        // this call, unseen by the run loop and its limits: past the most
        // that could be in flight, each goes through the loop as an event.
        let (at, n) = self.frames_at_instant;
        let n = if at == now { n } else { 0 };
        if n >= self.zero_time_after && !self.zero_time_go {
            s.at(now, Ev::ZeroTimeFrame);
            self.phase = CpuPhase::ZeroTimeWait;
            return Some(true);
        }
        self.zero_time_go = false;
        self.frames_at_instant = (now, n + 1);
        self.op = 0;
        env.records[self.frame as usize].begun = now;
        self.phase = CpuPhase::Ready;
        None
    }

    /// A replayed frame (`kind = "frames"`) that may not begin yet, because
    /// the previous frame's present call has not returned as the capture
    /// timed it (or the first frame's start is later), waits for it
    /// ([`CpuPhase::InPresent`]): returns true. Out of line: the other
    /// workloads never come here.
    #[inline(never)]
    fn wait_in_present_call(&mut self, now: Time, env: &Env, s: &mut Scheduler<Ev>) -> bool {
        let Some(t) = self.fixed.as_ref().and_then(|f| f.begins_at(self.frame, &env.records)) else {
            return false;
        };
        if t <= now {
            return false;
        }
        s.at(t, Ev::PresentReturn);
        self.phase = CpuPhase::InPresent;
        true
    }

    /// The [`Ev::PresentReturn`] event: the previous present call returned.
    pub(super) fn present_returned(&mut self) {
        if self.phase == CpuPhase::InPresent {
            self.phase = CpuPhase::NextFrame;
        }
    }
}
