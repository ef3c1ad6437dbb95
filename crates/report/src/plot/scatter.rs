//! Scatter plots of labelled points (e.g. error against run time).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::PlotError;
use super::axis::{all_integers, coord, omitted_note, padded_range, ticks, to_axis};
use super::font::{AXIS_PX, FAMILY, LABEL_PX, TICK_PX, TITLE_PX};
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

/// A box in pixels: `[l, r) x [t, b)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Rect {
    pub l: i32,
    pub t: i32,
    pub r: i32,
    pub b: i32,
}

impl Rect {
    fn overlaps(&self, o: &Rect) -> bool {
        self.l < o.r && o.l < self.r && self.t < o.b && o.t < self.b
    }

    fn inside(&self, o: &Rect) -> bool {
        self.l >= o.l && self.r <= o.r && self.t >= o.t && self.b <= o.b
    }

    fn grown(&self, d: i32) -> Rect {
        Rect {
            l: self.l - d,
            t: self.t - d,
            r: self.r + d,
            b: self.b + d,
        }
    }
}

/// Radius of a point's marker in pixels.
const MARKER: i32 = 5;

/// Label positions relative to the point: `(dx, dy, horizontal, vertical)`
/// anchors, tried in this order (mirrored left-right for points in the right
/// part of the plot, whose labels prefer the left side).
const CANDIDATES: [(i32, i32, HPos, VPos); 8] = [
    (8, -6, HPos::Left, VPos::Bottom),
    (-8, -6, HPos::Right, VPos::Bottom),
    (8, 6, HPos::Left, VPos::Top),
    (-8, 6, HPos::Right, VPos::Top),
    (10, 0, HPos::Left, VPos::Center),
    (-10, 0, HPos::Right, VPos::Center),
    (0, -9, HPos::Center, VPos::Bottom),
    (0, 9, HPos::Center, VPos::Top),
];

/// The box of a `(w, h)` label anchored at `(x, y)` with `h`/`v` alignment.
fn anchored(x: i32, y: i32, (w, h): (i32, i32), hp: HPos, vp: VPos) -> Rect {
    let l = match hp {
        HPos::Left => x,
        HPos::Right => x - w,
        HPos::Center => x - w / 2,
    };
    let t = match vp {
        VPos::Top => y,
        VPos::Bottom => y - h,
        VPos::Center => y - h / 2,
    };
    Rect {
        l,
        t,
        r: l + w,
        b: t + h,
    }
}

/// Place labels of size `sizes[i]` (pixels; `(0, 0)` for no label) next to
/// the points at pixel `centres[i]`, inside `area`, so that no two labels
/// overlap and no label covers a point's marker. Points are handled in
/// order; each label takes the first free spot of [`CANDIDATES`], or `None`
/// when there is none (and takes no space). Deterministic.
pub(crate) fn place_labels(
    centres: &[(i32, i32)],
    sizes: &[(i32, i32)],
    area: Rect,
    obstacles: &[Rect],
) -> Vec<Option<Rect>> {
    let markers: Vec<Rect> = centres
        .iter()
        .map(|&(x, y)| Rect {
            l: x - MARKER,
            t: y - MARKER,
            r: x + MARKER + 1,
            b: y + MARKER + 1,
        })
        .collect();
    let mid = (area.l + area.r) / 2 + (area.r - area.l) / 10;
    let mut placed: Vec<Rect> = obstacles.to_vec();
    let mut out = Vec::with_capacity(centres.len());
    for (&(x, y), &size) in centres.iter().zip(sizes) {
        if size.0 <= 0 || size.1 <= 0 {
            out.push(None);
            continue;
        }
        let mirror = x > mid;
        let spot = CANDIDATES
            .iter()
            .map(|&(dx, dy, hp, vp)| match (mirror, hp) {
                (true, HPos::Left) => (-dx, dy, HPos::Right, vp),
                (true, HPos::Right) => (-dx, dy, HPos::Left, vp),
                _ => (dx, dy, hp, vp),
            })
            .map(|(dx, dy, hp, vp)| anchored(x + dx, y + dy, size, hp, vp))
            .find(|r| {
                let padded = r.grown(2);
                r.inside(&area)
                    && !markers.iter().any(|m| m.overlaps(&padded))
                    && !placed.iter().any(|p| p.overlaps(&padded))
            });
        if let Some(r) = spot {
            placed.push(r);
        }
        out.push(spot);
    }
    out
}

/// Font of point labels.
fn label_font() -> TextStyle<'static> {
    (FAMILY, LABEL_PX).into_font().into()
}

/// Width of the side panel listing labels that found no free spot.
fn panel_width<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, rows: &[String]) -> i32 {
    super::legend::panel_width(area, rows, &label_font(), 26)
}

/// The text of panel row `n` (1-based) for `label`.
fn panel_row(n: usize, label: &str) -> String {
    format!("{n}: {label}")
}

/// Draw the chart into `area`; returns the indices (into `pts`) of points
/// whose labels found no free spot, without drawing them when `dry`.
#[allow(clippy::too_many_arguments)]
fn chart_into<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &Scatter,
    pts: &[(usize, f64, f64)],
    ranges: ((f64, f64), (f64, f64)),
    dry: bool,
) -> Result<Vec<usize>, String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let (xr, yr) = ranges;
    let xt = ticks(xr.0, xr.1, s.log_x, all_integers(s.points.iter().map(|p| p.x)));
    let yt = ticks(yr.0, yr.1, s.log_y, all_integers(s.points.iter().map(|p| p.y)));
    let mut chart = ChartBuilder::on(area)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(coord(xr.0, xr.1, &xt), coord(yr.0, yr.1, &yt))
        .map_err(e)?;
    let font = label_font();
    let centres: Vec<(i32, i32)> = pts.iter().map(|&(_, x, y)| chart.backend_coord(&(x, y))).collect();
    let sizes: Vec<(i32, i32)> = pts
        .iter()
        .map(|&(i, _, _)| match s.points[i].label.as_str() {
            "" => Ok((0, 0)),
            l => area.estimate_text_size(l, &font).map(|(w, h)| (w as i32, h as i32)),
        })
        .collect::<Result<_, _>>()
        .map_err(e)?;
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let plot_rect = Rect {
        l: xs.start,
        t: ys.start,
        r: xs.end,
        b: ys.end,
    };
    let spots = place_labels(&centres, &sizes, plot_rect, &[]);
    let dropped: Vec<usize> = (0..pts.len())
        .filter(|&k| spots[k].is_none() && sizes[k].0 > 0)
        .collect();
    if dry {
        return Ok(dropped);
    }
    // Dropped labels get their panel number next to the point, where it fits.
    let numbers: Vec<String> = (1..=dropped.len()).map(|n| n.to_string()).collect();
    let mut number_sizes = vec![(0, 0); pts.len()];
    for (k, n) in dropped.iter().zip(&numbers) {
        let (w, h) = area.estimate_text_size(n, &font).map_err(e)?;
        number_sizes[*k] = (w as i32, h as i32);
    }
    let taken: Vec<Rect> = spots.iter().flatten().copied().collect();
    let number_spots = place_labels(&centres, &number_sizes, plot_rect, &taken);

    let (fx, fy) = (|v: &f64| xt.label_at(*v), |v: &f64| yt.label_at(*v));
    chart
        .configure_mesh()
        .x_desc(s.x_label.as_str())
        .y_desc(s.y_label.as_str())
        .label_style((FAMILY, TICK_PX))
        .axis_desc_style((FAMILY, AXIS_PX))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .draw()
        .map_err(e)?;
    chart
        .draw_series(
            pts.iter()
                .map(|&(i, x, y)| Circle::new((x, y), MARKER as u32, color(i).filled())),
        )
        .map_err(e)?;
    let mut texts: Vec<(String, Rect)> = Vec::new();
    for (k, &(i, _, _)) in pts.iter().enumerate() {
        if let Some(r) = spots[k] {
            texts.push((s.points[i].label.clone(), r));
        }
    }
    for (k, n) in dropped.iter().zip(&numbers) {
        if let Some(r) = number_spots[*k] {
            texts.push((n.clone(), r));
        }
    }
    let top_left = font.pos(Pos::new(HPos::Left, VPos::Top));
    for (text, r) in texts {
        area.draw_text(
            &text,
            &top_left,
            (r.l - area.get_base_pixel().0, r.t - area.get_base_pixel().1),
        )
        .map_err(e)?;
    }
    Ok(dropped)
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
    let body = root
        .margin(20, 20, 20, 20)
        .titled(&s.title, (FAMILY, TITLE_PX))
        .map_err(e)?;
    // Labels that do not fit next to their points are listed in a panel on
    // the right instead, numbered, with the number next to the point.
    let mut dropped = chart_into(&body, s, pts, (xr, yr), true)?;
    if !dropped.is_empty() {
        let all_rows: Vec<String> = pts
            .iter()
            .enumerate()
            .map(|(k, &(i, _, _))| panel_row(k + 1, &s.points[i].label))
            .collect();
        let w = panel_width(&body, &all_rows);
        let (plot, panel) = body.split_horizontally(body.dim_in_pixel().0 as i32 - w);
        dropped = chart_into(&plot, s, pts, (xr, yr), false)?;
        draw_panel(&panel, s, pts, &dropped).map_err(e)?;
    } else {
        chart_into(&body, s, pts, (xr, yr), false)?;
    }
    draw_notes(root, notes)
}

/// The numbered list of labels that found no spot next to their points.
fn draw_panel<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    s: &Scatter,
    pts: &[(usize, f64, f64)],
    dropped: &[usize],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = label_font().pos(Pos::new(HPos::Left, VPos::Center));
    let (w, h) = panel.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let row_h = 18;
    let top = 8;
    let fits = ((h - 55 - top) / row_h).max(1) as usize;
    let shown = if dropped.len() > fits { fits - 1 } else { dropped.len() };
    for (n, &k) in dropped.iter().take(shown).enumerate() {
        let i = pts[k].0;
        let y = top + row_h * n as i32 + row_h / 2;
        panel.draw(&Circle::new((16, y), 5, color(i).filled()))?;
        // Shorten what the panel cannot hold.
        let text = super::legend::fit_text(panel, &panel_row(n + 1, &s.points[i].label), &font, w - 30)?;
        panel.draw_text(&text, &font, (26, y))?;
    }
    if shown < dropped.len() {
        let y = top + row_h * shown as i32 + row_h / 2;
        panel.draw_text(&format!("… and {} more", dropped.len() - shown), &font, (26, y))?;
    }
    Ok(())
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

    const AREA: Rect = Rect {
        l: 0,
        t: 0,
        r: 800,
        b: 500,
    };

    /// Placed labels overlap neither each other nor any marker, and stay inside.
    fn assert_clear(centres: &[(i32, i32)], spots: &[Option<Rect>]) {
        let placed: Vec<Rect> = spots.iter().flatten().copied().collect();
        for (i, a) in placed.iter().enumerate() {
            assert!(a.inside(&AREA), "{a:?}");
            for b in &placed[i + 1..] {
                assert!(!a.overlaps(b), "{a:?} overlaps {b:?}");
            }
            for &(x, y) in centres {
                let m = Rect {
                    l: x - MARKER,
                    t: y - MARKER,
                    r: x + MARKER + 1,
                    b: y + MARKER + 1,
                };
                assert!(!a.overlaps(&m), "{a:?} covers the point at {x},{y}");
            }
        }
    }

    #[test]
    fn labels_of_close_points_do_not_overlap() {
        // Five points in a row, 60 px apart, with 220 px labels (the
        // fidelity experiment's triangle points): the old fixed offset drew
        // them all on top of each other.
        let centres: Vec<(i32, i32)> = (0..5).map(|i| (300 + 60 * i, 450)).collect();
        let sizes = vec![(220, 14); 5];
        let spots = place_labels(&centres, &sizes, AREA, &[]);
        assert_clear(&centres, &spots);
        let placed = spots.iter().flatten().count();
        assert!((2..5).contains(&placed), "{spots:?}");
        // Deterministic.
        assert_eq!(spots, place_labels(&centres, &sizes, AREA, &[]));
        // Lone points keep the usual spot: above right, or above left in the
        // right part of the plot.
        let spots = place_labels(&[(100, 200), (700, 200)], &[(50, 14), (50, 14)], AREA, &[]);
        assert_eq!(
            spots[0],
            Some(Rect {
                l: 108,
                t: 180,
                r: 158,
                b: 194
            })
        );
        assert_eq!(spots[1].map(|r| r.r), Some(692));
        // Empty labels take no space and are not reported as dropped.
        let spots = place_labels(&[(100, 200)], &[(0, 0)], AREA, &[]);
        assert_eq!(spots, vec![None]);
        // Obstacles (already placed text) are avoided too.
        let block = Rect {
            l: 97,
            t: 150,
            r: 250,
            b: 250,
        };
        let spots = place_labels(&[(100, 200)], &[(50, 14)], AREA, &[block]);
        assert!(spots[0].is_some_and(|r| !r.overlaps(&block) && r.r <= 92), "{spots:?}");
    }

    #[test]
    fn crowded_labels_many_points() {
        let centres: Vec<(i32, i32)> = (0..40).map(|i| (20 + (i * 37) % 760, 20 + (i * 53) % 460)).collect();
        let sizes: Vec<(i32, i32)> = (0..40).map(|i| (60 + (i * 13) % 150, 14)).collect();
        assert_clear(&centres, &place_labels(&centres, &sizes, AREA, &[]));
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
            (
                "crowded",
                Scatter {
                    log_x: true,
                    points: (0..10)
                        .map(|i| {
                            pt(
                                &format!("workload.scale={i}, fidelity=triangle"),
                                0.05 * 1.5f64.powi(i),
                                if i < 5 { 0.0 } else { 0.14 },
                            )
                        })
                        .collect(),
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
