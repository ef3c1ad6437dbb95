//! The kernel alone: the classic "hold" model of discrete-event simulation.
//!
//! `N` jobs circulate forever: handling one reschedules it after a random
//! delay. It shows the three things a system needs from `rendersim_engine`:
//! an event type that names its kinds, a `Model` that handles events and
//! schedules follow-ups through the `Scheduler`, and `run` with limits. The
//! engine knows nothing of GPUs; every rendersim system is built this way.
//!
//! Run it with `cargo run --release -p rendersim-engine --example hold_model`.

use rand::Rng;
use rendersim_engine::{
    Control, Duration, EngineError, EventKind, Limits, Model, RngStreams, Scheduler, StopReason, StreamRng, Time, run,
};

/// The only event: job `id` is due.
struct Due {
    id: u32,
}

impl EventKind for Due {
    const NAMES: &'static [&'static str] = &["due"];
    fn kind(&self) -> usize {
        0
    }
}

/// The hold model: every event reschedules its job 1 ns to 1 us later.
struct Hold {
    rng: StreamRng,
    handled: Vec<u64>,
    last: Time,
}

impl Model for Hold {
    type Event = Due;
    type Error = EngineError;

    fn handle(&mut self, now: Time, e: Due, sched: &mut Scheduler<Due>) -> Result<Control, EngineError> {
        // Time never goes backwards.
        assert!(now >= self.last);
        self.last = now;
        self.handled[e.id as usize] += 1;
        let delay = Duration(self.rng.random_range(1_000..=1_000_000)); // picoseconds
        sched.after(delay, e, "hold job")?;
        Ok(Control::Continue)
    }
}

fn simulate(seed: u64, jobs: u32, events: u64) -> (Vec<u64>, Time) {
    // Named streams: the "hold" stream is the same whatever else draws.
    let streams = RngStreams::new(seed);
    let mut model = Hold {
        rng: streams.stream("hold"),
        handled: vec![0; jobs as usize],
        last: Time::ZERO,
    };
    let mut sched = Scheduler::new();
    for id in 0..jobs {
        sched.at(Time(u64::from(id)), Due { id });
    }
    let stats = run(
        &mut model,
        &mut sched,
        Limits {
            until: None,
            max_events: Some(events),
        },
    )
    .expect("the hold model cannot fail");
    assert_eq!(stats.stopped_by, StopReason::EventLimit);
    assert_eq!(stats.events, events);
    assert_eq!(stats.by_kind, vec![events]);
    // Every job is still pending: the queue holds exactly `jobs` events.
    assert_eq!(sched.pending(), jobs as usize);
    println!(
        "{events} events, {jobs} pending, {:.3} us simulated, {:.1} M events/s",
        stats.end_time.0 as f64 / 1e6,
        stats.events as f64 / stats.wall_seconds.max(1e-9) / 1e6
    );
    (model.handled, stats.end_time)
}

fn main() {
    let (a, end_a) = simulate(7, 1_000, 200_000);
    // Every job got its turn, and the counts add up.
    assert_eq!(a.iter().sum::<u64>(), 200_000);
    assert!(a.iter().all(|&n| n > 0));
    // Same seed, same run, to the picosecond.
    let (b, end_b) = simulate(7, 1_000, 200_000);
    assert_eq!((a.clone(), end_a), (b, end_b));
    // Another seed, another run.
    let (c, _) = simulate(8, 1_000, 200_000);
    assert_ne!(a, c);
    println!("deterministic: same seed, same counts and end time ({end_a})");
}
