//! The frame pipeline's plan: the one fallible step between a parsed model
//! and a run. [`PipelinePlan::new`] checks the model ([`CheckedPipeline`]:
//! ranges, distributions, the display, the architecture, the memory its
//! results take), compiles its scene (`workload.rs`), bounds the clock's
//! range and the count of events from the closed-form terms
//! (`analytic.rs`, paper 000 §4.1), and builds the system-task sources
//! (`components/noise.rs`). What it returns can only run: building the
//! units from it ([`super::model::FramePipeline::new`]) cannot fail, and
//! nothing after it checks the model again.
//!
//! ```
//! use std::path::Path;
//! use rendersim_models::config::{Overrides, deserialize, load_model};
//! use rendersim_models::systems::frame_pipeline::{FramePipelineConfig, PipelinePlan};
//!
//! // The embedded default model, 30 frames of it.
//! let m = load_model(None, &Overrides::with_sets(&["run.frames=30"])).unwrap();
//! let cfg: FramePipelineConfig = deserialize(&m.table, &m.source).unwrap();
//! let plan = PipelinePlan::new(cfg.clone(), Path::new(".")).unwrap();
//! // Paper 000's closed-form frame time, from the slowest unit to all of
//! // them in series, is known before a single event runs.
//! let a = plan.analytic();
//! assert!(a.frame_max_ms > 0.0 && a.frame_max_ms <= a.frame_sum_ms);
//! let run = plan.run(None).unwrap();
//! assert_eq!(run.records.len(), 30);
//! // The results stay typed: 30 frames less the 20 of the warm-up, shown.
//! assert_eq!(run.results.metrics.displayed_frames, 10);
//!
//! // A model the plan refuses names the key it refuses.
//! let mut bad = cfg;
//! bad.display.buffers = 0;
//! let e = PipelinePlan::new(bad, Path::new(".")).unwrap_err().to_string();
//! assert!(e.contains("display.buffers"), "{e}");
//! ```

use std::path::Path;

use crate::components::frame_generation::FrameGenerationConfig;
use crate::components::noise::{Arrivals, NoiseSource};
use crate::components::swap_chain::{PresentMode, VrrWindow};
use crate::components::tearing::ScanOut;
use crate::engine::{Duration, RngStreams};
use crate::systems::error::SystemError;

use super::analytic::{AnalyticTerms, analytic_terms};
use super::checked::CheckedPipeline;
use super::config::{FramePipelineConfig, WorkloadConfig};
use super::cpu_thread::FixedWork;
use super::unit_specs::{UnitSpecs, unit_specs};
use super::validate::{check_events, check_time_range};
use super::workload::{SceneProgram, compile_scene};

/// What a frame's work comes from: a compiled scene, or a fixed workload
/// (drawn from distributions, or given frame by frame).
#[derive(Debug)]
pub(super) enum PlannedWork {
    /// A compiled scene (`workload.kind = "scene"`).
    Scene(SceneProgram),
    /// A fixed workload, which the CPU thread holds.
    Fixed(FixedWork),
}

/// What the display is built from: its swap chain (images, and the present
/// mode resolved once: `immediate` without vsync), its refresh, when
/// frames are taken after each vertical blank and the compositor's delay, the variable-refresh window, the scan-out a tearing
/// flip lands in, and frame generation when it presents between frames.
#[derive(Debug, Clone)]
pub(super) struct DisplaySpec {
    pub(super) mode: PresentMode,
    pub(super) buffers: u32,
    /// The refresh period (the shortest, on a variable-refresh panel).
    pub(super) refresh: Duration,
    /// When the swap chain's frames are taken after each vertical blank
    /// (the compositor's wake when composed; else at the blank).
    pub(super) latch_phase: Duration,
    /// From a frame's being taken to its being on screen.
    pub(super) compositor_delay: Duration,
    pub(super) vrr: Option<VrrWindow>,
    pub(super) scan: Option<ScanOut>,
    pub(super) generation: Option<FrameGenerationConfig>,
    pub(super) frames_total: u64,
    pub(super) warmup_frames: u64,
}

impl DisplaySpec {
    fn of(cfg: &FramePipelineConfig) -> Self {
        let d = &cfg.display;
        DisplaySpec {
            mode: d.effective_mode(),
            buffers: d.buffers,
            refresh: d.shortest_period(),
            latch_phase: d.latch_phase(),
            compositor_delay: d.compositor_delay(),
            vrr: d.vrr_window(),
            scan: d.scan_out(),
            generation: cfg.frame_generation.enabled.then(|| cfg.frame_generation.clone()),
            frames_total: cfg.run.frames,
            warmup_frames: cfg.run.warmup_frames,
        }
    }
}

/// A frame-pipeline model that passed every check, with its scene compiled
/// and its system tasks built: everything a run needs, nothing left to
/// refuse. Made only by [`PipelinePlan::new`] (or, for a caller that
/// compiles its own program, [`PipelinePlan::with_program`]).
#[derive(Debug)]
pub struct PipelinePlan {
    checked: CheckedPipeline,
    pub(super) work: PlannedWork,
    pub(super) noise: Vec<NoiseSource>,
    pub(super) display: DisplaySpec,
    /// The other units' specs.
    units: UnitSpecs,
    analytic: Option<AnalyticTerms>,
    /// Seconds the plan took (the run adds the units' building).
    pub(super) build_seconds: f64,
}

impl PipelinePlan {
    /// Checks `cfg` and compiles it: relative file paths in it (meshes,
    /// scenes) are read from `base_dir`.
    pub fn new(cfg: FramePipelineConfig, base_dir: &Path) -> Result<Self, SystemError> {
        let start = std::time::Instant::now();
        let checked = CheckedPipeline::new(cfg)?;
        let cfg = checked.config();
        let scene = match &cfg.workload {
            WorkloadConfig::Scene(s) => Some(compile_scene(cfg, s, base_dir)?),
            WorkloadConfig::Fixed(_) | WorkloadConfig::Frames(_) => None,
        };
        let analytic = analytic_terms(cfg, scene.as_ref());
        check_time_range(cfg, &analytic)?;
        check_events(cfg, &analytic, scene.as_ref().map(|s| s.stats.triangles))?;
        let mut plan = Self::build(checked, scene)?;
        plan.analytic = Some(analytic);
        plan.build_seconds = start.elapsed().as_secs_f64();
        Ok(plan)
    }

    /// The plan of a checked model whose scene `program` the caller built
    /// ([`super::workload::build_program`]): the walkthrough draws each
    /// frame's visible objects as a one-frame run. The model's workload must
    /// be a scene. Its clock and events are not bounded here (the caller
    /// bounds its own runs), and it has no closed-form terms.
    pub fn with_program(checked: CheckedPipeline, program: SceneProgram) -> Result<Self, SystemError> {
        if !matches!(checked.config().workload, WorkloadConfig::Scene(_)) {
            return Err(SystemError::Invalid {
                key: "workload.kind".into(),
                message: "a compiled scene program needs a `scene` workload".into(),
            });
        }
        Self::build(checked, Some(program))
    }

    /// The plan's work and system tasks.
    fn build(checked: CheckedPipeline, scene: Option<SceneProgram>) -> Result<Self, SystemError> {
        let cfg = checked.config();
        let streams = RngStreams::new(cfg.run.seed);
        let work = match (&cfg.workload, scene) {
            (WorkloadConfig::Scene(_), Some(s)) => PlannedWork::Scene(s),
            (WorkloadConfig::Fixed(f), _) => PlannedWork::Fixed(FixedWork::Drawn {
                cpu: f.cpu.clone(),
                gpu: f.gpu.clone(),
                cpu_rng: streams.stream("workload.cpu"),
                gpu_rng: streams.stream("workload.gpu"),
            }),
            (WorkloadConfig::Frames(f), _) => PlannedWork::Fixed(FixedWork::PerFrame(f.clone())),
            (WorkloadConfig::Scene(_), None) => unreachable!("a scene workload is compiled before it is built"),
        };
        let noise = noise_sources(cfg, &streams)?;
        Ok(PipelinePlan {
            display: DisplaySpec::of(cfg),
            units: unit_specs(cfg),
            checked,
            work,
            noise,
            analytic: None,
            build_seconds: 0.0,
        })
    }

    /// The checked model (what `model.toml` writes).
    #[inline]
    pub fn config(&self) -> &FramePipelineConfig {
        self.checked.config()
    }

    /// The closed-form terms the plan's bounds came from (paper 000 §4.1).
    /// # Panics
    /// On a plan made by [`PipelinePlan::with_program`], which has none.
    pub fn analytic(&self) -> &AnalyticTerms {
        self.analytic
            .as_ref()
            .expect("a plan made by `PipelinePlan::new` has its closed-form terms")
    }

    /// The plan taken apart for the units: the model, the work, the system
    /// tasks, the display's spec and the other units' specs.
    pub(super) fn into_parts(
        self,
    ) -> (
        FramePipelineConfig,
        PlannedWork,
        Vec<NoiseSource>,
        DisplaySpec,
        UnitSpecs,
    ) {
        (
            self.checked.into_config(),
            self.work,
            self.noise,
            self.display,
            self.units,
        )
    }
}

/// The model's noise sources (system tasks), periodic then random.
fn noise_sources(cfg: &FramePipelineConfig, streams: &RngStreams) -> Result<Vec<NoiseSource>, SystemError> {
    let mut noise = Vec::new();
    if !cfg.noise.enabled {
        return Ok(noise);
    }
    for (i, p) in cfg.noise.periodic.iter().enumerate().filter(|(_, p)| p.enabled) {
        let src = NoiseSource::new(
            p.name.clone(),
            p.target,
            Arrivals::Periodic {
                period: p.period,
                phase: p.phase,
                jitter: p.jitter,
            },
            p.duration.clone(),
            streams.stream(&format!("noise.{}", p.name)),
        )
        .map_err(|e| SystemError::Invalid {
            key: format!("noise.periodic.{i}"),
            message: e.to_string(),
        })?;
        noise.push(src);
    }
    for (i, r) in cfg.noise.random.iter().enumerate().filter(|(_, r)| r.enabled) {
        let src = NoiseSource::new(
            r.name.clone(),
            r.target,
            Arrivals::Poisson {
                mean_gap: r.rate.period,
            },
            r.duration.clone(),
            streams.stream(&format!("noise.{}", r.name)),
        )
        .map_err(|e| SystemError::Invalid {
            key: format!("noise.random.{i}"),
            message: e.to_string(),
        })?;
        noise.push(src);
    }
    Ok(noise)
}
