//! Real measurements through wgpu (feature `wgpu`): draw a mesh offscreen on
//! a headless Vulkan adapter (on machines without a GPU, Mesa's lavapipe)
//! with pipeline-statistics queries (vertex shader, clipper and fragment
//! shader invocations) and timestamp queries around the render pass; warm
//! up, repeat, report the median. Knobs: extra vertex and fragment shader
//! work (ALU loop counts), depth test, layers drawn in a depth order, render
//! target size. Used by the hypothesis studies that check the simulator's
//! vertex-reuse and cost models against a device (issue 3).
//!
//! What lavapipe's counters mean is noted in `docs/measurements/README.md`.

mod device;
mod geometry;
pub mod h1;

pub use device::{AdapterSummary, MeasureError, MeasureOptions, Measurement, measure};
pub use geometry::{DepthOrder, mesh_positions};
