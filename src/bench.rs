//! Speed benchmarks behind `rendersim bench` (and `cargo bench`): each
//! measures its rate next to a baseline measured in the same run, repeated,
//! and keeps every figure's minimum, median and maximum ([`spread`]).
//!
//! - `kernel`: the classic hold model (a fixed population of pending events;
//!   each handled event schedules one more at a random later time) and a
//!   stiff mix (nanosecond delays with one-second ones) through the engine,
//!   on its radix heap and on its binary heap, against a bare `BinaryHeap`
//!   loop doing the same work ([`kernel`](mod@kernel)).
//! - `pipeline`: one frame of about one million triangles at `triangle`
//!   fidelity against the same frame at `draw` fidelity.
//! - `hour`: one simulated hour of the default (noisy, 60 Hz) model at `draw`
//!   fidelity.
//! - `pixelflow`: Figures 3 and 4 of paper 002 at event fidelity against
//!   the closed forms and a target.
//! - `build`: the vertex-cache reordering against its direct form, and the
//!   scene build against the simulation of the models that build a mesh
//!   ([`build`]).
//! - `replay`: replaying a 20,000-frame PresentMon capture against reading
//!   its CSV alone ([`replay`]).
//!
//! The functions return the measurements; `rendersim bench` prints them.

use std::time::Instant;

use crate::config::{ConfigError, ModelSource, Overrides, deserialize, load_model};
use crate::systems::frame_pipeline::PipelineSummary;
use crate::systems::frame_pipeline::{FramePipelineConfig, run_pipeline};
use crate::systems::pixelflow::PixelFlowRun;
use crate::systems::{SimError, run_model};

pub mod build;
pub mod kernel;
pub mod replay;
pub mod spread;

pub use kernel::{KERNEL_CASES, KernelBench, KernelWork, bare_rate, kernel, kernel_case, kernel_events, plot_kernel};
use spread::{Spread, paired_ratio};

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
    /// A benchmark's model ran as another system than the one whose typed
    /// results the benchmark reads.
    #[error("{model}: not a {system} model")]
    System {
        /// The model's name.
        model: String,
        /// The system the benchmark reads.
        system: &'static str,
    },
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
    /// A 20,000-frame capture's replay against reading it ([`replay::replay_bench`]).
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

fn run_default_with(sets: &[&str]) -> Result<(PipelineSummary, f64), BenchError> {
    let m = load_model(None, &Overrides::with_sets(sets))?;
    let start = Instant::now();
    let cfg: FramePipelineConfig = deserialize(&m.table, &m.source)?;
    let r = run_pipeline(cfg, &m.source.base_dir, None).map_err(|e| SimError::of(&m.source, e))?;
    Ok((r.results, start.elapsed().as_secs_f64()))
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
    let (mut tw, mut dw, mut ts, mut ds) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut s_tri, mut s_draw) = (None, None);
    for _ in 0..repeats.max(1) {
        let (s, w) = run_default_with(&tri)?;
        tw.push(w);
        ts.push(s.simulate_seconds);
        s_tri = Some(s);
        let (s, w) = run_default_with(&draw)?;
        dw.push(w);
        ds.push(s.simulate_seconds);
        s_draw = Some(s);
    }
    let events = |s: &Option<PipelineSummary>| s.as_ref().map_or(0, |s| s.events.total);
    let ft = |s: &Option<PipelineSummary>| s.as_ref().and_then(|s| s.metrics.gpu_time_ms.mean).unwrap_or(f64::NAN);
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
        triangle_events: events(&s_tri),
        draw_events: events(&s_draw),
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
                    let r =
                        run_model(&run_src, &t, None)?
                            .downcast::<PixelFlowRun>()
                            .map_err(|_| BenchError::System {
                                model: run_src.name.clone(),
                                system: "pixelflow",
                            })?;
                    events += r.summary.events.total;
                    runs += 1;
                }
            }
        }
    }
    Ok((runs, events, start.elapsed().as_secs_f64()))
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
        simulated = s.simulated_seconds;
        events = s.events.total;
        wall.push(wall_s);
        rate.push(s.events_per_second);
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
