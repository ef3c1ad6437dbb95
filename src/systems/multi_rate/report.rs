//! The human-readable report of a multi-frame-rate run (`rendersim run`),
//! from its JSON summary.

use std::io::{self, Write};

use serde_json::Value;

use crate::output::text::fixed;

/// Writes the report of the run whose summary is `s`.
pub fn write_report(s: &Value, w: &mut dyn Write) -> io::Result<()> {
    let m = &s["metrics"];
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    writeln!(
        w,
        "{} (multi_rate, {} path), {} input events, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["transfer_path"].as_str().unwrap_or(""),
        s["input_events"],
        s["seed"]
    )?;
    for path in ["fast", "slow", "conventional"] {
        let v = &m["event_latency_ms"][path];
        if v.is_null() {
            continue;
        }
        let a = &m["analytic_latency_ms"][path];
        writeln!(
            w,
            "  {path:<13} latency min {:>7} mean {:>7} p99 {:>7} max {:>7} ms   paper best {:>6} worst {:>6}",
            fixed(f(&v["min"]), 1),
            fixed(f(&v["mean"]), 1),
            fixed(f(&v["p99"]), 1),
            fixed(f(&v["max"]), 1),
            fixed(f(&a["best"]), 1),
            fixed(f(&a["worst"]), 1)
        )?;
    }
    writeln!(
        w,
        "  {} events in {:.3} s wall, {:.3} s simulated",
        s["events"]["total"],
        f(&s["wall_seconds"]),
        f(&s["simulated_seconds"])
    )?;
    Ok(())
}
