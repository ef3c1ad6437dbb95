//! The experiment file as parsed, before validation (serde structs with
//! `deny_unknown_fields`).

use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawExperiment {
    pub(super) name: String,
    #[serde(default)]
    pub(super) description: String,
    #[serde(default = "default_model")]
    pub(super) model: String,
    #[serde(default = "default_replications")]
    pub(super) replications: i64,
    #[serde(default = "default_seed")]
    pub(super) base_seed: u64,
    #[serde(default = "default_confidence")]
    pub(super) confidence: f64,
    #[serde(default)]
    pub(super) set: toml::Table,
    #[serde(default)]
    pub(super) sweep: Vec<RawSweep>,
    #[serde(default)]
    pub(super) metric: Vec<RawMetric>,
    #[serde(default)]
    pub(super) plot: Vec<RawPlot>,
    #[serde(default)]
    pub(super) derived: Vec<RawDerived>,
    #[serde(default)]
    pub(super) check: Vec<RawCheck>,
    #[serde(default)]
    pub(super) search: Vec<crate::experiment::inverse::RawSearch>,
    pub(super) sample: Option<RawSample>,
}

/// `[sample]`: points drawn from parameter ranges.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSample {
    pub(super) method: String,
    pub(super) n: i64,
    #[serde(default = "default_seed")]
    pub(super) seed: u64,
    pub(super) bootstrap: Option<i64>,
    pub(super) scramble: Option<bool>,
    #[serde(default)]
    pub(super) param: Vec<RawParam>,
}

/// `[[sample.param]]`: one sampled key and its range.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawParam {
    pub(super) key: String,
    pub(super) from: f64,
    pub(super) to: f64,
    pub(super) scale: Option<String>,
    #[serde(default)]
    pub(super) integer: bool,
    pub(super) unit: Option<String>,
}

pub(super) fn default_model() -> String {
    "default".into()
}
pub(super) fn default_replications() -> i64 {
    1
}
pub(super) fn default_seed() -> u64 {
    1
}
pub(super) fn default_confidence() -> f64 {
    0.95
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSweep {
    pub(super) key: String,
    pub(super) values: Option<Vec<toml::Value>>,
    pub(super) range: Option<RawRange>,
    pub(super) labels: Option<Vec<String>>,
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
pub(super) struct RawMetric {
    pub(super) path: String,
    pub(super) label: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum OneOrMany {
    One(String),
    Many(Vec<String>),
}

impl OneOrMany {
    pub(super) fn into_vec(self) -> Vec<String> {
        match self {
            OneOrMany::One(s) => vec![s],
            OneOrMany::Many(v) => v,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPlot {
    pub(super) file: String,
    pub(super) kind: String,
    pub(super) x: Option<String>,
    pub(super) y: Option<OneOrMany>,
    pub(super) title: Option<String>,
    pub(super) x_label: Option<String>,
    pub(super) y_label: Option<String>,
    pub(super) column: Option<String>,
    pub(super) bins: Option<i64>,
    pub(super) range: Option<Vec<f64>>,
    /// Line plots: `[lowest, highest]` the quantity can take.
    pub(super) y_bounds: Option<Vec<f64>>,
    /// Line plots: `[lowest, highest]` of the y axis, drawn whole.
    pub(super) y_axis: Option<Vec<f64>>,
    #[serde(default)]
    pub(super) log_x: bool,
    #[serde(default)]
    pub(super) log_y: bool,
    #[serde(rename = "where")]
    pub(super) filter: Option<toml::Table>,
    pub(super) marks: Option<Vec<RawMark>>,
    /// Line plots: published values to draw beside the simulated ones.
    pub(super) paper: Option<Vec<RawPaperValue>>,
    /// What the `paper` values are called on the plot (default "paper").
    pub(super) paper_label: Option<String>,
    /// Line plots: one published value per `y` path, independent of x,
    /// drawn as a dashed line in that series' colour.
    pub(super) paper_levels: Option<Vec<f64>>,
}

/// A published value on a line plot, `{ where = { KEY = VALUE, ... }, value = 4.969 }`,
/// or one per `y` path on a bar plot, `{ where = { ... }, values = [3.27, 0.7] }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPaperValue {
    #[serde(rename = "where")]
    pub(super) filter: toml::Table,
    pub(super) value: Option<f64>,
    pub(super) values: Option<Vec<f64>>,
}

/// A value marked on a histogram: `{ at = 337.0, label = "paper: best 337 ms" }`,
/// or a width above the lowest value plotted: `{ above_min = 1.52, label = "..." }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMark {
    pub(super) at: Option<f64>,
    pub(super) above_min: Option<f64>,
    pub(super) label: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDerived {
    pub(super) name: String,
    pub(super) kind: String,
    pub(super) column: Option<String>,
    pub(super) level: Option<f64>,
    /// Histogram bin width, in the column's unit (`modes`, `largest_bin_share`).
    pub(super) bin: Option<f64>,
    /// `modes`: the least prominence of a mode, as a share of the tallest bin.
    pub(super) prominence: Option<f64>,
    pub(super) path: Option<String>,
    pub(super) reference: Option<toml::Table>,
    /// Text for plots (legends, axes); the name by default.
    pub(super) label: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawCheck {
    pub(super) path: String,
    #[serde(rename = "where", default)]
    pub(super) filter: toml::Table,
    pub(super) expect: Option<f64>,
    pub(super) at_least_path: Option<String>,
    pub(super) at_most_path: Option<String>,
    pub(super) at_least: Option<f64>,
    pub(super) at_most: Option<f64>,
    pub(super) tolerance: Option<f64>,
    pub(super) rel_tolerance: Option<f64>,
    pub(super) claim: Option<String>,
}
