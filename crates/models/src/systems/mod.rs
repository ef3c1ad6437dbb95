//! Simulated systems, each composed from components and driven by the
//! engine. A model file's top-level `system` key picks one (default
//! `frame_pipeline`); [`run_model`] is the one entry point the CLI and the
//! experiment runner use.

pub mod checked;
pub mod error;
pub mod frame_pipeline;
pub mod multi_rate;
pub mod pixelflow;
pub mod present;
pub mod state_sorting;
pub mod summary;
pub mod tracked_input;
pub mod vr;
pub mod walkthrough;

use std::io::Write;
use std::path::Path;

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
    pub fn of(src: &ModelSource, e: SystemError) -> SimError {
        match e {
            SystemError::Invalid { key, message } => SimError::Config(invalid(src, &key, message, None)),
            e => SimError::Run {
                model: src.name.clone(),
                source: e,
            },
        }
    }
}

/// A system as its parts: the config a model file reads into, the run it
/// produces, and how a config runs. [`Registered`] makes any of them a
/// [`System`]; adding a system is implementing this (and [`Outcome`] for its
/// run) and adding one `Registered` line to [`SYSTEMS`]
/// (`docs/ARCHITECTURE.md`, "Adding a system").
///
/// ```
/// use std::path::Path;
/// use rendersim_models::config::ModelSource;
/// use rendersim_report::output::trace::TraceWriter;
/// use rendersim_models::systems::{Registered, System, SystemError, SystemModel};
/// use rendersim_models::systems::frame_pipeline::config::FramePipelineConfig;
/// use rendersim_models::systems::frame_pipeline::run::{PipelineRun, run_pipeline};
///
/// /// The frame pipeline again, under another name.
/// struct Again;
///
/// impl SystemModel for Again {
///     const NAME: &'static str = "again";
///     type Config = FramePipelineConfig;
///     type Run = PipelineRun;
///     fn run(cfg: FramePipelineConfig, base: &Path, trace: Option<TraceWriter>) -> Result<PipelineRun, SystemError> {
///         run_pipeline(cfg, base, trace)
///     }
/// }
///
/// let system: &dyn System = &Registered::<Again>::new();
/// // The embedded default model, 30 frames of it.
/// let text = rendersim_models::systems::DEFAULT_MODEL.replace("frames = 300", "frames = 30");
/// let src = ModelSource::from_text("again.toml", &text);
/// let run = system.run(&src, &src.table().unwrap(), None).unwrap();
/// assert_eq!(system.name(), "again");
/// // 30 frames less the model's 20 warm-up frames, each displayed.
/// assert_eq!(run.summary()["metrics"]["displayed_frames"], 10);
/// ```
pub trait SystemModel: 'static {
    /// The name a model file gives in `system = "..."`.
    const NAME: &'static str;
    /// Whether a run writes trace events; a system that does not is refused
    /// `rendersim run --trace` before it runs (and keeps a writer handed to
    /// it through the library for the caller to close, empty).
    const WRITES_TRACE: bool = true;
    /// The model file's typed form (read with `--set` patches applied).
    type Config: serde::de::DeserializeOwned;
    /// A finished run.
    type Run: Outcome + 'static;
    /// Validates `cfg` and runs it; relative file paths in it are from
    /// `base_dir`; with a `trace` writer, the run's trace goes into it.
    fn run(cfg: Self::Config, base_dir: &Path, trace: Option<TraceWriter>) -> Result<Self::Run, SystemError>;
}

/// The one [`System`] implementation, over a [`SystemModel`]: reads the
/// model's config from its table, runs it, and blames a bad value on the
/// model file's line ([`SimError::of`]).
pub struct Registered<S>(std::marker::PhantomData<fn() -> S>);

impl<S> Registered<S> {
    /// The registry entry of system `S`.
    pub const fn new() -> Self {
        Registered(std::marker::PhantomData)
    }
}

impl<S> Default for Registered<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<S: SystemModel> System for Registered<S> {
    fn name(&self) -> &'static str {
        S::NAME
    }

    fn run(
        &self,
        src: &ModelSource,
        table: &toml::Table,
        trace: Option<TraceWriter>,
    ) -> Result<Box<dyn Outcome>, SimError> {
        let cfg: S::Config = deserialize(table, src)?;
        let run = S::run(cfg, &src.base_dir, trace).map_err(|e| SimError::of(src, e))?;
        Ok(Box::new(run))
    }

    fn read(&self, src: &ModelSource, table: &toml::Table) -> Result<(), SimError> {
        deserialize::<S::Config>(table, src)?;
        Ok(())
    }

    fn writes_trace(&self) -> bool {
        S::WRITES_TRACE
    }
}

/// One simulated system, as [`run_model`] sees it (every one is a
/// [`Registered`] [`SystemModel`]).
pub trait System: Sync {
    /// The name a model file gives in `system = "..."`.
    fn name(&self) -> &'static str;

    /// Reads the model's typed config from its table (with `--set` patches
    /// applied), validates it and runs it; with a `trace` writer, the run's
    /// trace goes into it.
    fn run(
        &self,
        src: &ModelSource,
        table: &toml::Table,
        trace: Option<TraceWriter>,
    ) -> Result<Box<dyn Outcome>, SimError>;

    /// Reads the model's typed config from its table without running it:
    /// an unknown key, a misspelt one or a value of the wrong type is the
    /// error [`System::run`] would give first.
    fn read(&self, src: &ModelSource, table: &toml::Table) -> Result<(), SimError>;

    /// Whether a run writes trace events (`rendersim run --trace`); the
    /// systems that do not are refused a trace before they run, rather than
    /// writing an empty one.
    fn writes_trace(&self) -> bool {
        true
    }
}

/// What a finished run of any system offers: its summary, its per-row
/// table, its human report, its resolved model and its trace.
pub trait Outcome: std::fmt::Debug + Send {
    /// The summary as JSON (`summary.json`; experiments read it by dotted
    /// path), made here from the run's typed summary: the run keeps the
    /// typed one, and JSON is made only where it is written.
    fn summary(&self) -> Value;

    /// Writes the human-readable report (`rendersim run` without `--json`)
    /// of the run of the model named `model`, from the typed summary.
    fn write_report(&self, model: &str, w: &mut dyn Write) -> std::io::Result<()>;

    /// The per-row table's columns and rows: per frame, per input event
    /// (latency systems) or per screen region (PixelFlow).
    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>);

    /// Writes the per-row table as CSV (`frames.csv`).
    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()>;

    /// The fully resolved model as TOML, runnable again (relative file paths
    /// in it made absolute against `base_dir`).
    fn resolved_model(&self, base_dir: &std::path::Path) -> String;

    /// The trace writer, all events written, for the caller to close.
    fn take_trace(&mut self) -> Option<TraceWriter>;

    /// The run as `Any`, to see which system's run type it is.
    fn as_any(&self) -> &dyn std::any::Any;

    /// The run as `Any`, to get the system's own run type back.
    fn into_any(self: Box<Self>) -> Box<dyn std::any::Any>;
}

/// The [`Outcome`] methods every run type implements alike, for a run struct
/// with a typed summary field (`summary` unless named) and a
/// `trace: Option<TraceWriter>` field: used inside `impl Outcome for ...` in
/// each system. The report is `super::report::write_report(&summary, model,
/// w)`, or the function named in `outcome_basics!(report = PATH)`; the JSON
/// is [`summary::to_json`] of the typed summary, or the function named in
/// `json = PATH`.
macro_rules! outcome_basics {
    () => {
        outcome_basics!(report = super::report::write_report);
    };
    (report = $report:path) => {
        outcome_basics!(
            summary = summary,
            report = $report,
            json = crate::systems::summary::to_json
        );
    };
    (summary = $field:ident, report = $report:path, json = $json:path) => {
        fn summary(&self) -> serde_json::Value {
            $json(&self.$field)
        }

        fn write_report(&self, model: &str, w: &mut dyn std::io::Write) -> std::io::Result<()> {
            $report(&self.$field, model, w)
        }

        fn take_trace(&mut self) -> Option<crate::output::trace::TraceWriter> {
            self.trace.take()
        }

        fn as_any(&self) -> &dyn std::any::Any {
            self
        }

        fn into_any(self: Box<Self>) -> Box<dyn std::any::Any> {
            self
        }
    };
}
pub(crate) use outcome_basics;

/// Every system, by the name a model file gives.
pub const SYSTEMS: &[&dyn System] = &[
    &Registered::<frame_pipeline::system::FramePipelineSystem>::new(),
    &Registered::<multi_rate::system::MultiRateSystem>::new(),
    &Registered::<vr::system::VrSystem>::new(),
    &Registered::<pixelflow::system::PixelFlowSystem>::new(),
    &Registered::<walkthrough::system::WalkthroughSystem>::new(),
    &Registered::<state_sorting::system::StateSortingSystem>::new(),
    &Registered::<present::PresentSystem>::new(),
];

/// A resolved model's TOML with the header every system writes.
pub fn resolved_toml<T: serde::Serialize>(cfg: &T) -> String {
    let body = toml::to_string(cfg).unwrap_or_else(|e| format!("# could not serialize the model: {e}\n"));
    format!("# Fully resolved model written by rendersim; run it again with `rendersim run model.toml`.\n{body}")
}

/// The result of running one model, whatever its system.
#[derive(Debug)]
pub struct SystemRun(Box<dyn Outcome>);

fn known_systems(systems: &[&dyn System]) -> String {
    systems.iter().map(|s| s.name()).collect::<Vec<_>>().join(", ")
}

/// The name of the model's system when that system writes no trace events
/// (`walkthrough`, `state_sorting`); `None` for the others and for a
/// `system` key that names none (run_model reports it).
pub fn traceless_system(table: &toml::Table) -> Option<&'static str> {
    traceless_among(SYSTEMS, table)
}

/// [`traceless_system`] among `systems` (the binary's list adds the studies
/// run as systems).
pub fn traceless_among(systems: &[&dyn System], table: &toml::Table) -> Option<&'static str> {
    let name = match table.get("system") {
        None => "frame_pipeline",
        Some(toml::Value::String(s)) => s.as_str(),
        Some(_) => return None,
    };
    systems
        .iter()
        .find(|s| s.name() == name && !s.writes_trace())
        .map(|s| s.name())
}

/// The systems whose runs write trace events, comma separated.
pub fn tracing_systems() -> String {
    tracing_among(SYSTEMS)
}

/// [`tracing_systems`] among `systems`.
pub fn tracing_among(systems: &[&dyn System]) -> String {
    systems
        .iter()
        .filter(|s| s.writes_trace())
        .map(|s| s.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Builds and runs the system a model describes (its `system` key, default
/// `frame_pipeline`). With a `trace` writer, the run's trace is written into
/// it and handed back by [`SystemRun::take_trace`], to be closed by the caller.
///
/// A 12 ms render time on a 60 Hz double-buffered display misses no
/// vertical blank: a new image every 16.667 ms, as the summary's closed form
/// says. The run's JSON summary is read without knowing the system; its
/// typed results after [`SystemRun::downcast`] to the system's run type.
///
/// ```
/// use rendersim_models::config::ModelSource;
/// use rendersim_models::systems::present::PresentRun;
/// use rendersim_models::systems::run_model;
///
/// let text = r#"
/// system = "present"
/// [run]
/// frames = 60
/// [render]
/// time = "12ms"
/// [display]
/// refresh = "60Hz"
/// buffers = 2
/// "#;
/// let src = ModelSource::from_text("example.toml", text);
/// let run = run_model(&src, &src.table().unwrap(), None).unwrap();
/// let m = &run.summary()["metrics"];
/// let interval = m["display_interval_ms"]["mean"].as_f64().unwrap();
/// assert!((interval - 1000.0 / 60.0).abs() < 1e-6);
/// assert!((m["analytic_interval_ms"].as_f64().unwrap() - interval).abs() < 1e-6);
/// let present = run.downcast::<PresentRun>().unwrap();
/// assert_eq!(present.frames.len(), 60);
///
/// // A model that names no known system is an error that says so.
/// let bad = ModelSource::from_text("bad.toml", "system = \"raytracer\"\n");
/// let err = run_model(&bad, &bad.table().unwrap(), None).unwrap_err();
/// assert!(err.to_string().contains("raytracer"), "{err}");
/// ```
pub fn run_model(src: &ModelSource, table: &toml::Table, trace: Option<TraceWriter>) -> Result<SystemRun, SimError> {
    run_among(SYSTEMS, src, table, trace)
}

/// [`run_model`] among `systems` (the binary's list adds the studies run as
/// systems, `rendersim::systems::run_model`).
pub fn run_among(
    systems: &[&dyn System],
    src: &ModelSource,
    table: &toml::Table,
    trace: Option<TraceWriter>,
) -> Result<SystemRun, SimError> {
    system_of(systems, src, table)?.run(src, table, trace).map(SystemRun)
}

/// Reads a model as [`run_model`] would, without running it: the system
/// it names, and that system's typed config from its table.
///
/// ```
/// use rendersim_models::config::ModelSource;
/// use rendersim_models::systems::read_model;
///
/// let typo = ModelSource::from_text("m.toml", "[display]\nbufers = 3\n");
/// let e = read_model(&typo, &typo.table().unwrap()).unwrap_err().to_string();
/// assert!(e.starts_with("m.toml:2: key `display.bufers`"), "{e}");
/// let ok = ModelSource::embedded_default();
/// assert_eq!(read_model(&ok, &ok.table().unwrap()).unwrap(), "frame_pipeline");
/// ```
pub fn read_model(src: &ModelSource, table: &toml::Table) -> Result<&'static str, SimError> {
    read_among(SYSTEMS, src, table)
}

/// [`read_model`] among `systems`; returns the system's name.
pub fn read_among(systems: &[&dyn System], src: &ModelSource, table: &toml::Table) -> Result<&'static str, SimError> {
    let system = system_of(systems, src, table)?;
    system.read(src, table)?;
    Ok(system.name())
}

/// The system a model's table names (`system = `; the frame pipeline
/// without one) among `systems`.
fn system_of<'a>(
    systems: &[&'a dyn System],
    src: &ModelSource,
    table: &toml::Table,
) -> Result<&'a dyn System, SimError> {
    let name = match table.get("system") {
        None => "frame_pipeline",
        Some(toml::Value::String(s)) => s.as_str(),
        Some(other) => {
            return Err(SimError::Config(invalid(
                src,
                "system",
                format!(
                    "expected a system name as a string ({}), found {}",
                    known_systems(systems),
                    other.type_str()
                ),
                None,
            )));
        }
    };
    match systems.iter().find(|s| s.name() == name) {
        Some(system) => Ok(*system),
        None => Err(SimError::Config(invalid(
            src,
            "system",
            format!("unknown system {name:?} (known: {})", known_systems(systems)),
            None,
        ))),
    }
}

impl SystemRun {
    /// The summary as JSON (made from the run's typed summary each call:
    /// the CLI adds the model's name and the provenance to it, then writes it).
    pub fn summary(&self) -> Value {
        self.0.summary()
    }

    /// Writes the human-readable report of the run of the model named
    /// `model` (what `rendersim run` prints without `--json`).
    pub fn write_report(&self, model: &str, w: &mut dyn Write) -> std::io::Result<()> {
        self.0.write_report(model, w)
    }

    /// Writes the per-row table as CSV (per frame; per input event for
    /// latency systems; PixelFlow: one row per screen region).
    pub fn write_frames_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        self.0.write_table(w)
    }

    /// The run as `Any`, to read a system's own run type without taking it
    /// (`downcast_ref::<PipelineRun>()`).
    pub fn as_any(&self) -> &dyn std::any::Any {
        self.0.as_any()
    }

    /// The per-row table (columns and rows), for experiments.
    pub fn frame_table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        self.0.table()
    }

    /// The fully resolved model as TOML (runnable again); relative mesh
    /// file paths are made absolute against `base_dir`.
    pub fn resolved_model(&self, base_dir: &std::path::Path) -> String {
        self.0.resolved_model(base_dir)
    }

    /// The run's trace writer, all events written, for the caller to close
    /// ([`TraceWriter::finish`]); `None` when no trace was asked for.
    pub fn take_trace(&mut self) -> Option<TraceWriter> {
        self.0.take_trace()
    }

    /// The system's own run type (`PipelineRun`, `MultiRateRun`, `VrRun`,
    /// `PixelFlowRun`), or the run back when it is of another system.
    pub fn downcast<T: Outcome + 'static>(self) -> Result<T, SystemRun> {
        if !self.0.as_any().is::<T>() {
            return Err(self);
        }
        match self.0.into_any().downcast::<T>() {
            Ok(r) => Ok(*r),
            Err(_) => unreachable!("checked by `is` above"),
        }
    }
}
