//! Sweeps and their expansion into experiment points.

use super::Experiment;
use super::spec::RawRange;

/// One swept key and the values it takes, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// Dotted model key.
    pub key: String,
    /// The values written into the model.
    pub values: Vec<toml::Value>,
    /// A numeric x coordinate per value, for line plots: the number itself,
    /// the range number before formatting, the leading number of a string
    /// such as `"12ms"`, or else the value's index.
    pub coords: Vec<f64>,
    /// Text per value for plot axes: the sweep's `labels` if given, else
    /// [`value_text`].
    pub labels: Vec<String>,
    /// Whether plots label the x axis with `labels` at the values'
    /// coordinates instead of numeric ticks: when `labels` were given, or
    /// when some value is not a number (arrays, tables, strings without a
    /// leading number), whose coordinate is only its index.
    pub categorical: bool,
    /// Whether the file gave `labels` (words for the values): plots then
    /// show them alone in legends.
    pub named: bool,
}

impl Sweep {
    /// A sweep over explicit `values`.
    pub fn from_values(key: String, values: Vec<toml::Value>) -> Sweep {
        let categorical = values.iter().any(|v| numeric_coord(v).is_none());
        let coords = values
            .iter()
            .enumerate()
            .map(|(i, v)| numeric_coord(v).unwrap_or(i as f64))
            .collect();
        let labels = values.iter().map(value_text).collect();
        Sweep {
            key,
            values,
            coords,
            labels,
            categorical,
            named: false,
        }
    }

    /// Replaces the axis labels (one per value) and makes the sweep
    /// categorical on plot axes: the values are drawn evenly spaced, in
    /// their order (coordinates are their indices), so that numbers spread
    /// over decades (`0, 1k, 10k, 1M`) do not crowd one end.
    pub fn with_labels(mut self, labels: Vec<String>) -> Result<Sweep, LabelsError> {
        if labels.len() != self.values.len() {
            return Err(LabelsError::Count {
                labels: labels.len(),
                values: self.values.len(),
            });
        }
        if labels.iter().any(|l| l.trim().is_empty()) {
            return Err(LabelsError::Empty);
        }
        for (i, l) in labels.iter().enumerate() {
            if labels[..i].contains(l) {
                return Err(LabelsError::Twice(l.clone()));
            }
        }
        self.labels = labels;
        self.coords = (0..self.values.len()).map(|i| i as f64).collect();
        self.categorical = true;
        self.named = true;
        Ok(self)
    }
}

/// Why a sweep's `labels` were refused ([`Sweep::with_labels`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LabelsError {
    /// Not one label per value.
    #[error("needs one label per value: {labels} labels for {values} values")]
    Count {
        /// Labels given.
        labels: usize,
        /// Values of the sweep.
        values: usize,
    },
    /// A label is empty.
    #[error("labels must not be empty")]
    Empty,
    /// A label is given twice.
    #[error("label `{0}` is used twice")]
    Twice(String),
}

/// The number a sweep value stands for: integers and floats as such, and the
/// leading decimal number of a string (`"12.5ms"` -> 12.5).
pub fn numeric_coord(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(f) if f.is_finite() => Some(*f),
        toml::Value::String(s) => {
            let s = s.trim();
            let end = s
                .char_indices()
                .take_while(|&(i, c)| c.is_ascii_digit() || c == '.' || ((c == '-' || c == '+') && i == 0))
                .map(|(i, c)| i + c.len_utf8())
                .last()?;
            s[..end].parse::<f64>().ok().filter(|f| f.is_finite())
        }
        _ => None,
    }
}

/// Whether a sweep value matches a filter value: numbers compare by value
/// (`2` matches `2.0`), everything else by equality.
pub fn values_match(a: &toml::Value, b: &toml::Value) -> bool {
    let num = |v: &toml::Value| match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(f) => Some(*f),
        _ => None,
    };
    match (num(a), num(b)) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

/// A value as shown in CSV cells, labels and the report: strings without
/// quotes, everything else in TOML syntax.
pub fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Float(f) => format_range_number(*f),
        other => other.to_string(),
    }
}

/// A range number as text: up to 9 decimals, trailing zeros removed, so that
/// `10.000000000000002` prints as `10`.
pub fn format_range_number(x: f64) -> String {
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

/// Expand `range = { from, to, steps, format }` into a sweep: `steps`
/// evenly spaced numbers from `from` to `to` inclusive. With `format`, each
/// number replaces the `{}` in it and the value is a string; without, the
/// value is the number (an integer when `from` and `to` are integers and
/// every step lands on an integer).
pub(crate) fn expand_range(key: String, r: &RawRange) -> Result<Sweep, String> {
    let num = |v: &toml::Value, name: &str| match v {
        toml::Value::Integer(i) => Ok((*i as f64, true)),
        toml::Value::Float(f) if f.is_finite() => Ok((*f, false)),
        other => Err(format!("`{name}` must be a number, got {other}")),
    };
    let (from, from_int) = num(&r.from, "from")?;
    let (to, to_int) = num(&r.to, "to")?;
    if r.steps < 1 || r.steps > 1_000_000 {
        return Err(format!("`steps` must be between 1 and 1000000, got {}", r.steps));
    }
    if let Some(f) = &r.format
        && !f.contains("{}")
    {
        return Err(format!("`format` must contain `{{}}`, got \"{f}\""));
    }
    let steps = r.steps as usize;
    let numbers: Vec<f64> = (0..steps)
        .map(|i| {
            if steps == 1 {
                from
            } else {
                from + (to - from) * i as f64 / (steps - 1) as f64
            }
        })
        .collect();
    let integral = from_int && to_int && numbers.iter().all(|x| (x - x.round()).abs() < 1e-9);
    let values: Vec<toml::Value> = numbers
        .iter()
        .map(|&x| match &r.format {
            Some(f) => toml::Value::String(f.replacen("{}", &format_range_number(x), 1)),
            None if integral => toml::Value::Integer(x.round() as i64),
            None => toml::Value::Float(x),
        })
        .collect();
    let labels = values.iter().map(value_text).collect();
    Ok(Sweep {
        key,
        values,
        coords: numbers,
        labels,
        categorical: false,
        named: false,
    })
}

/// One combination of sweep values.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Position in expansion order (0-based).
    pub index: usize,
    /// `(sweep key, value)` for every sweep, in file order.
    pub assignments: Vec<(String, toml::Value)>,
    /// Index into each sweep's values.
    pub value_indices: Vec<usize>,
}

impl Point {
    /// `key=value, key=value` (or `(single point)` with no sweeps).
    pub fn label(&self) -> String {
        if self.assignments.is_empty() {
            return "(single point)".into();
        }
        self.assignments
            .iter()
            .map(|(k, v)| format!("{k}={}", value_text(v)))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The text plots show for assignment `i`: the sweep's label alone when
    /// the file gave `labels` (words a reader knows: `triple buffering`
    /// rather than `display.buffers=3`), else `key=value` as in
    /// [`Point::label`].
    pub fn plot_assignment(&self, sweeps: &[Sweep], i: usize) -> String {
        let (k, v) = &self.assignments[i];
        match (sweeps.get(i), self.value_indices.get(i)) {
            (Some(s), Some(&vi)) if s.key == *k && s.named => match s.labels.get(vi) {
                Some(label) => label.clone(),
                None => format!("{k}={}", value_text(v)),
            },
            _ => format!("{k}={}", value_text(v)),
        }
    }

    /// [`Point::label`] as plots show it: every assignment through
    /// [`Point::plot_assignment`].
    pub fn plot_label(&self, sweeps: &[Sweep]) -> String {
        if self.assignments.is_empty() {
            return self.label();
        }
        (0..self.assignments.len())
            .map(|i| self.plot_assignment(sweeps, i))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether the point satisfies every `key = value` of `filter`.
    pub fn matches(&self, filter: &[(String, toml::Value)]) -> bool {
        filter
            .iter()
            .all(|(k, v)| self.assignments.iter().any(|(pk, pv)| pk == k && values_match(pv, v)))
    }
}

/// The cartesian product of all sweeps in file order, the first sweep
/// varying slowest. No sweeps give one point. With a `[sample]`, its
/// points instead ([`super::sample::Sample::assignments`]).
pub fn expand_points(exp: &Experiment) -> Vec<Point> {
    if let Some(sample) = &exp.sample {
        return sample
            .assignments()
            .into_iter()
            .enumerate()
            .map(|(index, assignments)| Point {
                index,
                assignments,
                value_indices: Vec::new(),
            })
            .collect();
    }
    let total: usize = exp.sweeps.iter().map(|s| s.values.len()).product();
    (0..total)
        .map(|index| {
            let mut rem = index;
            let mut value_indices = vec![0; exp.sweeps.len()];
            for (i, s) in exp.sweeps.iter().enumerate().rev() {
                value_indices[i] = rem % s.values.len();
                rem /= s.values.len();
            }
            let assignments = exp
                .sweeps
                .iter()
                .zip(&value_indices)
                .map(|(s, &vi)| (s.key.clone(), s.values[vi].clone()))
                .collect();
            Point {
                index,
                assignments,
                value_indices,
            }
        })
        .collect()
}
