//! State sorting with a small buffer (paper 001, the lecture's sorting
//! buffer) as a system an experiment can sweep
//! (`experiments/state-sorting.toml`): a model file names a sequence of
//! state ids (a file, the lecture's worst case for LRU `lru-worst:M`, or a
//! frame-pipeline model's scene `scene:MODEL.toml[:attr]`), a buffer size
//! and the strategies; the run sends the sequence through the buffer once
//! per strategy (`components::sorting_buffer`) and reports the state
//! changes beside the lower bound of the offline optimum. `rendersim
//! sortbuf` is the same component on one sequence from the command line.
//!
//! - `config`: the model file;
//! - `system`: the run, its summary and table, the registry entry;
//! - `report`: the text report.

pub mod config;
pub mod report;
pub mod system;

pub use config::StateSortingConfig;
