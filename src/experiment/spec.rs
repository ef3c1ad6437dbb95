//! Experiment files: the TOML format, its validation, and the validated
//! [`Experiment`] description.
//!
//! Parsing uses `deny_unknown_fields` everywhere, so a misspelt key is an
//! error naming the key and line. Validation then checks cross-references
//! (plot axes and `where` filters name sweep keys and sweep values, names are
//! unique, exactly one of `values`/`range`, ...) and reports the offending
//! entry as e.g. `sweep[1]` or `plot[0] (interval).x`.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::ExperimentError;
use super::sweep::{Sweep, expand_range, values_match};

/// Where the base model of an experiment comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelSource {
    /// The embedded default model, supplied by the caller.
    Default,
    /// A model file (resolved relative to the experiment file).
    File(PathBuf),
}

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
    /// `wall_ref / wall` on the replication means of `wall_seconds`, with the
    /// reference point chosen as for `RelativeError`.
    Speedup {
        /// Sweep key = value identifying the reference point.
        reference: Vec<(String, toml::Value)>,
    },
}

/// A value computed per point after all runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    /// Column name in `points.csv` and the report.
    pub name: String,
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
            match &d.kind {
                DerivedKind::IntervalWidth { column, .. } | DerivedKind::QuantileWidthFromMin { column, .. } => {
                    cols.insert(column.clone());
                }
                _ => {}
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
                PlotKind::Line { y, .. } => y.iter().for_each(|y| add(y)),
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
                DerivedKind::Speedup { .. } => add("wall_seconds"),
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

    /// The label of a metric path (its `[[metric]]` label, else the path).
    pub fn label_of(&self, path: &str) -> String {
        self.metrics
            .iter()
            .find(|m| m.path == path)
            .map(|m| m.label.clone())
            .unwrap_or_else(|| path.to_string())
    }

    /// The base model: a clone of `default_model` for `model = "default"`,
    /// else the TOML file named by `model` (relative to the experiment file).
    pub fn resolve_model(&self, default_model: &toml::Table) -> Result<toml::Table, ExperimentError> {
        match &self.model {
            ModelSource::Default => Ok(default_model.clone()),
            ModelSource::File(path) => {
                let text = std::fs::read_to_string(path).map_err(|source| ExperimentError::Io {
                    path: path.clone(),
                    source,
                })?;
                text.parse::<toml::Table>().map_err(|e| ExperimentError::Parse {
                    file: path.clone(),
                    message: e.to_string(),
                })
            }
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawExperiment {
    name: String,
    #[serde(default)]
    description: String,
    #[serde(default = "default_model")]
    model: String,
    #[serde(default = "default_replications")]
    replications: i64,
    #[serde(default = "default_seed")]
    base_seed: u64,
    #[serde(default = "default_confidence")]
    confidence: f64,
    #[serde(default)]
    set: toml::Table,
    #[serde(default)]
    sweep: Vec<RawSweep>,
    #[serde(default)]
    metric: Vec<RawMetric>,
    #[serde(default)]
    plot: Vec<RawPlot>,
    #[serde(default)]
    derived: Vec<RawDerived>,
    #[serde(default)]
    check: Vec<RawCheck>,
    #[serde(default)]
    search: Vec<super::inverse::RawSearch>,
}

fn default_model() -> String {
    "default".into()
}
fn default_replications() -> i64 {
    1
}
fn default_seed() -> u64 {
    1
}
fn default_confidence() -> f64 {
    0.95
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    key: String,
    values: Option<Vec<toml::Value>>,
    range: Option<RawRange>,
    labels: Option<Vec<String>>,
}

/// `range = { from, to, steps, format }` of a sweep.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawRange {
    pub(crate) from: toml::Value,
    pub(crate) to: toml::Value,
    pub(crate) steps: i64,
    pub(crate) format: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMetric {
    path: String,
    label: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum OneOrMany {
    One(String),
    Many(Vec<String>),
}

impl OneOrMany {
    fn into_vec(self) -> Vec<String> {
        match self {
            OneOrMany::One(s) => vec![s],
            OneOrMany::Many(v) => v,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPlot {
    file: String,
    kind: String,
    x: Option<String>,
    y: Option<OneOrMany>,
    title: Option<String>,
    x_label: Option<String>,
    y_label: Option<String>,
    column: Option<String>,
    bins: Option<i64>,
    range: Option<Vec<f64>>,
    #[serde(default)]
    log_x: bool,
    #[serde(default)]
    log_y: bool,
    #[serde(rename = "where")]
    filter: Option<toml::Table>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDerived {
    name: String,
    kind: String,
    column: Option<String>,
    level: Option<f64>,
    path: Option<String>,
    reference: Option<toml::Table>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCheck {
    path: String,
    #[serde(rename = "where", default)]
    filter: toml::Table,
    expect: Option<f64>,
    at_least_path: Option<String>,
    at_most_path: Option<String>,
    at_least: Option<f64>,
    at_most: Option<f64>,
    tolerance: Option<f64>,
    rel_tolerance: Option<f64>,
    claim: Option<String>,
}

/// Read and validate the experiment file at `path`.
pub fn load_experiment(path: &Path) -> Result<Experiment, ExperimentError> {
    let text = std::fs::read_to_string(path).map_err(|source| ExperimentError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_experiment(&text, path)
}

/// Parse and validate experiment TOML `text`; `source` names the file in
/// messages and anchors a relative `model` path.
pub fn parse_experiment(text: &str, source: &Path) -> Result<Experiment, ExperimentError> {
    let raw: RawExperiment = toml::from_str(text).map_err(|e| ExperimentError::Parse {
        file: source.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })?;
    Validator { file: source }.experiment(raw)
}

struct Validator<'a> {
    file: &'a Path,
}

impl Validator<'_> {
    fn err(&self, key: impl Into<String>, message: impl Into<String>) -> ExperimentError {
        ExperimentError::Invalid {
            file: self.file.to_path_buf(),
            key: key.into(),
            message: message.into(),
        }
    }

    fn experiment(&self, raw: RawExperiment) -> Result<Experiment, ExperimentError> {
        if raw.name.trim().is_empty() {
            return Err(self.err("name", "must not be empty"));
        }
        if raw.replications < 1 || raw.replications > i64::from(u32::MAX) {
            return Err(self.err("replications", format!("must be at least 1, got {}", raw.replications)));
        }
        if !(raw.confidence > 0.0 && raw.confidence < 1.0) {
            return Err(self.err("confidence", format!("must be in (0, 1), got {}", raw.confidence)));
        }
        let model = if raw.model == "default" {
            ModelSource::Default
        } else if raw.model.trim().is_empty() {
            return Err(self.err("model", "must be \"default\" or a file path"));
        } else {
            let dir = self.file.parent().unwrap_or(Path::new(""));
            ModelSource::File(dir.join(&raw.model))
        };
        let mut set = Vec::new();
        flatten("", &raw.set, &mut set);

        let mut sweeps: Vec<Sweep> = Vec::new();
        for (i, s) in raw.sweep.into_iter().enumerate() {
            let key = format!("sweep[{i}]");
            if s.key.split('.').any(|p| p.trim().is_empty()) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is not a dotted key", s.key)));
            }
            if sweeps.iter().any(|o| o.key == s.key) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is swept twice", s.key)));
            }
            let sweep = match (s.values, s.range) {
                (Some(_), Some(_)) => {
                    return Err(self.err(key, "give either `values` or `range`, not both"));
                }
                (None, None) => return Err(self.err(key, "needs `values` or `range`")),
                (Some(values), None) => {
                    if values.is_empty() {
                        return Err(self.err(format!("{key}.values"), "must not be empty"));
                    }
                    Sweep::from_values(s.key, values)
                }
                (None, Some(r)) => expand_range(s.key, &r).map_err(|m| self.err(format!("{key}.range"), m))?,
            };
            let sweep = match s.labels {
                Some(l) => sweep.with_labels(l).map_err(|m| self.err(format!("{key}.labels"), m))?,
                None => sweep,
            };
            sweeps.push(sweep);
        }
        let find_sweep = |k: &str| sweeps.iter().find(|s| s.key == k);
        let filter = |key: &str, t: &toml::Table| -> Result<Vec<(String, toml::Value)>, ExperimentError> {
            let mut flat = Vec::new();
            flatten("", t, &mut flat);
            for (k, v) in &flat {
                let Some(s) = find_sweep(k) else {
                    return Err(self.err(key, format!("`{k}` is not a sweep key")));
                };
                if !s.values.iter().any(|sv| values_match(sv, v)) {
                    return Err(self.err(key, format!("`{k}` = {v} is not one of the swept values")));
                }
            }
            Ok(flat)
        };

        let mut metrics: Vec<Metric> = Vec::new();
        for (i, m) in raw.metric.into_iter().enumerate() {
            if m.path.trim().is_empty() {
                return Err(self.err(format!("metric[{i}].path"), "must not be empty"));
            }
            if metrics.iter().any(|o| o.path == m.path) {
                return Err(self.err(format!("metric[{i}].path"), format!("`{}` is listed twice", m.path)));
            }
            metrics.push(Metric {
                label: m.label.unwrap_or_else(|| m.path.clone()),
                path: m.path,
            });
        }

        let mut derived: Vec<Derived> = Vec::new();
        for (i, d) in raw.derived.into_iter().enumerate() {
            let key = format!("derived[{i}] ({})", d.name);
            if d.name.trim().is_empty() {
                return Err(self.err(format!("derived[{i}].name"), "must not be empty"));
            }
            if derived.iter().any(|o| o.name == d.name) || metrics.iter().any(|m| m.path == d.name) {
                return Err(self.err(&key, format!("name `{}` is already used", d.name)));
            }
            let need_column = || {
                d.column
                    .clone()
                    .ok_or_else(|| self.err(&key, format!("kind `{}` needs `column`", d.kind)))
            };
            let need_ref = || -> Result<Vec<(String, toml::Value)>, ExperimentError> {
                let r = d
                    .reference
                    .as_ref()
                    .ok_or_else(|| self.err(&key, format!("kind `{}` needs `reference`", d.kind)))?;
                let r = filter(&format!("{key}.reference"), r)?;
                if r.is_empty() {
                    return Err(self.err(format!("{key}.reference"), "must name at least one sweep key"));
                }
                Ok(r)
            };
            let kind = match d.kind.as_str() {
                "interval_width" => {
                    let level = d.level.ok_or_else(|| self.err(&key, "needs `level`"))?;
                    if !(level > 0.0 && level < 1.0) {
                        return Err(self.err(format!("{key}.level"), "must be in (0, 1)"));
                    }
                    DerivedKind::IntervalWidth {
                        column: need_column()?,
                        level,
                    }
                }
                "quantile_width_from_min" => {
                    let level = d.level.ok_or_else(|| self.err(&key, "needs `level`"))?;
                    if !(level > 0.0 && level <= 1.0) {
                        return Err(self.err(format!("{key}.level"), "must be in (0, 1]"));
                    }
                    DerivedKind::QuantileWidthFromMin {
                        column: need_column()?,
                        level,
                    }
                }
                "relative_error" => DerivedKind::RelativeError {
                    path: d
                        .path
                        .clone()
                        .ok_or_else(|| self.err(&key, "kind `relative_error` needs `path`"))?,
                    reference: need_ref()?,
                },
                "ratio" => DerivedKind::Ratio {
                    path: d
                        .path
                        .clone()
                        .ok_or_else(|| self.err(&key, "kind `ratio` needs `path`"))?,
                    reference: need_ref()?,
                },
                "speedup" => DerivedKind::Speedup { reference: need_ref()? },
                other => {
                    return Err(self.err(
                        format!("{key}.kind"),
                        format!(
                            "unknown kind `{other}` (expected interval_width, quantile_width_from_min, relative_error, ratio or speedup)"
                        ),
                    ));
                }
            };
            derived.push(Derived { name: d.name, kind });
        }

        let mut plots: Vec<PlotSpec> = Vec::new();
        for (i, p) in raw.plot.into_iter().enumerate() {
            let key = format!("plot[{i}] ({})", p.file);
            if p.file.is_empty() || p.file.contains(['/', '\\']) || p.file == "." || p.file == ".." {
                return Err(self.err(
                    format!("{key}.file"),
                    "must be a plain file name without directory or extension",
                ));
            }
            if plots.iter().any(|o| o.file == p.file) {
                return Err(self.err(format!("{key}.file"), "is used by two plots"));
            }
            let kind = match p.kind.as_str() {
                "line" => {
                    let x =
                        p.x.clone()
                            .ok_or_else(|| self.err(&key, "kind `line` needs `x` (a sweep key)"))?;
                    if find_sweep(&x).is_none() {
                        return Err(self.err(format!("{key}.x"), format!("`{x}` is not a sweep key")));
                    }
                    let y = p.y.map(OneOrMany::into_vec).unwrap_or_default();
                    if y.is_empty() || y.iter().any(|s| s.trim().is_empty()) {
                        return Err(self.err(format!("{key}.y"), "needs one or more metric paths"));
                    }
                    let f = match &p.filter {
                        Some(t) => filter(&format!("{key}.where"), t)?,
                        None => Vec::new(),
                    };
                    if f.iter().any(|(k, _)| *k == x) {
                        return Err(self.err(format!("{key}.where"), format!("must not fix the x axis key `{x}`")));
                    }
                    PlotKind::Line {
                        x,
                        y,
                        log_x: p.log_x,
                        log_y: p.log_y,
                        filter: f,
                    }
                }
                "histogram" => {
                    let column = p
                        .column
                        .clone()
                        .ok_or_else(|| self.err(&key, "kind `histogram` needs `column`"))?;
                    let bins = p.bins.unwrap_or(50);
                    if !(1..=100_000).contains(&bins) {
                        return Err(self.err(format!("{key}.bins"), "must be between 1 and 100000"));
                    }
                    let f = match &p.filter {
                        Some(t) => filter(&format!("{key}.where"), t)?,
                        None => Vec::new(),
                    };
                    let range = match &p.range {
                        None => None,
                        Some(r) => match r[..] {
                            [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi => Some((lo, hi)),
                            [lo, hi] if lo.is_finite() && hi.is_finite() => {
                                return Err(
                                    self.err(format!("{key}.range"), format!("needs lo < hi, got [{lo}, {hi}]"))
                                );
                            }
                            [_, _] => {
                                return Err(self.err(format!("{key}.range"), "bounds must be finite numbers"));
                            }
                            _ => {
                                return Err(self.err(
                                    format!("{key}.range"),
                                    format!("must be [lo, hi] (two numbers), got {} value(s)", r.len()),
                                ));
                            }
                        },
                    };
                    PlotKind::Histogram {
                        column,
                        bins: bins as usize,
                        range,
                        filter: f,
                    }
                }
                "scatter" => {
                    let x =
                        p.x.clone()
                            .ok_or_else(|| self.err(&key, "kind `scatter` needs `x` (a metric path)"))?;
                    let y = match p.y.map(OneOrMany::into_vec) {
                        Some(v) if v.len() == 1 => v.into_iter().next().unwrap_or_default(),
                        _ => {
                            return Err(
                                self.err(format!("{key}.y"), "kind `scatter` needs exactly one `y` metric path")
                            );
                        }
                    };
                    PlotKind::Scatter {
                        x,
                        y,
                        log_x: p.log_x,
                        log_y: p.log_y,
                    }
                }
                other => {
                    return Err(self.err(
                        format!("{key}.kind"),
                        format!("unknown kind `{other}` (expected line, histogram or scatter)"),
                    ));
                }
            };
            if p.range.is_some() && !matches!(kind, PlotKind::Histogram { .. }) {
                return Err(self.err(format!("{key}.range"), "only histogram plots take `range`"));
            }
            if p.filter.is_some() && matches!(kind, PlotKind::Scatter { .. }) {
                return Err(self.err(format!("{key}.where"), "only histogram and line plots take `where`"));
            }
            let (dx, dy) = match &kind {
                PlotKind::Line { x, y, .. } => (x.clone(), y.first().cloned().unwrap_or_default()),
                PlotKind::Histogram { column, .. } => (column.clone(), "density".into()),
                PlotKind::Scatter { x, y, .. } => (x.clone(), y.clone()),
            };
            let label = |p: &str| {
                metrics
                    .iter()
                    .find(|m| m.path == p)
                    .map(|m| m.label.clone())
                    .unwrap_or_else(|| p.to_string())
            };
            plots.push(PlotSpec {
                title: p.title.unwrap_or_else(|| raw.name.clone()),
                x_label: p.x_label.unwrap_or_else(|| label(&dx)),
                y_label: p.y_label.unwrap_or_else(|| label(&dy)),
                file: p.file,
                kind,
            });
        }

        let mut checks = Vec::new();
        for (i, c) in raw.check.into_iter().enumerate() {
            let key = format!("check[{i}] ({})", c.path);
            if c.path.trim().is_empty() {
                return Err(self.err(format!("check[{i}].path"), "must not be empty"));
            }
            let tolerance = match (c.tolerance, c.rel_tolerance) {
                (Some(t), None) => Tolerance::Absolute(t),
                (None, Some(t)) => Tolerance::Relative(t),
                _ => {
                    return Err(self.err(&key, "give exactly one of `tolerance` and `rel_tolerance`"));
                }
            };
            let (Tolerance::Absolute(t) | Tolerance::Relative(t)) = tolerance;
            if !(t >= 0.0 && t.is_finite()) {
                return Err(self.err(&key, "tolerance must be a finite number >= 0"));
            }
            let bound = |b: Option<String>, name: &str| match b {
                Some(b) if b.trim().is_empty() => Err(self.err(format!("{key}.{name}"), "must not be empty")),
                other => Ok(other),
            };
            let number = |v: Option<f64>, name: &str| match v {
                Some(v) if !v.is_finite() => Err(self.err(format!("{key}.{name}"), "must be finite")),
                other => Ok(other.map(BoundRef::Value)),
            };
            let either = |p: Option<String>, v: Option<BoundRef>, name: &str| match (p, v) {
                (Some(_), Some(_)) => Err(self.err(&key, format!("give either `{name}_path` or `{name}`, not both"))),
                (Some(p), None) => Ok(Some(BoundRef::Path(p))),
                (None, v) => Ok(v),
            };
            let at_least = either(
                bound(c.at_least_path, "at_least_path")?,
                number(c.at_least, "at_least")?,
                "at_least",
            )?;
            let at_most = either(
                bound(c.at_most_path, "at_most_path")?,
                number(c.at_most, "at_most")?,
                "at_most",
            )?;
            if let (Some(BoundRef::Value(lo)), Some(BoundRef::Value(hi))) = (&at_least, &at_most)
                && lo > hi
            {
                return Err(self.err(&key, format!("`at_least` = {lo} is above `at_most` = {hi}")));
            }
            if let Some(text) = &c.claim
                && text.trim().is_empty()
            {
                return Err(self.err(format!("{key}.claim"), "must not be empty"));
            }
            let expect = match (c.expect, at_least.is_some() || at_most.is_some()) {
                (Some(_), true) => {
                    return Err(self.err(
                        &key,
                        "give either `expect` or bounds (`at_least[_path]`/`at_most[_path]`), not both",
                    ));
                }
                (None, false) => {
                    return Err(self.err(
                        &key,
                        "needs `expect` or `at_least_path`/`at_most_path` (or `at_least`/`at_most`)",
                    ));
                }
                (Some(v), false) => {
                    if !v.is_finite() {
                        return Err(self.err(format!("{key}.expect"), "must be finite"));
                    }
                    Expect::Value(v)
                }
                (None, true) => Expect::Between { at_least, at_most },
            };
            checks.push(Check {
                filter: filter(&format!("{key}.where"), &c.filter)?,
                path: c.path,
                expect,
                tolerance,
                claim: c.claim,
            });
        }

        let mut searches = Vec::new();
        for (i, r) in raw.search.into_iter().enumerate() {
            let flat = |t: &toml::Table| {
                let mut v = Vec::new();
                flatten("", t, &mut v);
                v
            };
            let sp = super::inverse::validate(r, flat).map_err(|(k, m)| self.err(format!("search[{i}].{k}"), m))?;
            if searches.iter().any(|o: &super::inverse::Search| o.name == sp.name) {
                return Err(self.err(format!("search[{i}].name"), format!("`{}` is used twice", sp.name)));
            }
            searches.push(sp);
        }

        Ok(Experiment {
            source: self.file.to_path_buf(),
            name: raw.name,
            description: raw.description,
            model,
            replications: raw.replications as u32,
            base_seed: raw.base_seed,
            confidence: raw.confidence,
            set,
            sweeps,
            metrics,
            plots,
            derived,
            checks,
            searches,
        })
    }
}

/// Flatten nested tables into `(dotted key, value)` pairs, in table order.
fn flatten(prefix: &str, t: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
    for (k, v) in t {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(inner) => flatten(&key, inner, out),
            other => out.push((key, other.clone())),
        }
    }
}
