//! The human-readable report of a multi-frame-rate run (`rendersim run`),
//! from its typed summary.

use std::io::{self, Write};

use crate::output::text::{events_line, fixed, latency_row};

use super::run::MultiRateSummary;

/// Writes the report of the run of the model named `model` whose summary is `s`.
pub fn write_report(s: &MultiRateSummary, model: &str, w: &mut dyn Write) -> io::Result<()> {
    let m = &s.metrics;
    writeln!(
        w,
        "{model} (multi_rate, {} path), {} input events, seed {}",
        s.transfer_path, s.input_events, s.seed
    )?;
    let (lat, bounds) = (&m.event_latency_ms, &m.analytic_latency_ms);
    for (path, dist, bound) in [
        ("fast", Some(&lat.fast), Some(&bounds.fast)),
        ("slow", Some(&lat.slow), Some(&bounds.slow)),
        ("conventional", lat.conventional.as_ref(), bounds.conventional.as_ref()),
    ] {
        let (Some(dist), Some(bound)) = (dist, bound) else {
            continue;
        };
        latency_row(
            w,
            &format!("{path:<13} latency"),
            7,
            dist.row(),
            (Some(bound.best), Some(bound.worst)),
            "paper",
        )?;
        if !bound.holds {
            writeln!(
                w,
                "    closed forms do not hold here (see below); the bound that holds: max <= {} ms",
                fixed(bound.bound_max, 1)
            )?;
        }
    }
    for c in &m.closed_form_caveats {
        writeln!(w, "  note: {c}")?;
    }
    events_line(w, s.events.total, s.wall_seconds, s.simulated_seconds)
}
