//! rendersim's models: what a model file says and what it simulates.
//!
//! - [`capture`]: frame captures read back (PresentMon CSV);
//! - [`config`]: model files, units, `--set` patches, the one loader;
//! - [`components`]: reusable parts (bounded FIFOs, vertex caches, swap
//!   chains, system-task noise, distributions, state-time accounting);
//! - [`scene`]: workloads: meshes, generators, OBJ files, synthetic scenes;
//! - [`systems`]: simulated systems, each composed from components and
//!   driven by the engine; [`systems::run_model`] runs any of them;
//! - [`limits`]: the stated limits on sizes read from input.
//!
//! Layer: above `rendersim-engine` (time, queue, run loop) and
//! `rendersim-report` (tables, traces, plots), which the code here names as
//! `crate::engine` and `crate::{output, plot, stats}`; below the
//! measurements and the studies (docs/ARCHITECTURE.md).
#![warn(missing_docs)]

use rendersim_engine as engine;
use rendersim_report::{output, plot, stats};

pub mod capture;
pub mod components;
pub mod config;
pub mod limits;
pub mod scene;
pub mod systems;
