//! Axis helpers: value filtering for linear and log axes, range padding and
//! widening of degenerate ranges, tick positions and their labels.

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;

/// Map a data value onto an axis coordinate: `None` for NaN/inf, and on a
/// log axis for values that are not positive (the coordinate is `log10`).
pub(crate) fn to_axis(v: f64, log: bool) -> Option<f64> {
    if !v.is_finite() {
        return None;
    }
    if log {
        if v > 0.0 { Some(v.log10()) } else { None }
    } else {
        Some(v)
    }
}

/// A padded `(low, high)` range covering `values` (axis coordinates, all
/// finite). Empty input gives `(0, 1)`; a degenerate range is widened.
pub(crate) fn padded_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in values {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    widen(lo, hi, 0.05)
}

/// Pad `[lo, hi]` by `pad` of its width on both sides, widening a zero-width
/// range to a sensible non-empty one.
pub(crate) fn widen(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let width = hi - lo;
    if width > 0.0 && width.is_finite() {
        (lo - width * pad, hi + width * pad)
    } else {
        let half = if lo == 0.0 { 1.0 } else { (lo.abs() * 0.1).max(1e-9) };
        (lo - half, lo + half)
    }
}

/// At most this many labelled ticks per axis.
const MAX_TICKS: usize = 10;

/// The ticks of one axis, in axis coordinates (`log10` of the value on a log
/// axis): labelled major ticks with distinct labels, and unlabelled minor
/// grid positions.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Ticks {
    /// Major tick positions, ascending, all inside the axis range.
    pub positions: Vec<f64>,
    /// One label per major tick, pairwise distinct.
    pub labels: Vec<String>,
    /// Minor grid positions (unlabelled), inside the axis range.
    pub minor: Vec<f64>,
}

impl Ticks {
    /// The label of the major tick nearest to `v` (plotters hands the
    /// positions back to the label formatter).
    pub(crate) fn label_at(&self, v: f64) -> String {
        self.positions
            .iter()
            .zip(&self.labels)
            .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
            .map(|(_, l)| l.clone())
            .unwrap_or_default()
    }
}

/// Ticks for the axis range `[lo, hi]` (axis coordinates). On a linear axis:
/// multiples of a 1-2-5 step, at most [`MAX_TICKS`], labelled with just
/// enough decimals to tell them apart. On a log axis spanning decades:
/// 1-2-5 per decade (or every n-th decade for wide ranges); over less than
/// a decade 1..9 per decade, and for narrower ranges linear-style ticks in
/// value space. `integer` keeps major ticks on whole numbers (for data
/// whose values are all integers).
pub(crate) fn ticks(lo: f64, hi: f64, log: bool, integer: bool) -> Ticks {
    if !(lo.is_finite() && hi.is_finite()) {
        return Ticks::default();
    }
    if hi <= lo {
        let v = if log { 10f64.powf(lo) } else { lo };
        return Ticks {
            positions: vec![lo],
            labels: vec![format_number(v)],
            minor: Vec::new(),
        };
    }
    let make = |integer| {
        if log {
            log_ticks(lo, hi, integer)
        } else {
            linear_ticks(lo, hi, integer)
        }
    };
    match make(integer) {
        // A range holding fewer than two whole numbers gets fractional ticks after all.
        t if integer && t.positions.len() < 2 => make(false),
        t => t,
    }
}

/// A linear `f64` axis coordinate whose grid lines and labels sit at given
/// [`Ticks`] (plotters' own choice of key points is replaced).
pub(crate) struct TickedAxis {
    inner: RangedCoordf64,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl Ranged for TickedAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }
}

/// An axis coordinate over `[lo, hi]` whose grid lines and labels sit at `t`.
pub(crate) fn coord(lo: f64, hi: f64, t: &Ticks) -> TickedAxis {
    TickedAxis {
        inner: (lo..hi).into(),
        major: t.positions.clone(),
        minor: t.minor.clone(),
    }
}

/// True when every finite value is a whole number and there is at least one.
pub(crate) fn all_integers(values: impl IntoIterator<Item = f64>) -> bool {
    let mut any = false;
    for v in values.into_iter().filter(|v| v.is_finite()) {
        if v.fract() != 0.0 {
            return false;
        }
        any = true;
    }
    any
}

/// A 1-2-5 step `mantissa * 10^exp`.
#[derive(Debug, Clone, Copy)]
struct Step {
    mantissa: i64,
    exp: i32,
}

impl Step {
    fn value(self) -> f64 {
        scaled(self.mantissa, self.exp)
    }

    /// The next larger 1-2-5 step.
    fn next(self) -> Step {
        match self.mantissa {
            1 => Step { mantissa: 2, ..self },
            2 => Step { mantissa: 5, ..self },
            _ => Step {
                mantissa: 1,
                exp: self.exp + 1,
            },
        }
    }
}

/// `m * 10^exp`, computed by one multiplication or division so that e.g.
/// `3 * 10^-1` is exactly the double nearest to 0.3.
fn scaled(m: i64, exp: i32) -> f64 {
    if exp >= 0 {
        m as f64 * 10f64.powi(exp)
    } else {
        m as f64 / 10f64.powi(-exp)
    }
}

/// The integer multiples `k` of `step` with `k * step` in `[lo, hi]`
/// (a tiny tolerance admits ends hit up to rounding).
fn multiples(lo: f64, hi: f64, step: f64) -> std::ops::RangeInclusive<i64> {
    let eps = (hi - lo) * 1e-9;
    let first = ((lo - eps) / step).ceil() as i64;
    let last = ((hi + eps) / step).floor() as i64;
    first..=last
}

/// Linear ticks over `[lo, hi]` (`lo < hi`, both finite).
fn linear_ticks(lo: f64, hi: f64, integer: bool) -> Ticks {
    let span = hi - lo;
    // Start a little below the finest useful step and take the first 1-2-5
    // step that gives at most MAX_TICKS ticks.
    let mut step = Step {
        mantissa: 1,
        exp: (span / MAX_TICKS as f64).log10().floor() as i32 - 1,
    };
    if integer && step.exp < 0 {
        step = Step { mantissa: 1, exp: 0 };
    }
    let mut ks = multiples(lo, hi, step.value());
    while ks.end() - ks.start() + 1 > MAX_TICKS as i64 {
        step = step.next();
        ks = multiples(lo, hi, step.value());
    }
    let positions: Vec<f64> = ks.clone().map(|k| scaled(k * step.mantissa, step.exp)).collect();
    let labels = linear_labels(&positions, step);
    // Minor grid: a fifth of the step (a quarter for a step of 2), on whole
    // numbers only for integer axes.
    let div = if step.mantissa == 2 { 4 } else { 5 };
    let minor_step = Step {
        mantissa: step.mantissa * 10 / div,
        exp: step.exp - 1,
    };
    let minor = if integer && minor_step.value() < 1.0 {
        Vec::new()
    } else {
        multiples(lo, hi, minor_step.value())
            .map(|k| scaled(k * minor_step.mantissa, minor_step.exp))
            .collect()
    };
    Ticks {
        positions,
        labels,
        minor,
    }
}

/// Labels for ticks spaced by `step`: fixed-point with the step's decimals,
/// or scientific for very large or very small magnitudes.
fn linear_labels(values: &[f64], step: Step) -> Vec<String> {
    let max = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if max >= 1e6 || (max > 0.0 && max < 1e-3) {
        let digits = (max.log10().floor() as i32 - step.exp).max(0) as usize;
        values.iter().map(|&v| sci(v, digits)).collect()
    } else {
        let decimals = (-step.exp).max(0) as usize;
        values.iter().map(|&v| fixed(v, decimals)).collect()
    }
}

/// Fixed-point with `decimals` decimals, without a negative zero.
fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// Scientific notation with `digits` digits after the point, e.g. `1.25e-5`.
fn sci(v: f64, digits: usize) -> String {
    if v == 0.0 { "0".into() } else { format!("{v:.digits$e}") }
}

/// The label of `m * 10^exp` for a one-digit mantissa: plain decimals in a
/// readable range, else `2e-5` style.
fn mantissa_label(m: i64, exp: i32) -> String {
    if (-4..6).contains(&exp) {
        fixed(scaled(m, exp), (-exp).max(0) as usize)
    } else {
        format!("{m}e{exp}")
    }
}

/// The ticks `m * 10^k` in `[lo, hi]` (log10 coordinates) for `m` in
/// `mantissas` and every `stride`-th decade `k`: `(log10 value, m, k)`.
fn decade_ticks(lo: f64, hi: f64, mantissas: &[i64], stride: i32) -> Vec<(f64, i64, i32)> {
    let eps = (hi - lo) * 1e-9;
    let mut out = Vec::new();
    let (k0, k1) = (lo.floor() as i32, hi.ceil() as i32);
    for k in k0..=k1 {
        if k.rem_euclid(stride) != 0 {
            continue;
        }
        for &m in mantissas {
            let p = (m as f64).log10() + k as f64;
            if p >= lo - eps && p <= hi + eps {
                out.push((p, m, k));
            }
        }
    }
    out
}

/// Log ticks over `[lo, hi]` (log10 coordinates, `lo < hi`).
fn log_ticks(lo: f64, hi: f64, integer: bool) -> Ticks {
    const ALL: [i64; 9] = [1, 2, 3, 4, 5, 6, 7, 8, 9];
    // Whole numbers only, on integer axes (a value m * 10^k with k < 0 is not).
    let keep = |t: &(f64, i64, i32)| !integer || t.2 >= 0;
    let one_two_five: Vec<_> = decade_ticks(lo, hi, &[1, 2, 5], 1).into_iter().filter(keep).collect();
    let one_to_nine: Vec<_> = decade_ticks(lo, hi, &ALL, 1).into_iter().filter(keep).collect();
    let chosen = if one_two_five.len() > MAX_TICKS {
        // Wide range: decades only, every `stride`-th one.
        let mut stride = 1;
        loop {
            let t: Vec<_> = decade_ticks(lo, hi, &[1], stride).into_iter().filter(keep).collect();
            if t.len() <= MAX_TICKS {
                break Some((t, stride));
            }
            stride = match stride {
                1 => 2,
                2 => 5,
                s => s * 2,
            };
        }
    } else if one_two_five.len() >= 4 {
        Some((one_two_five, 0))
    } else if (3..=MAX_TICKS).contains(&one_to_nine.len()) {
        // About a decade: 1..9 labels the range more evenly than 1-2-5.
        Some((one_to_nine, -1))
    } else if one_two_five.len() == 3 {
        Some((one_two_five, 0))
    } else {
        None
    };
    let Some((major, stride)) = chosen else {
        // Less than about a decade: linear-style ticks in value space.
        // (10^lo > 0, so every tick is positive.)
        let lin = linear_ticks(10f64.powf(lo), 10f64.powf(hi), integer);
        let to_log = |v: Vec<f64>| v.into_iter().map(|x| x.max(f64::MIN_POSITIVE).log10()).collect();
        return Ticks {
            positions: to_log(lin.positions),
            labels: lin.labels,
            minor: to_log(lin.minor),
        };
    };
    let minor = match stride {
        // 1..9 majors: minor lines halfway between them.
        // (15..95 one decade up, shifted back down: 1.5, 2.5, ..., 9.5.)
        -1 => decade_ticks(lo + 1.0, hi + 1.0, &[15, 25, 35, 45, 55, 65, 75, 85, 95], 1)
            .into_iter()
            .map(|t| t.0 - 1.0)
            .collect(),
        // 1-2-5 majors: every 1..9.
        0 => decade_ticks(lo, hi, &ALL, 1).into_iter().map(|t| t.0).collect(),
        // Every decade, or 1..9 when that is not too dense.
        _ if hi - lo <= 8.0 => decade_ticks(lo, hi, &ALL, 1).into_iter().map(|t| t.0).collect(),
        _ => decade_ticks(lo, hi, &[1], 1).into_iter().map(|t| t.0).collect(),
    };
    Ticks {
        positions: major.iter().map(|t| t.0).collect(),
        labels: major.iter().map(|t| mantissa_label(t.1, t.2)).collect(),
        minor,
    }
}

/// A compact human-readable number: plain with up to 4 decimals, or
/// scientific for very large or small magnitudes.
pub(crate) fn format_number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        return format!("{v:.2e}");
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

/// The note drawn on a plot when values were dropped, if any.
pub(crate) fn omitted_note(dropped: usize, log_axis: bool) -> Option<String> {
    match dropped {
        0 => None,
        n if log_axis => Some(format!(
            "note: {n} non-finite or non-positive (log axis) value(s) omitted"
        )),
        n => Some(format!("note: {n} non-finite value(s) omitted")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_never_degenerate() {
        assert_eq!(padded_range([]), (0.0, 1.0));
        let (a, b) = padded_range([5.0]);
        assert!(a < 5.0 && b > 5.0);
        let (a, b) = padded_range([0.0, 0.0]);
        assert!(a < 0.0 && b > 0.0);
        let (a, b) = padded_range([1.0, 3.0, f64::NAN]);
        assert!(a < 1.0 && b > 3.0 && b.is_finite());
    }

    #[test]
    fn log_axis_filters_non_positive() {
        assert_eq!(to_axis(100.0, true), Some(2.0));
        assert_eq!(to_axis(0.0, true), None);
        assert_eq!(to_axis(-1.0, false), Some(-1.0));
        assert_eq!(to_axis(f64::INFINITY, false), None);
    }

    #[test]
    fn number_formatting() {
        assert_eq!(format_number(2.5), "2.5");
        assert_eq!(format_number(10.0), "10");
        assert_eq!(format_number(1e-5), "1.00e-5");
    }

    /// Ticks for data spanning `[a, b]` (values, not axis coordinates),
    /// padded like the plots pad them.
    fn for_data(a: f64, b: f64, log: bool, integer: bool) -> Ticks {
        let (lo, hi) = padded_range([to_axis(a, log).unwrap(), to_axis(b, log).unwrap()]);
        ticks(lo, hi, log, integer)
    }

    /// The invariants every tick set must satisfy; returns the labels.
    fn check(t: &Ticks, lo: f64, hi: f64, log: bool) -> Vec<String> {
        assert_eq!(t.positions.len(), t.labels.len());
        assert!(!t.positions.is_empty() && t.positions.len() <= MAX_TICKS, "{t:?}");
        let eps = (hi - lo) * 1e-6;
        for w in t.positions.windows(2) {
            assert!(w[0] < w[1], "ascending: {t:?}");
        }
        for &p in t.positions.iter().chain(&t.minor) {
            assert!(p >= lo - eps && p <= hi + eps, "{p} outside [{lo}, {hi}]: {t:?}");
        }
        let distinct: std::collections::BTreeSet<&String> = t.labels.iter().collect();
        assert_eq!(distinct.len(), t.labels.len(), "labels not distinct: {:?}", t.labels);
        // Each label reads back as its tick's value.
        for (p, l) in t.positions.iter().zip(&t.labels) {
            let v = if log { 10f64.powf(*p) } else { *p };
            let parsed: f64 = l.parse().unwrap_or_else(|_| panic!("label {l:?} is not a number"));
            assert!(
                (parsed - v).abs() <= 1e-9 * v.abs().max(1e-300) + 1e-12 * (hi - lo).abs(),
                "label {l} for value {v}"
            );
        }
        t.labels.clone()
    }

    #[test]
    fn narrow_log_range_gets_distinct_readable_labels() {
        // The old labels here were 0.13, 0.14, 0.14, ...
        let t = for_data(0.1336, 0.1444, true, false);
        let (lo, hi) = padded_range([0.1336f64.log10(), 0.1444f64.log10()]);
        let labels = check(&t, lo, hi, true);
        assert!(labels.len() >= 3, "{labels:?}");
        assert_eq!(labels[0], "0.134");
        assert!(labels.iter().all(|l| l.len() == 5), "{labels:?}");
        // A little wider, still within a decade: 1..9 per decade.
        let t = for_data(0.25, 0.95, true, false);
        assert_eq!(t.labels, ["0.3", "0.4", "0.5", "0.6", "0.7", "0.8", "0.9", "1"]);
    }

    #[test]
    fn log_range_over_decades_gets_one_two_five() {
        // Just under a decade: 1..9 rather than three 1-2-5 ticks.
        let t = for_data(260.0, 1990.0, true, false);
        assert_eq!(
            t.labels,
            ["300", "400", "500", "600", "700", "800", "900", "1000", "2000"]
        );
        let t = for_data(0.01, 0.2, true, false);
        assert_eq!(t.labels, ["0.01", "0.02", "0.05", "0.1", "0.2"]);
        let t = for_data(0.1, 130.0, true, false);
        assert_eq!(t.labels, ["0.1", "0.2", "0.5", "1", "2", "5", "10", "20", "50", "100"]);
        // Wider: decades only, then every other / fifth decade.
        let t = for_data(1e-4, 1e3, true, false);
        assert_eq!(t.labels, ["0.0001", "0.001", "0.01", "0.1", "1", "10", "100", "1000"]);
        let t = for_data(1e-12, 1e12, true, false);
        assert_eq!(t.labels, ["1e-10", "1e-5", "1", "100000", "1e10"]);
        let (lo, hi) = padded_range([-12.0, 12.0]);
        check(&t, lo, hi, true);
    }

    #[test]
    fn integer_data_gets_integer_ticks() {
        let t = for_data(1.0, 5.0, false, true);
        assert_eq!(t.labels, ["1", "2", "3", "4", "5"]);
        assert!(t.minor.iter().all(|m| m.fract() == 0.0), "{:?}", t.minor);
        let t = for_data(0.0, 3.0, false, true);
        assert_eq!(t.labels, ["0", "1", "2", "3"]);
        // Without the integer flag the same range gets half steps.
        let t = for_data(1.0, 5.0, false, false);
        assert!(t.labels.contains(&"1.5".to_string()), "{:?}", t.labels);
        // Many integers: a coarser whole step.
        let t = for_data(0.0, 64.0, false, true);
        assert_eq!(t.labels, ["0", "10", "20", "30", "40", "50", "60"]);
        // Integer data on a log axis: no fractional ticks.
        let t = for_data(1.0, 4.0, true, true);
        assert_eq!(t.labels, ["1", "2", "3", "4"]);
        let t = for_data(1.0, 64.0, true, true);
        assert_eq!(t.labels, ["1", "2", "5", "10", "20", "50"]);
    }

    #[test]
    fn linear_labels_use_the_steps_decimals() {
        let t = for_data(0.0, 0.145, false, false);
        assert_eq!(t.labels[..3], ["0.00", "0.02", "0.04"]);
        let t = for_data(12.0, 12.5, false, false);
        assert_eq!(t.labels, ["12.0", "12.1", "12.2", "12.3", "12.4", "12.5"]);
        let t = for_data(-3.0, 3.0, false, false);
        assert!(t.labels.contains(&"0".to_string()) && !t.labels.iter().any(|l| l == "-0"));
        let t = for_data(2.0e6, 3.0e6, false, false);
        assert_eq!(t.labels[0], "2.0e6");
        let t = for_data(1e-5, 5e-5, false, false);
        assert_eq!(t.labels[..2], ["1.0e-5", "1.5e-5"]);
    }

    #[test]
    fn ticks_are_valid_over_many_ranges() {
        let centres: [f64; 10] = [-1234.5, -1.0, 0.0, 1e-7, 0.0137, 0.5, 1.0, 12.0, 999.0, 5e7];
        let widths = [1e-9, 1e-6, 1e-3, 0.01, 0.3, 1.0, 7.0, 100.0, 1e5];
        for &c in &centres {
            for &w in &widths {
                for log in [false, true] {
                    let (a, b) = if log {
                        (c.abs().max(1e-6), c.abs().max(1e-6) * (1.0 + w))
                    } else {
                        (c, c + w)
                    };
                    for integer in [false, true] {
                        let (lo, hi) = padded_range([to_axis(a, log).unwrap(), to_axis(b, log).unwrap()]);
                        let t = ticks(lo, hi, log, integer);
                        let labels = check(&t, lo, hi, log);
                        assert!(labels.len() >= 2, "{a}..{b} log={log}: {labels:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn degenerate_and_non_finite_ranges() {
        assert_eq!(ticks(f64::NAN, 1.0, false, false), Ticks::default());
        assert_eq!(ticks(2.0, 2.0, false, false).labels, ["2"]);
        let t = ticks(0.0, 1.0, false, false);
        assert_eq!(t.label_at(0.6000001), "0.6");
        // Integer data over less than one unit: fractional ticks after all.
        assert!(for_data(3.0, 3.0, false, true).labels.len() >= 2);
        assert!(all_integers([1.0, 2.0, f64::NAN]) && !all_integers([1.0, 2.5]) && !all_integers([]));
    }
}
