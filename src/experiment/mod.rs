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
//! # File format
//!
//! ```toml
//! name = "vsync-quantization"
//! description = "one paragraph shown in the report"
//! model = "default"      # or a model file relative to this file
//! replications = 5       # seeds per point (default 1)
//! base_seed = 1          # seeds base_seed .. base_seed + replications - 1 (default 1)
//! confidence = 0.95      # Student's t intervals (default 0.95)
//! [set]                  # fixed overrides; nested tables flatten to dotted keys
//! "workload.kind" = "fixed"
//! [[sweep]]              # cartesian product in file order, first varies slowest
//! key = "workload.gpu"
//! range = { from = 10, to = 40, steps = 31, format = "{}ms" }   # or values = [...]
//! [[sweep]]
//! key = "display.buffers"
//! values = [2, 3]
//! labels = ["double", "triple"]   # optional: axis text per value (categorical x axis);
//!                                 # values that are not numbers (arrays, tables) are
//!                                 # categorical anyway, labelled with their text
//! [[metric]]
//! path = "metrics.display_interval_ms.mean"
//! label = "display interval (ms)"
//! [[plot]]               # kind = "line" | "histogram" | "scatter"
//! file = "interval"      # interval.svg + interval.png
//! kind = "line"
//! x = "workload.gpu"     # a sweep key; one series per value of the other keys
//! y = ["metrics.display_interval_ms.mean"]   # metric paths or derived names
//! # line: optional where = { key = value } draws only the matching points
//! # histogram: column = "FrameTime", bins = 80, optional where = { key = value },
//! #   optional range = [lo, hi] (finite, lo < hi): the bins span [lo, hi] instead of
//! #   the data; values outside are not drawn but counted, per group, in a note on the
//! #   plot and a line under it in report.md; densities stay relative to all values
//! #   optional marks = [{ at = 337.0, label = "paper: best 337 ms" }]: values drawn as
//! #   labelled dashed lines (a paper's numbers; at most 16; the x axis widens to show them)
//! # scatter: x and y are metric paths or derived names; log_x / log_y
//! [[derived]]            # interval_width | quantile_width_from_min | relative_error | ratio | speedup
//!                        # (speedup: reference / this of `path`, default "wall_seconds")
//! name = "c99"
//! kind = "interval_width"
//! column = "FrameTime"
//! level = 0.99
//! [[check]]
//! path = "metrics.display_interval_ms.mean"   # or a derived name
//! where = { "workload.gpu" = "17ms", "display.buffers" = 2 }
//! expect = 33.333
//! tolerance = 0.05       # absolute; or rel_tolerance = 0.01
//! [[check]]              # or bounds from other values of the same point
//! path = "metrics.gpu_time_ms.mean"
//! at_least_path = "metrics.analytic.gpu_max_ms"   # either or both
//! at_most_path = "metrics.analytic.gpu_sum_ms"
//! rel_tolerance = 0.01   # relative to each bound (or tolerance = absolute)
//! [[check]]              # or fixed bounds: at_least = 600000, at_most = ...
//! path = "metrics.analytic_primitives_at_30ms"
//! at_least = 600000
//! tolerance = 0
//! claim = "(a) over 600,000 triangles at 30 ms"   # a verdict, not a test (below)
//! [[search]]             # inverse what-if: which value of one key reaches a target
//! name = "first-pass"
//! vary = "deferred.t_first_pass"
//! from = 0.1             # bracket, bisection inside it
//! to = 5.0
//! format = "{}us"        # optional
//! path = "metrics.analytic_primitives_at_30ms"
//! target = 186572        # or target_from = { path = "...", set = { ... }, scale = 1.125 }
//! set = { architecture = "presort" }   # overrides for this search only
//! ```
//!
//! A sweep over `key = "model"` runs each point on another model file:
//! `values = ["../models/city.toml", "default"]` (paths relative to the
//! experiment file, `"default"` the embedded default model; `labels` name
//! them on plots). The top-level `model` is then left out, `[set]` and the
//! other sweeps apply to every model, and `[[search]]`es are refused (they
//! need one base model). Relative paths inside each model resolve against
//! its own folder.
//!
//! Searches are described in [`inverse`]; their results go to
//! `searches.csv` and a section of `report.md`.
//!
//! Instead of sweeps, points can be drawn from parameter ranges
//! ([`sample`]; sweeps and a sample do not mix):
//!
//! ```toml
//! [sample]
//! method = "sobol"       # or "latin_hypercube" (n points)
//! n = 256                # sobol: Saltelli's n (k + 2) points for k parameters
//! seed = 1               # default 1; the same seed gives the same points
//! bootstrap = 1000       # resamples for the indices' intervals (default 1000)
//! [[sample.param]]
//! key = "workload.gpu"
//! from = 4
//! to = 20
//! unit = "ms"            # optional: values are strings "12.5ms"
//! scale = "linear"       # or "log" (from > 0)
//! integer = false        # true: every whole number of from..=to equally likely
//! ```
//!
//! With `sobol`, every `[[metric]]` gets first-order and total Sobol'
//! indices ([`sobol`]) in `sensitivity.csv`, a table in `report.md` and a
//! bar plot `sensitivity-<metric number>.svg`/`.png`. Line plots and `where`
//! filters need sweeps; scatter plots and histograms work on samples.
//!
//! The runs can be split into shards (`--shard K/N`) run by separate
//! processes, e.g. the tasks of a Slurm job array (`--slurm`), and merged
//! (`--merge`) into the files one process writes (see `shard.rs` and
//! `slurm.rs`).
//!
//! A check with `claim = "text"` is a **verdict**: it is evaluated like any
//! check, but `report.md` lists it under "Claims" as holds / does not hold
//! (per claim: HOLDS, DOES NOT HOLD or HOLDS IN PART), with the measured
//! value, the expected value or bounds and the error, and it never counts
//! as a failed check. Checks without `claim` are tests: a failure fails the
//! experiment (exit status 1 from the CLI, after every output is written;
//! an error, such as an invalid file or a failed run, exits 2). Every
//! check's report row gives
//! its error: measured minus expected (or the distance beyond a bound),
//! absolute and relative.
//!
//! Outputs in the output directory: `runs.csv` (one row per point and seed),
//! `points.csv` (per point: `<path>:mean`, `:ci_low`, `:ci_high`, `:n` for
//! every tracked path, then derived values), `<file>.svg`/`.png` per plot,
//! and `report.md`. On stdout `rendersim experiment` prints one line per
//! point with the metrics, then the derived values per point (the numbers
//! an experiment is usually run for, e.g. `c99_from_min` of `system-noise`),
//! the check tally and the wall time.

mod check;
pub mod cost;
mod derived;
mod dotted;
mod error;
mod figures;
pub mod fingerprint;
pub mod inverse;
mod report;
mod run;
mod runner;
pub mod sample;
mod shard;
mod sim_runner;
mod slurm;
pub mod sobol;
mod spec;
mod sweep;
mod tables;

#[cfg(test)]
mod tests;

pub use check::{Bound, CheckOutcome, evaluate_between};
pub use derived::{interval_width, quantile_width_from_min, ratio, relative_error, speedup};
pub use dotted::{MetricPathError, json_number, json_path};
pub use error::ExperimentError;
pub use run::{ExperimentResult, PathStat, PointResult, RunRecord, ShardCost, point_model, run_experiment};
pub use runner::{FrameTable, RunError, RunOutput, Runner};
pub use shard::{SHARD_FORMAT, SHARDS_DIR, ShardId, ShardIdError, ShardOutcome, merge_shards, run_shard};
pub use sim_runner::SimRunner;
pub use slurm::{SlurmError, SlurmOptions, SlurmScripts, sbatch, slurm_scripts};
pub use spec::{
    BoundRef, Check, Derived, DerivedKind, Expect, Experiment, Metric, ModelSource, PlotKind, PlotSpec, Tolerance,
    load_experiment, parse_experiment,
};
pub use sweep::{LabelsError, Point, Sweep, expand_points, numeric_coord, value_text, values_match};
