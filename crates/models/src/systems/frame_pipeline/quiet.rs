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
//! directly in their common case ([`FrontEnd::handoff_fast`](super::front_end::FrontEnd::handoff_fast): the held draw
//! goes to geometry, the next draw command's front-end job starts), and the CPU's
//! accounting is skipped when the CPU took no step. The CPU's own common
//! instants have the same kind of direct path in `cpu_thread/mod.rs`
//! ([`CpuThread::draw_done_fast`](super::cpu_thread::CpuThread::draw_done_fast), [`CpuThread::step_alone`](super::cpu_thread::CpuThread::step_alone)). A traced run takes none
//! of these short cuts, which is what the trace-equivalence test compares
//! against.

//!
//! Each short cut's transitions are methods of the unit whose state they
//! change ([`FrontEnd::passed_quiet`](super::front_end::FrontEnd::passed_quiet), [`FrontEnd::quiet_done`](super::front_end::FrontEnd::quiet_done),
//! [`FrontEnd::handoff_fast`](super::front_end::FrontEnd::handoff_fast); the accounting's
//! `Accounting::front_waits_for_geometry` and `account_draw_handoff`); what
//! is here is the order in which the pipeline takes them.

use crate::engine::{Scheduler, Time};
use crate::systems::error::SystemError;

use super::accounting::{Units, units_of};
use super::events::Ev;
use super::front_end::FrontPhase;
use super::model::FramePipeline;

impl FramePipeline {
    /// Does the quiet completion whose turn came before the event being
    /// handled (after a run: before its end). Called first in every event.
    #[inline]
    pub(super) fn catch_up(&mut self, s: &Scheduler<Ev>) -> Result<(), SystemError> {
        if let Some((at, tag)) = self.front.passed_quiet(s) {
            self.quiet_front_done(at, tag);
        }
        Ok(())
    }

    /// The front end's draw command finished at `at` (job `tag`): the
    /// hand-off begins, and the instant is accounted as an event's would be.
    /// (`settle` would find nothing to do: the geometry stage holds a draw
    /// until after `at`, so the hand-off waits, and the CPU waits on
    /// nothing a hand-off changes.)
    #[inline(never)]
    fn quiet_front_done(&mut self, at: Time, tag: u32) {
        if !self.front.quiet_done(tag) {
            return;
        }
        debug_assert!(self.geom.done_at().is_some_and(|d| d > at));
        if self.env.traced {
            self.account(at);
            return;
        }
        self.acct.front_waits_for_geometry(at);
    }

    /// `draw` fidelity without a trace, called when a draw ended (after
    /// the geometry stage's `draw_done`) while the front end holds the next
    /// draw (a hand-off): `settle` takes every step as for any event (its
    /// front end's first ones by [`FrontEnd::handoff_fast`](super::front_end::FrontEnd::handoff_fast) when they are
    /// the common ones), and when neither the CPU's frame nor the GPU's
    /// changed, the instant's accounting is `account_draw_handoff` (the
    /// units that can have moved), else `account` in full. Returns false,
    /// having changed nothing, when the front end holds no draw, a system
    /// task holds it, the draw's fragments are binned, or a trace is
    /// written.
    #[inline]
    pub(super) fn draw_done_alone(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        if self.front.phase() != FrontPhase::Handoff || self.env.traced || self.front.in_system() || self.front.binned()
        {
            return Ok(false);
        }
        let gpu_frame = self.front.frame();
        let cpu_moved = if self
            .front
            .handoff_fast(now, &mut self.env, &mut self.geom, &mut self.frag, s)?
        {
            // The front end runs the next draw command's job: of `settle`'s
            // steps only the CPU's can do anything (a push does not reach a
            // running front end), and it does not change the front end.
            self.cpu.step(now, &mut self.env, s)?
        } else {
            self.settle(now, s)?;
            true
        };
        if self.front.frame() == gpu_frame && self.geom.busy() && self.cpu.frame() == self.acct.cpu_frame() {
            debug_assert!(
                !self.display.has_news(),
                "a draw's hand-off presented or showed a frame"
            );
            self.acct
                .account_draw_handoff(now, cpu_moved, units_of!(self), &mut self.env.records);
        } else {
            self.account(now);
        }
        Ok(true)
    }
}
