//! `rendersim bench kernel`: the event kernel against a bare heap.
//!
//! The classic hold model (a fixed population of pending events; each
//! handled event schedules one more at a random later time) and a stiff mix
//! (nanosecond delays with one-second ones) through the engine, on its radix
//! heap and on its binary heap, against a bare `BinaryHeap` loop doing the
//! same work. Each case's events are handled in slices, the three loops in
//! turn slice by slice; the lines and the plot are the same measurements.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

use rand::Rng;

use super::spread::{Spread, paired_ratio};
use crate::engine::{
    Control, Duration, EngineError, EventKind, Limits, Model, QueueKind, RngStreams, Scheduler, StreamRng, Time, run,
};

/// Hold-model event.
#[derive(Debug, Clone, Copy)]
pub struct Hold;

impl EventKind for Hold {
    const NAMES: &'static [&'static str] = &["hold"];
    #[inline]
    fn kind(&self) -> usize {
        0
    }
}

/// The delays of a kernel benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelWork {
    /// The classic hold model: delays uniform in 1 ps .. 2 us.
    Hold,
    /// A stiff mix: 99.9% of delays uniform in 1 .. 100 ns, 0.1% one second.
    Stiff,
}

impl KernelWork {
    /// The next delay, in picoseconds.
    #[inline]
    fn delay(self, rng: &mut StreamRng) -> u64 {
        match self {
            KernelWork::Hold => rng.random_range(1..2_000_000u64),
            KernelWork::Stiff => {
                if rng.random_range(0..1000u32) == 0 {
                    1_000_000_000_000
                } else {
                    rng.random_range(1_000..=100_000u64)
                }
            }
        }
    }

    /// Its name in the benchmark's lines.
    pub fn name(self) -> &'static str {
        match self {
            KernelWork::Hold => "hold",
            KernelWork::Stiff => "stiff",
        }
    }
}

struct HoldModel {
    rng: StreamRng,
    work: KernelWork,
}

impl Model for HoldModel {
    type Event = Hold;
    type Error = EngineError;
    #[inline]
    fn handle(&mut self, _now: Time, ev: Hold, s: &mut Scheduler<Hold>) -> Result<Control, EngineError> {
        let d = self.work.delay(&mut self.rng);
        s.after(Duration(d), ev, "benchmark event")?;
        Ok(Control::Continue)
    }
}

/// Result of one kernel benchmark case: each figure over the repeats.
#[derive(Debug, Clone, serde::Serialize)]
pub struct KernelBench {
    /// The delays.
    pub work: KernelWork,
    /// Pending events.
    pub population: usize,
    /// Events handled in each repeat, by each of the three loops.
    pub events: u64,
    /// Repeats: consecutive slices of `events` handled, the three loops in
    /// turn slice by slice.
    pub repeats: usize,
    /// Engine events per second (its default queue, the radix heap).
    pub engine_events_per_s: Spread,
    /// Engine events per second on its binary-heap queue.
    pub engine_binary_events_per_s: Spread,
    /// Bare `BinaryHeap` loop events per second (the baseline).
    pub bare_events_per_s: Spread,
    /// engine / bare, repeat by repeat.
    pub ratio: Spread,
}

/// The engine running the hold model, resumable slice by slice.
struct EngineLoop {
    sched: Scheduler<Hold>,
    model: HoldModel,
}

impl EngineLoop {
    fn new(work: KernelWork, population: usize, kind: QueueKind) -> Self {
        let streams = RngStreams::new(7);
        let mut sched = Scheduler::with_queue(kind);
        let mut init = streams.stream("init");
        for _ in 0..population {
            sched.at(Time(init.random_range(0..2_000_000u64)), Hold);
        }
        EngineLoop {
            sched,
            model: HoldModel {
                rng: streams.stream("hold"),
                work,
            },
        }
    }

    /// Handles `events` more; returns events per second.
    fn slice(&mut self, events: u64) -> f64 {
        let t = Instant::now();
        let limits = Limits {
            until: None,
            max_events: Some(events),
        };
        let st = run(&mut self.model, &mut self.sched, limits)
            .expect("the benchmark model cannot overflow in a benchmark's span");
        let secs = t.elapsed().as_secs_f64();
        assert_eq!(st.events, events);
        events as f64 / secs
    }
}

/// The bare loop: `work` on a `BinaryHeap` of `(time, seq)`, resumable.
struct BareLoop {
    heap: BinaryHeap<Reverse<(u64, u64)>>,
    rng: StreamRng,
    work: KernelWork,
    seq: u64,
}

impl BareLoop {
    fn new(work: KernelWork, population: usize) -> Self {
        let streams = RngStreams::new(7);
        let mut heap = BinaryHeap::with_capacity(64);
        let mut init = streams.stream("init");
        let mut seq = 0u64;
        for _ in 0..population.max(1) {
            heap.push(Reverse((init.random_range(0..2_000_000u64), seq)));
            seq += 1;
        }
        BareLoop {
            heap,
            rng: streams.stream("hold"),
            work,
            seq,
        }
    }

    /// Handles `events` more; returns events per second.
    fn slice(&mut self, events: u64) -> f64 {
        let t = Instant::now();
        let mut last = 0u64;
        for _ in 0..events {
            let Reverse((time, _)) = self.heap.pop().expect("population > 0");
            last = last.max(time);
            let d = self.work.delay(&mut self.rng);
            self.heap.push(Reverse((time + d, self.seq)));
            self.seq += 1;
        }
        let secs = t.elapsed().as_secs_f64();
        std::hint::black_box(last);
        events as f64 / secs
    }
}

/// The kernel on `work` with `population` pending events, `events` handled
/// in each of `repeats` slices, against a bare `BinaryHeap` loop doing the
/// same work (same delays). The three loops run in turn slice by slice, so
/// that each repeat's ratio compares loops timed side by side.
pub fn kernel_case(work: KernelWork, population: usize, events: u64, repeats: usize) -> KernelBench {
    let population = population.max(1);
    let repeats = repeats.max(1);
    let events = events.max(1);
    let mut radix = EngineLoop::new(work, population, QueueKind::Radix);
    let mut binary = EngineLoop::new(work, population, QueueKind::Binary);
    let mut bare = BareLoop::new(work, population);
    let (mut e, mut b, mut h) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..repeats {
        e.push(radix.slice(events));
        b.push(binary.slice(events));
        h.push(bare.slice(events));
    }
    KernelBench {
        work,
        population,
        events,
        repeats,
        engine_events_per_s: Spread::of(&e),
        engine_binary_events_per_s: Spread::of(&b),
        bare_events_per_s: Spread::of(&h),
        ratio: paired_ratio(&e, &h),
    }
}

/// Events per second of the bare loop: `work` on a `BinaryHeap` of
/// `(time, seq)` with `population` pending, `events` handled (the kernel
/// benchmark's baseline, and the hour's yardstick of the machine's speed).
pub fn bare_rate(work: KernelWork, population: usize, events: u64) -> f64 {
    BareLoop::new(work, population).slice(events)
}

/// The hold model with `population` pending events, `events` handled once
/// (see [`kernel_case`]).
pub fn kernel(population: usize, events: u64) -> KernelBench {
    kernel_case(KernelWork::Hold, population, events, 1)
}

/// The kernel benchmark's cases: hold and stiff at 1e3, 1e4, 1e5 and 1e6
/// pending (issue 15's targets among them). Its lines and its plot are the
/// same measurements.
pub const KERNEL_CASES: [(KernelWork, usize); 8] = [
    (KernelWork::Hold, 1_000),
    (KernelWork::Hold, 10_000),
    (KernelWork::Hold, 100_000),
    (KernelWork::Hold, 1_000_000),
    (KernelWork::Stiff, 1_000),
    (KernelWork::Stiff, 10_000),
    (KernelWork::Stiff, 100_000),
    (KernelWork::Stiff, 1_000_000),
];

/// Draws ns per event against the number pending (log axes): the engine
/// (radix heap), the engine on its binary heap and the bare `BinaryHeap`
/// loop, for hold and stiff; the medians as lines, the repeats' minimum to
/// maximum as bars. `path` names the PNG; an SVG is written beside.
pub fn plot_kernel(cases: &[KernelBench], path: &std::path::Path) -> Result<(), crate::plot::PlotError> {
    use crate::plot::{LinePlot, Series, line_plot};
    let mut series = Vec::new();
    for work in [KernelWork::Hold, KernelWork::Stiff] {
        let of = |rate: fn(&KernelBench) -> Spread, name: &str| {
            let mine: Vec<(f64, Spread)> = cases
                .iter()
                .filter(|c| c.work == work)
                .map(|c| (c.population as f64, rate(c).map(|r| 1e9 / r)))
                .collect();
            Series {
                name: format!("{name}, {}", work.name()),
                points: mine.iter().map(|(x, s)| (*x, s.median)).collect(),
                ci: Some(mine.iter().map(|(_, s)| (s.min, s.max)).collect()),
                level: None,
                ..Default::default()
            }
        };
        series.push(of(|c| c.engine_events_per_s, "engine (radix heap)"));
        series.push(of(|c| c.engine_binary_events_per_s, "engine (binary heap)"));
        series.push(of(|c| c.bare_events_per_s, "bare BinaryHeap loop"));
    }
    let repeats = cases.iter().map(|c| c.repeats).max().unwrap_or(1);
    let base = path.with_extension("");
    line_plot(
        &base,
        &LinePlot {
            title: format!("Event kernel: cost per event against events pending (median of {repeats}, bars min-max)"),
            x_label: "events pending (log)".into(),
            y_label: "ns per event (log)".into(),
            series,
            log_x: true,
            log_y: true,
            ..Default::default()
        },
    )
}

/// Events handled in each of `repeats` slices by the kernel case with
/// `population` pending at `scale`: 20 million at 1 in all, and at least 2
/// per pending one in all, so the heap is in steady state.
pub fn kernel_events(population: usize, scale: f64, repeats: usize) -> u64 {
    (((20_000_000.0 * scale) as u64).max(2 * population as u64) / repeats.max(1) as u64).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_plot_draws_every_case() {
        let cases: Vec<KernelBench> = KERNEL_CASES
            .iter()
            .filter(|c| c.1 <= 10_000)
            .map(|&(work, p)| kernel_case(work, p, 2_000, 3))
            .collect();
        assert_eq!(cases.len(), 4);
        let d = tempfile::tempdir().unwrap();
        plot_kernel(&cases, &d.path().join("kernel.png")).unwrap();
        for ext in ["png", "svg"] {
            let bytes = std::fs::read(d.path().join(format!("kernel.{ext}"))).unwrap();
            assert!(bytes.len() > 1000, "{ext}");
        }
    }

    #[test]
    fn a_kernel_case_handles_the_events_asked_for_and_measures_all_three() {
        let k = kernel_case(KernelWork::Stiff, 100, 1_000, 3);
        assert_eq!((k.population, k.events, k.repeats), (100, 1_000, 3));
        for r in [
            k.engine_events_per_s,
            k.engine_binary_events_per_s,
            k.bare_events_per_s,
            k.ratio,
        ] {
            assert_eq!(r.n, 3);
            assert!(r.min.is_finite() && r.min > 0.0 && r.min <= r.median && r.median <= r.max);
        }
        // Slices continue one run: the engine has handled every slice's events.
        let mut e = EngineLoop::new(KernelWork::Hold, 10, QueueKind::Radix);
        e.slice(50);
        e.slice(50);
        assert_eq!(e.sched.pending(), 10);
        assert_eq!(kernel_events(1_000_000, 0.001, 5), 400_000);
        assert_eq!(kernel_events(1_000, 1.0, 4), 5_000_000);
    }
}
