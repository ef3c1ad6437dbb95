//! Experiment files: the TOML format, its validation, and the validated
//! [`Experiment`] description.
//!
//! Parsing uses `deny_unknown_fields` everywhere, so a misspelt key is an
//! error naming the key and line. Validation then checks cross-references
//! (plot axes and `where` filters name sweep keys and sweep values, names are
//! unique, exactly one of `values`/`range`, ...) and reports the offending
//! entry as e.g. `sweep[1]` or `plot[0] (interval).x`.
//!
//! ```
//! use std::path::Path;
//! use rendersim::experiment::parse_experiment;
//!
//! // Display latency against frames in flight, on the fixed-work model
//! // (`model` is relative to the experiment file).
//! let text = r#"
//! name = "frames-ahead"
//! model = "../models/fixed.toml"
//! replications = 2
//!
//! [[sweep]]
//! key = "cpu.max_frames_ahead"
//! values = [1, 2, 3]
//!
//! [[metric]]
//! path = "metrics.display_latency_ms.mean"
//! label = "mean display latency (ms)"
//! "#;
//! let file = Path::new("experiments/frames-ahead.toml");
//! let e = parse_experiment(text, file).unwrap();
//! assert_eq!(e.sweeps[0].values.len(), 3);
//! assert_eq!(e.seeds().len(), 2);
//!
//! // A misspelt key is refused with its name and line.
//! let err = parse_experiment(&text.replace("replications", "replicates"), file).unwrap_err();
//! assert!(err.to_string().contains("replicates"), "{err}");
//! ```

use std::collections::BTreeSet;
use std::path::PathBuf;

use super::ExperimentError;
use super::sweep::Sweep;

mod outputs;
mod plots;
mod raw;
mod validate;

pub(crate) use raw::RawRange;
pub use validate::{load_experiment, parse_experiment};

/// Where the base model of an experiment comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelSource {
    /// The embedded default model, supplied by the caller.
    Default,
    /// A model file (resolved relative to the experiment file).
    File(PathBuf),
}

/// The sweep key that picks each point's model file instead of a model
/// value: `[[sweep]] key = "model"`, `values = ["../models/city.toml",
/// "default", ...]` (paths relative to the experiment file; `"default"` is
/// the embedded default model). The experiment's own `model` key is then
/// left out, and `[set]` and the other sweeps apply to every model alike.
pub const MODEL_SWEEP_KEY: &str = "model";

/// One reported metric: a dotted path into the run summary.
#[derive(Debug, Clone, PartialEq)]
pub struct Metric {
    /// Dotted path, e.g. `metrics.display_interval_ms.mean`.
    pub path: String,
    /// Human-readable label (defaults to the path).
    pub label: String,
}

/// What a plot shows.
#[derive(Debug, Clone, PartialEq)]
pub enum PlotKind {
    /// `x` is a sweep key; one series per combination of the other sweep
    /// keys' values (and per `y` entry); `y` are metric paths (mean with CI
    /// bars) or derived value names (no bars).
    Line {
        /// The sweep key on the x axis.
        x: String,
        /// Metric paths or derived names.
        y: Vec<String>,
        /// Logarithmic x axis.
        log_x: bool,
        /// Logarithmic y axis.
        log_y: bool,
        /// `where` filter: only the points with these sweep values are
        /// drawn (and the filtered keys are left out of the series names).
        filter: Vec<(String, toml::Value)>,
        /// `y_bounds`: the values the quantity can take; intervals are cut
        /// there (a fraction's `[0, 1]`).
        y_bounds: Option<(f64, f64)>,
        /// `y_axis`: the y axis's range, drawn whole whatever the data (an
        /// axis from 0 so a small difference looks small).
        y_axis: Option<(f64, f64)>,
        /// `paper`: published values, each at the points its `where`
        /// selects (it fixes the x key), drawn as crosses.
        paper: Vec<PaperValue>,
        /// `paper_levels`: one published value per `y` path, independent
        /// of x (empty: none), each a dashed line in its series' colour.
        levels: Vec<f64>,
    },
    /// Per-frame values of `column`, pooled over the replications of each
    /// point, one group per point (optionally only the points matching `filter`).
    Histogram {
        /// Frame column, e.g. `FrameTime`.
        column: String,
        /// Number of bins.
        bins: usize,
        /// Optional x range `(lo, hi)` of the bins (finite, `lo < hi`);
        /// values outside are counted and noted, not drawn.
        range: Option<(f64, f64)>,
        /// `where` filter: sweep key = value.
        filter: Vec<(String, toml::Value)>,
        /// Values marked with a labelled vertical line (the paper's numbers).
        marks: Vec<crate::plot::Mark>,
        /// Marks at a width above the lowest value plotted (`at` holds the
        /// width): a paper's constant measured from the minimum, such as
        /// paper 000's c.
        marks_above_min: Vec<crate::plot::Mark>,
    },
    /// Grouped bars: one group per `y` path (metric or derived name), one
    /// bar per point (those `filter` keeps) and one per `paper` entry.
    Bars {
        /// Metric paths or derived names, one group of bars each.
        y: Vec<String>,
        /// Logarithmic y axis.
        log_y: bool,
        /// `where` filter: sweep key = value.
        filter: Vec<(String, toml::Value)>,
        /// `paper`: published values, one per `y` path, with the points
        /// they belong to.
        paper: Vec<PaperValues>,
    },
    /// One labelled point per experiment point; `x` and `y` are metric
    /// paths (replication means) or derived names.
    Scatter {
        /// X metric path or derived name.
        x: String,
        /// Y metric path or derived name.
        y: String,
        /// Logarithmic x axis.
        log_x: bool,
        /// Logarithmic y axis.
        log_y: bool,
    },
}

/// A published value drawn on a line plot at the points `filter` selects.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperValue {
    /// Sweep key = value; includes the plot's x key.
    pub filter: Vec<(String, toml::Value)>,
    /// The published value.
    pub value: f64,
}

/// Published values drawn on a bar plot, one per `y` path, for the points
/// `filter` selects (named after the first of them).
#[derive(Debug, Clone, PartialEq)]
pub struct PaperValues {
    /// Sweep key = value.
    pub filter: Vec<(String, toml::Value)>,
    /// One value per `y` path.
    pub values: Vec<f64>,
}

/// A plot to write as `<file>.svg` and `<file>.png` in the output directory.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotSpec {
    /// Base file name (no directory, no extension).
    pub file: String,
    /// Title.
    pub title: String,
    /// X axis description.
    pub x_label: String,
    /// Y axis description.
    pub y_label: String,
    /// The kind and its parameters.
    pub kind: PlotKind,
    /// What a line or bar plot's `paper` values are called ("paper", or
    /// e.g. "measured on the H200").
    pub paper_label: String,
}

/// How a derived value is computed for each point.
#[derive(Debug, Clone, PartialEq)]
pub enum DerivedKind {
    /// Width of the central `level` interval of the pooled frame `column`:
    /// `quantile(1 - (1 - level) / 2) - quantile((1 - level) / 2)`.
    IntervalWidth {
        /// Frame column.
        column: String,
        /// Coverage, in `(0, 1)`.
        level: f64,
    },
    /// Spread above the minimum that covers `level` of the pooled frame
    /// `column`: `quantile(level) - min` (the paper's constant `c`).
    QuantileWidthFromMin {
        /// Frame column.
        column: String,
        /// Coverage, in `(0, 1]`.
        level: f64,
    },
    /// The modes of the pooled frame `column`'s histogram (bins of width
    /// `bin` from the smallest value): the local maxima that stand at
    /// least `prominence` times the tallest bin above the lowest bin
    /// between them and any taller bin (their topographic prominence), so
    /// that counting noise on a smooth curve is not a mode.
    Modes {
        /// Frame column.
        column: String,
        /// Bin width, in the column's unit.
        bin: f64,
        /// Least prominence, a share of the tallest bin, in `(0, 1]`.
        prominence: f64,
    },
    /// The share of the pooled frame `column`'s values in its fullest bin
    /// of width `bin` (bins from the smallest value): near 1 for a spike,
    /// small for a smooth density.
    LargestBinShare {
        /// Frame column.
        column: String,
        /// Bin width, in the column's unit.
        bin: f64,
    },
    /// `|v - v_ref| / |v_ref|` for the replication mean `v` of `path`, where
    /// `v_ref` is taken at the point that differs only in the `reference` keys.
    RelativeError {
        /// Metric path.
        path: String,
        /// Sweep key = value identifying the reference point.
        reference: Vec<(String, toml::Value)>,
    },
    /// `v / v_ref` for the replication mean `v` of `path`, the reference
    /// point chosen as for `RelativeError` (e.g. presort's primitives at
    /// 30 ms over standard's: 1.42 is a 42% gain).
    Ratio {
        /// Metric path.
        path: String,
        /// Sweep key = value identifying the reference point.
        reference: Vec<(String, toml::Value)>,
    },
    /// `wall_ref / wall` on the replication means of `path` (a wall time:
    /// `wall_seconds` unless the file gives another, e.g. `simulate_seconds`),
    /// with the reference point chosen as for `RelativeError`.
    Speedup {
        /// The wall-time path.
        path: String,
        /// Sweep key = value identifying the reference point.
        reference: Vec<(String, toml::Value)>,
    },
}

impl DerivedKind {
    /// The frame column this value is computed from, for the kinds taken
    /// on one point's frames (not between points).
    pub fn frame_column(&self) -> Option<&str> {
        match self {
            DerivedKind::IntervalWidth { column, .. }
            | DerivedKind::QuantileWidthFromMin { column, .. }
            | DerivedKind::Modes { column, .. }
            | DerivedKind::LargestBinShare { column, .. } => Some(column),
            DerivedKind::RelativeError { .. } | DerivedKind::Ratio { .. } | DerivedKind::Speedup { .. } => None,
        }
    }
}

/// A value computed per point after all runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    /// Column name in `points.csv` and the report.
    pub name: String,
    /// Text for plots (legends, axes): `label`, else the name.
    pub label: String,
    /// What to compute.
    pub kind: DerivedKind,
}

/// Allowed deviation of a checked value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// `|measured - expect| <= tol`.
    Absolute(f64),
    /// `|measured - expect| <= tol * |expect|`.
    Relative(f64),
}

/// One bound of a check: another value of the same point, or a number.
#[derive(Debug, Clone, PartialEq)]
pub enum BoundRef {
    /// A metric path or derived name (`at_least_path`, `at_most_path`).
    Path(String),
    /// A fixed number (`at_least`, `at_most`).
    Value(f64),
}

/// What a check compares its value with.
#[derive(Debug, Clone, PartialEq)]
pub enum Expect {
    /// A reference value: `|measured - value| <= tolerance`.
    Value(f64),
    /// Bounds, each another value of the same point (metric path or
    /// derived name) or a number: `measured >= at_least - tolerance` and
    /// `measured <= at_most + tolerance`, with a relative tolerance taken
    /// relative to each bound. At least one bound is given.
    Between {
        /// The lower bound.
        at_least: Option<BoundRef>,
        /// The upper bound.
        at_most: Option<BoundRef>,
    },
}

/// A reference value (or a pair of bounds) to compare against.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Metric path or derived name.
    pub path: String,
    /// Sweep key = value; every matching point is checked.
    pub filter: Vec<(String, toml::Value)>,
    /// Expected value or bounds.
    pub expect: Expect,
    /// Allowed deviation.
    pub tolerance: Tolerance,
    /// `Some(text)`: a verdict, not a test. The check is evaluated the same
    /// way, but its outcome is reported as "holds" / "does not hold" under
    /// the claim `text` in the report's Claims section and never counts as
    /// a failed check (an experiment can state that a published claim does
    /// not hold without failing).
    pub claim: Option<String>,
}

/// A validated experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// The file it was loaded from (used in messages and to resolve `model`).
    pub source: PathBuf,
    /// Short name.
    pub name: String,
    /// Paragraph shown in the report.
    pub description: String,
    /// Base model.
    pub model: ModelSource,
    /// Seeds per point.
    pub replications: u32,
    /// First seed; seeds are `base_seed .. base_seed + replications`.
    pub base_seed: u64,
    /// Confidence level of the intervals, in `(0, 1)`.
    pub confidence: f64,
    /// Fixed overrides (dotted key, value), applied before the sweeps.
    /// Nested tables in `[set]` are flattened into dotted keys.
    pub set: Vec<(String, toml::Value)>,
    /// Sweeps, in file order; the first varies slowest.
    pub sweeps: Vec<Sweep>,
    /// Reported metrics.
    pub metrics: Vec<Metric>,
    /// Plots.
    pub plots: Vec<PlotSpec>,
    /// Derived values.
    pub derived: Vec<Derived>,
    /// Reference checks.
    pub checks: Vec<Check>,
    /// Inverse what-ifs (`[[search]]`).
    pub searches: Vec<super::inverse::Search>,
    /// Points drawn from parameter ranges (`[sample]`) instead of sweeps.
    pub sample: Option<super::sample::Sample>,
}

impl Experiment {
    /// The seeds every point runs with.
    pub fn seeds(&self) -> Vec<u64> {
        (0..u64::from(self.replications))
            .map(|i| self.base_seed.wrapping_add(i))
            .collect()
    }

    /// Whether some plot or derived value needs per-frame data.
    pub fn needs_frames(&self) -> bool {
        !self.frame_columns().is_empty()
    }

    /// Frame columns needed by plots and derived values (sorted, unique).
    pub fn frame_columns(&self) -> Vec<String> {
        let mut cols = BTreeSet::new();
        for p in &self.plots {
            if let PlotKind::Histogram { column, .. } = &p.kind {
                cols.insert(column.clone());
            }
        }
        for d in &self.derived {
            if let Some(column) = d.kind.frame_column() {
                cols.insert(column.to_string());
            }
        }
        cols.into_iter().collect()
    }

    /// Every summary path the experiment reads, in a stable order: the
    /// metrics first, then paths used only by plots, derived values and
    /// checks. Derived names are not paths and are left out. `wall_seconds`
    /// appears only if referenced explicitly.
    pub fn tracked_paths(&self) -> Vec<String> {
        let derived: BTreeSet<&str> = self.derived.iter().map(|d| d.name.as_str()).collect();
        let mut out: Vec<String> = Vec::new();
        let mut add = |p: &str| {
            if !derived.contains(p) && !out.iter().any(|o| o == p) {
                out.push(p.to_string());
            }
        };
        for m in &self.metrics {
            add(&m.path);
        }
        for p in &self.plots {
            match &p.kind {
                PlotKind::Line { y, .. } | PlotKind::Bars { y, .. } => y.iter().for_each(|y| add(y)),
                PlotKind::Scatter { x, y, .. } => {
                    add(x);
                    add(y);
                }
                PlotKind::Histogram { .. } => {}
            }
        }
        for d in &self.derived {
            match &d.kind {
                DerivedKind::RelativeError { path, .. } | DerivedKind::Ratio { path, .. } => add(path),
                DerivedKind::Speedup { path, .. } => add(path),
                _ => {}
            }
        }
        for c in &self.checks {
            add(&c.path);
            if let Expect::Between { at_least, at_most } = &c.expect {
                for b in at_least.iter().chain(at_most) {
                    if let BoundRef::Path(p) = b {
                        add(p);
                    }
                }
            }
        }
        out
    }

    /// The keys every point assigns: the sweep keys, or the sampled
    /// parameters' keys.
    pub fn point_keys(&self) -> Vec<String> {
        match &self.sample {
            Some(s) => s.params.iter().map(|p| p.key.clone()).collect(),
            None => self.sweeps.iter().map(|s| s.key.clone()).collect(),
        }
    }

    /// The label of a metric path (its `[[metric]]` label, else the path).
    pub fn label_of(&self, path: &str) -> String {
        self.metrics
            .iter()
            .find(|m| m.path == path)
            .map(|m| m.label.clone())
            .or_else(|| self.derived.iter().find(|d| d.name == path).map(|d| d.label.clone()))
            .unwrap_or_else(|| path.to_string())
    }

    /// Where the model values the experiment writes come from, in the
    /// order they are applied: (dotted model key, e.g. ``[set] workload.gpu
    /// in e.toml:7`` or ``[[sweep]] of display.buffers in e.toml:12``), so
    /// that an error in such a value names the experiment file instead of
    /// the model file (see [`crate::config::ModelSource::overrides`]).
    pub fn value_origins(&self) -> Vec<(String, String)> {
        let text = crate::limits::read_input_string(&self.source, crate::limits::InputKind::Text).unwrap_or_default();
        let file = self.source.display().to_string();
        let src = crate::config::ModelSource::from_text(&file, &text);
        let at = |key: &str| match src.line_of(key) {
            Some(line) => format!("{file}:{line}"),
            None => file.clone(),
        };
        let mut origins = Vec::new();
        for (k, _) in &self.set {
            origins.push((k.clone(), format!("[set] {k} in {}", at(&format!("set.{k}")))));
        }
        for (i, s) in self.sweeps.iter().enumerate().filter(|(_, s)| s.key != MODEL_SWEEP_KEY) {
            let k = &s.key;
            origins.push((
                k.clone(),
                format!("[[sweep]] of {k} in {}", at(&format!("sweep.{i}.key"))),
            ));
        }
        for (i, p) in self.sample.iter().flat_map(|s| &s.params).enumerate() {
            let k = &p.key;
            origins.push((
                k.clone(),
                format!("[[sample.param]] of {k} in {}", at(&format!("sample.param.{i}.key"))),
            ));
        }
        origins
    }

    /// The model file a point runs on when a `[[sweep]] key = "model"`
    /// picks it (`MODEL_SWEEP_KEY`); `None` without such a sweep (every
    /// point runs on [`Experiment::model`]).
    pub fn point_source(&self, point: &super::Point) -> Option<ModelSource> {
        point
            .assignments
            .iter()
            .find(|(k, _)| k == MODEL_SWEEP_KEY)
            .and_then(|(_, v)| v.as_str())
            .map(|v| self.swept_source(v))
    }

    /// The model source a value of the model sweep names.
    fn swept_source(&self, value: &str) -> ModelSource {
        if value == "default" {
            ModelSource::Default
        } else {
            let dir = self.source.parent().unwrap_or(std::path::Path::new(""));
            ModelSource::File(dir.join(value))
        }
    }

    /// The model files of the model sweep, in sweep order (empty without
    /// one; the embedded default is not a file).
    pub fn swept_files(&self) -> Vec<PathBuf> {
        self.sweeps
            .iter()
            .filter(|s| s.key == MODEL_SWEEP_KEY)
            .flat_map(|s| &s.values)
            .filter_map(|v| match self.swept_source(v.as_str()?) {
                ModelSource::File(p) => Some(p),
                ModelSource::Default => None,
            })
            .collect()
    }

    /// The base model of a point: `base_model` (the experiment's resolved
    /// `model`), or the file the model sweep names for it.
    pub fn point_base(&self, point: &super::Point, base_model: &toml::Table) -> Result<toml::Table, ExperimentError> {
        match self.point_source(point) {
            None | Some(ModelSource::Default) => Ok(base_model.clone()),
            Some(ModelSource::File(path)) => read_model(&path),
        }
    }

    /// The base model: a clone of `default_model` for `model = "default"`,
    /// else the TOML file named by `model` (relative to the experiment file).
    pub fn resolve_model(&self, default_model: &toml::Table) -> Result<toml::Table, ExperimentError> {
        match &self.model {
            ModelSource::Default => Ok(default_model.clone()),
            ModelSource::File(path) => read_model(path),
        }
    }
}

/// A model file as a source, its read error naming the path as the
/// experiment's other file errors do.
pub(crate) fn model_source(path: &std::path::Path) -> Result<crate::config::ModelSource, ExperimentError> {
    crate::config::ModelSource::from_file(path).map_err(|e| match e {
        crate::config::ConfigError::Io { source, .. } => ExperimentError::Io {
            path: path.to_path_buf(),
            source,
        },
        e => e.into(),
    })
}

/// A model file as a TOML table, read as every model is
/// ([`crate::config::ModelSource::table`]: its hardware file merged in).
fn read_model(path: &std::path::Path) -> Result<toml::Table, ExperimentError> {
    let src = model_source(path)?;
    src.table().map_err(|e| match e {
        crate::config::ConfigError::Syntax { message, .. } => ExperimentError::Parse {
            file: path.to_path_buf(),
            message,
        },
        e => e.into(),
    })
}
