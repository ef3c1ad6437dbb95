//! The VR pipeline of Zachmann's lecture (paper 001): tracker ->
//! simulation -> renderer -> swap lock -> field-sequential stereo display
//! at 120 Hz, as the naive single loop and as the decoupled scheme with a
//! warping renderer (application frames at 20 Hz re-projected at 60 Hz with
//! the newest camera pose and object transforms). Reports motion-to-photon
//! latency of head and of object motion.
//!
//! - `config`: the model file; `analytic`: closed forms;
//! - `model`: the kernel model; `latency`: per-motion latencies and their
//!   stages, followed as frames swap; `run`: validate, run, summary, CSV.

pub mod analytic;
pub mod config;
pub mod latency;
pub mod model;
pub mod report;
pub mod run;
pub mod system;

pub use config::VrConfig;
pub use model::Vr;
pub use run::{VrRun, run_vr, validate};
