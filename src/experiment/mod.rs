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

mod check;
mod derived;
mod dotted;
mod error;
mod figures;
mod report;
mod run;
mod runner;
mod spec;
mod sweep;
mod tables;

#[cfg(test)]
mod tests;

pub use check::CheckOutcome;
pub use derived::{interval_width, quantile_width_from_min, relative_error, speedup};
pub use dotted::{json_number, json_path, set_dotted};
pub use error::ExperimentError;
pub use run::{ExperimentResult, PathStat, PointResult, RunRecord, point_model, run_experiment};
pub use runner::{FrameTable, RunOutput, Runner};
pub use spec::{
    Check, Derived, DerivedKind, Experiment, Metric, ModelSource, PlotKind, PlotSpec, Tolerance,
    load_experiment, parse_experiment,
};
pub use sweep::{Point, Sweep, expand_points, numeric_coord, value_text, values_match};
