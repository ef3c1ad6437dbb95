//! The plots of an experiment, built from point results with [`crate::plot`].

use std::path::Path;

use crate::plot::{Histogram, LinePlot, PlotError, Scatter, ScatterPoint, Series, histogram, line_plot, scatter};

use super::run::PointResult;
use super::spec::{Experiment, PlotKind, PlotSpec};
use super::sweep::Point;

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
        } => {
            let xi = exp.sweeps.iter().position(|s| &s.key == x).unwrap_or(0);
            // Group points by the values of the other sweeps, in first-seen order.
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
            let mut series = Vec::new();
            for path in y {
                let is_derived = exp.derived.iter().any(|d| &d.name == path);
                for (_, members) in &groups {
                    let group_label = points[members[0]]
                        .assignments
                        .iter()
                        .enumerate()
                        .filter(|&(i, (k, _))| i != xi && !filter.iter().any(|(f, _)| f == k))
                        .map(|(i, _)| points[members[0]].plot_assignment(&exp.sweeps, i))
                        .collect::<Vec<_>>()
                        .join(", ");
                    let name = match (group_label.is_empty(), y.len() > 1) {
                        (true, _) => exp.label_of(path),
                        (false, false) => group_label,
                        (false, true) => format!("{} ({group_label})", exp.label_of(path)),
                    };
                    let mut pts = Vec::new();
                    let mut ci = Vec::new();
                    for &m in members {
                        let xv = exp.sweeps[xi].coords[points[m].value_indices[xi]];
                        let r = &results[m];
                        match (is_derived, r.stat(path)) {
                            (false, Some(c)) if c.n > 0 => {
                                pts.push((xv, c.mean));
                                ci.push((c.low, c.high));
                            }
                            _ => {
                                if let Some(v) = r.value(path) {
                                    pts.push((xv, v));
                                    ci.push((v, v));
                                }
                            }
                        }
                    }
                    series.push(Series {
                        name,
                        points: pts,
                        ci: (!is_derived).then_some(ci),
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
                    x_categories: if exp.sweeps[xi].categorical {
                        exp.sweeps[xi]
                            .coords
                            .iter()
                            .copied()
                            .zip(exp.sweeps[xi].labels.iter().cloned())
                            .collect()
                    } else {
                        Vec::new()
                    },
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
        } => {
            let c = columns.iter().position(|k| k == column);
            let values = points
                .iter()
                .filter(|p| p.matches(filter))
                .map(|p| {
                    let v = c.and_then(|c| pooled.get(p.index)?.get(c).cloned()).unwrap_or_default();
                    (p.plot_label(&exp.sweeps), v)
                })
                .collect();
            let h = Histogram {
                title: spec.title.clone(),
                x_label: spec.x_label.clone(),
                values,
                bins: *bins,
                range: *range,
                marks: marks.clone(),
            };
            histogram(&base, &h)?;
            Ok(h.outside_range_notes())
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
