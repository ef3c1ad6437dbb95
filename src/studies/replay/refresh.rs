//! The phase of an assumed refresh: the vertical blanks of a given
//! period nearest the displayed frames' screen times (an inferred
//! refresh comes with its own, `capture::display`).

/// The screen time on a refresh grid of `period` (ms) nearest, in least
/// squares, to the displayed frames' screen times.
pub fn fit_phase(screen: &[f64], period: f64) -> f64 {
    let k = screen.len() as f64;
    screen
        .iter()
        .map(|s| s - ((s - screen[0]) / period).round() * period)
        .sum::<f64>()
        / k
}
