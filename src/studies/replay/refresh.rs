//! The refresh of a replay as captured: the period and phase of the
//! vertical blanks fitted to the displayed frames' screen times.

use crate::stats::quantile::quantile;

/// The refresh period (ms) and a screen time on its grid, fitted to the
/// displayed frames' screen times: a first period from the shorter
/// display changes, then least squares of screen time on refresh count.
pub fn fit_refresh(screen: &[f64]) -> Option<(f64, f64)> {
    let mut d: Vec<f64> = screen.windows(2).map(|w| w[1] - w[0]).filter(|&x| x > 1.0).collect();
    if d.is_empty() {
        return None;
    }
    d.sort_by(f64::total_cmp);
    let mut period = quantile(&d, 0.1);
    let mut phase = screen[0];
    for _ in 0..4 {
        let n: Vec<f64> = screen.iter().map(|s| ((s - screen[0]) / period).round()).collect();
        let k = n.len() as f64;
        let (mn, ms) = (n.iter().sum::<f64>() / k, screen.iter().sum::<f64>() / k);
        let sxx: f64 = n.iter().map(|x| (x - mn) * (x - mn)).sum();
        if sxx == 0.0 {
            break;
        }
        let sxy: f64 = n.iter().zip(screen).map(|(x, y)| (x - mn) * (y - ms)).sum();
        period = sxy / sxx;
        phase = ms - period * mn;
    }
    (period.is_finite() && period > 0.0).then_some((period, phase))
}

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
