//! The run loop: pop the earliest event, hand it to the model, repeat.
//!
//! A [`Model`] owns all state of a simulated system and handles its own typed
//! event enum with a `match` (no boxing, no dynamic dispatch on the hot path).
//! The loop counts events per kind, stops at a time limit, an event budget or
//! when the model says so (for example after N frames), and reports the wall
//! time it took.

use std::time::Instant;

use super::queue::{EventQueue, QueueKind};
use super::time::{Duration, Time, TimeError};

/// Implemented by each system's event enum so the loop can count per kind.
pub trait EventKind {
    /// Names of the kinds, indexed by [`EventKind::kind`].
    const NAMES: &'static [&'static str];
    /// Index of this event's kind in [`EventKind::NAMES`].
    fn kind(&self) -> usize;
}

/// What the model wants after handling an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// Keep going.
    Continue,
    /// The model reached its own end (for example the requested frames).
    Stop,
}

/// Errors raised by the kernel itself.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EngineError {
    /// Time arithmetic failed.
    #[error(transparent)]
    Time(#[from] TimeError),
    /// An event was scheduled before the current time (a model bug).
    #[error("event of kind {kind} scheduled at {at} before the current time {now}")]
    Backwards {
        /// Kind name.
        kind: &'static str,
        /// Its time.
        at: Time,
        /// The clock when it was popped.
        now: Time,
    },
}

/// A simulated system driven by the loop.
///
/// A model handles its own event enum; [`run`] hands it the events in
/// `(time, seq)` order: by time, and events due at the same time in the
/// order they were scheduled.
///
/// ```
/// use rendersim_engine::{run, Control, Duration, EngineError, EventKind, Limits, Model, Scheduler, StopReason, Time};
///
/// enum Ev {
///     Start,
///     Job(&'static str),
/// }
/// impl EventKind for Ev {
///     const NAMES: &'static [&'static str] = &["start", "job"];
///     fn kind(&self) -> usize {
///         match self {
///             Ev::Start => 0,
///             Ev::Job(_) => 1,
///         }
///     }
/// }
///
/// /// Writes down when each job ran.
/// struct Log(Vec<(u64, &'static str)>);
/// impl Model for Log {
///     type Event = Ev;
///     type Error = EngineError;
///     fn handle(&mut self, now: Time, e: Ev, s: &mut Scheduler<Ev>) -> Result<Control, EngineError> {
///         match e {
///             Ev::Start => {
///                 // Three jobs 5 ns from now, scheduled b, a, c; one at 2 ns.
///                 for name in ["b", "a", "c"] {
///                     s.after(Duration::ns(5), Ev::Job(name), "a job")?;
///                 }
///                 s.after(Duration::ns(2), Ev::Job("early"), "a job")?;
///             }
///             Ev::Job(name) => self.0.push((now.0 / 1000, name)),
///         }
///         Ok(Control::Continue)
///     }
/// }
///
/// let mut log = Log(Vec::new());
/// let mut sched = Scheduler::new();
/// sched.at(Time::ZERO, Ev::Start);
/// let stats = run(&mut log, &mut sched, Limits::default()).unwrap();
/// // Earliest first; the three at 5 ns in the order they were scheduled.
/// assert_eq!(log.0, [(2, "early"), (5, "b"), (5, "a"), (5, "c")]);
/// assert_eq!((stats.events, stats.by_kind.clone()), (5, vec![1, 4]));
/// assert_eq!(stats.stopped_by, StopReason::Exhausted);
/// assert_eq!(stats.end_time, Time(5_000)); // picoseconds
/// ```
pub trait Model {
    /// The system's event type.
    type Event: EventKind;
    /// The system's error type; kernel errors convert into it.
    type Error: From<EngineError>;
    /// Handles one event at `now`, scheduling follow-ups on `sched`.
    fn handle(
        &mut self,
        now: Time,
        event: Self::Event,
        sched: &mut Scheduler<Self::Event>,
    ) -> Result<Control, Self::Error>;
}

/// The model's handle on the future: schedule events relative to now.
///
/// [`Scheduler::at`] takes an absolute time, [`Scheduler::after`] a delay
/// from [`Scheduler::now`] and returns when the event is due. Outside a run
/// the clock stands at zero; [`run`] advances it to each event it pops.
///
/// ```
/// use rendersim_engine::{Duration, Scheduler, Time};
///
/// let mut sched: Scheduler<&str> = Scheduler::new();
/// assert_eq!(sched.now(), Time::ZERO);
/// let due = sched.after(Duration::us(3), "vblank", "the first vblank").unwrap();
/// assert_eq!(due, Time(3_000_000)); // 3 us in picoseconds
/// sched.at(Time(10), "input");
/// assert_eq!(sched.pending(), 2);
/// ```
#[derive(Debug)]
pub struct Scheduler<E> {
    queue: EventQueue<E>,
    now: Time,
    /// The sequence number of the event being handled (`u64::MAX` once a
    /// run stopped at its time limit: every slot up to the limit passed).
    seq: u64,
}

/// A place in the `(time, seq)` order of events taken without an event
/// ([`Scheduler::reserve`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Slot {
    time: Time,
    seq: u64,
}

impl Slot {
    /// When the event that was not scheduled would have been due.
    #[inline]
    pub fn time(&self) -> Time {
        self.time
    }
}

impl<E> Default for Scheduler<E> {
    fn default() -> Self {
        Self::new()
    }
}

impl<E> Scheduler<E> {
    /// An empty scheduler at time zero (default queue: a radix heap).
    pub fn new() -> Self {
        Self::with_queue(QueueKind::default())
    }

    /// An empty scheduler at time zero on a queue of the given kind (results
    /// are the same; only the speed differs).
    pub fn with_queue(kind: QueueKind) -> Self {
        Scheduler {
            queue: EventQueue::of_kind(kind),
            now: Time::ZERO,
            seq: 0,
        }
    }

    /// The current simulated time.
    #[inline]
    pub fn now(&self) -> Time {
        self.now
    }

    /// Schedules `event` at the absolute time `t` (must not be in the past;
    /// the loop reports it as an error if it is).
    #[inline(always)]
    pub fn at(&mut self, t: Time, event: E) {
        self.queue.push(t, event);
    }

    /// Schedules `event` after `d`, or fails on time overflow naming `context`.
    #[inline(always)]
    pub fn after(&mut self, d: Duration, event: E, context: &str) -> Result<Time, TimeError> {
        let t = self.now.add(d, context)?;
        self.queue.push(t, event);
        Ok(t)
    }

    /// Number of pending events.
    pub fn pending(&self) -> usize {
        self.queue.len()
    }

    /// Takes the place in the `(time, seq)` order that an event scheduled
    /// now at `t` would have, without scheduling one. For an event whose
    /// handling would change nothing but the model's own bookkeeping (no
    /// other event, no other unit's step): the model keeps the slot and does
    /// that bookkeeping itself at the first event handled after the slot
    /// ([`Scheduler::passed`]), exactly where the event would have run, and
    /// the run has one event fewer to queue, pop and dispatch.
    #[inline]
    pub fn reserve(&mut self, t: Time) -> Slot {
        Slot {
            time: t,
            seq: self.queue.reserve_seq(),
        }
    }

    /// Whether `slot` comes before the event being handled in `(time, seq)`
    /// order (after a run that stopped at its time limit: whether it is due
    /// by the limit).
    #[inline]
    pub fn passed(&self, slot: Slot) -> bool {
        // Written out: the tuple's derived `<` calls a comparison helper
        // that the release profile (opt-level "s") does not inline.
        slot.time.0 < self.now.0 || (slot.time.0 == self.now.0 && slot.seq < self.seq)
    }
}

/// When the loop stops regardless of the model.
#[derive(Debug, Clone, Copy, Default)]
pub struct Limits {
    /// Stop before handling any event due after this time.
    pub until: Option<Time>,
    /// Stop after handling this many events.
    pub max_events: Option<u64>,
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The model returned [`Control::Stop`].
    Model,
    /// [`Limits::until`] was reached.
    TimeLimit,
    /// [`Limits::max_events`] was reached.
    EventLimit,
    /// No events were left.
    Exhausted,
}

/// What a run cost and how it ended.
#[derive(Debug, Clone)]
pub struct RunStats {
    /// Events handled.
    pub events: u64,
    /// Events handled per kind, indexed like [`EventKind::NAMES`].
    pub by_kind: Vec<u64>,
    /// Kind names.
    pub kind_names: &'static [&'static str],
    /// Simulated time of the last handled event.
    pub end_time: Time,
    /// Why the run ended.
    pub stopped_by: StopReason,
    /// Wall-clock seconds spent in the loop.
    pub wall_seconds: f64,
}

/// Runs `model` until it stops, the limits are hit or no events are left.
pub fn run<M: Model>(model: &mut M, sched: &mut Scheduler<M::Event>, limits: Limits) -> Result<RunStats, M::Error> {
    let names = <M::Event as EventKind>::NAMES;
    let mut by_kind = vec![0u64; names.len()];
    let mut events = 0u64;
    let start = Instant::now();
    let until = limits.until.unwrap_or(Time(u64::MAX));
    let max_events = limits.max_events.unwrap_or(u64::MAX);
    let stopped_by = loop {
        if events >= max_events {
            break StopReason::EventLimit;
        }
        let Some(next) = sched.queue.pop() else {
            break StopReason::Exhausted;
        };
        if next.time > until {
            // Put it back (in its place) so the caller could resume.
            sched.queue.restore(next);
            sched.now = until;
            sched.seq = u64::MAX;
            break StopReason::TimeLimit;
        }
        let kind = next.event.kind();
        if next.time < sched.now {
            return Err(EngineError::Backwards {
                kind: names[kind],
                at: next.time,
                now: sched.now,
            }
            .into());
        }
        sched.now = next.time;
        sched.seq = next.seq;
        by_kind[kind] += 1;
        events += 1;
        if model.handle(next.time, next.event, sched)? == Control::Stop {
            break StopReason::Model;
        }
    };
    Ok(RunStats {
        events,
        by_kind,
        kind_names: names,
        end_time: sched.now,
        stopped_by,
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    enum Ev {
        Tick,
        Tock,
    }
    impl EventKind for Ev {
        const NAMES: &'static [&'static str] = &["tick", "tock"];
        fn kind(&self) -> usize {
            match self {
                Ev::Tick => 0,
                Ev::Tock => 1,
            }
        }
    }
    struct Clock {
        seen: Vec<Time>,
        stop_after: usize,
    }
    impl Model for Clock {
        type Event = Ev;
        type Error = EngineError;
        fn handle(&mut self, now: Time, e: Ev, s: &mut Scheduler<Ev>) -> Result<Control, EngineError> {
            self.seen.push(now);
            if let Ev::Tick = e {
                s.after(Duration(10), Ev::Tock, "tock")?;
                s.after(Duration(20), Ev::Tick, "tick")?;
            }
            Ok(if self.seen.len() >= self.stop_after {
                Control::Stop
            } else {
                Control::Continue
            })
        }
    }

    #[test]
    fn counts_kinds_and_stops() {
        let mut m = Clock {
            seen: vec![],
            stop_after: 7,
        };
        let mut s = Scheduler::new();
        s.at(Time(0), Ev::Tick);
        let st = run(&mut m, &mut s, Limits::default()).unwrap();
        assert_eq!(st.events, 7);
        assert_eq!(st.by_kind, vec![4, 3]);
        assert_eq!(st.stopped_by, StopReason::Model);
        assert!(m.seen.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn time_limit_and_event_limit() {
        let mut m = Clock {
            seen: vec![],
            stop_after: usize::MAX,
        };
        let mut s = Scheduler::new();
        s.at(Time(0), Ev::Tick);
        let st = run(
            &mut m,
            &mut s,
            Limits {
                until: Some(Time(100)),
                max_events: None,
            },
        )
        .unwrap();
        assert_eq!(st.stopped_by, StopReason::TimeLimit);
        assert!(m.seen.iter().all(|t| t.0 <= 100));
        let mut s = Scheduler::new();
        s.at(Time(0), Ev::Tick);
        let st = run(
            &mut m,
            &mut s,
            Limits {
                until: None,
                max_events: Some(5),
            },
        )
        .unwrap();
        assert_eq!((st.events, st.stopped_by), (5, StopReason::EventLimit));
    }

    /// A model that keeps some events as slots: it must see each one
    /// passed exactly where the event would have run.
    struct Keeper {
        /// (time, label) of each event and each passed slot, in order.
        seen: Vec<(Time, char)>,
        slots: Vec<(Slot, char)>,
    }
    impl Keeper {
        fn catch_up(&mut self, s: &Scheduler<Ev>) {
            while let Some(i) = self.slots.iter().position(|(slot, _)| s.passed(*slot)) {
                let (slot, c) = self.slots.remove(i);
                self.seen.push((slot.time(), c));
            }
        }
    }
    impl Model for Keeper {
        type Event = Ev;
        type Error = EngineError;
        fn handle(&mut self, now: Time, e: Ev, s: &mut Scheduler<Ev>) -> Result<Control, EngineError> {
            self.catch_up(s);
            self.seen.push((now, if let Ev::Tick = e { 'T' } else { 't' }));
            if self.seen.len() == 1 {
                // Slots between, before and after events due at 10 and 20.
                let slot = s.reserve(Time(10));
                self.slots.push((slot, 'a'));
                s.at(Time(10), Ev::Tock);
                self.slots.push((s.reserve(Time(10)), 'b'));
                self.slots.push((s.reserve(Time(15)), 'c'));
                s.at(Time(20), Ev::Tock);
                self.slots.push((s.reserve(Time(20)), 'd'));
                self.slots.push((s.reserve(Time(25)), 'e'));
            }
            Ok(Control::Continue)
        }
    }

    #[test]
    fn reserved_slots_pass_in_time_and_scheduling_order() {
        let limits = Limits {
            until: Some(Time(24)),
            max_events: None,
        };
        let go = |last: Option<Time>| {
            let mut m = Keeper {
                seen: vec![],
                slots: vec![],
            };
            let mut s = Scheduler::new();
            s.at(Time(0), Ev::Tick);
            if let Some(t) = last {
                s.at(t, Ev::Tick);
            }
            let st = run(&mut m, &mut s, limits).unwrap();
            m.catch_up(&s);
            assert!(m.seen.windows(2).all(|w| w[0].0 <= w[1].0));
            (st.stopped_by, m.seen.iter().map(|e| e.1).collect::<String>())
        };
        // Out of events after the one at 20: the slots after it stay.
        assert_eq!(go(None), (StopReason::Exhausted, "Tatbct".to_string()));
        // Stopped by the time limit: the slots due by the limit pass.
        assert_eq!(go(Some(Time(30))), (StopReason::TimeLimit, "Tatbctd".to_string()));
    }

    #[test]
    fn overflow_surfaces_as_error() {
        let mut m = Clock {
            seen: vec![],
            stop_after: usize::MAX,
        };
        let mut s = Scheduler::new();
        s.at(Time(u64::MAX - 15), Ev::Tick);
        let e = run(&mut m, &mut s, Limits::default()).unwrap_err();
        assert!(matches!(e, EngineError::Time(TimeError::Overflow { .. })), "{e}");
    }
}
