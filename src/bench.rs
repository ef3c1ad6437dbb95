//! Speed benchmarks behind `rendersim bench` (and `cargo bench`): each
//! measures its rate next to a baseline measured in the same run, repeated,
//! and keeps every figure's minimum, median and maximum ([`spread`]).
//!
//! - `kernel`: the classic hold model (a fixed population of pending events;
//!   each handled event schedules one more at a random later time) and a
//!   stiff mix (nanosecond delays with one-second ones) through the engine,
//!   on its radix heap and on its binary heap, against a bare `BinaryHeap`
//!   loop doing the same work.
//! - `pipeline`: one frame of about one million triangles at `triangle`
//!   fidelity against the same frame at `draw` fidelity.
//! - `hour`: one simulated hour of the default (noisy, 60 Hz) model at `draw`
//!   fidelity.
//! - `pixelflow`: Figures 3 and 4 of paper 002 at event fidelity against
//!   the closed forms and a target.
//! - `build`: the vertex-cache reordering against its direct form, and the
//!   scene build against the simulation of the models that build a mesh
//!   ([`build`]).
//! - `replay`: replaying a 10,000-frame PresentMon capture against reading
//!   its CSV alone ([`replay`]).
//!
//! The functions return the measurements; `rendersim bench` prints them.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

use rand::Rng;

use crate::config::{ConfigError, ModelSource, Overrides, load_model};
use crate::engine::{
    Control, Duration, EngineError, EventKind, Limits, Model, QueueKind, RngStreams, Scheduler, StreamRng, Time, run,
};
use crate::systems::{SimError, run_model};

pub mod build;
pub mod replay;
pub mod spread;

use spread::{Spread, paired_ratio};

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
            x_categories: Vec::new(),
            y_bounds: None,
        },
    )
}

/// Why a benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// `--scale` is outside (0, 1].
    #[error("--scale must be in (0, 1], got {0}")]
    Scale(f64),
    /// `--repeats` is outside 1..=1000.
    #[error("--repeats must be in 1..=1000, got {0}")]
    Repeats(usize),
    /// A benchmark's model is wrong.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A benchmark's run failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The reordering benchmark's mesh or its check failed.
    #[error("reordering benchmark: {0}")]
    Reorder(String),
    /// The replay benchmark's capture did not replay.
    #[error("replay benchmark: {0}")]
    Replay(String),
}

/// One of the benchmarks of `rendersim bench`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bench {
    /// The event kernel against a bare heap ([`kernel_case`]).
    Kernel,
    /// One frame at both fidelities ([`pipeline_bench`]).
    Pipeline,
    /// One simulated hour of the default model ([`hour_bench`]).
    Hour,
    /// PixelFlow's Figures 3 and 4 ([`pixelflow_bench`]).
    Pixelflow,
    /// Scene building against simulation ([`build::build_bench`]).
    Build,
    /// A 10,000-frame capture's replay against reading it ([`replay::replay_bench`]).
    Replay,
}

impl Bench {
    /// Every benchmark, in the order `rendersim bench all` runs them.
    pub const ALL: [Bench; 6] = [
        Bench::Pixelflow,
        Bench::Kernel,
        Bench::Pipeline,
        Bench::Hour,
        Bench::Build,
        Bench::Replay,
    ];
}

/// Most repeats a benchmark takes.
pub const MAX_REPEATS: usize = 1000;

/// Checks that `repeats` is in 1..=[`MAX_REPEATS`].
pub fn check_repeats(repeats: usize) -> Result<(), BenchError> {
    if (1..=MAX_REPEATS).contains(&repeats) {
        Ok(())
    } else {
        Err(BenchError::Repeats(repeats))
    }
}

/// Checks that `scale` (the fraction of the full work) is in (0, 1].
pub fn check_scale(scale: f64) -> Result<(), BenchError> {
    if scale > 0.0 && scale <= 1.0 {
        Ok(())
    } else {
        Err(BenchError::Scale(scale))
    }
}

fn run_default_with(sets: &[&str]) -> Result<(serde_json::Value, f64), BenchError> {
    let m = load_model(None, &Overrides::with_sets(sets))?;
    let start = Instant::now();
    let r = run_model(&m.source, &m.table, None)?;
    Ok((r.summary().clone(), start.elapsed().as_secs_f64()))
}

/// One frame at both fidelities, each figure over the repeats.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PipelineBench {
    /// The grid's side: the frame is `grid:WxW`.
    pub width: u32,
    /// Triangles in the frame.
    pub triangles: u64,
    /// Repeats of each fidelity, in turn.
    pub repeats: usize,
    /// Wall seconds, build (mesh, cache simulation) and simulation, `triangle`.
    pub triangle_total_s: Spread,
    /// The same at `draw` fidelity.
    pub draw_total_s: Spread,
    /// Event-loop seconds at `triangle` fidelity.
    pub triangle_simulate_s: Spread,
    /// Event-loop seconds at `draw` fidelity.
    pub draw_simulate_s: Spread,
    /// Whole-run speed-up (triangle / draw), repeat by repeat.
    pub speedup: Spread,
    /// Event-loop speed-up, repeat by repeat.
    pub simulate_speedup: Spread,
    /// Events at `triangle` fidelity.
    pub triangle_events: u64,
    /// Events at `draw` fidelity.
    pub draw_events: u64,
    /// GPU time of the frame, `triangle` (ms).
    pub triangle_gpu_ms: f64,
    /// GPU time of the frame, `draw` (ms).
    pub draw_gpu_ms: f64,
}

/// One frame of `grid:WxW` (2 W^2 triangles) at both fidelities, `repeats`
/// times each in turn.
pub fn pipeline(w: u32, repeats: usize) -> Result<PipelineBench, BenchError> {
    let mesh = format!(
        "workload.groups=[{{name=\"big\", mesh=\"grid:{w}x{w}\", triangle_pixels={{kind=\"lognormal\", median=4.0, sigma=1.0}}}}]"
    );
    let common = [
        "run.frames=1",
        "run.warmup_frames=0",
        "noise.enabled=false",
        mesh.as_str(),
    ];
    let mut tri: Vec<&str> = common.to_vec();
    tri.push("fidelity=\"triangle\"");
    let mut draw: Vec<&str> = common.to_vec();
    draw.push("fidelity=\"draw\"");
    let sim = |s: &serde_json::Value| s["simulate_seconds"].as_f64().unwrap_or(f64::NAN);
    let (mut tw, mut dw, mut ts, mut ds) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut s_tri, mut s_draw) = (serde_json::Value::Null, serde_json::Value::Null);
    for _ in 0..repeats.max(1) {
        let (s, w) = run_default_with(&tri)?;
        tw.push(w);
        ts.push(sim(&s));
        s_tri = s;
        let (s, w) = run_default_with(&draw)?;
        dw.push(w);
        ds.push(sim(&s));
        s_draw = s;
    }
    let ft = |s: &serde_json::Value| s["metrics"]["gpu_time_ms"]["mean"].as_f64().unwrap_or(f64::NAN);
    Ok(PipelineBench {
        width: w,
        triangles: 2 * w as u64 * w as u64,
        repeats: tw.len(),
        triangle_total_s: Spread::of(&tw),
        draw_total_s: Spread::of(&dw),
        triangle_simulate_s: Spread::of(&ts),
        draw_simulate_s: Spread::of(&ds),
        speedup: paired_ratio(&tw, &dw),
        simulate_speedup: paired_ratio(&ts, &ds),
        triangle_events: s_tri["events"]["total"].as_u64().unwrap_or(0),
        draw_events: s_draw["events"]["total"].as_u64().unwrap_or(0),
        triangle_gpu_ms: ft(&s_tri),
        draw_gpu_ms: ft(&s_draw),
    })
}

/// Issue 4's target for Figures 3 and 4 together (51 primitive counts x all
/// configurations) at event fidelity: at most 10 s.
pub const PIXELFLOW_TARGET_S: f64 = 10.0;

/// The target for `counts` primitive counts: [`PIXELFLOW_TARGET_S`] scaled
/// by `counts / 51` (so `--scale` keeps the comparison fair).
pub fn pixelflow_target_s(counts: u32) -> f64 {
    PIXELFLOW_TARGET_S * f64::from(counts) / 51.0
}

/// Figures 3 and 4 of paper 002 at event fidelity, one thread: every
/// architecture, 1 and 4 shaders, 1 and 8 samples, `counts` primitive
/// counts from 0 to 1,000,000. Returns (runs, events, wall seconds).
pub fn pixelflow_figures(counts: u32) -> Result<(u64, u64, f64), BenchError> {
    pixelflow_figures_at(counts, "event")
}

/// [`pixelflow_figures`] at `fidelity` (`"event"` or `"analytic"`, the
/// closed forms: the baseline the event simulation is compared with).
pub fn pixelflow_figures_at(counts: u32, fidelity: &str) -> Result<(u64, u64, f64), BenchError> {
    let src = ModelSource::from_text("models/pixelflow-20.toml", include_str!("../models/pixelflow-20.toml"));
    let base = src.table()?;
    let (mut runs, mut events) = (0u64, 0u64);
    let start = Instant::now();
    for samples in [8, 1] {
        for arch in ["standard", "presort", "nontex"] {
            for shaders in [1, 4] {
                for i in 0..counts.max(2) {
                    let n = 1_000_000u64 * i as u64 / (counts.max(2) - 1) as u64;
                    let (mut run_src, mut t) = (src.clone(), base.clone());
                    Overrides::with_sets(&[
                        format!("samples={samples}"),
                        format!("architecture=\"{arch}\""),
                        format!("shading_nodes={shaders}"),
                        format!("primitives={n}"),
                        format!("fidelity=\"{fidelity}\""),
                    ])
                    .apply(&mut run_src, &mut t)?;
                    let r = run_model(&run_src, &t, None)?;
                    events += r.summary()["events"]["total"].as_u64().unwrap_or(0);
                    runs += 1;
                }
            }
        }
    }
    Ok((runs, events, start.elapsed().as_secs_f64()))
}

/// Events handled in each of `repeats` slices by the kernel case with
/// `population` pending at `scale`: 20 million at 1 in all, and at least 2
/// per pending one in all, so the heap is in steady state.
pub fn kernel_events(population: usize, scale: f64, repeats: usize) -> u64 {
    (((20_000_000.0 * scale) as u64).max(2 * population as u64) / repeats.max(1) as u64).max(1)
}

/// The PixelFlow benchmark: [`pixelflow_figures`] at event fidelity against
/// the same runs at analytic fidelity and against the target.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PixelflowBench {
    /// Primitive counts per configuration.
    pub counts: u32,
    /// Runs at event fidelity in one repeat.
    pub runs: u64,
    /// Events in all, one repeat.
    pub events: u64,
    /// Repeats of both fidelities, in turn.
    pub repeats: usize,
    /// Wall seconds at event fidelity.
    pub wall_s: Spread,
    /// Wall seconds of the same runs at analytic fidelity (closed forms).
    pub closed_s: Spread,
    /// Event over closed form, repeat by repeat.
    pub ratio: Spread,
    /// The target for `counts` ([`pixelflow_target_s`]).
    pub target_s: f64,
}

/// The PixelFlow benchmark at `scale` (51 primitive counts at 1), `repeats`
/// times each fidelity in turn.
pub fn pixelflow_bench(scale: f64, repeats: usize) -> Result<PixelflowBench, BenchError> {
    let counts = ((51.0 * scale) as u32).max(2);
    let (mut wall, mut closed) = (Vec::new(), Vec::new());
    let (mut runs, mut events) = (0, 0);
    for _ in 0..repeats.max(1) {
        let (r, e, w) = pixelflow_figures(counts)?;
        (runs, events) = (r, e);
        wall.push(w);
        closed.push(pixelflow_figures_at(counts, "analytic")?.2);
    }
    Ok(PixelflowBench {
        counts,
        runs,
        events,
        repeats: wall.len(),
        wall_s: Spread::of(&wall),
        closed_s: Spread::of(&closed),
        ratio: paired_ratio(&wall, &closed),
        target_s: pixelflow_target_s(counts),
    })
}

/// The pipeline benchmark at `scale`: one frame of `grid:WxW` with W = 707
/// at 1 (about a million triangles), fewer for smaller scales.
pub fn pipeline_bench(scale: f64, repeats: usize) -> Result<PipelineBench, BenchError> {
    pipeline(((707.0 * scale.sqrt()) as u32).max(2), repeats)
}

/// One long run of the default model at draw fidelity, repeated.
#[derive(Debug, Clone, serde::Serialize)]
pub struct HourBench {
    /// Frames simulated.
    pub frames: u64,
    /// Simulated seconds.
    pub simulated_seconds: f64,
    /// Events handled in one run.
    pub events: u64,
    /// Runs.
    pub repeats: usize,
    /// Wall seconds of a run, loading included.
    pub wall_s: Spread,
    /// The run's own events per second (its event loop).
    pub events_per_second: Spread,
    /// The machine's speed beside it: the bare `BinaryHeap` hold loop at
    /// 1,000 pending ([`bare_rate`]), events per second, for each run the
    /// mean of one measurement just before it and one just after (the speed
    /// of this build machine moves by half within minutes as other work
    /// shares its host).
    pub yardstick_events_per_s: Spread,
    /// A run's wall time in yardstick events (millions): wall seconds
    /// times the yardstick's rate beside it, which stays put when the whole
    /// machine is slower or faster.
    pub yardstick_m_events: Spread,
}

/// The hour benchmark at `scale`: 216,000 frames (an hour at 60 Hz) at 1,
/// run `repeats` times with the yardstick measured between the runs.
pub fn hour_bench(scale: f64, repeats: usize) -> Result<HourBench, BenchError> {
    let frames = (216_000.0 * scale) as u64;
    let f = format!("run.frames={frames}");
    let yardstick_events = ((5_000_000.0 * scale) as u64).max(200_000);
    let mut before = bare_rate(KernelWork::Hold, 1_000, yardstick_events);
    let (mut wall, mut rate, mut yard, mut m_events) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut simulated, mut events) = (0.0, 0);
    for _ in 0..repeats.max(1) {
        let (s, wall_s) = run_default_with(&["fidelity=\"draw\"", f.as_str()])?;
        let after = bare_rate(KernelWork::Hold, 1_000, yardstick_events);
        let yardstick = 0.5 * (before + after);
        before = after;
        simulated = s["simulated_seconds"].as_f64().unwrap_or(0.0);
        events = s["events"]["total"].as_u64().unwrap_or(0);
        wall.push(wall_s);
        rate.push(s["events_per_second"].as_f64().unwrap_or(0.0));
        yard.push(yardstick);
        m_events.push(wall_s * yardstick / 1e6);
    }
    Ok(HourBench {
        frames,
        simulated_seconds: simulated,
        events,
        repeats: wall.len(),
        wall_s: Spread::of(&wall),
        events_per_second: Spread::of(&rate),
        yardstick_events_per_s: Spread::of(&yard),
        yardstick_m_events: Spread::of(&m_events),
    })
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

    #[test]
    fn pixelflow_target_scales_with_the_primitive_counts() {
        assert_eq!(pixelflow_target_s(51), PIXELFLOW_TARGET_S);
        assert!((pixelflow_target_s(25) - 10.0 * 25.0 / 51.0).abs() < 1e-12);
    }

    #[test]
    fn pixelflow_figures_run_every_configuration_at_both_fidelities() {
        // 2 counts x 3 architectures x 2 shader counts x 2 sample counts.
        let (runs, events, _) = pixelflow_figures_at(2, "event").unwrap();
        assert_eq!(runs, 24);
        assert!(events > 0);
        let (runs, events, _) = pixelflow_figures_at(2, "analytic").unwrap();
        assert_eq!((runs, events), (24, 0));
        let b = pixelflow_bench(0.01, 2).unwrap();
        assert_eq!((b.runs, b.repeats, b.wall_s.n, b.ratio.n), (24, 2, 2, 2));
    }
}
