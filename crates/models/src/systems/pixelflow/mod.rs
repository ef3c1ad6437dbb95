//! PixelFlow (Olano, Cohen, Mine & Bishop, paper 002): an image-composition
//! machine of N identical nodes working on one 128 x 64 screen region at a
//! time, with three software architectures (§4 standard, §5 pre-sorting,
//! §6 non-texturing instanced frame buffer).
//!
//! - `config`: the model file;
//! - `analytic`: the closed forms of §4-6 (`analytic` fidelity, test oracle);
//! - `layout`: primitives per node and per (node, region);
//! - `model`: the event simulation per node and region;
//! - `run`: validate, run, summarize, per-region table, trace.

pub mod analytic;
pub mod config;
pub mod layout;
pub mod model;
pub mod report;
pub mod run;
pub mod system;

#[cfg(test)]
mod tests;

pub use config::{Architecture, Fidelity, PixelFlowConfig, Placement};
pub use model::PixelFlow;
pub use run::{PixelFlowRun, run_pixelflow, validate};
