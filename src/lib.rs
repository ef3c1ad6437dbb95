//! rendersim: a discrete-event simulator of GPU rendering pipelines and latency.
//!
//! Layers, from the bottom up (see `docs/ARCHITECTURE.md`):
//! - [`engine`]: integer-picosecond time, the event queue, the run loop, RNG
//!   streams. Knows nothing of GPUs.
//! - [`components`]: reusable parts (bounded FIFOs, vertex caches, swap chains,
//!   system-task noise, distributions, state-time accounting).
//! - [`scene`]: workloads: meshes, generators, OBJ files, synthetic scenes.
//! - [`systems`]: simulated systems, each composed from components.
//! - [`config`]: model files, units, `--set` patches, validation.
//! - [`stats`], [`output`], [`plot`], [`experiment`]: results and studies.
//! - [`limits`]: the stated limits on sizes read from input.
#![warn(missing_docs)]

pub mod bench;
pub mod components;
pub mod config;
pub mod engine;
pub mod experiment;
pub mod limits;
pub mod measure;
pub mod output;
pub mod plot;
pub mod scene;
pub mod stats;
pub mod systems;
