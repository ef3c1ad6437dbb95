//! Grouped bar charts with interval whiskers: one group of bars per
//! category, one bar per series (e.g. first-order and total Sobol indices
//! per parameter, with their bootstrap confidence intervals).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::PlotError;
use super::axis::{coord, ticks, to_axis, widen};
use super::font::{AXIS_PX, FAMILY, TICK_PX, TITLE_PX};
use super::output::{Sink, draw_notes, render_to, svg_of};
use super::palette::color;

/// One series of a [`BarChart`]: a value per category.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BarSeries {
    /// Legend text.
    pub name: String,
    /// One value per category (NaN or infinite: no bar, noted).
    pub values: Vec<f64>,
    /// An interval per category, drawn as a whisker (optional; none where
    /// the interval has no width).
    pub ci: Option<Vec<(f64, f64)>>,
    /// Drawn in a light tint of the previous series' colour (a reference
    /// beside the values it belongs to, e.g. a paper's number).
    pub tint_of_previous: bool,
}

/// A grouped bar chart description.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BarChart {
    /// Title above the plot.
    pub title: String,
    /// Y axis description.
    pub y_label: String,
    /// Category names along the x axis.
    pub categories: Vec<String>,
    /// The series, each in its own colour.
    pub series: Vec<BarSeries>,
    /// Logarithmic y axis: bars rise from below the smallest value, and
    /// values that are not positive get no bar (noted).
    pub log_y: bool,
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, c: &BarChart) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let n = c.categories.len().max(1);
    let axis = |v: f64| to_axis(v, c.log_y);
    let mut lo: f64 = if c.log_y { f64::INFINITY } else { 0.0 };
    let mut hi: f64 = if c.log_y { f64::NEG_INFINITY } else { 0.0 };
    let mut dropped = 0usize;
    for s in &c.series {
        for v in &s.values {
            match axis(*v) {
                Some(a) => {
                    lo = lo.min(a);
                    hi = hi.max(a);
                }
                None => dropped += 1,
            }
        }
        for (a, b) in s.ci.iter().flatten() {
            for a in [a, b].into_iter().filter_map(|v| axis(*v)) {
                lo = lo.min(a);
                hi = hi.max(a);
            }
        }
    }
    let (lo, hi) = if !(lo.is_finite() && hi.is_finite()) {
        (0.0, 1.0)
    } else if c.log_y {
        // Bars rise from a third of a decade below the smallest value.
        // Headroom above the tallest bar for the legend.
        (
            lo - 0.35,
            hi + (hi - lo).max(1.0) * (0.1 + 0.06 * c.series.len() as f64),
        )
    } else if hi > lo {
        // Headroom above the tallest bar for the legend (a line a series).
        (
            lo - (hi - lo) * 0.02,
            hi + (hi - lo) * (0.1 + 0.06 * c.series.len() as f64),
        )
    } else {
        widen(lo, hi, 0.05)
    };
    let yt = ticks(lo, hi, c.log_y, false);
    let base = if c.log_y { lo } else { 0.0 };
    let mut chart = ChartBuilder::on(root)
        .margin(20)
        .caption(&c.title, (FAMILY, TITLE_PX))
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), coord(lo, hi, &yt))
        .map_err(e)?;
    let fy = |v: &f64| yt.label_at(*v);
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc(c.y_label.as_str())
        .y_label_formatter(&fy)
        .label_style((FAMILY, TICK_PX))
        .axis_desc_style((FAMILY, AXIS_PX))
        .draw()
        .map_err(e)?;
    let k = c.series.len().max(1) as f64;
    let group = 0.8;
    let w = group / k;
    // Colours count the series that are not tints; a tint takes the
    // previous colour, lightened.
    let (mut next, mut last) = (0usize, color(0).to_rgba());
    for (j, s) in c.series.iter().enumerate() {
        let col = if s.tint_of_previous && j > 0 {
            last.mix(0.4)
        } else {
            last = color(next).to_rgba();
            next += 1;
            last
        };
        let left = |i: usize| i as f64 - group / 2.0 + j as f64 * w;
        chart
            .draw_series(
                s.values
                    .iter()
                    .enumerate()
                    .filter_map(|(i, &v)| Some((i, axis(v)?)))
                    .map(|(i, v)| Rectangle::new([(left(i) + w * 0.05, base), (left(i) + w * 0.95, v)], col.filled())),
            )
            .map_err(e)?
            .label(s.name.as_str())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], col.filled()));
        if let Some(ci) = &s.ci {
            for (i, &(a, b)) in ci.iter().enumerate() {
                let (Some(a), Some(b)) = (axis(a), axis(b)) else {
                    continue;
                };
                if a == b {
                    continue;
                }
                let x = left(i) + w / 2.0;
                let cap = w * 0.2;
                for path in [
                    vec![(x, a), (x, b)],
                    vec![(x - cap, a), (x + cap, a)],
                    vec![(x - cap, b), (x + cap, b)],
                ] {
                    chart
                        .draw_series(std::iter::once(PathElement::new(path, BLACK.stroke_width(2))))
                        .map_err(e)?;
                }
            }
        }
    }
    // Category names under the groups.
    let font = TextStyle::from((FAMILY, TICK_PX).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    for (i, name) in c.categories.iter().enumerate() {
        let (x, y) = chart.backend_coord(&(i as f64, lo));
        root.draw_text(
            name,
            &font,
            (x - root.get_base_pixel().0, y + 8 - root.get_base_pixel().1),
        )
        .map_err(e)?;
    }
    if !c.series.is_empty() {
        chart
            .configure_series_labels()
            .label_font((FAMILY, TICK_PX))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(e)?;
    }
    let notes: Vec<String> = if dropped > 0 {
        vec![if c.log_y {
            format!("{dropped} value(s) not finite or not positive: no bar drawn on the log axis")
        } else {
            format!("{dropped} value(s) not finite: no bar drawn")
        }]
    } else {
        Vec::new()
    };
    draw_notes(root, &notes)
}

/// Write `c` to `<base>.svg` and `<base>.png`.
pub fn bar_chart(base: &Path, c: &BarChart) -> Result<(), PlotError> {
    render_to(Sink::Files(base), |r| draw(r, c), |r| draw(r, c))
}

/// `c` as one SVG document (what [`bar_chart`] writes to `<base>.svg`).
pub fn bar_chart_svg(c: &BarChart) -> Result<String, PlotError> {
    svg_of(|sink| render_to(sink, |r| draw(r, c), |r| draw(r, c)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::output::test_support::assert_plot_files;

    #[test]
    fn bars_with_whiskers_and_awkward_values() {
        let d = tempfile::tempdir().unwrap();
        let base = d.path().join("bars");
        bar_chart(
            &base,
            &BarChart {
                title: "indices".into(),
                y_label: "index".into(),
                categories: vec!["a".into(), "b".into(), "c".into()],
                series: vec![
                    BarSeries {
                        name: "first order".into(),
                        values: vec![0.3, 0.44, -0.01],
                        ci: Some(vec![(0.25, 0.35), (0.4, 0.5), (-0.05, 0.03)]),
                        tint_of_previous: false,
                    },
                    BarSeries {
                        name: "total".into(),
                        values: vec![0.55, f64::NAN, 0.24],
                        ci: None,
                        tint_of_previous: false,
                    },
                ],
                log_y: false,
            },
        )
        .unwrap();
        assert_plot_files(&base);
        let svg = std::fs::read_to_string(d.path().join("bars.svg")).unwrap();
        assert!(svg.contains("not finite"), "the NaN is noted");
        // Nothing at all still draws.
        bar_chart(&d.path().join("empty"), &BarChart::default()).unwrap();
        assert_plot_files(&d.path().join("empty"));
    }

    #[test]
    fn a_log_axis_drops_what_it_cannot_show_and_says_so() {
        let d = tempfile::tempdir().unwrap();
        let base = d.path().join("log");
        let chart = BarChart {
            title: "mse".into(),
            y_label: "ms^2".into(),
            categories: vec!["h1".into(), "h2".into()],
            series: vec![
                BarSeries {
                    name: "simulated".into(),
                    values: vec![32.2, 0.0],
                    ci: None,
                    tint_of_previous: false,
                },
                BarSeries {
                    name: "paper".into(),
                    values: vec![3.27, 0.7],
                    ci: None,
                    tint_of_previous: false,
                },
            ],
            log_y: true,
        };
        bar_chart(&base, &chart).unwrap();
        assert_plot_files(&base);
        let svg = std::fs::read_to_string(d.path().join("log.svg")).unwrap();
        assert!(svg.contains("not positive"), "the zero is noted");
    }
}
