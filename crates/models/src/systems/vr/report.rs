//! The human-readable report of a VR-pipeline run (`rendersim run`), from
//! its typed summary.

use std::io::{self, Write};

use crate::output::text::{events_line, latency_row};
use crate::systems::summary::name_of;

use super::run::VrSummary;

/// Writes the report of the run of the model named `model` whose summary is `s`.
pub fn write_report(s: &VrSummary, model: &str, w: &mut dyn Write) -> io::Result<()> {
    let m = &s.metrics;
    writeln!(
        w,
        "{model} (vr, {} scheme), {} motion events, seed {}",
        name_of(&s.scheme),
        s.input_events,
        s.seed
    )?;
    for (kind, dist, bounds) in [
        ("head", &m.motion_to_photon_ms.head, &m.analytic_latency_ms.head),
        ("object", &m.motion_to_photon_ms.object, &m.analytic_latency_ms.object),
    ] {
        latency_row(
            w,
            &format!("{kind:<7} motion-to-photon"),
            6,
            dist.row(),
            (Some(bounds.best), Some(bounds.worst)),
            "closed form",
        )?;
    }
    events_line(w, s.events.total, s.wall_seconds, s.simulated_seconds)
}
