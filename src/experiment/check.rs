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
    /// Expected value.
    pub expect: f64,
    /// Allowed absolute deviation (a relative tolerance already multiplied by `|expect|`).
    pub allowed: f64,
    /// The tolerance as written, e.g. `±0.05` or `±1%`.
    pub tolerance_text: String,
    /// Whether `|measured - expect| <= allowed`.
    pub passed: bool,
}

/// Evaluate one check.
pub fn evaluate(
    path: &str,
    point: &str,
    measured: Option<f64>,
    expect: f64,
    tolerance: Tolerance,
) -> CheckOutcome {
    let (allowed, tolerance_text) = match tolerance {
        Tolerance::Absolute(t) => (t, format!("±{}", format_range_number(t))),
        Tolerance::Relative(t) => (
            t * expect.abs(),
            format!("±{}%", format_range_number(t * 100.0)),
        ),
    };
    let passed = measured.is_some_and(|m| m.is_finite() && (m - expect).abs() <= allowed);
    CheckOutcome {
        path: path.to_string(),
        point: point.to_string(),
        measured,
        expect,
        allowed,
        tolerance_text,
        passed,
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
}
