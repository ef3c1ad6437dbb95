//! Inverse what-ifs: which value of one model key makes a metric reach a
//! target? A bracketed bisection over `[from, to]` (the metric must cross
//! the target inside the bracket; a monotone metric is the intended case).
//!
//! ```toml
//! [[search]]
//! name = "presort-first-pass-for-claim-c"
//! vary = "deferred.t_first_pass"       # the one key searched
//! from = 0.1                           # bracket
//! to = 5.0
//! format = "{}us"                      # optional, like a sweep range's
//! integer = false                      # true: only whole values are tried (and reported)
//! path = "metrics.analytic_primitives_at_30ms"
//! target = 186572                      # or target_from = { path, set, scale }
//! set = { architecture = "presort" }   # overrides for this search only
//! tolerance = 0.001                    # relative to the target (default 0.001)
//! max_iterations = 60                  # default 60
//! ```
//!
//! `target_from = { path = "...", set = { ... }, scale = 1.0 }` runs the base
//! model (experiment `[set]`, the search's `set`, then the reference's `set`;
//! the varied key keeps its model value) once and takes `scale` times its
//! metric `path` as the target: "presort should gain only 12.5%
//! over standard" is `target_from = { path = "...", set = { architecture =
//! "standard" }, scale = 1.125 }`.

use serde::{Deserialize, Serialize};

use super::dotted::{MetricPathError, json_number};
use super::runner::{RunError, Runner};
use crate::config::{PatchError, set_dotted};

/// Why a search could not finish.
#[derive(Debug, thiserror::Error)]
pub enum SearchError {
    /// A key of the search could not be set in the model.
    #[error(transparent)]
    Patch(#[from] PatchError),
    /// A run failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// The metric path is not in the run summary.
    #[error(transparent)]
    Metric(#[from] MetricPathError),
    /// The metric is `null` in the run summary.
    #[error("`{0}` is not a number in the run summary")]
    NotANumber(String),
    /// The derived value of a frame column is undefined for a run (its
    /// column is missing or holds no finite value).
    #[error("the derived value `{0}` is undefined for a run of the search (its frame column is missing or empty)")]
    NoFrameValue(String),
}
use super::sweep::format_range_number;

/// One search, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    /// Name shown in the report.
    pub name: String,
    /// Free text.
    pub description: String,
    /// Dotted model key that varies.
    pub vary: String,
    /// Lower end of the bracket.
    pub from: f64,
    /// Upper end of the bracket.
    pub to: f64,
    /// `{}` is replaced by the number (a string value); none: a float.
    pub format: Option<String>,
    /// Write the value as an integer (rounded), for counts.
    pub integer: bool,
    /// Metric path into the run summary, or the name of a derived value of
    /// a frame column.
    pub path: String,
    /// Set when `path` names a derived value of a frame column: how it is
    /// computed from each run's frames (the experiment's validation sets it).
    pub frame_value: Option<crate::experiment::spec::DerivedKind>,
    /// What the target is.
    pub target: Target,
    /// Overrides for this search, after the experiment's `[set]`.
    pub set: Vec<(String, toml::Value)>,
    /// Relative tolerance on the target.
    pub tolerance: f64,
    /// Bisection steps at most.
    pub max_iterations: u32,
}

/// The value the metric should reach.
#[derive(Debug, Clone, PartialEq)]
pub enum Target {
    /// A number.
    Value(f64),
    /// `scale` times a metric of a reference run.
    FromRun {
        /// Metric path of the reference run.
        path: String,
        /// Overrides of the reference run.
        set: Vec<(String, toml::Value)>,
        /// Factor.
        scale: f64,
    },
}

/// What a search found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SearchResult {
    /// The search's name.
    pub name: String,
    /// The varied key.
    pub vary: String,
    /// The metric path.
    pub path: String,
    /// Target value of the metric.
    pub target: f64,
    /// Value at the bracket's ends (from, to).
    pub at_ends: (f64, f64),
    /// The value found (None when the bracket does not cross the target).
    pub value: Option<f64>,
    /// The metric at the value found.
    pub metric: Option<f64>,
    /// Runs made.
    pub runs: u32,
    /// Whether the tolerance was met.
    pub converged: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSearch {
    name: String,
    #[serde(default)]
    description: String,
    vary: String,
    from: f64,
    to: f64,
    format: Option<String>,
    #[serde(default)]
    integer: bool,
    path: String,
    target: Option<f64>,
    target_from: Option<RawTargetFrom>,
    #[serde(default)]
    set: toml::Table,
    tolerance: Option<f64>,
    max_iterations: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawTargetFrom {
    path: String,
    #[serde(default)]
    set: toml::Table,
    scale: Option<f64>,
}

/// Validates a raw search; the error is (key suffix, message).
pub(crate) fn validate(
    raw: RawSearch,
    flatten: impl Fn(&toml::Table) -> Vec<(String, toml::Value)>,
) -> Result<Search, (String, String)> {
    let e = |k: &str, m: String| Err((k.to_string(), m));
    if raw.name.trim().is_empty() {
        return e("name", "must not be empty".into());
    }
    if raw.vary.split('.').any(|p| p.trim().is_empty()) {
        return e("vary", format!("`{}` is not a dotted key", raw.vary));
    }
    if !(raw.from.is_finite() && raw.to.is_finite()) || raw.from >= raw.to {
        return e(
            "from",
            format!("need finite from < to, got {} and {}", raw.from, raw.to),
        );
    }
    if let Some(f) = &raw.format
        && !f.contains("{}")
    {
        return e("format", format!("must contain `{{}}`, got \"{f}\""));
    }
    let tolerance = raw.tolerance.unwrap_or(1e-3);
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return e("tolerance", format!("must be > 0, got {tolerance}"));
    }
    let target = match (raw.target, raw.target_from) {
        (Some(v), None) if v.is_finite() => Target::Value(v),
        (None, Some(t)) => {
            let scale = t.scale.unwrap_or(1.0);
            if !scale.is_finite() {
                return e("target_from.scale", format!("must be finite, got {scale}"));
            }
            Target::FromRun {
                path: t.path,
                set: flatten(&t.set),
                scale,
            }
        }
        _ => {
            return e(
                "target",
                "give exactly one of a finite `target` or `target_from`".into(),
            );
        }
    };
    Ok(Search {
        name: raw.name,
        description: raw.description,
        vary: raw.vary,
        from: raw.from,
        to: raw.to,
        format: raw.format,
        integer: raw.integer,
        path: raw.path,
        frame_value: None,
        target,
        set: flatten(&raw.set),
        tolerance,
        max_iterations: raw.max_iterations.unwrap_or(60).clamp(1, 200),
    })
}

impl Search {
    /// `x` as the search tries it: whole when `integer`.
    fn snap(&self, x: f64) -> f64 {
        if self.integer { x.round() } else { x }
    }

    fn value(&self, x: f64) -> toml::Value {
        let x = self.snap(x);
        match &self.format {
            Some(f) => toml::Value::String(f.replacen("{}", &format_range_number(x), 1)),
            None if self.integer => toml::Value::Integer(x.round() as i64),
            None => toml::Value::Float(x),
        }
    }

    fn metric(
        &self,
        runner: &dyn Runner,
        base: &toml::Table,
        set: &[(String, toml::Value)],
        path: &str,
        seed: u64,
    ) -> Result<f64, SearchError> {
        let mut model = base.clone();
        for (k, v) in set {
            set_dotted(&mut model, k, v.clone())?;
        }
        let origins: Vec<(String, String)> = set
            .iter()
            .map(|(k, _)| (k.clone(), format!("[[search]] {:?}, which sets {k}", self.name)))
            .collect();
        let frame_value = self.frame_value.as_ref().filter(|_| path == self.path);
        let out = runner.run_noted(&model, seed, frame_value.is_some(), &origins)?;
        match frame_value {
            Some(kind) => {
                let column = kind
                    .frame_column()
                    .and_then(|c| out.frames.as_ref()?.column(c))
                    .unwrap_or_default();
                super::derived::of_frames(kind, &column).ok_or_else(|| SearchError::NoFrameValue(path.to_string()))
            }
            None => json_number(&out.summary, path)?.ok_or_else(|| SearchError::NotANumber(path.to_string())),
        }
    }

    /// Runs the search from `base` (the experiment's model with its `[set]`).
    pub fn run(&self, runner: &dyn Runner, base: &toml::Table, seed: u64) -> Result<SearchResult, SearchError> {
        let mut runs = 0;
        let target = match &self.target {
            Target::Value(v) => *v,
            Target::FromRun { path, set, scale } => {
                runs += 1;
                let mut all = self.set.clone();
                all.extend(set.iter().cloned());
                scale * self.metric(runner, base, &all, path, seed)?
            }
        };
        let mut at = |x: f64| -> Result<f64, SearchError> {
            runs += 1;
            let mut set = self.set.clone();
            set.push((self.vary.clone(), self.value(x)));
            self.metric(runner, base, &set, &self.path, seed)
        };
        let (mut lo, mut hi) = (self.snap(self.from), self.snap(self.to));
        let (flo, fhi) = (at(lo)?, at(hi)?);
        let mut result = SearchResult {
            name: self.name.clone(),
            vary: self.vary.clone(),
            path: self.path.clone(),
            target,
            at_ends: (flo, fhi),
            value: None,
            metric: None,
            runs: 0,
            converged: false,
        };
        let tol = self.tolerance * target.abs().max(f64::MIN_POSITIVE);
        let (glo, ghi) = (flo - target, fhi - target);
        if glo.abs() <= tol || ghi.abs() <= tol || glo.signum() != ghi.signum() {
            let (mut best, mut best_m) = if glo.abs() <= ghi.abs() { (lo, flo) } else { (hi, fhi) };
            let rising = ghi > glo;
            for _ in 0..self.max_iterations {
                if (best_m - target).abs() <= tol {
                    result.converged = true;
                    break;
                }
                let mid = self.snap(0.5 * (lo + hi));
                if mid == lo || mid == hi {
                    // Whole values: the bracket cannot shrink further.
                    break;
                }
                let m = at(mid)?;
                if (m - target).abs() < (best_m - target).abs() {
                    (best, best_m) = (mid, m);
                }
                if (m < target) == rising {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            result.converged |= (best_m - target).abs() <= tol;
            result.value = Some(best);
            result.metric = Some(best_m);
        }
        result.runs = runs;
        Ok(result)
    }
}

/// The report section for the searches.
pub fn report_section(searches: &[Search], results: &[SearchResult]) -> String {
    if results.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "\n## Inverse what-ifs\n\nEach search varies one key over a bracket (bisection) until the metric reaches \
         the target.\n\n| search | key | metric | target | at bracket ends | value found | metric there | runs |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for (sp, r) in searches.iter().zip(results) {
        let found = match (r.value, r.converged) {
            (Some(v), true) => sp.value(v).to_string(),
            (Some(v), false) => format!("{} (not converged)", sp.value(v)),
            (None, _) => "none in the bracket".into(),
        };
        s.push_str(&format!(
            "| {} | `{}` | `{}` | {:.6} | {} = {:.6}, {} = {:.6} | {} | {} | {} |\n",
            r.name,
            r.vary,
            r.path,
            r.target,
            sp.value(sp.from),
            r.at_ends.0,
            sp.value(sp.to),
            r.at_ends.1,
            found,
            r.metric.map_or("-".into(), |m| format!("{m:.6}")),
            r.runs
        ));
    }
    for sp in searches {
        if !sp.description.is_empty() {
            s.push_str(&format!("\n- **{}**: {}\n", sp.name, sp.description));
        }
    }
    s
}

/// `searches.csv`.
pub fn csv(results: &[SearchResult]) -> String {
    let header = [
        "search",
        "key",
        "path",
        "target",
        "metric_at_from",
        "metric_at_to",
        "value",
        "metric",
        "converged",
        "runs",
    ];
    let rows = results.iter().map(|r| {
        vec![
            r.name.clone(),
            r.vary.clone(),
            r.path.clone(),
            r.target.to_string(),
            r.at_ends.0.to_string(),
            r.at_ends.1.to_string(),
            r.value.map_or(String::new(), |v| v.to_string()),
            r.metric.map_or(String::new(), |v| v.to_string()),
            r.converged.to_string(),
            r.runs.to_string(),
        ]
    });
    let mut out = Vec::new();
    // Writing into memory cannot fail.
    let _ = crate::output::table::write_table(&mut out, &header, rows);
    String::from_utf8(out).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::runner::RunOutput;

    /// metric = 3 x + 1 (x read from `k`, a float or "<x>us"); asked for
    /// frames, a column `T` of 101 values evenly from 0 to x.
    struct Linear;
    impl Runner for Linear {
        fn run(&self, model: &toml::Table, _seed: u64, want_frames: bool) -> Result<RunOutput, RunError> {
            let x = match model.get("k") {
                Some(toml::Value::Float(f)) => *f,
                Some(toml::Value::String(s)) => s
                    .trim_end_matches("us")
                    .parse()
                    .map_err(|_| RunError::Other("bad".into()))?,
                Some(toml::Value::Integer(i)) => *i as f64,
                _ => 0.0,
            };
            let scale = model.get("scale").and_then(|v| v.as_float()).unwrap_or(1.0);
            let frames = want_frames.then(|| crate::experiment::runner::FrameTable {
                columns: vec!["T".into()],
                rows: (0..=100).map(|i| vec![x * f64::from(i) / 100.0]).collect(),
            });
            Ok(RunOutput {
                summary: serde_json::json!({"metrics": {"y": scale * (3.0 * x + 1.0)}}),
                frames,
            })
        }
    }

    fn search(target: Target, format: Option<&str>) -> Search {
        Search {
            name: "s".into(),
            description: String::new(),
            vary: "k".into(),
            from: 0.0,
            to: 10.0,
            format: format.map(String::from),
            integer: false,
            path: "metrics.y".into(),
            frame_value: None,
            target,
            set: vec![],
            tolerance: 1e-9,
            max_iterations: 80,
        }
    }

    #[test]
    fn bisection_finds_the_value() {
        let r = search(Target::Value(10.0), None)
            .run(&Linear, &toml::Table::new(), 1)
            .unwrap();
        assert!(r.converged);
        assert!((r.value.unwrap() - 3.0).abs() < 1e-6, "{r:?}");
        let r = search(Target::Value(10.0), Some("{}us"))
            .run(&Linear, &toml::Table::new(), 1)
            .unwrap();
        assert!((r.value.unwrap() - 3.0).abs() < 1e-6, "{r:?}");
    }

    #[test]
    fn an_integer_search_tries_and_reports_whole_values() {
        // y = 3x + 1 = 11.5 lies between x = 3 (10) and 4 (13): the closer
        // whole value is 3, with a format and without.
        for format in [None, Some("{}us")] {
            let mut s = search(Target::Value(11.5), format);
            s.integer = true;
            let r = s.run(&Linear, &toml::Table::new(), 1).unwrap();
            assert_eq!(r.value, Some(3.0), "{format:?}: {r:?}");
            assert_eq!(r.metric, Some(10.0));
            assert!(!r.converged);
            assert!(r.runs < 10, "the bracket stops at whole values: {r:?}");
        }
    }

    #[test]
    fn target_from_a_reference_run() {
        let t = Target::FromRun {
            path: "metrics.y".into(),
            set: vec![("k".into(), toml::Value::Float(2.0))],
            scale: 2.0,
        };
        // reference y(2) = 7, target 14 -> x = 13/3.
        let r = search(t, None).run(&Linear, &toml::Table::new(), 1).unwrap();
        assert!((r.target - 14.0).abs() < 1e-12);
        assert!((r.value.unwrap() - 13.0 / 3.0).abs() < 1e-6);
    }

    #[test]
    fn a_bracket_that_misses_reports_no_value() {
        let r = search(Target::Value(100.0), None)
            .run(&Linear, &toml::Table::new(), 1)
            .unwrap();
        assert_eq!(r.value, None);
        assert!(!r.converged);
        assert_eq!(r.at_ends, (1.0, 31.0));
    }

    #[test]
    fn a_search_can_aim_at_a_derived_value_of_a_frame_column() {
        // The width of column T above its minimum (all of it: level 1) is
        // x, so x = 4 reaches 4; each run of the search asks for frames.
        let mut s = search(Target::Value(4.0), None);
        s.path = "t_width".into();
        s.frame_value = Some(crate::experiment::spec::DerivedKind::QuantileWidthFromMin {
            column: "T".into(),
            level: 1.0,
        });
        let r = s.run(&Linear, &toml::Table::new(), 1).unwrap();
        assert!(r.converged, "{r:?}");
        assert!((r.value.unwrap() - 4.0).abs() < 1e-6, "{r:?}");
        assert_eq!(r.at_ends, (0.0, 10.0));
        // A column the runs do not have: an error naming the value, not a panic.
        s.frame_value = Some(crate::experiment::spec::DerivedKind::QuantileWidthFromMin {
            column: "U".into(),
            level: 1.0,
        });
        let e = s.run(&Linear, &toml::Table::new(), 1).unwrap_err().to_string();
        assert!(e.contains("`t_width`") && e.contains("undefined"), "{e}");
    }
}
