//! The `state_sorting` run's text report, from its typed summary.

use std::io::Write;

use super::system::StateSortingSummary;

/// Writes the report from the summary (the model's name is not part of it:
/// the sequence names the run).
pub fn write_report(s: &StateSortingSummary, _model: &str, w: &mut dyn Write) -> std::io::Result<()> {
    let m = &s.metrics;
    writeln!(
        w,
        "{}: {} elements, {} distinct states, {} changes without a buffer; buffer {} slots",
        s.sequence, m.sequence_length, m.distinct_states, m.input_runs, m.buffer
    )?;
    writeln!(w, "offline optimum >= {}", m.lower_bound)?;
    if let Some(o) = m.offline_optimum {
        writeln!(w, "offline optimum = {o}")?;
    }
    for (name, v) in &m.state_changes {
        writeln!(
            w,
            "  {name:<14} {v:>10} state changes ({:.3} of the lower bound)",
            m.over_bound.get(name).copied().unwrap_or(f64::NAN)
        )?;
    }
    Ok(())
}
