//! The human-readable report of a PixelFlow run (`rendersim run`), from
//! its JSON summary.

use std::io::{self, Write};

use serde_json::Value;

/// Writes the report of the run whose summary is `s`.
pub fn write_report(s: &Value, w: &mut dyn Write) -> io::Result<()> {
    let m = &s["metrics"];
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    writeln!(
        w,
        "{} ({}, {}), {} nodes ({} rasterizing, {} shading), {} samples, {} primitives",
        s["model"].as_str().unwrap_or(""),
        s["architecture"].as_str().unwrap_or(""),
        s["fidelity"].as_str().unwrap_or(""),
        s["nodes"],
        s["rasterizers"],
        s["shaders"],
        s["samples"],
        s["primitives"]
    )?;
    writeln!(
        w,
        "  latency {:.3} ms (front end {:.3} + back end {:.3}); closed form {:.3} ms ({:+.2}%)",
        f(&m["latency_ms"]),
        f(&m["front_end_ms"]),
        f(&m["back_end_ms"]),
        f(&m["analytic_latency_ms"]),
        100.0 * f(&m["relative_error"])
    )?;
    if let Some(st) = m["stages_ms"].as_object() {
        let parts: Vec<String> = st.iter().map(|(k, v)| format!("{k} {:.3}", f(v))).collect();
        writeln!(w, "  busy per unit (ms): {}", parts.join(", "))?;
    }
    writeln!(
        w,
        "  {} events in {:.4} s wall",
        s["events"]["total"],
        f(&s["wall_seconds"])
    )?;
    Ok(())
}
