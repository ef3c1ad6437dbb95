//! Experiments: parameter sweeps over a model, replicated with several seeds,
//! summarised with confidence intervals, checked against reference values,
//! plotted and written up.
//!
//! An experiment file (`experiments/*.toml`) names a base model, fixed
//! `[set]` overrides, `[[sweep]]`s whose cartesian product gives the points,
//! `[[metric]]`s (dotted paths into each run's JSON summary), `[[plot]]`s,
//! `[[derived]]` values and `[[check]]`s. [`load_experiment`] validates it;
//! [`run_experiment`] runs every (point, seed) pair through a [`Runner`] in
//! parallel and writes `runs.csv`, `points.csv`, the plots and `report.md`.
//!
//! The simulator is reached only through the [`Runner`] trait.
//!
//! The file format, the sweeps, samples, plots, derived values, checks,
//! claims and searches, and the outputs are documented in
//! `docs/experiments.md`; every shipped `experiments/*.toml` is an example.

mod beside_paper;
mod check;
pub mod cost;
mod derived;
mod dotted;
mod error;
mod figures;
pub mod fingerprint;
pub mod inverse;
mod report;
mod results;
mod run;
mod runner;
pub mod sample;
mod shard;
mod sim_runner;
mod slurm;
pub mod sobol;
pub mod sobol_sequence;
mod spec;
mod sweep;
mod tables;

#[cfg(test)]
mod tests;

pub use check::{Bound, CheckOutcome, evaluate_between};
pub use derived::{interval_width, largest_bin_share, modes, quantile_width_from_min, ratio, relative_error, speedup};
pub use dotted::{MetricPathError, json_number, json_path};
pub use error::ExperimentError;
pub use report::{add_provenance, lexically_normal};
pub use results::{ExperimentResult, PathStat, PointResult, RunRecord, ShardCost};
pub use run::{Progress, point_model, run_experiment};
pub use runner::{FrameTable, RunError, RunOutput, Runner};
pub use shard::{SHARD_FORMAT, SHARDS_DIR, ShardId, ShardIdError, ShardOutcome, merge_shards, run_shard};
pub use sim_runner::SimRunner;
pub use slurm::{SlurmError, SlurmOptions, SlurmScripts, sbatch, shell_quote, slurm_scripts};
pub use spec::{
    BoundRef, Check, Derived, DerivedKind, Expect, Experiment, Metric, ModelSource, PlotKind, PlotSpec, Tolerance,
    load_experiment, parse_experiment,
};
pub use sweep::{LabelsError, Point, Sweep, expand_points, numeric_coord, value_text, values_match};
