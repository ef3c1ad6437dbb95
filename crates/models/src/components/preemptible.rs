//! A unit whose work can be preempted by system tasks (paper 000 §4.2): the
//! operating system or the driver steals the processor for a while, and the
//! interrupted work resumes where it stopped. Tasks that arrive while another
//! runs wait their turn (one processor).
//!
//! The unit runs at most one job. The owner schedules the completion event the
//! methods return, tagged with [`Preemptible::generation`]; a completion whose
//! tag is stale was cancelled by a preemption and must be ignored.

use std::collections::VecDeque;

use crate::engine::{Duration, Time, TimeError};

/// A preemptible processor.
///
/// A 10 ms job started at 0 is preempted by a 3 ms system task at 4 ms: the
/// completion event scheduled for 10 ms goes stale, and the job resumes when
/// the task ends, finishing at 13 ms, 3 ms late.
///
/// ```
/// use rendersim_models::components::preemptible::{Preemptible, Wake};
/// use rendersim_engine::{Duration, Time};
///
/// let ms = |v| Time(Duration::ms(v).0);
/// let mut cpu = Preemptible::new();
/// let Wake::JobAt(end, stale) = cpu.start_job(ms(0), Duration::ms(10)).unwrap() else { panic!() };
/// assert_eq!(end, ms(10));
/// // The task starts at once and ends at 7 ms.
/// assert_eq!(cpu.task_arrives(ms(4), Duration::ms(3)).unwrap(), Some(ms(7)));
/// assert!(cpu.in_system());
/// // The job's remaining 6 ms resume at 7 ms, under a new tag.
/// let (next_task, wake) = cpu.task_ends(ms(7)).unwrap();
/// assert_eq!(next_task, None);
/// let Wake::JobAt(end, tag) = wake else { panic!() };
/// assert_eq!(end, ms(13));
/// assert!(!cpu.complete(stale)); // the 10 ms completion is ignored
/// assert!(cpu.complete(tag));
/// assert!(!cpu.has_job());
/// ```
#[derive(Debug, Clone, Default)]
pub struct Preemptible {
    /// Remaining work of the current job, when suspended or not yet started.
    remaining: Option<Duration>,
    /// When the running job ends (None when none runs).
    running_until: Option<Time>,
    /// End of the running system task.
    system_until: Option<Time>,
    /// Tasks waiting for the processor.
    pending: VecDeque<Duration>,
    generation: u32,
}

/// What the owner must schedule after a call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wake {
    /// Nothing new.
    Nothing,
    /// The job completes at this time (event tagged with the generation).
    JobAt(Time, u32),
}

impl Preemptible {
    /// An idle unit.
    pub fn new() -> Self {
        Self::default()
    }

    /// Tag of the job completion event currently valid.
    #[inline]
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// True while a system task holds the processor.
    #[inline]
    pub fn in_system(&self) -> bool {
        self.system_until.is_some()
    }

    /// True while a job is started and not completed (running or suspended).
    #[inline]
    pub fn has_job(&self) -> bool {
        self.running_until.is_some() || self.remaining.is_some()
    }

    /// Starts a job of `work` at `now`.
    #[inline(always)]
    pub fn start_job(&mut self, now: Time, work: Duration) -> Result<Wake, TimeError> {
        debug_assert!(!self.has_job());
        if self.in_system() {
            self.remaining = Some(work);
            return Ok(Wake::Nothing);
        }
        let end = now.add(work, "running a job")?;
        self.generation = self.generation.wrapping_add(1);
        self.running_until = Some(end);
        Ok(Wake::JobAt(end, self.generation))
    }

    /// The completion event with tag `tag` fired: true if it is current (the
    /// job is then finished), false if stale.
    #[inline]
    pub fn complete(&mut self, tag: u32) -> bool {
        if tag != self.generation || self.running_until.is_none() {
            return false;
        }
        self.running_until = None;
        true
    }

    /// The job's speed changes at `now`: what is left of it takes `factor`
    /// times as long (a copy whose share of a bus moved). A running job gets
    /// a new completion (returned, with a new generation; the old one goes
    /// stale); a suspended one keeps the scaled rest for when it resumes.
    pub fn rescale(&mut self, now: Time, factor: f64) -> Result<Wake, TimeError> {
        let scale = |d: Duration| Duration::from_ps_f64(d.0 as f64 * factor);
        if let Some(end) = self.running_until {
            let end = now.add(scale(end.since(now)), "rescaling a job")?;
            self.generation = self.generation.wrapping_add(1);
            self.running_until = Some(end);
            return Ok(Wake::JobAt(end, self.generation));
        }
        if let Some(rem) = self.remaining {
            self.remaining = Some(scale(rem));
        }
        Ok(Wake::Nothing)
    }

    /// A system task of `d` arrives at `now`. Returns the end time of the
    /// task if it starts now (the owner schedules a task-end event then).
    pub fn task_arrives(&mut self, now: Time, d: Duration) -> Result<Option<Time>, TimeError> {
        if self.in_system() {
            self.pending.push_back(d);
            return Ok(None);
        }
        self.begin_task(now, d).map(Some)
    }

    fn begin_task(&mut self, now: Time, d: Duration) -> Result<Time, TimeError> {
        if let Some(end) = self.running_until.take() {
            // Suspend the job: keep what is left; invalidate its completion.
            self.remaining = Some(end.since(now));
            self.generation = self.generation.wrapping_add(1);
        }
        let end = now.add(d, "running a system task")?;
        self.system_until = Some(end);
        Ok(end)
    }

    /// The running system task ended at `now`. Returns the next task's end
    /// (if another was waiting) and the job wake-up (if a job resumes).
    pub fn task_ends(&mut self, now: Time) -> Result<(Option<Time>, Wake), TimeError> {
        self.system_until = None;
        if let Some(d) = self.pending.pop_front() {
            return Ok((Some(self.begin_task(now, d)?), Wake::Nothing));
        }
        if let Some(rem) = self.remaining.take() {
            let end = now.add(rem, "resuming a preempted job")?;
            self.generation = self.generation.wrapping_add(1);
            self.running_until = Some(end);
            return Ok((None, Wake::JobAt(end, self.generation)));
        }
        Ok((None, Wake::Nothing))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preemption_delays_the_job_by_the_task() {
        let mut p = Preemptible::new();
        let Wake::JobAt(end, g0) = p.start_job(Time(0), Duration(100)).unwrap() else {
            panic!()
        };
        assert_eq!(end, Time(100));
        let t_end = p.task_arrives(Time(30), Duration(50)).unwrap().unwrap();
        assert_eq!(t_end, Time(80));
        // a second task queues
        assert_eq!(p.task_arrives(Time(40), Duration(5)).unwrap(), None);
        assert!(!p.complete(g0), "stale completion must be ignored");
        let (next, w) = p.task_ends(Time(80)).unwrap();
        assert_eq!((next, w), (Some(Time(85)), Wake::Nothing));
        let (next, w) = p.task_ends(Time(85)).unwrap();
        assert_eq!(next, None);
        let Wake::JobAt(end, g) = w else { panic!() };
        assert_eq!(end, Time(100 + 55));
        assert!(p.complete(g));
        assert!(!p.has_job());
    }

    #[test]
    fn a_rescaled_job_ends_when_its_rest_at_the_new_speed_is_done() {
        let mut p = Preemptible::new();
        let Wake::JobAt(_, g0) = p.start_job(Time(0), Duration(100)).unwrap() else {
            panic!()
        };
        // At 40, 60 left; half the speed: 120 more.
        let Wake::JobAt(end, g1) = p.rescale(Time(40), 2.0).unwrap() else {
            panic!()
        };
        assert_eq!(end, Time(160));
        assert!(!p.complete(g0), "the old completion is stale");
        // Suspended by a task at 100 (60 left), then back to full speed: 30.
        p.task_arrives(Time(100), Duration(10)).unwrap();
        assert_eq!(p.rescale(Time(105), 0.5).unwrap(), Wake::Nothing);
        let (_, w) = p.task_ends(Time(110)).unwrap();
        assert!(matches!(w, Wake::JobAt(Time(140), _)), "{w:?}");
        let _ = g1;
    }

    #[test]
    fn job_started_during_a_task_waits_for_it() {
        let mut p = Preemptible::new();
        p.task_arrives(Time(0), Duration(10)).unwrap();
        assert_eq!(p.start_job(Time(3), Duration(4)).unwrap(), Wake::Nothing);
        let (_, w) = p.task_ends(Time(10)).unwrap();
        assert!(matches!(w, Wake::JobAt(Time(14), _)));
    }
}
