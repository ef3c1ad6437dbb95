//! Timelines for slides, in the manner of paper 000 Figure 4: one lane per
//! unit, each unit's busy periods drawn as bars coloured by the frame they
//! belong to (so a reader sees the CPU on frame n+1 while the GPU draws
//! frame n), waits and system tasks in greys, an optional level (a FIFO's
//! fill) drawn as a filled step line inside its lane, and vertical lines at
//! marked times (vertical blanks).
//!
//! Unlike the other plots, a timeline is written to one file whose
//! extension picks the format (`.svg` or `.png`).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::PlotError;
use super::axis::{TickedAxis, Ticks, coord, ticks};
use super::font::{AXIS_PX, FAMILY, TICK_PX, TITLE_PX, ensure_font};
use super::output::draw_notes;
use super::palette::color;
use super::{HEIGHT, WIDTH};

/// What a bar shows, which decides its colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fill {
    /// Work on frame `n` (coloured by `n`, labelled when wide enough).
    Frame(u64),
    /// The frame generated before frame `n` (frame generation): in `n`'s
    /// colour, lighter, labelled `gN`.
    Generated(u64),
    /// A system task (dark grey).
    System,
    /// Waiting or blocked (light grey, thin).
    Wait,
}

/// One bar of a lane.
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    /// Start, in the x axis's units.
    pub start: f64,
    /// End.
    pub end: f64,
    /// What it shows.
    pub fill: Fill,
}

/// A level drawn as a filled step line across its lane (0 at the lane's
/// bottom, `max` at its top).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Level {
    /// `(x, value)` steps: the value holds from its x to the next step's.
    pub steps: Vec<(f64, f64)>,
    /// The value drawn at the top of the lane.
    pub max: f64,
}

/// One lane (a unit).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Lane {
    /// Name drawn left of the lane.
    pub name: String,
    /// Bars (drawn in the order: waits, system tasks, frames).
    pub bars: Vec<Bar>,
    /// A level instead of (or beside) bars.
    pub level: Option<Level>,
}

/// A timeline description.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timeline {
    /// Title above the plot.
    pub title: String,
    /// X axis description, with its unit.
    pub x_label: String,
    /// The x range drawn.
    pub range: (f64, f64),
    /// Lanes, top to bottom.
    pub lanes: Vec<Lane>,
    /// Times marked by a vertical dashed line across every lane.
    pub marks: Vec<f64>,
    /// Legend text of the marks, e.g. "vertical blank".
    pub mark_label: String,
    /// Notes drawn in the lower left corner.
    pub notes: Vec<String>,
}

/// The picture formats a timeline is written in, by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.svg`
    Svg,
    /// `.png`
    Png,
}

impl ImageFormat {
    /// The format named by `path`'s extension (case-insensitive).
    pub fn of(path: &Path) -> Result<ImageFormat, PlotError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
        {
            Some(e) if e == "svg" => Ok(ImageFormat::Svg),
            Some(e) if e == "png" => Ok(ImageFormat::Png),
            _ => Err(PlotError::Extension {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// Light grey of waits, dark grey of system tasks.
const WAIT: RGBColor = RGBColor(200, 200, 200);
const SYSTEM: RGBColor = RGBColor(70, 70, 70);

/// Draws `t` into `root`.
fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, t: &Timeline) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let n = t.lanes.len().max(1) as f64;
    let (x0, x1) = if t.range.0.is_finite() && t.range.1.is_finite() && t.range.0 < t.range.1 {
        t.range
    } else {
        (0.0, 1.0)
    };
    let xt = ticks(x0, x1, false, false);
    // Lane i (from the top) spans [n-1-i, n-i); its name is the y tick at its centre.
    let yt = Ticks {
        positions: (0..t.lanes.len()).rev().map(|i| n - 1.0 - i as f64 + 0.5).collect(),
        labels: t.lanes.iter().rev().map(|l| l.name.clone()).collect(),
        minor: Vec::new(),
    };
    let mut chart = ChartBuilder::on(root)
        .caption(&t.title, (FAMILY, TITLE_PX))
        .margin(20)
        .margin_bottom(44 + 16 * t.notes.len() as u32)
        .x_label_area_size(55)
        .y_label_area_size(170)
        .build_cartesian_2d(coord(x0, x1, &xt), coord(0.0, n, &yt))
        .map_err(e)?;
    let fx = |v: &f64| xt.label_at(*v);
    let fy = |v: &f64| yt.label_at(*v);
    chart
        .configure_mesh()
        .x_desc(t.x_label.as_str())
        .label_style((FAMILY, TICK_PX))
        .axis_desc_style((FAMILY, AXIS_PX))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .disable_y_mesh()
        .draw()
        .map_err(e)?;
    let px_per_x = {
        let a = chart.backend_coord(&(x0, 0.0));
        let b = chart.backend_coord(&(x1, 0.0));
        (b.0 - a.0) as f64 / (x1 - x0)
    };
    for (i, lane) in t.lanes.iter().enumerate() {
        let base = n - 1.0 - i as f64;
        if let Some(level) = &lane.level {
            draw_level(&mut chart, level, base, (x0, x1))?;
        }
        draw_bars(&mut chart, &lane.bars, base, (x0, x1), px_per_x)?;
    }
    let marks: Vec<f64> = t.marks.iter().copied().filter(|m| *m >= x0 && *m <= x1).collect();
    for &m in &marks {
        chart
            .draw_series(DashedLineSeries::new(
                [(m, 0.0), (m, n)],
                5,
                4,
                BLACK.mix(0.6).stroke_width(1),
            ))
            .map_err(e)?;
    }
    draw_key(root, t, !marks.is_empty())?;
    draw_notes(root, &t.notes)
}

/// A timeline's chart: both axes ticked.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<TickedAxis, TickedAxis>>;

/// Draws `level` as a filled step line inside the lane whose bottom is at
/// `base`, over the x range `(x0, x1)`.
fn draw_level<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    level: &Level,
    base: f64,
    (x0, x1): (f64, f64),
) -> Result<(), String> {
    let clip = |v: f64| v.clamp(x0, x1);
    let max = if level.max > 0.0 { level.max } else { 1.0 };
    let y = |v: f64| base + 0.1 + 0.8 * (v / max).clamp(0.0, 1.0);
    let mut pts = vec![(x0, base + 0.1)];
    let mut last = 0.0;
    for &(x, v) in &level.steps {
        if x > x1 {
            break;
        }
        pts.push((clip(x), y(last)));
        pts.push((clip(x), y(v)));
        last = v;
    }
    pts.push((x1, y(last)));
    pts.push((x1, base + 0.1));
    let c = color(0);
    chart
        .draw_series(std::iter::once(Polygon::new(pts.clone(), c.mix(0.35).filled())))
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(std::iter::once(PathElement::new(pts, c.stroke_width(1))))
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// Draws a lane's `bars` (waits, then system tasks, then frames, each
/// frame's number on it when wide enough) in the lane whose bottom is at
/// `base`, clipped to the x range `(x0, x1)`; `px_per_x` is pixels per x unit.
fn draw_bars<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    bars: &[Bar],
    base: f64,
    (x0, x1): (f64, f64),
    px_per_x: f64,
) -> Result<(), String> {
    let clip = |v: f64| v.clamp(x0, x1);
    for pass in [Fill::Wait, Fill::System, Fill::Generated(0), Fill::Frame(0)] {
        let bars = bars
            .iter()
            .filter(|b| std::mem::discriminant(&b.fill) == std::mem::discriminant(&pass) && b.end > x0 && b.start < x1);
        for b in bars {
            let (lo, hi) = match b.fill {
                Fill::Wait => (base + 0.4, base + 0.6),
                _ => (base + 0.15, base + 0.85),
            };
            let style = match b.fill {
                Fill::Frame(f) => color(f as usize).filled(),
                Fill::Generated(f) => color(f as usize).mix(0.45).filled(),
                Fill::System => SYSTEM.filled(),
                Fill::Wait => WAIT.filled(),
            };
            let (s, end) = (clip(b.start), clip(b.end));
            chart
                .draw_series(std::iter::once(Rectangle::new([(s, lo), (end, hi)], style)))
                .map_err(|e| e.to_string())?;
            let label = match b.fill {
                Fill::Frame(f) => Some(f.to_string()),
                Fill::Generated(f) => Some(format!("g{f}")),
                _ => None,
            };
            if let Some(label) = label
                && (end - s) * px_per_x >= 9.0 * label.len() as f64 + 4.0
            {
                chart
                    .draw_series(std::iter::once(Text::new(
                        label,
                        ((s + end) / 2.0, base + 0.5),
                        (FAMILY, TICK_PX)
                            .into_font()
                            .color(&WHITE)
                            .pos(Pos::new(HPos::Center, VPos::Center)),
                    )))
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    Ok(())
}

/// Draws the key under the x axis: what colours, greys and (with
/// `has_marks` and a mark label) dashes mean.
fn draw_key<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, t: &Timeline, has_marks: bool) -> Result<(), String> {
    let key_y = root.dim_in_pixel().1 as i32 - 26 - 16 * t.notes.len() as i32;
    let mut x = 20;
    let font = (FAMILY, TICK_PX).into_font().color(&BLACK);
    let key = |x: &mut i32, swatch: &dyn Fn(i32) -> Result<(), String>, text: &str| -> Result<(), String> {
        swatch(*x)?;
        root.draw(&Text::new(
            text.to_string(),
            (*x + 26, key_y),
            font.clone().pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(|e| e.to_string())?;
        *x += 26 + 9 * text.len() as i32 + 24;
        Ok(())
    };
    key(
        &mut x,
        &|x| {
            root.draw(&Rectangle::new(
                [(x, key_y - 7), (x + 20, key_y + 7)],
                color(1).filled(),
            ))
            .map_err(|e| e.to_string())
        },
        "work on frame n (colour and number)",
    )?;
    key(
        &mut x,
        &|x| {
            root.draw(&Rectangle::new([(x, key_y - 7), (x + 20, key_y + 7)], SYSTEM.filled()))
                .map_err(|e| e.to_string())
        },
        "system task",
    )?;
    key(
        &mut x,
        &|x| {
            root.draw(&Rectangle::new([(x, key_y - 2), (x + 20, key_y + 2)], WAIT.filled()))
                .map_err(|e| e.to_string())
        },
        "waiting / blocked",
    )?;
    if has_marks && !t.mark_label.is_empty() {
        key(
            &mut x,
            &|x| {
                root.draw(&PathElement::new(
                    vec![(x + 10, key_y - 8), (x + 10, key_y + 8)],
                    BLACK.mix(0.6).stroke_width(2),
                ))
                .map_err(|e| e.to_string())
            },
            &t.mark_label,
        )?;
    }
    Ok(())
}

/// `t` as one SVG document (what [`timeline`] writes to a `.svg` file).
pub fn timeline_svg(t: &Timeline) -> Result<String, PlotError> {
    let mut out = String::new();
    super::output::render_svg(&mut out, |root| draw(root, t))?;
    Ok(out)
}

/// Writes `t` to `path` as SVG or PNG, by the path's extension (see
/// [`ImageFormat::of`]); the file is replaced atomically.
pub fn timeline(path: &Path, t: &Timeline) -> Result<(), PlotError> {
    let format = ImageFormat::of(path)?;
    ensure_font()?;
    let draw_err = |message: String| PlotError::Draw {
        path: path.to_path_buf(),
        message,
    };
    let bytes = match format {
        ImageFormat::Svg => {
            let mut s = String::new();
            super::output::render_svg(&mut s, |root| draw(root, t)).map_err(|e| match e {
                PlotError::Draw { message, .. } => draw_err(message),
                e => e,
            })?;
            s.into_bytes()
        }
        ImageFormat::Png => {
            let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
                root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
                draw(&root, t).map_err(draw_err)?;
                root.present().map_err(|e| draw_err(e.to_string()))?;
            }
            super::output::encode_png(&rgb, WIDTH, HEIGHT).map_err(|e| draw_err(e.to_string()))?
        }
    };
    crate::output::files::write_output(path, |w| w.write_all(&bytes)).map_err(|e| PlotError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> Timeline {
        Timeline {
            title: "t".into(),
            x_label: "time (ms)".into(),
            range: (0.0, 40.0),
            lanes: vec![
                Lane {
                    name: "CPU".into(),
                    bars: vec![
                        Bar {
                            start: 0.0,
                            end: 10.0,
                            fill: Fill::Frame(0),
                        },
                        Bar {
                            start: 10.0,
                            end: 12.0,
                            fill: Fill::System,
                        },
                        Bar {
                            start: 12.0,
                            end: 30.0,
                            fill: Fill::Wait,
                        },
                    ],
                    level: None,
                },
                Lane {
                    name: "FIFO".into(),
                    bars: Vec::new(),
                    level: Some(Level {
                        steps: vec![(0.0, 1.0), (5.0, 4.0), (20.0, 0.0)],
                        max: 4.0,
                    }),
                },
            ],
            marks: vec![16.7, 33.3],
            mark_label: "vertical blank".into(),
            notes: vec!["note: example".into()],
        }
    }

    #[test]
    fn writes_svg_or_png_by_extension() {
        let dir = tempfile::tempdir().unwrap();
        let svg = dir.path().join("t.svg");
        timeline(&svg, &example()).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.starts_with("<svg") || text.starts_with("<?xml"));
        assert!(text.contains("CPU") && text.contains("vertical blank") && text.contains("note: example"));
        let png = dir.path().join("t.PNG");
        timeline(&png, &example()).unwrap();
        assert_eq!(&std::fs::read(&png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
    }

    #[test]
    fn other_extensions_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["t.jpg", "t", "t.svg.txt"] {
            let p = dir.path().join(name);
            let err = timeline(&p, &example()).unwrap_err().to_string();
            assert!(err.contains(".png or .svg"), "{err}");
            assert!(!p.exists());
        }
    }
}
