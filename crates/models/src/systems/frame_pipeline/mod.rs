//! The single-GPU frame pipeline (paper 000 §3-4, Figure 4; paper 004 §4):
//! CPU thread -> command FIFO -> GPU front end -> geometry -> triangle FIFO
//! -> fragment -> swap chain -> display, with system-task noise.
//!
//! - `config`: the model file;
//! - `workload`: compiling scenes into draws and meshes;
//! - `model`: the kernel model (the units, event dispatch, the step in
//!   the order of the data flow);
//! - `cpu_thread`, `front_end`, `geometry_stage`, `fragment_stage`,
//!   `display`: the units, each owning its state and transitions;
//! - `events`: the event enum the units schedule;
//! - `links`: what the units share (the command and triangle FIFOs, the
//!   shader pool, the swap chain), passed to their methods;
//! - `closed_form`: the `draw`-fidelity formula;
//! - `quiet`: front-end completions kept out of the event queue at `draw`
//!   fidelity (they only start a hand-off);
//! - `accounting`: state clocks, trace timeline, each unit's mode;
//! - `critical_path`: bottleneck attribution along the critical path;
//! - `records`: per-frame records and the PresentMon-style table;
//! - `report`: the human-readable report of a run;
//! - `plan`: the one fallible step, from a parsed model to what runs;
//! - `unit_specs`: what each unit reads of the model, taken out once;
//! - `run`: run a plan;
//! - `validate`: what a model is refused for before it runs;
//! - `summary`: the run's summary (`summary.json`).
//!
//! Outside it, the frame pipeline is its model file ([`config`]), the plan
//! ([`PipelinePlan`]), the run ([`run_pipeline`], [`PipelineRun`]) and the
//! typed results ([`PipelineSummary`], [`records`]); the units, links,
//! accounting and checks are private to it.
//!
//! Studies that run this system whole (isolation, Table 1, the Figure 4
//! timeline) live above it, in the `rendersim` crate's `studies`.

mod accounting;
mod analytic;
mod bus_copy;
mod checked;
mod closed_form;
pub mod config;
mod cpu_thread;
mod critical_path;
mod display;
mod events;
mod fragment_stage;
mod front_end;
mod geometry_cost;
mod geometry_stage;
mod links;
mod model;
mod pipeline_trace;
mod plan;
mod quiet;
pub mod records;
mod report;
pub mod run;
mod summary;
pub mod system;
mod unit_specs;
mod unit_states;
mod validate;
pub mod workload;

pub use checked::CheckedPipeline;
pub use config::{Fidelity, FramePipelineConfig};
pub use model::FramePipeline;
pub use plan::PipelinePlan;
pub use run::{PipelineRun, run_pipeline};
pub use summary::PipelineSummary;
