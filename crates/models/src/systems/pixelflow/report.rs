//! The human-readable report of a PixelFlow run (`rendersim run`), from
//! its typed summary.

use std::io::{self, Write};

use crate::systems::summary::name_of;

use super::run::PixelFlowSummary;

/// Writes the report of the run of the model named `model` whose summary is `s`.
pub fn write_report(s: &PixelFlowSummary, model: &str, w: &mut dyn Write) -> io::Result<()> {
    let m = &s.metrics;
    writeln!(
        w,
        "{model} ({}, {}), {} nodes ({} rasterizing, {} shading), {} samples, {} primitives",
        name_of(&s.architecture),
        name_of(&s.fidelity),
        s.nodes,
        s.rasterizers,
        s.shaders,
        s.samples,
        s.primitives
    )?;
    writeln!(
        w,
        "  latency {:.3} ms (front end {:.3} + back end {:.3}); closed form {:.3} ms ({:+.2}%)",
        m.latency_ms,
        m.front_end_ms,
        m.back_end_ms,
        m.analytic_latency_ms,
        100.0 * m.relative_error
    )?;
    let st = &m.stages_ms;
    // By name, as summary.json lists them.
    let mut stages = vec![
        ("composite", st.composite),
        ("generate", st.generate),
        ("geometry", st.geometry),
        ("load", st.load),
        ("rasterize", st.rasterize),
        ("shade", st.shade),
    ];
    if let Some(c) = st.color {
        stages.insert(0, ("color", c));
    }
    let parts: Vec<String> = stages.iter().map(|(k, v)| format!("{k} {v:.3}")).collect();
    writeln!(w, "  busy per unit (ms): {}", parts.join(", "))?;
    writeln!(w, "  {} events in {:.4} s wall", s.events.total, s.wall_seconds)?;
    Ok(())
}
