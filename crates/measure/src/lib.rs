//! Real measurements through wgpu (feature `wgpu`): draw a mesh offscreen on
//! a headless Vulkan adapter (on machines without a GPU, Mesa's lavapipe)
//! with pipeline-statistics queries (vertex shader, clipper and fragment
//! shader invocations) and timestamp queries around the render pass; warm
//! up, repeat, report the median. Knobs: extra vertex and fragment shader
//! work (ALU loop counts), depth test, layers drawn in a depth order, render
//! target size, geometry only. Used by the hypothesis studies that check the
//! simulator's vertex-reuse and cost models against a device (issue 3):
//!
//! - H1 (`h1.rs`): vertex reuse, paper 000 §2 and §4.5 (actually transformed
//!   vertices);
//! - H2 (`h2.rs`): sum vs max of the geometry and fragment terms, paper 000
//!   §4.5.1 and Table 1;
//! - H3 (`h3.rs`): draw order and early-z, paper 000 §4.5.2 and Table 3;
//! - H4 (`h4.rs`): cost per transformed vertex over index orders.
//!
//! Every measured pass can be written as a row of one CSV format
//! (`passes.rs`; `measure --csv`, `study --csv`), and the loop counts the
//! studies need are searched on the device by `loops.rs`.
//!
//! The analysis of each study (fits, predictions by the simulator, errors) is
//! plain code compiled in every build and tested on synthetic measurements;
//! only the parts that talk to a device need the `wgpu` feature.
//!
//! Device profiles (issue 10): `calibrate.rs` fits a `device_profile.rs`
//! to measured passes (what they cover: `coverage.rs`), `device_predict.rs`
//! runs one pass on it through the frame-pipeline model (`predict.rs`), and
//! `predictions.rs` predicts every measured row (leave-one-out and
//! simulated) for the per-device report.
//!
//! Rendering-time estimation (issue 11 item 8, paper 000 §5): `estimation.rs`
//! plans single- and multi-object passes, fits h1-h4 and builds pos tables,
//! and scores them; `estimation_device.rs` measures the plan
//! (`rendersim study estimation`).
//!
//! What lavapipe's counters mean is noted in `docs/measurements/README.md`.
//!
//! Layer: above the models (it runs the frame pipeline to predict a pass),
//! which the code here names as `crate::{components, config, scene, systems}`;
//! the only crate that depends on wgpu.
#![warn(missing_docs)]

use rendersim_engine as engine;
use rendersim_models::{components, config, limits, scene, systems};
use rendersim_report::output;

pub mod calibrate;
pub mod coverage;
pub mod cross_validation;
pub mod device_predict;
pub mod device_profile;
pub mod estimation;
pub mod fit;
pub mod h2;
pub mod h3;
pub mod h4;
pub mod loops;
pub mod machine_load;
pub mod passes;
pub mod predict;
pub mod predictions;
pub mod report;

#[cfg(feature = "wgpu")]
mod device;
#[cfg(feature = "wgpu")]
pub mod estimation_device;
mod geometry;
#[cfg(feature = "wgpu")]
pub mod h1;
#[cfg(feature = "wgpu")]
mod measured_pass;
#[cfg(feature = "wgpu")]
pub mod profile_passes;
#[cfg(feature = "wgpu")]
pub mod studies;

#[cfg(feature = "wgpu")]
pub use device::{AdapterSummary, Gpu, MeasureError, MeasureOptions, MeasuredPasses, Measurement, measure};
pub use geometry::{DepthOrder, UnknownDepthOrder, mesh_positions};
