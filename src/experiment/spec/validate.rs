//! Loading and validating an experiment file: cross-references between
//! sweeps, plots, derived values and checks, reported by entry.

use std::path::Path;

use super::raw::*;
use super::*;
use crate::experiment::ExperimentError;
use crate::experiment::sweep::{expand_range, values_match};

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
    Validator { file: source, text }.experiment(raw)
}

pub(super) struct Validator<'a> {
    file: &'a Path,
    text: &'a str,
}

impl Validator<'_> {
    fn err(&self, key: impl Into<String>, message: impl Into<String>) -> ExperimentError {
        let key = key.into();
        ExperimentError::Invalid {
            file: self.file.to_path_buf(),
            line: self.line_of(&key),
            key,
            message: message.into(),
        }
    }

    /// The line of the entry an error `key` names (`check[2] (path).expect`
    /// is `expect` of the third `[[check]]`), or of the nearest enclosing
    /// entry that stands in the file.
    fn line_of(&self, key: &str) -> Option<usize> {
        let mut plain = String::with_capacity(key.len());
        let mut depth = 0usize;
        for c in key.chars() {
            match c {
                '(' => depth += 1,
                ')' => depth = depth.saturating_sub(1),
                c if depth == 0 => plain.push(c),
                _ => {}
            }
        }
        let plain = plain.replace(' ', "");
        let dotted = crate::config::load::dotted_path(&plain);
        let src = crate::config::ModelSource::from_text("", self.text);
        let parts: Vec<&str> = dotted.split('.').collect();
        (1..=parts.len()).rev().find_map(|n| src.line_of(&parts[..n].join(".")))
    }

    fn experiment(&self, raw: RawExperiment) -> Result<Experiment, ExperimentError> {
        if raw.name.trim().is_empty() {
            return Err(self.err("name", "must not be empty"));
        }
        if raw.replications < 1 {
            return Err(self.err("replications", format!("must be at least 1, got {}", raw.replications)));
        }
        if raw.replications > crate::limits::MAX_REPLICATIONS {
            return Err(self.err(
                "replications",
                format!(
                    "{} is more than the limit of {} replications per point",
                    raw.replications,
                    crate::limits::MAX_REPLICATIONS
                ),
            ));
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
                Some(l) => sweep
                    .with_labels(l)
                    .map_err(|m| self.err(format!("{key}.labels"), m.to_string()))?,
                None => sweep,
            };
            if sweep.key == MODEL_SWEEP_KEY {
                self.model_sweep(&key, &sweep, &raw.model)?;
            }
            sweeps.push(sweep);
        }
        if sweeps.iter().any(|s| s.key == MODEL_SWEEP_KEY) && !raw.search.is_empty() {
            return Err(self.err(
                "search[0]",
                "searches run on one base model; an experiment that sweeps `model` cannot have them",
            ));
        }
        let sample = match raw.sample {
            None => None,
            Some(s) => {
                if !sweeps.is_empty() {
                    return Err(self.err("sample", "give either `[[sweep]]`s or `[sample]`, not both"));
                }
                Some(self.sample(s)?)
            }
        };
        // Runs = points (the product of the sweeps' sizes, or the sample's
        // points) x replications, checked before the points are expanded.
        let points = match &sample {
            Some(s) => s.points() as u64,
            None => sweeps
                .iter()
                .try_fold(1u64, |n, s| n.checked_mul(s.values.len() as u64))
                .unwrap_or(u64::MAX),
        };
        let runs = points.saturating_mul(raw.replications as u64);
        if runs > crate::limits::MAX_EXPERIMENT_RUNS {
            let sizes: Vec<String> = sweeps.iter().map(|s| s.values.len().to_string()).collect();
            return Err(self.err(
                "sweep",
                format!(
                    "{} points ({}) x {} replications = {runs} runs is more than the limit of {}",
                    points,
                    if sizes.is_empty() {
                        "no sweep".to_string()
                    } else {
                        sizes.join(" x ")
                    },
                    raw.replications,
                    crate::limits::MAX_EXPERIMENT_RUNS
                ),
            ));
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
                "speedup" => DerivedKind::Speedup {
                    path: d.path.clone().unwrap_or_else(|| "wall_seconds".into()),
                    reference: need_ref()?,
                },
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
                    let mut marks = Vec::new();
                    for (i, m) in p.marks.iter().flatten().enumerate() {
                        let mkey = format!("{key}.marks.{i}");
                        if !m.at.is_finite() {
                            return Err(self.err(format!("{mkey}.at"), "must be a finite number"));
                        }
                        if m.label.trim().is_empty() || m.label.chars().count() > 80 {
                            return Err(self.err(format!("{mkey}.label"), "must be 1 to 80 characters"));
                        }
                        if i >= 16 {
                            return Err(self.err(format!("{key}.marks"), "at most 16 marks"));
                        }
                        marks.push(crate::plot::Mark {
                            at: m.at,
                            label: m.label.clone(),
                        });
                    }
                    PlotKind::Histogram {
                        column,
                        bins: bins as usize,
                        range,
                        filter: f,
                        marks,
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
            if p.marks.is_some() && !matches!(kind, PlotKind::Histogram { .. }) {
                return Err(self.err(format!("{key}.marks"), "only histogram plots take `marks`"));
            }
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
            let sp = crate::experiment::inverse::validate(r, flat)
                .map_err(|(k, m)| self.err(format!("search[{i}].{k}"), m))?;
            if searches
                .iter()
                .any(|o: &crate::experiment::inverse::Search| o.name == sp.name)
            {
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
            sample,
        })
    }

    /// A `[[sweep]] key = "model"`: every value a model file relative to
    /// the experiment file (that exists) or `"default"`, and no top-level
    /// `model` beside it.
    fn model_sweep(&self, key: &str, sweep: &Sweep, model: &str) -> Result<(), ExperimentError> {
        if model != "default" {
            return Err(self.err(
                "model",
                format!("`{key}` sweeps `model` (the model file of each point); leave out the top-level `model`"),
            ));
        }
        let dir = self.file.parent().unwrap_or(Path::new(""));
        for v in &sweep.values {
            let Some(name) = v.as_str().filter(|n| !n.trim().is_empty()) else {
                return Err(self.err(
                    format!("{key}.values"),
                    format!("a `model` sweep takes model file paths or \"default\", got {v}"),
                ));
            };
            if name != "default" && !dir.join(name).is_file() {
                return Err(self.err(
                    format!("{key}.values"),
                    format!(
                        "model file {name:?} not found (looked for {}; paths are relative to the experiment file)",
                        dir.join(name).display()
                    ),
                ));
            }
        }
        Ok(())
    }

    fn sample(&self, s: RawSample) -> Result<crate::experiment::sample::Sample, ExperimentError> {
        use crate::experiment::sample::{Sample, SampleMethod, SampleParam, Scale};
        let method = match s.method.as_str() {
            "latin_hypercube" => SampleMethod::LatinHypercube,
            "sobol" => SampleMethod::Sobol,
            other => {
                return Err(self.err(
                    "sample.method",
                    format!("unknown method `{other}` (expected latin_hypercube or sobol)"),
                ));
            }
        };
        if !(2..=1_000_000).contains(&s.n) {
            return Err(self.err("sample.n", format!("must be between 2 and 1000000, got {}", s.n)));
        }
        let bootstrap = s.bootstrap.unwrap_or(1000);
        if !(0..=100_000).contains(&bootstrap) {
            return Err(self.err(
                "sample.bootstrap",
                format!("must be between 0 and 100000, got {bootstrap}"),
            ));
        }
        if s.param.is_empty() {
            return Err(self.err("sample", "needs at least one `[[sample.param]]`"));
        }
        let mut params: Vec<SampleParam> = Vec::new();
        for (i, p) in s.param.into_iter().enumerate() {
            let key = format!("sample.param[{i}]");
            if p.key.split('.').any(|x| x.trim().is_empty()) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is not a dotted key", p.key)));
            }
            if params.iter().any(|o| o.key == p.key) {
                return Err(self.err(format!("{key}.key"), format!("`{}` is sampled twice", p.key)));
            }
            if !(p.from.is_finite() && p.to.is_finite() && p.from < p.to) {
                return Err(self.err(
                    &key,
                    format!("needs finite `from` < `to`, got from = {}, to = {}", p.from, p.to),
                ));
            }
            let scale = match p.scale.as_deref().unwrap_or("linear") {
                "linear" => Scale::Linear,
                "log" if p.from > 0.0 => Scale::Log,
                "log" => {
                    return Err(self.err(format!("{key}.scale"), "`log` needs `from` > 0"));
                }
                other => {
                    return Err(self.err(
                        format!("{key}.scale"),
                        format!("unknown scale `{other}` (expected linear or log)"),
                    ));
                }
            };
            if p.integer && (p.from.fract() != 0.0 || p.to.fract() != 0.0) {
                return Err(self.err(&key, "`integer = true` needs whole numbers for `from` and `to`"));
            }
            if let Some(u) = &p.unit
                && (u.is_empty() || !u.chars().all(|c| c.is_ascii_alphabetic() || c == '/'))
            {
                return Err(self.err(
                    format!("{key}.unit"),
                    format!("`{u}` is not a unit (letters, e.g. ms, us, Hz)"),
                ));
            }
            params.push(SampleParam {
                key: p.key,
                from: p.from,
                to: p.to,
                scale,
                integer: p.integer,
                unit: p.unit,
            });
        }
        Ok(Sample {
            method,
            n: s.n as usize,
            seed: s.seed,
            bootstrap: bootstrap as usize,
            params,
        })
    }
}

/// Flatten nested tables into `(dotted key, value)` pairs, in table order.
pub(super) fn flatten(prefix: &str, t: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
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
