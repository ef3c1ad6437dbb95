//! The human-readable report of a multi-frame-rate run (`rendersim run`),
//! from its JSON summary.

use std::io::{self, Write};

use serde_json::Value;

use crate::output::text::{events_line, latency_row};

/// Writes the report of the run whose summary is `s`.
pub fn write_report(s: &Value, w: &mut dyn Write) -> io::Result<()> {
    let m = &s["metrics"];
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
        latency_row(
            w,
            &format!("{path:<13} latency"),
            7,
            v,
            &m["analytic_latency_ms"][path],
            "paper",
        )?;
    }
    events_line(w, s)
}
