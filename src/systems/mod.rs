//! Simulated systems, each composed from components and driven by the
//! engine. A model file's top-level `system` key picks one (default
//! `frame_pipeline`); [`run_model`] is the one entry point the CLI and the
//! experiment runner use.

pub mod error;
pub mod frame_pipeline;
pub mod multi_rate;
pub mod pixelflow;
pub mod summary;
pub mod vr;

use std::io::Write;

use serde_json::Value;

use crate::config::{ConfigError, ModelSource, deserialize, invalid};
use crate::output::trace::TraceWriter;

pub use crate::config::DEFAULT_MODEL;
pub use error::SystemError;

/// The latency-stage vocabulary shared by the multi-frame-rate and VR
/// breakdowns (`metrics.latency_breakdown_ms`), in chain order, each with
/// the NVIDIA Reflex stage it corresponds to (docs/latency.md explains the
/// mapping and which stages are zero in the papers' models).
pub const LATENCY_STAGES: [(&str, &str); 12] = [
    ("input_sample", "sensor/input (input to the sample that captures it)"),
    (
        "sensor_transport",
        "sensor/input (tracker to application; Reflex has no separate stage)",
    ),
    (
        "simulation_wait",
        "simulation (wait for the simulation/frame start that reads the sample)",
    ),
    ("simulation", "simulation"),
    ("render", "render (GPU render)"),
    ("readback", "transfer (GPU to host)"),
    ("transfer", "transfer (host to host)"),
    (
        "composite_wait",
        "render submission (wait for the frame that takes another process's image)",
    ),
    ("render_submission", "render submission (upload and submit)"),
    ("composite_render", "render (the frame that composites or re-projects)"),
    ("swap_lock", "display (present: wait for the swap / vertical blank)"),
    ("display", "display (scan-out to photons)"),
];

/// Errors of running any system.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The model file is wrong.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The system failed while running.
    #[error("{model}: {source}")]
    Run {
        /// The model's name (its file, or the embedded default).
        model: String,
        /// What went wrong.
        #[source]
        source: SystemError,
    },
}

impl SimError {
    /// A system's error as the model's: a value the system cannot use is
    /// blamed on the model file (with its line and the `--set` that gave
    /// it), anything else names the model.
    fn of(src: &ModelSource, e: SystemError) -> SimError {
        match e {
            SystemError::Invalid { key, message } => SimError::Config(invalid(src, &key, message, None)),
            e => SimError::Run {
                model: src.name.clone(),
                source: e,
            },
        }
    }
}

/// The result of running one model.
#[derive(Debug)]
pub enum SystemRun {
    /// A frame-pipeline run.
    FramePipeline(Box<frame_pipeline::PipelineRun>),
    /// A multi-frame-rate run.
    MultiRate(Box<multi_rate::MultiRateRun>),
    /// A VR-pipeline run.
    Vr(Box<vr::VrRun>),
    /// A PixelFlow run (one frame).
    PixelFlow(Box<pixelflow::PixelFlowRun>),
}

/// Builds and runs the system a model describes. With a `trace` writer, the
/// run's trace is written into it (the frame pipeline's while it runs) and
/// handed back by [`SystemRun::take_trace`], to be closed by the caller.
pub fn run_model(src: &ModelSource, table: &toml::Table, trace: Option<TraceWriter>) -> Result<SystemRun, SimError> {
    let system = match table.get("system") {
        None => "frame_pipeline",
        Some(toml::Value::String(s)) => s.as_str(),
        Some(other) => {
            return Err(SimError::Config(invalid(
                src,
                "system",
                format!(
                    "expected a system name as a string (frame_pipeline, multi_rate, vr, pixelflow), found {}",
                    other.type_str()
                ),
                None,
            )));
        }
    };
    match system {
        "frame_pipeline" => {
            let cfg: frame_pipeline::FramePipelineConfig = deserialize(table, src)?;
            frame_pipeline::run_pipeline(cfg, &src.base_dir, trace)
                .map(|r| SystemRun::FramePipeline(Box::new(r)))
                .map_err(|e| SimError::of(src, e))
        }
        "multi_rate" => {
            let cfg: multi_rate::MultiRateConfig = deserialize(table, src)?;
            multi_rate::run_multi_rate(cfg, trace)
                .map(|r| SystemRun::MultiRate(Box::new(r)))
                .map_err(|e| SimError::of(src, e))
        }
        "vr" => {
            let cfg: vr::VrConfig = deserialize(table, src)?;
            vr::run_vr(cfg, trace)
                .map(|r| SystemRun::Vr(Box::new(r)))
                .map_err(|e| SimError::of(src, e))
        }
        "pixelflow" => {
            let cfg: pixelflow::PixelFlowConfig = deserialize(table, src)?;
            let traced = trace.is_some();
            pixelflow::run_pixelflow(cfg, traced)
                .map(|mut r| {
                    r.trace = trace.map(|mut t| {
                        pixelflow::run::write_trace(&r, &mut t);
                        t
                    });
                    SystemRun::PixelFlow(Box::new(r))
                })
                .map_err(|e| SimError::of(src, e))
        }
        other => Err(SimError::Config(invalid(
            src,
            "system",
            format!("unknown system {other:?} (known: frame_pipeline, multi_rate, vr, pixelflow)"),
            None,
        ))),
    }
}

impl SystemRun {
    /// The JSON summary.
    pub fn summary(&self) -> &Value {
        match self {
            SystemRun::FramePipeline(r) => &r.summary,
            SystemRun::MultiRate(r) => &r.summary,
            SystemRun::Vr(r) => &r.summary,
            SystemRun::PixelFlow(r) => &r.summary,
        }
    }

    /// Mutable summary (the CLI adds the model's name).
    pub fn summary_mut(&mut self) -> &mut Value {
        match self {
            SystemRun::FramePipeline(r) => &mut r.summary,
            SystemRun::MultiRate(r) => &mut r.summary,
            SystemRun::Vr(r) => &mut r.summary,
            SystemRun::PixelFlow(r) => &mut r.summary,
        }
    }

    /// Writes the human-readable report of the run (what `rendersim run`
    /// prints without `--json`), from its summary.
    pub fn write_report(&self, w: &mut dyn Write) -> std::io::Result<()> {
        match self {
            SystemRun::FramePipeline(r) => frame_pipeline::report::write_report(&r.summary, w),
            SystemRun::MultiRate(r) => multi_rate::report::write_report(&r.summary, w),
            SystemRun::Vr(r) => vr::report::write_report(&r.summary, w),
            SystemRun::PixelFlow(r) => pixelflow::report::write_report(&r.summary, w),
        }
    }

    /// Writes the per-frame table as CSV (per input event for latency
    /// systems; PixelFlow: one row per screen region of the simulated frame).
    pub fn write_frames_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        match self {
            SystemRun::FramePipeline(r) => frame_pipeline::records::write_frames_csv(&r.records, w),
            SystemRun::MultiRate(r) => multi_rate::run::write_events_csv(&r.events, w),
            SystemRun::Vr(r) => vr::run::write_motions_csv(&r.motions, w),
            SystemRun::PixelFlow(r) => pixelflow::run::write_regions_csv(r, w),
        }
    }

    /// The per-frame table (columns and rows), for experiments.
    pub fn frame_table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        match self {
            SystemRun::FramePipeline(r) => (
                frame_pipeline::records::COLUMNS.iter().map(|s| s.to_string()).collect(),
                frame_pipeline::records::frame_rows(&r.records)
                    .into_iter()
                    .map(|row| row.to_vec())
                    .collect(),
            ),
            SystemRun::MultiRate(r) => (
                multi_rate::latency::COLUMNS.iter().map(|s| s.to_string()).collect(),
                multi_rate::latency::event_rows(&r.events),
            ),
            SystemRun::Vr(r) => (
                vr::run::COLUMNS.iter().map(|s| s.to_string()).collect(),
                vr::run::motion_rows(&r.motions),
            ),
            SystemRun::PixelFlow(r) => (
                pixelflow::run::COLUMNS.iter().map(|s| s.to_string()).collect(),
                pixelflow::run::region_rows(r),
            ),
        }
    }

    /// The fully resolved model as TOML (runnable again); relative mesh
    /// file paths are made absolute against `base_dir`.
    pub fn resolved_model(&self, base_dir: &std::path::Path) -> String {
        match self {
            SystemRun::FramePipeline(r) => {
                let mut cfg = r.config.clone();
                if let frame_pipeline::config::WorkloadConfig::Scene(s) = &mut cfg.workload {
                    for g in &mut s.groups {
                        if let crate::scene::config::MeshRef::Spec(spec) = &mut g.mesh {
                            let p = std::path::Path::new(spec.as_str());
                            if (spec.ends_with(".obj") || spec.ends_with(".idx")) && p.is_relative() {
                                let abs = base_dir.join(p);
                                *spec = abs.canonicalize().unwrap_or(abs).display().to_string();
                            }
                        }
                    }
                }
                let body = toml::to_string(&cfg).unwrap_or_else(|e| format!("# could not serialize the model: {e}\n"));
                format!(
                    "# Fully resolved model written by rendersim; run it again with `rendersim run model.toml`.\n{body}"
                )
            }
            SystemRun::Vr(r) => {
                let body =
                    toml::to_string(&r.config).unwrap_or_else(|e| format!("# could not serialize the model: {e}\n"));
                format!(
                    "# Fully resolved model written by rendersim; run it again with `rendersim run model.toml`.\n{body}"
                )
            }
            SystemRun::MultiRate(r) => {
                let body =
                    toml::to_string(&r.config).unwrap_or_else(|e| format!("# could not serialize the model: {e}\n"));
                format!(
                    "# Fully resolved model written by rendersim; run it again with `rendersim run model.toml`.\n{body}"
                )
            }
            SystemRun::PixelFlow(r) => {
                let body =
                    toml::to_string(&r.config).unwrap_or_else(|e| format!("# could not serialize the model: {e}\n"));
                format!(
                    "# Fully resolved model written by rendersim; run it again with `rendersim run model.toml`.\n{body}"
                )
            }
        }
    }

    /// The run's trace writer, all events written, for the caller to close
    /// ([`TraceWriter::finish`]); `None` when no trace was asked for.
    pub fn take_trace(&mut self) -> Option<TraceWriter> {
        match self {
            SystemRun::FramePipeline(r) => r.trace.take(),
            SystemRun::MultiRate(r) => r.trace.take(),
            SystemRun::Vr(r) => r.trace.take(),
            SystemRun::PixelFlow(r) => r.trace.take(),
        }
    }
}
