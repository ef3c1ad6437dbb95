//! The CPU thread held before a frame starts, submits or presents
//! (`[pacing]`): a frame limiter measured from the frame's start, its GPU
//! submission or its present, and
//! the low-latency pacer, which starts a frame as late as the GPU's
//! forecast allows ([`crate::components::frame_pacing`]).

use crate::components::frame_pacing::{GpuForecast, limited, paced_start};
use crate::engine::{Duration, Time};

use super::super::links::Env;
use super::{CpuPhase, CpuThread, Op};

impl CpuThread {
    /// Whether the low-latency pacer holds the thread (it waits for the GPU
    /// to drain, not for a limiter's interval).
    #[inline(always)]
    pub(in crate::systems::frame_pipeline) fn paced_for_gpu(&self) -> bool {
        self.phase == CpuPhase::PaceStart && self.pace_for_gpu
    }

    /// The [`Ev::PaceWake`] event: the held frame starts, or presents.
    pub(in crate::systems::frame_pipeline) fn pace_wake(&mut self) {
        self.pace_go = true;
        self.phase = self.pace_resume;
    }

    /// The time the frame about to start must wait for (`[pacing]`: a
    /// start-measured limiter, the low-latency pacer; the later wins), if
    /// later than `now`.
    pub(super) fn start_wait(&mut self, now: Time, env: &Env) -> Option<Time> {
        let p = &self.spec.pacing;
        if p.is_off() || self.frame == 0 {
            return None;
        }
        let prev = &env.records[self.frame as usize - 1];
        let mut t = now;
        if let Some(interval) = p.start_limit() {
            t = t.max(limited(Some(prev.start), interval).unwrap_or(now));
        }
        self.pace_for_gpu = false;
        if p.low_latency {
            // Times the accounting has closed: busy time is attributed to a
            // frame at the end of the instant that moves past it, so a
            // frame finished at `now` (or the CPU's frame just presented)
            // is read from the frame before it.
            let completed = env.links.frames_completed as usize;
            let closed = |i: usize| env.records.get(i).filter(|r| r.gpu_end.is_some_and(|e| e < now));
            let gpu_frame = (1..=2)
                .filter_map(|back| completed.checked_sub(back).and_then(closed))
                .map(|r| Duration(r.gpu_busy))
                .next();
            let f = self.frame as usize;
            let cpu_frame = match f {
                1 => Some(prev.present.since(prev.start)),
                _ => Some(Duration(env.records[f - 2].cpu_busy)),
            };
            let forecast = GpuForecast {
                in_flight: self.frame - env.links.frames_completed,
                oldest_gpu_start: env.records.get(completed).and_then(|r| r.gpu_start),
                gpu_frame,
                cpu_frame,
            };
            let paced = paced_start(now, forecast);
            if paced > t {
                t = paced;
                self.pace_for_gpu = true;
            }
        }
        (t > now).then_some(t)
    }

    /// The time the current operation must wait for under a limiter placed
    /// inside the frame, if later than `now`: the swap under a
    /// present-measured limiter (the previous present plus the interval,
    /// less the swap's own work); the clear, the frame's first GPU command,
    /// under a submission-measured one (the previous frame's clear plus
    /// the interval, less the clear's work).
    pub(super) fn op_wait(&mut self, now: Time, env: &Env) -> Option<Time> {
        let op = self.op_at(self.op);
        let (interval, previous) = match op {
            Op::Swap => (
                self.spec.pacing.present_limit()?,
                env.records.get((self.frame as usize).checked_sub(1)?)?.present,
            ),
            Op::Clear => (self.spec.pacing.submit_limit()?, self.last_submit?),
            _ => return None,
        };
        if std::mem::take(&mut self.pace_go) {
            return None;
        }
        let target = limited(Some(previous), interval)?;
        let work = self.op_work(op, env);
        let t = Time(target.0.saturating_sub(work.0));
        (t > now).then_some(t)
    }
}
