//! An experiment's `[[plot]]`s validated against its sweeps: file names,
//! each kind (line, bars, histogram, scatter) with its axes, filters,
//! ranges, marks and the paper's values. Errors name the entry and its key,
//! with the file's line, as everywhere in [`super::validate`].

use super::outputs::Filter;
use super::raw::*;
use super::validate::Validator;
use super::*;
use crate::experiment::ExperimentError;

impl Validator<'_> {
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
                Some(_) if p.paper.is_none() && p.paper_levels.is_none() => {
                    return Err(self.err(
                        format!("{key}.paper_label"),
                        "names the `paper` values; give `paper` or `paper_levels` too",
                    ));
                }
                Some(l) if l.trim().is_empty() || l.chars().count() > 60 => {
                    return Err(self.err(format!("{key}.paper_label"), "must be 1 to 60 characters"));
                }
                Some(l) => l,
                None => "paper".to_string(),
            };
            if p.paper_levels.is_some() && !matches!(kind, PlotKind::Line { .. }) {
                return Err(self.err(format!("{key}.paper_levels"), "only line plots take `paper_levels`"));
            }
            if p.y_bounds.is_some() && !matches!(kind, PlotKind::Line { .. }) {
                return Err(self.err(format!("{key}.y_bounds"), "only line plots take `y_bounds`"));
            }
            if p.y_axis.is_some() && !matches!(kind, PlotKind::Line { .. }) {
                return Err(self.err(format!("{key}.y_axis"), "only line plots take `y_axis`"));
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
        let range = |b: &Option<Vec<f64>>, name: &str| {
            match b {
            None => Ok(None),
            Some(b) => match b.as_slice() {
                [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi && !(p.log_y && *lo <= 0.0) => Ok(Some((*lo, *hi))),
                _ => Err(self.err(
                    format!("{key}.{name}"),
                    format!("needs [lowest, highest]: two finite numbers, the first below the second (and above 0 on a log axis); got {b:?}"),
                )),
            },
        }
        };
        let y_bounds = range(&p.y_bounds, "y_bounds")?;
        let y_axis = range(&p.y_axis, "y_axis")?;
        let paper = self.paper_values(p, key, sweeps, &x)?;
        let levels = match p.paper_levels.clone() {
            None => Vec::new(),
            Some(v) if v.len() == y.len() && v.iter().all(|l| l.is_finite() && !(p.log_y && *l <= 0.0)) => v,
            Some(v) => {
                return Err(self.err(
                    format!("{key}.paper_levels"),
                    format!(
                        "needs {} finite numbers, one per `y` path{}; got {v:?}",
                        y.len(),
                        if p.log_y { ", each above 0 on a log axis" } else { "" }
                    ),
                ));
            }
        };
        Ok(PlotKind::Line {
            x,
            y,
            log_x: p.log_x,
            log_y: p.log_y,
            filter: f,
            y_bounds,
            y_axis,
            paper,
            levels,
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
        let (marks, marks_above_min) = self.histogram_marks(key, &p.marks)?;
        Ok(PlotKind::Histogram {
            column,
            bins: bins as usize,
            range,
            filter: f,
            marks,
            marks_above_min,
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

    /// A histogram's `marks`: at most 16, each with a label of 1 to 80
    /// characters and either a finite `at` or a finite, non-negative
    /// `above_min` (returned apart, the width in `at`).
    #[allow(clippy::type_complexity)]
    fn histogram_marks(
        &self,
        key: &str,
        raw: &Option<Vec<RawMark>>,
    ) -> Result<(Vec<crate::plot::Mark>, Vec<crate::plot::Mark>), ExperimentError> {
        let (mut marks, mut above) = (Vec::new(), Vec::new());
        for (i, m) in raw.iter().flatten().enumerate() {
            let mkey = format!("{key}.marks.{i}");
            if m.label.trim().is_empty() || m.label.chars().count() > 80 {
                return Err(self.err(format!("{mkey}.label"), "must be 1 to 80 characters"));
            }
            if i >= 16 {
                return Err(self.err(format!("{key}.marks"), "at most 16 marks"));
            }
            let label = m.label.clone();
            match (m.at, m.above_min) {
                (Some(at), None) if at.is_finite() => marks.push(crate::plot::Mark { at, label }),
                (Some(_), None) => return Err(self.err(format!("{mkey}.at"), "must be a finite number")),
                (None, Some(w)) if w.is_finite() && w >= 0.0 => above.push(crate::plot::Mark { at: w, label }),
                (None, Some(_)) => {
                    return Err(self.err(format!("{mkey}.above_min"), "must be a finite number, 0 or more"));
                }
                _ => {
                    return Err(self.err(
                        mkey,
                        "needs `at` (a value) or `above_min` (a width above the lowest value plotted), not both",
                    ));
                }
            }
        }
        Ok((marks, above))
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
}
