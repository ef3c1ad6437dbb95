//! Derived values computed per point after all runs: frame-time spreads
//! (`interval_width`, `quantile_width_from_min`) from pooled per-frame data,
//! and comparisons between points (`relative_error`, `ratio`, `speedup`).
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

fn sorted_finite(values: &[f64]) -> Option<Vec<f64>> {
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
                    DerivedKind::IntervalWidth { column: c, level } => interval_width(column(p.index, c), *level),
                    DerivedKind::QuantileWidthFromMin { column: c, level } => {
                        quantile_width_from_min(column(p.index, c), *level)
                    }
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
