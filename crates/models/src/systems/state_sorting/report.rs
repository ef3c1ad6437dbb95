//! The `state_sorting` run's text report.

use std::io::Write;

use serde_json::Value;

/// Writes the report from the summary.
pub fn write_report(s: &Value, w: &mut dyn Write) -> std::io::Result<()> {
    let m = &s["metrics"];
    writeln!(
        w,
        "{}: {} elements, {} distinct states, {} changes without a buffer; buffer {} slots",
        s["sequence"].as_str().unwrap_or(""),
        m["sequence_length"],
        m["distinct_states"],
        m["input_runs"],
        m["buffer"]
    )?;
    writeln!(w, "offline optimum >= {}", m["lower_bound"])?;
    if let Some(o) = m.get("offline_optimum") {
        writeln!(w, "offline optimum = {o}")?;
    }
    if let Some(c) = m["state_changes"].as_object() {
        for (name, v) in c {
            writeln!(
                w,
                "  {name:<14} {v:>10} state changes ({:.3} of the lower bound)",
                m["over_bound"][name].as_f64().unwrap_or(f64::NAN)
            )?;
        }
    }
    Ok(())
}
