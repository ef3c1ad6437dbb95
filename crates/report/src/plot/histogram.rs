//! Density histograms of one or more groups of values over shared bins.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::PlotError;
use super::axis::{coord, format_number, omitted_note, ticks, widen};
use super::font::{AXIS_PX, FAMILY, LABEL_PX, TICK_PX, TITLE_PX};
use super::legend::{self, Occupied};
use super::output::{Sink, draw_notes, render_to, svg_of};
use super::palette::color;

/// A histogram description: each group gets its own colour; all groups share
/// the same bins; the y axis is probability density (each group integrates
/// to 1, or with a [`range`](Histogram::range) to the fraction of its values
/// inside the range).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Histogram {
    /// Title above the plot.
    pub title: String,
    /// X axis description (the y axis is "density").
    pub x_label: String,
    /// `(group name, values)` pairs.
    pub values: Vec<(String, Vec<f64>)>,
    /// Number of bins (0 is treated as 1).
    pub bins: usize,
    /// Optional x range `(lo, hi)` of the bins (ignored unless finite with
    /// `lo < hi`); without it the bins span the data. Values outside are not
    /// drawn but counted: a note on the plot gives the counts per group
    /// (see [`Histogram::outside_range`]), and densities stay relative to
    /// all of a group's finite values.
    pub range: Option<(f64, f64)>,
    /// Values marked with a dashed vertical line and a label (a paper's
    /// numbers beside the simulated distribution); the x axis widens to
    /// show them.
    pub marks: Vec<Mark>,
}

/// A value marked on a histogram.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mark {
    /// Where, in the x axis's units.
    pub at: f64,
    /// What it is, e.g. "paper: best 337 ms".
    pub label: String,
}

impl Histogram {
    /// The range actually used, if any (finite, `lo < hi`).
    fn valid_range(&self) -> Option<(f64, f64)> {
        self.range
            .filter(|&(lo, hi)| lo.is_finite() && hi.is_finite() && lo < hi)
    }

    /// Per group with finite values outside [`range`](Histogram::range):
    /// `(group name, count below lo, count above hi)`. Empty without a range
    /// or when every value is inside.
    pub fn outside_range(&self) -> Vec<(String, usize, usize)> {
        let Some((lo, hi)) = self.valid_range() else {
            return Vec::new();
        };
        self.values
            .iter()
            .map(|(name, v)| {
                let below = v.iter().filter(|x| x.is_finite() && **x < lo).count();
                let above = v.iter().filter(|x| x.is_finite() && **x > hi).count();
                (name.clone(), below, above)
            })
            .filter(|g| g.1 + g.2 > 0)
            .collect()
    }

    /// One line per group with values outside the range, e.g.
    /// `x range [11.9, 14.1]: 3 below, 5 above not shown (a=1)`.
    pub fn outside_range_notes(&self) -> Vec<String> {
        let Some((lo, hi)) = self.valid_range() else {
            return Vec::new();
        };
        let groups = self.values.len();
        self.outside_range()
            .into_iter()
            .map(|(name, below, above)| {
                let total = self
                    .values
                    .iter()
                    .find(|g| g.0 == name)
                    .map_or(0, |g| g.1.iter().filter(|x| x.is_finite()).count());
                let whose = if groups > 1 && !name.is_empty() {
                    format!(" ({name})")
                } else {
                    String::new()
                };
                format!(
                    "x range [{}, {}]: {below} value(s) below and {above} above of {total} not shown{whose}",
                    format_number(lo),
                    format_number(hi)
                )
            })
            .collect()
    }
}

/// Binned groups: shared edges and per-group densities.
struct Binned {
    lo: f64,
    width: f64,
    groups: Vec<(String, Vec<f64>)>,
}

fn bin(h: &Histogram) -> (Binned, usize) {
    let bins = h.bins.max(1);
    let mut dropped = 0;
    let finite: Vec<(String, Vec<f64>)> = h
        .values
        .iter()
        .map(|(name, v)| {
            let f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
            dropped += v.len() - f.len();
            (name.clone(), f)
        })
        .collect();
    let (lo, hi) = match h.valid_range() {
        Some(r) => r,
        None => {
            let all = finite.iter().flat_map(|g| g.1.iter().copied());
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for v in all {
                lo = lo.min(v);
                hi = hi.max(v);
            }
            if !lo.is_finite() {
                (0.0, 1.0)
            } else if hi <= lo {
                widen(lo, hi, 0.0)
            } else {
                (lo, hi)
            }
        }
    };
    let width = (hi - lo) / bins as f64;
    let groups = finite
        .into_iter()
        .map(|(name, v)| {
            let mut counts = vec![0u64; bins];
            // Values outside [lo, hi] (only with a range) are not binned but
            // still count in `n`.
            for x in v.iter().filter(|&&x| x >= lo && x <= hi) {
                let i = (((x - lo) / width) as usize).min(bins - 1);
                counts[i] += 1;
            }
            let n = v.len().max(1) as f64;
            (name, counts.iter().map(|&c| c as f64 / (n * width)).collect())
        })
        .collect();
    (Binned { lo, width, groups }, dropped)
}

/// The y axis's description: a density per unit of x, the unit taken from
/// the x label's last parenthesis ("frame time (ms)" gives "density (1/ms)").
pub(crate) fn density_label(x_label: &str) -> String {
    let unit = x_label
        .rfind('(')
        .and_then(|i| x_label[i + 1..].split(')').next())
        .map(|u| u.split(',').next().unwrap_or(u).trim())
        .filter(|u| !u.is_empty() && u.len() <= 12 && !u.contains(' '));
    match unit {
        Some(u) => format!("density (1/{u})"),
        None => "density (per unit of x)".into(),
    }
}

/// The layout of a histogram's plot area: x range, y maximum, and where
/// the legend goes so that it covers no bar and no mark label (see
/// [`super::legend`]).
struct Layout {
    x: (f64, f64),
    ymax: f64,
    legend: SeriesLabelPosition,
    /// Legend box size (plot-area fractions).
    legend_box: (f64, f64),
    /// Whether the y axis grew to free a top band for the legend.
    grown: bool,
}

/// Whether mark `m`'s label is drawn left of its line: when, at about 7 px
/// a character on a 900 px plot area, it would run past the right edge of
/// the x range `x`.
fn label_goes_left(m: &Mark, x: (f64, f64)) -> bool {
    let chars = m.label.chars().count() as f64 + 1.0;
    (m.at - x.0) / (x.1 - x.0) + chars * 7.0 / 900.0 > 1.0
}

/// Where mark `i`'s label is drawn: its height as a fraction of the plot
/// area (stacked down from the top, below a legend band `band`).
fn mark_label_y(i: usize, band: f64) -> f64 {
    0.97 - band - 0.06 * (i % 8) as f64
}

fn layout(h: &Histogram, b: &Binned) -> Layout {
    let bins = h.bins.max(1);
    let hi = b.lo + b.width * bins as f64;
    let top = b.groups.iter().flat_map(|g| g.1.iter().copied()).fold(0.0f64, f64::max);
    let mut ymax = if top > 0.0 && top.is_finite() { top * 1.08 } else { 1.0 };
    let marks: Vec<&Mark> = h.marks.iter().filter(|m| m.at.is_finite()).collect();
    let lo = marks.iter().map(|m| m.at).fold(b.lo, f64::min);
    let hi = marks.iter().map(|m| m.at).fold(hi, f64::max);
    let pad = (hi - lo) * 0.02;
    let x = (lo - pad, hi + pad);
    let named: Vec<&String> = b.groups.iter().map(|g| &g.0).filter(|n| !n.is_empty()).collect();
    let longest = named.iter().map(|n| n.chars().count()).max().unwrap_or(0);
    let (bw, bh) = legend::legend_size(named.len(), longest);
    let occupied = |ymax: f64, band: f64| {
        let fx = |v: f64| (v - x.0) / (x.1 - x.0);
        let mut occ = Vec::new();
        for (_, dens) in &b.groups {
            for (i, &d) in dens.iter().enumerate() {
                if d > 0.0 {
                    for k in 0..4 {
                        let xv = b.lo + b.width * (i as f64 + (k as f64 + 0.5) / 4.0);
                        occ.push(Occupied {
                            x: fx(xv),
                            y0: 0.0,
                            y1: d / ymax,
                        });
                    }
                }
            }
        }
        // Mark labels: about 7 px per character right of the line (left of
        // it near the right edge).
        for (i, m) in marks.iter().enumerate() {
            let y = mark_label_y(i, band);
            let chars = m.label.chars().count() as f64 + 1.0;
            let side = if label_goes_left(m, x) { -1.0 } else { 1.0 };
            for k in 0..=8 {
                occ.push(Occupied::point(
                    fx(m.at) + side * k as f64 / 8.0 * chars * 7.0 / 900.0,
                    y,
                ));
            }
        }
        occ
    };
    let (mut legend, covered) = legend::corner(&occupied(ymax, 0.0), bw, bh);
    let grown = covered > 0 && !named.is_empty();
    if grown {
        // No free corner: the y axis grows so that bars and mark labels keep
        // below a top band, where the legend goes.
        ymax = legend::grow((0.0, ymax), bh).1;
        let occ = occupied(ymax, bh);
        legend = if legend::covered(&occ, true, true, bw, bh) < legend::covered(&occ, false, true, bw, bh) {
            SeriesLabelPosition::UpperLeft
        } else {
            SeriesLabelPosition::UpperRight
        };
    }
    Layout {
        x,
        ymax,
        legend,
        legend_box: (bw, bh),
        grown,
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    h: &Histogram,
    b: &Binned,
    notes: &[String],
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let bins = h.bins.max(1);
    let l = layout(h, b);
    let ymax = l.ymax;
    let marks: Vec<&Mark> = h.marks.iter().filter(|m| m.at.is_finite()).collect();
    // Mark labels go below the legend's band when the axis grew for it.
    let band = if l.grown { l.legend_box.1 } else { 0.0 };
    let xt = ticks(l.x.0, l.x.1, false, false);
    let yt = ticks(0.0, ymax, false, false);
    let mut chart = ChartBuilder::on(root)
        .caption(&h.title, (FAMILY, TITLE_PX))
        .margin(20)
        .margin_bottom(20 + 16 * notes.len() as u32)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(coord(l.x.0, l.x.1, &xt), coord(0.0, ymax, &yt))
        .map_err(e)?;
    let fx = |v: &f64| xt.label_at(*v);
    let fy = |v: &f64| yt.label_at(*v);
    chart
        .configure_mesh()
        .x_desc(h.x_label.as_str())
        .y_desc(density_label(&h.x_label))
        .label_style((FAMILY, TICK_PX))
        .axis_desc_style((FAMILY, AXIS_PX))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .draw()
        .map_err(e)?;
    let mut any_legend = false;
    for (gi, (name, dens)) in b.groups.iter().enumerate() {
        let c = color(gi);
        chart
            .draw_series(dens.iter().enumerate().map(|(i, &d)| {
                let x0 = b.lo + b.width * i as f64;
                Rectangle::new([(x0, 0.0), (x0 + b.width, d)], c.mix(0.3).filled())
            }))
            .map_err(e)?;
        let mut outline = Vec::with_capacity(2 * dens.len() + 2);
        outline.push((b.lo, 0.0));
        for (i, &d) in dens.iter().enumerate() {
            let x0 = b.lo + b.width * i as f64;
            outline.push((x0, d));
            outline.push((x0 + b.width, d));
        }
        outline.push((b.lo + b.width * bins as f64, 0.0));
        let s = chart
            .draw_series(LineSeries::new(outline, c.stroke_width(2)))
            .map_err(e)?;
        if !name.is_empty() {
            any_legend = true;
            s.label(name.as_str())
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], c.mix(0.6).filled()));
        }
    }
    // Marks: dashed vertical lines, labels stacked down from the top so
    // that close values stay readable.
    for (i, m) in marks.iter().enumerate() {
        chart
            .draw_series(DashedLineSeries::new(
                [(m.at, 0.0), (m.at, ymax)],
                6,
                4,
                BLACK.mix(0.75).stroke_width(2),
            ))
            .map_err(e)?;
        let y = ymax * mark_label_y(i, band);
        // Right of the line, or left of it where the label would run past
        // the plot's right edge.
        let font = (FAMILY, LABEL_PX).into_font().color(&BLACK);
        let (text, font) = if label_goes_left(m, l.x) {
            (format!("{} ", m.label), font.pos(Pos::new(HPos::Right, VPos::Top)))
        } else {
            (format!(" {}", m.label), font)
        };
        chart
            .draw_series(std::iter::once(Text::new(text, (m.at, y), font)))
            .map_err(e)?;
    }
    if any_legend {
        chart
            .configure_series_labels()
            .label_font((FAMILY, TICK_PX))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(l.legend)
            .draw()
            .map_err(e)?;
    }
    draw_notes(root, notes)
}

/// Write `h` to `<base>.svg` and `<base>.png`.
pub fn histogram(base: &Path, h: &Histogram) -> Result<(), PlotError> {
    histogram_to(Sink::Files(base), h)
}

/// `h` as one SVG document (what [`histogram`] writes to `<base>.svg`).
pub fn histogram_svg(h: &Histogram) -> Result<String, PlotError> {
    svg_of(|sink| histogram_to(sink, h))
}

fn histogram_to(sink: Sink<'_>, h: &Histogram) -> Result<(), PlotError> {
    let (binned, dropped) = bin(h);
    let mut notes: Vec<String> = omitted_note(dropped, false).into_iter().collect();
    notes.extend(h.outside_range_notes().into_iter().map(|n| format!("note: {n}")));
    if h.values.iter().all(|g| g.1.is_empty()) {
        notes.push("note: no data".into());
    }
    render_to(sink, |r| draw(r, h, &binned, &notes), |r| draw(r, h, &binned, &notes))
}

#[cfg(test)]
mod tests {
    use super::super::output::test_support::assert_plot_files;
    use super::*;

    fn hist(values: Vec<(String, Vec<f64>)>, bins: usize) -> Histogram {
        Histogram {
            title: "h".into(),
            x_label: "frame time (ms)".into(),
            values,
            bins,
            range: None,
            marks: Vec::new(),
        }
    }

    #[test]
    fn range_bins_only_inside_and_counts_the_rest() {
        let h = Histogram {
            range: Some((1.0, 3.0)),
            ..hist(
                vec![
                    ("a".into(), vec![0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 3.5, f64::NAN]),
                    ("b".into(), vec![2.0, 2.5]),
                ],
                2,
            )
        };
        let (b, dropped) = bin(&h);
        assert_eq!(dropped, 1);
        assert_eq!((b.lo, b.width), (1.0, 1.0));
        // a: [1,2) holds 1.0, 1.5; [2,3] holds 2.0, 3.0; of 7 finite values.
        assert_eq!(b.groups[0].1, vec![2.0 / 7.0, 2.0 / 7.0]);
        assert_eq!(b.groups[1].1, vec![0.0, 1.0]);
        assert_eq!(h.outside_range(), vec![("a".to_string(), 2, 1)]);
        let notes = h.outside_range_notes();
        assert_eq!(
            notes,
            ["x range [1, 3]: 2 value(s) below and 1 above of 7 not shown (a)"]
        );
        // An invalid range is ignored: bins span the data again.
        let h = Histogram {
            range: Some((3.0, 1.0)),
            ..h
        };
        assert_eq!(bin(&h).0.lo, 0.0);
        assert!(h.outside_range().is_empty());
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("ranged");
        histogram(
            &base,
            &Histogram {
                range: Some((1.0, 3.0)),
                ..h
            },
        )
        .unwrap();
        assert_plot_files(&base);
    }

    #[test]
    fn a_mark_label_near_the_right_edge_goes_left_of_its_line() {
        let m = |at: f64| Mark {
            at,
            label: "paper c = 1.52 ms above the lowest frame plotted".into(),
        };
        // 49 characters at about 7 px on a 900 px area: 38% of the width.
        assert!(!label_goes_left(&m(12.0), (11.8, 14.1)));
        assert!(label_goes_left(&m(13.5), (11.8, 14.1)));
    }

    #[test]
    fn marks_widen_the_axis_and_are_drawn() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("marked");
        let h = Histogram {
            marks: vec![
                Mark {
                    at: 2.0,
                    label: "paper: 2".into(),
                },
                Mark {
                    at: 40.0,
                    label: "far right".into(),
                },
            ],
            ..hist(vec![("a".into(), vec![1.0, 2.0, 3.0])], 3)
        };
        histogram(&base, &h).unwrap();
        assert_plot_files(&base);
        let svg = std::fs::read_to_string(base.with_extension("svg")).unwrap();
        assert!(svg.contains("paper: 2") && svg.contains("far right"), "labels drawn");
        // The axis reaches the far mark: a tick label of 30 or more is drawn.
        let ticks: Vec<f64> = svg
            .split('>')
            .filter_map(|t| t.split('<').next()?.trim().parse::<f64>().ok())
            .collect();
        assert!(ticks.iter().any(|&t| t >= 30.0), "axis widened: {ticks:?}");
    }

    #[test]
    fn the_legend_covers_no_bar_and_no_mark_label() {
        // The system-noise case: two groups with long names, spikes and a
        // mark label near the right edge where the legend used to sit.
        let spiky: Vec<f64> = (0..1000).map(|i| [12.1, 12.6, 13.1][i % 3]).collect();
        let smooth: Vec<f64> = (0..1000).map(|i| 12.2 + (i as f64 / 1000.0) * 1.5).collect();
        let h = Histogram {
            range: Some((11.8, 14.1)),
            marks: vec![
                Mark {
                    at: 11.92,
                    label: "paper Fig. 3 axis from 11.92 ms".into(),
                },
                Mark {
                    at: 13.96,
                    label: "to 13.96 ms".into(),
                },
            ],
            ..hist(
                vec![
                    ("noise.enabled=true, variation.enabled=false".into(), spiky),
                    ("noise.enabled=true, variation.enabled=true".into(), smooth),
                ],
                92,
            )
        };
        let (b, _) = bin(&h);
        let l = layout(&h, &b);
        // Re-derive what is drawn in plot-area fractions and check the box.
        let (bw, bh) = l.legend_box;
        let fx = |v: f64| (v - l.x.0) / (l.x.1 - l.x.0);
        let mut occ = Vec::new();
        for (_, dens) in &b.groups {
            for (i, &d) in dens.iter().enumerate() {
                if d > 0.0 {
                    let xv = b.lo + b.width * (i as f64 + 0.5);
                    occ.push(Occupied {
                        x: fx(xv),
                        y0: 0.0,
                        y1: d / l.ymax,
                    });
                }
            }
        }
        let band = if l.grown { bh } else { 0.0 };
        for (i, m) in h.marks.iter().enumerate() {
            let chars = m.label.chars().count() as f64 + 1.0;
            for k in 0..=8 {
                occ.push(Occupied::point(
                    fx(m.at) + k as f64 / 8.0 * chars * 7.0 / 900.0,
                    mark_label_y(i, band),
                ));
            }
        }
        let (left, top) = match l.legend {
            SeriesLabelPosition::UpperLeft => (true, true),
            SeriesLabelPosition::UpperRight => (false, true),
            SeriesLabelPosition::LowerLeft => (true, false),
            _ => (false, false),
        };
        assert_eq!(legend::covered(&occ, left, top, bw, bh), 0, "{:?}", l.legend);
        assert_eq!(density_label("frame time (ms)"), "density (1/ms)");
        assert_eq!(density_label("latency (ms, log)"), "density (1/ms)");
        assert_eq!(density_label("size"), "density (per unit of x)");
    }

    #[test]
    fn densities_integrate_to_one() {
        let h = hist(vec![("a".into(), vec![0.0, 1.0, 1.0, 2.0, 3.0, 4.0])], 4);
        let (b, dropped) = bin(&h);
        assert_eq!(dropped, 0);
        let total: f64 = b.groups[0].1.iter().map(|d| d * b.width).sum();
        assert!((total - 1.0).abs() < 1e-12);
        // bins [0,1) [1,2) [2,3) [3,4]: counts 1,2,1,2
        let counts: Vec<f64> = b.groups[0].1.iter().map(|d| d * b.width * 6.0).collect();
        assert_eq!(
            counts.iter().map(|c| c.round() as u32).collect::<Vec<_>>(),
            vec![1, 2, 1, 2]
        );
    }

    #[test]
    fn writes_files_for_normal_and_degenerate_data() {
        let dir = tempfile::tempdir().unwrap();
        let cases = vec![
            (
                "two",
                hist(
                    vec![
                        ("a".into(), (0..500).map(|i| (i % 37) as f64).collect()),
                        ("b".into(), (0..300).map(|i| 10.0 + (i % 11) as f64).collect()),
                    ],
                    30,
                ),
            ),
            ("empty", hist(vec![], 10)),
            ("empty_group", hist(vec![("a".into(), vec![])], 10)),
            ("same", hist(vec![("a".into(), vec![3.0; 10])], 0)),
            (
                "nan",
                hist(vec![("a".into(), vec![f64::NAN, 1.0, f64::INFINITY, 2.0])], 5),
            ),
        ];
        for (name, h) in cases {
            let base = dir.path().join(name);
            histogram(&base, &h).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_plot_files(&base);
        }
    }
}
