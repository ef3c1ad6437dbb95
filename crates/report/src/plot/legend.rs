//! Where a legend goes: the corner of the plot area whose box covers the
//! fewest drawn things (points and line samples, histogram bars, labels of
//! marked values), every plot kind using the same rule; when every corner
//! covers something, the caller grows the y axis by the legend's height so
//! that the top band is free. A line plot's legend of more than
//! [`IN_PLOT_ENTRIES`] entries goes to a panel beside the plot instead
//! ([`panel_width`], [`fit_text`], shared with the scatter plot's panel of
//! labels).

use plotters::coord::Shift;
use plotters::prelude::{DrawingArea, DrawingAreaErrorKind, DrawingBackend, SeriesLabelPosition, TextStyle};

/// A line plot's legend with more entries than this goes to a panel beside
/// the plot: a box that tall would cover most of the plot area, and the
/// corner search ([`corner`], its height capped by [`legend_height`])
/// would not see it.
pub(crate) const IN_PLOT_ENTRIES: usize = 8;

/// Width of a panel beside a plot that lists `rows` at `font`, each after
/// `lead` pixels of swatch or number: the widest row, at most two fifths
/// of `area`'s width (longer rows are shortened by [`fit_text`]).
pub(crate) fn panel_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[String],
    font: &TextStyle,
    lead: i32,
) -> i32 {
    let widest = rows
        .iter()
        .filter_map(|r| area.estimate_text_size(r, font).ok())
        .map(|(w, _)| w as i32)
        .max()
        .unwrap_or(0);
    (widest + lead + 8).min(area.dim_in_pixel().0 as i32 * 2 / 5)
}

/// `text`, shortened with an ellipsis until it is at most `max_w` pixels
/// wide at `font` (never below four characters).
pub(crate) fn fit_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    font: &TextStyle,
    max_w: i32,
) -> Result<String, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut text = text.to_string();
    while text.chars().count() > 4 && area.estimate_text_size(&text, font)?.0 as i32 > max_w {
        text.pop();
        text.pop();
        text.push('…');
    }
    Ok(text)
}

/// Something drawn, in plot-area fractions (`0..1` left to right, bottom to
/// top): a vertical extent at one x (a point is `y0 == y1`; a histogram bar
/// from 0 to its height).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Occupied {
    /// Horizontal position.
    pub x: f64,
    /// Bottom.
    pub y0: f64,
    /// Top.
    pub y1: f64,
}

impl Occupied {
    /// A point.
    pub(crate) fn point(x: f64, y: f64) -> Self {
        Occupied { x, y0: y, y1: y }
    }
}

/// The legend box's size in plot-area fractions: about 8 px per character
/// of the longest label plus the swatch, on a plot area about 900 x 500 px;
/// a line per entry.
pub(crate) fn legend_size(entries: usize, longest_label: usize) -> (f64, f64) {
    let w = ((longest_label as f64 * 8.0 + 60.0) / 900.0).min(0.95);
    (w, legend_height(entries))
}

/// The legend's height as a fraction of the plot area's (a line per entry).
pub(crate) fn legend_height(entries: usize) -> f64 {
    (0.05 + 0.065 * entries as f64).min(0.6)
}

/// How many `occupied` things a legend box of `w` x `h` in a corner covers.
pub(crate) fn covered(occupied: &[Occupied], left: bool, top: bool, w: f64, h: f64) -> usize {
    occupied
        .iter()
        .filter(|o| {
            let in_x = if left { o.x <= w } else { o.x >= 1.0 - w };
            let in_y = if top { o.y1 >= 1.0 - h } else { o.y0 <= h };
            in_x && in_y
        })
        .count()
}

/// The middle of the left or the right edge covering fewer occupied things
/// (the left on a tie), and how many it covers: where a legend goes when
/// the y axis may not grow to free a corner (a bounded quantity).
pub(crate) fn middle(occupied: &[Occupied], w: f64, h: f64) -> (SeriesLabelPosition, usize) {
    let (lo, hi) = (0.5 - h / 2.0, 0.5 + h / 2.0);
    let count = |left: bool| {
        occupied
            .iter()
            .filter(|o| {
                let in_x = if left { o.x <= w } else { o.x >= 1.0 - w };
                in_x && o.y1 >= lo && o.y0 <= hi
            })
            .count()
    };
    let (l, r) = (count(true), count(false));
    if r < l {
        (SeriesLabelPosition::MiddleRight, r)
    } else {
        (SeriesLabelPosition::MiddleLeft, l)
    }
}

/// The corner covering the fewest occupied things, and how many it covers.
/// Ties keep the upper right, then upper left, lower right, lower left.
pub(crate) fn corner(occupied: &[Occupied], w: f64, h: f64) -> (SeriesLabelPosition, usize) {
    [
        (SeriesLabelPosition::UpperRight, covered(occupied, false, true, w, h)),
        (SeriesLabelPosition::UpperLeft, covered(occupied, true, true, w, h)),
        (SeriesLabelPosition::LowerRight, covered(occupied, false, false, w, h)),
        (SeriesLabelPosition::LowerLeft, covered(occupied, true, false, w, h)),
    ]
    .into_iter()
    .min_by_key(|c| c.1)
    .unwrap_or((SeriesLabelPosition::UpperRight, 0))
}

/// Whether the legend, placed by [`corner`] (and, when that covers
/// something, with the y axis grown by `grow` so that the data keep to the
/// lower `1 - h` of the plot area), covers none of `occupied`: the check
/// the plots' layouts are tested against.
#[cfg(test)]
pub(crate) fn is_clear(occupied: &[Occupied], w: f64, h: f64) -> bool {
    let (_, n) = corner(occupied, w, h);
    if n == 0 {
        return true;
    }
    // Grown: every y scales by 1 - h, so the top band holds nothing.
    let grown: Vec<Occupied> = occupied
        .iter()
        .map(|o| Occupied {
            x: o.x,
            y0: o.y0 * (1.0 - h),
            y1: o.y1 * (1.0 - h) - 1e-12,
        })
        .collect();
    covered(&grown, false, true, w, h) == 0 || covered(&grown, true, true, w, h) == 0
}

/// The y-axis range grown so that the data keep below a top band of
/// `h` (a fraction of the plot area).
pub(crate) fn grow(yr: (f64, f64), h: f64) -> (f64, f64) {
    (yr.0, yr.1 + (yr.1 - yr.0) * h / (1.0 - h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legend_avoids_bars_and_points() {
        // Bars high on the right, low on the left: the upper left is free.
        let bars: Vec<Occupied> = (0..20)
            .map(|i| Occupied {
                x: i as f64 / 19.0,
                y0: 0.0,
                y1: i as f64 / 19.0 * 0.95,
            })
            .collect();
        let (w, h) = legend_size(2, 20);
        let (pos, n) = corner(&bars, w, h);
        assert_eq!(n, 0);
        assert!(matches!(pos, SeriesLabelPosition::UpperLeft), "{pos:?}");
        // Bars reach the top everywhere: no corner is free, but growing the
        // y axis frees the top band.
        let full: Vec<Occupied> = (0..20)
            .map(|i| Occupied {
                x: i as f64 / 19.0,
                y0: 0.0,
                y1: 1.0,
            })
            .collect();
        assert!(corner(&full, w, h).1 > 0);
        assert!(is_clear(&full, w, h));
        let (lo, hi) = grow((0.0, 10.0), h);
        assert_eq!(lo, 0.0);
        assert!((10.0 / hi - (1.0 - h)).abs() < 1e-12);
    }
}

#[cfg(test)]
mod middle_tests {
    use super::*;

    #[test]
    fn the_middle_of_the_freer_edge() {
        let at = |x: f64, y: f64| Occupied { x, y0: y, y1: y };
        // Data high and low on the left, through the middle on the right.
        let occ = [at(0.1, 0.9), at(0.1, 0.05), at(0.9, 0.5), at(0.95, 0.45)];
        assert!(matches!(middle(&occ, 0.3, 0.3), (SeriesLabelPosition::MiddleLeft, 0)));
        let occ = [at(0.1, 0.5), at(0.9, 0.95)];
        assert!(matches!(middle(&occ, 0.3, 0.3), (SeriesLabelPosition::MiddleRight, 0)));
    }
}
