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

/// A summary statistic, NaN when it is missing (`None`: a statistic of an
/// empty sample), which [`fixed`] writes as "n/a".
pub fn number(v: Option<f64>) -> f64 {
    v.unwrap_or(f64::NAN)
}

/// One latency line of a report: `  {head} min .. mean .. p99 .. max .. ms
/// {bound} best .. worst ..`, from a distribution's `[min, mean, p99, max]`
/// and its bounds `(best, worst)`; the distribution's numbers take `width`
/// columns.
pub fn latency_row(
    w: &mut dyn std::io::Write,
    head: &str,
    width: usize,
    dist: [Option<f64>; 4],
    (best, worst): (Option<f64>, Option<f64>),
    bound: &str,
) -> std::io::Result<()> {
    let d = |k: usize| fixed(number(dist[k]), 1);
    writeln!(
        w,
        "  {head} min {:>width$} mean {:>width$} p99 {:>width$} max {:>width$} ms   {bound} best {:>6} worst {:>6}",
        d(0),
        d(1),
        d(2),
        d(3),
        fixed(number(best), 1),
        fixed(number(worst), 1)
    )
}

/// A latency report's last line: kernel events, wall and simulated time.
pub fn events_line(
    w: &mut dyn std::io::Write,
    events: u64,
    wall_seconds: f64,
    simulated_seconds: f64,
) -> std::io::Result<()> {
    writeln!(
        w,
        "  {events} events in {wall_seconds:.3} s wall, {simulated_seconds:.3} s simulated"
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
