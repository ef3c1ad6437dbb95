//! The human-readable report of a VR-pipeline run (`rendersim run`), from
//! its JSON summary.

use std::io::{self, Write};

use serde_json::Value;

use crate::output::text::fixed;

/// Writes the report of the run whose summary is `s`.
pub fn write_report(s: &Value, w: &mut dyn Write) -> io::Result<()> {
    let m = &s["metrics"];
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    writeln!(
        w,
        "{} (vr, {} scheme), {} motion events, seed {}",
        s["model"].as_str().unwrap_or(""),
        s["scheme"].as_str().unwrap_or(""),
        s["input_events"],
        s["seed"]
    )?;
    for kind in ["head", "object"] {
        let v = &m["motion_to_photon_ms"][kind];
        let a = &m["analytic_latency_ms"][kind];
        writeln!(
            w,
            "  {kind:<7} motion-to-photon min {:>6} mean {:>6} p99 {:>6} max {:>6} ms   closed form best {:>6} worst {:>6}",
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
