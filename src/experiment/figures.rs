//! The plots of an experiment, built from point results with [`crate::plot`].

use std::path::Path;

use crate::plot::{
    BarChart, BarSeries, Histogram, LinePlot, PlotError, Scatter, ScatterPoint, Series, bar_chart, histogram,
    line_plot, scatter,
};

use super::results::PointResult;
use super::spec::{Experiment, PlotKind, PlotSpec};
use super::sweep::{Point, Sweep};

/// Draw one plot into `out_dir`; returns caption lines for the report (for
/// histograms with a `range`: the values left outside it).
pub(crate) fn draw(
    exp: &Experiment,
    spec: &PlotSpec,
    points: &[Point],
    results: &[PointResult],
    pooled: &[Vec<Vec<f64>>],
    columns: &[String],
    out_dir: &Path,
) -> Result<Vec<String>, PlotError> {
    let base = out_dir.join(&spec.file);
    match &spec.kind {
        PlotKind::Line {
            x,
            y,
            log_x,
            log_y,
            filter,
            y_bounds,
            y_axis,
            paper,
            levels,
        } => {
            let xi = exp.sweeps.iter().position(|s| &s.key == x).unwrap_or(0);
            let groups = line_groups(points, xi, filter);
            let mut series = Vec::new();
            for (k, path) in y.iter().enumerate() {
                let is_derived = exp.derived.iter().any(|d| &d.name == path);
                // The path's published level, named in the legend.
                let level = levels.get(k).copied();
                // Several quantities under several settings: a colour a
                // quantity, a line pattern a setting (up to four).
                let styled = y.len() > 1 && groups.len() > 1 && groups.len() <= 4;
                for (g, (_, members)) in groups.iter().enumerate() {
                    let (pts, ci) = series_points(exp, points, results, xi, path, members);
                    let name = series_name(exp, points, xi, filter, path, y.len() > 1, members);
                    series.push(Series {
                        name: match level {
                            Some(v) => format!("{name} (dashed: {} {v})", spec.paper_label),
                            None => name,
                        },
                        points: pts,
                        ci: (!is_derived).then_some(ci),
                        level,
                        color: styled.then_some(k),
                        pattern: if styled { g as u8 } else { 0 },
                    });
                }
            }
            line_plot(
                &base,
                &LinePlot {
                    title: spec.title.clone(),
                    x_label: spec.x_label.clone(),
                    y_label: spec.y_label.clone(),
                    series,
                    log_x: *log_x,
                    log_y: *log_y,
                    x_categories: x_categories(&exp.sweeps[xi]),
                    y_bounds: *y_bounds,
                    y_axis: *y_axis,
                    reference: paper_reference(exp, points, xi, paper, &spec.paper_label),
                },
            )?;
            Ok(Vec::new())
        }
        PlotKind::Histogram {
            column,
            bins,
            range,
            filter,
            marks,
            marks_above_min,
        } => {
            let c = columns.iter().position(|k| k == column);
            let values: Vec<(String, Vec<f64>)> = points
                .iter()
                .filter(|p| p.matches(filter))
                .map(|p| {
                    let v = c.and_then(|c| pooled.get(p.index)?.get(c).cloned()).unwrap_or_default();
                    (p.plot_label(&exp.sweeps), v)
                })
                .collect();
            let marks = histogram_marks(marks, marks_above_min, &values);
            let h = Histogram {
                title: spec.title.clone(),
                x_label: spec.x_label.clone(),
                values,
                bins: *bins,
                range: *range,
                marks,
            };
            histogram(&base, &h)?;
            Ok(h.outside_range_notes())
        }
        PlotKind::Bars {
            y,
            log_y,
            filter,
            paper,
        } => {
            bar_chart(&base, &bars(exp, spec, points, results, (y, *log_y, filter, paper)))?;
            Ok(Vec::new())
        }
        PlotKind::Scatter { x, y, log_x, log_y } => {
            let pts = results
                .iter()
                .zip(points)
                .filter_map(|(r, p)| {
                    Some(ScatterPoint {
                        label: p.plot_label(&exp.sweeps),
                        x: r.value(x)?,
                        y: r.value(y)?,
                    })
                })
                .collect();
            scatter(
                &base,
                &Scatter {
                    title: spec.title.clone(),
                    x_label: spec.x_label.clone(),
                    y_label: spec.y_label.clone(),
                    points: pts,
                    log_x: *log_x,
                    log_y: *log_y,
                },
            )?;
            Ok(Vec::new())
        }
    }
}

/// A line plot's groups of points (indices), one per combination of the
/// other sweeps' values (all but sweep `xi`), in first-seen order; only
/// the points `filter` keeps.
fn line_groups(points: &[Point], xi: usize, filter: &[(String, toml::Value)]) -> Vec<(Vec<usize>, Vec<usize>)> {
    let mut groups: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
    for p in points.iter().filter(|p| p.matches(filter)) {
        let key: Vec<usize> = p
            .value_indices
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != xi)
            .map(|(_, &v)| v)
            .collect();
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1.push(p.index),
            None => groups.push((key, vec![p.index])),
        }
    }
    groups
}

/// A line series' name: the metric's label, the group's other sweep values
/// (those neither on the x axis nor fixed by `filter`), or both when the
/// plot has several metrics (`multi`).
fn series_name(
    exp: &Experiment,
    points: &[Point],
    xi: usize,
    filter: &[(String, toml::Value)],
    path: &str,
    multi: bool,
    members: &[usize],
) -> String {
    let group_label = points[members[0]]
        .assignments
        .iter()
        .enumerate()
        .filter(|&(i, (k, _))| i != xi && !filter.iter().any(|(f, _)| f == k))
        .map(|(i, _)| points[members[0]].plot_assignment(&exp.sweeps, i))
        .collect::<Vec<_>>()
        .join(", ");
    match (group_label.is_empty(), multi) {
        (true, _) => exp.label_of(path),
        (false, false) => group_label,
        (false, true) => format!("{} ({group_label})", exp.label_of(path)),
    }
}

/// A line series' points `(x, value)` over the group's `members`, with
/// each point's interval (a derived value's is the value itself).
#[allow(clippy::type_complexity)]
fn series_points(
    exp: &Experiment,
    points: &[Point],
    results: &[PointResult],
    xi: usize,
    path: &str,
    members: &[usize],
) -> (Vec<(f64, f64)>, Vec<(f64, f64)>) {
    let is_derived = exp.derived.iter().any(|d| d.name == path);
    let mut pts = Vec::new();
    let mut ci = Vec::new();
    for &m in members {
        let xv = exp.sweeps[xi].coords[points[m].value_indices[xi]];
        if let Some((v, interval)) = mean_and_interval(&results[m], path, is_derived) {
            pts.push((xv, v));
            ci.push(interval);
        }
    }
    (pts, ci)
}

/// A point's value of `path` and its interval: the replication mean and
/// its confidence interval, or a derived (or single) value as its own
/// interval; `None` when the point has no value.
fn mean_and_interval(r: &PointResult, path: &str, is_derived: bool) -> Option<(f64, (f64, f64))> {
    match (is_derived, r.stat(path)) {
        (false, Some(c)) if c.n > 0 => Some((c.mean, (c.low, c.high))),
        _ => r.value(path).map(|v| (v, (v, v))),
    }
}

/// A bar plot: one group per `y` path, a bar per kept point (its mean,
/// with its interval), each followed by the `paper` entries that select it
/// (a tint of its colour); entries for points the filter left out come
/// last, named after the first point they select.
#[allow(clippy::type_complexity)]
fn bars(
    exp: &Experiment,
    spec: &PlotSpec,
    points: &[Point],
    results: &[PointResult],
    (y, log_y, filter, paper): (&[String], bool, &[(String, toml::Value)], &[super::spec::PaperValues]),
) -> BarChart {
    let mut series = Vec::new();
    let mut drawn = vec![false; paper.len()];
    for p in points.iter().filter(|p| p.matches(filter)) {
        let r = &results[p.index];
        let (values, ci): (Vec<f64>, Vec<(f64, f64)>) = y
            .iter()
            .map(|path| {
                let is_derived = exp.derived.iter().any(|d| &d.name == path);
                mean_and_interval(r, path, is_derived).unwrap_or((f64::NAN, (f64::NAN, f64::NAN)))
            })
            .unzip();
        let label = label_without(exp, p, filter);
        series.push(BarSeries {
            name: format!("{label} (simulated)"),
            values,
            ci: Some(ci),
            tint_of_previous: false,
        });
        // The paper's values for this point, beside it in a tint of its
        // colour, named by what its `where` fixes (the paper has one value
        // there, whatever the sweeps it leaves free).
        for (i, v) in paper.iter().enumerate() {
            if !drawn[i] && p.matches(&v.filter) {
                drawn[i] = true;
                series.push(BarSeries {
                    name: format!("{} ({})", label_of_keys(exp, p, &v.filter, filter), spec.paper_label),
                    values: v.values.clone(),
                    ci: None,
                    tint_of_previous: true,
                });
            }
        }
    }
    // Paper entries for points the filter left out.
    for (i, v) in paper.iter().enumerate().filter(|(i, _)| !drawn[*i]) {
        let name = points.iter().find(|p| p.matches(&v.filter)).map_or_else(
            || format!("{} {}", spec.paper_label, i + 1),
            |p| format!("{} ({})", label_of_keys(exp, p, &v.filter, &[]), spec.paper_label),
        );
        series.push(BarSeries {
            name,
            values: v.values.clone(),
            ci: None,
            tint_of_previous: false,
        });
    }
    BarChart {
        title: spec.title.clone(),
        y_label: spec.y_label.clone(),
        categories: y.iter().map(|p| exp.label_of(p)).collect(),
        series,
        log_y,
    }
}

/// Whether `filter` fixes the sweep key `k`.
fn fixes(filter: &[(String, toml::Value)], k: &str) -> bool {
    filter.iter().any(|(f, _)| f == k)
}

/// `p`'s assignments whose key `keep` accepts, in words, joined; `None`
/// when it accepts none.
fn label_of(exp: &Experiment, p: &Point, keep: impl Fn(&str) -> bool) -> Option<String> {
    let parts: Vec<String> = p
        .assignments
        .iter()
        .enumerate()
        .filter(|(_, (k, _))| keep(k))
        .map(|(i, _)| p.plot_assignment(&exp.sweeps, i))
        .collect();
    (!parts.is_empty()).then(|| parts.join(", "))
}

/// `p`'s label from the keys `keys` fixes, less those `filter` fixes (the
/// plot's own filter, said in its title); [`label_without`] when that
/// leaves nothing.
fn label_of_keys(
    exp: &Experiment,
    p: &Point,
    keys: &[(String, toml::Value)],
    filter: &[(String, toml::Value)],
) -> String {
    label_of(exp, p, |k| fixes(keys, k) && !fixes(filter, k)).unwrap_or_else(|| label_without(exp, p, filter))
}

/// A point's plot label without the keys `filter` fixes (they are the
/// same for every bar); the whole label when that leaves nothing.
fn label_without(exp: &Experiment, p: &Point, filter: &[(String, toml::Value)]) -> String {
    label_of(exp, p, |k| !fixes(filter, k)).unwrap_or_else(|| p.plot_label(&exp.sweeps))
}

/// A line plot's published values as crosses: each at the x of the first
/// point its `where` selects (none when it selects no point).
fn paper_reference(
    exp: &Experiment,
    points: &[Point],
    xi: usize,
    paper: &[super::spec::PaperValue],
    label: &str,
) -> Option<crate::plot::Reference> {
    let pts: Vec<(f64, f64)> = paper
        .iter()
        .filter_map(|v| {
            let p = points.iter().find(|p| p.matches(&v.filter))?;
            Some((exp.sweeps[xi].coords[p.value_indices[xi]], v.value))
        })
        .collect();
    (!pts.is_empty()).then(|| crate::plot::Reference {
        label: label.into(),
        points: pts,
    })
}

/// The x axis's categories (coordinate, label) of a categorical sweep
/// (none for a numeric one).
fn x_categories(sweep: &Sweep) -> Vec<(f64, String)> {
    if sweep.categorical {
        sweep.coords.iter().copied().zip(sweep.labels.iter().cloned()).collect()
    } else {
        Vec::new()
    }
}

/// A histogram's marks: those at a value, then those at a width above the
/// lowest finite value plotted (over every group; with no values there is
/// no minimum, and no such mark).
pub(crate) fn histogram_marks(
    at: &[crate::plot::Mark],
    above_min: &[crate::plot::Mark],
    values: &[(String, Vec<f64>)],
) -> Vec<crate::plot::Mark> {
    let lowest = values
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    let mut marks = at.to_vec();
    if lowest.is_finite() {
        marks.extend(above_min.iter().map(|m| crate::plot::Mark {
            at: lowest + m.at,
            label: m.label.clone(),
        }));
    }
    marks
}
