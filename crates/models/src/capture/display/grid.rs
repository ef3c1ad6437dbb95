//! A refresh grid fitted to display-change times (issue 54, item 2): the
//! longest period every change is a whole multiple of, unless a finer one
//! explains more of them than chance would, and the phase of its vertical
//! blanks ([`fit_grid`]).

use serde::Serialize;

use rendersim_report::stats::quantile::quantile;

/// The shortest refresh period searched for (ms): a 500 Hz panel.
const MIN_PERIOD_MS: f64 = 2.0;
/// The longest (ms): a 20 Hz grid (every third refresh of a 60 Hz panel).
const MAX_PERIOD_MS: f64 = 50.0;
/// Display changes closer than this (ms) are one vertical blank seen by
/// two swap chains.
const SAME_BLANK_MS: f64 = 0.5;
/// Intervals longer than this (ms) are gaps, not evidence.
const LONGEST_INTERVAL_MS: f64 = 250.0;
/// How far (ms) a display change may be from a grid line and still be on
/// it: 6% of the period, at most 0.25 ms (the captures' screen times
/// scatter by about 0.05 ms around their vertical blanks; FrameView's
/// composed flips by up to 0.2 ms).
pub fn tolerance(period_ms: f64) -> f64 {
    (0.06 * period_ms).min(0.25)
}

/// A refresh grid: vertical blanks every `period_ms`, one at `phase_ms`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Grid {
    /// The refresh period, ms.
    pub period_ms: f64,
    /// A vertical blank on the capture's clock, ms.
    pub phase_ms: f64,
    /// Intervals between display changes the grid was fitted to.
    pub intervals: usize,
    /// Of those, how many are a whole number of periods (within [`tolerance`]).
    pub on_grid: usize,
}

impl Grid {
    /// The refresh rate, Hz.
    pub fn hz(&self) -> f64 {
        1000.0 / self.period_ms
    }

    /// Whether a screen time lies on the grid.
    pub fn holds(&self, t: f64) -> bool {
        let x = (t - self.phase_ms) / self.period_ms;
        (x - x.round()).abs() * self.period_ms < tolerance(self.period_ms)
    }

    /// The share of `times` on the grid (`None` for none).
    pub fn share(&self, times: &[f64]) -> Option<f64> {
        (!times.is_empty()).then(|| times.iter().filter(|&&t| self.holds(t)).count() as f64 / times.len() as f64)
    }

    /// Whether two grids are one panel's (the same period within 0.5%,
    /// blanks within tolerance of each other).
    pub(super) fn same_panel(&self, other: &Grid) -> bool {
        (self.period_ms / other.period_ms - 1.0).abs() < 0.005 && self.holds(other.phase_ms)
    }
}

/// Intervals (ms) between consecutive display changes of sorted `times`,
/// changes of one vertical blank merged, gaps left out.
pub(super) fn intervals(times: &[f64]) -> Vec<f64> {
    let mut d = Vec::with_capacity(times.len());
    let mut last: Option<f64> = None;
    for &t in times {
        match last {
            Some(l) if t - l <= SAME_BLANK_MS => continue,
            Some(l) if t - l <= LONGEST_INTERVAL_MS => d.push(t - l),
            _ => {}
        }
        last = Some(t);
    }
    d
}

/// How many intervals are whole multiples of `period` (within tolerance).
fn fits(d: &[f64], period: f64) -> usize {
    let tol = tolerance(period);
    d.iter()
        .filter(|&&x| {
            let n = (x / period).round();
            n >= 1.0 && (x - n * period).abs() < tol
        })
        .count()
}

/// Least-squares period of the intervals that are whole multiples of `period`.
fn refine(d: &[f64], mut period: f64) -> f64 {
    for _ in 0..3 {
        let tol = tolerance(period);
        let (mut nd, mut nn) = (0.0, 0.0);
        for &x in d {
            let n = (x / period).round();
            if n >= 1.0 && (x - n * period).abs() < tol {
                nd += n * x;
                nn += n * n;
            }
        }
        if nn == 0.0 {
            break;
        }
        period = nd / nn;
    }
    period
}

/// The refresh grid of display-change times (ms, any order, any number of
/// swap chains pooled), or `None` with fewer than three intervals.
///
/// The period is the longest whose whole multiples the intervals are,
/// unless a shorter one explains more of them than chance would (an
/// interval off one grid lands within tolerance of a finer grid with
/// probability twice the tolerance over the finer period); then the
/// phase is fitted by least squares of the changes on the grid against
/// their refresh counts. The result says how many intervals are on it:
/// the caller decides whether that is a grid at all.
///
/// ```
/// use rendersim_models::capture::display::fit_grid;
/// // A 120 Hz panel; an app shows every fourth refresh, now and then a third.
/// let p = 1000.0 / 120.0;
/// let mut t = vec![0.0];
/// for i in 1..60 { t.push(t[i - 1] + p * if i % 15 == 0 { 3.0 } else { 4.0 }); }
/// let g = fit_grid(&t).unwrap();
/// assert!((g.hz() - 120.0).abs() < 1e-6, "{}", g.hz());
/// ```
pub fn fit_grid(times: &[f64]) -> Option<Grid> {
    let mut t: Vec<f64> = times.iter().copied().filter(|x| x.is_finite()).collect();
    t.sort_by(f64::total_cmp);
    let d = intervals(&t);
    if d.len() < 3 {
        return None;
    }
    // Candidates are scored on at most this many intervals, evenly strided
    // (a 20,000-frame capture's choice does not need them all); the phase
    // fit below takes every change.
    const SCORED: usize = 2000;
    let d: Vec<f64> = if d.len() > SCORED {
        let step = d.len() as f64 / SCORED as f64;
        (0..SCORED).map(|i| d[(i as f64 * step) as usize]).collect()
    } else {
        d
    };
    let mut sorted = d.clone();
    sorted.sort_by(f64::total_cmp);
    let mut candidates: Vec<f64> = Vec::new();
    for q in [0.02, 0.1, 0.25, 0.5] {
        let d0 = quantile(&sorted, q);
        let mut n = 1.0;
        while d0 / n >= MIN_PERIOD_MS {
            if d0 / n <= MAX_PERIOD_MS {
                candidates.push(refine(&d, d0 / n));
            }
            n += 1.0;
        }
    }
    let mut scored: Vec<(f64, usize)> = candidates
        .into_iter()
        .filter(|p| (MIN_PERIOD_MS..=MAX_PERIOD_MS).contains(p))
        .map(|p| (p, fits(&d, p)))
        .collect();
    if scored.is_empty() {
        return None;
    }
    // Longest first.
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    let &(best_p, best_n) = scored
        .iter()
        .max_by(|a, b| a.1.cmp(&b.1).then(a.0.total_cmp(&b.0)))
        .expect("not empty");
    let chance = (2.0 * tolerance(best_p) / best_p).min(1.0);
    let &(period, _) = scored
        .iter()
        .find(|&&(_, n)| {
            let expected = (d.len() - n) as f64 * chance;
            (best_n - n) as f64 <= expected + 3.0 * expected.sqrt() + 1.0
        })
        .expect("the best candidate passes its own test");
    Some(phase_fit(&t, period))
}

/// The grid of period about `period` through sorted times `t`: refresh
/// counts accumulated interval by interval, then least squares of the
/// times on the grid against their counts.
fn phase_fit(t: &[f64], period: f64) -> Grid {
    let mut counts = Vec::with_capacity(t.len());
    let mut k = 0.0;
    let mut last = t[0];
    for &x in t {
        k += ((x - last) / period).round();
        counts.push(k);
        last = x;
    }
    let fit = |keep: &dyn Fn(usize) -> bool| -> Option<(f64, f64)> {
        let idx: Vec<usize> = (0..t.len()).filter(|&i| keep(i)).collect();
        let m = idx.len() as f64;
        if m < 2.0 {
            return None;
        }
        let mk = idx.iter().map(|&i| counts[i]).sum::<f64>() / m;
        let mt = idx.iter().map(|&i| t[i]).sum::<f64>() / m;
        let sxx: f64 = idx.iter().map(|&i| (counts[i] - mk).powi(2)).sum();
        if sxx == 0.0 {
            return None;
        }
        let sxy: f64 = idx.iter().map(|&i| (counts[i] - mk) * (t[i] - mt)).sum();
        let p = sxy / sxx;
        Some((p, mt - p * mk))
    };
    let (mut p, mut phase) = fit(&|_| true).unwrap_or((period, t[0]));
    if !(p.is_finite() && p > 0.0) {
        (p, phase) = (period, t[0]);
    }
    // Again without the changes off the first fit's grid.
    let tol = tolerance(p);
    if let Some((p2, ph2)) = fit(&|i| (t[i] - phase - counts[i] * p).abs() < tol)
        && p2.is_finite()
        && p2 > 0.0
    {
        (p, phase) = (p2, ph2);
    }
    let d = intervals(t);
    Grid {
        period_ms: p,
        phase_ms: phase,
        intervals: d.len(),
        on_grid: fits(&d, p),
    }
}
