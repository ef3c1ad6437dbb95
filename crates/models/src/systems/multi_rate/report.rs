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
        if m["analytic_latency_ms"][path]["holds"] == false {
            writeln!(
                w,
                "    closed forms do not hold here (see below); the bound that holds: max <= {} ms",
                crate::output::text::fixed(
                    m["analytic_latency_ms"][path]["bound_max"].as_f64().unwrap_or(f64::NAN),
                    1
                )
            )?;
        }
    }
    for c in m["closed_form_caveats"].as_array().into_iter().flatten() {
        writeln!(w, "  note: {}", c.as_str().unwrap_or(""))?;
    }
    events_line(w, s)
}
