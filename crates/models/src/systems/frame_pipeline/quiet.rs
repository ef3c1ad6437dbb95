//! Quiet completions at `draw` fidelity: a front-end completion that would
//! change nothing but the accounting is not queued as an event.
//!
//! Paper 000 §4.5: the GPU's front end processes a draw command (its state
//! changes) and hands the draw to the geometry stage, which takes it once
//! the previous draw is through (at `draw` fidelity, when that draw's closed
//! form ends, [`super::closed_form`]). When the front end finishes a draw
//! command while the geometry stage still holds an earlier draw, all that
//! happens is that the front end starts waiting for geometry: no FIFO space
//! is freed, no frame completes, and no unit can take a step it could not
//! take before. In a GPU-bound stretch that is almost every draw.
//!
//! Such a completion keeps its place in the event order without an event
//! ([`Scheduler::reserve`]); the hand-off and the accounting of that instant
//! are done at the first event handled after it (or after the run), exactly
//! where the event would have run ([`Scheduler::passed`]), so every clock,
//! record and critical-path share is the same to the picosecond. The run
//! counts only the front-end completions that do something
//! (`events.by_kind.gpu_front_end`), and has one event fewer to queue, pop
//! and settle per quiet draw. At `triangle` fidelity the geometry stage's
//! end is not known in advance, so every completion is an event.
//!
//! The same stretch's other common instant, a draw's end while the front
//! end holds the next draw, is an event as always, but its accounting
//! touches only the units that can have moved
//! ([`FramePipeline::draw_done_alone`]): the geometry and fragment stages go
//! from one draw to the next without a change of state, so only the CPU's
//! and the front end's clocks and the critical-path modes of the CPU, the
//! front end and the two stages are carried forward. Its steps are taken
//! directly in their common case (`handoff_fast`: the held draw goes to
//! geometry, the next draw command's front-end job starts), and the CPU's
//! accounting is skipped when the CPU took no step. The CPU's own common
//! instants have the same kind of direct path in `cpu.rs`
//! (`cpu_draw_done_fast`, `push_draw_start_next`). A traced run takes none
//! of these short cuts, which is what the trace-equivalence test compares
//! against.

use crate::engine::{Scheduler, Time};
use crate::systems::error::SystemError;

use super::accounting::FRONT_WAIT_GEOMETRY;
use super::critical_path::{Mode, Unit};
use super::model::{Command, Ev, FramePipeline, FrontPhase, Program};

impl FramePipeline {
    /// Whether the front end's job for `c`, ending at `end`, would only
    /// start a hand-off: a draw command finished while the geometry stage's
    /// draw ends later (one ending at the same instant runs first, since it
    /// was scheduled first, and frees the stage).
    #[inline]
    pub(super) fn quiet_completion(&self, c: Command, end: Time) -> bool {
        matches!(c, Command::Draw { .. }) && self.draw_done_at.is_some_and(|d| d > end)
    }

    /// Does the quiet completion whose turn came before the event being
    /// handled (after a run: before its end). Called first in every event.
    #[inline]
    pub(super) fn catch_up(&mut self, s: &Scheduler<Ev>) -> Result<(), SystemError> {
        if let Some((slot, tag)) = self.front_quiet
            && s.passed(slot)
        {
            self.front_quiet = None;
            self.quiet_front_done(slot.time(), tag)?;
        }
        Ok(())
    }

    /// The front end's draw command finished at `at` (job `tag`): the
    /// hand-off begins, and the instant is accounted as an event's would be.
    /// (`settle` would find nothing to do: the geometry stage holds a draw
    /// until after `at`, so the hand-off waits, and the CPU waits on
    /// nothing a hand-off changes.)
    #[inline(never)]
    fn quiet_front_done(&mut self, at: Time, tag: u32) -> Result<(), SystemError> {
        // A system task that preempted the job made the tag stale; the
        // resumed job's completion is an event of its own.
        if !self.front.complete(tag) {
            return Ok(());
        }
        debug_assert!(self.draw_done_at.is_some_and(|d| d > at));
        debug_assert!(matches!(self.front_cmd, Command::Draw { .. }));
        // What `front_command_done` does for a draw command: the hand-off
        // begins. (Calling it here costs 1.4% of the hour's instructions:
        // its result goes through memory.)
        if self.front_phase == FrontPhase::Running {
            self.front_phase = FrontPhase::Handoff;
        }
        debug_assert_eq!(self.front_phase, FrontPhase::Handoff);
        if self.acct.trace.is_some() {
            self.account(at);
            return Ok(());
        }
        // Without a trace, `account` would find only the front end moved
        // (busy -> waiting for geometry, for the critical path too): the
        // geometry and fragment stages are busy with the draw throughout
        // (so the GPU stays busy), the CPU and the frames are as the last
        // event left them.
        self.acct.front.set(at, FRONT_WAIT_GEOMETRY);
        self.acct.path.set_mode(Unit::Front, Mode::wait(Unit::Geometry), at);
        Ok(())
    }

    /// The front end's first steps of `settle` at a draw's end
    /// ([`FramePipeline::draw_done_alone`]) in their common case, taken
    /// without the general step's dispatch: the held draw goes to the
    /// geometry stage (its closed form, its [`Ev::DrawDone`]), and the front
    /// end takes the next command when it is a draw with front-end work
    /// (its job, quiet when it ends before the new draw, as in
    /// `front_job`), or starts waiting for commands when the FIFO is empty.
    /// Any other next command, and a draw without its closed form, leave
    /// everything to `settle`. The CPU's step that `settle` takes first
    /// does nothing at this instant (a draw's end frees no FIFO space and
    /// completes no frame), so taking the front end's steps before it
    /// changes no order; `settle` runs next and takes every step left.
    /// Returns whether the front end is running the next command's job.
    #[inline]
    fn handoff_fast(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        let (Command::Draw { draw, .. }, Program::Scene(sc)) = (self.front_cmd, &self.program) else {
            return Ok(false);
        };
        let d = &sc.draws[draw as usize];
        let Some(t) = d.closed else {
            return Ok(false);
        };
        let triangles = sc.meshes[d.mesh as usize].triangles;
        let next = match self.fifo.front() {
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
        // The geometry stage takes the held draw (`geom_start_draw`).
        self.start_closed_draw(draw, triangles, t, s)?;
        self.front_phase = FrontPhase::Idle;
        // The front end takes the next draw command (`front_begin`, `front_job`).
        if let Some((work, commands)) = next
            && let Some(c) = self.fifo.pop()
        {
            self.commands_executed += commands;
            self.front_cmd = c;
            self.start_front_job(now, c, work, s)?;
            self.front_phase = FrontPhase::Running;
            return Ok(true);
        }
        Ok(false)
    }

    /// `draw` fidelity without a trace, called when a draw ended (after
    /// [`FramePipeline::draw_done`]) while the front end holds the next draw
    /// (a hand-off): `settle` takes every step as for any event, and when
    /// neither the CPU's frame nor the GPU's changed, the instant's
    /// accounting is [`FramePipeline::account_draw_handoff`] (the units
    /// that can have moved), else `account` in full. Returns false, having
    /// changed nothing, when the front end holds no draw, a system task
    /// holds it, the draw's fragments are binned, or a trace is written.
    #[inline]
    pub(super) fn draw_done_alone(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        if self.front_phase != FrontPhase::Handoff
            || self.acct.trace.is_some()
            || self.front.in_system()
            || self.cfg.gpu.fragment.binned()
        {
            return Ok(false);
        }
        let gpu_frame = self.gpu_frame;
        let cpu_moved = if self.handoff_fast(now, s)? {
            // The front end runs the next draw command's job: of `settle`'s
            // steps only the CPU's can do anything (a push does not reach a
            // running front end), and it does not change the front end.
            self.cpu_step(now, s)?
        } else {
            self.settle(now, s)?;
            true
        };
        if self.gpu_frame == gpu_frame && self.geom_busy && self.cpu_frame == self.acct.cpu_frame() {
            self.account_draw_handoff(now, cpu_moved);
        } else {
            self.account(now);
        }
        Ok(true)
    }
}
