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

/// A summary number, NaN when it is missing or `null`.
fn number(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// One latency line of a report: `  {head} min .. mean .. p99 .. max .. ms
/// {bound} best .. worst ..`, from a distribution (`min`, `mean`, `p99`,
/// `max`) and its bounds (`best`, `worst`) in a summary; the distribution's
/// numbers take `width` columns.
pub fn latency_row(
    w: &mut dyn std::io::Write,
    head: &str,
    width: usize,
    dist: &serde_json::Value,
    bounds: &serde_json::Value,
    bound: &str,
) -> std::io::Result<()> {
    let d = |k: &str| fixed(number(&dist[k]), 1);
    writeln!(
        w,
        "  {head} min {:>width$} mean {:>width$} p99 {:>width$} max {:>width$} ms   {bound} best {:>6} worst {:>6}",
        d("min"),
        d("mean"),
        d("p99"),
        d("max"),
        fixed(number(&bounds["best"]), 1),
        fixed(number(&bounds["worst"]), 1)
    )
}

/// A latency report's last line: kernel events, wall and simulated time.
pub fn events_line(w: &mut dyn std::io::Write, s: &serde_json::Value) -> std::io::Result<()> {
    writeln!(
        w,
        "  {} events in {:.3} s wall, {:.3} s simulated",
        s["events"]["total"],
        number(&s["wall_seconds"]),
        number(&s["simulated_seconds"])
    )
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
