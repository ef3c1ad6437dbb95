//! Axis helpers: value filtering for linear and log axes, range padding and
//! widening of degenerate ranges, tick label formatting.

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

/// A compact tick label for an axis coordinate (`log` undoes `log10`).
pub(crate) fn tick_label(v: f64, log: bool) -> String {
    if log {
        // Two significant digits: 1, 1.6, 2.5, 4, 6.3, 10, ...
        let x = 10f64.powf(v);
        let magnitude = x.abs().log10().floor();
        let scale = 10f64.powf(magnitude - 1.0);
        format_number((x / scale).round() * scale)
    } else {
        format_number(v)
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
        assert_eq!(tick_label(2.0, true), "100");
        assert_eq!(tick_label(0.2, true), "1.6");
        assert_eq!(tick_label(-0.8, true), "0.16");
    }
}
