//! Plots written as SVG and PNG side by side.
//!
//! A small API shared by the experiment runner and other code:
//! [`line_plot`], [`histogram`], [`scatter`] and [`bar_chart`] each take a base path without
//! extension and write `<base>.svg` and `<base>.png` (1024x640); their `_svg`
//! twins return the SVG document instead (a page that shows it). Text is
//! drawn with the embedded DejaVu Sans font, so no system fonts are needed.
//!
//! All plots tolerate awkward data: empty inputs, a single point and
//! identical values (degenerate axis ranges are widened), and NaN or infinite
//! values (dropped, with a note drawn on the plot). On log axes, values that
//! are not positive are dropped in the same way.

mod axis;
mod bar;
mod error;
mod font;
mod histogram;
mod legend;
mod line;
mod output;
mod palette;
mod scatter;
mod timeline;

pub use bar::{BarChart, BarSeries, bar_chart, bar_chart_svg};
pub use error::PlotError;
pub use histogram::{Histogram, Mark, histogram, histogram_svg};
pub use line::{LinePlot, Reference, Series, line_plot, line_plot_svg};
pub use scatter::{Scatter, ScatterPoint, scatter};
pub use timeline::{Bar, Fill, ImageFormat, Lane, Level, Timeline, timeline, timeline_svg};

/// Width of written plots in pixels.
pub const WIDTH: u32 = 1024;
/// Height of written plots in pixels.
pub const HEIGHT: u32 = 640;
