//! The CPU thread (paper 000 §4.3-4.4, Figure 4): per frame it waits until
//! fewer than `max_frames_ahead` frames are in flight, samples input, runs
//! non-rendering work, then issues clear, one batch per object (traversal,
//! driver cost per draw and per state change, uploads over the bus) and the
//! swap, pushing each into the command FIFO. A full FIFO blocks it.

use crate::engine::{Duration, Scheduler, Time};

use super::model::{Command, CpuPhase, Ev, FramePipeline, FrontPhase, Program, draw_batch_weight};
use super::records::FrameRecord;
use crate::systems::error::SystemError;

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

impl FramePipeline {
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

    fn op_work(&mut self, op: Op) -> Duration {
        let c = &self.cfg.cpu;
        match op {
            Op::Input => c.input_sampling,
            Op::NonRender => {
                let work = Duration::from_ps_f64(c.non_render.sample(&mut self.non_render_rng));
                // Per-frame variation (config `variation.cpu`), drawn only when given.
                match &self.cfg.variation.cpu() {
                    Some(v) => work.saturating_add(Duration::from_ps_f64(v.sample(&mut self.variation_rng[0]))),
                    None => work,
                }
            }
            Op::Clear => c.clear,
            Op::Swap => c.swap,
            Op::Fixed => match &mut self.program {
                Program::Fixed { cpu, cpu_rng, .. } => Duration::from_ps_f64(cpu.sample(cpu_rng)),
                Program::Scene(_) => Duration::ZERO,
            },
            Op::Draw(k) => match &self.program {
                Program::Scene(sc) => sc.draws[k as usize].cpu,
                Program::Fixed { .. } => Duration::ZERO,
            },
        }
    }

    /// The phase after operation `cpu_op`'s work is done.
    fn cpu_after_work(&mut self, now: Time) -> CpuPhase {
        let frame = self.cpu_frame;
        match self.op_at(self.cpu_op) {
            Op::Input => {
                self.records[frame as usize].input = now;
                self.cpu_advance(now)
            }
            Op::NonRender => self.cpu_advance(now),
            Op::Clear => self.push_phase(Command::Clear { frame }),
            Op::Fixed => {
                let gpu = match &mut self.program {
                    Program::Fixed { gpu, gpu_rng, .. } => Duration::from_ps_f64(gpu.sample(gpu_rng)),
                    Program::Scene(_) => Duration::ZERO,
                };
                self.push_phase(Command::Fixed { frame, gpu })
            }
            Op::Draw(k) => self.push_phase(Command::Draw { frame, draw: k }),
            Op::Swap => self.push_phase(Command::Swap { frame }),
        }
    }

    /// The phase that pushes `c`.
    #[inline]
    fn push_phase(&mut self, c: Command) -> CpuPhase {
        self.cpu_cmd = c;
        self.cpu_cmd_weight = self.command_weight(&c);
        CpuPhase::Push
    }

    /// After a completed push or an operation without command: next
    /// operation, or the end of the frame after the swap.
    fn cpu_advance(&mut self, now: Time) -> CpuPhase {
        if let Op::Swap = self.op_at(self.cpu_op) {
            self.records[self.cpu_frame as usize].present = now;
            self.cpu_frame += 1;
            self.cpu_op = 0;
            CpuPhase::NextFrame
        } else {
            self.cpu_op += 1;
            CpuPhase::Ready
        }
    }

    /// The running operation's work finished.
    pub(super) fn cpu_op_done(&mut self, now: Time) {
        debug_assert_eq!(self.cpu_phase, CpuPhase::Running);
        self.cpu_phase = self.cpu_after_work(now);
    }

    /// After an operation's work, when nothing but the CPU thread moves:
    /// takes the CPU's step (push the command, start the next operation)
    /// and returns true when that was all the event did, so `settle` and
    /// `account` can be skipped. That holds when the front end is not
    /// waiting for commands (a push wakes only an idle front end; no other
    /// GPU step depends on the CPU), no trace is written (it records the
    /// FIFO's level at every event), and the CPU ends up on the same frame
    /// either working (its clock, frame and critical-path mode are what the
    /// last event left) or blocked on a full command FIFO (then only its
    /// own clock and mode move, [`FramePipeline::account_cpu_alone`]; in a
    /// GPU-bound stretch that is about a quarter of the operations). A new
    /// frame or a rendezvous needs the full accounting. Returns false
    /// otherwise, with at most the CPU's step taken, which `settle` then
    /// repeats as a no-op before the front end's.
    pub(super) fn cpu_step_alone(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        if self.front_phase == FrontPhase::Idle || self.acct.trace.is_some() {
            return Ok(false);
        }
        let frame = self.cpu_frame;
        self.cpu_step(now, s)?;
        if self.cpu_frame != frame {
            return Ok(false);
        }
        match self.cpu_phase {
            CpuPhase::Running => Ok(true),
            CpuPhase::Push => {
                self.account_cpu_alone(now);
                Ok(true)
            }
            _ => Ok(false),
        }
    }

    /// A draw batch's CPU work finished (`cpu_op` is a draw of the scene's
    /// body), in the case that is most of a long run's CPU events: the
    /// front end is not waiting for commands, no trace is written, and the
    /// batch either fits in the FIFO (pushed, and the next operation
    /// starts, [`FramePipeline::push_draw_start_next`]) or finds it full
    /// (the CPU waits). That is what [`FramePipeline::cpu_op_done`]
    /// followed by [`FramePipeline::cpu_step_alone`] does then, taken
    /// without the general steps' dispatch on the operation and the phase.
    /// Returns false, having changed nothing, in every other case (the
    /// general path runs): the front end idle, a trace, a fixed workload,
    /// the next operation without work, a FIFO the batch would overfill.
    #[inline]
    pub(super) fn cpu_draw_done_fast(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        let k = self.cpu_op.wrapping_sub(3);
        if k >= self.body_ops || !self.scene_body || self.front_phase == FrontPhase::Idle || self.acct.trace.is_some() {
            return Ok(false);
        }
        let Program::Scene(sc) = &self.program else {
            return Ok(false);
        };
        let d = &sc.draws[k as usize];
        let weight = draw_batch_weight(self.cfg.command_fifo.unit, d);
        let cmd = Command::Draw {
            frame: self.cpu_frame,
            draw: k,
        };
        if !self.fifo.can_push(weight) {
            // Blocked on a full FIFO: only the CPU's clock and mode move.
            self.cpu_cmd = cmd;
            self.cpu_cmd_weight = weight;
            self.cpu_phase = CpuPhase::Push;
            self.account_cpu_alone(now);
            return Ok(true);
        }
        if !self.push_draw_start_next(now, s, cmd, weight)? {
            return Ok(false);
        }
        Ok(true)
    }

    /// Pushes the draw batch `cmd` of the current frame (weight `weight`,
    /// which fits in the FIFO) and starts the CPU's next operation, a draw
    /// or the swap, as [`FramePipeline::cpu_step_from_rest`] does from
    /// [`CpuPhase::Push`]; the CPU is then [`CpuPhase::Running`]. Returns
    /// false, having changed nothing, when that is not all the step would
    /// do: the batch would fill the FIFO past its capacity (a rendezvous),
    /// or the next operation has no work (it ends at once).
    #[inline(always)]
    fn push_draw_start_next(
        &mut self,
        now: Time,
        s: &mut Scheduler<Ev>,
        cmd: Command,
        weight: u64,
    ) -> Result<bool, SystemError> {
        let (Command::Draw { draw: k, .. }, Program::Scene(sc)) = (cmd, &self.program) else {
            return Ok(false);
        };
        let Some(d) = sc.draws.get(k as usize) else {
            return Ok(false);
        };
        let next = match sc.draws.get(k as usize + 1) {
            Some(n) => n.cpu,
            None => self.cfg.cpu.swap,
        };
        if next.0 == 0 || self.fifo.used().saturating_add(weight) > self.fifo.capacity() {
            return Ok(false);
        }
        let count = u64::from(d.commands);
        self.fifo.push(cmd, weight);
        self.commands_issued += count;
        self.cpu_cmd = cmd;
        self.cpu_cmd_weight = weight;
        self.cpu_op += 1;
        let w = self.cpu.start_job(now, next)?;
        Self::schedule_wake(s, w, true);
        self.cpu_phase = CpuPhase::Running;
        Ok(true)
    }

    /// Advances the CPU thread as far as it can go now. Returns whether
    /// anything changed.
    #[inline]
    pub(super) fn cpu_step(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        // At rest while an operation runs or too many frames are in flight
        // (most events find it so), and for good once finished or waiting
        // for its zero-time frame: no step, and no call.
        match self.cpu_phase {
            CpuPhase::Running | CpuPhase::ZeroTimeWait | CpuPhase::Finished => return Ok(false),
            CpuPhase::WaitFrames if self.frames_ahead_full() => {
                return Ok(false);
            }
            // Blocked on a full FIFO (or a rendezvous not yet taken).
            CpuPhase::Push if !self.fifo.can_push(self.cpu_cmd_weight) => return Ok(false),
            CpuPhase::Rendezvous if self.fifo.over_capacity() => return Ok(false),
            _ => {}
        }
        self.cpu_step_from_rest(now, s)
    }

    /// Whether `cpu.max_frames_ahead` frames are in flight (submitted by the
    /// CPU, not yet completed by the GPU): the CPU may not start another.
    #[inline(always)]
    fn frames_ahead_full(&self) -> bool {
        self.cpu_frame - self.gpu_completed >= u64::from(self.cfg.cpu.max_frames_ahead)
    }

    /// [`FramePipeline::cpu_step`] from a phase that may move.
    #[inline(never)]
    fn cpu_step_from_rest(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        // Released from a full FIFO with a draw batch (at a draw's end, in a
        // GPU-bound stretch): push it and start the next operation.
        if self.cpu_phase == CpuPhase::Push
            && self.fifo.can_push(self.cpu_cmd_weight)
            && self.push_draw_start_next(now, s, self.cpu_cmd, self.cpu_cmd_weight)?
        {
            return Ok(true);
        }
        let mut progressed = false;
        loop {
            match self.cpu_phase {
                CpuPhase::NextFrame | CpuPhase::WaitFrames => {
                    if self.cpu_frame >= self.frames_total {
                        self.cpu_phase = CpuPhase::Finished;
                        return Ok(true);
                    }
                    if self.records.len() as u64 == self.cpu_frame {
                        self.records.push(FrameRecord::new(self.cpu_frame, now));
                    }
                    if self.frames_ahead_full() {
                        let changed = self.cpu_phase != CpuPhase::WaitFrames;
                        self.cpu_phase = CpuPhase::WaitFrames;
                        return Ok(progressed || changed);
                    }
                    // Frames that take no time would all run at this one
                    // instant inside this call, unseen by the run loop and
                    // its limits: past the most that could be in flight,
                    // each goes through the loop as an event.
                    let (at, n) = self.frames_at_instant;
                    let n = if at == now { n } else { 0 };
                    if n >= self.zero_time_after && !self.zero_time_go {
                        s.at(now, Ev::ZeroTimeFrame);
                        self.cpu_phase = CpuPhase::ZeroTimeWait;
                        return Ok(true);
                    }
                    self.zero_time_go = false;
                    self.frames_at_instant = (now, n + 1);
                    self.cpu_op = 0;
                    self.cpu_phase = CpuPhase::Ready;
                }
                CpuPhase::Ready => {
                    let work = self.op_work(self.op_at(self.cpu_op));
                    if work.0 > 0 || self.cpu.in_system() {
                        let w = self.cpu.start_job(now, work)?;
                        Self::schedule_wake(s, w, true);
                        self.cpu_phase = CpuPhase::Running;
                        return Ok(true);
                    }
                    self.cpu_phase = self.cpu_after_work(now);
                }
                CpuPhase::Push => {
                    let c = self.cpu_cmd;
                    let w = self.cpu_cmd_weight;
                    if !self.fifo.can_push(w) {
                        return Ok(progressed);
                    }
                    self.fifo.push(c, w);
                    self.commands_issued += self.command_count(&c);
                    self.cpu_phase = if self.fifo.over_capacity() {
                        CpuPhase::Rendezvous
                    } else {
                        self.cpu_advance(now)
                    };
                }
                CpuPhase::Rendezvous => {
                    if self.fifo.over_capacity() {
                        return Ok(progressed);
                    }
                    self.cpu_phase = self.cpu_advance(now);
                }
                CpuPhase::Running | CpuPhase::ZeroTimeWait | CpuPhase::Finished => return Ok(progressed),
            }
            progressed = true;
        }
    }
}
