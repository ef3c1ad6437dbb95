//! Speed benchmarks behind `rendersim bench` (and `cargo bench`): each
//! measures its rate next to a baseline measured in the same run.
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

/// Result of one kernel benchmark case.
#[derive(Debug, Clone, serde::Serialize)]
pub struct KernelBench {
    /// The delays.
    pub work: KernelWork,
    /// Pending events.
    pub population: usize,
    /// Events handled.
    pub events: u64,
    /// Engine events per second (its default queue, the radix heap).
    pub engine_events_per_s: f64,
    /// Engine events per second on its binary-heap queue.
    pub engine_binary_events_per_s: f64,
    /// Bare `BinaryHeap` loop events per second (the baseline).
    pub bare_events_per_s: f64,
    /// engine / bare.
    pub ratio: f64,
}

fn engine_rate(work: KernelWork, population: usize, events: u64, kind: QueueKind) -> f64 {
    let streams = RngStreams::new(7);
    let mut sched = Scheduler::with_queue(kind);
    let mut init = streams.stream("init");
    for _ in 0..population {
        sched.at(Time(init.random_range(0..2_000_000u64)), Hold);
    }
    let mut m = HoldModel {
        rng: streams.stream("hold"),
        work,
    };
    let t = Instant::now();
    let st = run(
        &mut m,
        &mut sched,
        Limits {
            until: None,
            max_events: Some(events),
        },
    )
    .expect("the benchmark model cannot overflow in a benchmark's span");
    let secs = t.elapsed().as_secs_f64();
    assert_eq!(st.events, events);
    events as f64 / secs
}

/// The kernel on `work` with `population` pending events, `events` handled,
/// against a bare `BinaryHeap` loop doing the same work (same delays).
pub fn kernel_case(work: KernelWork, population: usize, events: u64) -> KernelBench {
    let population = population.max(1);
    let engine = engine_rate(work, population, events, QueueKind::Radix);
    let engine_binary = engine_rate(work, population, events, QueueKind::Binary);
    let bare = bare_rate(work, population, events);
    KernelBench {
        work,
        population,
        events,
        engine_events_per_s: engine,
        engine_binary_events_per_s: engine_binary,
        bare_events_per_s: bare,
        ratio: engine / bare,
    }
}

/// Events per second of the bare loop: `work` on a `BinaryHeap` of
/// `(time, seq)` with `population` pending, `events` handled (the kernel
/// benchmark's baseline, and the hour's yardstick of the machine's speed).
pub fn bare_rate(work: KernelWork, population: usize, events: u64) -> f64 {
    let population = population.max(1);
    let streams = RngStreams::new(7);
    let mut heap: BinaryHeap<Reverse<(u64, u64)>> = BinaryHeap::with_capacity(64);
    let mut init = streams.stream("init");
    let mut seq = 0u64;
    for _ in 0..population {
        heap.push(Reverse((init.random_range(0..2_000_000u64), seq)));
        seq += 1;
    }
    let mut rng = streams.stream("hold");
    let t = Instant::now();
    let mut last = 0u64;
    for _ in 0..events {
        let Reverse((time, _)) = heap.pop().expect("population > 0");
        last = last.max(time);
        let d = work.delay(&mut rng);
        heap.push(Reverse((time + d, seq)));
        seq += 1;
    }
    let bare_s = t.elapsed().as_secs_f64();
    std::hint::black_box(last);
    events as f64 / bare_s
}

/// The hold model with `population` pending events (see [`kernel_case`]).
pub fn kernel(population: usize, events: u64) -> KernelBench {
    kernel_case(KernelWork::Hold, population, events)
}

/// The kernel benchmark's cases: hold at 1,000, 100,000 and 1,000,000
/// pending; stiff at 100,000 and 1,000,000 (issue 15's targets).
pub const KERNEL_CASES: [(KernelWork, usize); 5] = [
    (KernelWork::Hold, 1_000),
    (KernelWork::Hold, 100_000),
    (KernelWork::Hold, 1_000_000),
    (KernelWork::Stiff, 100_000),
    (KernelWork::Stiff, 1_000_000),
];

/// The kernel's scaling: hold and stiff at 1e3, 1e4, 1e5 and 1e6 pending
/// (what `rendersim bench kernel --plot` draws).
pub fn kernel_scaling(scale: f64) -> Vec<KernelBench> {
    let mut out = Vec::new();
    for work in [KernelWork::Hold, KernelWork::Stiff] {
        for pop in [1_000usize, 10_000, 100_000, 1_000_000] {
            let events = ((4_000_000.0 * scale) as u64).max(2 * pop as u64);
            out.push(kernel_case(work, pop, events));
        }
    }
    out
}

/// Draws ns per event against the number pending (log axes): the engine
/// (radix heap), the engine on its binary heap and the bare `BinaryHeap`
/// loop, for hold and stiff. `path` names the PNG; an SVG is written beside.
pub fn plot_kernel(cases: &[KernelBench], path: &std::path::Path) -> Result<(), crate::plot::PlotError> {
    use crate::plot::{LinePlot, Series, line_plot};
    let mut series = Vec::new();
    for work in [KernelWork::Hold, KernelWork::Stiff] {
        let of = |rate: fn(&KernelBench) -> f64, name: &str| Series {
            name: format!("{name}, {}", work.name()),
            points: cases
                .iter()
                .filter(|c| c.work == work)
                .map(|c| (c.population as f64, 1e9 / rate(c)))
                .collect(),
            ci: None,
        };
        series.push(of(|c| c.engine_events_per_s, "engine (radix heap)"));
        series.push(of(|c| c.engine_binary_events_per_s, "engine (binary heap)"));
        series.push(of(|c| c.bare_events_per_s, "bare BinaryHeap loop"));
    }
    let base = path.with_extension("");
    line_plot(
        &base,
        &LinePlot {
            title: "Event kernel: cost per event against events pending".into(),
            x_label: "events pending (log)".into(),
            y_label: "ns per event (log)".into(),
            series,
            log_x: true,
            log_y: true,
            x_categories: Vec::new(),
        },
    )
}

/// Why a benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// `--scale` is outside (0, 1].
    #[error("--scale must be in (0, 1], got {0}")]
    Scale(f64),
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

/// One frame at both fidelities.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PipelineBench {
    /// The grid's side: the frame is `grid:WxW`.
    pub width: u32,
    /// Triangles in the frame.
    pub triangles: u64,
    /// Wall seconds, build (mesh, cache simulation) and simulation, `triangle`.
    pub triangle_total_s: f64,
    /// The same at `draw` fidelity.
    pub draw_total_s: f64,
    /// Event-loop seconds at `triangle` fidelity.
    pub triangle_simulate_s: f64,
    /// Event-loop seconds at `draw` fidelity.
    pub draw_simulate_s: f64,
    /// Events at `triangle` fidelity.
    pub triangle_events: u64,
    /// Events at `draw` fidelity.
    pub draw_events: u64,
    /// GPU time of the frame, `triangle` (ms).
    pub triangle_gpu_ms: f64,
    /// GPU time of the frame, `draw` (ms).
    pub draw_gpu_ms: f64,
}

/// One frame of `grid:WxW` (2 W^2 triangles) at both fidelities.
pub fn pipeline(w: u32) -> Result<PipelineBench, BenchError> {
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
    let (s_tri, w_tri) = run_default_with(&tri)?;
    let mut draw: Vec<&str> = common.to_vec();
    draw.push("fidelity=\"draw\"");
    let (s_draw, w_draw) = run_default_with(&draw)?;
    let ft = |s: &serde_json::Value| s["metrics"]["gpu_time_ms"]["mean"].as_f64().unwrap_or(f64::NAN);
    let sim = |s: &serde_json::Value| s["simulate_seconds"].as_f64().unwrap_or(f64::NAN);
    Ok(PipelineBench {
        width: w,
        triangles: 2 * w as u64 * w as u64,
        triangle_total_s: w_tri,
        draw_total_s: w_draw,
        triangle_simulate_s: sim(&s_tri),
        draw_simulate_s: sim(&s_draw),
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

/// Events handled by the kernel case with `population` pending at `scale`:
/// at least 2 per pending one, so the heap is in steady state.
pub fn kernel_events(population: usize, scale: f64) -> u64 {
    ((20_000_000.0 * scale) as u64).max(2 * population as u64)
}

/// The PixelFlow benchmark: [`pixelflow_figures`] at event fidelity against
/// the same runs at analytic fidelity and against the target.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PixelflowBench {
    /// Primitive counts per configuration.
    pub counts: u32,
    /// Runs at event fidelity.
    pub runs: u64,
    /// Events in all.
    pub events: u64,
    /// Wall seconds at event fidelity.
    pub wall_s: f64,
    /// Wall seconds of the same runs at analytic fidelity (closed forms).
    pub closed_s: f64,
    /// The target for `counts` ([`pixelflow_target_s`]).
    pub target_s: f64,
}

/// The PixelFlow benchmark at `scale` (51 primitive counts at 1).
pub fn pixelflow_bench(scale: f64) -> Result<PixelflowBench, BenchError> {
    let counts = ((51.0 * scale) as u32).max(2);
    let (runs, events, wall_s) = pixelflow_figures(counts)?;
    let (_, _, closed_s) = pixelflow_figures_at(counts, "analytic")?;
    Ok(PixelflowBench {
        counts,
        runs,
        events,
        wall_s,
        closed_s,
        target_s: pixelflow_target_s(counts),
    })
}

/// The pipeline benchmark at `scale`: one frame of `grid:WxW` with W = 707
/// at 1 (about a million triangles), fewer for smaller scales.
pub fn pipeline_bench(scale: f64) -> Result<PipelineBench, BenchError> {
    pipeline(((707.0 * scale.sqrt()) as u32).max(2))
}

/// One long run of the default model at draw fidelity.
#[derive(Debug, Clone, serde::Serialize)]
pub struct HourBench {
    /// Frames simulated.
    pub frames: u64,
    /// Simulated seconds.
    pub simulated_seconds: f64,
    /// Wall seconds, loading included.
    pub wall_s: f64,
    /// Events handled.
    pub events: u64,
    /// The run's own events per second (its event loop).
    pub events_per_second: f64,
    /// The machine's speed beside it: the bare `BinaryHeap` hold loop at
    /// 1,000 pending ([`bare_rate`]), events per second, the mean of one
    /// measurement just before the run and one just after (the speed of
    /// this build machine moves by half within minutes as other work
    /// shares its host).
    pub yardstick_events_per_s: f64,
    /// The run's wall time in yardstick events (millions): wall seconds
    /// times the yardstick's rate, which stays put when the whole machine
    /// is slower or faster.
    pub yardstick_m_events: f64,
}

/// The hour benchmark at `scale`: 216,000 frames (an hour at 60 Hz) at 1.
pub fn hour_bench(scale: f64) -> Result<HourBench, BenchError> {
    let frames = (216_000.0 * scale) as u64;
    let f = format!("run.frames={frames}");
    let yardstick_events = ((5_000_000.0 * scale) as u64).max(200_000);
    let before = bare_rate(KernelWork::Hold, 1_000, yardstick_events);
    let (s, wall_s) = run_default_with(&["fidelity=\"draw\"", f.as_str()])?;
    let after = bare_rate(KernelWork::Hold, 1_000, yardstick_events);
    let yardstick = 0.5 * (before + after);
    Ok(HourBench {
        frames,
        simulated_seconds: s["simulated_seconds"].as_f64().unwrap_or(0.0),
        wall_s,
        events: s["events"]["total"].as_u64().unwrap_or(0),
        events_per_second: s["events_per_second"].as_f64().unwrap_or(0.0),
        yardstick_events_per_s: yardstick,
        yardstick_m_events: wall_s * yardstick / 1e6,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_plot_draws_every_case() {
        let cases: Vec<KernelBench> = [KernelWork::Hold, KernelWork::Stiff]
            .into_iter()
            .flat_map(|work| {
                [1_000usize, 1_000_000].into_iter().map(move |p| KernelBench {
                    work,
                    population: p,
                    events: 2 * p as u64,
                    engine_events_per_s: 2e7,
                    engine_binary_events_per_s: 1e7 / (p as f64).log10(),
                    bare_events_per_s: 1e7 / (p as f64).log10(),
                    ratio: 2.0,
                })
            })
            .collect();
        let d = tempfile::tempdir().unwrap();
        plot_kernel(&cases, &d.path().join("kernel.png")).unwrap();
        for ext in ["png", "svg"] {
            let bytes = std::fs::read(d.path().join(format!("kernel.{ext}"))).unwrap();
            assert!(bytes.len() > 1000, "{ext}");
        }
    }

    #[test]
    fn a_kernel_case_handles_the_events_asked_for_and_measures_all_three() {
        let k = kernel_case(KernelWork::Stiff, 100, 1_000);
        assert_eq!((k.population, k.events), (100, 1_000));
        for r in [k.engine_events_per_s, k.engine_binary_events_per_s, k.bare_events_per_s] {
            assert!(r.is_finite() && r > 0.0);
        }
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
    }
}
