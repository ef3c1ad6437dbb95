//! Numbers in human-readable reports.

/// `x` with `decimals` decimals, never as a negative zero ("-0.000" for
/// -0.0 or a tiny negative rounding error reads like a negative time);
/// "n/a" for a missing number (a `null` statistic of an empty sample reads
/// as NaN here).
pub fn fixed(x: f64, decimals: usize) -> String {
    if x.is_nan() {
        return "n/a".to_string();
    }
    let t = format!("{x:.decimals$}");
    match t.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => t,
    }
}

#[cfg(test)]
mod tests {
    use super::fixed;

    #[test]
    fn no_negative_zero_and_nan_is_not_available() {
        assert_eq!(fixed(-0.0, 3), "0.000");
        assert_eq!(fixed(-0.0001, 3), "0.000");
        assert_eq!(fixed(-0.5, 1), "-0.5");
        assert_eq!(fixed(f64::NAN, 2), "n/a");
        assert_eq!(fixed(12.345, 1), "12.3");
    }
}
