//! Reference checks: compare a point's value with an expected value.

use serde::Serialize;

use super::spec::Tolerance;
use super::sweep::format_range_number;

/// The outcome of one check at one point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckOutcome {
    /// Metric path or derived name checked.
    pub path: String,
    /// The point's label.
    pub point: String,
    /// The point's replication mean (or derived value); `None` if it has none.
    pub measured: Option<f64>,
    /// Expected value (`None` for a check against bounds).
    pub expect: Option<f64>,
    /// Allowed absolute deviation (a relative tolerance already multiplied by
    /// `|expect|`; for bounds, by the larger bound magnitude).
    pub allowed: f64,
    /// The tolerance as written, e.g. `±0.05` or `±1%`.
    pub tolerance_text: String,
    /// What was expected, as shown in the report: the value, or the bounds
    /// with their paths and values at this point.
    pub expected_text: String,
    /// Whether the measured value is within the tolerance of the expected
    /// value, or within the bounds widened by the tolerance.
    pub passed: bool,
    /// Signed error: `measured - expect`; for bounds, the distance beyond
    /// the violated bound (negative below the lower one, positive above the
    /// upper one) and 0 inside them. `None` without a measurement.
    pub error: Option<f64>,
    /// The value `error` is relative to (`expect`, or the violated bound).
    pub error_reference: Option<f64>,
    /// The claim this check gives a verdict on (`claim = "..."` in the
    /// experiment file): reported as holds / does not hold, never a failure.
    pub claim: Option<String>,
}

impl CheckOutcome {
    /// `error / |error_reference|` (`None` when either is missing or the
    /// reference is zero).
    pub fn relative_error(&self) -> Option<f64> {
        let (e, r) = (self.error?, self.error_reference?);
        (r != 0.0 && r.is_finite()).then(|| e / r.abs())
    }

    /// The measured value over the expected one as report text, `0.946x`
    /// (the paper's value beside the simulated one, as a ratio); empty for
    /// a check against bounds, without a measurement, or against 0.
    pub fn ratio_text(&self) -> String {
        match (self.measured, self.expect) {
            (Some(m), Some(e)) if e != 0.0 && (m / e).is_finite() => format!("{:.3}x", m / e),
            _ => String::new(),
        }
    }

    /// The error as report text: `+0.5 (+0.68%)`, `0 (inside the bounds)`, or `n/a`.
    pub fn error_text(&self) -> String {
        match (self.error, self.relative_error()) {
            (None, _) => "n/a".into(),
            (Some(e), _) if e == 0.0 && self.expect.is_none() => "0 (inside the bounds)".into(),
            (Some(e), Some(r)) => format!(
                "{}{} ({}{}%)",
                if e >= 0.0 { "+" } else { "" },
                super::report::fmt_precise(e),
                if r >= 0.0 { "+" } else { "" },
                super::report::fmt_num(r * 100.0)
            ),
            (Some(e), None) => format!("{}{}", if e >= 0.0 { "+" } else { "" }, super::report::fmt_precise(e)),
        }
    }
}

/// A bound of a check against other values of the same point, or a number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound<'a> {
    /// Its path or derived name; empty for a fixed number.
    pub path: &'a str,
    /// Its value at the point (`None`: undefined, the check fails).
    pub value: Option<f64>,
}

/// Evaluate a check against bounds: passes when `measured >= low - tol` and
/// `measured <= high + tol`, the tolerance taken relative to each bound for
/// a relative tolerance. A missing or non-finite value fails.
pub fn evaluate_between(
    path: &str,
    point: &str,
    measured: Option<f64>,
    low: Option<Bound<'_>>,
    high: Option<Bound<'_>>,
    tolerance: Tolerance,
) -> CheckOutcome {
    let allowed_for = |b: f64| match tolerance {
        Tolerance::Absolute(t) => t,
        Tolerance::Relative(t) => t * b.abs(),
    };
    let tolerance_text = match tolerance {
        Tolerance::Absolute(t) => format!("±{}", format_range_number(t)),
        Tolerance::Relative(t) => format!("±{}% of the bound", format_range_number(t * 100.0)),
    };
    let finite = |v: Option<f64>| v.filter(|x| x.is_finite());
    let m = finite(measured);
    let ok_low = match low {
        None => true,
        Some(b) => matches!((m, finite(b.value)), (Some(m), Some(l)) if m >= l - allowed_for(l)),
    };
    let ok_high = match high {
        None => true,
        Some(b) => matches!((m, finite(b.value)), (Some(m), Some(h)) if m <= h + allowed_for(h)),
    };
    let show = |b: &Bound<'_>| {
        let v = b.value.map(super::report::fmt_precise).unwrap_or_else(|| "n/a".into());
        if b.path.is_empty() {
            v
        } else {
            format!("`{}` = {v}", b.path)
        }
    };
    let (error, error_reference) = match m {
        None => (None, None),
        Some(m) => match (low.and_then(|b| finite(b.value)), high.and_then(|b| finite(b.value))) {
            (Some(l), _) if m < l => (Some(m - l), Some(l)),
            (_, Some(h)) if m > h => (Some(m - h), Some(h)),
            (l, h) => (Some(0.0), l.or(h)),
        },
    };
    let expected_text = match (&low, &high) {
        (Some(l), Some(h)) => format!("between {} and {}", show(l), show(h)),
        (Some(l), None) => format!("at least {}", show(l)),
        (None, Some(h)) => format!("at most {}", show(h)),
        (None, None) => "anything".into(),
    };
    let allowed = [low, high]
        .iter()
        .flatten()
        .filter_map(|b| finite(b.value))
        .map(allowed_for)
        .fold(0.0, f64::max);
    CheckOutcome {
        path: path.to_string(),
        point: point.to_string(),
        measured,
        expect: None,
        allowed,
        tolerance_text,
        expected_text,
        passed: m.is_some() && ok_low && ok_high,
        error,
        error_reference,
        claim: None,
    }
}

/// Evaluate one check.
pub fn evaluate(path: &str, point: &str, measured: Option<f64>, expect: f64, tolerance: Tolerance) -> CheckOutcome {
    let (allowed, tolerance_text) = match tolerance {
        Tolerance::Absolute(t) => (t, format!("±{}", format_range_number(t))),
        Tolerance::Relative(t) => (t * expect.abs(), format!("±{}%", format_range_number(t * 100.0))),
    };
    let passed = measured.is_some_and(|m| m.is_finite() && (m - expect).abs() <= allowed);
    CheckOutcome {
        path: path.to_string(),
        point: point.to_string(),
        measured,
        expect: Some(expect),
        allowed,
        tolerance_text,
        expected_text: super::report::fmt_precise(expect),
        passed,
        error: measured.filter(|m| m.is_finite()).map(|m| m - expect),
        error_reference: Some(expect),
        claim: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absolute_and_relative() {
        assert!(evaluate("m", "p", Some(33.3), 33.333, Tolerance::Absolute(0.05)).passed);
        assert!(!evaluate("m", "p", Some(33.4), 33.333, Tolerance::Absolute(0.05)).passed);
        assert!(evaluate("m", "p", Some(101.0), 100.0, Tolerance::Relative(0.01)).passed);
        let o = evaluate("m", "p", Some(102.0), 100.0, Tolerance::Relative(0.01));
        assert!(!o.passed);
        assert_eq!(o.tolerance_text, "±1%");
        assert!(!evaluate("m", "p", None, 1.0, Tolerance::Absolute(10.0)).passed);
        assert!(!evaluate("m", "p", Some(f64::NAN), 1.0, Tolerance::Absolute(10.0)).passed);
    }

    #[test]
    fn the_ratio_is_measured_over_expected_where_there_is_one() {
        let r = |m: Option<f64>, e: f64| evaluate("m", "p", m, e, Tolerance::Relative(0.1)).ratio_text();
        assert_eq!(r(Some(9.573), 9.143), "1.047x");
        assert_eq!(r(Some(1.0), 0.0), "");
        assert_eq!(r(None, 1.0), "");
        assert_eq!(r(Some(f64::NAN), 1.0), "");
        let bound = Some(Bound {
            path: "",
            value: Some(1.0),
        });
        let b = evaluate_between("t", "p", Some(2.0), bound, None, Tolerance::Absolute(0.0));
        assert_eq!(b.ratio_text(), "", "a bound is not a paper value");
    }

    #[test]
    fn between_bounds() {
        let b = |path, value| Some(Bound { path, value });
        let abs = Tolerance::Absolute(0.01);
        let check = |m: f64, lo: Option<Bound<'static>>, hi: Option<Bound<'static>>| {
            evaluate_between("t", "p", Some(m), lo, hi, abs).passed
        };
        assert!(check(5.0, b("max", Some(4.0)), b("sum", Some(6.0))));
        assert!(check(4.0, b("max", Some(4.0)), b("sum", Some(6.0))));
        assert!(check(3.995, b("max", Some(4.0)), b("sum", Some(6.0))));
        assert!(!check(3.98, b("max", Some(4.0)), b("sum", Some(6.0))));
        assert!(!check(6.02, b("max", Some(4.0)), b("sum", Some(6.0))));
        assert!(check(100.0, b("max", Some(4.0)), None));
        assert!(check(-100.0, None, b("sum", Some(6.0))));
        // A missing bound or measurement fails.
        assert!(!check(5.0, b("max", None), b("sum", Some(6.0))));
        assert!(!evaluate_between("t", "p", None, None, b("sum", Some(6.0)), abs).passed);
        // Relative tolerance is relative to each bound.
        let rel = Tolerance::Relative(0.01);
        let o = evaluate_between("t", "p", Some(101.0), None, b("sum", Some(100.0)), rel);
        assert!(o.passed);
        assert_eq!(o.allowed, 1.0);
        assert_eq!(o.expected_text, "at most `sum` = 100");
        assert!(!evaluate_between("t", "p", Some(98.0), b("max", Some(100.0)), None, rel).passed);
        let o = evaluate_between("t", "p", Some(5.0), b("a", Some(4.0)), b("b", Some(6.5)), abs);
        assert_eq!(o.expected_text, "between `a` = 4 and `b` = 6.5");
        assert_eq!(o.expect, None);
        assert_eq!(o.error, Some(0.0));
        assert_eq!(o.error_text(), "0 (inside the bounds)");
        // Below the lower bound: negative distance to it; a fixed-number bound shows as a number.
        let o = evaluate_between("t", "p", Some(3.0), b("", Some(4.0)), None, abs);
        assert_eq!(o.expected_text, "at least 4");
        assert_eq!(o.error, Some(-1.0));
        assert_eq!(o.relative_error(), Some(-0.25));
        assert_eq!(o.error_text(), "-1 (-25.00%)");
        let o = evaluate_between("t", "p", Some(8.0), b("a", Some(4.0)), b("", Some(6.0)), abs);
        assert_eq!(o.error, Some(2.0));
        assert_eq!(o.error_reference, Some(6.0));
    }

    #[test]
    fn error_against_the_expected_value() {
        let o = evaluate("m", "p", Some(73.5), 73.0, Tolerance::Absolute(1.0));
        assert_eq!(o.error, Some(0.5));
        assert!((o.relative_error().unwrap() - 0.5 / 73.0).abs() < 1e-12);
        assert_eq!(o.error_text(), "+0.5 (+0.6849%)");
        assert_eq!(
            evaluate("m", "p", None, 1.0, Tolerance::Absolute(1.0)).error_text(),
            "n/a"
        );
    }
}
