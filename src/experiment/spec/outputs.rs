//! What an experiment reports, validated against its sweeps: metrics,
//! derived values, plots, checks and inverse searches (the experiment
//! file's `[[metric]]`, `[[derived]]`, `[[plot]]`, `[[check]]` and
//! `[[search]]` entries). Errors name the entry and its key, with the
//! file's line, as everywhere in [`super::validate`].

use super::raw::*;
use super::validate::Validator;
use super::*;
use crate::config::{flatten, flatten_until};
use crate::experiment::ExperimentError;
use crate::experiment::sweep::values_match;

/// Sweep key = value pairs selecting points.
type Filter = Vec<(String, toml::Value)>;
impl Validator<'_> {
    /// A `where`-like table of `key` = value: every key a sweep key, every
    /// value one of that sweep's values; flattened to dotted keys, except
    /// below a sweep key, whose value (a table, for a sweep of tables) is
    /// taken whole.
    fn filter(
        &self,
        sweeps: &[Sweep],
        key: &str,
        t: &toml::Table,
    ) -> Result<Vec<(String, toml::Value)>, ExperimentError> {
        let mut flat = Vec::new();
        flatten_until("", t, &|k| sweeps.iter().any(|s| s.key == k), &mut flat);
        for (k, v) in &flat {
            let Some(s) = sweeps.iter().find(|s| s.key == *k) else {
                return Err(self.err(key, format!("`{k}` is not a sweep key")));
            };
            if !s.values.iter().any(|sv| values_match(sv, v)) {
                return Err(self.err(key, format!("`{k}` = {v} is not one of the swept values")));
            }
        }
        Ok(flat)
    }

    /// The `[[metric]]`s: summary paths, each listed once.
    pub(super) fn metrics(&self, raw: Vec<RawMetric>) -> Result<Vec<Metric>, ExperimentError> {
        let mut metrics: Vec<Metric> = Vec::new();
        for (i, m) in raw.into_iter().enumerate() {
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
        Ok(metrics)
    }

    /// The `[[derived]]` values: unique names, each kind with what it needs.
    pub(super) fn derived(
        &self,
        raw: Vec<RawDerived>,
        sweeps: &[Sweep],
        metrics: &[Metric],
    ) -> Result<Vec<Derived>, ExperimentError> {
        let mut derived: Vec<Derived> = Vec::new();
        for (i, d) in raw.into_iter().enumerate() {
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
            let need_path = || {
                d.path
                    .clone()
                    .ok_or_else(|| self.err(&key, format!("kind `{}` needs `path`", d.kind)))
            };
            let need_ref = || -> Result<Vec<(String, toml::Value)>, ExperimentError> {
                let r = d
                    .reference
                    .as_ref()
                    .ok_or_else(|| self.err(&key, format!("kind `{}` needs `reference`", d.kind)))?;
                let r = self.filter(sweeps, &format!("{key}.reference"), r)?;
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
                    path: need_path()?,
                    reference: need_ref()?,
                },
                "ratio" => DerivedKind::Ratio {
                    path: need_path()?,
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
            let label = match d.label {
                Some(l) if l.trim().is_empty() => {
                    return Err(self.err(format!("{key}.label"), "must not be empty"));
                }
                Some(l) => l,
                None => d.name.clone(),
            };
            derived.push(Derived {
                name: d.name,
                label,
                kind,
            });
        }
        Ok(derived)
    }

    /// The `[[plot]]`s: file names, each kind with its axes, filters,
    /// ranges and marks; labels from the metrics' (the title from `name`).
    pub(super) fn plots(
        &self,
        raw: Vec<RawPlot>,
        sweeps: &[Sweep],
        metrics: &[Metric],
        name: &str,
    ) -> Result<Vec<PlotSpec>, ExperimentError> {
        let mut plots: Vec<PlotSpec> = Vec::new();
        for (i, mut p) in raw.into_iter().enumerate() {
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
            let kind = match p.kind.clone().as_str() {
                "line" => self.line_plot(&mut p, &key, sweeps)?,
                "histogram" => self.histogram_plot(&p, &key, sweeps)?,
                "scatter" => self.scatter_plot(&mut p, &key)?,
                "bars" => self.bar_plot(&mut p, &key, sweeps)?,
                other => {
                    return Err(self.err(
                        format!("{key}.kind"),
                        format!("unknown kind `{other}` (expected line, histogram, scatter or bars)"),
                    ));
                }
            };
            if p.marks.is_some() && !matches!(kind, PlotKind::Histogram { .. }) {
                return Err(self.err(format!("{key}.marks"), "only histogram plots take `marks`"));
            }
            if p.range.is_some() && !matches!(kind, PlotKind::Histogram { .. }) {
                return Err(self.err(format!("{key}.range"), "only histogram plots take `range`"));
            }
            if p.paper.is_some() && !matches!(kind, PlotKind::Line { .. } | PlotKind::Bars { .. }) {
                return Err(self.err(format!("{key}.paper"), "only line and bar plots take `paper`"));
            }
            let paper_label = match p.paper_label.take() {
                Some(_) if p.paper.is_none() => {
                    return Err(self.err(
                        format!("{key}.paper_label"),
                        "names the `paper` values; give `paper` too",
                    ));
                }
                Some(l) if l.trim().is_empty() || l.chars().count() > 60 => {
                    return Err(self.err(format!("{key}.paper_label"), "must be 1 to 60 characters"));
                }
                Some(l) => l,
                None => "paper".to_string(),
            };
            if p.y_bounds.is_some() && !matches!(kind, PlotKind::Line { .. }) {
                return Err(self.err(format!("{key}.y_bounds"), "only line plots take `y_bounds`"));
            }
            if p.filter.is_some() && matches!(kind, PlotKind::Scatter { .. }) {
                return Err(self.err(format!("{key}.where"), "only histogram and line plots take `where`"));
            }
            let (dx, dy) = match &kind {
                PlotKind::Line { x, y, .. } => (x.clone(), y.first().cloned().unwrap_or_default()),
                PlotKind::Histogram { column, .. } => (column.clone(), "density".into()),
                PlotKind::Scatter { x, y, .. } => (x.clone(), y.clone()),
                PlotKind::Bars { y, .. } => (String::new(), y.first().cloned().unwrap_or_default()),
            };
            let label = |p: &str| {
                metrics
                    .iter()
                    .find(|m| m.path == p)
                    .map(|m| m.label.clone())
                    .unwrap_or_else(|| p.to_string())
            };
            plots.push(PlotSpec {
                paper_label,
                title: p.title.unwrap_or_else(|| name.to_string()),
                x_label: p.x_label.unwrap_or_else(|| label(&dx)),
                y_label: p.y_label.unwrap_or_else(|| label(&dy)),
                file: p.file,
                kind,
            });
        }
        Ok(plots)
    }

    /// A line plot's x (a sweep key), y (metric paths), scales and filter.
    fn line_plot(&self, p: &mut RawPlot, key: &str, sweeps: &[Sweep]) -> Result<PlotKind, ExperimentError> {
        let find_sweep = |k: &str| sweeps.iter().find(|s| s.key == k);
        let x =
            p.x.clone()
                .ok_or_else(|| self.err(key, "kind `line` needs `x` (a sweep key)"))?;
        if find_sweep(&x).is_none() {
            return Err(self.err(format!("{key}.x"), format!("`{x}` is not a sweep key")));
        }
        let y = p.y.take().map(OneOrMany::into_vec).unwrap_or_default();
        if y.is_empty() || y.iter().any(|s| s.trim().is_empty()) {
            return Err(self.err(format!("{key}.y"), "needs one or more metric paths"));
        }
        let f = match &p.filter {
            Some(t) => self.filter(sweeps, &format!("{key}.where"), t)?,
            None => Vec::new(),
        };
        if f.iter().any(|(k, _)| *k == x) {
            return Err(self.err(format!("{key}.where"), format!("must not fix the x axis key `{x}`")));
        }
        let y_bounds = match &p.y_bounds {
            None => None,
            Some(b) => match b.as_slice() {
                [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi && !(p.log_y && *lo <= 0.0) => Some((*lo, *hi)),
                _ => {
                    return Err(self.err(
                        format!("{key}.y_bounds"),
                        format!("needs [lowest, highest]: two finite numbers, the first below the second (and above 0 on a log axis); got {b:?}"),
                    ));
                }
            },
        };
        let paper = self.paper_values(p, key, sweeps, &x)?;
        Ok(PlotKind::Line {
            x,
            y,
            log_x: p.log_x,
            log_y: p.log_y,
            filter: f,
            y_bounds,
            paper,
        })
    }

    /// A plot's `paper` entries: at most 64 (`what` names them in that
    /// error), each read by `read` (given the entry and its key) and its
    /// `where` checked against the sweeps.
    fn paper_entries<T>(
        &self,
        p: &RawPlot,
        key: &str,
        sweeps: &[Sweep],
        what: &str,
        mut read: impl FnMut(&super::raw::RawPaperValue, &str) -> Result<T, ExperimentError>,
    ) -> Result<Vec<(Filter, T)>, ExperimentError> {
        let raw = p.paper.as_deref().unwrap_or_default();
        if raw.len() > 64 {
            return Err(self.err(format!("{key}.paper"), format!("at most 64 {what}")));
        }
        raw.iter()
            .enumerate()
            .map(|(i, v)| {
                let vkey = format!("{key}.paper.{i}");
                let read = read(v, &vkey)?;
                Ok((self.filter(sweeps, &format!("{vkey}.where"), &v.filter)?, read))
            })
            .collect()
    }

    /// A line plot's `paper` values: each finite, each `where` naming
    /// swept values and fixing the x key `x`.
    fn paper_values(
        &self,
        p: &RawPlot,
        key: &str,
        sweeps: &[Sweep],
        x: &str,
    ) -> Result<Vec<super::PaperValue>, ExperimentError> {
        let entries = self.paper_entries(p, key, sweeps, "values", |v, vkey| match (v.value, &v.values) {
            (Some(x), None) if x.is_finite() => Ok(x),
            (Some(x), None) => Err(self.err(format!("{vkey}.value"), format!("must be a finite number, got {x}"))),
            _ => Err(self.err(
                vkey,
                "a line plot's paper value needs `value` (one number; `values` is for bar plots)",
            )),
        })?;
        entries
            .into_iter()
            .enumerate()
            .map(|(i, (filter, value))| {
                if !filter.iter().any(|(k, _)| k == x) {
                    return Err(self.err(
                        format!("{key}.paper.{i}.where"),
                        format!("must fix the x axis key `{x}` (the value is drawn at that x)"),
                    ));
                }
                Ok(super::PaperValue { filter, value })
            })
            .collect()
    }

    /// A bar plot's `y` paths (the groups), scale, filter and `paper`
    /// values (one per `y` path each, finite; at most 64 entries).
    fn bar_plot(&self, p: &mut RawPlot, key: &str, sweeps: &[Sweep]) -> Result<PlotKind, ExperimentError> {
        if p.x.is_some() || p.log_x {
            return Err(self.err(key, "kind `bars` has no x axis: its groups are the `y` paths"));
        }
        let y = p.y.take().map(OneOrMany::into_vec).unwrap_or_default();
        if y.is_empty() || y.iter().any(|s| s.trim().is_empty()) {
            return Err(self.err(
                format!("{key}.y"),
                "needs one or more metric paths (one group of bars each)",
            ));
        }
        let filter = match &p.filter {
            Some(t) => self.filter(sweeps, &format!("{key}.where"), t)?,
            None => Vec::new(),
        };
        let paper = self
            .paper_entries(p, key, sweeps, "entries", |v, vkey| match (&v.values, v.value) {
                (Some(vs), None) if vs.len() == y.len() && vs.iter().all(|x| x.is_finite()) => Ok(vs.clone()),
                (Some(vs), None) => Err(self.err(
                    format!("{vkey}.values"),
                    format!("needs {} finite numbers, one per `y` path; got {vs:?}", y.len()),
                )),
                _ => Err(self.err(
                    vkey,
                    "a bar plot's paper entry needs `values` (one number per `y` path)",
                )),
            })?
            .into_iter()
            .map(|(filter, values)| super::PaperValues { filter, values })
            .collect();
        Ok(PlotKind::Bars {
            y,
            log_y: p.log_y,
            filter,
            paper,
        })
    }

    /// A histogram's column, bins, filter, range and marks.
    fn histogram_plot(&self, p: &RawPlot, key: &str, sweeps: &[Sweep]) -> Result<PlotKind, ExperimentError> {
        let column = p
            .column
            .clone()
            .ok_or_else(|| self.err(key, "kind `histogram` needs `column`"))?;
        let bins = p.bins.unwrap_or(50);
        if !(1..=100_000).contains(&bins) {
            return Err(self.err(format!("{key}.bins"), "must be between 1 and 100000"));
        }
        let f = match &p.filter {
            Some(t) => self.filter(sweeps, &format!("{key}.where"), t)?,
            None => Vec::new(),
        };
        let range = self.histogram_range(key, &p.range)?;
        let marks = self.histogram_marks(key, &p.marks)?;
        Ok(PlotKind::Histogram {
            column,
            bins: bins as usize,
            range,
            filter: f,
            marks,
        })
    }

    /// A histogram's `range`: none, or finite [lo, hi] with lo < hi.
    fn histogram_range(&self, key: &str, range: &Option<Vec<f64>>) -> Result<Option<(f64, f64)>, ExperimentError> {
        Ok(match range {
            None => None,
            Some(r) => match r[..] {
                [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi => Some((lo, hi)),
                [lo, hi] if lo.is_finite() && hi.is_finite() => {
                    return Err(self.err(format!("{key}.range"), format!("needs lo < hi, got [{lo}, {hi}]")));
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
        })
    }

    /// A histogram's `marks`: at most 16, each at a finite x with a label of 1 to 80 characters.
    fn histogram_marks(
        &self,
        key: &str,
        raw: &Option<Vec<RawMark>>,
    ) -> Result<Vec<crate::plot::Mark>, ExperimentError> {
        let mut marks = Vec::new();
        for (i, m) in raw.iter().flatten().enumerate() {
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
        Ok(marks)
    }

    /// A scatter plot's x and y (one metric path each) and scales.
    fn scatter_plot(&self, p: &mut RawPlot, key: &str) -> Result<PlotKind, ExperimentError> {
        let x =
            p.x.clone()
                .ok_or_else(|| self.err(key, "kind `scatter` needs `x` (a metric path)"))?;
        let y = match p.y.take().map(OneOrMany::into_vec) {
            Some(v) if v.len() == 1 => v.into_iter().next().unwrap_or_default(),
            _ => {
                return Err(self.err(format!("{key}.y"), "kind `scatter` needs exactly one `y` metric path"));
            }
        };
        Ok(PlotKind::Scatter {
            x,
            y,
            log_x: p.log_x,
            log_y: p.log_y,
        })
    }

    /// The `[[check]]`s: a path, a tolerance, and an expected value or
    /// bounds (numbers or other paths), with an optional claim.
    pub(super) fn checks(&self, raw: Vec<RawCheck>, sweeps: &[Sweep]) -> Result<Vec<Check>, ExperimentError> {
        let mut checks = Vec::new();
        for (i, c) in raw.into_iter().enumerate() {
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
                filter: self.filter(sweeps, &format!("{key}.where"), &c.filter)?,
                path: c.path,
                expect,
                tolerance,
                claim: c.claim,
            });
        }
        Ok(checks)
    }

    /// The `[[search]]`es, each under its own name.
    pub(super) fn searches(
        &self,
        raw: Vec<crate::experiment::inverse::RawSearch>,
    ) -> Result<Vec<crate::experiment::inverse::Search>, ExperimentError> {
        let mut searches = Vec::new();
        for (i, r) in raw.into_iter().enumerate() {
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
        Ok(searches)
    }
}
