//! The human-readable report of a VR-pipeline run (`rendersim run`), from
//! its JSON summary.

use std::io::{self, Write};

use serde_json::Value;

use crate::output::text::{events_line, latency_row};

/// Writes the report of the run whose summary is `s`.
pub fn write_report(s: &Value, w: &mut dyn Write) -> io::Result<()> {
    let m = &s["metrics"];
    writeln!(
        w,
        "{} (vr, {} scheme), {} motion events, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["scheme"].as_str().unwrap_or(""),
        s["input_events"],
        s["seed"]
    )?;
    for kind in ["head", "object"] {
        latency_row(
            w,
            &format!("{kind:<7} motion-to-photon"),
            6,
            &m["motion_to_photon_ms"][kind],
            &m["analytic_latency_ms"][kind],
            "closed form",
        )?;
    }
    events_line(w, s)
}
