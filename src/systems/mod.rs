//! Simulated systems, each composed from components and driven by the engine.
pub mod frame_pipeline;
