//! Derived values computed per point after all runs: frame-time spreads
//! (`interval_width`, `quantile_width_from_min`) and the histogram's shape
//! (`modes`, `largest_bin_share`) from pooled per-frame data, and
//! comparisons between points (`relative_error`, `ratio`, `speedup`).
//!
//! Two spread definitions are provided because they answer different
//! questions:
//! - `interval_width` is the width of the central `level` interval, from the
//!   `(1 - level) / 2` quantile to the `1 - (1 - level) / 2` quantile: a
//!   symmetric measure of jitter that ignores both tails.
//! - `quantile_width_from_min` is `quantile(level) - min`: the spread above
//!   the fastest frame that covers `level` of all frames. This is the paper's
//!   constant `c` (frame times lie in `[min, min + c]` with probability
//!   `level`).
//!
//! Per-frame data are pooled over all replications of a point before the
//! quantiles are taken. `relative_error` and `speedup` use the replication
//! means of each point.

use crate::stats::quantile::quantile;

use super::spec::{DerivedKind, Experiment};
use super::sweep::{Point, values_match};

/// Width of the central `level` interval of `values`, or `None` when there
/// are no finite values.
pub fn interval_width(values: &[f64], level: f64) -> Option<f64> {
    let s = sorted_finite(values)?;
    let tail = (1.0 - level.clamp(0.0, 1.0)) / 2.0;
    Some(quantile(&s, 1.0 - tail) - quantile(&s, tail))
}

/// `quantile(level) - min` of `values`, or `None` when there are no finite
/// values.
pub fn quantile_width_from_min(values: &[f64], level: f64) -> Option<f64> {
    let s = sorted_finite(values)?;
    Some(quantile(&s, level) - s[0])
}

/// Counts of the finite `values` in bins of width `bin` from the smallest,
/// or `None` when there are none (or more than a million bins).
fn histogram(values: &[f64], bin: f64) -> Option<Vec<u64>> {
    let s = sorted_finite(values)?;
    let (lo, hi) = (s[0], s[s.len() - 1]);
    let bins = ((hi - lo) / bin).floor();
    if !(bins.is_finite() && bins < 1e6) {
        return None;
    }
    let mut h = vec![0u64; bins as usize + 1];
    for v in s {
        let i = (((v - lo) / bin).floor() as usize).min(h.len() - 1);
        h[i] += 1;
    }
    Some(h)
}

/// The modes of `values` in bins of width `bin`: the local maxima (a run of
/// equal bins counts once) whose topographic prominence (their height above
/// the highest of the two lowest points that separate them from a taller
/// bin, or from the ends) is at least `prominence` times the tallest bin.
/// `None` when there are no finite values.
pub fn modes(values: &[f64], bin: f64, prominence: f64) -> Option<f64> {
    let h = histogram(values, bin)?;
    let tallest = *h.iter().max()? as f64;
    let mut count = 0u32;
    let mut i = 0;
    while i < h.len() {
        // A plateau h[i..j] of equal bins.
        let mut j = i + 1;
        while j < h.len() && h[j] == h[i] {
            j += 1;
        }
        let left_lower = i == 0 || h[i - 1] < h[i];
        let right_lower = j == h.len() || h[j] < h[i];
        if left_lower && right_lower && h[i] > 0 {
            // The lowest bin on each side before a taller one (or the end);
            // of two equal peaks the earlier counts as the taller.
            let low = |range: &mut dyn Iterator<Item = usize>| {
                let mut m = h[i];
                for k in range {
                    if h[k] > h[i] || (h[k] == h[i] && k < i) {
                        return (m, true);
                    }
                    m = m.min(h[k]);
                }
                (m, false)
            };
            let (l, l_taller) = low(&mut (0..i).rev());
            let (r, r_taller) = low(&mut (j..h.len()));
            // The saddle towards a taller bin: the higher of the two sides'
            // lows where both lead to one, else the side that does; the
            // tallest peak stands on the ground (no values beyond the ends).
            let base = match (l_taller, r_taller) {
                (true, true) => l.max(r),
                (true, false) => l,
                (false, true) => r,
                (false, false) => 0,
            };
            if (h[i] - base) as f64 >= prominence * tallest {
                count += 1;
            }
        }
        i = j;
    }
    Some(f64::from(count))
}

/// The share of the finite `values` in their fullest bin of width `bin`
/// (bins from the smallest value), `None` when there are none.
pub fn largest_bin_share(values: &[f64], bin: f64) -> Option<f64> {
    let h = histogram(values, bin)?;
    let n: u64 = h.iter().sum();
    Some(*h.iter().max()? as f64 / n as f64)
}

/// `|value - reference| / |reference|`, `None` if the reference is zero or
/// either value is not finite.
pub fn relative_error(value: f64, reference: f64) -> Option<f64> {
    let r = (value - reference).abs() / reference.abs();
    (reference != 0.0 && r.is_finite()).then_some(r)
}

/// `value / reference`, `None` if the reference is zero or the ratio is not finite.
pub fn ratio(value: f64, reference: f64) -> Option<f64> {
    let r = value / reference;
    (reference != 0.0 && r.is_finite()).then_some(r)
}

/// `reference_wall / wall`, `None` unless both are finite and positive.
pub fn speedup(wall: f64, reference_wall: f64) -> Option<f64> {
    (wall > 0.0 && reference_wall > 0.0 && wall.is_finite() && reference_wall.is_finite())
        .then_some(reference_wall / wall)
}

pub(crate) fn sorted_finite(values: &[f64]) -> Option<Vec<f64>> {
    let mut s: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if s.is_empty() {
        return None;
    }
    s.sort_by(f64::total_cmp);
    Some(s)
}

/// The index of the point equal to `point` except for the `reference`
/// assignments.
pub(crate) fn reference_point(exp: &Experiment, point: &Point, reference: &[(String, toml::Value)]) -> Option<usize> {
    let mut index = 0;
    for (si, s) in exp.sweeps.iter().enumerate() {
        let vi = match reference.iter().find(|(k, _)| *k == s.key) {
            Some((_, v)) => s.values.iter().position(|sv| values_match(sv, v))?,
            None => point.value_indices[si],
        };
        index = index * s.values.len() + vi;
    }
    Some(index)
}

/// Inputs to [`compute`] for all points.
pub(crate) struct DerivedInputs<'a> {
    pub points: &'a [Point],
    /// Replication mean per point per tracked path (`None`: no values).
    pub means: &'a [Vec<Option<f64>>],
    pub paths: &'a [String],
    /// Per point, pooled frame columns in `Experiment::frame_columns` order.
    pub frames: &'a [Vec<Vec<f64>>],
    pub frame_columns: &'a [String],
}

/// A derived value taken on one point's frames (`values`: its column,
/// pooled over the point's runs); `None` for the kinds taken between
/// points, and where the value is undefined (no finite values).
pub(crate) fn of_frames(kind: &DerivedKind, values: &[f64]) -> Option<f64> {
    match kind {
        DerivedKind::IntervalWidth { level, .. } => interval_width(values, *level),
        DerivedKind::QuantileWidthFromMin { level, .. } => quantile_width_from_min(values, *level),
        DerivedKind::Modes { bin, prominence, .. } => modes(values, *bin, *prominence),
        DerivedKind::LargestBinShare { bin, .. } => largest_bin_share(values, *bin),
        DerivedKind::RelativeError { .. } | DerivedKind::Ratio { .. } | DerivedKind::Speedup { .. } => None,
    }
}

/// Every derived value of every point, in `exp.derived` order.
pub(crate) fn compute(exp: &Experiment, inp: &DerivedInputs<'_>) -> Vec<Vec<Option<f64>>> {
    let mean = |pi: usize, path: &str| -> Option<f64> {
        let k = inp.paths.iter().position(|p| p == path)?;
        inp.means.get(pi)?.get(k).copied().flatten()
    };
    let column = |pi: usize, col: &str| -> &[f64] {
        inp.frame_columns
            .iter()
            .position(|c| c == col)
            .and_then(|k| inp.frames.get(pi)?.get(k))
            .map(Vec::as_slice)
            .unwrap_or(&[])
    };
    inp.points
        .iter()
        .map(|p| {
            exp.derived
                .iter()
                .map(|d| match &d.kind {
                    DerivedKind::IntervalWidth { column: c, .. }
                    | DerivedKind::QuantileWidthFromMin { column: c, .. }
                    | DerivedKind::Modes { column: c, .. }
                    | DerivedKind::LargestBinShare { column: c, .. } => of_frames(&d.kind, column(p.index, c)),
                    DerivedKind::RelativeError { path, reference } => {
                        let r = reference_point(exp, p, reference)?;
                        relative_error(mean(p.index, path)?, mean(r, path)?)
                    }
                    DerivedKind::Ratio { path, reference } => {
                        let r = reference_point(exp, p, reference)?;
                        ratio(mean(p.index, path)?, mean(r, path)?)
                    }
                    DerivedKind::Speedup { path, reference } => {
                        let r = reference_point(exp, p, reference)?;
                        speedup(mean(p.index, path)?, mean(r, path)?)
                    }
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_width_on_known_data() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        // quantile(0.995) - quantile(0.005) on 0..=100 = 99.5 - 0.5
        assert!((interval_width(&v, 0.99).unwrap() - 99.0).abs() < 1e-9);
        assert!((interval_width(&v, 0.5).unwrap() - 50.0).abs() < 1e-9);
        assert_eq!(interval_width(&[], 0.9), None);
        assert_eq!(interval_width(&[3.0; 4], 0.9), Some(0.0));
    }

    #[test]
    fn quantile_width_from_min_on_known_data() {
        let v: Vec<f64> = (10..=110).map(f64::from).collect();
        // quantile(0.99) = 109, min = 10
        assert!((quantile_width_from_min(&v, 0.99).unwrap() - 99.0).abs() < 1e-9);
        assert_eq!(quantile_width_from_min(&v, 1.0), Some(100.0));
        assert_eq!(quantile_width_from_min(&[f64::NAN], 0.5), None);
    }

    #[test]
    fn modes_count_separated_humps_not_counting_noise() {
        // Two humps of 100 and 60 values in bins 0..=4 and 10..=14, with a
        // valley of zeros between: two modes.
        let hump = |at: f64, n: usize| (0..n).map(move |k| at + (k % 5) as f64 + 0.5);
        let two: Vec<f64> = hump(0.0, 100).chain(hump(10.0, 60)).collect();
        assert_eq!(modes(&two, 1.0, 0.1), Some(2.0));
        // One spike: every value in one bin.
        assert_eq!(modes(&[3.2; 50], 0.1, 0.1), Some(1.0));
        // A broad hump with a notch of one count on its top (20 19 20):
        // the notch is under 10% of the tallest bin, so one mode.
        let mut broad = Vec::new();
        for (b, n) in [5, 12, 20, 19, 20, 12, 5].iter().enumerate() {
            broad.extend(std::iter::repeat_n(b as f64 + 0.5, *n));
        }
        assert_eq!(modes(&broad, 1.0, 0.1), Some(1.0));
        // With a 1% threshold the notch splits it.
        assert_eq!(modes(&broad, 1.0, 0.01), Some(2.0));
        // Three spikes 5 bins apart, the middle one the smallest.
        let three: Vec<f64> = [0.5; 40].iter().chain(&[5.5; 10]).chain(&[10.5; 30]).copied().collect();
        assert_eq!(modes(&three, 1.0, 0.1), Some(3.0));
        assert_eq!(modes(&[], 1.0, 0.1), None);
        assert_eq!(modes(&[f64::NAN], 1.0, 0.1), None);
    }

    #[test]
    fn the_largest_bin_share_tells_a_spike_from_a_spread() {
        assert_eq!(largest_bin_share(&[2.0; 10], 0.5), Some(1.0));
        let spread: Vec<f64> = (0..100).map(f64::from).collect();
        assert_eq!(largest_bin_share(&spread, 10.0), Some(0.1));
        // The largest value falls in the last bin, not past it.
        assert_eq!(largest_bin_share(&[0.0, 1.0], 1.0), Some(0.5));
        assert_eq!(largest_bin_share(&[], 1.0), None);
    }

    #[test]
    fn relative_error_and_speedup() {
        assert_eq!(relative_error(11.0, 10.0), Some(0.1));
        assert_eq!(relative_error(9.0, -10.0), Some(1.9));
        assert_eq!(relative_error(1.0, 0.0), None);
        assert_eq!(speedup(0.5, 2.0), Some(4.0));
        assert_eq!(ratio(142.0, 100.0), Some(1.42));
        assert_eq!(ratio(1.0, 0.0), None);
        assert_eq!(speedup(0.0, 2.0), None);
    }
}
