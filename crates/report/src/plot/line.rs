//! Line plots: one or more series with optional confidence-interval bars.

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::PlotError;
use super::axis::{TickedAxis, Ticks, all_integers, coord, omitted_note, padded_range, ticks, to_axis};
use super::font::{AXIS_PX, FAMILY, TICK_PX, TITLE_PX};
use super::legend::{self, Occupied};
use super::output::{Sink, draw_notes, render_to, svg_of};
use super::palette::color;

/// One named series of a [`LinePlot`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Legend entry (empty: no legend entry).
    pub name: String,
    /// `(x, y)` points; drawn in ascending `x` order.
    pub points: Vec<(f64, f64)>,
    /// Optional `(low, high)` interval per point, same length as `points`,
    /// drawn as vertical error bars.
    pub ci: Option<Vec<(f64, f64)>>,
    /// A published value for this series (a paper's number, independent of
    /// x): a thin dashed horizontal line in the series' colour across the
    /// plot. Not drawn where the y axis cannot show it (not finite, or not
    /// positive on a logarithmic axis; counted in the omitted note).
    pub level: Option<f64>,
    /// Its colour, an index into the palette (`None`: the series' own
    /// place in the plot). Series of one quantity share a colour.
    pub color: Option<usize>,
    /// Its line: 0 solid; 1, 2, 3 dashes ever shorter (the same quantity
    /// under a second, third, fourth setting, in its colour).
    pub pattern: u8,
}

/// A line plot description.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinePlot {
    /// Title above the plot.
    pub title: String,
    /// X axis description.
    pub x_label: String,
    /// Y axis description.
    pub y_label: String,
    /// The series, each in its own colour.
    pub series: Vec<Series>,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Categorical x axis: `(x, label)` per category. When not empty the x
    /// axis has one tick per category, labelled with its text, instead of
    /// numeric ticks (e.g. resolutions `1024x768`, `1280x1024` drawn at
    /// their indices 0 and 1). Ignored on a logarithmic x axis.
    pub x_categories: Vec<(f64, String)>,
    /// The values the quantity can take, `(lowest, highest)` (a fraction:
    /// `(0, 1)`): intervals are cut there, so the y axis never runs past
    /// what the data could be. `None`: unbounded.
    pub y_bounds: Option<(f64, f64)>,
    /// The y axis's range, drawn whole whatever the data (`None`: the
    /// data's, padded): an axis from 0, so that a difference of a few
    /// percent looks like one. Points outside it are clipped.
    pub y_axis: Option<(f64, f64)>,
    /// Published values to compare with (a paper's numbers): drawn as black
    /// crosses without a line, one legend entry.
    pub reference: Option<Reference>,
}

/// Reference values drawn on a [`LinePlot`]: points in data coordinates
/// and their legend entry (e.g. `paper`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Reference {
    /// Legend entry.
    pub label: String,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
}

/// The ticks of a categorical x axis (positions ascending, labels distinct)
/// and its range, half a category wider than the outer ones on each side.
fn category_ticks(cats: &[(f64, String)]) -> (Ticks, (f64, f64)) {
    let mut c: Vec<(f64, String)> = cats.iter().filter(|c| c.0.is_finite()).cloned().collect();
    c.sort_by(|a, b| a.0.total_cmp(&b.0));
    c.dedup_by(|a, b| a.0 == b.0 || a.1 == b.1);
    let lo = c.first().map_or(0.0, |c| c.0);
    let hi = c.last().map_or(1.0, |c| c.0);
    let step = c.windows(2).map(|w| w[1].0 - w[0].0).fold(f64::INFINITY, f64::min);
    let pad = if step.is_finite() { step / 2.0 } else { 0.5 };
    let ticks = Ticks {
        positions: c.iter().map(|c| c.0).collect(),
        labels: c.into_iter().map(|c| c.1).collect(),
        minor: Vec::new(),
    };
    (ticks, (lo - pad, hi + pad))
}

/// A series mapped to axis coordinates.
struct Prepared {
    name: String,
    /// Reference values: crosses, no line.
    reference: bool,
    points: Vec<(f64, f64)>,
    /// `(x, low, y, high)` per point that has an interval.
    bars: Vec<(f64, f64, f64, f64)>,
    /// The series' published level, in axis coordinates.
    level: Option<f64>,
    /// Palette index.
    color: usize,
    /// Line pattern ([`Series::pattern`]).
    pattern: u8,
}

/// Cuts every interval at `bounds` (the values the quantity can take), so
/// that the y axis, fitted to points and intervals, stays within them.
fn bound_bars(series: &mut [Prepared], bounds: Option<(f64, f64)>) {
    if let Some((lo, hi)) = bounds.filter(|(lo, hi)| lo < hi) {
        for b in series.iter_mut().flat_map(|s| s.bars.iter_mut()) {
            (b.1, b.3) = (b.1.clamp(lo, hi), b.3.clamp(lo, hi));
        }
    }
}

fn prepare(plot: &LinePlot) -> (Vec<Prepared>, usize) {
    let mut dropped = 0;
    let mut out = Vec::new();
    for s in &plot.series {
        let mut rows = Vec::new();
        for (i, &(x, y)) in s.points.iter().enumerate() {
            match (to_axis(x, plot.log_x), to_axis(y, plot.log_y)) {
                (Some(ax), Some(ay)) => {
                    let ci =
                        s.ci.as_ref()
                            .and_then(|c| c.get(i))
                            .and_then(|&(lo, hi)| Some((to_axis(lo, plot.log_y)?, to_axis(hi, plot.log_y)?)));
                    rows.push((ax, ay, ci));
                }
                _ => dropped += 1,
            }
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let level = s.level.and_then(|v| {
            let a = to_axis(v, plot.log_y);
            dropped += usize::from(a.is_none());
            a
        });
        out.push(Prepared {
            name: s.name.clone(),
            reference: false,
            level,
            color: s.color.unwrap_or(out.len()),
            pattern: s.pattern,
            points: rows.iter().map(|r| (r.0, r.1)).collect(),
            bars: rows
                .iter()
                .filter_map(|r| r.2.map(|(lo, hi)| (r.0, lo.min(r.1), r.1, hi.max(r.1))))
                .collect(),
        });
    }
    if let Some(r) = &plot.reference {
        let mut pts: Vec<(f64, f64)> = Vec::new();
        for &(x, y) in &r.points {
            match (to_axis(x, plot.log_x), to_axis(y, plot.log_y)) {
                (Some(ax), Some(ay)) => pts.push((ax, ay)),
                _ => dropped += 1,
            }
        }
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        if !pts.is_empty() {
            out.push(Prepared {
                name: r.label.clone(),
                reference: true,
                points: pts,
                bars: Vec::new(),
                level: None,
                color: 0,
                pattern: 0,
            });
        }
    }
    (out, dropped)
}

/// Whether two series draw the same curve (same x, y within 1e-9 relative).
fn coincide(a: &Prepared, b: &Prepared) -> bool {
    !a.reference
        && !b.reference
        && !a.points.is_empty()
        && a.points.len() == b.points.len()
        && a.points
            .iter()
            .zip(&b.points)
            .all(|(p, q)| p.0 == q.0 && (p.1 - q.1).abs() <= 1e-9 * p.1.abs().max(q.1.abs()).max(1e-300))
}

/// Where series `b` runs on top of series `a` without coinciding with it
/// everywhere: the x ranges (each a run of adjacent segments) of the
/// segments of `b` whose two ends are also two consecutive points of `a`
/// (same x, y within `tol`), so that `a` hides them. Empty when no
/// segment is hidden.
fn overlap(a: &Prepared, b: &Prepared, tol: f64) -> Vec<(f64, f64)> {
    if a.reference || b.reference {
        return Vec::new();
    }
    let same = |p: &(f64, f64), q: &(f64, f64)| p.0 == q.0 && (p.1 - q.1).abs() <= tol;
    let mut ranges: Vec<(f64, f64)> = Vec::new();
    for w in b.points.windows(2) {
        if !a.points.windows(2).any(|v| same(&v[0], &w[0]) && same(&v[1], &w[1])) {
            continue;
        }
        match ranges.last_mut() {
            Some(last) if last.1 == w[0].0 => last.1 = w[1].0,
            _ => ranges.push((w[0].0, w[1].0)),
        }
    }
    ranges
}

/// Series `k`'s name in a note ("series k+1" when it has none).
fn series_name(series: &[Prepared], k: usize) -> String {
    match series[k].name.as_str() {
        "" => format!("series {}", k + 1),
        n => n.to_string(),
    }
}

/// A number for a note: at most four significant digits, no trailing zeros.
fn short(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e5) {
        return format!("{x:.3e}");
    }
    let digits = (3 - x.abs().max(1e-300).log10().floor() as i32).clamp(0, 6) as usize;
    let t = format!("{x:.digits$}");
    if t.contains('.') {
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        t
    }
}

/// For each series, the earlier series it coincides with, if any.
fn coinciding(series: &[Prepared]) -> Vec<Option<usize>> {
    series
        .iter()
        .enumerate()
        .map(|(i, s)| (0..i).find(|&j| coincide(&series[j], s)))
        .collect()
}

/// The legend corner covering the fewest drawn points, and how many it
/// covers ([`super::legend::corner`]): each segment is sampled, and the box
/// is as wide as the longest name and a line per entry high.
fn legend_corner(series: &[Prepared], xr: (f64, f64), yr: (f64, f64), entries: usize) -> (SeriesLabelPosition, usize) {
    let (w, h) = (xr.1 - xr.0, yr.1 - yr.0);
    if !(w > 0.0 && h > 0.0) {
        return (SeriesLabelPosition::UpperLeft, 0);
    }
    let occupied = occupied(series, xr, yr);
    let (bw, bh) = legend_box(series, entries);
    legend::corner(&occupied, bw, bh)
}

/// The legend box's size for these series (plot-area fractions).
fn legend_box(series: &[Prepared], entries: usize) -> (f64, f64) {
    let longest = series.iter().map(|s| s.name.chars().count()).max().unwrap_or(0);
    legend::legend_size(entries, longest)
}

/// The drawn points and samples of every segment, in plot-area fractions.
fn occupied(series: &[Prepared], xr: (f64, f64), yr: (f64, f64)) -> Vec<Occupied> {
    let (w, h) = (xr.1 - xr.0, yr.1 - yr.0);
    let mut samples = Vec::new();
    let at = |x: f64, y: f64| Occupied::point((x - xr.0) / w, (y - yr.0) / h);
    for s in series {
        for p in &s.points {
            samples.push(at(p.0, p.1));
        }
        for p in s.points.windows(2).filter(|_| !s.reference) {
            for k in 1..10 {
                let t = k as f64 / 10.0;
                samples.push(at(p[0].0 + t * (p[1].0 - p[0].0), p[0].1 + t * (p[1].1 - p[0].1)));
            }
        }
        for b in &s.bars {
            samples.push(Occupied {
                x: (b.0 - xr.0) / w,
                y0: (b.1 - yr.0) / h,
                y1: (b.3 - yr.0) / h,
            });
        }
        if let Some(l) = s.level {
            for k in 0..=20 {
                samples.push(at(xr.0 + w * k as f64 / 20.0, l));
            }
        }
    }
    samples
}

/// Where the legend goes: a corner free of data; when every corner has
/// some, the y axis (`yr`) grows by the legend's height so that the top is
/// free, or, for a bounded quantity, the middle of an edge if that covers
/// fewer points. With `beside` (a legend of many entries, drawn in a panel
/// next to the plot) the corner is unused and the axis kept.
fn place_legend(
    plot: &LinePlot,
    series: &[Prepared],
    xr: (f64, f64),
    yr: &mut (f64, f64),
    entries: usize,
    beside: bool,
) -> SeriesLabelPosition {
    let (mut legend, covered) = legend_corner(series, xr, *yr, entries);
    if covered == 0 || beside {
        return legend;
    }
    let (bw, bh) = legend_box(series, entries);
    if plot.y_bounds.is_some_and(|(lo, hi)| lo < hi) || plot.y_axis.is_some() {
        // A bounded quantity (a fraction), or an axis given, keeps its axis: the legend goes
        // to the middle of an edge if that covers fewer points.
        let (m, n) = legend::middle(&occupied(series, xr, *yr), bw, bh);
        if n < covered {
            legend = m;
        }
    } else {
        *yr = legend::grow(*yr, bh);
        // The top band is free now: the upper corner the box fits best.
        let occ = occupied(series, xr, *yr);
        legend = if legend::covered(&occ, true, true, bw, bh) < legend::covered(&occ, false, true, bw, bh) {
            SeriesLabelPosition::UpperLeft
        } else {
            SeriesLabelPosition::UpperRight
        };
    }
    legend
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &LinePlot,
    series: &[Prepared],
    notes: &[String],
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let categorical = !plot.x_categories.is_empty() && !plot.log_x;
    let mut xr = padded_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let mut yr = padded_range(series.iter().flat_map(|s| {
        s.points
            .iter()
            .map(|p| p.1)
            .chain(s.bars.iter().flat_map(|b| [b.1, b.3]))
            .chain(s.level)
    }));
    // Integer x data (frame counts, buffer counts, ...) gets whole-number ticks.
    let x_integer = all_integers(plot.series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let xt = if categorical {
        let (t, r) = category_ticks(&plot.x_categories);
        xr = r;
        t
    } else {
        ticks(xr.0, xr.1, plot.log_x, x_integer)
    };
    let entries = series.iter().filter(|s| !s.name.is_empty()).count();
    let beside = entries > legend::IN_PLOT_ENTRIES;
    if let Some(axis) = plot.y_axis {
        yr = axis;
    }
    let legend = place_legend(plot, series, xr, &mut yr, entries, beside);
    let yt = ticks(yr.0, yr.1, plot.log_y, false);
    let panel_w = if beside {
        let names: Vec<String> = series
            .iter()
            .filter(|s| !s.name.is_empty())
            .map(|s| s.name.clone())
            .collect();
        legend::panel_width(root, &names, &legend_font(), SWATCH_PX)
    } else {
        0
    };
    // With a panel the title spans the whole image, above plot and panel.
    let body = if beside {
        root.titled(&plot.title, (FAMILY, TITLE_PX)).map_err(e)?
    } else {
        root.clone()
    };
    let (area, panel) = body.split_horizontally(body.dim_in_pixel().0 as i32 - panel_w);
    let mut builder = ChartBuilder::on(&area);
    if !beside {
        builder.caption(&plot.title, (FAMILY, TITLE_PX));
    }
    let mut chart = builder
        .margin(20)
        .margin_bottom(20 + 16 * notes.len() as u32)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(coord(xr.0, xr.1, &xt), coord(yr.0, yr.1, &yt))
        .map_err(e)?;
    let fx = |v: &f64| xt.label_at(*v);
    let fy = |v: &f64| yt.label_at(*v);
    chart
        .configure_mesh()
        .x_desc(plot.x_label.as_str())
        .y_desc(plot.y_label.as_str())
        .label_style((FAMILY, TICK_PX))
        .axis_desc_style((FAMILY, AXIS_PX))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .draw()
        .map_err(e)?;
    let mut any_legend = false;
    let twins = coinciding(series);
    // On a categorical axis the series stand side by side within each
    // category (dodged), so equal values do not hide one another.
    let drawn: Vec<usize> = (0..series.len()).filter(|&i| !series[i].reference).collect();
    let dodge = |i: usize| match drawn.iter().position(|&d| d == i) {
        Some(k) if categorical && drawn.len() > 1 => {
            let step = (0.5 / drawn.len() as f64).min(0.08);
            (k as f64 - (drawn.len() - 1) as f64 / 2.0) * step
        }
        _ => 0.0,
    };
    for (i, s) in series.iter().enumerate() {
        let how = Placement {
            twin: twins[i].is_some(),
            categorical,
            dx: dodge(i),
            xr,
        };
        any_legend |= draw_one(&mut chart, s, how)?;
    }
    if any_legend && beside {
        draw_legend_beside(&panel, series, &twins).map_err(e)?;
    } else if any_legend {
        chart
            .configure_series_labels()
            .label_font((FAMILY, TICK_PX))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(legend)
            .draw()
            .map_err(e)?;
    }
    draw_notes(root, notes)
}

/// Where and how one series is drawn: over an earlier one (`twin`), on a
/// categorical axis, shifted by `dx` within its category, across `xr`.
#[derive(Clone, Copy)]
struct Placement {
    twin: bool,
    categorical: bool,
    dx: f64,
    xr: (f64, f64),
}

/// Draws one series (its level, line or points, markers and intervals);
/// returns whether it made a legend entry.
fn draw_one<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<TickedAxis, TickedAxis>>,
    s: &Prepared,
    how: Placement,
) -> Result<bool, String> {
    let mut legend = false;
    if s.reference {
        let cross = |p: (f64, f64)| EmptyElement::at(p) + Cross::new((0, 0), 6, BLACK.stroke_width(2));
        let marks = chart
            .draw_series(s.points.iter().map(|&p| cross(p)))
            .map_err(|e| e.to_string())?;
        if !s.name.is_empty() {
            legend = true;
            marks
                .label(s.name.as_str())
                .legend(move |(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
        }
        return Ok(legend);
    }
    let c = color(s.color);
    if let Some(l) = s.level {
        chart
            .draw_series(DashedLineSeries::new(
                [(how.xr.0, l), (how.xr.1, l)],
                10,
                6,
                c.stroke_width(1),
            ))
            .map_err(|e| e.to_string())?;
    }
    // On a how.categorical axis (architectures, policies) nothing lies
    // between two categories: the points stand alone, no line joins them.
    if how.categorical {
        let marks = chart
            .draw_series(
                s.points
                    .iter()
                    .map(|&(x, y)| Circle::new((x + how.dx, y), 5, c.filled())),
            )
            .map_err(|e| e.to_string())?;
        if !s.name.is_empty() {
            legend = true;
            marks
                .label(s.name.as_str())
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, c.filled()));
        }
    }
    // A series drawn exactly over an earlier one is dashed, with open
    // square markers, so that both stay visible (and a note says so).
    let line = if how.categorical {
        None
    } else if how.twin {
        Some(
            chart
                .draw_series(DashedLineSeries::new(s.points.iter().copied(), 8, 6, c.stroke_width(2)))
                .map_err(|e| e.to_string())?,
        )
    } else if let Some((dash, gap)) = dashes(s.pattern) {
        Some(
            chart
                .draw_series(DashedLineSeries::new(
                    s.points.iter().copied(),
                    dash,
                    gap,
                    c.stroke_width(2),
                ))
                .map_err(|e| e.to_string())?,
        )
    } else {
        Some(
            chart
                .draw_series(LineSeries::new(s.points.iter().copied(), c.stroke_width(2)))
                .map_err(|e| e.to_string())?,
        )
    };
    if let Some(line) = line
        && !s.name.is_empty()
    {
        legend = true;
        let pattern = s.pattern;
        line.label(s.name.as_str())
            .legend(move |(x, y)| swatch((x, y), pattern, c));
    }
    if how.twin {
        chart
            .draw_series(s.points.iter().map(|&(x, y)| {
                EmptyElement::at((x + how.dx, y)) + Rectangle::new([(-6, -6), (6, 6)], c.stroke_width(2))
            }))
            .map_err(|e| e.to_string())?;
    } else if !how.categorical {
        chart
            .draw_series(s.points.iter().map(|&p| Circle::new(p, 3, c.filled())))
            .map_err(|e| e.to_string())?;
    }
    chart
        .draw_series(
            s.bars
                .iter()
                .map(|&(x, lo, y, hi)| ErrorBar::new_vertical(x + how.dx, lo, y, hi, c.stroke_width(1), 8)),
        )
        .map_err(|e| e.to_string())?;
    Ok(legend)
}

/// A line pattern's (dash, gap) in pixels; `None` for a solid line.
fn dashes(pattern: u8) -> Option<(u32, u32)> {
    match pattern {
        0 => None,
        1 => Some((10, 5)),
        2 => Some((4, 4)),
        _ => Some((2, 6)),
    }
}

/// A legend swatch 20 pixels long from `(x, y)` in the series' pattern
/// (a dash longer than the swatch for a solid line).
fn swatch((x, y): (i32, i32), pattern: u8, c: RGBColor) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, u32> {
    let (dash, gap) = dashes(pattern).unwrap_or((24, 1));
    DashedPathElement::new(vec![(x, y), (x + 20, y)], dash, gap, c.stroke_width(2))
}

/// Width of a legend row's swatch (line, dash or cross) and its gap.
const SWATCH_PX: i32 = 32;

fn legend_font() -> TextStyle<'static> {
    (FAMILY, TICK_PX).into_font().into()
}

/// The legend as a column in `panel`, beside the plot: each named series'
/// swatch as the plot draws it (a cross for published values, a dashed
/// line for one drawn over another, a line otherwise) and its name,
/// shortened to fit; what the panel cannot hold is counted in a last row.
fn draw_legend_beside<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    series: &[Prepared],
    twins: &[Option<usize>],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    let font = legend_font().pos(Pos::new(HPos::Left, VPos::Center));
    let (w, h) = panel.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    // A row per entry, from the plot area's top (the panel starts below
    // the title).
    let (top, row) = (30, 20);
    let named: Vec<usize> = (0..series.len()).filter(|&i| !series[i].name.is_empty()).collect();
    let fits = ((h - top - 20) / row).max(1) as usize;
    let shown = if named.len() > fits { fits - 1 } else { named.len() };
    for (n, &i) in named.iter().take(shown).enumerate() {
        let y = top + row * n as i32;
        let c = color(series[i].color);
        if series[i].reference {
            panel.draw(&Cross::new((14, y), 6, BLACK.stroke_width(2)))?;
        } else if twins[i].is_some() {
            panel.draw(&PathElement::new(vec![(4, y), (10, y)], c.stroke_width(2)))?;
            panel.draw(&PathElement::new(vec![(16, y), (24, y)], c.stroke_width(2)))?;
        } else {
            panel.draw(&swatch((4, y), series[i].pattern, c))?;
        }
        let text = legend::fit_text(panel, &series[i].name, &font, w - SWATCH_PX - 4)?;
        panel.draw_text(&text, &font, (SWATCH_PX, y))?;
    }
    if shown < named.len() {
        let y = top + row * shown as i32;
        panel.draw_text(&format!("… and {} more", named.len() - shown), &font, (SWATCH_PX, y))?;
    }
    Ok(())
}

/// Write `plot` to `<base>.svg` and `<base>.png`.
pub fn line_plot(base: &Path, plot: &LinePlot) -> Result<(), PlotError> {
    line_plot_to(Sink::Files(base), plot)
}

/// `plot` as one SVG document (what [`line_plot`] writes to `<base>.svg`).
pub fn line_plot_svg(plot: &LinePlot) -> Result<String, PlotError> {
    svg_of(|sink| line_plot_to(sink, plot))
}

fn line_plot_to(sink: Sink<'_>, plot: &LinePlot) -> Result<(), PlotError> {
    let (mut series, dropped) = prepare(plot);
    bound_bars(&mut series, plot.y_bounds);
    let mut notes: Vec<String> = omitted_note(dropped, plot.log_x || plot.log_y).into_iter().collect();
    if series.iter().all(|s| s.points.is_empty()) {
        notes.push("note: no data".into());
    }
    let name = |k: usize| series_name(&series, k);
    let twins = coinciding(&series);
    for (i, twin) in twins.iter().enumerate() {
        if let &Some(j) = twin {
            notes.push(format!("note: {} coincides with {} (drawn dashed)", name(i), name(j)));
        }
    }
    // Series that share part of their curve: the hidden part is named. On
    // the plot, "the same" is within 0.2% of the data's y span (under a
    // pixel of the plotting area).
    let ys = series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
    let (y_lo, y_hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| (lo.min(y), hi.max(y)));
    let tol = if y_hi > y_lo { 2e-3 * (y_hi - y_lo) } else { 0.0 };
    for i in 0..series.len() {
        if twins[i].is_some() {
            continue;
        }
        for j in 0..i {
            let hidden = overlap(&series[j], &series[i], tol);
            if !hidden.is_empty() {
                // Back from the axis's coordinate to the data's.
                let data = |x: f64| if plot.log_x { 10f64.powf(x) } else { x };
                let spans: Vec<String> = hidden
                    .iter()
                    .map(|&(lo, hi)| format!("{} to {}", short(data(lo)), short(data(hi))))
                    .collect();
                notes.push(format!(
                    "note: {} lies on {} from x = {}",
                    name(i),
                    name(j),
                    spans.join(" and from ")
                ));
                break;
            }
        }
    }
    render_to(
        sink,
        |r| draw(r, plot, &series, &notes),
        |r| draw(r, plot, &series, &notes),
    )
}

#[cfg(test)]
mod tests {
    use super::super::output::test_support::assert_plot_files;
    use super::*;

    fn prepared(name: &str, points: &[(f64, f64)]) -> Prepared {
        Prepared {
            name: name.into(),
            reference: false,
            points: points.to_vec(),
            bars: Vec::new(),
            level: None,
            color: 0,
            pattern: 0,
        }
    }

    #[test]
    fn a_series_level_is_kept_where_the_axis_can_show_it() {
        let plot = |level, log_y| LinePlot {
            series: vec![Series {
                name: "h1".into(),
                points: vec![(1.0, 1.0), (2.0, 2.0)],
                ci: None,
                level: Some(level),
                ..Default::default()
            }],
            log_y,
            ..Default::default()
        };
        let (s, dropped) = prepare(&plot(10.0, false));
        assert_eq!((s[0].level, dropped), (Some(10.0), 0));
        // On a log axis the level is in log10 units, and a level of 0
        // cannot be shown: left out and counted.
        let (s, _) = prepare(&plot(100.0, true));
        assert_eq!(s[0].level, Some(2.0));
        let (s, dropped) = prepare(&plot(0.0, true));
        assert_eq!((s[0].level, dropped), (None, 1));
        // A level far above the data is inside the drawn range: the
        // legend's corner search sees the line.
        let (s, _) = prepare(&plot(10.0, false));
        let occ = occupied(&s, (0.0, 3.0), (0.0, 11.0));
        assert!(
            occ.iter().any(|o| (o.y0 - 10.0 / 11.0).abs() < 1e-9),
            "the level's samples"
        );
    }

    #[test]
    fn intervals_are_cut_at_the_bounds_and_the_points_are_kept() {
        let mut s = vec![Prepared {
            name: "share".into(),
            reference: false,
            points: vec![(1.0, 0.5), (2.0, 0.9)],
            bars: vec![(1.0, -0.4, 0.5, 1.6), (2.0, 0.8, 0.9, 1.0)],
            level: None,
            color: 0,
            pattern: 0,
        }];
        bound_bars(&mut s, None);
        assert_eq!(s[0].bars[0], (1.0, -0.4, 0.5, 1.6));
        bound_bars(&mut s, Some((1.0, 0.0)));
        assert_eq!(s[0].bars[0], (1.0, -0.4, 0.5, 1.6), "empty bounds are ignored");
        bound_bars(&mut s, Some((0.0, 1.0)));
        assert_eq!(s[0].bars, vec![(1.0, 0.0, 0.5, 1.0), (2.0, 0.8, 0.9, 1.0)]);
        assert_eq!(s[0].points, vec![(1.0, 0.5), (2.0, 0.9)]);
    }

    #[test]
    fn the_legend_goes_to_the_emptiest_corner() {
        // A curve rising from the lower left to the upper right leaves the
        // upper left and lower right free; the upper left wins the tie.
        let rising = prepared("a", &[(0.0, 0.0), (10.0, 10.0)]);
        let r = ((0.0, 10.0), (0.0, 10.0));
        assert!(matches!(
            legend_corner(&[rising], r.0, r.1, 1),
            (SeriesLabelPosition::UpperLeft, 0)
        ));
        // A curve high on the left: the lower right is free.
        let falling = prepared("b", &[(0.0, 10.0), (10.0, 9.0)]);
        let high_left = prepared("c", &[(0.0, 0.5), (10.0, 9.5)]);
        let p = legend_corner(&[falling, high_left], r.0, r.1, 2);
        assert!(matches!(p, (SeriesLabelPosition::LowerRight, 0)), "{p:?}");
        // Data in every corner: the fewest covered is reported, not zero.
        let zigzag = prepared(
            "a zigzag with a long name",
            &[(0.0, 0.0), (1.0, 10.0), (9.0, 0.0), (10.0, 10.0)],
        );
        assert!(legend_corner(&[zigzag], r.0, r.1, 1).1 > 0);
    }

    #[test]
    fn the_legend_covers_no_data_after_layout() {
        // bottleneck-share: geometry falls from 1 to 0 while fragment rises
        // and the front end stays near 0, so curves touch every corner.
        let xs: Vec<f64> = (0..14).map(|i| -1.0 + i as f64 * 0.25).collect();
        let geometry = prepared(
            "geometry bottleneck share",
            &xs.iter()
                .map(|&x| (x, 1.0 / (1.0 + (4.0 * (x - 1.2)).exp())))
                .collect::<Vec<_>>(),
        );
        let fragment = prepared(
            "fragment bottleneck share",
            &xs.iter()
                .map(|&x| (x, 1.0 - 1.0 / (1.0 + (4.0 * (x - 1.2)).exp())))
                .collect::<Vec<_>>(),
        );
        let front = prepared(
            "front-end bottleneck share",
            &xs.iter().map(|&x| (x, 0.01)).collect::<Vec<_>>(),
        );
        let series = [geometry, fragment, front];
        let xr = padded_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
        let yr = padded_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
        let (bw, bh) = legend_box(&series, 3);
        assert!(legend_corner(&series, xr, yr, 3).1 > 0, "every corner has data");
        assert!(legend::is_clear(&occupied(&series, xr, yr), bw, bh));
        // And the plot draws with the legend inside the grown top band.
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("share");
        let plot = LinePlot {
            title: "t".into(),
            series: series
                .iter()
                .map(|s| Series {
                    name: s.name.clone(),
                    points: s.points.clone(),
                    ci: None,
                    level: None,
                    ..Default::default()
                })
                .collect(),
            ..LinePlot::default()
        };
        line_plot(&base, &plot).unwrap();
    }

    #[test]
    fn coinciding_series_are_found_and_noted() {
        let a = prepared("one shader", &[(1.0, 2.0), (2.0, 3.0)]);
        let b = prepared("four shaders", &[(1.0, 2.0), (2.0, 3.0 + 1e-12)]);
        let c = prepared("other", &[(1.0, 2.0), (2.0, 3.5)]);
        assert_eq!(coinciding(&[a, b, c]), vec![None, Some(0), None]);
        let svg = drawn(&[("one", &[(1.0, 1.0), (2.0, 2.0)]), ("four", &[(1.0, 1.0), (2.0, 2.0)])]);
        assert!(
            svg.contains("four coincides with one (drawn dashed)"),
            "the note is on the plot"
        );
    }

    /// The SVG of a line plot of these named series.
    fn drawn(series: &[(&str, &[(f64, f64)])]) -> String {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("drawn");
        let plot = LinePlot {
            title: "t".into(),
            series: series
                .iter()
                .map(|(name, points)| Series {
                    name: name.to_string(),
                    points: points.to_vec(),
                    ci: None,
                    level: None,
                    ..Default::default()
                })
                .collect(),
            ..LinePlot::default()
        };
        line_plot(&base, &plot).unwrap();
        std::fs::read_to_string(base.with_extension("svg")).unwrap()
    }

    #[test]
    fn series_sharing_part_of_their_curve_are_noted_with_the_range() {
        let a = prepared("FIFO 1", &[(0.5, 1.0), (1.0, 1.0), (2.0, 0.8), (4.0, 0.5)]);
        let b = prepared("FIFO 64", &[(0.5, 1.0), (1.0, 1.0), (2.0, 0.9), (4.0, 0.6)]);
        let c = prepared("apart", &[(0.5, 0.1), (1.0, 0.2)]);
        // One shared point is not a hidden segment.
        let d = prepared("crossing", &[(0.5, 0.5), (1.0, 1.0), (2.0, 2.0)]);
        assert_eq!(overlap(&a, &b, 1e-9), vec![(0.5, 1.0)]);
        assert_eq!(overlap(&a, &c, 1e-9), vec![]);
        assert_eq!(overlap(&a, &d, 1e-9), vec![]);
        // Within the tolerance the rest is hidden too.
        assert_eq!(overlap(&a, &b, 0.2), vec![(0.5, 4.0)]);
        // Two runs apart are two ranges.
        let e = prepared(
            "apart in the middle",
            &[(0.5, 1.0), (1.0, 1.0), (2.0, 0.2), (4.0, 0.5), (8.0, 0.5)],
        );
        let f = prepared(
            "FIFO 1 longer",
            &[(0.5, 1.0), (1.0, 1.0), (2.0, 0.8), (4.0, 0.5), (8.0, 0.5)],
        );
        assert_eq!(overlap(&f, &e, 1e-9), vec![(0.5, 1.0), (4.0, 8.0)]);
        assert_eq!(
            (short(0.5), short(1.0), short(12.25), short(1234.6), short(2e-5)),
            (
                "0.5".to_string(),
                "1".to_string(),
                "12.25".to_string(),
                "1235".to_string(),
                "2.000e-5".to_string()
            )
        );
        let svg = drawn(&[
            ("FIFO 1", &[(0.5, 1.0), (1.0, 1.0), (2.0, 0.8)]),
            ("FIFO 64", &[(0.5, 1.0), (1.0, 1.0), (2.0, 0.9)]),
        ]);
        assert!(
            svg.contains("FIFO 64 lies on FIFO 1 from x = 0.5 to 1"),
            "the note is on the plot"
        );
    }

    fn plot(series: Vec<Series>) -> LinePlot {
        LinePlot {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            series,
            ..Default::default()
        }
    }

    #[test]
    fn writes_svg_and_png() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("line");
        let p = plot(vec![
            Series {
                name: "a".into(),
                points: vec![(1.0, 2.0), (2.0, 3.0), (3.0, 2.5)],
                ci: Some(vec![(1.5, 2.5), (2.8, 3.2), (2.0, 3.0)]),
                level: None,
                ..Default::default()
            },
            Series {
                name: "b".into(),
                points: vec![(3.0, 1.0), (1.0, 1.5)],
                ci: None,
                level: None,
                ..Default::default()
            },
        ]);
        line_plot(&base, &p).unwrap();
        assert_plot_files(&base);
    }

    #[test]
    fn a_legend_of_many_entries_goes_beside_the_plot() {
        // Horizontal lines across the plot, each named at length. Up to
        // `IN_PLOT_ENTRIES` the legend sits in a corner of the plot area, and
        // the first line runs to the image's right margin; one more entry and
        // the legend is a panel beside the plot, which narrows the plot area
        // by the panel's width: the first colour then ends at its swatch,
        // far from the right edge.
        let dir = tempfile::tempdir().unwrap();
        let rightmost_of_first_colour = |n: usize| {
            let base = dir.path().join(format!("lines{n}"));
            let series: Vec<Series> = (0..n)
                .map(|k| Series {
                    name: format!("series number {k} with a long name"),
                    points: vec![(0.0, k as f64), (10.0, k as f64)],
                    ci: None,
                    level: None,
                    ..Default::default()
                })
                .collect();
            line_plot(&base, &plot(series)).unwrap();
            assert_plot_files(&base);
            let file = std::fs::File::open(base.with_extension("png")).unwrap();
            let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().unwrap();
            let mut buf = vec![0; reader.output_buffer_size()];
            let info = reader.next_frame(&mut buf).unwrap();
            assert_eq!(info.color_type, png::ColorType::Rgb);
            let (w, c) = (info.width as usize, color(0));
            buf.chunks_exact(3)
                .enumerate()
                .filter(|(_, p)| (p[0], p[1], p[2]) == (c.0, c.1, c.2))
                .map(|(i, _)| i % w)
                .max()
                .unwrap()
        };
        let corner = rightmost_of_first_colour(legend::IN_PLOT_ENTRIES);
        let beside = rightmost_of_first_colour(legend::IN_PLOT_ENTRIES + 1);
        assert!(corner > 950, "{corner}");
        assert!(beside + 150 < corner, "{beside} against {corner}");
    }

    #[test]
    fn robust_to_degenerate_data() {
        let dir = tempfile::tempdir().unwrap();
        let cases = vec![
            ("empty", plot(vec![])),
            ("empty_series", plot(vec![Series::default()])),
            (
                "single",
                plot(vec![Series {
                    name: "s".into(),
                    points: vec![(1.0, 1.0)],
                    ci: None,
                    level: None,
                    ..Default::default()
                }]),
            ),
            (
                "same",
                plot(vec![Series {
                    name: "s".into(),
                    points: vec![(0.0, 0.0), (0.0, 0.0)],
                    ci: Some(vec![(0.0, 0.0)]),
                    level: None,
                    ..Default::default()
                }]),
            ),
            (
                "nan",
                plot(vec![Series {
                    name: "s".into(),
                    points: vec![(f64::NAN, 1.0), (1.0, f64::INFINITY), (2.0, 2.0)],
                    ci: None,
                    level: None,
                    ..Default::default()
                }]),
            ),
            (
                "log",
                LinePlot {
                    log_x: true,
                    log_y: true,
                    ..plot(vec![Series {
                        name: "s".into(),
                        points: vec![(0.0, 1.0), (10.0, 100.0), (1000.0, 0.1)],
                        ci: Some(vec![(-1.0, 2.0), (50.0, 150.0), (0.05, 0.2)]),
                        level: None,
                        ..Default::default()
                    }])
                },
            ),
        ];
        for (name, p) in cases {
            let base = dir.path().join(name);
            line_plot(&base, &p).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_plot_files(&base);
        }
    }

    #[test]
    fn categorical_x_axis_is_labelled_with_the_categories() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("cat");
        let p = LinePlot {
            x_categories: vec![
                (0.0, "1024x768".into()),
                (1.0, "1280x1024".into()),
                (2.0, "1600x1200".into()),
            ],
            ..plot(vec![Series {
                name: "network".into(),
                points: vec![(0.0, 300.0), (1.0, 400.0), (2.0, 500.0)],
                ci: None,
                level: None,
                ..Default::default()
            }])
        };
        line_plot(&base, &p).unwrap();
        assert_plot_files(&base);
        let svg = std::fs::read_to_string(base.with_extension("svg")).unwrap();
        for l in ["1024x768", "1280x1024", "1600x1200"] {
            assert!(svg.contains(l), "{l} missing");
        }
        let (t, r) = category_ticks(&p.x_categories);
        assert_eq!(t.positions, vec![0.0, 1.0, 2.0]);
        assert_eq!(r, (-0.5, 2.5));
        assert_eq!(t.label_at(1.1), "1280x1024");
    }

    #[test]
    fn categories_are_points_side_by_side_not_joined_by_lines() {
        let series = |name: &str, y: f64| Series {
            name: name.into(),
            points: vec![(0.0, y), (1.0, y)],
            ..Default::default()
        };
        let cats = vec![(0.0, "standard".into()), (1.0, "pre-sorting".into())];
        let svg = |x_categories: Vec<(f64, String)>| {
            line_plot_svg(&LinePlot {
                x_categories,
                ..plot(vec![series("a", 10.0), series("b", 10.0)])
            })
            .unwrap()
        };
        let (numeric, categorical) = (svg(Vec::new()), svg(cats));
        // The numeric axis joins each series' points with a line (and its
        // legend swatch is one); the categorical one draws none in the
        // series' colours.
        let lines = |svg: &str| {
            (0..2)
                .map(|i| {
                    let RGBColor(r, g, b) = color(i);
                    let stroke = format!("stroke=\"#{r:02X}{g:02X}{b:02X}\"");
                    svg.split("<polyline")
                        .skip(1)
                        .filter(|l| l.split('>').next().is_some_and(|a| a.contains(&stroke)))
                        .count()
                })
                .sum::<usize>()
        };
        assert!(lines(&numeric) >= 2, "{}", lines(&numeric));
        assert_eq!(lines(&categorical), 0);
        // Equal values in a category stand apart: the circles' centres differ.
        let centres = |svg: &str| -> Vec<String> {
            svg.split("<circle")
                .skip(1)
                .map(|c| c.split(" r=").next().unwrap_or("").to_string())
                .collect()
        };
        let c = centres(&categorical);
        assert_eq!(c.len(), 4 + 2, "four points and two legend swatches");
        let mut unique = c.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), c.len(), "no two circles at one place: {c:?}");
    }

    #[test]
    fn one_quantity_keeps_its_colour_and_a_setting_its_line_pattern() {
        let series = |name: &str, y: f64, pattern: u8| Series {
            name: name.into(),
            points: vec![(0.0, y), (10.0, y + 1.0)],
            color: Some(3),
            pattern,
            ..Default::default()
        };
        let svg = line_plot_svg(&plot(vec![series("a", 1.0, 0), series("b", 5.0, 1)])).unwrap();
        let RGBColor(r, g, b) = color(3);
        let stroke = format!("stroke=\"#{r:02X}{g:02X}{b:02X}\"");
        let others = (0..10).filter(|&i| i != 3).map(|i| {
            let RGBColor(r, g, b) = color(i);
            format!("stroke=\"#{r:02X}{g:02X}{b:02X}\"")
        });
        let strokes = |s: &str| svg.matches(s).count();
        // Both in the palette's fourth colour, none in another; the dashed
        // one drawn as many short pieces, its swatch too.
        assert!(strokes(&stroke) > 6, "{}", strokes(&stroke));
        for o in others {
            assert_eq!(strokes(&o), 0, "{o}");
        }
        assert_eq!(dashes(0), None);
        assert!(dashes(1).is_some() && dashes(2) != dashes(1) && dashes(3) != dashes(2));
    }

    #[test]
    fn dotted_base_name_keeps_its_dot() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("sub").join("a.b");
        line_plot(&base, &plot(vec![])).unwrap();
        assert!(dir.path().join("sub/a.b.svg").exists());
        assert!(dir.path().join("sub/a.b.png").exists());
    }
}
