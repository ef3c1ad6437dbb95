//! Predicted against measured, per device, as a system an experiment can
//! run (issue 10 item 3, last bullet; `experiments/device-predictions.toml`):
//! a model file names measured pass CSVs and the device's vertex-cache
//! policy; the run fits a device profile to the rows
//! (`measure::calibrate`), predicts every row from the fit to the other
//! rows (leave-one-out: the shared data are few), simulates every row with
//! the full profile as `rendersim predict` does (frame pipeline, unified
//! pool, triangle fidelity; paper 000 §4.5's pipeline with the H200's
//! measured costs), and reports the errors and the device time measuring
//! took against the wall time simulating took (`measure::predictions`).
//!
//! - `config`: the model file;
//! - `system`: the run, its summary and table, the registry entry;
//! - `sum_vs_max`: study H2's ratio as the profile predicts it (`[sum_vs_max]`).

pub mod config;
pub mod sum_vs_max;
pub mod system;

pub use config::DevicePredictionsConfig;
