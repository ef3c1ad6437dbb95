//! Scatter plots of labelled points (e.g. error against run time).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::PlotError;
use super::axis::{omitted_note, padded_range, tick_label, to_axis};
use super::font::FAMILY;
use super::output::{draw_notes, render_both};
use super::palette::color;

/// One labelled point of a [`Scatter`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScatterPoint {
    /// Text drawn next to the point (may be empty).
    pub label: String,
    /// X value.
    pub x: f64,
    /// Y value.
    pub y: f64,
}

/// A scatter plot description.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scatter {
    /// Title above the plot.
    pub title: String,
    /// X axis description.
    pub x_label: String,
    /// Y axis description.
    pub y_label: String,
    /// The points, each in its own colour.
    pub points: Vec<ScatterPoint>,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    s: &Scatter,
    pts: &[(usize, f64, f64)],
    notes: &[String],
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let xr = padded_range(pts.iter().map(|p| p.1));
    let yr = padded_range(pts.iter().map(|p| p.2));
    let mut chart = ChartBuilder::on(root)
        .caption(&s.title, (FAMILY, 24))
        .margin(20)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(e)?;
    let (log_x, log_y) = (s.log_x, s.log_y);
    let fx = move |v: &f64| tick_label(*v, log_x);
    let fy = move |v: &f64| tick_label(*v, log_y);
    chart
        .configure_mesh()
        .x_desc(s.x_label.as_str())
        .y_desc(s.y_label.as_str())
        .label_style((FAMILY, 14))
        .axis_desc_style((FAMILY, 16))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .draw()
        .map_err(e)?;
    // Labels of points in the right part of the plot go to their left.
    let flip_at = xr.0 + (xr.1 - xr.0) * 0.6;
    chart
        .draw_series(pts.iter().map(|&(i, x, y)| {
            let c = color(i);
            let (offset, h) = if x > flip_at {
                ((-8, -8), HPos::Right)
            } else {
                ((8, -8), HPos::Left)
            };
            let font = TextStyle::from((FAMILY, 13).into_font()).pos(Pos::new(h, VPos::Bottom));
            EmptyElement::at((x, y))
                + Circle::new((0, 0), 5, c.filled())
                + Text::new(s.points[i].label.clone(), offset, font)
        }))
        .map_err(e)?;
    draw_notes(root, notes)
}

/// Write `s` to `<base>.svg` and `<base>.png`.
pub fn scatter(base: &Path, s: &Scatter) -> Result<(), PlotError> {
    let pts: Vec<(usize, f64, f64)> = s
        .points
        .iter()
        .enumerate()
        .filter_map(|(i, p)| Some((i, to_axis(p.x, s.log_x)?, to_axis(p.y, s.log_y)?)))
        .collect();
    let mut notes: Vec<String> = omitted_note(s.points.len() - pts.len(), s.log_x || s.log_y)
        .into_iter()
        .collect();
    if pts.is_empty() {
        notes.push("note: no data".into());
    }
    render_both(base, |r| draw(r, s, &pts, &notes), |r| draw(r, s, &pts, &notes))
}

#[cfg(test)]
mod tests {
    use super::super::output::test_support::assert_plot_files;
    use super::*;

    fn pt(label: &str, x: f64, y: f64) -> ScatterPoint {
        ScatterPoint {
            label: label.into(),
            x,
            y,
        }
    }

    #[test]
    fn writes_files_for_normal_and_degenerate_data() {
        let dir = tempfile::tempdir().unwrap();
        let base = Scatter {
            title: "error vs run time".into(),
            x_label: "wall (s)".into(),
            y_label: "error".into(),
            ..Default::default()
        };
        let cases = vec![
            (
                "normal",
                Scatter {
                    points: vec![pt("triangle", 2.0, 0.0), pt("tile", 0.5, 0.02), pt("frame", 0.01, 0.3)],
                    ..base.clone()
                },
            ),
            (
                "log",
                Scatter {
                    log_x: true,
                    log_y: true,
                    points: vec![pt("triangle", 2.0, 0.0), pt("tile", 0.5, 0.02), pt("frame", 0.01, 0.3)],
                    ..base.clone()
                },
            ),
            ("empty", base.clone()),
            (
                "single",
                Scatter {
                    points: vec![pt("a", 1.0, 1.0)],
                    ..base.clone()
                },
            ),
            (
                "nan",
                Scatter {
                    points: vec![pt("a", f64::NAN, 1.0), pt("b", 1.0, 1.0)],
                    ..base.clone()
                },
            ),
        ];
        for (name, s) in cases {
            let p = dir.path().join(name);
            scatter(&p, &s).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_plot_files(&p);
        }
    }
}
